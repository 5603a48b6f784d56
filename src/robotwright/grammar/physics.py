"""Physics of a limb mounted on its carrier: payload, trajectory tracking, energy.

Every function here is a deterministic function of a built limb, a :class:`Carrier` and
its parameters (seeded sampling, fixed time step, no wall-clock or thread dependence),
evaluated in MuJoCo with the actuator limits of the component library (the connector's
``peak_torque``: N m for a revolute DoF, N for a prismatic one).

The carrier (default: the bundled ``mini_humanoid``, limb on its ``back_mount`` site
pointing backwards, as ``robotwright demo`` mounts it) is held still in its reference
pose: its joints are locked, so only the limb moves. Positions are in metres in the
world frame, which is the carrier's frame (its root body stays where its model puts
it); gravity is the carrier model's (-9.81 m/s^2 along z).
"""

from __future__ import annotations

import math
import warnings
import xml.etree.ElementTree as ET  # noqa: N817 (serialising our own tree, not parsing)
from dataclasses import dataclass
from functools import cached_property, lru_cache, partial

import mujoco
import numpy as np

from robotwright._bounds import Bound
from robotwright._names import shown
from robotwright.grammar.build import Limb
from robotwright.grammar.overlap import OverlapCheck

#: The limb's z axis (its base normal) along the site's -x: worn on the back, pointing
#: backwards. Rotation of -90 deg about y, as (w, x, y, z).
BACKWARDS = (math.sqrt(0.5), 0.0, -math.sqrt(0.5), 0.0)


@dataclass(frozen=True)
class Carrier:
    """Where a limb is worn: a bundled robot (``robot``, by name), the body or site
    ``at`` that carries the limb's base, and the limb's pose there (m; w, x, y, z).

    ``posture`` holds joints of the carrier at other values than its reference pose
    (joint name, rad for a hinge or m for a slide); every joint is locked where the
    posture (or else the reference pose) puts it."""

    robot: str = "mini_humanoid"
    at: str = "back_mount"
    pos: tuple[float, float, float] = (0.0, 0.0, 0.0)
    quat: tuple[float, float, float, float] = BACKWARDS
    prefix: str = "srl_"
    posture: tuple[tuple[str, float], ...] = ()


#: The range of every setting of the physics objectives (payload, track, energy,
#: collision), from the Python API and task files alike: each has an upper bound, so
#: that no setting can ask for minutes of work or gigabytes per design.
SETTING_BOUNDS: dict[str, Bound] = {
    "samples": Bound(0, 10_000, integer=True, unit="poses"),
    "seed": Bound(0, 2**32 - 1, integer=True),
    "duration": Bound(0.0, 60.0, unit="s", open_low=True),
    "omega": Bound(0.0, 1000.0, unit="rad/s", open_low=True),
    "limit": Bound(0.0, 10_000.0, unit="kg", open_low=True),
    "min_free_share": Bound(0.0, 1.0),
    "scale": Bound(0.0, 10.0),
    "reach": Bound(0.0, 1000.0, unit="m"),
    "radius": Bound(0.0, 10.0, unit="m"),
    "min_reach": Bound(0.0, 10.0, unit="m"),
    "max_track_error": Bound(0.0, 10.0, unit="m"),
    "voxel": Bound(0.001, 1.0, unit="m"),
}

#: The built-in tracking target, fixed in the mount frame (the limb's base: z out of
#: the carrier's back, x up it on the built-in carrier): a circle of 5 cm radius centred
#: 0.4 m out from the back and 0.4 m above the mount, the same for every design (a
#: target scaled by the design's own reach rewards a limb too small to do anything).
#: Where random designs of up to 4 links reach most often (18 of 80 come within 3 cm
#: of it, against 11 for a point 0.3 m straight out).
TRACK_CENTER: tuple[float, float, float] = (0.4, 0.0, 0.4)
TRACK_RADIUS = 0.05
#: The built-in payload test counts poses whose tool point is at least this far (m) from
#: the mount: a payload held close to the base is no payload held where it is needed.
PAYLOAD_MIN_REACH = 0.25


def check_settings(what: str, **values: float) -> None:
    """Refuse a setting that is not a number of its kind in its range
    (:data:`SETTING_BOUNDS`).

    Raises:
        ValueError: naming ``what``, the setting and the expectation.
    """
    for name, v in values.items():
        bound = SETTING_BOUNDS[name]
        whole = bound.integer and isinstance(v, float) and v.is_integer()
        if bound.check(int(v) if whole else v) is None:
            raise ValueError(f"{what}: {name} {bound.expected()}, got {shown(v)}")


