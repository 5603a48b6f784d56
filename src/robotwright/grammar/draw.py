"""Pictures of limbs: a matplotlib 3D drawing of links, joint axes and tool points.

Poses come from MuJoCo's forward kinematics of the limb (positions in metres, in the
mount frame). Revolute axes are red arrows, prismatic axes blue arrows, tool points red
dots; cylinders are drawn as thick segments and boxes as outlines. The title lists the
joints by kind (a universal joint is two revolute DoF about crossing axes) and a legend
says what each mark is.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only; never open a window

import matplotlib.pyplot as plt  # noqa: E402
import mujoco  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.ticker import MaxNLocator  # noqa: E402

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


def _kind(types: list[str]) -> str:
    """Name of a joint made of DoF ``types`` (MuJoCo joint types, in order)."""
    if types == ["slide"]:
        return "prismatic"
    if types == ["hinge"]:
        return "revolute"
    if types == ["hinge", "hinge"]:
        return "universal"
    if all(t == "hinge" for t in types):
        return f"{len(types)}-DoF revolute"
    return " + ".join("prismatic" if t == "slide" else "revolute" for t in types)


def _groups(limb: Limb) -> list[list[str]]:
    """Joint names grouped by the connector node they come from, in chain order."""
    groups: dict[int, list[str]] = {}
    for j in limb.joints:
        groups.setdefault(j.node, []).append(j.name)
    return list(groups.values())


def _joint_kinds(limb: Limb) -> dict[str, str]:
    """Joint name -> ``prismatic``, ``revolute`` or ``universal 1/2`` (DoF i of n)."""
    types = {j.name: j.type for j in limb.joints}
    out = {}
    for group in _groups(limb):
        kind = _kind([types[n] for n in group])
        for i, name in enumerate(group, 1):
            out[name] = f"{kind} {i}/{len(group)}" if len(group) > 1 else kind
    return out


def joint_summary(limb: Limb) -> str:
    """The limb's DoF by joint kind, in chain order: ``4 DoF: prismatic, revolute,
    universal (2 DoF)``. Joints of one connector node are one joint of several DoF."""
    types = {j.name: j.type for j in limb.joints}
    kinds = []
    for group in _groups(limb):
        kind = _kind([types[n] for n in group])
        kinds.append(f"{kind} ({len(group)} DoF)" if len(group) > 1 else kind)
    return f"{limb.dof} DoF: {', '.join(kinds)}" if kinds else "0 DoF (rigid)"


def _merge_labels(
    anchors: list[np.ndarray], names: list[str], min_gap: float
) -> list[tuple[np.ndarray, str]]:
    """Labels closer than ``min_gap`` [m] to an earlier one join it (``joint3, joint4``),
    so that no two labels are drawn over each other."""
    merged: list[tuple[np.ndarray, list[str]]] = []
    for p, name in zip(anchors, names):
        for q, group in merged:
            if np.linalg.norm(p - q) < min_gap:
                group.append(name)
                break
        else:
            merged.append((p, [name]))
    return [(p, ", ".join(group)) for p, group in merged]


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
    fig = plt.figure(figsize=(6, 6))
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
    extent = float(np.ptp(np.array(pts), axis=0).max())
    scale = max(0.05, 0.15 * extent)
    tips, names = [], []
    kinds = _joint_kinds(limb)
    for jid in range(model.njnt):
        p, a = data.xanchor[jid], data.xaxis[jid]
        color = "red" if model.jnt_type[jid] == mujoco.mjtJoint.mjJNT_HINGE else "blue"
        ax.quiver(*p, *(a * scale), color=color, linewidth=2, arrow_length_ratio=0.25)
        tips.append(p + a * scale * 1.15)
        name = model.joint(jid).name
        names.append(f"{name} ({kinds[name]})" if name in kinds else name)
    for p, text in _merge_labels(tips, names, 0.12 * max(extent, 0.05)):
        ax.text(*p, text, fontsize=8, bbox={"facecolor": "white", "alpha": 0.6, "pad": 1, "lw": 0})
    # Tool points from the branches' DH chains (the same FK the grammar optimises).
    values = {j.name: float(v) for j, v in zip(limb.joints, qv)}
    tools = False
    for branch in limb.branches:
        pose = branch.tool_pose(np.array([values[n] for n in branch.joints]))
        tip = np.asarray(pose)[:3, 3]
        ax.scatter(*tip, color="red", s=30, depthshade=False)
        pts.append(tip)
        tools = True
    for sid in range(model.nsite):
        p = data.site_xpos[sid]
        tool = model.site(sid).name.startswith(("tcp", "tip"))
        tools |= tool
        ax.scatter(*p, color="red" if tool else "black", s=25)
        pts.append(p)
    P = np.array(pts)
    center = (P.max(axis=0) + P.min(axis=0)) / 2
    half = max(0.05, float(np.ptp(P, axis=0).max()) / 2 * 1.1)
    ax.set_xlim(center[0] - half, center[0] + half)
    ax.set_ylim(center[1] - half, center[1] + half)
    ax.set_zlim(center[2] - half, center[2] + half)
    ax.set_box_aspect((1, 1, 1))
    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
        axis.set_major_locator(MaxNLocator(4))  # few ticks: 3D tick labels crowd
    ax.tick_params(labelsize=8, pad=1)
    ax.set_xlabel("x [m]", fontsize=9, labelpad=2)
    ax.set_ylabel("y [m]", fontsize=9, labelpad=2)
    ax.set_zlabel("z [m]", fontsize=9, labelpad=2)
    heading = title or f"{limb.name}, design {limb.design.hash()}"
    ax.set_title(f"{heading}\n{joint_summary(limb)}", fontsize=9)
    kinds = {int(t) for t in model.jnt_type}
    handles = []
    if int(mujoco.mjtJoint.mjJNT_HINGE) in kinds:
        handles.append(Line2D([], [], color="red", lw=2, label="revolute joint axis"))
    if int(mujoco.mjtJoint.mjJNT_SLIDE) in kinds:
        handles.append(Line2D([], [], color="blue", lw=2, label="prismatic joint axis"))
    if tools:
        handles.append(Line2D([], [], ls="", marker="o", color="red", label="tool point"))
    if model.nsite and not all(
        model.site(i).name.startswith(("tcp", "tip")) for i in range(model.nsite)
    ):
        handles.append(Line2D([], [], ls="", marker="o", color="black", label="site"))
    handles.append(Line2D([], [], color="0.6", lw=4, label="parts (their colours)"))
    fig.legend(handles=handles, loc="lower center", ncol=3, fontsize=8, frameon=False)
    fig.subplots_adjust(left=0.02, right=0.95, bottom=0.1, top=0.9)
    path.parent.mkdir(parents=True, exist_ok=True)
    try:
        with atomic_open(path, "wb") as fh:
            fig.savefig(fh, format="png", dpi=dpi)
    finally:
        plt.close(fig)
    return path
