"""Sensors (MJCF ``<sensor>`` children), attached to the object they measure.

Attach a site sensor (IMU parts, touch, force, torque) to a
:class:`~robotwright.things.sites.Site`, a joint sensor to a joint, an actuator sensor
to an actuator, a frame sensor to a body, site, geom or camera, a subtree sensor to a
body. The MJCF tag is the class's ``_TAG``. After a step, ``sensor.data`` holds its
reading (SI units).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from robotwright.things.attrs import Choice, Real, Ref
from robotwright.things.base import BaseThing
from robotwright.things.runtime import sim_index

_SENSOR_ATTR: dict[str, Any] = {"noise": Real(nonneg=True), "cutoff": Real(nonneg=True)}


class Sensor(BaseThing):
    """Base of all sensors. ``noise`` is the standard deviation MuJoCo records (it does not
    add noise itself); ``cutoff`` clamps the reading when positive."""

    _NAMESPACE = "sensor"
    _NAMES_PARENT = True
    #: MJCF attribute that names the measured object ("site", "joint", "objname", ...).
    _TARGET_ATTR = ""
    #: Namespaces of Things this sensor can be attached to.
    _TARGET_KINDS: frozenset[str] = frozenset()
    _NEW_MUJOCO_ATTR = _SENSOR_ATTR
    _NEW_BLUEPRINTS_ATTR = _SENSOR_ATTR
    _NEW_DEFAULT_VALS = {"noise": 0.0, "cutoff": 0.0}

    def __init__(self, name: str | None = None, parent: BaseThing | None = None, **kwargs: Any):
        super().__init__(name=name, parent=parent, **kwargs)

    @property
    def data(self) -> np.ndarray:
        """The sensor's current reading in ``world.data.sensordata``, copy."""
        model, data, i = sim_index(self)
        adr, dim = int(model.sensor_adr[i]), int(model.sensor_dim[i])
        return data.sensordata[adr : adr + dim].copy()


class FrameSensor(Sensor):
    """Sensors of an object's frame; ``objtype`` defaults to the parent's kind
    (``"xbody"`` selects a body's inertial frame). ``ref`` expresses the reading in another
    object's frame (``reftype`` its kind)."""

    _TARGET_ATTR = "objname"
    _TARGET_KINDS = frozenset({"body", "site", "geom", "camera"})
    _FRAME_ATTR: dict[str, Any] = {
        "objtype": Choice("body", "xbody", "site", "geom", "camera", optional=True),
        "reftype": Choice("body", "xbody", "site", "geom", "camera", optional=True),
        "refname": Ref(),
    }
    _NEW_MUJOCO_ATTR = _FRAME_ATTR
    _NEW_BLUEPRINTS_ATTR = _FRAME_ATTR
    _NEW_DEFAULT_VALS = {"objtype": None, "reftype": None, "refname": None}


def _sensor(tag: str, base: type[Sensor], target: str, kinds: set[str], doc: str) -> type[Sensor]:
    ns = {"_TAG": tag, "__doc__": doc, "__module__": __name__}
    if base is Sensor:
        ns["_TARGET_ATTR"] = target
        ns["_TARGET_KINDS"] = frozenset(kinds)
    return type(base)(tag.capitalize(), (base,), ns)


