"""Things <-> HRDF: load a robot into an editable Body tree, and save a tree as HRDF.

``hrdf_to_body(robot)`` gives the robot's root :class:`Body` (attach it to a World or to
another robot's body); ``hrdf_to_world(robot)`` also carries the simulator settings and
the robot's ``mjcf_extra`` sections. The mapping mirrors
:class:`robotwright.generators.MJCFHumanoidGenerator`, so the compiled models are equal.

``things_to_hrdf(tree)`` goes back. Body inertials are taken from MuJoCo's compiled
model (so bodies whose mass comes from their geoms get exactly the mass MuJoCo computes);
Thing attributes HRDF has no column for are reported in a
:class:`~robotwright.errors.ConversionWarning` naming the Thing and attribute (or raise
:class:`~robotwright.errors.ConversionError` with ``strict=True``).
"""

from __future__ import annotations

import copy
import warnings
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from robotwright.errors import ConversionError, ConversionWarning, Problem
from robotwright.hrdf import model as H
from robotwright.things import actuators as A
from robotwright.things import sensors as S
from robotwright.things.base import BaseThing
from robotwright.things.body import Body
from robotwright.things.geoms import GEOM_CLASSES, Geom, Mesh
from robotwright.things.joints import JOINT_CLASSES, Joint
from robotwright.things.sites import Site
from robotwright.things.world import World

_IMU_SENSORS = {"quat": "framequat", "angvel": "gyro", "linacc": "accelerometer"}


def _report(problems: list[Problem], strict: bool, what: str) -> None:
    """One warning (or, with ``strict``, one error) listing what was not kept."""
    if not problems:
        return
    if strict:
        raise ConversionError(problems, what)
    shown = "; ".join(str(p) for p in problems[:6])
    more = f" (+{len(problems) - 6} more)" if len(problems) > 6 else ""
    warnings.warn(
        ConversionWarning(f"{what}: {len(problems)} value(s) not kept: {shown}{more}"),
        stacklevel=3,
    )


# ====================================================================== HRDF -> Things
def hrdf_to_body(robot: H.HRDF, *, strict: bool = False) -> Body:
    """The robot as a Thing tree: its root :class:`Body` with all bodies, joints,
    actuators, geoms, sites, sensors and IMUs (as a site with framequat/gyro/
    accelerometer sensors, as the MJCF generator writes them).

    HRDF columns MuJoCo has no field for (peak velocity, restitution, static friction,
    motor gains) and the robot's metadata ride along in ``extras`` for
    :func:`things_to_hrdf`. ``mjcf_extra`` cannot live on a Body: use
    :func:`hrdf_to_world` to keep it (here it is reported as not kept).
    """
    body, problems = _hrdf_tree(robot)
    body.extras["hrdf_meta"] = copy.deepcopy(robot.meta)
    body.extras["hrdf_name"] = robot.name
    if robot.mjcf_extra and robot.mjcf_extra.strip():
        problems.append(
            Problem(
                "mjcf_extra",
                "tendon/equality/contact/keyframe sections are not kept on a Body; "
                "use hrdf_to_world",
            )
        )
    _report(problems, strict, f"robot '{robot.name}' to Things")
    return body


def hrdf_to_world(robot: H.HRDF, *, strict: bool = False) -> World:
    """A World holding the robot, its simulator settings and its ``mjcf_extra``."""
    body, problems = _hrdf_tree(robot)
    world = World(robot.name)
    world.extras["hrdf_meta"] = copy.deepcopy(robot.meta)
    sim = robot.meta.simulator_config
    if sim is not None:
        if sim.timestep is not None:
            world.timestep = sim.timestep
        if sim.gravity is not None:
            world.gravity = sim.gravity
        if sim.integrator is not None:
            world.integrator = sim.integrator
    world.attach(body)
    if robot.mjcf_extra and robot.mjcf_extra.strip():
        from defusedxml import ElementTree as SafeET

        root = SafeET.fromstring(robot.mjcf_extra)
        for section in root:
            if section.tag in _EXTRA_SECTIONS:
                ET.indent(section, space="  ", level=1)
                text = ET.tostring(section, encoding="unicode").strip()
                world.extra_xml[section.tag] = "  " + text
            else:
                problems.append(Problem("mjcf_extra", f"section <{section.tag}> is not kept"))
    _report(problems, strict, f"robot '{robot.name}' to Things")
    return world


