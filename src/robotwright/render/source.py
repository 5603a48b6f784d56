"""What ``robotwright render`` draws: any source the viewer takes, as a compiled model.

Sources are loaded by :func:`robotwright.scene.load.load_source` (one loader for the
viewer and the pictures): a bundled robot name (or one under
``$HURODES_ASSETS_PATH``), an HRDF folder, an MJCF file (a robot, or a scene written by
``robotwright compose`` or the demo), a URDF file, a grammar design folder, or a scan
``.npz`` with the MJCF scene it was taken in. Robots go through the project's readers
and MJCF generator, an MJCF file is compiled by MuJoCo after the project's safety
checks (no XML entities; every file it names inside its folder or a trusted one).
"""

from __future__ import annotations

import os
import warnings
from dataclasses import dataclass, field

import mujoco
import numpy as np

from robotwright.errors import ConversionWarning
from robotwright.scene.load import ScanCloud, ViewError, load_source

__all__ = ["LoadedModel", "SourceError", "load_model"]

#: A source that is of no known kind, unreadable, or refused by MuJoCo (the viewer's
#: error type: both commands read sources the same way).
SourceError = ViewError


@dataclass
class LoadedModel:
    """A compiled model, where it came from, and the scan when the source was one.

    Attributes:
        model: the compiled model.
        title: a short name (robot name or file stem).
        kind: ``"robot"``, ``"mjcf"``, ``"urdf"``, ``"design"`` or ``"scan"``.
        qpos: the pose to draw: keyframe 0 when the model has one (a model's home
            pose, and the pose ``robotwright lidar`` scans in), else ``qpos0``.
        scan: the scan's hit points, for a scan source.
        notes: what the readers reported (conversion notes), one message each.
        warnings: how the model drawn differs from the robot (physics replaced to
            show a robot whose masses or inertias are refused), one line each.
    """

    model: mujoco.MjModel
    title: str
    kind: str
    qpos: np.ndarray
    scan: ScanCloud | None = None
    notes: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)

    def initial_data(self) -> mujoco.MjData:
        """A state in :attr:`qpos` with forward kinematics done."""
        data = mujoco.MjData(self.model)
        data.qpos[:] = self.qpos
        mujoco.mj_forward(self.model, data)
        return data


def load_model(
    source: str | os.PathLike[str],
    *,
    scene: str | os.PathLike[str] | None = None,
    asset_roots: tuple[str | os.PathLike[str], ...] = (),
) -> LoadedModel:
    """Load ``source`` (see the module docstring); ``scene`` is the MJCF scene of a
    scan ``.npz``. The readers' conversion notes are also issued again as
    :class:`~robotwright.errors.ConversionWarning` (the command line counts them).

    Raises:
        SourceError: unknown kind of source, unreadable scan, MuJoCo refuses the MJCF.
        RobotwrightError: what the readers raise for bad input (naming file and field).
    """
    loaded = load_source(source, scene=scene, asset_roots=asset_roots)
    for note in loaded.notes:
        warnings.warn(note, ConversionWarning, stacklevel=2)
    return LoadedModel(
        loaded.model,
        loaded.title,
        loaded.kind,
        loaded.initial_qpos(),
        loaded.scan,
        list(loaded.notes),
        list(loaded.warnings),
    )
