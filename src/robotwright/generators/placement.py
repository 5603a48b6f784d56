"""Where a robot goes in a composite scene: a pose in the world or on another robot."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TypeVar

from robotwright.errors import GeneratorError

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]
G = TypeVar("G")


@dataclass(frozen=True)
class Placement:
    """Pose of a robot in a composite.

    Attributes:
        pos: position (m) of the robot's frame in the world, or in ``frame`` when attached.
        yaw: rotation (rad) about the world z axis (or ``frame``'s z axis when attached).
        parent: key of another robot of the composite to attach to, or ``None`` (world).
        frame: name (unprefixed) of a site or body of ``parent`` to attach at; the robot's
            root is welded there (its free joint, if any, is dropped).
        orientation: a full orientation (w, x, y, z) instead of ``yaw`` (normalised).
    """

    pos: Vec3 = (0.0, 0.0, 0.0)
    yaw: float = 0.0
    parent: str | None = None
    frame: str | None = None
    orientation: Quat | None = None

    def __post_init__(self) -> None:
        if len(self.pos) != 3 or not all(math.isfinite(float(v)) for v in self.pos):
            raise GeneratorError(f"Placement.pos {self.pos!r}: expected 3 finite numbers (m)")
        if not math.isfinite(float(self.yaw)):
            raise GeneratorError(f"Placement.yaw {self.yaw!r}: expected a finite angle (rad)")
        if (self.parent is None) != (self.frame is None):
            raise GeneratorError(
                f"Placement(parent={self.parent!r}, frame={self.frame!r}): give both the robot "
                "and the site/body to attach at, or neither"
            )
        object.__setattr__(self, "pos", tuple(float(v) for v in self.pos))
        object.__setattr__(self, "yaw", float(self.yaw))
        if self.orientation is not None:
            q = tuple(float(v) for v in self.orientation)
            norm = math.sqrt(sum(v * v for v in q)) if len(q) == 4 else 0.0
            if len(q) != 4 or not math.isfinite(norm) or norm == 0.0:
                raise GeneratorError(
                    f"Placement.orientation {self.orientation!r}: expected a non-zero "
                    "quaternion (w, x, y, z)"
                )
            if self.yaw != 0.0:
                raise GeneratorError("Placement: give yaw or orientation, not both")
            object.__setattr__(self, "orientation", tuple(v / norm for v in q))

    @property
    def quat(self) -> Quat:
        """The orientation as a quaternion (w, x, y, z): ``orientation``, else the yaw."""
        if self.orientation is not None:
            return self.orientation
        if self.yaw == 0.0:
            return (1.0, 0.0, 0.0, 0.0)
        return (math.cos(self.yaw / 2), 0.0, 0.0, math.sin(self.yaw / 2))

    @classmethod
    def parse(cls, text: str) -> Placement:
        """``"x,y,z"`` or ``"x,y,z,yaw"`` (metres, radians) -> Placement."""
        parts = [p for p in text.split(",") if p.strip()]
        try:
            values = [float(p) for p in parts]
        except ValueError:
            values = []
        if len(values) not in (3, 4):
            raise GeneratorError(f"placement '{text}': expected x,y,z or x,y,z,yaw (m, rad)")
        return cls(
            pos=(values[0], values[1], values[2]), yaw=values[3] if len(values) == 4 else 0.0
        )


def composite_members(
    owner: str,
    generators: Mapping[str, G] | Sequence[G],
    placements: Mapping[str, Placement | Sequence[float]] | None,
    kind: type,
    expected: str,
) -> tuple[dict[str, G], dict[str, Placement]]:
    """The robots of composite ``owner`` keyed (a sequence is keyed ``generator0``, ...)
    and their placements (``(x, y, z[, yaw])`` tuples become :class:`Placement`), checked:
    at least one robot, each an instance of ``kind`` (else "expected ``expected``"), and
    every placement and attachment parent naming one of the robots."""
    if isinstance(generators, Mapping):
        gens = dict(generators)
    else:
        gens = {f"generator{i}": g for i, g in enumerate(generators)}
    if not gens:
        raise GeneratorError(f"{owner}: no generators given")
    for key, gen in gens.items():
        if not isinstance(gen, kind):
            raise GeneratorError(
                f"{owner}: generator '{key}' is a {type(gen).__name__}, expected {expected}"
            )
    placed: dict[str, Placement] = {}
    for key, value in (placements or {}).items():
        if key not in gens:
            raise GeneratorError(f"placement for unknown robot '{key}'; robots: {list(gens)}")
        if isinstance(value, Placement):
            placed[key] = value
        else:
            v = [float(x) for x in value]
            if len(v) not in (3, 4):
                raise GeneratorError(f"placement of '{key}': expected (x, y, z[, yaw])")
            placed[key] = Placement(pos=(v[0], v[1], v[2]), yaw=v[3] if len(v) == 4 else 0.0)
    for key, p in placed.items():
        if p.parent is not None and p.parent not in gens:
            raise GeneratorError(
                f"robot '{key}' is attached to unknown robot '{p.parent}'; robots: {list(gens)}"
            )
    return gens, placed


def qmul(a: tuple[float, ...], b: tuple[float, ...]) -> Quat:
    """Quaternion product ``a * b`` (w, x, y, z)."""
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


def qrot(q: tuple[float, ...], v: tuple[float, ...]) -> Vec3:
    """Vector ``v`` rotated by unit quaternion ``q``."""
    w, x, y, z = q
    if (x, y, z) == (0.0, 0.0, 0.0):
        return (float(v[0]), float(v[1]), float(v[2]))
    # v + 2w (u x v) + 2 u x (u x v), u = (x, y, z)
    cx = y * v[2] - z * v[1]
    cy = z * v[0] - x * v[2]
    cz = x * v[1] - y * v[0]
    return (
        v[0] + 2 * (w * cx + y * cz - z * cy),
        v[1] + 2 * (w * cy + z * cx - x * cz),
        v[2] + 2 * (w * cz + x * cy - y * cx),
    )


def compose(
    pos: tuple[float, ...],
    quat: tuple[float, ...],
    child_pos: tuple[float, ...],
    child_quat: tuple[float, ...],
) -> tuple[Vec3, Quat]:
    """Pose ``(pos, quat) * (child_pos, child_quat)``."""
    r = qrot(quat, child_pos)
    return (pos[0] + r[0], pos[1] + r[1], pos[2] + r[2]), qmul(quat, child_quat)