_EXTRA_SECTIONS = ("default", "contact", "equality", "tendon", "keyframe")


def _hrdf_tree(robot: H.HRDF) -> tuple[Body, list[Problem]]:
    problems: list[Problem] = []
    bodies: list[Body] = []
    for b in robot.bodies:
        bodies.append(
            Body(
                b.name,
                pos=b.pos,
                quat=b.quat,
                mass=b.mass,
                ipos=b.inertial_pos,
                iquat=b.inertial_quat,
                inertia=b.diag_inertia,
            )
        )
    by_name = {b.name: t for b, t in zip(robot.bodies, bodies, strict=True)}
    joints: dict[str, Joint] = {}
    for j in robot.joints:
        cls = next(c for c in JOINT_CLASSES if c.type == j.type)
        kw: dict[str, Any] = {
            "armature": j.armature,
            "damping": [j.viscous_friction],
            "frictionloss": j.dynamic_friction,
            "stiffness": [j.stiffness],
        }
        if j.type != "free":
            kw.update(pos=j.pos, springref=j.springref, ref=j.ref)
            if j.range is not None:
                kw.update(range=j.range, limited="true")
        if j.type in ("hinge", "slide"):
            kw["axis"] = j.axis
        if j.static_friction:  # no MuJoCo field: kept for the way back to HRDF
            kw["extras"] = {"hrdf": {"static_friction": j.static_friction}}
        joint = cls(j.name, **kw)
        by_name[j.body].attach(joint)
        if j.name is not None:
            joints[j.name] = joint
    for a in robot.actuators:
        joints[a.joint].attach(_actuator(a))
    for m in robot.meshes:
        geom = Mesh(
            m.geom_name,
            file=str(robot.mesh_source(m)),
            scale=m.scale,
            mesh=m.name,
            **_geom_kw(m),
        )
        by_name[m.body].attach(geom)
    for g in robot.simple_geoms:
        cls = next(c for c in GEOM_CLASSES if c.type == g.type)
        by_name[g.body].attach(cls(g.geom_name or g.name or None, size=g.size, **_geom_kw(g)))
    sites: dict[str, Site] = {}
    for s in robot.sites:
        site = Site(
            s.name, pos=s.pos, quat=s.quat, type=s.type, size=s.size, rgba=s.rgba, group=s.group
        )
        by_name[s.body].attach(site)
        sites[s.name] = site
    # Child bodies after each body's own elements, so walking the tree lists joints and
    # geoms in the order of the HRDF tables.
    for b, thing in zip(robot.bodies, bodies, strict=True):
        if b.parent >= 0:
            bodies[b.parent].attach(thing)
    # IMUs exactly as the MJCF generator writes them (a site, then one sensor per value)
    from robotwright.generators.mjcf import imu_sites

    for imu, (name, new) in zip(robot.meta.imu_config_list or [], imu_sites(robot), strict=True):
        if new:
            sites[name] = Site(name, pos=imu.position, quat=imu.orientation)
            sites[name].extras["hrdf_imu"] = True
            by_name[imu.body_name].attach(sites[name])
        for value in imu.value:
            sensor = S.SENSOR_CLASSES[_IMU_SENSORS[value]](f"{name}_{value}")
            sensor.extras["hrdf_imu"] = True
            sites[name].attach(sensor)
    for extra in robot.root_indices[1:]:
        problems.append(
            Problem(
                "meta.yaml",
                f"body '{robot.bodies[extra].name}' is another root of the scene: a Things "
                "tree holds one robot, so it and its subtree are dropped",
                column="body_parent_id",
            )
        )
    named: dict[tuple[str, str], BaseThing] = {}
    for thing in bodies[robot.root_index].walk():
        if thing._NAMESPACE and thing._name:
            named[(thing._NAMESPACE, thing._name)] = thing
    for row, s in enumerate(robot.sensors):
        sensor_cls = S.SENSOR_CLASSES.get(s.type)
        target = named.get(("body" if s.objtype == "xbody" else s.objtype, s.objname))
        if sensor_cls is None or target is None:
            problems.append(
                Problem(
                    "sensor.csv",
                    f"sensor '{s.name}' ({s.type} on {s.objtype} '{s.objname}') cannot be "
                    "represented; dropped",
                    row,
                    "type",
                )
            )
            continue
        skw: dict[str, Any] = {"noise": s.noise, "cutoff": s.cutoff}
        if issubclass(sensor_cls, S.FrameSensor):
            if s.objtype == "xbody":
                skw["objtype"] = "xbody"
            if s.reftype is not None and s.refname is not None:
                skw.update(reftype=s.reftype, refname=s.refname)
        target.attach(sensor_cls(s.name, **skw))
    return bodies[robot.root_index], problems


