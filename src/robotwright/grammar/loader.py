"""Load a grammar and a component library from YAML, with validation.

Every problem found is reported at once in a :class:`~robotwright.errors.GrammarError`
whose entries name the file, the rule or component, and the field.
"""

from __future__ import annotations

import math
import re
import warnings
from importlib import resources
from pathlib import Path
from typing import Any

import yaml

from robotwright._bounds import Bound, finite_number
from robotwright._inputs import load_yaml
from robotwright._names import name_problem, shown, shown_key
from robotwright._paths import resolve_inside
from robotwright.errors import GrammarError, InputFileError, Problem, UnsafePathError
from robotwright.grammar.library import (
    COMPONENT_KINDS,
    REQUIRED_PARAMS,
    Component,
    DofSpec,
    Library,
    ParamDomain,
)
from robotwright.grammar.rules import Grammar, Rule
from robotwright.grammar.symbols import NodePattern, NodeState, Symbol, parse_chain


class GrammarWarning(UserWarning):
    """Something in a grammar is suspicious but not wrong (e.g. a symbol never produced)."""


#: The names a design file (design.txt, see robotwright.grammar.design) can hold: a
#: rule, symbol or parameter name is a word, a component name may also hold '-', a
#: grammar name holds no blank. A grammar with other names would write designs that
#: cannot be read back.
_WORD = re.compile(r"[A-Za-z_]\w*\Z")
_COMPONENT_WORD = re.compile(r"[A-Za-z_][\w-]*\Z")
_NO_BLANK = re.compile(r"\S+\Z")
_EXPECTED = {
    _WORD: "a letter or '_' followed by letters, digits or '_'",
    _COMPONENT_WORD: "a letter or '_' followed by letters, digits, '_' or '-'",
    _NO_BLANK: "a name without blanks",
}


#: The ratings a connector's actuator may give (N m or N, rad/s or m/s, N, N m).
_ACTUATOR_KEYS = ("peak_torque", "peak_velocity", "peak_bearing_force", "peak_bearing_moment")


def _name_error(name: object, pattern: re.Pattern[str]) -> str | None:
    """Why ``name`` cannot name a grammar part (``pattern``: what design files hold)."""
    if not isinstance(name, str):
        return f"name {shown(name)}: expected a text"
    text = name
    problem = name_problem(text)
    if problem is not None:
        return f"name {shown(text)} {problem}"
    if pattern.match(text) is None:
        return f"name {shown(text)}: expected {_EXPECTED[pattern]} (as design files write it)"
    return None


_GRAMMAR_KEYS = {"name", "start", "symbols", "rules", "link_symbols", "library", "description"}
_RULE_KEYS = {"lhs", "rhs", "branching", "description"}
_COMPONENT_KEYS = {
    "symbol",
    "kind",
    "attach",
    "offer",
    "params",
    "density",
    "rgba",
    "dofs",
    "housing",
    "actuator",
    "description",
}


def default_grammar_path() -> Path:
    """Path of the bundled SRL grammar."""
    return Path(str(resources.files("robotwright.grammar") / "data" / "srl_grammar.yaml"))


def default_library_path() -> Path:
    """Path of the bundled SRL component library."""
    return Path(str(resources.files("robotwright.grammar") / "data" / "srl_library.yaml"))


def default_grammar() -> Grammar:
    """The bundled SRL grammar (seed rules r1..r4, open ends marked) and library."""
    return load_grammar(default_grammar_path(), default_library_path())


def _read_yaml(path: Path, problems: list[Problem]) -> dict[str, Any] | None:
    # A regular file under the size cap, UTF-8, nested at most MAX_NESTING levels.
    try:
        data = load_yaml(path, exponent_floats=True)
    except InputFileError as exc:
        problems.append(Problem(str(path), f"cannot read file: it {exc.reason}"))
        return None
    except OSError as exc:
        problems.append(Problem(str(path), f"cannot read file: {exc.strerror or exc}"))
        return None
    except yaml.YAMLError as exc:
        problems.append(Problem(str(path), f"invalid YAML: {exc}"))
        return None
    if not isinstance(data, dict):
        problems.append(Problem(str(path), "expected a YAML mapping at top level"))
        return None
    return data