#: The default carrier: the bundled humanoid, the limb on its back.
DEFAULT_CARRIER = Carrier()


# Room for a task's every posture (16) and the carrier itself, twice over.
@lru_cache(maxsize=40)
def _carrier_xml(carrier: Carrier) -> tuple[str, str, tuple[float, ...], tuple[float, ...]]:
    """MJCF text of the carrier with every joint, actuator and sensor removed (held in
    its reference pose, or in ``carrier.posture``), and the body and pose (in that body)
    where the limb goes."""
    from robotwright.errors import ConversionWarning
    from robotwright.generators import MJCFHumanoidGenerator
    from robotwright.grammar.mount import _compose
    from robotwright.hrdf.model import HRDF

    robot = HRDF.from_robot_name(carrier.robot)
    site = next((s for s in robot.sites if s.name == carrier.at), None)
    if site is not None:
        body, fpos, fquat = site.body, site.pos, site.quat
    elif carrier.at in {b.name for b in robot.bodies}:
        body, fpos, fquat = carrier.at, (0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0)
    else:
        raise ValueError(f"carrier {carrier.robot!r} has no body or site named {carrier.at!r}")
    pos, quat = _compose(fpos, fquat, carrier.pos, carrier.quat)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConversionWarning)  # peak velocity has no MJCF field
        root = MJCFHumanoidGenerator.from_hrdf(robot).generate(add_scene=False)
    xml = ET.tostring(root, encoding="unicode")
    spec = mujoco.MjSpec.from_string(xml)
    if carrier.posture:
        _hold_posture(spec, carrier)
    for kind in ("sensors", "actuators", "joints"):
        for item in list(getattr(spec, kind)):
            spec.delete(item)
    return spec.to_xml(), body, pos, quat


def _hold_posture(spec: mujoco.MjSpec, carrier: Carrier) -> None:
    """Pose every body of ``spec`` where the joints at ``carrier.posture`` put it, so that
    the pose stays when the joints are deleted.

    Raises:
        ValueError: a joint the carrier lacks (or that is not a hinge or slide), or a
            value outside the joint's range.
    """
    model = spec.compile()
    data = mujoco.MjData(model)
    hinge, slide = int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE)
    for name, value in carrier.posture:
        jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)
        if jid < 0 or int(model.jnt_type[jid]) not in (hinge, slide):
            raise ValueError(
                f"posture: carrier {carrier.robot!r} has no hinge or slide joint named {name!r}"
            )
        lo, hi = model.jnt_range[jid]
        if model.jnt_limited[jid] and not lo <= value <= hi:
            unit = "rad" if int(model.jnt_type[jid]) == hinge else "m"
            raise ValueError(
                f"posture: joint {name!r} expects a value in [{lo:g}, {hi:g}] {unit}, got {value:g}"
            )
        data.qpos[model.jnt_qposadr[jid]] = value
    mujoco.mj_kinematics(model, data)
    for b in spec.bodies[1:]:
        i, parent = model.body(b.name).id, model.body(b.parent.name).id
        rot = data.xmat[parent].reshape(3, 3)
        b.pos = rot.T @ (data.xpos[i] - data.xpos[parent])
        quat = np.zeros(4)
        mujoco.mju_negQuat(quat, data.xquat[parent])
        mujoco.mju_mulQuat(quat, quat, data.xquat[i])
        b.alt.type = mujoco.mjtOrientation.mjORIENTATION_QUAT
        b.quat = quat


@dataclass
class Mounted:
    """A limb on its carrier, compiled: ids of the limb's joints, tool sites and bodies."""

    model: mujoco.MjModel
    peak: np.ndarray  # (nv,) peak torque per limb DoF, N m or N
    rated_speed: np.ndarray  # (nv,) peak velocity per limb DoF, rad/s or m/s
    lo: np.ndarray  # (nv,) joint range lower bounds (rad or m)
    hi: np.ndarray
    sites: list[int]  # tool-point site ids, branch order
    limb_bodies: frozenset[int]
    #: Rated joints: (joint id, is a slide, bearing force N, bearing moment N m, the
    #: tool sites carried by the joint).
    bearings: tuple[tuple[int, bool, float, float, tuple[int, ...]], ...] = ()
    #: The limb's base body, whose frame is the mount frame.
    base_body: int = -1
    #: What the limb's names are prefixed with in ``model``.
    prefix: str = ""

    def to_world(self, data: mujoco.MjData, point: np.ndarray) -> np.ndarray:
        """``point`` (m, mount frame) in the world frame (kinematics computed)."""
        b = self.base_body
        return data.xpos[b] + data.xmat[b].reshape(3, 3) @ np.asarray(point, dtype=float)

    def is_limb_geom(self, geom: int) -> bool:
        return bool(self.limb_geoms[geom])

    @cached_property
    def limb_geoms(self) -> np.ndarray:
        """(ngeom,) bool: the geom belongs to the limb."""
        return np.isin(self.model.geom_bodyid, list(self.limb_bodies))