def _geom_kw(g: H.Geom) -> dict[str, Any]:
    # restitution and a separate dynamic friction have no MuJoCo field: kept in extras
    hrdf_only: dict[str, Any] = {
        "restitution": g.restitution,
        "dynamic_friction": g.dynamic_friction,
        "geom_name": g.geom_name,
    }
    if isinstance(g, H.SimpleGeom):
        hrdf_only["name"] = g.name
    return {
        "extras": {"hrdf": hrdf_only},
        "pos": g.pos,
        "quat": g.quat,
        "rgba": g.rgba,
        "contype": g.contact_type,
        "conaffinity": g.contact_affinity,
        "condim": g.condim,
        "group": g.group,
        "friction": [g.static_friction, g.torsional_friction, g.rolling_friction],
    }


def _actuator(a: H.Actuator) -> A.Actuator:
    """An HRDF actuator as the MJCF generator writes it."""
    kw: dict[str, Any] = {"gear": [a.gear]}
    # Columns MuJoCo has no field for ride along for the way back to HRDF.
    hrdf_only: dict[str, Any] = {
        "peak_torque": a.peak_torque,
        "peak_velocity": a.peak_velocity,
        "ctrl_range": a.ctrl_range,
        "force_range": a.force_range,
    }
    ctrl, force = a.ctrl_range, a.force_range
    if a.type == "motor":
        cls: type[A.Actuator] = A.Motor
        if ctrl is None and a.peak_torque is not None:
            ctrl = (-a.peak_torque, a.peak_torque)
        hrdf_only.update(p_gain=a.p_gain, d_gain=a.d_gain)
    else:
        cls = A.Position if a.type == "position" else A.Velocity
        if force is None and a.peak_torque is not None:
            force = (-a.peak_torque, a.peak_torque)
        if a.type == "position" and a.p_gain is not None:
            kw["kp"] = a.p_gain
        if a.type == "velocity":
            hrdf_only["p_gain"] = a.p_gain
        if a.d_gain is not None:
            kw["kv"] = a.d_gain
    if ctrl is not None:
        kw.update(ctrlrange=ctrl, ctrllimited="true")
    if force is not None:
        kw.update(forcerange=force, forcelimited="true")
    return cls(a.name, extras={"hrdf": hrdf_only}, **kw)


# ====================================================================== Things -> HRDF
# Attributes each Thing class maps to HRDF columns (others must equal MuJoCo defaults).
_MAPPED: dict[str, set[str]] = {
    "body": {"pos", "quat", "mass", "ipos", "iquat", "inertia", "fullinertia"},
    "joint": {
        "pos",
        "axis",
        "range",
        "limited",
        "armature",
        "damping",
        "frictionloss",
        "stiffness",
        "springref",
        "ref",
    },
    "geom": {
        "size",
        "pos",
        "quat",
        "contype",
        "conaffinity",
        "condim",
        "group",
        "friction",
        "rgba",
        "mass",
        "density",
        "shellinertia",
        "mesh",
        "file",
        "scale",
    },
    "site": {"type", "size", "pos", "quat", "rgba", "group"},
    "actuator": {"gear", "ctrlrange", "ctrllimited", "forcerange", "forcelimited", "kp", "kv"},
    "sensor": {"noise", "cutoff", "objtype", "reftype", "refname"},
}


