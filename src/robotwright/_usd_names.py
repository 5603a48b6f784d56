"""What a USD file calls its prims, as the robot's own names, and which prims Newton
merged into one multi-axis joint. Shared by the USD reader and the USD export's proof.

mujoco-usd-converter gives a prim a valid identifier (``robot0:forearm`` becomes
``tn__robot0forearm_hP``) and keeps the name as written in the prim's ``displayName``;
Newton labels bodies and joints by prim path. Newton merges the single-axis joints
authored between the same two bodies (MuJoCo's several hinges on one body) into one D6
joint whose degrees of freedom are the linear joints first, then the angular ones, each
in the order Newton met them.

Needs usd-core (``pxr``) at call time; importing this module needs nothing.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from robotwright._usd_format import prim_name

__all__ = ["display_names", "joint_dof_prims", "name_of"]


def display_names(stage: Any) -> dict[str, str]:
    """Prim path -> the name a user wrote: the prim's ``displayName`` where one is
    authored, else the prim's own name."""
    out: dict[str, str] = {}
    for prim in stage.Traverse():
        shown = prim.GetDisplayName() if prim.HasAuthoredDisplayName() else ""
        out[str(prim.GetPath())] = shown or prim.GetName()
    return out


def name_of(names: Mapping[str, str], label: str) -> str:
    """The robot's name of the prim Newton labels ``label`` (a prim path)."""
    return names.get(label) or prim_name(label)


def joint_dof_prims(path_joint_map: Mapping[str, int], stage: Any) -> dict[int, list[str]]:
    """Newton joint index -> the joint prim behind each of its degrees of freedom, in
    Newton's order (``path_joint_map`` as ``ModelBuilder.add_usd`` returns it).

    A joint read from one prim has that prim alone; a D6 joint Newton merged from
    several single-axis prims lists them linear (prismatic) first, then angular, each in
    the order of the map.
    """
    from pxr import UsdPhysics

    grouped: dict[int, list[str]] = {}
    for path, index in path_joint_map.items():
        grouped.setdefault(int(index), []).append(str(path))
    # A stable sort: the linear axes keep their order, then the angular ones theirs.
    return {
        index: sorted(paths, key=lambda p: stage.GetPrimAtPath(p).IsA(UsdPhysics.RevoluteJoint))
        if len(paths) > 1
        else paths
        for index, paths in grouped.items()
    }
