"""Numbers read from a file or given by a user, checked against a range with both ends.

Every number an input gives has a type and a range with an upper bound, checked before
anything is allocated or run with it: a task file's ``samples: 1e12`` or a 400-digit
integer is refused with one line naming the range, never handed to numpy or to a loop.
Schemas (task files, grammar libraries) describe each field with a :class:`Bound`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

__all__ = ["Bound", "finite_number"]


def finite_number(value: Any) -> float | None:
    """``value`` as a float when it is a finite number: not a bool, NaN or infinity, and
    not an integer beyond float range (which ``float()`` would refuse with a traceback)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    try:
        x = float(value)
    except OverflowError:
        return None
    return x if math.isfinite(x) else None


@dataclass(frozen=True)
class Bound:
    """A field's type and range: ``low <= x <= high`` (``low < x`` with ``open_low``).

    Attributes:
        low, high: the range's ends, in ``unit``.
        integer: a whole number is expected (YAML's ``32``, not ``32.0``).
        unit: shown after the range in messages ("s", "m", "kg"; "" for none).
        open_low: the low end itself is refused (a duration of 0 s).
    """

    low: float
    high: float
    integer: bool = False
    unit: str = ""
    open_low: bool = False

    def describe(self) -> str:
        """The type and range: ``a whole number in [0, 10000] poses``."""
        kind = "a whole number" if self.integer else "a finite number"
        left = "(" if self.open_low else "["
        unit = f" {self.unit}" if self.unit else ""
        return f"{kind} in {left}{self.low:g}, {self.high:g}]{unit}"

    def expected(self) -> str:
        """What the field expects, as a message says it."""
        return f"expected {self.describe()}"

    def check(self, value: Any) -> int | float | None:
        """``value`` when it has the type and lies in the range, else ``None`` (the caller
        reports :meth:`expected`)."""
        if self.integer:
            if isinstance(value, bool) or not isinstance(value, int):
                return None
            if not self.low <= value <= self.high or (self.open_low and value == self.low):
                return None
            return value
        x = finite_number(value)
        if x is None or not self.low <= x <= self.high or (self.open_low and x == self.low):
            return None
        return x