def _description(value: Any) -> str:
    """A symbol's, rule's or component's description: a text, shown as given; anything
    else (a list, an alias bomb) is summarised, never formatted whole."""
    return value if isinstance(value, str) else "" if value is None else shown(value)


#: Highest material density accepted (kg/m^3): osmium, the densest element, is 22,590.
MAX_DENSITY = 100_000.0
#: A component parameter's values and a DoF's range ends (m or rad: a limb's parts are
#: centimetres to a metre or two, its angles a few radians).
PARAM_BOUND = Bound(-1000.0, 1000.0)
#: Most values one parameter may list (the search enumerates them).
MAX_PARAM_VALUES = 1000
#: A DoF's twist about the link axis [rad].
TWIST_BOUND = Bound(-2 * math.pi, 2 * math.pi, unit="rad")
#: Housing sizes [m] and actuator ratings (N m or N, rad/s or m/s).
RATING_BOUND = Bound(0.0, 1e6, open_low=True)
#: A colour channel.
RGBA_BOUND = Bound(0.0, 1.0)


def _reversed_range(dof: DofSpec, params: dict[str, ParamDomain]) -> dict[str, float] | None:
    """Parameter values (``{}`` for numbers) for which the DoF's range has lower > upper,
    or ``None`` when it is ordered for every choice of its parameters."""
    names = sorted({i.lstrip("-") for i in dof.range if isinstance(i, str)} & set(params))
    if len(names) != len({i.lstrip("-") for i in dof.range if isinstance(i, str)}):
        return None  # an unknown parameter, reported already
    choices: list[dict[str, float]] = [{}]
    for name in names:
        choices = [{**c, name: v} for c in choices for v in params[name].values]
    for values in choices:
        low, high = dof.resolve_range(values)
        if low > high:
            return values
    return None


def load_library(path: str | Path) -> Library:
    """Load and validate a component library file (raises :class:`GrammarError`)."""
    path = Path(path)
    problems: list[Problem] = []
    data = _read_yaml(path, problems)
    if data is None:
        raise GrammarError(problems, f"cannot load component library {path}")
    lib = _parse_library(path, data, problems)
    if problems:
        raise GrammarError(problems, f"component library {path} is invalid")
    return lib


