"""Attribute types of Things: validation on assignment and MJCF formatting.

Every MuJoCo attribute of a Thing is declared with one of these types in the Thing's
``_NEW_MUJOCO_ATTR``. The type converts what a user assigns (lists, tuples, numbers)
into the stored value (floats, numpy arrays, strings), rejects wrong input with an
error naming the Thing and the attribute, and formats the value for MJCF.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from robotwright._names import name_problem
from robotwright.errors import RobotwrightError


class ThingAttributeError(RobotwrightError, ValueError):
    """A value assigned to a Thing attribute has the wrong type, size or range."""


def fmt_float(value: float) -> str:
    """Shortest text that reads back as the same float (``1.0`` -> ``"1"``)."""
    text = repr(value if type(value) is float else float(value))
    if text.endswith(".0"):
        text = text[:-2]
    return "0" if text == "-0" else text


def _where(owner: Any, name: str) -> str:
    label = getattr(owner, "_label", None)
    who = label() if callable(label) else repr(owner)
    return f"{who}.{name}"


class AttrType:
    """Base attribute type. ``convert`` validates; ``format`` writes MJCF text."""

    def convert(self, value: Any, owner: Any, name: str) -> Any:
        return value

    def format(self, value: Any) -> str:
        return str(value)

    def equal(self, a: Any, b: Any) -> bool:
        return bool(a == b)

    def fail(self, owner: Any, name: str, value: Any, expected: str) -> ThingAttributeError:
        return ThingAttributeError(f"{_where(owner, name)}: got {value!r}, expected {expected}")


class Real(AttrType):
    """A float; ``nonneg`` rejects negative values. ``optional`` allows None (unset)."""

    def __init__(self, nonneg: bool = False, optional: bool = False) -> None:
        self.nonneg = nonneg
        self.optional = optional

    def convert(self, value: Any, owner: Any, name: str) -> Any:
        if value is None and self.optional:
            return None
        if isinstance(value, bool) or not isinstance(value, (int, float, np.number)):
            raise self.fail(owner, name, value, "a number")
        out = float(value)
        if np.isnan(out):
            raise self.fail(owner, name, value, "a number, not NaN")
        if self.nonneg and out < 0:
            raise self.fail(owner, name, value, "a number >= 0")
        return out

    def format(self, value: Any) -> str:
        return fmt_float(value)

    def equal(self, a: Any, b: Any) -> bool:
        if a is None or b is None:
            return a is b
        return float(a) == float(b)


class Integer(AttrType):
    def __init__(self, minimum: int | None = None) -> None:
        self.minimum = minimum

    def convert(self, value: Any, owner: Any, name: str) -> Any:
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
            raise self.fail(owner, name, value, "an integer")
        out = int(value)
        if self.minimum is not None and out < self.minimum:
            raise self.fail(owner, name, value, f"an integer >= {self.minimum}")
        return out


class Flag(AttrType):
    def convert(self, value: Any, owner: Any, name: str) -> Any:
        if not isinstance(value, (bool, np.bool_)):
            raise self.fail(owner, name, value, "True or False")
        return bool(value)

    def format(self, value: Any) -> str:
        return "true" if value else "false"


class Text(AttrType):
    def __init__(self, optional: bool = True) -> None:
        self.optional = optional

    def convert(self, value: Any, owner: Any, name: str) -> Any:
        if value is None and self.optional:
            return None
        if not isinstance(value, str):
            raise self.fail(owner, name, value, "a string")
        return value


class Choice(AttrType):
    """One keyword out of a fixed set (MJCF keyword attributes such as ``limited``)."""

    def __init__(self, *choices: str, optional: bool = False) -> None:
        self.choices = choices
        self.optional = optional

    def convert(self, value: Any, owner: Any, name: str) -> Any:
        if value is None and self.optional:
            return None
        if value not in self.choices:
            raise self.fail(owner, name, value, f"one of {', '.join(self.choices)}")
        return value


class Vector(AttrType):
    """A float vector of fixed ``size`` (or any size when None).

    ``nonneg`` rejects negative entries; ``ordered`` requires ``v[0] <= v[1]`` (ranges);
    ``unit`` normalises a non-zero vector (axes stay as given, quaternions are
    normalised because MuJoCo normalises them at compile time anyway).
    ``trim`` writes trailing zeros beyond ``trim`` entries as omitted (MJCF lets them be).
    """

    def __init__(
        self,
        size: int | None,
        nonneg: bool = False,
        ordered: bool = False,
        nonzero: bool = False,
        optional: bool = False,
        trim: int | None = None,
        integer: bool = False,
    ) -> None:
        self.size = size
        self.nonneg = nonneg
        self.ordered = ordered
        self.nonzero = nonzero
        self.optional = optional
        self.trim = trim
        self.integer = integer

    def convert(self, value: Any, owner: Any, name: str) -> Any:
        if value is None and self.optional:
            return None
        if self.trim is not None and isinstance(value, (int, float, np.number)):
            value = [value]
        if isinstance(value, (str, bytes)) or not isinstance(value, (Sequence, np.ndarray)):
            raise self.fail(owner, name, value, self._expect())
        try:
            arr = np.array(value, dtype=int if self.integer else float).reshape(-1)
        except (TypeError, ValueError):
            raise self.fail(owner, name, value, self._expect()) from None
        if self.trim is not None and self.size is not None and 0 < arr.size < self.size:
            # MJCF pads short parameter vectors with zeros; so do we.
            arr = np.concatenate([arr, np.zeros(self.size - arr.size, dtype=arr.dtype)])
        if self.size is not None and arr.size != self.size:
            raise self.fail(owner, name, value, self._expect())
        if not self.integer and np.isnan(arr).any():
            raise self.fail(owner, name, value, "numbers, not NaN")
        if self.nonneg and (arr < 0).any():
            raise self.fail(owner, name, value, "non-negative entries (sizes cannot be negative)")
        if self.ordered and arr.size >= 2 and arr[0] > arr[1]:
            raise self.fail(owner, name, value, "a range with lower <= upper")
        if self.nonzero and not arr.any():
            raise self.fail(owner, name, value, "a non-zero vector")
        # Read-only, so that in-place edits cannot bypass validation and rebuilds.
        arr.flags.writeable = False
        return arr

    def _expect(self) -> str:
        kind = "integers" if self.integer else "numbers"
        if self.size and self.trim is not None:
            return f"a sequence of {self.trim} to {self.size} {kind}"
        return f"a sequence of {self.size} {kind}" if self.size else f"a sequence of {kind}"

    def format(self, value: Any) -> str:
        vals = list(value)
        if self.trim is not None:
            while len(vals) > self.trim and vals[-1] == 0:
                vals.pop()
        if self.integer:
            return " ".join(str(int(v)) for v in vals)
        return " ".join(map(fmt_float, np.asarray(vals, dtype=float).tolist()))

    def equal(self, a: Any, b: Any) -> bool:
        if a is None or b is None:
            return a is b
        if a.shape != b.shape:
            return False
        # Small vectors: comparing Python lists is much cheaper than numpy calls.
        return bool(a.tolist() == b.tolist())


class Ref(AttrType):
    """A reference to another element: a name string or the referenced Thing itself."""

    def __init__(self, kind: type | tuple[type, ...] | None = None) -> None:
        self.kind = kind

    def convert(self, value: Any, owner: Any, name: str) -> Any:
        if value is None:
            return value
        if isinstance(value, str):
            problem = name_problem(value)
            if problem is not None:
                raise self.fail(owner, name, value, f"a name (this one {problem})")
            return value
        if self.kind is None and hasattr(value, "_NAMESPACE") and hasattr(value, "ID"):
            return value
        if self.kind is not None and isinstance(value, self.kind):
            return value
        raise self.fail(owner, name, value, "a name or a Thing of the right kind")

    def format(self, value: Any) -> str:
        return value if isinstance(value, str) else value.name

    def equal(self, a: Any, b: Any) -> bool:
        return a is b if not isinstance(a, str) else a == b


class Extras(AttrType):
    """A dict of Python-side data a Thing carries (copied deeply, never written to MJCF)."""

    def convert(self, value: Any, owner: Any, name: str) -> Any:
        if not isinstance(value, dict):
            raise self.fail(owner, name, value, "a dict")
        return value
