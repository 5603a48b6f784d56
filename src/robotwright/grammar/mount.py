"""Mount a limb on a robot: one HRDF with the limb's base fixed to a body or site.

This merges at the HRDF level, so the result exports to MJCF and URDF through the
generators like any robot, and can be saved as an HRDF folder.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np

from robotwright._rotations import compose_pose
from robotwright._suggest import did_you_mean
from robotwright.errors import GrammarError, Problem
from robotwright.hrdf.model import HRDF

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]


def _compose(
    pos_a: Sequence[float], quat_a: Sequence[float], pos_b: Sequence[float], quat_b: Sequence[float]
) -> tuple[Vec3, Quat]:
    """Pose a then pose b (b expressed in a's frame), as plain floats with a unit quaternion."""
    qa = np.asarray(quat_a, dtype=float)
    p, q = compose_pose(pos_a, qa / np.linalg.norm(qa), pos_b, quat_b)
    q = q / np.linalg.norm(q)
    return tuple(float(x) for x in p), tuple(float(x) for x in q)  # type: ignore[return-value]


def mount_on(
    robot: HRDF,
    limb: HRDF,
    at: str,
    *,
    prefix: str = "srl_",
    pos: Vec3 = (0.0, 0.0, 0.0),
    quat: Quat = (1.0, 0.0, 0.0, 0.0),
    name: str | None = None,
) -> HRDF:
    """Return a new robot: ``robot`` wearing ``limb`` at body or site ``at``.

    The limb's root body becomes a child of the body ``at`` (or of the site's body, at
    the site's pose), placed by ``pos``/``quat`` relative to that frame (m; w, x, y, z)
    and then by the limb root's own pose. Every limb name gets ``prefix``.

    Raises:
        GrammarError: ``at`` names no body or site, the limb has a floating base or MJCF
            extras whose names cannot be renamed, or prefixed names clash.
    """
    problems: list[Problem] = []
    body_names = {b.name for b in robot.bodies}
    site = next((s for s in robot.sites if s.name == at), None)
    if at in body_names:
        parent_name, frame_pos, frame_quat = at, (0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0)
    elif site is not None:
        parent_name, frame_pos, frame_quat = site.body, site.pos, site.quat
    else:
        raise GrammarError(
            [
                Problem(
                    robot.name,
                    f"no body or site named {at!r} to mount on (bodies: {sorted(body_names)[:12]}..., sites: {[s.name for s in robot.sites]})"
                    + did_you_mean(at, [*body_names, *(s.name for s in robot.sites)]),
                )
            ]
        )
    if limb.floating_base:
        problems.append(
            Problem(
                limb.name, "the limb has a floating base (free joint); a mounted limb must be fixed"
            )
        )
    if limb.mjcf_extra:
        problems.append(
            Problem(
                limb.name,
                "the limb carries an MJCF fragment (mjcf_extra) whose names cannot be prefixed; mount it without one",
            )
        )
    rn = prefix + "{}"
    new_names = [rn.format(b.name) for b in limb.bodies] + [rn.format(s.name) for s in limb.sites]
    new_names += [rn.format(j.name) for j in limb.joints if j.name]
    taken = body_names | {s.name for s in robot.sites} | {j.name for j in robot.joints if j.name}
    clash = sorted(set(new_names) & taken)
    if clash:
        problems.append(
            Problem(robot.name, f"names {clash} exist in the robot already; choose another prefix")
        )
    if problems:
        raise GrammarError(problems, f"cannot mount '{limb.name}' on '{robot.name}' at {at!r}")

    parent_index = robot.body_index(parent_name)
    offset = len(robot.bodies)
    root = limb.root_index
    mount_pos, mount_quat = _compose(frame_pos, frame_quat, pos, quat)
    bodies = list(robot.bodies)
    order = list(range(len(limb.bodies)))
    for i in order:
        b = limb.bodies[i]
        if i == root:
            p, q = _compose(mount_pos, mount_quat, b.pos, b.quat)
            bodies.append(
                dataclasses.replace(b, name=rn.format(b.name), parent=parent_index, pos=p, quat=q)
            )
        else:
            bodies.append(dataclasses.replace(b, name=rn.format(b.name), parent=b.parent + offset))
    joints = list(robot.joints) + [
        dataclasses.replace(j, name=rn.format(j.name) if j.name else None, body=rn.format(j.body))
        for j in limb.joints
    ]
    actuators = list(robot.actuators) + [
        dataclasses.replace(a, joint=rn.format(a.joint), name=rn.format(a.name) if a.name else None)
        for a in limb.actuators
    ]
    meshes = list(robot.meshes) + [
        dataclasses.replace(
            m,
            body=rn.format(m.body),
            file=str(limb.mesh_source(m)) if limb.root_dir else m.file,
        )
        for m in limb.meshes
    ]
    geoms = list(robot.simple_geoms) + [
        dataclasses.replace(
            g,
            body=rn.format(g.body),
            name=rn.format(g.name) if g.name else g.name,
            geom_name=rn.format(g.geom_name) if g.geom_name else None,
        )
        for g in limb.simple_geoms
    ]
    sites = list(robot.sites) + [
        dataclasses.replace(s, name=rn.format(s.name), body=rn.format(s.body)) for s in limb.sites
    ]
    sensors = list(robot.sensors) + [
        dataclasses.replace(
            s,
            name=rn.format(s.name),
            objname=rn.format(s.objname),
            refname=rn.format(s.refname) if s.refname else None,
        )
        for s in limb.sensors
    ]
    meta = dataclasses.replace(robot.meta, extra=dict(robot.meta.extra))
    mounted = list(meta.extra.get("mounted_limbs", []))
    mounted.append(
        {
            "limb": limb.name,
            "at": at,
            "prefix": prefix,
            "design_hash": (limb.meta.extra.get("grammar") or {}).get("design_hash"),
        }
    )
    meta.extra["mounted_limbs"] = mounted
    return HRDF(
        name=name or f"{robot.name}_{limb.name}",
        bodies=bodies,
        joints=joints,
        actuators=actuators,
        meshes=meshes,
        simple_geoms=geoms,
        sites=sites,
        sensors=sensors,
        meta=meta,
        mjcf_extra=robot.mjcf_extra,
        root_dir=robot.root_dir,
        temp_assets=robot.temp_assets,  # keeps a parsed robot's staged meshes alive
        # The limb's meshes keep their absolute paths in its folder: trusted here.
        asset_roots=tuple(
            dict.fromkeys(
                [*robot.asset_roots, *limb.asset_roots]
                + ([limb.root_dir.resolve()] if limb.root_dir and limb.meshes else [])
            )
        ),
    )


def oriented(limb: HRDF, pos: Vec3 = (0.0, 0.0, 0.0), quat: Quat = (1.0, 0.0, 0.0, 0.0)) -> HRDF:
    """A copy of ``limb`` whose root body is moved by ``pos``/``quat`` (m; w, x, y, z)."""
    root = limb.root_index
    bodies = list(limb.bodies)
    b = bodies[root]
    p, q = _compose(pos, quat, b.pos, b.quat)
    bodies[root] = dataclasses.replace(b, pos=p, quat=q)
    return dataclasses.replace(limb, bodies=bodies)


def mount_scene(
    robot: HRDF,
    limb: HRDF,
    at: str,
    *,
    pos: Vec3 = (0.0, 0.0, 0.0),
    quat: Quat = (1.0, 0.0, 0.0, 0.0),
    robot_key: str = "robot",
    limb_key: str = "srl",
):
    """The same mount as :func:`mount_on`, made by the generators' composite: an
    ``MJCFGeneratorComposite`` holding both robots, the limb attached at site or body
    ``at`` of the robot (names prefixed ``<robot_key>_`` and ``<limb_key>_``).

    The composite's placement turns about z only, so the limb's orientation ``quat``
    is applied to the limb's root body first.
    """
    from robotwright.generators import (
        MJCFGeneratorComposite,
        MJCFHumanoidGenerator,
        Placement,
    )

    return MJCFGeneratorComposite(
        {
            robot_key: MJCFHumanoidGenerator.from_hrdf(robot),
            limb_key: MJCFHumanoidGenerator.from_hrdf(oriented(limb, pos, quat)),
        },
        placements={limb_key: Placement(parent=robot_key, frame=at)},
    )