def _parse_library(path: Path, data: dict[str, Any], problems: list[Problem]) -> Library:
    f = str(path)
    ports = tuple(str(p) for p in (data.get("ports") or []))
    comps: dict[str, Component] = {}
    raw = data.get("components")
    if not isinstance(raw, dict) or not raw:
        problems.append(
            Problem(f, "expected a non-empty mapping of components", column="components")
        )
        raw = {}
    for cname, spec in raw.items():
        bad = _name_error(cname, _COMPONENT_WORD)
        if bad is not None:
            problems.append(Problem(f, bad, column="components"))
            continue
        where = f"component '{cname}'"

        def err(msg: str, col: str | None = None, _w: str = where) -> None:
            problems.append(Problem(f, msg, column=col, element=_w))

        if not isinstance(spec, dict):
            err("expected a mapping")
            continue
        for key in spec:
            if key not in _COMPONENT_KEYS:
                err(f"unknown field (expected one of {sorted(_COMPONENT_KEYS)})", shown_key(key))
        kind = spec.get("kind")
        if kind not in COMPONENT_KINDS:
            err(f"kind must be one of {list(COMPONENT_KINDS)}, got {shown(kind)}", "kind")
            continue
        symbol = spec.get("symbol")
        if not isinstance(symbol, str) or not symbol:
            err("needs the grammar symbol it realises", "symbol")
            continue
        port_lists: dict[str, tuple[str, ...]] = {}
        for key in ("attach", "offer"):
            vals = spec.get(key) or []
            if not isinstance(vals, list):
                err("expected a list of port types", key)
                vals = []
            for p in vals:
                if ports and p not in ports:
                    err(f"unknown port type {shown(p)} (library declares {list(ports)})", key)
            port_lists[key] = tuple(str(p) for p in vals)
        params: dict[str, ParamDomain] = {}
        for pname, pspec in (spec.get("params") or {}).items():
            bad = _name_error(pname, _WORD)
            if bad is not None:
                err(bad, "params")
                continue
            col = f"params.{pname}"
            if not isinstance(pspec, dict) or "range" not in pspec or "values" not in pspec:
                err("expected {range: [low, high], values: [...]}", col)
                continue
            rng = pspec["range"]
            if not (
                isinstance(rng, list)
                and len(rng) == 2
                and all(PARAM_BOUND.check(v) is not None for v in rng)
            ):
                err(
                    f"range must be two numbers [low, high], each {PARAM_BOUND.describe()}, "
                    f"got {shown(rng)}",
                    col,
                )
                continue
            low, high = float(rng[0]), float(rng[1])
            if low > high:
                err(f"range low {low} > high {high}", col)
                continue
            values = pspec["values"]
            if not isinstance(values, list) or not 0 < len(values) <= MAX_PARAM_VALUES:
                err(f"values must be a list of 1 to {MAX_PARAM_VALUES} numbers", col)
                continue
            good = True
            for v in values:
                x = finite_number(v)
                if x is None:
                    err(f"value {shown(v)} is not a number", col)
                    good = False
                elif not low <= x <= high:
                    err(f"value {x} is out of the domain [{low}, {high}]", col)
                    good = False
            if len(set(values)) != len(values):
                err("values repeat (each design would be counted twice)", col)
                good = False
            if good:
                params[pname] = ParamDomain(pname, low, high, tuple(float(v) for v in values))
        for need, meaning in REQUIRED_PARAMS[kind].items():
            if need not in params and need not in (spec.get("params") or {}):
                err(f"kind '{kind}' needs parameter '{need}' ({meaning})", "params")
            elif need in params and "(m)" in meaning and not params[need].low > 0:
                err(f"{need} is a size: expected a domain above 0 m", f"params.{need}")
        dofs: list[DofSpec] = []
        if kind == "connector":
            raw_dofs = spec.get("dofs")
            if not isinstance(raw_dofs, list) or not raw_dofs:
                err("a connector needs a non-empty list of dofs (one DoF each)", "dofs")
                raw_dofs = []
            for i, d in enumerate(raw_dofs):
                col = f"dofs[{i}]"
                if not isinstance(d, dict):
                    err("expected {type, twist, range}", col)
                    continue
                twist = TWIST_BOUND.check(d.get("twist", 0.0))
                rng = d.get("range")
                if twist is None:
                    err(
                        f"twist must be a number: {TWIST_BOUND.expected()}, got {shown(d.get('twist'))}",
                        col,
                    )
                    continue
                if not (isinstance(rng, list) and len(rng) == 2):
                    err("range must be [lower, upper] (numbers or parameter names)", col)
                    continue
                items: list[float | str] = []
                for item in rng:
                    if isinstance(item, str):
                        if item.lstrip("-") not in params:
                            err(f"range refers to unknown parameter {shown(item)}", col)
                        items.append(item)
                    elif PARAM_BOUND.check(item) is not None:
                        items.append(float(item))
                    else:
                        err(
                            f"range item {shown(item)} is neither a parameter nor a number "
                            f"({PARAM_BOUND.expected()})",
                            col,
                        )
                try:
                    dof = DofSpec(d.get("type"), twist, (items[0], items[1]))
                except (ValueError, IndexError) as exc:
                    err(str(exc), col)
                    continue
                reversed_at = _reversed_range(dof, params)
                if reversed_at is not None:
                    err(f"range {list(rng)} has lower > upper for {reversed_at}", col)
                    continue
                dofs.append(dof)
            for key in ("housing", "actuator"):
                val = spec.get(key)
                if not isinstance(val, dict) or any(
                    RATING_BOUND.check(v) is None for v in val.values()
                ):
                    err(f"expected a mapping of numbers, each {RATING_BOUND.describe()}", key)
            for need in ("diameter", "length"):
                if need not in (spec.get("housing") or {}):
                    err(f"housing needs '{need}' (m)", "housing")
            for need in ("peak_torque", "peak_velocity"):
                if need not in (spec.get("actuator") or {}):
                    err(f"actuator needs '{need}'", "actuator")
            for key in spec.get("actuator") or {}:
                if key not in _ACTUATOR_KEYS:
                    err(
                        f"unknown actuator rating {shown(key)}; expected {', '.join(_ACTUATOR_KEYS)}",
                        "actuator",
                    )
        density = finite_number(spec.get("density", 1000.0))
        if density is None or not 0 < density <= MAX_DENSITY:
            err(
                f"density must be a number in (0, {MAX_DENSITY:g}] kg/m^3, got "
                f"{shown(spec.get('density'))}",
                "density",
            )
            density = 1000.0
        rgba = spec.get("rgba", [0.7, 0.7, 0.7, 1.0])
        if not (
            isinstance(rgba, list)
            and len(rgba) == 4
            and all(RGBA_BOUND.check(v) is not None for v in rgba)
        ):
            err(f"rgba must be 4 numbers, each {RGBA_BOUND.describe()}, got {shown(rgba)}", "rgba")
            rgba = [0.7, 0.7, 0.7, 1.0]
        try:
            comps[cname] = Component(
                name=str(cname),
                symbol=symbol,
                kind=kind,
                attach=port_lists["attach"],
                offer=port_lists["offer"],
                params=params,
                density=density,
                rgba=tuple(float(v) for v in rgba),  # type: ignore[arg-type]
                dofs=tuple(dofs),
                housing={
                    k: float(v) for k, v in (spec.get("housing") or {}).items() if finite_number(v)
                },
                actuator={
                    k: float(v) for k, v in (spec.get("actuator") or {}).items() if finite_number(v)
                },
            )
        except ValueError as exc:
            err(str(exc))
    return Library(name=str(data.get("name", path.stem)), components=comps, ports=ports, source=f)


