"""URDF -> HRDF.

Frames: a URDF joint's ``<origin>`` is the child link frame in the parent link frame;
it becomes the child body's ``pos``/``quat`` and the joint sits at the body origin
(``pos`` 0) with its ``<axis>`` in the child frame, as MuJoCo's own URDF importer does.
Inertia tensors (``<inertial><origin rpy>`` honoured) are diagonalised exactly.

Visual geoms go to group 2 without contacts (contype = conaffinity = 0), collision geoms
to group 3 with contype = conaffinity = 1, so the two stay apart. A visual and a
collision of the same geometry and origin are one geom that is drawn and collides
(group 0, contype = conaffinity = 1, the visual's colour; see
:mod:`robotwright.parsers.urdf.geom_pairs`), as MuJoCo's own geoms are by default.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from collections import Counter
from dataclasses import replace
from pathlib import Path

from robotwright._notes import name_list
from robotwright._paths import trusted_asset_roots
from robotwright._progress import steps
from robotwright._xmlsafe import describe
from robotwright.errors import ConversionError, Problem
from robotwright.hrdf.model import (
    HRDF,
    Actuator,
    Body,
    Joint,
    MeshGeom,
    Meta,
    SimpleGeom,
    Site,
)
from robotwright.parsers.meshes import (
    rewrite_staged,
)
from robotwright.parsers.report import ParseResult, Reporter, warn_massless_moving
from robotwright.parsers.urdf import actuators as acts
from robotwright.parsers.urdf.common import (  # noqa: F401
    COLLISION_GROUP,
    DRAWN_COLLISION_GROUP,
    VISUAL_GROUP,
    URDFOptions,
    _origin,
    _Pose,
    _t,
)
from robotwright.parsers.urdf.joints import _body_record, _joint_record, _mimic_extra, _read_tree
from robotwright.parsers.urdf.links import _make_geom, _URDFReader
from robotwright.parsers.urdf.visuals import drop_unbuildable_visuals
from robotwright.parsers.xacro.expand import read_robot_xml

#: Joints from a root link named "world" that stay on its child when the root is dropped.
_WORLD_CHILD_JOINTS = ("revolute", "continuous", "prismatic")

_KNOWN_TOP = {"link", "joint", "material"}


def parse_urdf(
    path: str | os.PathLike, options: URDFOptions | None = None, *, strict: bool = False
) -> ParseResult:
    """Parse a URDF file into an HRDF (see :class:`URDFOptions`).

    Raises:
        ConversionError: malformed or unsafe XML, an invalid tree, unresolved meshes or
            mesh paths leaving the robot folder (all listed in one error), or, with
            ``strict=True``, any warning.
    """
    opt = options or URDFOptions()
    with trusted_asset_roots(opt.asset_roots):
        return _parse_urdf(Path(path), opt, strict)


def _parse_urdf(path: Path, opt: URDFOptions, strict: bool) -> ParseResult:
    rep = Reporter(str(path))
    root = read_robot_xml(path, opt, rep)  # a .xacro file is expanded first
    if root.tag != "robot":
        raise ConversionError([Problem(str(path), f"root element <{root.tag}>: expected <robot>")])
    reader = _URDFReader(path, opt, rep)

    for mat in root.findall("material"):
        rgba = reader._material(mat, describe(mat))
        if rgba is not None and mat.get("name"):
            reader.materials[mat.get("name")] = rgba
    reads = acts.INTERFACE_TAGS if opt.actuators in acts.MODES else ()  # read below
    dropped = Counter(c.tag for c in root if c.tag not in _KNOWN_TOP and c.tag not in reads)
    for tag, count in sorted(dropped.items()):
        rep.warn(f"{count} top-level <{tag}> element(s) dropped (not robot structure)")

    tree = _read_tree(root, path)
    links, joints, parent_of, children = tree.links, tree.joints, tree.parent_of, tree.children
    order, roots = tree.order, tree.roots
    # A robot of many links with large meshes takes a while: progress past 2 s.
    data = {n: reader.link_data(links[n]) for n in steps(order, len(order), "links read")}
    if reader.unresolved:
        from robotwright.parsers.urdf.unresolved import group_unresolved

        raise ConversionError(
            group_unresolved(reader.unresolved),
            summary=f"{len(reader.unresolved)} mesh(es) of {path} not resolved",
        )

    # A massless, geometry-free root link (usually "world") only anchors the robot: its
    # single child becomes the root, placed at the joint origin.
    root_name = roots[0]
    root_pose = _Pose()
    free_root = opt.floating_base
    free_name: str | None = None
    dropped_root: tuple[str, str] | None = None
    # A root link named "world" is MuJoCo's world: its moving joint stays on the child.
    root_joint: ET.Element | None = None
    r = data[root_name]
    # (With bound_mass the root is not massless: it stays, as in MuJoCo's importer.)
    if (
        (not r.has_inertial or r.mass == 0.0)
        and opt.bound_mass is None
        and not r.geoms
        and len(children[root_name]) == 1
    ):
        j = children[root_name][0]
        moving_from_world = root_name == "world" and j.get("type") in _WORLD_CHILD_JOINTS
        if j.get("type") in ("fixed", "floating") or moving_from_world:
            child = j.find("child").get("link")
            root_pose = _origin(j.find("origin"), rep, describe(j))
            if j.get("type") == "floating":
                free_root, free_name = True, j.get("name")
            if moving_from_world:
                root_joint = j
            kept = (
                ", the joint kept on it (a root link named 'world' is MuJoCo's world)"
                if moving_from_world
                else ""
            )
            rep.warn(
                f"massless root link '{root_name}' dropped; '{child}' is the root, placed at "
                f"the pose of {j.get('type')} joint '{j.get('name')}'{kept}",
                describe(links[root_name]),
            )
            order.remove(root_name)
            dropped_root = (root_name, child)
            root_name = child
            parent_of.pop(child)
            joints.remove(j)

    mimics: list[tuple[str, str, float, float]] = []
    sites: list[Site] = []
    if dropped_root is not None and dropped_root[0] != "world":
        # Keep the dropped root's frame as a site on the new root (MuJoCo's convention
        # makes only a root link called "world" the world itself).
        inv = _Pose(-root_pose.rot.T @ root_pose.pos, root_pose.rot.T)
        sites.append(
            Site(name=dropped_root[0], body=dropped_root[1], pos=_t(inv.pos), quat=inv.quat)
        )
    hrdf_joints: list[Joint] = []
    actuators: list[Actuator] = []
    # owner[link] = (body name, pose of the link frame in the owner body frame)
    owner: dict[str, tuple[str, _Pose]] = {}
    bodies: dict[str, dict] = {}
    body_order: list[str] = []
    dropped_limits: list[str] = []
    for name in order:
        d = data[name]
        j = parent_of.get(name)
        if j is None:
            pose, jtype, parent_body = root_pose, "root", None
        else:
            pose = _origin(j.find("origin"), rep, describe(j))
            jtype = j.get("type")
            parent_body, parent_pose = owner[j.find("parent").get("link")]
            pose = parent_pose.compose(pose)
        if jtype == "floating":
            raise ConversionError(
                [
                    Problem(
                        str(path),
                        "floating joint below the root: HRDF allows a free joint on the root only",
                        element=describe(j),
                    )
                ]
            )
        if jtype == "planar":
            raise ConversionError(
                [
                    Problem(
                        str(path),
                        "planar joints are not supported (no HRDF equivalent)",
                        element=describe(j),
                    )
                ]
            )
        massless = not d.has_inertial or (d.mass == 0.0 and not d.tensor.any())
        leaf = not children[name]
        as_site = jtype == "fixed" and (
            opt.fixed_joints == "merge" or (opt.fixed_joints == "site" and massless and leaf)
        )
        if as_site:
            owner[name] = (parent_body, pose)
            target = bodies[parent_body]
            if d.mass > 0 or d.tensor.any():  # a massless inertia is kept as written
                target["parts"].append(
                    (d.mass, pose.pos + pose.rot @ d.com, pose.rot @ d.tensor @ pose.rot.T)
                )
            for kind, gpose, fields in d.geoms:
                target["geoms"].append((kind, pose.compose(gpose), fields))
            sites.append(Site(name=name, body=parent_body, pos=_t(pose.pos), quat=pose.quat))
            continue
        owner[name] = (name, _Pose())
        bodies[name] = {
            "parent": parent_body,
            "pose": pose,
            "parts": [(d.mass, d.com, d.tensor)] if d.mass > 0 or d.tensor.any() else [],
            "geoms": list(d.geoms),
            "principal": d.principal if d.mass > 0 or d.tensor.any() else None,
        }
        body_order.append(name)
        if j is None and root_joint is not None:
            j, jtype = root_joint, root_joint.get("type")
        if j is None:
            if free_root:
                if free_name is None:
                    from robotwright.parsers.reference import free_joint_name

                    # The name our URDF generator gives it, so our MJCF names it alike.
                    free_name = free_joint_name({x.get("name") for x in joints})
                hrdf_joints.append(Joint(name=free_name, body=name, type="free"))
            continue
        if jtype == "fixed":
            continue
        joint, actuator, mimic, limits_dropped = _joint_record(j, name, opt, rep)
        hrdf_joints.append(joint)
        if actuator is not None:
            actuators.append(actuator)
        if limits_dropped:
            dropped_limits.append(joint.name)
        if mimic is not None:
            mimics.append(mimic)
    if opt.actuators in acts.MODES:
        actuators, kept = acts.make_actuators(
            root, hrdf_joints, opt.actuators, opt.actuator_gains, rep
        )
        dropped_limits = [n for n in dropped_limits if n not in kept]
    if dropped_limits:
        rep.warn(
            f"effort/velocity limits of {len(dropped_limits)} joint(s) not kept as motors "
            "(effort is kept as the joint's actuatorfrcrange, velocity dropped; keep both "
            "on motors with actuators='motor', or convert's --actuators motor): "
            + name_list(dropped_limits)
        )
    clamped = [j.name for j in hrdf_joints if j.actuatorfrcrange is not None]
    from robotwright.parsers.reference import mujoco_urdf_clamps_effort

    if clamped and not mujoco_urdf_clamps_effort():
        import mujoco  # the running version decides what its own URDF import does

        rep.warn(
            f"actuatorfrcrange +-effort set on {len(clamped)} joint(s) from <limit effort>, "
            f"as MuJoCo 3.11's and 4's URDF imports do; MuJoCo {mujoco.__version__}'s import "
            "leaves them unclamped: " + name_list(clamped)
        )

    hrdf_bodies: list[Body] = []
    index = {n: i for i, n in enumerate(body_order)}
    geoms_mesh: list[MeshGeom] = []
    geoms_simple: list[SimpleGeom] = []
    for name in body_order:
        b = bodies[name]
        hrdf_bodies.append(_body_record(name, b, index, opt, rep))
        for kind, gpose, fields in b["geoms"]:
            g = _make_geom(name, kind, gpose, fields)
            (geoms_mesh if isinstance(g, MeshGeom) else geoms_simple).append(g)
    for i, g in enumerate(geoms_simple):
        geoms_simple[i] = _replace_name(g, f"geom_{i}", "name")
    # Geom names must be unique in MJCF; URDF repeats them freely.
    seen_names: Counter[str] = Counter()
    for table in (geoms_mesh, geoms_simple):
        for i, g in enumerate(table):
            if g.geom_name is None:
                continue
            seen_names[g.geom_name] += 1
            if seen_names[g.geom_name] > 1:
                new_name = f"{g.geom_name}_{seen_names[g.geom_name] - 1}"
                rep.warn(f"geom name '{g.geom_name}' repeated: renamed '{new_name}'", cosmetic=True)
                table[i] = _replace_name(g, new_name, "geom_name")
    extra = _mimic_extra(mimics, {j.name for j in hrdf_joints}, rep)
    geoms_mesh, geoms_simple = drop_unbuildable_visuals(
        geoms_mesh,
        geoms_simple,
        reader.store.root,
        rep,
        lambda rel: rewrite_staged(reader.store, rel),
    )
    tables = (hrdf_bodies, hrdf_joints, geoms_mesh, geoms_simple, sites)
    _rename_world_body(tables, {x.get("name") for x in links.values()}, rep)
    hrdf = HRDF(
        name=root.get("name") or path.stem,
        bodies=hrdf_bodies,
        joints=hrdf_joints,
        actuators=actuators,
        meshes=geoms_mesh,
        simple_geoms=geoms_simple,
        sites=sites,
        meta=Meta(simulator_config=None, body_name_config=None),
        mjcf_extra=extra,
        root_dir=reader.store.root,
        temp_assets=reader.store.lifetime,
    )
    warn_massless_moving(hrdf, rep, '<link name="{}">')
    warnings = rep.finish(strict)
    return ParseResult(hrdf, warnings, str(path))


def _rename_world_body(tables: tuple[list, ...], taken: set[str], rep: Reporter) -> None:
    """A link named ``world`` that stays a body (it has mass, geometry, a parent or
    several children) is renamed: ``world`` is MuJoCo's world body, our MJCF would not
    compile. Renamed in place in (bodies, joints, meshes, simple geoms, sites)."""

    bodies, *others = tables
    if not any(b.name == "world" for b in bodies):
        return
    new = "world_link"
    while new in taken:
        new += "_"
    rep.warn(
        f"link 'world' renamed '{new}' ('world' is MuJoCo's world body)", '<link name="world">'
    )
    bodies[:] = [replace(b, name=new) if b.name == "world" else b for b in bodies]
    for table in others:
        table[:] = [replace(x, body=new) if x.body == "world" else x for x in table]


def _replace_name(g, name: str, field_name: str):

    return replace(g, **{field_name: name})
