"""In-memory HRDF robot description.

One robot is a tree of bodies with joints, actuators, geoms (meshes and primitives),
sites and sensors, plus metadata. All records are plain dataclasses whose vector fields
are tuples of floats (immutable, so a generator can never mutate the model it reads).

Conventions (same as MJCF):
- SI units: metres, kilograms, seconds, newtons; angles in radians.
- Quaternions are ``(w, x, y, z)``.
- A body's ``pos``/``quat`` are relative to its parent body frame; the root body's are
  relative to the world. Joint, geom and site poses are relative to their body frame.
- Inertia is given as ``diag_inertia`` (principal moments, kg m^2) in the inertial frame
  ``inertial_pos``/``inertial_quat`` (relative to the body frame).

See ``docs/hrdf.md`` for the folder format (files, columns, defaults).
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]
RGBA = tuple[float, float, float, float]
Range = tuple[float, float]

#: Joint types HRDF can hold. ``free`` is only valid on the root body.
JOINT_TYPES: tuple[str, ...] = ("hinge", "slide", "ball", "free")
#: Actuator types HRDF can hold (MuJoCo shortcuts).
ACTUATOR_TYPES: tuple[str, ...] = ("motor", "position", "velocity")
#: Primitive geom types of ``simple_geom.csv`` (sizes are MuJoCo half-sizes).
SIMPLE_GEOM_TYPES: tuple[str, ...] = ("box", "sphere", "capsule", "cylinder", "ellipsoid")
#: Site shapes (MuJoCo site types).
SITE_TYPES: tuple[str, ...] = ("sphere", "capsule", "ellipsoid", "cylinder", "box")
#: Object types a frame sensor (``framepos``, ...) may read, or measure relative to.
FRAME_OBJTYPES: tuple[str, ...] = ("body", "xbody", "geom", "site", "camera")
#: ``sensor.csv`` types: the MJCF sensor elements that read one named object, each with
#: the object types it reads (written as the element's ``site=``/``joint=``/... attribute,
#: or as ``objtype`` for frame sensors).
SENSOR_OBJTYPES: dict[str, tuple[str, ...]] = {
    **dict.fromkeys(
        ("touch", "accelerometer", "velocimeter", "gyro", "force", "torque", "magnetometer"),
        ("site",),
    ),
    "rangefinder": ("site",),
    **dict.fromkeys(
        (
            "jointpos",
            "jointvel",
            "ballquat",
            "ballangvel",
            "jointlimitpos",
            "jointlimitvel",
            "jointlimitfrc",
            "jointactuatorfrc",
        ),
        ("joint",),
    ),  # fmt: skip
    **dict.fromkeys(
        (
            "tendonpos",
            "tendonvel",
            "tendonactuatorfrc",
            "tendonlimitpos",
            "tendonlimitvel",
            "tendonlimitfrc",
        ),
        ("tendon",),
    ),  # fmt: skip
    **dict.fromkeys(("actuatorpos", "actuatorvel", "actuatorfrc"), ("actuator",)),
    **dict.fromkeys(("subtreecom", "subtreelinvel", "subtreeangmom"), ("body",)),
    **dict.fromkeys(
        (
            "framepos",
            "framequat",
            "framexaxis",
            "frameyaxis",
            "framezaxis",
            "framelinvel",
            "frameangvel",
            "framelinacc",
            "frameangacc",
        ),
        FRAME_OBJTYPES,
    ),  # fmt: skip
}
#: ``simulator_config.integrator`` values (MuJoCo integrator names).
INTEGRATORS: tuple[str, ...] = ("Euler", "RK4", "implicit", "implicitfast")
#: ``simulator_config.ground.type`` values the generators write.
GROUND_TYPES: tuple[str, ...] = ("plane",)
#: Top-level sections ``extra.xml`` (``HRDF.mjcf_extra``) may hold.
EXTRA_SECTIONS: tuple[str, ...] = (
    "extension",
    "tendon",
    "equality",
    "contact",
    "actuator",
    "sensor",
    "keyframe",
)
#: Deepest element nesting in ``extra.xml`` (``<mujoco><tendon><spatial><site>`` is 4).
EXTRA_MAX_DEPTH = 8
#: ``site.csv`` ``body_name`` of a site fixed in the world (not on a robot body): an IMU
#: frame or a muscle origin of the robot file's world. MuJoCo's name for its body 0.
WORLD = "world"
#: The format version this package writes into ``meta.yaml``.
FORMAT_VERSION = "robotwright-hrdf/1"

IDENTITY_QUAT: Quat = (1.0, 0.0, 0.0, 0.0)
ZERO3: Vec3 = (0.0, 0.0, 0.0)
#: MuJoCo's default constraint solver parameters (``solref``: time constant (s), damping
#: ratio; ``solimp``: dmin, dmax, width (m), midpoint, power).
MUJOCO_SOLREF: tuple[float, float] = (0.02, 1.0)
MUJOCO_SOLIMP: tuple[float, float, float, float, float] = (0.9, 0.95, 0.001, 0.5, 2.0)
#: ``<size>`` attributes ``meta.yaml``'s ``mjcf_size`` holds: the length of each ``user``
#: array (MuJoCo pads every object's ``user`` values with zeros to this length).
NUSER_KEYS: tuple[str, ...] = (
    "nuser_body",
    "nuser_jnt",
    "nuser_geom",
    "nuser_site",
    "nuser_cam",
    "nuser_tendon",
    "nuser_actuator",
    "nuser_sensor",
)
#: MuJoCo's default torsional and rolling friction coefficients.
MUJOCO_TORSIONAL_FRICTION = 0.005
MUJOCO_ROLLING_FRICTION = 0.0001


@dataclass(frozen=True)
class Body:
    """A rigid body.

    Attributes:
        name: unique body name.
        parent: index of the parent body in ``HRDF.bodies``; -1 for the root.
        pos: position of the body frame in the parent frame (m).
        quat: orientation of the body frame in the parent frame (w, x, y, z).
        mass: mass (kg), >= 0. MuJoCo's rule applies: a body with joints needs mass and
            inertia (>= 1e-15) itself or in a body welded to it (no joint between them).
        inertial_pos: centre of mass in the body frame (m).
        inertial_quat: orientation of the principal inertia frame in the body frame.
        diag_inertia: principal moments of inertia about the centre of mass (kg m^2).
        gravcomp: MuJoCo ``gravcomp``: the fraction of the body's weight cancelled by
            a force at its centre of mass (0 = none, 1 = weightless).
        user: MuJoCo ``user`` data (numbers MuJoCo stores but does not use).
    """

    name: str
    parent: int
    pos: Vec3
    quat: Quat
    mass: float
    inertial_pos: Vec3
    inertial_quat: Quat
    diag_inertia: Vec3
    gravcomp: float = 0.0
    user: tuple[float, ...] = ()


@dataclass(frozen=True)
class Joint:
    """A joint between a body and its parent; a body may carry several (in order).

    Attributes:
        name: unique joint name. ``None`` only for the implied free joint of a hurodes
            floating base (hurodes writes an unnamed ``<freejoint/>``).
        body: name of the child body that the joint moves.
        type: one of :data:`JOINT_TYPES`.
        pos: joint anchor in the body frame (m).
        axis: joint axis in the body frame (unit vector; hinge and slide only).
        range: (lower, upper) in rad (hinge, ball) or m (slide); ``None`` = unlimited.
        armature: rotor inertia added to the joint (kg m^2 or kg).
        static_friction: hurodes' static friction (N m or N); kept for compatibility.
        dynamic_friction: dry friction torque/force (N m or N), MuJoCo ``frictionloss``.
        viscous_friction: viscous damping (N m s/rad or N s/m), MuJoCo ``damping``.
        stiffness: joint spring stiffness (N m/rad or N/m).
        springref: spring reference position (rad or m).
        ref: reference position (rad or m) at which the body is at its ``pos``/``quat``.
        margin: distance (rad or m) before the limit at which the limit becomes active.
        actuatorfrcrange: (lower, upper) clamp of the total actuator force at the joint
            (N m or N), ``None`` = unclamped (MuJoCo ``actuatorfrcrange``).
        actuatorgravcomp: gravity compensation (``gravcomp``) acts through actuators
            (counts against ``actuatorfrcrange``) instead of as a passive force.
        solreflimit, solimplimit: solver parameters of the joint limit.
        solreffriction, solimpfriction: solver parameters of the dry friction.
        user: MuJoCo ``user`` data.

    The dof fields (``armature``, ``dynamic_friction``, ``viscous_friction``) apply to
    every degree of freedom of a ball or free joint.
    """

    name: str | None
    body: str
    type: str = "hinge"
    pos: Vec3 = ZERO3
    axis: Vec3 = (0.0, 0.0, 1.0)
    range: Range | None = None
    armature: float = 0.0
    static_friction: float = 0.0
    dynamic_friction: float = 0.0
    viscous_friction: float = 0.0
    stiffness: float = 0.0
    springref: float = 0.0
    ref: float = 0.0
    margin: float = 0.0
    actuatorfrcrange: Range | None = None
    actuatorgravcomp: bool = False
    solreflimit: tuple[float, float] = MUJOCO_SOLREF
    solimplimit: tuple[float, float, float, float, float] = MUJOCO_SOLIMP
    solreffriction: tuple[float, float] = MUJOCO_SOLREF
    solimpfriction: tuple[float, float, float, float, float] = MUJOCO_SOLIMP
    user: tuple[float, ...] = ()


@dataclass(frozen=True)
class Actuator:
    """An actuator driving one joint.

    hurodes' table has no type: its actuators are torque motors whose control range is
    ``[-peak_torque, peak_torque]``. Explicit ``ctrl_range``/``force_range`` take
    precedence where given.

    Attributes:
        joint: name of the driven joint.
        name: actuator name, or ``None`` (hurodes writes unnamed actuators).
        type: one of :data:`ACTUATOR_TYPES`.
        peak_torque: peak joint torque/force (N m or N), or ``None``.
        peak_velocity: peak joint speed (rad/s or m/s), or ``None``.
        p_gain: position gain (N m/rad), MuJoCo ``kp`` for position actuators, or ``None``.
        d_gain: damping gain (N m s/rad), MuJoCo ``kv``, or ``None``.
        gear: transmission ratio.
        ctrl_range: control range, or ``None`` (derived from peak_torque for motors).
        force_range: actuator force range, or ``None``.
        user: MuJoCo ``user`` data.
    """

    joint: str
    name: str | None = None
    type: str = "motor"
    peak_torque: float | None = None
    peak_velocity: float | None = None
    p_gain: float | None = None
    d_gain: float | None = None
    gear: float = 1.0
    ctrl_range: Range | None = None
    force_range: Range | None = None
    user: tuple[float, ...] = ()


@dataclass(frozen=True)
class Geom:
    """Contact and appearance fields shared by mesh geoms and primitive geoms.

    Attributes:
        body: name of the body the geom is attached to.
        pos: geom position in the body frame (m).
        quat: geom orientation in the body frame.
        rgba: colour (0..1).
        contact_type: MuJoCo ``contype`` bitmask.
        contact_affinity: MuJoCo ``conaffinity`` bitmask.
        static_friction: sliding friction coefficient (MuJoCo ``friction[0]``).
        dynamic_friction: hurodes' dynamic friction (kept; MuJoCo has no separate one).
        restitution: restitution coefficient, or ``None`` (not modelled by MuJoCo).
        torsional_friction: MuJoCo ``friction[1]``.
        rolling_friction: MuJoCo ``friction[2]``.
        group: MuJoCo visualisation group (0..5).
        condim: contact dimensionality (1, 3, 4 or 6).
        geom_name: the geom's own name, or ``None``.
        solref: contact solver reference (time constant s, damping ratio; or negative
            stiffness, damping).
        solimp: contact solver impedance (dmin, dmax, width m, midpoint, power).
        margin: distance (m) at which contacts are detected.
        gap: contacts within ``margin - gap`` of touching are active (m).
        priority: contact priority (the higher geom's parameters win).
        order: position among its body's geoms, counting both tables, or ``None``:
            where a body's mesh and primitive geoms interleave, the order they are
            written in (MuJoCo's contact order follows it); else meshes first, then
            primitives, each in row order.
        solmix: weight of this geom's solref/solimp when two geoms of equal priority
            touch.
        user: MuJoCo ``user`` data.
    """

    body: str
    pos: Vec3 = ZERO3
    quat: Quat = IDENTITY_QUAT
    rgba: RGBA = (0.5, 0.5, 0.5, 1.0)
    contact_type: int = 1
    contact_affinity: int = 1
    static_friction: float = 1.0
    dynamic_friction: float = 1.0
    restitution: float | None = None
    torsional_friction: float = MUJOCO_TORSIONAL_FRICTION
    rolling_friction: float = MUJOCO_ROLLING_FRICTION
    group: int = 0
    condim: int = 3
    geom_name: str | None = None
    solref: tuple[float, float] = MUJOCO_SOLREF
    solimp: tuple[float, float, float, float, float] = MUJOCO_SOLIMP
    margin: float = 0.0
    gap: float = 0.0
    priority: int = 0
    solmix: float = 1.0
    order: int | None = None
    user: tuple[float, ...] = ()


#: MuJoCo's ``<mesh inertia>`` modes.
MESH_INERTIA_MODES = ("legacy", "convex", "exact", "shell")


@dataclass(frozen=True)
class MeshGeom(Geom):
    """A geom whose shape is a mesh file.

    Attributes:
        name: mesh asset name; the file is ``meshes/<name>.<mesh_file_type>`` unless
            ``file`` is set. Several rows may share one mesh (e.g. visual + collision).
        file: mesh file path relative to the HRDF folder, or ``None`` for the default.
        scale: per-axis scale applied to the mesh vertices (unitless); a negative factor
            mirrors the mesh on that axis, as MuJoCo does: it hulls the file's own
            vertices and mirrors the hull, which no mirrored copy of the file reproduces.
        inertia: MuJoCo's mesh inertia mode (one of :data:`MESH_INERTIA_MODES`: how it
            computes the mesh's volume, centre and inertia; ``"shell"`` for open or flat
            meshes), or ``None`` for MuJoCo's default (legacy).
    """

    name: str = ""
    file: str | None = None
    scale: Vec3 = (1.0, 1.0, 1.0)
    inertia: str | None = None


@dataclass(frozen=True)
class SimpleGeom(Geom):
    """A primitive geom.

    Attributes:
        name: geom name (hurodes writes ``geom_<i>``).
        type: one of :data:`SIMPLE_GEOM_TYPES`.
        size: MuJoCo half-sizes (m): box (x, y, z); sphere (r, 0, 0); capsule and
            cylinder (r, half-length, 0); ellipsoid (rx, ry, rz).
    """

    name: str = ""
    type: str = "box"
    size: Vec3 = ZERO3


@dataclass(frozen=True)
class Site:
    """A named frame on a body (sensor mount, tool point, attachment point).

    Attributes:
        name: unique site name.
        body: body name.
        pos: position in the body frame (m).
        quat: orientation in the body frame.
        type: one of :data:`SITE_TYPES` (for drawing only).
        size: MuJoCo half-sizes for drawing (m).
        rgba: colour for drawing.
        group: visualisation group.
        user: MuJoCo ``user`` data.
    """

    name: str
    body: str
    pos: Vec3 = ZERO3
    quat: Quat = IDENTITY_QUAT
    type: str = "sphere"
    size: Vec3 = (0.005, 0.0, 0.0)
    rgba: RGBA = (0.5, 0.5, 0.5, 1.0)
    group: int = 0
    user: tuple[float, ...] = ()


@dataclass(frozen=True)
class Sensor:
    """A MuJoCo sensor.

    Attributes:
        name: unique sensor name.
        type: MuJoCo sensor element name, one of :data:`SENSOR_OBJTYPES` (e.g.
            ``accelerometer``, ``gyro``, ``framequat``, ``jointpos``, ``touch``).
        objtype: type of the object it reads, one of ``SENSOR_OBJTYPES[type]``
            (``site``, ``body``, ``xbody``, ``joint``, ``actuator``, ...), as in MJCF.
        objname: name of that object.
        reftype: reference frame object type for frame sensors (one of
            :data:`FRAME_OBJTYPES`), or ``None``.
        refname: reference frame object name, or ``None``.
        noise: standard deviation of sensor noise (sensor units).
        cutoff: absolute-value cutoff (0 = none).
        user: MuJoCo ``user`` data.
    """

    name: str
    type: str
    objtype: str
    objname: str
    reftype: str | None = None
    refname: str | None = None
    noise: float = 0.0
    cutoff: float = 0.0
    user: tuple[float, ...] = ()


@dataclass
class GroundConfig:
    """The ground added by ``add_scene``. Units: friction coefficient (sliding)."""

    type: str | None = "plane"
    contact_type: int | None = 1
    contact_affinity: int | None = 1
    friction: float | None = 1.0


@dataclass
class SimulatorConfig:
    """Simulation settings: ``timestep`` (s), ``gravity`` (m/s^2, world frame),
    ``integrator`` (MuJoCo integrator name or ``None`` for MuJoCo's default).

    ``option`` holds the other MJCF ``<option>`` attributes the robot sets (MJCF names
    and units, see :data:`robotwright.hrdf.options.OPTION_FIELDS`: ``impratio``,
    ``cone``, ``o_solref``, ``wind`` ...); ``flag`` the ``<option><flag>`` switches it
    sets (``{"contact": "disable", "energy": "enable"}``). Absent keys mean MuJoCo's
    default."""

    timestep: float | None = 0.002
    gravity: Vec3 | None = (0.0, 0.0, -9.81)
    ground: GroundConfig | None = field(default_factory=GroundConfig)
    integrator: str | None = None
    option: dict[str, Any] = field(default_factory=dict)
    flag: dict[str, str] = field(default_factory=dict)


@dataclass
class BodyNameConfig:
    """Names of semantically important bodies (for controllers and rewards)."""

    torso_name: str | None = None
    hip_names: list[str] | None = None
    knee_names: list[str] | None = None
    foot_names: list[str] | None = None


@dataclass
class ImuConfig:
    """An IMU mounted on a body.

    Attributes:
        body_name: body carrying the IMU.
        position: IMU position in the body frame (m).
        orientation: IMU orientation in the body frame (w, x, y, z).
        value: measured quantities, a subset of ``linacc``, ``angvel``, ``quat``.
        device_type: hardware device type, or ``None``.
        device_config_name: hardware device config name, or ``None``.
    """

    body_name: str
    position: Vec3 = ZERO3
    orientation: Quat = IDENTITY_QUAT
    value: list[str] = field(default_factory=lambda: ["linacc", "angvel", "quat"])
    device_type: str | None = None
    device_config_name: str | None = None

    @property
    def name(self) -> str | None:
        """hurodes' device name ``<device_type>_<device_config_name>``, when both are set."""
        if self.device_type is not None and self.device_config_name is not None:
            return f"{self.device_type}_{self.device_config_name}"
        return None


@dataclass
class Meta:
    """Robot-level metadata (``meta.yaml``).

    Attributes:
        mesh_file_type: default mesh file extension (``stl`` or ``obj``).
        simulator_config: simulation settings.
        body_name_config: semantic body names.
        imu_config_list: IMUs.
        motor_config_list: hurodes motor device configs, kept verbatim.
        joint_mapping: contents of ``joint_mapping.yaml``, kept verbatim, or ``None``.
        format_version: the HRDF format version read, or ``None`` for a hurodes folder.
        mjcf_size: MJCF ``<size>`` ``nuser_*`` values (see :data:`NUSER_KEYS`) the
            robot sets: the length of each object type's ``user`` array.
        extra: other top-level keys of ``meta.yaml``, kept verbatim.
    """

    mesh_file_type: str = "stl"
    simulator_config: SimulatorConfig | None = field(default_factory=SimulatorConfig)
    body_name_config: BodyNameConfig | None = field(default_factory=BodyNameConfig)
    imu_config_list: list[ImuConfig] | None = None
    motor_config_list: list[dict[str, Any]] | None = None
    joint_mapping: dict[str, Any] | None = None
    format_version: str | None = FORMAT_VERSION
    mjcf_size: dict[str, int] = field(default_factory=dict)
    extra: dict[str, Any] = field(default_factory=dict)


@dataclass
class HRDF:
    """A robot: bodies (a tree), joints, actuators, geoms, sites, sensors and metadata.

    ``bodies[i].parent`` indexes ``bodies``; exactly one body is the root (parent -1).
    The base is floating when the root body carries a ``free`` joint, fixed otherwise.

    ``mjcf_extra`` holds an MJCF fragment (a ``<mujoco>`` element as a string) with what
    the tables do not model, such as tendons, equality constraints, contact pairs and
    excludes, and keyframes, so that a round trip loses nothing. Names in it refer to the
    robot's bodies, joints, sites and actuators.

    ``root_dir`` is the folder the robot was loaded from (mesh files are resolved against
    it), or ``None`` for a robot built in memory whose meshes are given by absolute paths.
    Mesh paths of a robot with a folder must resolve inside it (no ``..``, absolute path
    or symbolic link leading out), or inside one of ``asset_roots``: folders the caller
    trusts explicitly (see :mod:`robotwright._paths`).
    """

    name: str
    bodies: list[Body]
    joints: list[Joint] = field(default_factory=list)
    actuators: list[Actuator] = field(default_factory=list)
    meshes: list[MeshGeom] = field(default_factory=list)
    simple_geoms: list[SimpleGeom] = field(default_factory=list)
    sites: list[Site] = field(default_factory=list)
    sensors: list[Sensor] = field(default_factory=list)
    meta: Meta = field(default_factory=Meta)
    mjcf_extra: str | None = None
    root_dir: Path | None = None
    asset_roots: tuple[Path, ...] = field(default=(), compare=False, repr=False)
    #: The temporary folder ``root_dir`` lies in when a parser staged the meshes there
    #: (removed when no HRDF holds it; ``dataclasses.replace`` carries it). None otherwise.
    temp_assets: object | None = field(default=None, compare=False, repr=False)

    # -- loading and saving -------------------------------------------------------------
    @classmethod
    def from_dir(
        cls, path: str | Path, *, asset_roots: Iterable[str | os.PathLike[str]] | None = None
    ) -> HRDF:
        """Load an HRDF folder from anywhere on disk (hurodes 0.1.9 or robotwright format).

        Args:
            path: the folder.
            asset_roots: folders outside ``path`` that mesh paths may point into
                (trusted explicitly; by default mesh paths must stay inside ``path``).

        Raises:
            robotwright.errors.HRDFError: listing every problem found.
        """
        from robotwright.hrdf.io import read_hrdf_dir

        return read_hrdf_dir(path, asset_roots=asset_roots)

    def save(self, path: str | Path, *, overwrite: bool = False) -> Path:
        """Write this robot as an HRDF folder (atomically: all or nothing).

        Only robotwright extensions that carry information are written, so a robot that
        uses hurodes' features only gives a folder hurodes can read.
        """
        from robotwright.hrdf.write import write_hrdf_dir

        return write_hrdf_dir(self, path, overwrite=overwrite)

    @classmethod
    def from_robot_name(cls, name: str) -> HRDF:
        """Load a robot by name: ``$HURODES_ASSETS_PATH/robots/<name>``, then bundled robots."""
        from robotwright.hrdf.assets import find_robot

        return cls.from_dir(find_robot(name))

    # -- queries ------------------------------------------------------------------------
    @property
    def root_index(self) -> int:
        """Index of the root body (parent -1): the first one where a scene holds several
        (a robot and its objects: see :attr:`root_indices`)."""
        for i, body in enumerate(self.bodies):
            if body.parent == -1:
                return i
        raise ValueError(f"robot '{self.name}' has no root body")

    @property
    def root_indices(self) -> list[int]:
        """Indices of every root body (parent -1), in table order: one for a robot, one
        per top-level body for a scene read whole (each fixed in the world or free)."""
        return [i for i, body in enumerate(self.bodies) if body.parent == -1]

    @property
    def base_joint(self) -> Joint | None:
        """The free joint of the (first) root body, which ``meta.yaml`` holds as
        ``floating_base``; None for a fixed base. Other roots' free joints are rows of
        ``joint.csv``."""
        roots = self.root_indices
        if not roots:
            return None
        root = self.bodies[roots[0]].name
        return next((j for j in self.joints if j.type == "free" and j.body == root), None)

    @property
    def root_body(self) -> Body:
        return self.bodies[self.root_index]

    @property
    def body_parent_id(self) -> list[int]:
        """hurodes' ``body_parent_id`` list (index = body id)."""
        return [b.parent for b in self.bodies]

    @property
    def floating_base(self) -> bool:
        """True when the (first) root body carries a free joint."""
        return self.base_joint is not None

    @property
    def total_mass(self) -> float:
        """Sum of body masses (kg)."""
        return float(sum(b.mass for b in self.bodies))

    @property
    def dof(self) -> int:
        """Degrees of freedom (velocity dimension, as MuJoCo's ``nv``)."""
        per_type = {"hinge": 1, "slide": 1, "ball": 3, "free": 6}
        return sum(per_type[j.type] for j in self.joints)

    def body(self, name: str) -> Body:
        """The body called ``name`` (KeyError naming it otherwise)."""
        for b in self.bodies:
            if b.name == name:
                return b
        raise KeyError(f"robot '{self.name}' has no body '{name}'")

    def body_index(self, name: str) -> int:
        for i, b in enumerate(self.bodies):
            if b.name == name:
                return i
        raise KeyError(f"robot '{self.name}' has no body '{name}'")

    def children(self, index: int) -> list[int]:
        """Indices of the child bodies of body ``index``, in table order."""
        return [i for i, b in enumerate(self.bodies) if b.parent == index]

    def joints_of(self, body_name: str) -> list[Joint]:
        """Joints of a body, in table order."""
        return [j for j in self.joints if j.body == body_name]

    def mesh_path(self, mesh: MeshGeom) -> Path:
        """Absolute path of a mesh geom's file."""
        rel = (
            mesh.file if mesh.file is not None else f"meshes/{mesh.name}.{self.meta.mesh_file_type}"
        )
        path = Path(rel)
        if path.is_absolute() or self.root_dir is None:
            return path
        return self.root_dir / path

    def mesh_source(self, mesh: MeshGeom) -> Path:
        """The resolved path of a mesh geom's file, the one to read or copy.

        For a robot with a folder (``root_dir``) the path must resolve inside it or
        inside a trusted folder (``asset_roots``, or a
        :func:`robotwright._paths.trusted_asset_roots` block); a robot built in memory
        names its own files.

        Raises:
            robotwright.errors.UnsafePathError: the path leads out of the robot folder
                (the message names the path, where it resolves to and the mesh).
        """
        from robotwright._paths import resolve_inside, trusted_roots
        from robotwright.errors import UnsafePathError

        if self.root_dir is None:
            return self.mesh_path(mesh).resolve()
        rel = (
            mesh.file if mesh.file is not None else f"meshes/{mesh.name}.{self.meta.mesh_file_type}"
        )
        try:
            return resolve_inside(
                rel,
                base=self.root_dir,
                root=self.root_dir,
                trusted=self.asset_roots + trusted_roots(),
            )
        except UnsafePathError as exc:
            column = "file" if mesh.file is not None else "name"
            raise UnsafePathError(
                exc.reason, file="mesh.csv", element=f"mesh '{mesh.name}' (column '{column}')"
            ) from None

    def summary(self) -> dict[str, Any]:
        """Counts and totals for display."""
        return {
            "name": self.name,
            "bodies": len(self.bodies),
            "joints": len(self.joints),
            "actuators": len(self.actuators),
            "meshes": len(self.meshes),
            "simple_geoms": len(self.simple_geoms),
            "sites": len(self.sites),
            "sensors": len(self.sensors),
            "dof": self.dof,
            "total_mass": self.total_mass,
            "floating_base": self.floating_base,
        }