def load_grammar(path: str | Path, library: str | Path | Library | None = None) -> Grammar:
    """Load and validate a grammar file and its component library.

    Args:
        path: grammar YAML file.
        library: a library file or object; default: the file named by the grammar's
            ``library`` key (relative to the grammar file), else the bundled library.

    Raises:
        GrammarError: listing every problem (file, rule or component, field).
    """
    path = Path(path)
    problems: list[Problem] = []
    data = _read_yaml(path, problems)
    if data is None:
        raise GrammarError(problems, f"cannot load grammar {path}")
    if isinstance(library, Library):
        lib = library
    else:
        lib_path: Path
        if library is None and data.get("library"):
            # Named by the (untrusted) grammar file: it must stay in the grammar's folder.
            try:
                if not isinstance(data["library"], str):
                    raise UnsafePathError(f"{shown(data['library'])}: expected a file name")
                lib_path = resolve_inside(
                    data["library"],
                    base=path.parent,
                    root=path.parent,
                    what="the grammar's folder",
                    hint="",
                )
            except UnsafePathError as exc:
                problems.append(Problem(str(path), exc.reason, column="library"))
                raise GrammarError(problems, f"cannot load grammar {path}") from None
        elif library is None:
            lib_path = default_library_path()
        else:
            lib_path = Path(library)
        lib_data = _read_yaml(lib_path, problems)
        lib = _parse_library(lib_path, lib_data, problems) if lib_data is not None else None
    grammar = _parse_grammar(path, data, lib, problems) if lib is not None else None
    if grammar is not None and not problems:
        _check_grammar(grammar, problems)
    errors = [p for p in problems if p.severity == "error"]
    if errors or grammar is None:
        raise GrammarError(problems, f"grammar {path} is invalid")
    for p in problems:
        warnings.warn(str(p), GrammarWarning, stacklevel=2)
    return grammar


