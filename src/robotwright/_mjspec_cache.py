"""MuJoCo's parse of an MJCF text, made once per text: the export's own compile check and
its proof read the same generated MJCF, and MuJoCo's parse costs as the bodies squared
(each body added rebuilds its lists of the whole tree: MuJoCo 3.12 takes 7-10 s for a
3,000-link tree, 4.0 about 1 s), where a copy of the parsed spec costs 0.02 s.

Only a text read without files (:meth:`mujoco.MjSpec.from_string` without assets: our
generated MJCF names every mesh by its absolute path, read at compile) is kept; the
spec handed out is always a copy, which the caller may change and compile.
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import mujoco

#: Texts whose parse is kept (the check's and the proof's; a convert has two models).
_KEPT = 2
_parsed: OrderedDict[str, mujoco.MjSpec] = OrderedDict()
_lock = threading.Lock()


def parsed_spec(xml: str) -> mujoco.MjSpec:
    """A copy of MuJoCo's parse of ``xml`` (parsed on its first call; the last
    :data:`_KEPT` texts kept).

    Raises:
        ValueError: MuJoCo refuses the text (nothing is kept).
    """
    import mujoco

    with _lock:  # copies are made under it: no thread copies a spec being dropped
        spec = _parsed.get(xml)
        if spec is not None:
            _parsed.move_to_end(xml)
            return spec.copy()
    spec = mujoco.MjSpec.from_string(xml)  # outside the lock: other threads parse on
    with _lock:
        _parsed[xml] = spec
        while len(_parsed) > _KEPT:
            _parsed.popitem(last=False)
        return spec.copy()


def forget() -> None:
    """Drop every parse kept (a benchmark timing each command as its own process
    would)."""
    with _lock:
        _parsed.clear()
