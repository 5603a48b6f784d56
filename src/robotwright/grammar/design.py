"""Designs: derivation trees, their readable text form, JSON, and canonical hash.

A design is the list of rule applications (steps) of a derivation, in the canonical
order (see :mod:`robotwright.grammar.derive`); each step names its rule, the node it
grows, and the component and parameters chosen for each new node. Replaying the steps
gives the design tree (:class:`DesignNode`).

Text form, one step per line (``#`` starts a comment)::

    r1 @0: B=base(diameter=0.08, thickness=0.02) P=pinned()
    r2 @0: C=revolute(limit=1.5708) L=link(diameter=0.04, length=0.15, rotation=0.0)
    r4 @3: E=gripper(finger_length=0.06)
"""

from __future__ import annotations

import hashlib
import json
import re
from dataclasses import dataclass, field
from typing import Any

from robotwright._inputs import load_json
from robotwright.errors import GrammarError, InputFileError, Problem

FORMAT = "robotwright-design/1"


@dataclass(frozen=True)
class Choice:
    """The component and parameter values chosen for one node (SI units, radians)."""

    symbol: str
    component: str | None
    params: tuple[tuple[str, float], ...] = ()

    @property
    def param_dict(self) -> dict[str, float]:
        return dict(self.params)

    def __str__(self) -> str:
        if self.component is None:
            return self.symbol
        inner = ", ".join(f"{k}={_fmt(v)}" for k, v in self.params)
        return f"{self.symbol}={self.component}({inner})"


@dataclass(frozen=True)
class Step:
    """One rule application: ``rule`` applied at node ``at`` with ``choices``.

    ``choices`` holds one entry per right-side node that gets a component: the first
    right-side node when it replaces the matched node, then every new node, in order.
    """

    rule: str
    at: int
    choices: tuple[Choice, ...] = ()

    def __str__(self) -> str:
        return f"{self.rule} @{self.at}: " + " ".join(str(c) for c in self.choices)


@dataclass(frozen=True)
class Design:
    """A complete derivation: a grammar name and its steps in canonical order."""

    grammar: str
    steps: tuple[Step, ...]

    # -- serialisation ---------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        return {
            "format": FORMAT,
            "grammar": self.grammar,
            "steps": [
                {
                    "rule": s.rule,
                    "at": s.at,
                    "choices": [
                        {"symbol": c.symbol, "component": c.component, "params": dict(c.params)}
                        for c in s.choices
                    ],
                }
                for s in self.steps
            ],
        }

    def to_json(self, indent: int | None = 2) -> str:
        return json.dumps(self.to_dict(), indent=indent, sort_keys=True)

    @classmethod
    def from_dict(cls, data: dict[str, Any], source: str = "<design>") -> Design:
        """Inverse of :meth:`to_dict` (structure checked; rules checked by ``Grammar``)."""
        try:
            if data.get("format", FORMAT) != FORMAT:
                raise ValueError(f"format must be {FORMAT!r}, got {data.get('format')!r}")
            steps = tuple(
                Step(
                    rule=str(s["rule"]),
                    at=int(s["at"]),
                    choices=tuple(
                        Choice(
                            str(c["symbol"]),
                            None if c.get("component") is None else str(c["component"]),
                            tuple(
                                sorted((str(k), float(v)) for k, v in c.get("params", {}).items())
                            ),
                        )
                        for c in s.get("choices", [])
                    ),
                )
                for s in data["steps"]
            )
            return cls(grammar=str(data["grammar"]), steps=steps)
        except (KeyError, TypeError, ValueError, AttributeError) as exc:
            raise GrammarError([Problem(source, f"not a design: {exc!r}")]) from exc

    @classmethod
    def from_json(cls, text: str, source: str = "<design>") -> Design:
        try:
            data = load_json(text, source)
        except json.JSONDecodeError as exc:
            raise GrammarError([Problem(source, f"invalid JSON: {exc}")]) from exc
        except InputFileError as exc:
            raise GrammarError([Problem(source, exc.reason)]) from exc
        if not isinstance(data, dict):
            raise GrammarError([Problem(source, "a design must be a JSON object")])
        return cls.from_dict(data, source)

    def to_text(self) -> str:
        # The header says how to read a step, for readers of a design.txt on its own.
        lines = [
            f"# {FORMAT} grammar={self.grammar} hash={self.hash()} "
            "(one step per line: RULE @NODE: CHOICES, NODE = id of the node grown, "
            "ids in creation order)"
        ]
        lines += [str(s) for s in self.steps]
        return "\n".join(lines) + "\n"

    @classmethod
    def from_text(cls, text: str, source: str = "<design>") -> Design:
        grammar = None
        steps: list[Step] = []
        for row, raw in enumerate(text.splitlines()):
            line = raw.strip()
            if line.startswith("#"):
                m = re.search(r"grammar=(\S+)", line)
                if m and grammar is None:
                    grammar = m.group(1)
                continue
            if not line:
                continue
            steps.append(_parse_step(line, source, row))
        if grammar is None:
            raise GrammarError([Problem(source, "missing header '# ... grammar=NAME'", row=0)])
        return cls(grammar=grammar, steps=tuple(steps))

    # -- identity --------------------------------------------------------------------
    def canonical(self) -> str:
        """Canonical JSON (sorted keys, no spaces, shortest float repr) that the hash covers."""
        return json.dumps(self.to_dict(), sort_keys=True, separators=(",", ":"))

    def hash(self) -> str:
        """SHA-256 of :meth:`canonical`, first 16 hex digits."""
        # Kept on the (immutable) design: a search asks for it several times per design.
        cached = self.__dict__.get("_hash")
        if cached is None:
            cached = hashlib.sha256(self.canonical().encode()).hexdigest()[:16]
            object.__setattr__(self, "_hash", cached)
        return cached

    def __str__(self) -> str:
        return "; ".join(str(s) for s in self.steps)