def mount(limb: Limb, carrier: Carrier = Carrier()) -> Mounted:
    """Compile ``limb`` on ``carrier`` (the carrier's joints locked), with one motor per
    limb joint limited to its peak torque."""
    xml, body, pos, quat = _carrier_xml(carrier)
    spec = mujoco.MjSpec.from_string(xml)
    spec.compiler.degree = False
    names = limb.add_to(spec, spec.body(body), pos, quat, carrier.prefix, motors=True)
    for s in limb.sites:
        b = spec.body(carrier.prefix + s.body)
        b.add_site(name=carrier.prefix + s.name, pos=s.pos, quat=s.quat, size=(0.008, 0, 0))
    model = spec.compile()
    peak = np.array([j.peak_torque for j in limb.joints], dtype=float)
    rated_speed = np.array([j.peak_velocity for j in limb.joints], dtype=float)
    rng = limb.joint_ranges()
    sites = [model.site(carrier.prefix + br.site).id for br in limb.branches]
    bearings = []
    for j in limb.joints:
        if math.isinf(j.peak_bearing_force) and math.isinf(j.peak_bearing_moment):
            continue
        jid = model.joint(carrier.prefix + j.name).id
        body = int(model.jnt_bodyid[jid])
        carried = tuple(s for s in sites if _in_subtree(model, int(model.site_bodyid[s]), body))
        slide = int(model.jnt_type[jid]) == mujoco.mjtJoint.mjJNT_SLIDE
        bearings.append((jid, slide, j.peak_bearing_force, j.peak_bearing_moment, carried))
    return Mounted(
        model,
        peak,
        rated_speed,
        rng[:, 0].copy(),
        rng[:, 1].copy(),
        sites,
        frozenset(model.body(n).id for n in names),
        tuple(bearings),
        model.body(names[0]).id,
        carrier.prefix,
    )


def _in_subtree(model: mujoco.MjModel, body: int, root: int) -> bool:
    while body > 0:
        if body == root:
            return True
        body = int(model.body_parentid[body])
    return root == 0