_S = {"site"}
Touch = _sensor("touch", Sensor, "site", _S, "Normal contact force in the site's volume (N).")
Accelerometer = _sensor(
    "accelerometer", Sensor, "site", _S, "Linear acceleration in the site frame (m/s^2)."
)
Velocimeter = _sensor("velocimeter", Sensor, "site", _S, "Linear velocity in the site frame (m/s).")
Gyro = _sensor("gyro", Sensor, "site", _S, "Angular velocity in the site frame (rad/s).")
Force = _sensor("force", Sensor, "site", _S, "Force between the site's body and its parent (N).")
Torque = _sensor(
    "torque", Sensor, "site", _S, "Torque between the site's body and its parent (N m)."
)
Magnetometer = _sensor("magnetometer", Sensor, "site", _S, "Magnetic field in the site frame.")
Rangefinder = _sensor(
    "rangefinder", Sensor, "site", _S, "Distance along the site's +z (m, -1 = none)."
)
_J = {"joint"}
JointPos = _sensor("jointpos", Sensor, "joint", _J, "Joint position (rad or m).")
JointVel = _sensor("jointvel", Sensor, "joint", _J, "Joint velocity (rad/s or m/s).")
JointActuatorFrc = _sensor("jointactuatorfrc", Sensor, "joint", _J, "Actuator force at the joint.")
BallQuat = _sensor("ballquat", Sensor, "joint", _J, "Ball joint quaternion (w, x, y, z).")
BallAngVel = _sensor("ballangvel", Sensor, "joint", _J, "Ball joint angular velocity (rad/s).")
_A = {"actuator"}
ActuatorPos = _sensor("actuatorpos", Sensor, "actuator", _A, "Actuator length.")
ActuatorVel = _sensor("actuatorvel", Sensor, "actuator", _A, "Actuator velocity.")
ActuatorFrc = _sensor("actuatorfrc", Sensor, "actuator", _A, "Actuator force.")
FramePos = _sensor("framepos", FrameSensor, "", set(), "Frame position (m).")
FrameQuat = _sensor("framequat", FrameSensor, "", set(), "Frame orientation (w, x, y, z).")
FrameXAxis = _sensor("framexaxis", FrameSensor, "", set(), "Frame x axis.")
FrameYAxis = _sensor("frameyaxis", FrameSensor, "", set(), "Frame y axis.")
FrameZAxis = _sensor("framezaxis", FrameSensor, "", set(), "Frame z axis.")
FrameLinVel = _sensor("framelinvel", FrameSensor, "", set(), "Frame linear velocity (m/s).")
FrameAngVel = _sensor("frameangvel", FrameSensor, "", set(), "Frame angular velocity (rad/s).")
FrameLinAcc = _sensor("framelinacc", FrameSensor, "", set(), "Frame linear acceleration (m/s^2).")
FrameAngAcc = _sensor(
    "frameangacc", FrameSensor, "", set(), "Frame angular acceleration (rad/s^2)."
)
_B = {"body"}
SubtreeCom = _sensor("subtreecom", Sensor, "body", _B, "Centre of mass of the subtree (m).")
SubtreeLinVel = _sensor("subtreelinvel", Sensor, "body", _B, "Linear velocity of the subtree CoM.")
SubtreeAngMom = _sensor("subtreeangmom", Sensor, "body", _B, "Angular momentum of the subtree.")

for _cls, _pretty in [
    (JointPos, "JointPos"),
    (JointVel, "JointVel"),
    (JointActuatorFrc, "JointActuatorFrc"),
    (BallQuat, "BallQuat"),
    (BallAngVel, "BallAngVel"),
    (ActuatorPos, "ActuatorPos"),
    (ActuatorVel, "ActuatorVel"),
    (ActuatorFrc, "ActuatorFrc"),
    (FramePos, "FramePos"),
    (FrameQuat, "FrameQuat"),
    (FrameXAxis, "FrameXAxis"),
    (FrameYAxis, "FrameYAxis"),
    (FrameZAxis, "FrameZAxis"),
    (FrameLinVel, "FrameLinVel"),
    (FrameAngVel, "FrameAngVel"),
    (FrameLinAcc, "FrameLinAcc"),
    (FrameAngAcc, "FrameAngAcc"),
    (SubtreeCom, "SubtreeCom"),
    (SubtreeLinVel, "SubtreeLinVel"),
    (SubtreeAngMom, "SubtreeAngMom"),
]:
    _cls.__name__ = _cls.__qualname__ = _pretty

SENSOR_CLASSES: dict[str, type[Sensor]] = {
    c._TAG: c
    for c in (
        Touch,
        Accelerometer,
        Velocimeter,
        Gyro,
        Force,
        Torque,
        Magnetometer,
        Rangefinder,
        JointPos,
        JointVel,
        JointActuatorFrc,
        BallQuat,
        BallAngVel,
        ActuatorPos,
        ActuatorVel,
        ActuatorFrc,
        FramePos,
        FrameQuat,
        FrameXAxis,
        FrameYAxis,
        FrameZAxis,
        FrameLinVel,
        FrameAngVel,
        FrameLinAcc,
        FrameAngAcc,
        SubtreeCom,
        SubtreeLinVel,
        SubtreeAngMom,
    )
}
