"""Pictures of limbs: a matplotlib 3D drawing of links, joint axes and tool points.

Poses come from MuJoCo's forward kinematics of the limb (positions in metres, in the
mount frame). Hinge axes are red arrows, slide axes blue arrows, tool points red dots;
cylinders are drawn as thick segments and boxes as outlines.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only; never open a window

import matplotlib.pyplot as plt  # noqa: E402
import mujoco  # noqa: E402
import numpy as np  # noqa: E402

from robotwright._atomic import atomic_open  # noqa: E402
from robotwright.grammar.build import Limb  # noqa: E402


def display_pose(limb: Limb, angle: float = 0.5) -> np.ndarray:
    """A pose that shows the structure: hinges at +-``angle`` rad (alternating, within
    limits), slides at mid-stroke."""
    q = []
    for i, j in enumerate(limb.joints):
        lo, hi = j.range
        v = angle * (-1) ** i if j.type == "hinge" else (lo + hi) / 2
        q.append(min(max(v, lo), hi))
    return np.array(q)


def draw_limb(
    limb: Limb,
    path: str | Path,
    *,
    q: Sequence[float] | None = None,
    title: str | None = None,
    dpi: int = 100,
) -> Path:
    """Write a PNG drawing of ``limb`` at joint values ``q`` (default: zero pose).

    The file is written atomically; returns its path.
    """
    path = Path(path)
    model = limb.to_spec().compile()
    data = mujoco.MjData(model)
    qv = np.zeros(model.nq) if q is None else np.asarray(q, dtype=float)
    if qv.shape != (model.nq,):
        raise ValueError(f"q has shape {qv.shape}; expected ({model.nq},)")
    for j, v in zip(limb.joints, qv):
        data.joint(j.name).qpos[0] = v
    mujoco.mj_kinematics(model, data)
    fig = plt.figure(figsize=(5, 5))
    ax = fig.add_subplot(projection="3d")
    pts = [np.zeros(3)]
    for gid in range(model.ngeom):
        c = data.geom_xpos[gid]
        R = data.geom_xmat[gid].reshape(3, 3)
        size = model.geom_size[gid]
        rgba = model.geom_rgba[gid]
        if model.geom_type[gid] == mujoco.mjtGeom.mjGEOM_CYLINDER:
            half = R[:, 2] * size[1]
            seg = np.array([c - half, c + half])
            ax.plot(
                *seg.T, color=rgba[:3], linewidth=max(1.0, 200 * size[0]), solid_capstyle="butt"
            )
            pts += list(seg)
        elif model.geom_type[gid] == mujoco.mjtGeom.mjGEOM_BOX:
            corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
            world = (corners * size) @ R.T + c
            for i in range(8):
                for k in range(i + 1, 8):
                    if np.sum(corners[i] != corners[k]) == 1:
                        ax.plot(*world[[i, k]].T, color=rgba[:3], linewidth=1.5)
            pts += list(world)
    scale = max(0.05, 0.15 * float(np.ptp(np.array(pts), axis=0).max()))
    for jid in range(model.njnt):
        p, a = data.xanchor[jid], data.xaxis[jid]
        color = "red" if model.jnt_type[jid] == mujoco.mjtJoint.mjJNT_HINGE else "blue"
        ax.quiver(*p, *(a * scale), color=color, linewidth=2, arrow_length_ratio=0.25)
        ax.text(*(p + a * scale * 1.1), model.joint(jid).name, fontsize=7)
    for sid in range(model.nsite):
        p = data.site_xpos[sid]
        ax.scatter(
            *p, color="red" if model.site(sid).name.startswith(("tcp", "tip")) else "black", s=25
        )
        pts.append(p)
    P = np.array(pts)
    center = (P.max(axis=0) + P.min(axis=0)) / 2
    half = max(0.05, float(np.ptp(P, axis=0).max()) / 2 * 1.1)
    ax.set_xlim(center[0] - half, center[0] + half)
    ax.set_ylim(center[1] - half, center[1] + half)
    ax.set_zlim(center[2] - half, center[2] + half)
    ax.set_box_aspect((1, 1, 1))
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    ax.set_title(title or f"{limb.name}: {limb.dof} DoF, design {limb.design.hash()}", fontsize=9)
    path.parent.mkdir(parents=True, exist_ok=True)
    try:
        with atomic_open(path, "wb") as fh:
            fig.savefig(fh, format="png", dpi=dpi)
    finally:
        plt.close(fig)
    return path
