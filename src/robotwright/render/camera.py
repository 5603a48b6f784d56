"""Where the picture is taken from: a model camera, a named view, or angles.

A camera is given as text (the ``--camera`` option):

- the name of a camera of the model (``<camera name="...">``);
- a named view of MuJoCo's free camera: ``iso`` (front-right, from above; the
  default), ``front`` (from +x, the way robots face), ``back``, ``left``, ``right``,
  ``top``;
- ``AZIMUTH,ELEVATION`` or ``AZIMUTH,ELEVATION,DISTANCE``: MuJoCo free-camera angles
  in degrees (elevation < 0 looks down) and the distance to the point looked at [m].

Text made of numbers alone but not in that form (``150``, ``150 -25``, ``150;-25``) is
refused at once, before any robot is read: it is angles mistyped, not a camera's name.

A free camera looks at the centre of the drawn geoms' bounding box; without a
distance it stands as close as it can with every drawn geom (planes excepted) in the
picture.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import mujoco
import numpy as np

from robotwright._suggest import did_you_mean
from robotwright.errors import RobotwrightError

__all__ = ["VIEWS", "CameraError", "CameraSpec", "make_camera", "parse_camera"]

#: Named views: azimuth, elevation [deg] of MuJoCo's free camera.
VIEWS: dict[str, tuple[float, float]] = {
    "iso": (150.0, -25.0),
    "front": (180.0, -10.0),
    "back": (0.0, -10.0),
    "left": (-90.0, -10.0),
    "right": (90.0, -10.0),
    "top": (90.0, -90.0),
}

#: Free space left around the framed geoms, as a fraction of the distance.
_MARGIN = 1.06


class CameraError(RobotwrightError, ValueError):
    """A camera text that names no model camera, view or angles."""


@dataclass(frozen=True)
class CameraSpec:
    """A parsed camera: a model camera's name, or free-camera angles.

    Attributes:
        name: model camera name (``None`` for a free camera).
        azimuth, elevation: free-camera angles [deg].
        distance: free-camera distance to the point looked at [m]; ``None`` = fit.
        text: the camera as given, for messages and picture titles.
    """

    name: str | None = None
    azimuth: float = VIEWS["iso"][0]
    elevation: float = VIEWS["iso"][1]
    distance: float | None = None
    text: str = "iso"

    def __post_init__(self) -> None:
        if self.name is None:
            for field, value in (("azimuth", self.azimuth), ("elevation", self.elevation)):
                if not math.isfinite(value):
                    raise CameraError(f"camera '{self.text}': {field} {value} is not finite")
            if not -90.0 <= self.elevation <= 90.0:
                raise CameraError(
                    f"camera '{self.text}': elevation {self.elevation} deg outside [-90, 90]"
                )
            if self.distance is not None and not (
                math.isfinite(self.distance) and self.distance > 0
            ):
                raise CameraError(
                    f"camera '{self.text}': distance {self.distance} m; expected a positive number"
                )


def parse_camera(text: str) -> CameraSpec:
    """Parse ``text`` (see the module docstring). A name that is neither a view nor
    angles is taken as a model camera's name, checked when the model is known."""
    t = text.strip()
    if not t:
        raise CameraError("camera '': expected a model camera name, a view or AZ,EL[,DIST]")
    if t.lower() in VIEWS:
        az, el = VIEWS[t.lower()]
        return CameraSpec(azimuth=az, elevation=el, text=t.lower())
    if "," in t:
        parts = t.split(",")
        try:
            values = [float(p) for p in parts]
        except ValueError:
            values = []
        if len(values) not in (2, 3):
            raise CameraError(
                f"camera '{t}': expected AZIMUTH,ELEVATION[,DISTANCE] in degrees and metres, "
                f"e.g. 150,-25 or 150,-25,3"
            )
        return CameraSpec(
            azimuth=values[0],
            elevation=values[1],
            distance=values[2] if len(values) == 3 else None,
            text=t,
        )
    if _NUMBERS_ONLY.fullmatch(t):
        raise CameraError(
            f"camera '{t}': expected AZIMUTH,ELEVATION[,DISTANCE] separated by commas "
            "(degrees and metres, e.g. 150,-25), a view (" + ", ".join(VIEWS) + ") or the "
            "name of a camera of the model"
        )
    return CameraSpec(name=t, text=t)


#: One or more numbers apart from separators other than a lone comma form.
_NUMBERS_ONLY = re.compile(r"[+-]?[\d.]+(?:[eE][+-]?\d+)?(?:[\s;:/]+[+-]?[\d.]+(?:[eE][+-]?\d+)?)*")


def _axes(azimuth: float, elevation: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Forward, up and right unit vectors of MuJoCo's free camera (degrees)."""
    az, el = math.radians(azimuth), math.radians(elevation)
    forward = np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])
    up = np.array([-math.sin(el) * math.cos(az), -math.sin(el) * math.sin(az), math.cos(el)])
    return forward, up, np.cross(forward, up)


def fit_distance(
    corners: np.ndarray,
    lookat: np.ndarray,
    azimuth: float,
    elevation: float,
    fovy: float,
    aspect: float,
) -> float:
    """Smallest free-camera distance [m] at which every point of ``corners`` ``(N, 3)``
    lies in a view of vertical field ``fovy`` [deg] and width/height ``aspect``."""
    forward, up, right = _axes(azimuth, elevation)
    rel = corners - lookat
    x, y, z = np.abs(rel @ right), np.abs(rel @ up), rel @ forward
    tan_v = math.tan(math.radians(fovy) / 2)
    tan_h = tan_v * aspect
    need = np.maximum(x / tan_h, y / tan_v) - z
    return float(max(need.max(), 1e-3) * _MARGIN)


def make_camera(
    model: mujoco.MjModel, spec: CameraSpec, corners: np.ndarray, aspect: float
) -> mujoco.MjvCamera:
    """A ``MjvCamera`` for ``spec``: the model camera it names, or a free camera
    framing ``corners`` ``(N, 3)`` [m] (the drawn geoms' bounding-box corners).

    Raises:
        CameraError: ``spec`` names no camera of ``model``.
    """
    cam = mujoco.MjvCamera()
    if spec.name is not None:
        cid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, spec.name)
        if cid < 0:
            names = [
                mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_CAMERA, i) for i in range(model.ncam)
            ]
            listed = ", ".join(n or f"#{i}" for i, n in enumerate(names)) or "none"
            hint = did_you_mean(spec.name, [*VIEWS, *(n for n in names if n)])
            raise CameraError(
                f"camera '{spec.name}': not a camera of the model (its cameras: {listed}) "
                f"nor a view ({', '.join(VIEWS)}) nor AZIMUTH,ELEVATION[,DISTANCE]{hint}"
            )
        cam.type = mujoco.mjtCamera.mjCAMERA_FIXED
        cam.fixedcamid = cid
        return cam
    mujoco.mjv_defaultFreeCamera(model, cam)
    cam.type = mujoco.mjtCamera.mjCAMERA_FREE
    cam.azimuth, cam.elevation = spec.azimuth, spec.elevation
    if len(corners):
        lookat = (corners.min(axis=0) + corners.max(axis=0)) / 2
    else:
        lookat = np.asarray(model.stat.center, dtype=np.float64)
    cam.lookat[:] = lookat
    if spec.distance is not None:
        cam.distance = spec.distance
    elif len(corners):
        fovy = float(model.vis.global_.fovy)
        cam.distance = fit_distance(corners, lookat, spec.azimuth, spec.elevation, fovy, aspect)
    return cam
