"""A picture of the seed's task: the robot among its labelled objects, its scan drawn in
the scene coloured by class, from any framework's state.

The framework gives what it simulated (the robot's MJCF, its base pose and joint
positions, each object's asset and pose, the scan's world points and labels); MuJoCo
draws it (:func:`robotwright.render.scan.render_scan`) on a ground plane at z = 0. The
same drawing therefore shows an mjlab state and an Isaac Lab state alike.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import mujoco
import numpy as np

from robotwright.sensors.semantic_scene import SceneAssetCfg

__all__ = ["draw_nav_scene"]


def draw_nav_scene(
    robot_xml: str,
    root_pose: Sequence[float],
    joint_pos: Mapping[str, float],
    objects: Sequence[tuple[SceneAssetCfg, Sequence[float]]],
    points: np.ndarray,
    labels: np.ndarray,
    class_names: Sequence[str],
    output: str | os.PathLike[str],
    *,
    mapping: Mapping[str, Sequence[str]] | None = None,
    title: str | None = None,
    camera: str = "iso",
    size: tuple[int, int] = (1000, 700),
) -> Path:
    """Write a PNG of the robot (MJCF text ``robot_xml``, one free joint) at
    ``root_pose`` (x, y, z [m], quaternion w, x, y, z; world) with ``joint_pos``
    (joint name -> [rad] or [m]), each object (asset, pose as ``root_pose``), and the
    scan's ``points`` ``(N, 3)`` [m] (NaN rows: misses) coloured by ``labels``."""
    from robotwright.render.core import RenderOptions
    from robotwright.render.scan import render_scan

    spec = mujoco.MjSpec.from_string(robot_xml)
    spec.worldbody.add_geom(
        name="ground", type=mujoco.mjtGeom.mjGEOM_PLANE, size=(0, 0, 1), rgba=(0.8, 0.8, 0.8, 1)
    )
    for i, (asset, pose) in enumerate(objects):
        body = spec.worldbody.add_body(name=f"object_{i}", pos=pose[:3], quat=pose[3:7])
        asset.add_geom(body)
    model = spec.compile()
    data = mujoco.MjData(model)
    free = next(j for j in range(model.njnt) if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE)
    adr = model.jnt_qposadr[free]
    data.qpos[adr : adr + 7] = np.asarray(root_pose, dtype=np.float64)[:7]
    for name, q in joint_pos.items():
        data.qpos[model.jnt_qposadr[model.joint(name).id]] = q
    mujoco.mj_forward(model, data)
    if mapping is not None:  # the legend names a class's first keywords, not all
        mapping = {k: [*v[:3], "..."] if len(v) > 3 else list(v) for k, v in mapping.items()}
    options = RenderOptions(width=size[0], height=size[1], camera=camera, point_radius=2.0)
    render_scan(
        model,
        data,
        points,
        labels,
        class_names,
        output,
        options,
        mapping=mapping,
        title=title,
    )
    return Path(output)
