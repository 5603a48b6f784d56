"""Pictures of limbs: a matplotlib 3D drawing of links, joint axes and tool points.

Drawn at the zero pose in the mount frame (m). Hinge axes are red arrows, slide axes
blue arrows, tool points red dots; each geom is drawn as a segment (cylinders) or a
box outline.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only; never open a window

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from robotwright.grammar.build import Limb  # noqa: E402


def _quat_to_mat(q) -> np.ndarray:
    w, x, y, z = q
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def draw_limb(limb: Limb, path: str | Path, *, title: str | None = None, dpi: int = 100) -> Path:
    """Write a PNG drawing of ``limb`` at its zero pose; returns the path (atomic write)."""
    path = Path(path)
    fig = plt.figure(figsize=(5, 5))
    ax = fig.add_subplot(projection="3d")
    pts = [np.zeros(3)]
    for body in limb.bodies:
        F = body.frame
        for g in body.geoms:
            R = F[:3, :3] @ _quat_to_mat(g.quat)
            c = F[:3, :3] @ np.asarray(g.pos) + F[:3, 3]
            if g.type == "cylinder":
                half = R[:, 2] * g.size[1]
                seg = np.array([c - half, c + half])
                width = max(1.0, 200 * g.size[0])
                ax.plot(*seg.T, color=g.rgba[:3], linewidth=width, solid_capstyle="butt")
                pts += list(seg)
            elif g.type == "box":
                corners = (
                    np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
                    * g.size
                )
                world = corners @ R.T + c
                for i in range(8):
                    for j in range(i + 1, 8):
                        if np.sum(corners[i] != corners[j]) == 1:
                            ax.plot(*world[[i, j]].T, color=g.rgba[:3], linewidth=1.5)
                pts += list(world)
    scale = max(0.05, 0.15 * float(np.ptp(np.array(pts), axis=0).max()))
    names = {b.name: b for b in limb.bodies}
    for j in limb.joints:
        F = names[j.body].frame
        p = F[:3, :3] @ np.asarray(j.pos) + F[:3, 3]
        a = F[:3, :3] @ np.asarray(j.axis)
        color = "red" if j.type == "hinge" else "blue"
        ax.quiver(*p, *(a * scale), color=color, linewidth=2, arrow_length_ratio=0.25)
        ax.text(*(p + a * scale * 1.1), j.name, fontsize=7)
    for s in limb.sites:
        F = names[s.body].frame
        p = F[:3, :3] @ np.asarray(s.pos) + F[:3, 3]
        ax.scatter(*p, color="red" if "tcp" in s.name else "black", s=25)
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
    fd, tmp = tempfile.mkstemp(suffix=".png", dir=path.parent)
    os.close(fd)
    try:
        fig.savefig(tmp, dpi=dpi)
        os.replace(tmp, path)
    finally:
        plt.close(fig)
        if os.path.exists(tmp):
            os.unlink(tmp)
    return path
