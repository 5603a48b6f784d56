"""Which of the proof's differences a conversion note already reports, and the others as
:class:`~robotwright.errors.Problem` lines (a few per field, then a count)."""

from __future__ import annotations

import re
from collections.abc import Sequence
from typing import TYPE_CHECKING

from robotwright.errors import Problem
from robotwright.proof.objects import Difference

if TYPE_CHECKING:
    pass


#: MjModel field stem -> the MJCF attribute words a note about it may use.
_ALIASES = {
    "actfrcrange": ("actuatorfrcrange", "actfrcrange"),
    "actfrclimited": ("actuatorfrcrange", "actuatorfrclimited", "actfrclimited"),
    "actgravcomp": ("actuatorgravcomp",),
    "invweight0": ("inertia", "mass"),
    "subtreemass": ("mass",),
    "solref_lim": ("solreflimit", "solref"),
    "solimp_lim": ("solimplimit", "solimp"),
    "solref_fri": ("solreffriction", "solref"),
    "solimp_fri": ("solimpfriction", "solimp"),
    "lengthspring": ("springlength",),
}


# -- notes ----------------------------------------------------------------------------------
def _stem(field: str) -> str:
    return field.split(".", 1)[1] if field.startswith("opt.") else field.split("_", 1)[-1]


def _words(field: str) -> tuple[str, ...]:
    stem = _stem(field)
    return (stem, *_ALIASES.get(stem, ()))


def _mentions(text: str, word: str) -> bool:
    return re.search(rf"(?<![A-Za-z0-9_]){re.escape(word)}(?![A-Za-z0-9_])", text) is not None


def covered(diff: Difference, notes: Sequence[str], absent: set[str] | None = None) -> bool:
    """Whether a conversion note reports ``diff``: for a missing object, a note naming
    it (or naming a body it belongs to that is itself missing); for a value, a note naming
    the object and the field (its MJCF attribute word: ``solref``, ``gravcomp``, ...);
    for an option, a note naming ``<option>`` and the field."""
    named = [n for n in notes if any(lab in n for lab in diff.labels)]
    if diff.field == "(object)":
        return bool(named)
    if diff.family == "opt":
        return any(
            "option" in n and any(_mentions(n, w) for w in _words(diff.field)) for n in notes
        )
    words = _words(diff.field)
    return any(any(_mentions(n, w) for w in words) for n in named)


def uncovered(diffs: Sequence[Difference], notes: Sequence[str]) -> list[Difference]:
    """The differences no note reports (see :func:`covered`); an object whose body is
    missing and reported is reported with it."""
    notes = list(notes)
    missing_bodies = {d.obj for d in diffs if d.field == "(object)" and d.family == "body"}
    reported_bodies = {
        d.obj for d in diffs
        if d.field == "(object)" and d.family == "body" and covered(d, notes)
    }  # fmt: skip
    out = []
    for d in diffs:
        if covered(d, notes):
            continue
        if d.field == "(object)" and d.obj.endswith("'") and " of body '" in d.obj:
            body = "body '" + d.obj.split(" of body '", 1)[1]
            if body in reported_bodies or body in missing_bodies and body in reported_bodies:
                continue
        out.append(d)
    return out


#: how many differences of one field are listed one by one before a count.
LISTED_PER_FIELD = 20


def as_problems(
    file: str, diffs: Sequence[Difference], sides: tuple[str, str] = ("source", "result")
) -> list[Problem]:
    """Conversion notes for differences no note reported: one per object and field (the
    first :data:`LISTED_PER_FIELD` of each field, then one line with the count);
    ``sides`` names the two models compared."""
    out: list[Problem] = []
    per_field: dict[str, int] = {}
    for d in diffs:
        n = per_field.get(d.field, 0)
        per_field[d.field] = n + 1
        if n < LISTED_PER_FIELD:
            what = "the object" if d.field == "(object)" else d.field
            out.append(
                Problem(
                    file,
                    f"proof: {what} differs after conversion: {sides[0]} {d.source}, "
                    f"{sides[1]} {d.result}",
                    element=d.obj,
                    severity="warning",
                )
            )
    for fld, n in per_field.items():
        if n > LISTED_PER_FIELD:
            out.append(
                Problem(
                    file,
                    f"proof: {fld} differs on {n - LISTED_PER_FIELD} more object(s)",
                    severity="warning",
                )
            )
    return out
