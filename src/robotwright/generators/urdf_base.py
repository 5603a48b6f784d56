"""``URDFGeneratorBase``: URDF output (a flat list of links and joints)."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from functools import lru_cache
from typing import Any

from robotwright.generators.base import GeneratorBase

Quat = tuple[float, float, float, float]
Vec3 = tuple[float, float, float]

#: Name of the fixed world link every generated URDF starts from.
WORLD_LINK = "world"


def quat_to_matrix(q: Quat) -> list[list[float]]:
    """Rotation matrix of a unit quaternion (w, x, y, z)."""
    w, x, y, z = q
    n = math.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = w / n, x / n, y / n, z / n
    return [
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ]


def rotate(q: Quat, v: Vec3) -> Vec3:
    """``v`` rotated by quaternion ``q``."""
    if q == (1.0, 0.0, 0.0, 0.0):
        return (float(v[0]), float(v[1]), float(v[2]))
    r = quat_to_matrix(q)
    return (
        r[0][0] * v[0] + r[0][1] * v[1] + r[0][2] * v[2],
        r[1][0] * v[0] + r[1][1] * v[1] + r[1][2] * v[2],
        r[2][0] * v[0] + r[2][1] * v[1] + r[2][2] * v[2],
    )


@lru_cache(maxsize=4096)
def quat_to_rpy(q: Quat) -> Vec3:
    """URDF roll-pitch-yaw (fixed axes X, Y, Z: R = Rz(yaw) Ry(pitch) Rx(roll)), radians."""
    if q == (1.0, 0.0, 0.0, 0.0):
        return (0.0, 0.0, 0.0)
    r = quat_to_matrix(q)
    sp = -r[2][0]
    if abs(sp) >= 1.0 - 1e-12:
        # Gimbal lock: roll and yaw share one axis; put it all in yaw.
        pitch = math.copysign(math.pi / 2, sp)
        return (0.0, pitch, math.atan2(-r[0][1], r[1][1]))
    return (math.atan2(r[2][1], r[2][2]), math.asin(sp), math.atan2(r[1][0], r[0][0]))


@lru_cache(maxsize=4096)
def inertia_tensor(diag: Vec3, q: Quat) -> tuple[float, float, float, float, float, float]:
    """Full inertia tensor ``R diag(I) R^T`` of principal moments ``diag`` in frame ``q``,
    as URDF's ``(ixx, ixy, ixz, iyy, iyz, izz)``.

    Moments on the edge of the triangle inequality (``A + B == C``, a rod, a flat plate:
    common in musculoskeletal models) come back from a reader's diagonalisation of the
    rotated tensor as ``A + B < C`` by rounding (~1e-18), which MuJoCo refuses. Such a
    tensor gets ``1e-14 * max(diag)`` added on its diagonal (each moment raised by that
    much), so that it stays physical through any reader's rounding.
    """
    r = quat_to_matrix(q)
    a, b, c = diag
    big = max(a, b, c)
    rotated = any(abs(r[i][j]) not in (0.0, 1.0) for i in range(3) for j in range(3))
    pad = 0.0
    if rotated and min(a + b - c, b + c - a, c + a - b) <= _EDGE_RTOL * big:
        pad = _PAD_RTOL * big

    def e(i: int, j: int) -> float:
        return (
            r[i][0] * a * r[j][0]
            + r[i][1] * b * r[j][1]
            + r[i][2] * c * r[j][2]
            + (pad if i == j else 0.0)
        )

    return (e(0, 0), e(0, 1), e(0, 2), e(1, 1), e(1, 2), e(2, 2))


#: Triangle slack (relative) below which a rotated tensor is padded, and the padding.
_EDGE_RTOL = 1e-12
_PAD_RTOL = 1e-14


class URDFGeneratorBase(GeneratorBase):
    """Base of URDF generators: a ``<robot name>`` root holding links and joints."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)

    def _robot_name(self) -> str:
        return "robot"

    def _xml_root_init(self) -> ET.Element:
        return ET.Element("robot", {"name": self._robot_name()})

    @staticmethod
    def mujoco_compiler_attrs() -> dict[str, str]:
        """The ``<mujoco><compiler>`` attributes that make MuJoCo load the URDF as written:
        mesh paths kept (``strippath``), visual geoms kept, fixed links kept as bodies, and
        no inertia changed."""
        return {
            "angle": "radian",
            "strippath": "false",
            "discardvisual": "false",
            "fusestatic": "false",
            "balanceinertia": "false",
        }