def _parse_grammar(
    path: Path, data: dict[str, Any], lib: Library, problems: list[Problem]
) -> Grammar | None:
    f = str(path)
    for key in data:
        if key not in _GRAMMAR_KEYS:
            problems.append(
                Problem(
                    f,
                    f"unknown field (expected one of {sorted(_GRAMMAR_KEYS)})",
                    column=shown_key(key),
                )
            )
    symbols: dict[str, Symbol] = {}
    raw_syms = data.get("symbols")
    if not isinstance(raw_syms, dict) or not raw_syms:
        problems.append(Problem(f, "expected a non-empty mapping of symbols", column="symbols"))
        raw_syms = {}
    for sname, spec in raw_syms.items():
        bad = _name_error(sname, _WORD)
        if bad is not None:
            problems.append(Problem(f, bad, column="symbols"))
            continue
        spec = spec if isinstance(spec, dict) else {"kind": spec}
        try:
            symbols[str(sname)] = Symbol(
                str(sname), spec.get("kind"), _description(spec.get("description"))
            )
        except ValueError as exc:
            problems.append(Problem(f, str(exc), column="kind", element=f"symbol '{sname}'"))
    start = data.get("start")
    if not isinstance(start, str) or start not in symbols:
        problems.append(
            Problem(f, f"start symbol {shown(start)} is not a declared symbol", column="start")
        )
    elif symbols[start].kind != "nonterminal":
        problems.append(
            Problem(f, f"start symbol {shown(start)} must be a nonterminal", column="start")
        )
    raw_links = data.get("link_symbols") or []
    if not isinstance(raw_links, list):
        problems.append(Problem(f, "expected a list of symbols", column="link_symbols"))
        raw_links = []
    link_symbols = tuple(s for s in raw_links if isinstance(s, str) and s in symbols)
    for s in raw_links:
        if not isinstance(s, str) or s not in symbols:
            problems.append(Problem(f, f"unknown symbol {shown(s)}", column="link_symbols"))
    rules: dict[str, Rule] = {}
    raw_rules = data.get("rules")
    if not isinstance(raw_rules, dict) or not raw_rules:
        problems.append(Problem(f, "expected a non-empty mapping of rules", column="rules"))
        raw_rules = {}
    for rname, spec in raw_rules.items():
        bad = _name_error(rname, _WORD)
        if bad is not None:
            problems.append(Problem(f, bad, column="rules"))
            continue
        where = f"rule '{rname}'"
        if not isinstance(spec, dict):
            problems.append(Problem(f, "expected {lhs, rhs}", element=where))
            continue
        for key in spec:
            if key not in _RULE_KEYS:
                problems.append(
                    Problem(
                        f,
                        f"unknown field (expected one of {sorted(_RULE_KEYS)})",
                        column=shown_key(key),
                        element=where,
                    )
                )
        try:
            lhs = NodePattern.parse(spec.get("lhs", ""))
        except ValueError as exc:
            problems.append(Problem(f, str(exc), column="lhs", element=where))
            continue
        try:
            rhs = parse_chain(spec.get("rhs", ""))
        except ValueError as exc:
            problems.append(Problem(f, str(exc), column="rhs", element=where))
            continue
        ok = True
        for col, node in [("lhs", lhs)] + [("rhs", n) for n in rhs]:
            if node.symbol not in symbols:
                problems.append(
                    Problem(
                        f,
                        f"unknown symbol {shown(node.symbol)} (declared: {sorted(symbols)})",
                        column=col,
                        element=where,
                    )
                )
                ok = False
        if not ok:
            continue
        if symbols[lhs.symbol].kind == "terminal":
            problems.append(
                Problem(
                    f,
                    f"left side {lhs} is a terminal symbol, which is never rewritten",
                    column="lhs",
                    element=where,
                )
            )
        if rhs[0].keep and rhs[0].symbol != lhs.symbol:
            problems.append(
                Problem(
                    f,
                    f"'{rhs[0]}' keeps the matched node, so it must be the left side's symbol {shown(lhs.symbol)}",
                    column="rhs",
                    element=where,
                )
            )
        for node in rhs:
            if node.open and symbols[node.symbol].kind == "terminal":
                problems.append(
                    Problem(
                        f,
                        f"terminal {shown(node.symbol)} cannot be left open ('{node}')",
                        column="rhs",
                        element=where,
                    )
                )
        branching = spec.get("branching", False)
        if not isinstance(branching, bool):
            problems.append(
                Problem(
                    f,
                    f"branching must be true or false, got {shown(branching)}",
                    column="branching",
                    element=where,
                )
            )
            branching = False
        rules[str(rname)] = Rule(
            str(rname), lhs, rhs, branching, _description(spec.get("description"))
        )
    for comp in lib.components.values():
        if comp.symbol not in symbols:
            problems.append(
                Problem(
                    lib.source,
                    f"symbol {shown(comp.symbol)} is not declared by grammar {f}",
                    column="symbol",
                    element=f"component '{comp.name}'",
                )
            )
    name = data.get("name", path.stem)
    bad = _name_error(name, _NO_BLANK)
    if bad is not None:
        # The name of the file when it has no 'name' field.
        problems.append(Problem(f, bad, column="name"))
    if not isinstance(start, str) or start not in symbols:
        return None
    return Grammar(
        name=str(name),
        start=str(start),
        symbols=symbols,
        rules=rules,
        library=lib,
        link_symbols=link_symbols,
        source=f,
    )


