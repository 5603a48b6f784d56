"""What the HRDF checks share: tolerances, MuJoCo's smallest value, and the checks of a
quaternion, of duplicate names and of a reversed range."""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Iterable, Sequence

from robotwright.errors import Problem

QUAT_NORM_TOL = 1e-4

INERTIA_TRIANGLE_RTOL = 1e-9

AXIS_NORM_MIN = 1e-9

#: MuJoCo's smallest mass or principal inertia of a moving body (``mjMINVAL``).
MJ_MINVAL = 1e-15

#: The per-row checks below start with a quick pass over the row, written as exactly the
#: negation of every check that follows it, so that messages are built only for rows
#: with a problem. Tests turn it off to compare both ways on broken rows.
QUICK_PASS = True

#: size values a simple geom type uses (the others are ignored); 3 for the rest.
_SIZE_USED = {"sphere": 1, "capsule": 2, "cylinder": 2}


def _quat_problem(q: Sequence[float]) -> str | None:
    norm = math.hypot(*q)
    if abs(norm - 1.0) > QUAT_NORM_TOL:
        return f"quaternion {tuple(q)} has norm {norm:.6g}: expected 1 (tolerance {QUAT_NORM_TOL})"
    return None


def _duplicates(names: Iterable[str | None]) -> set[str]:
    counts = Counter(n for n in names if n is not None)
    return {n for n, c in counts.items() if c > 1}


def _reversed_range(
    table: str, column: str, bounds: Sequence[float] | None, row: int
) -> list[Problem]:
    """The problem of a ``column`` range whose lower bound is above its upper one
    (MuJoCo refuses it), on its ``<column>0`` cell; none for a sound or absent range."""
    if bounds is not None and bounds[0] > bounds[1]:
        message = f"{column} lower {bounds[0]} > upper {bounds[1]}"
        return [Problem(table, message, row=row, column=f"{column}0")]
    return []