_STEP = re.compile(r"^([A-Za-z_][\w]*)\s*@\s*(\d+)\s*:\s*(.*)$")
_CHOICE = re.compile(r"([A-Za-z_]\w*)(?:=([A-Za-z_][\w\-]*)\(([^)]*)\))?")


def _parse_step(line: str, source: str, row: int) -> Step:
    m = _STEP.match(line)
    if m is None:
        raise GrammarError(
            [
                Problem(
                    source, f"cannot parse step {line!r}: expected 'RULE @NODE: CHOICES'", row=row
                )
            ]
        )
    choices: list[Choice] = []
    rest = m.group(3).strip()
    pos = 0
    while pos < len(rest):
        if rest[pos].isspace():
            pos += 1
            continue
        cm = _CHOICE.match(rest, pos)
        if cm is None:
            raise GrammarError(
                [
                    Problem(
                        source,
                        f"cannot parse choice at {rest[pos:]!r}: expected SYMBOL=component(name=value, ...)",
                        row=row,
                    )
                ]
            )
        params: list[tuple[str, float]] = []
        if cm.group(3):
            for item in cm.group(3).split(","):
                if not item.strip():
                    continue
                k, sep, v = item.partition("=")
                try:
                    params.append((k.strip(), float(v)))
                except ValueError:
                    raise GrammarError(
                        [Problem(source, f"parameter {item.strip()!r} is not NAME=NUMBER", row=row)]
                    ) from None
                if not sep:
                    raise GrammarError(
                        [Problem(source, f"parameter {item.strip()!r} is not NAME=NUMBER", row=row)]
                    )
        choices.append(Choice(cm.group(1), cm.group(2), tuple(sorted(params))))
        pos = cm.end()
    return Step(m.group(1), int(m.group(2)), tuple(choices))


def _fmt(v: float) -> str:
    return repr(float(v))


@dataclass
class DesignNode:
    """A node of the design tree (after replaying the steps).

    Attributes:
        id: creation index (0 = the start node).
        symbol: grammar symbol; ``component``/``params``: the chosen part.
        open: still an open end (only in partial designs).
        rule: the rule that created (or last replaced) the node; None for the start.
        children: in creation order.
    """

    id: int
    symbol: str
    component: str | None = None
    params: dict[str, float] = field(default_factory=dict)
    open: bool = True
    rule: str | None = None
    parent: DesignNode | None = field(default=None, repr=False)
    children: list[DesignNode] = field(default_factory=list)

    def walk(self):
        """Pre-order traversal (node, then children in order)."""
        yield self
        for c in self.children:
            yield from c.walk()

    def label(self) -> str:
        if self.component is None:
            return f"{self.symbol}{'*' if self.open else ''}"
        inner = ", ".join(f"{k}={v:g}" for k, v in sorted(self.params.items()))
        return f"{self.symbol}:{self.component}({inner})"


def to_dot(root: DesignNode, title: str = "design") -> str:
    """Graphviz DOT text of a design tree (nodes labelled ``symbol:component(params)``)."""
    lines = [f'digraph "{title}" {{', "  node [shape=box, fontname=Helvetica];"]
    for n in root.walk():
        lines.append(f'  n{n.id} [label="{n.label()}"];')
    for n in root.walk():
        for c in n.children:
            lines.append(f'  n{n.id} -> n{c.id} [label="{c.rule or ""}"];')
    lines.append("}")
    return "\n".join(lines) + "\n"