def _check_grammar(g: Grammar, problems: list[Problem]) -> None:
    """Whole-grammar checks: components, ports, open-end marks, matching, reachability, termination."""
    f = g.source
    closed_symbols = {n.symbol for r in g.rules.values() for n in r.rhs if not n.open}
    for r in g.rules.values():
        where = f"rule '{r.name}'"
        for node in r.rhs:
            if not node.open and not g.library.for_symbol(node.symbol):
                problems.append(
                    Problem(
                        f,
                        f"'{node}' is finished here but the library has no component for symbol {shown(node.symbol)} (mark it open or add a component)",
                        column="rhs",
                        element=where,
                    )
                )
        if not r.lhs.open and r.lhs.symbol in closed_symbols and not r.branching:
            problems.append(
                Problem(
                    f,
                    f"left side '{r.lhs}' matches every {r.lhs.symbol} node, also interior ones, so it would grow extra branches; write '{r.lhs}*' to grow only the open end, or set 'branching: true'",
                    column="lhs",
                    element=where,
                )
            )
        for a, b in zip(r.rhs, r.rhs[1:]):
            for ca in g.library.for_symbol(a.symbol):
                for cb in g.library.for_symbol(b.symbol):
                    if not set(ca.offer) & set(cb.attach):
                        problems.append(
                            Problem(
                                f,
                                f"port mismatch on edge {a.symbol} -> {b.symbol}: component '{ca.name}' offers {list(ca.offer)} but '{cb.name}' attaches by {list(cb.attach)}",
                                column="rhs",
                                element=where,
                            )
                        )
    if problems:
        return
    # States any rule (or the start) can create, ignoring whether they are reachable.
    produced_by: dict[str, set[NodeState]] = {}
    for r in g.rules.values():
        out: set[NodeState] = set()
        for has_edges in (False, True):
            for open_ in (False, True):
                st = NodeState(r.lhs.symbol, open_, has_edges)
                if r.matches(st):
                    kept, new = r.result_states(st)
                    out.update((kept, *new))
        produced_by[r.name] = out
    reachable = g.reachable_states()
    for r in g.rules.values():
        where = f"rule '{r.name}'"
        # States the start or any *other* rule creates (a rule cannot feed itself first).
        produced = {g.start_state}.union(*(v for k, v in produced_by.items() if k != r.name))
        if not any(r.matches(s) for s in produced):
            occurring = (
                ", ".join(sorted(str(s) for s in produced if s.symbol == r.lhs.symbol)) or "none"
            )
            problems.append(
                Problem(
                    f,
                    f"left side '{r.lhs}' can never match: no rule creates such a node (nodes of {shown(r.lhs.symbol)} that occur: {occurring})",
                    column="lhs",
                    element=where,
                )
            )
        elif not any(r.matches(s) for s in reachable):
            problems.append(
                Problem(
                    f,
                    f"rule is unreachable from the start symbol {shown(g.start)}",
                    column="lhs",
                    element=where,
                )
            )
    # An open state terminates if some rule turns it into terminating states only.
    done = {s for s in reachable if not s.open}
    changed = True
    while changed:
        changed = False
        for st in reachable - done:
            for r in g.matching_rules(st):
                kept, new = r.result_states(st)
                if all(s in done for s in (kept, *new)):
                    done.add(st)
                    changed = True
                    break
    for st in sorted(reachable - done, key=str):
        names = [r.name for r in g.matching_rules(st)] or ["none"]
        problems.append(
            Problem(
                f,
                f"an open '{st}' node can never be finished: no derivation through rules {names} closes it",
                column="rules",
                element=f"symbol '{st.symbol}'",
            )
        )
    for sym in g.symbols.values():
        if not any(s.symbol == sym.name for s in reachable):
            problems.append(
                Problem(
                    f,
                    "symbol is declared but no derivation from the start produces it",
                    column="symbols",
                    element=f"symbol '{sym.name}'",
                    severity="warning",
                )
            )
