"""The search log: one JSON line per evaluated design, written as evaluations come.

A log is readable while its search runs (every line is flushed whole) and lets a
stopped search resume (:func:`read_log`: designs found in it are not evaluated again).
Format (``robotwright-search-log/1``), one JSON object per line:

- a ``search`` line opens each run that wrote to the file::

    {"kind": "search", "format": "robotwright-search-log/1", "grammar": "srl",
     "method": "beam", "seed": 0, "budget": 100, "max_links": 4,
     "objectives": [{"name": "reach", "maximize": true, "settings": "Reach(...)"}],
     "constraints": [{"name": "no-self-collision", "settings": "NoSelfCollision()"}]}

  A refine of the search's best design (``--refine``, CMA-ES) appends a ``search`` line
  of its own (``"method": "refine"``, its ``seed``, ``budget`` and initial step
  ``sigma``), then its evaluations, its start design first.

- an ``evaluation`` line per design, in evaluation order::

    {"kind": "evaluation", "seed": 0, "iteration": 7, "hash": "3f...",
     "design": "# robotwright-design/1 grammar=srl ...\\nr1 @0: ...\\n",
     "values": {"reach": 0.4841}, "violations": [], "feasible": true}

  ``iteration`` counts the evaluations of the search from 0; ``values`` are in the
  objectives' units (m, m^3, kg, W; see docs/grammar.md); ``violations`` holds one
  message per constraint not met. An objective value that is not a finite number is
  written as the string ``"inf"``, ``"-inf"`` or ``"nan"`` (JSON has no such numbers).

A log is untrusted input when resumed (it may have been edited): every line is parsed
as JSON and checked (design text read by the design reader and its hash recomputed,
numbers finite, the objectives and constraints those of the search resumed); the first
line that fails is refused with an :class:`~robotwright.errors.InputFileError` naming
the file, the line and what was expected.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import IO, Any

from robotwright._inputs import MAX_NESTING, read_text
from robotwright.errors import GrammarError, InputFileError, OutputPathError
from robotwright.grammar.design import Design
from robotwright.grammar.objectives import Constraint, Evaluation, Objective, scored

__all__ = ["FORMAT", "MAX_LOG_BYTES", "SearchLog", "read_log"]

FORMAT = "robotwright-search-log/1"
#: Largest log :func:`read_log` reads (about a million evaluations of 4-link designs).
MAX_LOG_BYTES = 1 << 30
_NON_FINITE = {"inf": math.inf, "-inf": -math.inf, "nan": math.nan}
_SEARCH_KEYS = {
    "kind",
    "format",
    "grammar",
    "method",
    "seed",
    "budget",
    "max_links",
    "batch",
    "sigma",
    "objectives",
    "constraints",
}
_EVAL_KEYS = {"kind", "seed", "iteration", "hash", "design", "values", "violations", "feasible"}


def _settings(items: Sequence[Any]) -> list[dict[str, Any]]:
    out = []
    for x in items:
        entry: dict[str, Any] = {"name": x.name}
        if hasattr(x, "maximize"):
            entry["maximize"] = bool(x.maximize)
        entry["settings"] = repr(x)  # compared as text on resume, never evaluated
        out.append(entry)
    return out


def _number(v: float) -> float | str:
    v = float(v)
    if math.isfinite(v):
        return v
    return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf")


def open_log(path: Path, append: bool) -> IO[str]:
    """The log file opened for writing (``append``: at its end), never through a symbolic
    link at its name (a link planted there would be written through): a log grows line
    by line as the search runs, so it cannot be written to a temporary and renamed.

    Raises:
        OutputPathError: the name is a link, or the file cannot be opened.
    """
    flags = os.O_WRONLY | os.O_CREAT | (os.O_APPEND if append else os.O_TRUNC)
    flags |= getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)
    try:
        fd = os.open(path, flags, 0o666)
    except OSError as exc:
        link = " (a symbolic link: not followed)" if path.is_symlink() else ""
        raise OutputPathError(
            f"{path}: cannot write the search log{link}: {exc.strerror}"
        ) from None
    return os.fdopen(fd, "a" if append else "w", encoding="utf-8")


class SearchLog:
    """Appends a search's evaluations to a JSON-lines file, one flushed line each.

    Args:
        path: the log file; created (its folder too), or appended to with ``append``.
        append: add to an existing log (a resumed search writing on into its own log).
        header: the ``search`` line's fields (method, seed, budget, max_links).
    """

    def __init__(
        self,
        path: str | os.PathLike[str],
        grammar: str,
        objectives: Sequence[Objective],
        constraints: Sequence[Constraint],
        *,
        append: bool = False,
        **header: Any,
    ) -> None:
        self.path = Path(path)
        self.seed = header.get("seed")
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._file: IO[str] = open_log(self.path, append)
        self._write(
            {
                "kind": "search",
                "format": FORMAT,
                "grammar": grammar,
                **header,
                "objectives": _settings(objectives),
                "constraints": _settings(constraints),
            }
        )

    def _write(self, record: dict[str, Any]) -> None:
        # One write and a flush per line: a reader (tail -f) sees whole lines.
        self._file.write(json.dumps(record, allow_nan=False, separators=(", ", ": ")) + "\n")
        self._file.flush()

    def write(self, ev: Evaluation, iteration: int) -> None:
        """Append one evaluation (``iteration``: its index in the search, from 0)."""
        self._write(
            {
                "kind": "evaluation",
                "seed": self.seed,
                "iteration": iteration,
                "hash": ev.design.hash(),
                "design": ev.design.to_text(),
                "values": {k: _number(v) for k, v in ev.values.items()},
                "violations": list(ev.violations),
                "feasible": ev.feasible,
            }
        )

    def close(self) -> None:
        self._file.close()

    def __enter__(self) -> SearchLog:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class _Bad(Exception):
    """A check of one line failed (the message says what was expected)."""


def _reject_constant(name: str) -> float:
    raise _Bad(f"{name} is not a number JSON allows; expected a finite number")


def _finite(v: Any, what: str) -> float:
    if isinstance(v, str) and v in _NON_FINITE:
        return _NON_FINITE[v]
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise _Bad(f"{what} is {json.dumps(v)[:60]}; expected a number")
    if not math.isfinite(v):
        raise _Bad(f"{what} is not finite; expected a finite number")
    return float(v)


def _int(v: Any, what: str) -> int:
    if isinstance(v, bool) or not isinstance(v, int):
        raise _Bad(f"{what} is {json.dumps(v)[:60]}; expected an integer")
    return v


def _keys(rec: dict[str, Any], allowed: set[str], what: str) -> None:
    extra = sorted(set(rec) - allowed)
    if extra:
        raise _Bad(f"unknown field(s) {', '.join(map(repr, extra))} in a {what} line")


def read_log(
    path: str | os.PathLike[str],
    grammar: str,
    objectives: Sequence[Objective],
    constraints: Sequence[Constraint],
    search: Mapping[str, Any] | None = None,
) -> dict[str, Evaluation]:
    """The evaluations of the log at ``path`` by design hash, checked line by line.

    Every ``search`` line must name ``grammar`` and the same objectives and constraints
    (names and settings) as the search resuming, so that its evaluations are the ones
    this search would make. An MCTS search (``search``: the resuming search's ``search``
    line fields) resumes only a log of MCTS with the same ``batch``: another batch walks
    another tree and would end elsewhere. Scores are recomputed from the values (the first objective,
    negated when minimised, ``-inf`` when a constraint is violated).

    Raises:
        InputFileError: the file is not a regular UTF-8 file under
            :data:`MAX_LOG_BYTES`, or a line is not what it must be (message: ``line N:
            ...``); a design logged twice with different results is refused too.
        OSError: the file cannot be opened.
    """
    text = read_text(path, MAX_LOG_BYTES)
    want_obj = _settings(objectives)
    want_con = _settings(constraints)
    found: dict[str, tuple[int, Evaluation]] = {}
    header_seen = False
    lines = text.split("\n")
    complete = text.endswith("\n")
    for n, line in enumerate(lines, start=1):
        if not line.strip():
            continue
        try:
            try:
                rec = json.loads(line, parse_constant=_reject_constant)
            except RecursionError:
                raise _Bad(f"nests deeper than {MAX_NESTING} levels") from None
            except json.JSONDecodeError as exc:
                last = n == len(lines) and not complete
                hint = " (the last line is incomplete: the search stopped while writing it)"
                raise _Bad(f"not JSON: {exc.msg}{hint if last else ''}") from None
            if not isinstance(rec, dict):
                raise _Bad("expected a JSON object")
            kind = rec.get("kind")
            if kind == "search":
                _keys(rec, _SEARCH_KEYS, "search")
                if rec.get("format") != FORMAT:
                    raise _Bad(
                        f"format is {json.dumps(rec.get('format'))[:60]}; expected {FORMAT!r}"
                    )
                if rec.get("grammar") != grammar:
                    raise _Bad(
                        f"grammar is {json.dumps(rec.get('grammar'))[:60]}; expected {grammar!r} "
                        "(the grammar of the search resumed)"
                    )
                for key, want in (("objectives", want_obj), ("constraints", want_con)):
                    if rec.get(key) != want:
                        names = ", ".join(x["name"] for x in want) or "none"
                        raise _Bad(
                            f"{key} differ from this search's ({names}, with the same "
                            "settings); resume with the objectives and constraints the log "
                            "was written with"
                        )
                _check_batch(rec, search or {})
                header_seen = True
                continue
            if kind != "evaluation":
                raise _Bad(f"kind is {json.dumps(kind)[:60]}; expected 'search' or 'evaluation'")
            if not header_seen:
                raise _Bad("an evaluation before any 'search' line; expected a search line first")
            _keys(rec, _EVAL_KEYS, "evaluation")
            ev = _evaluation(rec, grammar, objectives, [o["name"] for o in want_obj])
            h = rec.get("hash")
            if h != ev.design.hash():
                raise _Bad(
                    f"hash is {json.dumps(h)[:60]}; the design's hash is {ev.design.hash()!r}"
                )
            if h in found:
                m, old = found[h]
                if not (_same_values(old.values, ev.values) and old.violations == ev.violations):
                    raise _Bad(f"design {h} was logged on line {m} with other results")
                continue
            found[h] = (n, ev)
        except _Bad as exc:
            raise InputFileError(path, f"line {n}: {exc}") from None
    return {h: ev for h, (_, ev) in found.items()}


def _check_batch(rec: Mapping[str, Any], search: Mapping[str, Any]) -> None:
    if search.get("method") != "mcts" or rec.get("method") != "mcts":
        return
    if rec.get("batch") != search.get("batch"):
        logged = "no batch" if "batch" not in rec else f"batch {json.dumps(rec['batch'])[:20]}"
        raise _Bad(
            f"an MCTS search with {logged}; this one has batch {search.get('batch')} (resume "
            "with the batch the log was written with: another batch walks another tree)"
        )


def _same_values(a: Mapping[str, float], b: Mapping[str, float]) -> bool:
    # nan != nan: the same logged nan is the same result
    return a.keys() == b.keys() and all(
        (x == y) or (math.isnan(x) and math.isnan(y)) for x, y in ((a[k], b[k]) for k in a)
    )


def _evaluation(
    rec: dict[str, Any], grammar: str, objectives: Sequence[Objective], names: list[str]
) -> Evaluation:
    _int(rec.get("iteration"), "iteration")
    if rec.get("seed") is not None:
        _int(rec.get("seed"), "seed")
    text = rec.get("design")
    if not isinstance(text, str):
        raise _Bad("design is not a string; expected the design's text")
    try:
        design = Design.from_text(text, "design")
    except GrammarError as exc:
        raise _Bad("; ".join(str(p) for p in exc.problems)) from None
    if design.grammar != grammar:
        raise _Bad(f"design is of grammar {design.grammar!r}; expected {grammar!r}")
    for step in design.steps:
        for choice in step.choices:
            for k, v in choice.params:
                if not math.isfinite(v):
                    raise _Bad(
                        f"design: parameter {k} of {step.rule} is {v}; expected a finite number"
                    )
    values = rec.get("values")
    if not isinstance(values, dict):
        raise _Bad("values is not an object; expected {objective: number}")
    if sorted(values) != sorted(names):
        raise _Bad(
            f"values are for {', '.join(map(repr, values)) or 'nothing'}; expected "
            f"{', '.join(map(repr, names))}"
        )
    vals = {k: _finite(values[k], f"value of {k!r}") for k in names}
    violations = rec.get("violations")
    if not isinstance(violations, list) or not all(isinstance(v, str) for v in violations):
        raise _Bad("violations is not a list of strings")
    if "feasible" in rec and rec["feasible"] is not (not violations):
        raise _Bad("feasible disagrees with violations (feasible means no violation)")
    return scored(design, vals, tuple(violations), objectives)