def bearing_loads(
    m: Mounted, data: mujoco.MjData, joint: int, slide: bool, carried: tuple[int, ...]
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """What a joint's bearing (hinge) or guide (slide) carries holding the pose in
    ``data`` (kinematics and ``subtree_com`` computed) still, as ``(f0, f1, t0, t1)``:
    the force [N] is ``f0 + M f1`` and the moment about the joint [N m] ``t0 + M t1``
    with ``M`` kg hung at each tool point the joint carries (world frame). The weight
    of everything beyond the joint is carried there; the motor takes what acts along
    its axis (a slide's force along it, a hinge's moment about it), the bearing the
    rest (a slide's force across its axis and its whole moment, a hinge's whole force
    and its moment about the two axes across its own)."""
    model = m.model
    g = model.opt.gravity
    body = int(model.jnt_bodyid[joint])
    anchor, axis = data.xanchor[joint], data.xaxis[joint]
    mass = float(model.body_subtreemass[body])
    # Weights hang downward: the joint supports them with the opposite force.
    f0 = -mass * g
    t0 = np.cross(data.subtree_com[body] - anchor, -mass * g)
    f1 = -len(carried) * g
    t1 = np.zeros(3)
    for s in carried:
        t1 += np.cross(data.site_xpos[s] - anchor, -g)

    def across(v: np.ndarray) -> np.ndarray:
        return v - np.dot(v, axis) * axis

    if slide:
        return across(f0), across(f1), t0, t1
    return f0, f1, across(t0), across(t1)


def _max_mass_norm(u: np.ndarray, v: np.ndarray, limit: float) -> float:
    """Largest ``M >= 0`` with ``|u + M v| <= limit`` (0 when ``|u| > limit`` already;
    ``inf`` when ``v`` is 0 or the limit infinite)."""
    if math.isinf(limit):
        return math.inf
    uu, uv, vv = float(u @ u), float(u @ v), float(v @ v)
    if uu > limit * limit:
        return 0.0
    if vv < 1e-24:
        return math.inf
    return max((-uv + math.sqrt(max(uv * uv - vv * (uu - limit * limit), 0.0))) / vv, 0.0)


def sample_joint_vectors(lo: np.ndarray, hi: np.ndarray, samples: int, seed: int) -> np.ndarray:
    """The zero pose (clipped into ``[lo, hi]``) and ``samples`` joint vectors drawn
    uniformly inside the ranges with ``numpy.random.default_rng(seed)``."""
    rng = np.random.default_rng(seed)
    q = rng.uniform(lo, hi, size=(samples, len(lo)))
    return np.vstack([np.clip(np.zeros(len(lo)), lo, hi), q])


def sample_poses(m: Mounted, samples: int, seed: int) -> np.ndarray:
    """:func:`sample_joint_vectors` in the mounted limb's joint ranges."""
    return sample_joint_vectors(m.lo, m.hi, samples, seed)


def contacts(m: Mounted, data: mujoco.MjData) -> list[tuple[str, str, bool]]:
    """Contacts involving the limb at the current state: (geom, geom, with carrier)."""
    out = []
    for c in data.contact[: data.ncon]:
        a, b = int(c.geom1), int(c.geom2)
        la, lb = m.is_limb_geom(a), m.is_limb_geom(b)
        if la or lb:
            out.append((m.model.geom(a).name, m.model.geom(b).name, not (la and lb)))
    return out


def carrier_collisions(m: Mounted, q: np.ndarray) -> list[tuple[int, str, str]]:
    """(pose index, limb geom, carrier geom) for every pose of ``q`` where the limb
    touches a geom of the carrier (MuJoCo collision detection, zero margin)."""
    data = mujoco.MjData(m.model)
    out = []
    for k, qk in enumerate(q):
        data.qpos[:] = qk
        mujoco.mj_kinematics(m.model, data)
        mujoco.mj_collision(m.model, data)
        for a, b, with_carrier in contacts(m, data):
            if with_carrier:
                out.append((k, a, b))
    return out


#: Share of the sampled poses a limb must take without touching itself or its carrier
#: for its payload to count (see :func:`payload`): a limb free at a few poses only is no
#: limb that holds anything where it is asked to.
MIN_FREE_SHARE = 0.5


@dataclass(frozen=True)
class PayloadResult:
    """Payload (kg), the worst pose, per-pose limits (kg; ``inf`` where no joint limits
    it) of the free poses at ``min_reach`` (the poses that count), the share of all
    sampled poses that were free, and whether
    the payload is the ``limit`` (the limb holds at least that much: ``bounded``)."""

    mass: float
    worst: int
    poses: np.ndarray
    per_pose: np.ndarray
    free_share: float = 1.0
    bounded: bool = False


def holding_torques(
    m: Mounted, q: np.ndarray, data: mujoco.MjData | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Joint torques (N m / N) that hold pose ``q`` still: ``tau0`` for the limb alone
    (``mj_inverse`` at zero velocity and acceleration, contacts and other constraints
    off) and ``per_kg``, the extra torque per kilogram hung at each tool point
    (``J^T (-g)`` summed over the tool sites). Holding ``M`` kg needs
    ``tau0 + M * per_kg``: torque is linear in the payload mass at a fixed pose.
    ``data`` (reused between calls when given) gets zero velocity and acceleration."""
    model = m.model
    data = data if data is not None else mujoco.MjData(model)
    data.qvel[:] = 0.0
    data.qacc[:] = 0.0
    flags = model.opt.disableflags
    model.opt.disableflags = flags | mujoco.mjtDisableBit.mjDSBL_CONSTRAINT
    try:
        data.qpos[:] = q
        mujoco.mj_inverse(model, data)
        tau0 = data.qfrc_inverse.copy()
    finally:
        model.opt.disableflags = flags
    jac = np.zeros((3, model.nv))
    per_kg = np.zeros(model.nv)
    for s in m.sites:
        mujoco.mj_jacSite(model, data, jac, None, s)
        per_kg += jac.T @ (-model.opt.gravity)
    return tau0, per_kg


def payload(
    limb: Limb,
    carrier: Carrier = Carrier(),
    *,
    samples: int = 32,
    seed: int = 0,
    limit: float = 100.0,
    min_free_share: float = MIN_FREE_SHARE,
    mounted: Mounted | None = None,
    min_reach: float = PAYLOAD_MIN_REACH,
) -> PayloadResult:
    """Largest mass (kg) hung at every tool point that the limb holds at each of the
    zero pose and ``samples`` seeded random poses, every joint within its peak torque.

    Per pose the holding torque is ``tau0 + M * per_kg`` (:func:`holding_torques`), so
    the largest ``M`` with ``|tau_i| <= peak_i`` for all joints is found in closed form;
    the payload is the smallest over the poses, 0 when the limb cannot hold itself at
    some pose. Every sampled pose counts: a pose where the limb touches itself or the
    carrier is one it cannot take, and when fewer than ``min_free_share`` of the poses
    are free the payload is 0 (a limb free at 2 poses of 33 does not score on those
    two). Each joint's bearing or guide must carry its share as well, within the
    component's ``peak_bearing_force`` and ``peak_bearing_moment`` (see
    :func:`bearing_loads`): a horizontal slide whose motor holds nothing still carries
    the load across its axis. The payload is at most ``limit`` kg, a physical bound
    reported as such (``bounded``): a limb whose joints have no ratings and bear no load
    (no joint, or horizontal slides) holds anything its carrier carries.

    The payload is held where it is needed: only the free poses with every tool point
    at least ``min_reach`` m from the mount (the base's origin) count, and a limb with
    none scores 0 (a 2 cm bracket holds much, and nowhere useful).
    """
    check_settings(
        "payload",
        samples=samples,
        seed=seed,
        limit=limit,
        min_free_share=min_free_share,
        min_reach=min_reach,
    )
    m = mounted or mount(limb, carrier)
    poses = sample_poses(m, samples, seed)
    data = mujoco.MjData(m.model)
    keep, far = [], []
    for k, qk in enumerate(poses):
        data.qpos[:] = qk
        mujoco.mj_kinematics(m.model, data)
        mujoco.mj_collision(m.model, data)
        if not contacts(m, data):
            keep.append(k)
            origin = data.xpos[m.base_body]
            if all(np.linalg.norm(data.site_xpos[s] - origin) >= min_reach for s in m.sites):
                far.append(k)
    share = len(keep) / len(poses)
    if share < min_free_share or not far:
        return PayloadResult(0.0, -1, poses[far], np.zeros(0), share)
    poses = poses[far]
    per_pose = np.empty(len(poses))
    for k, qk in enumerate(poses):
        tau0, a = holding_torques(m, qk, data)
        best = _max_mass(tau0, a, m.peak)
        for joint, slide, force, moment, carried in m.bearings:
            f0, f1, t0, t1 = bearing_loads(m, data, joint, slide, carried)
            best = min(best, _max_mass_norm(f0, f1, force), _max_mass_norm(t0, t1, moment))
        per_pose[k] = best
    worst = int(np.argmin(per_pose))
    mass = float(per_pose[worst])
    return PayloadResult(min(mass, limit), worst, poses, per_pose, share, mass >= limit)


def _max_mass(tau0: np.ndarray, a: np.ndarray, peak: np.ndarray) -> float:
    """Largest ``M >= 0`` with ``|tau0 + M a| <= peak`` for every entry (0 when
    ``|tau0| > peak`` somewhere; ``inf`` when nothing bounds it)."""
    if np.any(np.abs(tau0) > peak):
        return 0.0
    best = math.inf
    for t, s, p in zip(tau0, a, peak):
        if s > 1e-12:
            best = min(best, (p - t) / s)
        elif s < -1e-12:
            best = min(best, (-p - t) / s)
    return max(best, 0.0)


def _smooth(s: np.ndarray) -> np.ndarray:
    """Minimum-jerk time scaling 0 -> 1 (zero velocity and acceleration at both ends)."""
    return s**3 * (10 - 15 * s + 6 * s**2)


def reference_path(center: np.ndarray, radius: float, duration: float, n: int) -> np.ndarray:
    """``n`` points (m) of the reference over ``duration`` s: a full circle of ``radius``
    about ``center`` in the carrier's y-z plane (a vertical plane facing along x) in the
    first half, then a straight line along y through the centre, from ``+radius`` to
    ``-radius``, in the second; both start and stop at rest (minimum-jerk timing)."""
    t = np.linspace(0.0, duration, n)
    half = duration / 2
    out = np.empty((n, 3))
    first = t <= half
    ang = 2 * np.pi * _smooth(np.clip(t / half, 0, 1))
    out[first] = (
        center + radius * np.stack([np.zeros_like(ang), np.cos(ang), np.sin(ang)], axis=1)[first]
    )
    s = _smooth(np.clip((t - half) / half, 0, 1))
    line = center + radius * np.stack([np.zeros_like(s), 1 - 2 * s, np.zeros_like(s)], axis=1)
    out[~first] = line[~first]
    return out


def waypoint_path(center: np.ndarray, waypoints: np.ndarray, duration: float, n: int) -> np.ndarray:
    """``n`` points (m) of a reference through ``center + waypoints[k]`` in order over
    ``duration`` s, each leg given the same time and started and stopped at rest
    (minimum-jerk timing); the first waypoint is where the reference starts."""
    wp = center + np.asarray(waypoints, dtype=float)
    legs = len(wp) - 1
    t = np.linspace(0.0, duration, n)
    u = np.clip(t / duration * legs, 0.0, legs)
    k = np.minimum(u.astype(int), legs - 1)
    s = _smooth(u - k)[:, None]
    return wp[k] + s * (wp[k + 1] - wp[k])


def ik_path(
    m: Mounted,
    targets: np.ndarray,
    q0: np.ndarray,
    iters: int = 6,
    damping: float = 0.1,
    max_step: float = 0.02,
) -> np.ndarray:
    """Joint vectors following ``targets`` (m) with the first tool point, by damped least
    squares (``dq = J^T (J J^T + damping^2 I)^-1 e``, ``damping`` in m, the error ``e``
    shortened to at most ``max_step`` m per iteration so the solution moves
    continuously), warm-started from the previous point (``q0`` first; the first point
    gets fifty times the iterations: the reference starts far from the display pose),
    clipped to the joint ranges.

    A fixed number of iterations, each a smooth function of the last: the joint path,
    and so every score computed from it, moves by as little as the model does. A stop
    once the error is small, or a damping of 0.01 m, made it chaotic where a target is
    out of reach (the iteration overshoots and wanders): a 1e-9 change of a mass moved
    the tracking error of 17 of 48 random designs by 3-87%; with these settings none
    moves by more than 2e-9 of its value (72 designs).
    """
    model, data = m.model, mujoco.MjData(m.model)
    site = m.sites[0]
    jac = np.zeros((3, model.nv))
    q = np.clip(np.asarray(q0, dtype=float), m.lo, m.hi)
    out = np.empty((len(targets), model.nv))
    eye = damping**2 * np.eye(3)
    chol, step = np.empty((3, 3)), np.empty(3)
    for k, target in enumerate(targets):
        for _ in range(iters * (50 if k == 0 else 1)):
            data.qpos[:] = q
            mujoco.mj_kinematics(model, data)
            err = target - data.site_xpos[site]
            norm = math.sqrt(float(err @ err))
            if norm > max_step:
                err *= max_step / norm
            mujoco.mj_comPos(model, data)
            mujoco.mj_jacSite(model, data, jac, None, site)
            # (J J^T + damping^2 I) is symmetric positive definite: MuJoCo's Cholesky
            # solves it in a third of numpy's time for a 3x3.
            np.add(jac @ jac.T, eye, out=chol)
            mujoco.mju_cholFactor(chol, 0.0)
            mujoco.mju_cholSolve(step, chol, err)
            q = np.clip(q + jac.T @ step, m.lo, m.hi)
        out[k] = q
    return out


@dataclass(frozen=True)
class TrackResult:
    """A tracking run: RMS tool-point error (m), mean mechanical power (W), the
    reference and actual tool paths (m, world = carrier frame) sampled every step, the
    share of steps at which the limb touched itself or its carrier (contacts are on:
    what touches is pushed back, and the run is scored by what the limb achieves), the
    first touch as (time s, geom, geom), and the largest joint speed as a multiple of
    that joint's rating (``peak_velocity``; 1.0 is at the rating)."""

    error: float
    power: float
    reference: np.ndarray
    path: np.ndarray
    dt: float
    contact_share: float = 0.0
    first_contact: tuple[float, str, str] | None = None
    speed_ratio: float = 0.0
    #: The first step at which two parts of the limb overlap where MuJoCo does not look
    #: (a body and its parent: :mod:`robotwright.grammar.overlap`), as (time s, part,
    #: part, depth m); ``None`` when none does.
    first_overlap: tuple[float, str, str, float] | None = None
    #: Joint positions (rad or m) and velocities (rad/s or m/s) at every step, in the
    #: limb's joint order.
    qpos: np.ndarray | None = None
    qvel: np.ndarray | None = None


def rate_limited(q: np.ndarray, dt: float, speed: np.ndarray) -> np.ndarray:
    """``q`` (samples x joints, every ``dt`` s) followed as closely as joints moving at
    most ``speed`` (rad/s or m/s, per joint) can: each sample moves from the last by at
    most ``speed * dt``, so the path lags where ``q`` asks for more. A continuous
    function of ``q``: a small change of the input changes the output as little."""
    out = np.empty_like(q)
    out[0] = q[0]
    step = np.asarray(speed, dtype=float) * dt
    for k in range(1, len(q)):
        out[k] = out[k - 1] + np.clip(q[k] - out[k - 1], -step, step)
    return out


#: Share of each joint's rated speed the tracking reference may ask for: the controller
#: overshoots its reference a little, and the rating is what the joint must not exceed.
REFERENCE_SPEED_SHARE = 0.9


def track(
    limb: Limb,
    carrier: Carrier = Carrier(),
    *,
    duration: float = 2.0,
    scale: float = 0.15,
    omega: float = 30.0,
    reach: float | None = None,
    mounted: Mounted | None = None,
    path: tuple[tuple[float, float, float], ...] | None = None,
    center: tuple[float, float, float] | None = TRACK_CENTER,
    radius: float | None = TRACK_RADIUS,
) -> TrackResult:
    """Follow the reference of :func:`reference_path` with the first tool point (or,
    given ``path``, the waypoints of :func:`waypoint_path`: offsets [m] from the
    reference's centre, world frame).

    Reference: centred on ``center`` (m, mount frame: the limb's base), or with
    ``center=None`` on the tool point at the limb's display pose (revolute joints at
    +-0.5 rad, prismatic at mid-stroke); radius ``radius`` m, or with ``radius=None``
    ``scale`` times the limb's reach (the largest tool-point distance from the base over
    256 seeded poses, or ``reach`` m). The built-in target (:data:`TRACK_CENTER`,
    :data:`TRACK_RADIUS`) is the same for every design; the relative one follows the
    design (and rewards a limb too small to do anything).
    Joint reference: damped-least-squares IK (damping 0.1 m, a fixed number of
    iterations: see :func:`ik_path`) at 100 Hz, slowed where it would move a joint
    faster than :data:`REFERENCE_SPEED_SHARE` of its rated speed (:func:`rate_limited`:
    a design that cannot keep up lags, and is scored by the path it achieves); it, its
    velocity and acceleration (finite differences at 100 Hz) are interpolated to each
    step.
    Controller (every 0.002 s step of the carrier model): ``tau = M(q) (qdd_ref + kp e +
    kd de) + bias(q, dq)`` with ``kp = omega^2``, ``kd = 2 omega`` (a PD law scaled by
    the inertia, plus gravity and velocity-bias compensation), clipped by MuJoCo to
    +-peak torque. Contacts are on, against the carrier and the limb itself (MuJoCo's
    default filter: not between a body and its parent), and every step's contacts are
    recorded; joint limits stay on. The limb starts at rest on the reference.

    Returns:
        RMS distance (m) between tool point and reference over the run, and the mean
        over steps of ``sum |tau_i * dq_i|`` (W; N m rad/s or N m/s).
    """
    check_settings("track", duration=duration, scale=scale, omega=omega)
    if reach is not None:
        check_settings("track", reach=reach)
    if radius is not None:
        check_settings("track", radius=radius)
    m = mounted or mount(limb, carrier)
    model = m.model
    dt = float(model.opt.timestep)
    steps = max(1, int(round(duration / dt)))
    data = mujoco.MjData(model)
    qn = display_pose(limb) if limb.joints else np.zeros(0)
    data.qpos[:] = qn
    mujoco.mj_kinematics(model, data)
    if center is None:
        middle = data.site_xpos[m.sites[0]].copy()
    else:
        middle = m.to_world(data, np.asarray(center, dtype=float))
    # The reference at n points (the tool path computed below is named ``path`` too:
    # the waypoints are bound now).
    if path is not None:
        reference = partial(waypoint_path, middle, np.asarray(path, dtype=float), duration)
    else:
        if radius is None:
            radius = scale * (_reach(limb) if reach is None else reach)
        reference = partial(reference_path, middle, radius, duration)
    ref = reference(steps + 1)
    nv = model.nv
    if nv == 0:
        path = np.repeat(data.site_xpos[m.sites[0]][None], steps + 1, axis=0)
        err = np.linalg.norm(path - ref, axis=1)
        return TrackResult(float(np.sqrt(np.mean(err**2))), 0.0, ref, path, dt)
    coarse = max(2, int(round(duration * 100)) + 1)
    tc = np.linspace(0.0, duration, coarse)
    qc = rate_limited(
        ik_path(m, reference(coarse), qn), tc[1] - tc[0], REFERENCE_SPEED_SHARE * m.rated_speed
    )
    t = np.linspace(0.0, duration, steps + 1)
    # Velocities and accelerations from the 100 Hz samples, then interpolated: the
    # derivatives of the piecewise-linear interpolant would be spikes at every sample.
    vc = np.gradient(qc, tc, axis=0)
    ac = np.gradient(vc, tc, axis=0)
    qr, vr, ar = (
        np.stack([np.interp(t, tc, x[:, i]) for i in range(nv)], axis=1) for x in (qc, vc, ac)
    )
    data = mujoco.MjData(model)
    data.qpos[:] = qr[0]
    mujoco.mj_forward(model, data)
    path = np.empty((steps + 1, 3))
    path[0] = data.site_xpos[m.sites[0]]
    qpos, qvel = np.empty((steps + 1, nv)), np.zeros((steps + 1, nv))
    qpos[0] = data.qpos
    mv = np.zeros(nv)
    power = 0.0
    fastest = 0.0
    touching = 0
    first: tuple[float, str, str] | None = None
    limb_geoms = m.limb_geoms
    rated = np.where(m.rated_speed > 0, m.rated_speed, np.inf)
    kp, kd = omega**2, 2 * omega
    for k in range(steps):
        mujoco.mj_step1(model, data)
        e = qr[k] - data.qpos
        de = vr[k] - data.qvel
        mujoco.mj_mulM(model, data, mv, ar[k] + kp * e + kd * de)
        data.ctrl[:] = mv + data.qfrc_bias
        mujoco.mj_step2(model, data)
        # the force MuJoCo applied (after clipping) times the velocity it produced
        power += float(np.abs(data.qfrc_actuator * data.qvel).sum())
        fastest = max(fastest, float(np.max(np.abs(data.qvel) / rated)))
        path[k + 1] = data.site_xpos[m.sites[0]]
        qpos[k + 1], qvel[k + 1] = data.qpos, data.qvel
        if data.ncon:  # found by mj_step1, at the state before this step: time k * dt
            geoms = data.contact.geom[: data.ncon]
            hit = limb_geoms[geoms].any(axis=1)
            if hit.any():
                touching += 1
                if first is None:
                    a, b = geoms[int(np.argmax(hit))]
                    first = (k * dt, model.geom(int(a)).name, model.geom(int(b)).name)
    mujoco.mj_kinematics(model, data)
    path[-1] = data.site_xpos[m.sites[0]]
    err = np.linalg.norm(path - ref, axis=1)
    # MuJoCo's contacts above watched every other pair at every step.
    check = OverlapCheck(limb, model, m.prefix, hidden_only=True)
    found = check.over(qpos, first_only=True)
    overlap = (found[0].pose * dt, found[0].a, found[0].b, found[0].depth) if found else None
    return TrackResult(
        float(np.sqrt(np.mean(err**2))),
        power / steps,
        ref,
        path,
        dt,
        touching / steps,
        first,
        fastest,
        overlap,
        qpos,
        qvel,
    )


def display_pose(limb: Limb, angle: float = 0.5) -> np.ndarray:
    """The pose the pictures show: hinges at +-``angle`` rad (alternating, within
    limits), slides at mid-stroke (the same rule as :func:`grammar.draw.display_pose`,
    without importing matplotlib)."""
    q = []
    for i, j in enumerate(limb.joints):
        lo, hi = j.range
        v = angle * (-1) ** i if j.type == "hinge" else (lo + hi) / 2
        q.append(min(max(v, lo), hi))
    return np.array(q, dtype=float)


def _reach(limb: Limb, samples: int = 256, seed: int = 0) -> float:
    """Largest tool-point distance (m) from the limb's base over seeded poses."""
    rng = np.random.default_rng(seed)
    names = [j.name for j in limb.joints]
    lo, hi = limb.joint_ranges().T if limb.joints else (np.zeros(0), np.zeros(0))
    q = np.vstack(
        [np.clip(np.zeros(len(names)), lo, hi), rng.uniform(lo, hi, (samples, len(names)))]
    )
    best = 0.0
    for br in limb.branches:
        cols = [names.index(n) for n in br.joints]
        pts = br.tool_pose(q[:, cols])[..., :3, 3]
        best = max(best, float(np.linalg.norm(pts, axis=1).max()))
    return best
