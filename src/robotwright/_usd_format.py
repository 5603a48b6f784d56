"""What robotwright's USD writer and reader agree on (no USD library needed)."""

from __future__ import annotations

#: File names of a USD robot, written (``robotwright export``) and read.
USD_SUFFIXES = (".usd", ".usda", ".usdc")

#: Custom attribute on a floating body's prim: its free joint's name, which USD has no
#: prim for (written by the exporter, read back by the reader).
FREE_JOINT_ATTR = "robotwright:freeJointName"


def prim_name(path: str) -> str:
    """The last element of a prim path (Newton's label of a body, joint or shape)."""
    return path.rsplit("/", 1)[-1]
