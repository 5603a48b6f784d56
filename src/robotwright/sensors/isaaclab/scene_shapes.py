"""What a LiDAR makes of a Newton model's shapes: which it sees, and their classes.

Newton labels each shape with its USD prim path, except shapes it makes itself: a
generated terrain that Isaac Lab turns into a height field enters as ``shape_N``.
Those get their prim path back from the stage (the prims Isaac Lab tags
``newton:heightfield:resolution``, in the order Newton adds them), and otherwise the
config's ``terrain_class``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import newton
import numpy as np

from robotwright.sensors.isaaclab.config import ResolvedLidarCfg

__all__ = ["SceneShapes", "scene_shapes", "articulation_bodies", "heightfield_prim_paths"]

HEIGHTFIELD_ATTRIBUTE = "newton:heightfield:resolution"


@dataclass(frozen=True)
class SceneShapes:
    """Per Newton shape (index = shape id), as one LiDAR sees the scene.

    Attributes:
        labels: the shape's prim path (Newton's ``shape_label``, recovered for
            unlabelled height fields where the stage tells).
        collides: the shape is a collision shape (what rays can hit).
        visible: rays stop at it (else they pass through).
        classes: int32 class id a hit on it reads (0 for see-through shapes).
        carrier: the shape belongs to a body carrying the sensor.
        own_robot: the shape belongs to the articulation carrying the sensor.
        unlabelled_terrain: a global shape with no prim path (class ``terrain_class``).
        unmatched_patterns: the ``mesh_prim_paths`` entries that match no collision
            shape (as the user wrote them).
    """

    labels: list[str]
    collides: np.ndarray
    visible: np.ndarray
    classes: np.ndarray
    carrier: np.ndarray
    own_robot: np.ndarray
    unlabelled_terrain: np.ndarray
    unmatched_patterns: tuple[str, ...] = ()


def articulation_bodies(child: np.ndarray, art: np.ndarray, body: int) -> set[int]:
    """Bodies of the articulation holding ``body`` (just ``body`` when it has none), from
    Newton's ``joint_child`` and ``joint_articulation`` arrays."""
    joints = np.flatnonzero(child == body)
    if joints.size == 0 or art[joints[0]] < 0:
        return {int(body)}
    return {int(b) for b in child[art == art[joints[0]]] if b >= 0}


def heightfield_prim_paths() -> list[str]:
    """Prim paths of the terrain meshes Isaac Lab asked Newton to turn into height
    fields, in stage order (empty when there is no stage)."""
    try:
        import isaaclab.sim as sim_utils
        from pxr import Usd, UsdGeom
    except ImportError:  # pragma: no cover - the adapter always has them
        return []
    stage = sim_utils.get_current_stage()
    if stage is None:
        return []
    paths = []
    for prim in stage.Traverse():
        attr = prim.GetAttribute(HEIGHTFIELD_ATTRIBUTE)
        if not attr or not attr.HasAuthoredValue():
            continue
        mesh = prim if prim.IsA(UsdGeom.Mesh) else None
        if mesh is None:
            mesh = next((p for p in Usd.PrimRange(prim) if p.IsA(UsdGeom.Mesh)), None)
        if mesh is not None:
            paths.append(str(mesh.GetPath()))
    return paths


def _ancestors(path: str) -> list[str]:
    parts = path.split("/")
    return ["/".join(parts[:i]) for i in range(2, len(parts) + 1)]


def _recover_labels(
    labels: list[str], shape_world: np.ndarray, shape_type: np.ndarray, found: Sequence[str]
) -> tuple[list[str], np.ndarray]:
    """Give unlabelled global height fields the tagged terrain paths (when the counts
    agree); returns the labels and the mask of global shapes still without a path."""
    out = list(labels)
    unlabelled = np.array(
        [not lb.startswith("/") and w == -1 for lb, w in zip(labels, shape_world)], dtype=bool
    )
    hfields = [s for s in np.flatnonzero(unlabelled) if shape_type[s] == int(newton.GeoType.HFIELD)]
    if hfields and len(hfields) == len(found):
        for s, path in zip(hfields, found):
            out[s] = path
            unlabelled[s] = False
    return out, unlabelled


def scene_shapes(
    model: newton.Model,
    carriers: Sequence[int],
    resolved: ResolvedLidarCfg,
    exclude_parent_body: bool,
    classify: Callable[[str], int],
) -> SceneShapes:
    """Decide, once, what every shape of ``model`` is to the sensor.

    Args:
        model: the finalised Newton model.
        carriers: the body carrying the sensor, per environment.
        resolved: the sensor's checked config.
        exclude_parent_body: the carrier bodies' shapes are see-through.
        classify: class id of a prim path (the mapping's keyword rule).
    """
    n = int(model.shape_count)
    shape_body = model.shape_body.numpy()
    shape_world = model.shape_world.numpy()
    shape_type = model.shape_type.numpy()
    flags = model.shape_flags.numpy()
    collides = (flags & int(newton.ShapeFlags.COLLIDE_SHAPES)) != 0
    labels, unlabelled = _recover_labels(
        list(model.shape_label), shape_world, shape_type, heightfield_prim_paths()
    )
    carrier_bodies = {int(b) for b in carriers if b >= 0}
    robot_bodies: set[int] = set()
    child, art = model.joint_child.numpy(), model.joint_articulation.numpy()
    for b in carrier_bodies:
        robot_bodies |= articulation_bodies(child, art, b)
    carrier = np.isin(shape_body, list(carrier_bodies)) & (shape_body >= 0)
    own = np.isin(shape_body, list(robot_bodies)) & (shape_body >= 0)
    visible = collides.copy()
    matched = [False] * len(resolved.mesh_patterns)
    if resolved.mesh_patterns:
        for s in range(n):
            hits = [
                any(p.fullmatch(a) for a in _ancestors(labels[s])) for p in resolved.mesh_patterns
            ]
            if not any(hits):
                visible[s] = False
            elif collides[s]:
                matched = [m or h for m, h in zip(matched, hits, strict=True)]
    entries = list(resolved.mesh_prim_paths)
    unmatched = tuple(entries[i] for i, m in enumerate(matched) if not m)
    if exclude_parent_body:
        visible &= ~carrier
    if not resolved.self_class_id:
        visible &= ~own
    classes = np.zeros(n, dtype=np.int32)
    for s in np.flatnonzero(visible):
        if own[s] and resolved.self_class_id:
            classes[s] = resolved.self_class_id
        elif unlabelled[s]:
            classes[s] = resolved.terrain_class_id
        else:
            classes[s] = classify(labels[s])
    return SceneShapes(labels, collides, visible, classes, carrier, own, unlabelled, unmatched)