def things_to_hrdf(
    tree: Body | World, name: str | None = None, *, strict: bool = False, meta: H.Meta | None = None
) -> H.HRDF:
    """An HRDF robot from a Thing tree (a Body, or a World with exactly one top-level body).

    Args:
        tree: the robot. A World's own geoms/lights/... (the scene) are not part of it.
        name: robot name (default: the World's or root body's name).
        strict: raise instead of warning when an attribute cannot be represented.
        meta: metadata to keep (body names config, ...); the simulator settings of a
            World replace its ``simulator_config``.
    """
    problems: list[Problem] = []
    world = tree if isinstance(tree, World) else None
    if world is not None:
        roots = world.bodies
        if len(roots) != 1:
            raise ConversionError(
                [
                    Problem(
                        world._label(),
                        f"expected one top-level body (the robot's root), found {len(roots)}",
                    )
                ],
                "Things to HRDF",
            )
        root = roots[0]
        for thing in world.children:
            if thing is not root:
                problems.append(
                    Problem(
                        world._label(),
                        f"{getattr(thing, 'xml', None) or thing._label()} belongs to the world "
                        "(scene), not to the robot's tree; not kept",
                    )
                )
    else:
        root = tree
    robot_name = (
        name
        or (world.name if world is not None and world.name else None)
        or root.extras.get("hrdf_name")
        or root.name
        or "robot"
    )
    kept_meta = meta
    if kept_meta is None and world is not None:
        kept_meta = world.extras.get("hrdf_meta")
    if kept_meta is None:
        kept_meta = root.extras.get("hrdf_meta")
    hrdf_meta = copy.deepcopy(kept_meta) if kept_meta is not None else H.Meta()
    # IMUs listed in the metadata are written by the generators from it: skip the
    # site/sensors made from them, or they would appear twice.
    skip_imu = bool(hrdf_meta.imu_config_list)
    model, index = _compile_alone(root)
    names = root._resolved_names()
    bodies: list[H.Body] = []
    body_row: dict[int, int] = {}
    joints: list[H.Joint] = []
    actuators: list[tuple[int, H.Actuator]] = []
    meshes: list[H.MeshGeom] = []
    simple: list[H.SimpleGeom] = []
    sites: list[H.Site] = []
    sensors: list[tuple[int, H.Sensor]] = []

    def nm(thing: BaseThing, fallback: str) -> str:
        return names.get(thing.ID) or fallback

    for thing in root.walk():
        ns = thing._NAMESPACE
        if skip_imu and thing.extras.get("hrdf_imu"):
            continue
        if ns not in _MAPPED and ns != "raw":
            problems.append(
                Problem(thing._label(), f"a {type(thing).__name__} has no HRDF table; not kept")
            )
            continue
        if ns == "raw":
            problems.append(
                Problem(thing._label(), f"{thing.xml}: verbatim MJCF has no HRDF table; not kept")
            )
            continue
        _check_unmapped(thing, problems)
        if ns == "body":
            i = index[thing.ID]
            body_row[thing.ID] = len(bodies)
            bodies.append(
                H.Body(
                    name=nm(thing, f"body{len(bodies)}"),
                    parent=body_row[thing._parent.ID] if thing is not root else -1,
                    pos=_t(thing.pos),
                    quat=_t(thing.quat),
                    **_inertial(thing, model, i),
                )
            )
        elif ns == "joint":
            joints.append(
                _hrdf_joint(thing, nm(thing, ""), bodies[body_row[thing._parent.ID]].name, world)
            )
        elif ns == "geom":
            body_name = bodies[body_row[thing._parent.ID]].name
            g = _hrdf_geom(thing, nm(thing, ""), body_name, len(simple), problems)
            if isinstance(g, H.MeshGeom):
                meshes.append(g)
            elif g is not None:
                simple.append(g)
        elif ns == "site":
            sites.append(
                H.Site(
                    name=nm(thing, f"site{len(sites)}"),
                    body=bodies[body_row[thing._parent.ID]].name,
                    pos=_t(thing.pos),
                    quat=_t(thing.quat),
                    type=thing.type,
                    size=_t(thing.size),
                    rgba=_t(thing.rgba),
                    group=thing.group,
                )
            )
        elif ns == "actuator":
            a = _hrdf_actuator(thing, names, problems)
            if a is not None:
                actuators.append((thing.ID, a))
        elif ns == "sensor":
            target = thing._parent
            objtype = getattr(thing, "objtype", None) or target._NAMESPACE
            ref = getattr(thing, "refname", None)
            sensors.append(
                (
                    thing.ID,
                    H.Sensor(
                        name=nm(thing, f"{nm(target, 'sensor')}_{thing._TAG}"),
                        type=thing._TAG,
                        objtype=objtype,
                        objname=nm(target, ""),
                        reftype=(
                            thing.reftype
                            or (ref._NAMESPACE if isinstance(ref, BaseThing) else "body")
                        )
                        if ref is not None
                        else None,
                        refname=(ref if isinstance(ref, str) or ref is None else names[ref.ID]),
                        noise=thing.noise,
                        cutoff=thing.cutoff,
                    ),
                )
            )
    if world is not None:
        sim = hrdf_meta.simulator_config or H.SimulatorConfig()
        hrdf_meta.simulator_config = H.SimulatorConfig(
            timestep=world.timestep,
            gravity=_t(world.gravity),
            ground=sim.ground,
            integrator=world.integrator if world.integrator != "Euler" else None,
        )
    extra = None
    if world is not None and world.extra_xml:
        kept = [
            world.extra_xml[k]
            for k in ("default", "contact", "equality", "tendon", "keyframe")
            if k in world.extra_xml
        ]
        dropped = [
            k
            for k in world.extra_xml
            if k not in ("default", "contact", "equality", "tendon", "keyframe")
        ]
        for k in dropped:
            problems.append(
                Problem(world._label(), f"MJCF section <{k}> (scene settings) is not kept")
            )
        if kept:
            extra = "<mujoco>\n" + "\n".join(kept) + "\n</mujoco>\n"
    _report(problems, strict, f"Things to HRDF robot '{robot_name}'")
    return H.HRDF(
        name=robot_name,
        bodies=bodies,
        joints=joints,
        actuators=[a for _, a in sorted(actuators, key=lambda p: p[0])],
        meshes=meshes,
        simple_geoms=simple,
        sites=sites,
        sensors=[s for _, s in sorted(sensors, key=lambda p: p[0])],
        meta=hrdf_meta,
        mjcf_extra=extra,
    )


