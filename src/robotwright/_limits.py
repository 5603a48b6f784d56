"""Caps on how much of a model an input file may ask for, checked before MuJoCo
allocates it.

Keyframes: MuJoCo stores every keyframe as a full state (``qpos``, ``qvel``, ``act``,
``ctrl``, mocap poses), so a file of a few megabytes of ``<key/>`` elements, or one
``<size nkey="1000000000"/>``, makes compiling the model allocate gigabytes. A model
may hold at most :data:`MAX_KEYFRAMES` keyframes unless a caller raises the limit for
the current context with :func:`keyframe_limit` (the command line's
``--max-keyframes``).
"""

from __future__ import annotations

import contextlib
import contextvars
import math
from collections.abc import Iterator
from typing import TypeVar

__all__ = ["MAX_KEYFRAMES", "keyframe_limit", "keyframes_problem"]

_T = TypeVar("_T")

#: Most keyframes a model may hold (real robots ship fewer than 100).
MAX_KEYFRAMES = 10_000

_LIMIT: contextvars.ContextVar[int] = contextvars.ContextVar(
    "keyframe_limit", default=MAX_KEYFRAMES
)


@contextlib.contextmanager
def limit_for_block(var: contextvars.ContextVar[_T], value: _T | None) -> Iterator[None]:
    """Within the block, the limit held by context variable ``var`` is ``value``
    (``None``: left as it is); the caller has checked ``value``."""
    if value is None:
        yield
        return
    token = var.set(value)
    try:
        yield
    finally:
        var.reset(token)


def megabytes(mb: float | None, what: str) -> int | None:
    """A limit of ``mb`` megabytes (10**6 bytes) in bytes (``None`` stays ``None``).

    Raises:
        ValueError: ``mb`` is not a positive finite number; the message names the
            limit as ``what``.
    """
    if mb is None:
        return None
    if not 0 < mb < math.inf:
        raise ValueError(f"{what} must be a positive number of MB, got {mb}")
    return round(mb * 10**6)


@contextlib.contextmanager
def keyframe_limit(max_keyframes: int | None) -> Iterator[None]:
    """Within the block, models may hold up to ``max_keyframes`` keyframes (``None``:
    the default, :data:`MAX_KEYFRAMES`)."""
    if max_keyframes is not None and (
        isinstance(max_keyframes, bool) or not isinstance(max_keyframes, int) or max_keyframes < 0
    ):
        raise ValueError(f"max_keyframes: expected an integer >= 0, got {max_keyframes!r}")
    with limit_for_block(_LIMIT, max_keyframes):
        yield


def keyframes_problem(count: int) -> str | None:
    """Why a model asking for ``count`` keyframes is refused, or None."""
    limit = _LIMIT.get()
    if count > limit:
        return (
            f"asks for {count:,} keyframes: at most {limit:,} are allowed "
            "(--max-keyframes raises the limit)"
        )
    return None
