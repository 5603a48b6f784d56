"""The MJCF reader's last compile, kept for the proof of the conversion that follows
(one compile of the source saved): the reader remembers it here, the proof
(:func:`robotwright.proof.models.source_model`) takes it. The reader does not know the
proof; the proof reads this module."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np


def _cacheable_mesh_files(spec: mujoco.MjSpec) -> list[str]:
    """The mesh files of ``spec`` the result may read by the same name (MuJoCo's cache):
    not one read with a ``refpos``/``refquat``, which MuJoCo 3.11 keeps in the cached
    mesh (the result holds that frame in its geoms' poses instead)."""
    return [
        m.file
        for m in spec.meshes
        if not (np.any(m.refpos != 0) or np.any(np.asarray(m.refquat) != [1, 0, 0, 0]))
    ]


#: the last MJCF the parser compiled: (resolved path, size and mtime) -> its model, model
#: folder, mesh folder and mesh file names; taken by :func:`source_model` (one compile
#: of the source saved). At most one is kept.
_PARSED: dict[tuple[str, int, int], tuple[mujoco.MjModel, str, str, list[str]]] = {}


def _stat_key(path: str | Path) -> tuple[str, int, int] | None:
    try:
        st = Path(path).stat()
        return str(Path(path).resolve()), st.st_size, st.st_mtime_ns
    except OSError:
        return None


def remember_parsed(path: str | Path, spec: mujoco.MjSpec, model: mujoco.MjModel) -> None:
    """Keep ``model``, the parser's compile of the MJCF file ``path`` from ``spec``
    (compiled, not changed since), for the proof of the conversion that follows."""
    _PARSED.clear()
    key = _stat_key(path)
    if key is not None:
        files = _cacheable_mesh_files(spec)
        _PARSED[key] = (model, spec.modelfiledir or "", spec.compiler.meshdir or "", files)


def _take_parsed(path: str | Path) -> tuple[mujoco.MjModel, str, str, list[str]] | None:
    key = _stat_key(path)
    return _PARSED.pop(key, None) if key is not None else None