def _inertial(body: Body, model: mujoco.MjModel, i: int) -> dict[str, Any]:
    """HRDF inertial columns: the Body's own explicit values when MuJoCo kept them as
    given, else what MuJoCo computed (from the geoms, a full tensor, total-mass scaling)."""
    explicit = (
        body.mass is not None
        and body.inertia is not None
        and body.fullinertia is None
        and float(model.body_mass[i]) == body.mass
    )
    if explicit:
        return {
            "mass": body.mass,
            "inertial_pos": _t(body.ipos if body.ipos is not None else H.ZERO3),
            "inertial_quat": _t(body.iquat if body.iquat is not None else H.IDENTITY_QUAT),
            "diag_inertia": _t(body.inertia),
        }
    return {
        "mass": float(model.body_mass[i]),
        "inertial_pos": _t(model.body_ipos[i]),
        "inertial_quat": _t(model.body_iquat[i]),
        "diag_inertia": _t(model.body_inertia[i]),
    }


def _compile_alone(root: Body) -> tuple[mujoco.MjModel, dict[int, int]]:
    """Compile a body subtree on its own to read MuJoCo's inertials."""
    if isinstance(root._parent, World):
        world = root._parent
    else:
        # A temporary World around a detached copy would renumber IDs; instead borrow the
        # tree: attach to a scratch World, compile, and put it back where it was.
        parent = root._parent
        position = parent._children.index(root) if parent is not None else None
        world = World()
        world.attach(root)
        try:
            model, _, index = world._ensure_built()
        finally:
            root.detach()
            if parent is not None:
                parent._children.insert(position, root)
                object.__setattr__(root, "_parent", parent)
                parent._touch()
        return model, index
    model, _, index = world._ensure_built()
    return model, index


def _check_unmapped(thing: BaseThing, problems: list[Problem]) -> None:
    mapped = _MAPPED[thing._NAMESPACE]
    shared = type(thing).__dict__.get("_INIT_DEFAULTS") or {}
    for key, spec in thing._MUJOCO_ATTR.items():
        if key in mapped or key in thing._DERIVED_ATTR:
            continue
        value = thing.__dict__.get(key)
        if value is None or value is shared.get(key, False):
            continue
        default = thing._DEFAULT_VALS.get(key)
        if not spec.equal(value, default):
            problems.append(
                Problem(
                    thing._label(),
                    f"attribute '{key}' = {value!r} has no HRDF column; not kept",
                    column=key,
                )
            )
    if thing._NAMESPACE == "joint":
        for key in ("damping", "stiffness"):
            if np.any(getattr(thing, key)[1:]):
                problems.append(
                    Problem(
                        thing._label(), f"only the first coefficient of '{key}' is kept", column=key
                    )
                )
    if thing._NAMESPACE == "actuator" and np.any(thing.gear[1:]):
        problems.append(Problem(thing._label(), "only gear[0] is kept", column="gear"))


def _limited(flag: str, rng: Any, autolimits: bool) -> bool:
    if flag == "auto":
        return autolimits and bool(rng[0] != 0 or rng[1] != 0)
    return flag == "true"


