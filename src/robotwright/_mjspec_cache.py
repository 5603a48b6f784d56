"""MuJoCo's parse of an MJCF text, made once per text: the export's own compile check and
its proof read the same generated MJCF, and MuJoCo's parse costs as the bodies squared
(each body added rebuilds its lists of the whole tree: MuJoCo 3.12 takes 7-10 s for a
3,000-link tree, 4.0 about 1 s), where a copy of the parsed spec costs 0.02 s.

A parse is kept only once it has compiled: ``MjSpec.copy`` drops what refers to
something the model does not have (a sensor of a missing joint compiles in a copy, and
not in the parse), so a copy stands for a new parse only of a model MuJoCo accepts.
Only texts read without files are kept (:meth:`mujoco.MjSpec.from_string` without
assets: our generated MJCF names every mesh by its path, which MuJoCo reads when it
compiles, not when it parses). What a caller gets is always its own spec.
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from collections.abc import Callable
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import mujoco

#: Texts whose parse is kept (the check's and the proof's; a convert has two models).
_KEPT = 2
_parsed: OrderedDict[str, mujoco.MjSpec] = OrderedDict()
_lock = threading.Lock()


def _kept_copy(xml: str) -> mujoco.MjSpec | None:
    """A copy of the kept parse of ``xml``, or None."""
    with _lock:  # copies are made under it: no thread copies a spec being dropped
        spec = _parsed.get(xml)
        if spec is None:
            return None
        _parsed.move_to_end(xml)
        return spec.copy()


def parsed_spec(xml: str) -> mujoco.MjSpec:
    """MuJoCo's parse of ``xml``, the caller's own: a copy of the parse kept (one that
    compiled), else a new parse (kept once :func:`compiled` compiles it).

    Raises:
        ValueError: MuJoCo refuses the text.
    """
    import mujoco

    kept = _kept_copy(xml)
    return kept if kept is not None else mujoco.MjSpec.from_string(xml)


def compiled(xml: str, prepare: Callable[[mujoco.MjSpec], None] | None = None) -> mujoco.MjModel:
    """MuJoCo's compile of ``xml``, from the parse kept or a new one (``prepare``, given
    the caller's spec, changes it first: where meshes are read, visuals dropped); a new
    parse compiled as it is (no ``prepare``: what it holds is then known to resolve) is
    kept when it compiles.

    Raises:
        ValueError: MuJoCo refuses the text or the model (nothing is kept).
    """
    import mujoco

    spec = _kept_copy(xml)
    pristine = None
    if spec is None:
        spec = mujoco.MjSpec.from_string(xml)
        if prepare is None:  # copied before compile changes the spec; kept if it compiles
            pristine = spec.copy()
    if prepare is not None:
        prepare(spec)
    model = spec.compile()
    if pristine is not None:
        with _lock:
            _parsed[xml] = pristine
            while len(_parsed) > _KEPT:
                _parsed.popitem(last=False)
    return model


def forget() -> None:
    """Drop every parse kept (a benchmark timing each command as its own process
    would)."""
    with _lock:
        _parsed.clear()