def _hrdf_joint(j: Any, name: str, body: str, world: World | None) -> H.Joint:
    autolimits = world.autolimits if world is not None else True
    limited = j.type != "free" and _limited(j.limited, j.range, autolimits)
    return H.Joint(
        name=name or None,
        body=body,
        type=j.type,
        pos=_t(j.pos) if j.type != "free" else H.ZERO3,
        axis=_t(j.axis) if j.type in ("hinge", "slide") else (0.0, 0.0, 1.0),
        range=_t(j.range) if limited else None,
        armature=j.armature,
        static_friction=j.extras.get("hrdf", {}).get("static_friction", 0.0),
        dynamic_friction=j.frictionloss,
        viscous_friction=float(j.damping[0]),
        stiffness=float(j.stiffness[0]),
        springref=getattr(j, "springref", 0.0),
        ref=getattr(j, "ref", 0.0),
    )


def _hrdf_geom(g: Geom, name: str, body: str, i: int, problems: list[Problem]) -> H.Geom | None:
    kept = g.extras.get("hrdf", {})
    common: dict[str, Any] = {
        "restitution": kept.get("restitution"),
        "body": body,
        "pos": _t(g.pos),
        "quat": _t(g.quat),
        "rgba": _t(g.rgba),
        "contact_type": g.contype,
        "contact_affinity": g.conaffinity,
        "static_friction": float(g.friction[0]),
        "dynamic_friction": float(kept.get("dynamic_friction", g.friction[0])),
        "torsional_friction": float(g.friction[1]),
        "rolling_friction": float(g.friction[2]),
        "group": g.group,
        "condim": g.condim,
        "geom_name": name or None,
    }
    if kept.get("name") is not None and name == (kept.get("geom_name") or kept["name"]):
        # unchanged since read from HRDF: restore its two name columns exactly
        common["geom_name"] = kept.get("geom_name")
        name = kept["name"]
    if isinstance(g, Mesh):
        if g.file is None:
            problems.append(
                Problem(g._label(), "a mesh given by inline vertices has no HRDF file; not kept")
            )
            return None
        asset = g.mesh or Path(g.file).stem
        return H.MeshGeom(name=asset, file=str(Path(g.file).resolve()), scale=_t(g.scale), **common)
    if g.type not in H.SIMPLE_GEOM_TYPES:
        problems.append(Problem(g._label(), f"geom type '{g.type}' has no HRDF table; not kept"))
        return None
    return H.SimpleGeom(name=name or f"geom_{i}", type=g.type, size=_t(g.size), **common)


def _hrdf_actuator(a: Any, names: dict[int, str], problems: list[Problem]) -> H.Actuator | None:
    target = a._parent
    if target._NAMESPACE != "joint" or isinstance(a, A.General):
        problems.append(
            Problem(
                a._label(),
                "only motor/position/velocity actuators on joints have an HRDF table; not kept",
            )
        )
        return None
    kind = {A.Motor: "motor", A.Position: "position", A.Velocity: "velocity"}[type(a)]
    ctrl = _t(a.ctrlrange) if _limited(a.ctrllimited, a.ctrlrange, True) else None
    force = _t(a.forcerange) if _limited(a.forcelimited, a.forcerange, True) else None
    kept = a.extras.get("hrdf", {})
    if kind == "position":
        p_gain, d_gain = a.kp, (a.kv or kept.get("d_gain"))
    elif kind == "velocity":
        p_gain, d_gain = kept.get("p_gain"), a.kv
    else:
        p_gain, d_gain = kept.get("p_gain"), kept.get("d_gain")
    peak_torque = kept.get("peak_torque")
    if peak_torque is not None:
        implied = (-peak_torque, peak_torque)
        # A range the HRDF row gave through peak_torque alone stays implied.
        if kind == "motor" and ctrl == implied and kept.get("ctrl_range") is None:
            ctrl = None
        elif kind != "motor" and force == implied and kept.get("force_range") is None:
            force = None
        elif kind != "motor" and force is None:
            peak_torque = None  # it gave the force range, which has since been removed
    return H.Actuator(
        peak_torque=peak_torque,
        peak_velocity=kept.get("peak_velocity"),
        joint=names[target.ID],
        name=names.get(a.ID),
        type=kind,
        gear=float(a.gear[0]),
        ctrl_range=ctrl,
        force_range=force,
        p_gain=p_gain,
        d_gain=d_gain,
    )


def _t(values: Any) -> tuple[float, ...]:
    return tuple(float(v) for v in values)
