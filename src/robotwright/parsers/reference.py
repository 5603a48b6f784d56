"""Kinematic and inertial views of a robot for fidelity checks.

A :class:`RobotView` answers, for one robot, the questions the round-trip table asks:
body names and masses, world-frame inertia at the reference configuration, joints
(type, axis, range), and forward kinematics at a given joint configuration. Views are
built from a compiled ``mujoco.MjModel`` (the source compiled by MuJoCo, or our output
compiled) or from a URDF through ``yourdfpy`` (an independent kinematics library, used
when MuJoCo cannot import the source).

Frames: every pose is in the frame of the robot's root (MuJoCo world = URDF root link).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import defusedxml.ElementTree as DET
import mujoco
import numpy as np

from robotwright._rotations import quat_to_mat, rpy_to_quat
from robotwright._xmlsafe import parse_xml
from robotwright.errors import UnsafePathError
from robotwright.parsers.mujoco_probes import (  # noqa: F401
    _INERTIA_KEYS,
    mujoco_diagonalises_inertia_exactly,
    mujoco_urdf_clamps_effort,
    mujoco_urdf_imports_mimic,
    mujoco_urdf_keeps_inertial_rotation,
    mujoco_urdf_keeps_mesh_files_apart,
    mujoco_xml_reads_subnormals,
)
from robotwright.parsers.packages import UnresolvedMesh, resolve_uri
from robotwright.parsers.robot_view import (  # noqa: F401
    JointInfo,
    RobotView,
    body_name,
    joint_name,
    view_from_model,
)


def _split_mesh_scales(root: ET.Element) -> dict[str, bytes]:
    """Give each (file, scale) pair of the collision meshes its own mesh name.

    MuJoCo names a URDF mesh after its file name without folder and extension. MuJoCo
    3.11 keys its meshes on that name and the scale only, and gives a geom the first
    scale's mesh again from the third use on (see :func:`mujoco_urdf_keeps_mesh_files_apart`):
    two files of one name in different folders (talos: ``torso/base_link_collision.STL``
    and ``gripper/base_link_collision.STL``) or a file used with two scales (mirrored
    limbs) get the wrong mesh; 4.x gets both right. The second and later pairs of a name
    are renamed here to ``<name>__<k><ext>``, a file MuJoCo reads from the returned
    assets (that file's bytes). Visual meshes are left alone (``urdf_for_mujoco``
    discards them). A file that cannot be read is left as written: MuJoCo's own error
    then names it.
    """
    pairs_seen: dict[str, list[tuple[str, tuple[float, ...]]]] = {}
    renamed: dict[tuple[str, tuple[float, ...]], str] = {}
    assets: dict[str, bytes] = {}
    for collision in root.iter("collision"):
        for mesh in collision.iter("mesh"):
            file = mesh.get("filename")
            if not file:
                continue
            try:
                scale = tuple(float(v) for v in mesh.get("scale", "1 1 1").split())
            except ValueError:
                continue
            name = Path(file).stem
            seen = pairs_seen.setdefault(name, [])
            if (file, scale) not in seen:
                seen.append((file, scale))
            k = seen.index((file, scale))
            if k == 0:
                continue
            if (file, scale) not in renamed:
                alias = f"{name}__{k}{Path(file).suffix}"
                try:
                    assets[alias] = Path(file).read_bytes()
                except OSError:
                    continue
                renamed[(file, scale)] = alias
            mesh.set("filename", renamed[(file, scale)])
    return assets


def _mimic_equalities(root: ET.Element) -> list[tuple[str, str, float, float]]:
    """(joint, mimicked joint, multiplier, offset) of every ``<joint><mimic>``."""
    out = []
    for joint in root.iter("joint"):
        mimic = joint.find("mimic")
        if mimic is None or not joint.get("name") or not mimic.get("joint"):
            continue
        try:
            mult = float(mimic.get("multiplier", "1"))
            offset = float(mimic.get("offset", "0"))
        except ValueError:
            continue
        out.append((joint.get("name", ""), mimic.get("joint", ""), mult, offset))
    return out


def _inertia_into_link_frame(root: ET.Element) -> None:
    """Rewrite each ``<inertial>`` whose ``<origin rpy>`` rotates the inertia into the
    equivalent one with ``rpy="0 0 0"`` and the tensor ``R I R^T`` in the link frame.

    For a MuJoCo that drops that rotation (3.11, see
    :func:`mujoco_urdf_keeps_inertial_rotation`): the rewritten URDF is the same robot
    for any correct importer. The tensor is computed as the URDF parser computes it, so
    on such a MuJoCo the rotation of inertial frames is checked against our own
    arithmetic (4.x checks it independently). An ``<inertial>`` with numbers that do not
    parse is left as written: MuJoCo's own error then names it.
    """
    for inertial in root.iter("inertial"):
        origin = inertial.find("origin")
        if origin is None or origin.get("rpy") is None:
            continue
        try:
            rpy = [float(v) for v in origin.get("rpy", "").split()]
            i_el = inertial.find("inertia")
            v = {k: float(i_el.get(k, "0")) for k in _INERTIA_KEYS} if i_el is not None else {}
        except ValueError:
            continue
        if len(rpy) != 3:
            continue
        if any(rpy) and i_el is not None:
            local = np.array(
                [
                    [v["ixx"], v["ixy"], v["ixz"]],
                    [v["ixy"], v["iyy"], v["iyz"]],
                    [v["ixz"], v["iyz"], v["izz"]],
                ]
            )
            rot = quat_to_mat(rpy_to_quat(rpy))
            t = rot @ local @ rot.T
            for k, (r, c) in zip(_INERTIA_KEYS, ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))):
                i_el.set(k, repr(float(t[r, c])))
        origin.set("rpy", "0 0 0")


def urdf_for_mujoco(
    path: Path,
    package_map=None,
    *,
    balance_inertia: bool = False,
    bound_mass=None,
    bound_inertia=None,
    root: ET.Element | None = None,
    inertia_from_geoms: str = "auto",
) -> str:
    """The URDF text with mesh URIs made absolute, rotated inertial frames written in the
    link frame where MuJoCo would drop the rotation (see
    :func:`_inertia_into_link_frame`) and a ``<mujoco><compiler>`` block
    that keeps every link a body (``fusestatic="false"``), gives a link without
    ``<inertial>`` the inertia of its collision geoms as MuJoCo's import does by default
    (``inertiafromgeom="auto"``; ``inertia_from_geoms="never"``: ``"false"``, none) and
    drops visual geoms (which carry no mass in MuJoCo's import).

    ``root``: the URDF already parsed (changed in place), for a document that is not a
    file yet (one robotwright wrote: its mesh paths are its own, not checked); relative
    mesh URIs then resolve from ``path``'s folder all the same. A source file's mesh
    paths keep the parsers' containment rule: one that exists outside the file's root
    (and outside trusted folders) raises :class:`~robotwright.errors.UnsafePathError`
    (a ``ValueError``) instead of reaching MuJoCo.
    """
    contained = root is None
    if root is None:
        root = parse_xml(path)
    for mesh in root.iter("mesh"):
        uri = mesh.get("filename")
        if uri:
            try:
                resolved = resolve_uri(uri, path, package_map, None if contained else Path("/"))
            except UnresolvedMesh as exc:
                try:
                    resolve_uri(uri, path, package_map, Path("/"))
                except UnresolvedMesh:
                    continue  # left as written: MuJoCo's own error then names the file
                # It exists, outside the robot's root: the parsers' containment rule.
                raise UnsafePathError(str(exc), file=str(path)) from None
            mesh.set("filename", str(resolved))
    if not mujoco_urdf_keeps_inertial_rotation():
        _inertia_into_link_frame(root)
    # A continuous joint has no limits (URDF specification; MuJoCo 4 ignores lower/upper
    # there), but MuJoCo 3.11 applies them: leave them out, so both import it alike.
    for joint in root.iter("joint"):
        limit = joint.find("limit")
        if joint.get("type") == "continuous" and limit is not None:
            limit.attrib.pop("lower", None)
            limit.attrib.pop("upper", None)
    for old in root.findall("mujoco"):
        root.remove(old)
    mj = ET.SubElement(root, "mujoco")
    attrs = {
        "fusestatic": "false",
        "discardvisual": "true",
        "inertiafromgeom": "false" if inertia_from_geoms == "never" else "auto",
        "strippath": "false",
        "balanceinertia": "true" if balance_inertia else "false",
    }
    if bound_mass is not None:
        attrs["boundmass"] = repr(float(bound_mass))
    if bound_inertia is not None:
        attrs["boundinertia"] = repr(float(bound_inertia))
    ET.SubElement(mj, "compiler", attrs)
    return ET.tostring(root, encoding="unicode")


def free_joint_name(taken: set[str]) -> str:
    """The name a URDF robot's requested free base gets (``floating_base``, ``_``
    appended while one of the ``taken`` joint names holds it), in the URDF reader and in
    the proof's reference of ``floating_base=True`` alike."""
    name = "floating_base"
    while name in taken:
        name += "_"
    return name


def compile_urdf(
    text: str, density: float | None = None, *, fuse_static: bool = False, floating: bool = False
) -> mujoco.MjModel:
    """MuJoCo's import of a URDF text (as :func:`urdf_for_mujoco` writes it), compiled.

    ``fuse_static``: links on fixed joints fused into their parents by MuJoCo
    (``fusestatic``, the import's default), the root link kept a body (MuJoCo would fuse
    a fixed base into the world): the reference of ``fixed_joints="merge"``. It adds one
    ``framepos`` sensor per top-level body (what keeps it; sensors are not a URDF's).

    ``density``: kg/m^3 given to the collision geoms (MuJoCo's import gives them its
    default, 1000; a URDF cannot say otherwise), for the links without ``<inertial>``.

    ``floating``: the root body gets a free joint named as the URDF reader names it
    (``floating_base``, ``_`` appended while a joint holds the name): the reference of
    ``floating_base=True``, so that the free base the user asked for is not a difference.

    On MuJoCo 4.x this is ``MjModel.from_xml_string(text)``. Where the installed MuJoCo
    gets a URDF wrong (3.11; each found by a probe), the import is completed so that the
    reference is the same as 4.x's: ``<mimic>`` added as the joint equality 4.x makes
    (:func:`mujoco_urdf_imports_mimic`), each scale of a mesh file its own mesh name
    (:func:`_split_mesh_scales`), and each body's tensor, as MuJoCo's URDF reader stored
    it, given to the compiler already diagonalised (``numpy.linalg.eigh``) where the
    compiler does not diagonalise to rounding
    (:func:`mujoco_diagonalises_inertia_exactly`). Everything else (masses, centres of
    mass, which tensor goes to which body, frames, joints, geoms) stays MuJoCo's own
    import. Raises ValueError when MuJoCo refuses it.
    """
    if (
        mujoco_diagonalises_inertia_exactly()
        and mujoco_urdf_imports_mimic()
        and mujoco_urdf_keeps_mesh_files_apart()
        and density is None
        and not fuse_static
        and not floating
    ):
        return mujoco.MjModel.from_xml_string(text)
    root = DET.fromstring(text)
    assets: dict[str, bytes] = {}
    if not mujoco_urdf_keeps_mesh_files_apart():
        assets = _split_mesh_scales(root)
        if assets:
            text = ET.tostring(root, encoding="unicode")
    spec = mujoco.MjSpec.from_string(text, assets=assets or None)
    if floating:
        spec.worldbody.first_body().add_freejoint(
            name=free_joint_name({j.name for j in spec.joints})
        )
    if fuse_static:
        spec.compiler.fusestatic = True
        # A body a sensor refers to is not fused: the root stays the robot's base. (A
        # body's frame, mjOBJ_XBODY, keeps it on 4.x only: MuJoCo 3.11 fuses it and then
        # finds no body of that name; its inertial frame, mjOBJ_BODY, keeps it on both.)
        top = spec.worldbody.first_body()
        while top is not None:
            spec.add_sensor(
                type=mujoco.mjtSensor.mjSENS_FRAMEPOS,
                objtype=mujoco.mjtObj.mjOBJ_BODY,
                objname=top.name,
            )
            top = spec.worldbody.next_body(top)
    if density is not None:
        for geom in spec.geoms:
            if geom.density > 0:  # collision geoms; the import gives visual ones 0
                geom.density = float(density)
    if not mujoco_urdf_imports_mimic():
        # As MuJoCo 4.x's URDF reader does (same fields, defaults for the rest).
        joints = {j.name for j in spec.joints}
        for joint, mimicked, mult, offset in _mimic_equalities(root):
            if joint in joints and mimicked in joints:
                eq = spec.add_equality(type=mujoco.mjtEq.mjEQ_JOINT, name1=joint, name2=mimicked)
                data = np.array(eq.data, dtype=float)
                data[:5] = (offset, mult, 0.0, 0.0, 0.0)
                eq.data = data
    if mujoco_diagonalises_inertia_exactly():
        return spec.compile()
    # With the inertial rotation dropped by this MuJoCo, urdf_for_mujoco has written
    # every tensor in the link frame and the reader's iquat is not the tensor's frame;
    # otherwise the tensor is given in the frame iquat.
    in_link_frame = not mujoco_urdf_keeps_inertial_rotation()
    # MuJoCo's own verdict first: a tensor it refuses ("inertia must have positive
    # eigenvalues") stays refused; the diagonalisation below only makes its axes exact.
    # On a copy: compiling with fusestatic removes the fused bodies from the spec.
    spec.copy().compile()
    for body in spec.bodies:
        f = np.asarray(body.fullinertia, dtype=float)
        if not body.explicitinertial or np.isnan(f[0]):
            continue
        tensor = np.array([[f[0], f[3], f[4]], [f[3], f[1], f[5]], [f[4], f[5], f[2]]])
        if not in_link_frame:
            rot = quat_to_mat(body.iquat)
            tensor = rot @ tensor @ rot.T
        values, vectors = np.linalg.eigh(tensor)
        if np.linalg.det(vectors) < 0:
            vectors[:, 2] = -vectors[:, 2]
        quat = np.zeros(4)
        mujoco.mju_mat2Quat(quat, vectors.flatten())
        body.inertia = values
        body.iquat = quat
        body.fullinertia = [np.nan, 0, 0, 0, 0, 0]
    return spec.compile()


def urdf_mujoco_view(path: Path, package_map=None, **compiler) -> RobotView:
    """MuJoCo's own URDF import of ``path`` (raises ValueError when MuJoCo refuses it;
    see :func:`urdf_for_mujoco` and :func:`compile_urdf` for what is completed for it on
    MuJoCo 3.11)."""
    text = urdf_for_mujoco(path, package_map, **compiler)
    return view_from_model(compile_urdf(text), "mujoco")


def _repair(
    mass: float, tensor: np.ndarray, balance_inertia: bool, bound_mass, bound_inertia
) -> tuple[float, np.ndarray]:
    """MuJoCo's compiler repairs (balanceinertia, boundmass, boundinertia) applied to one
    body's mass and tensor: moments are frame-invariant, so any frame works."""
    if not (balance_inertia or bound_mass is not None or bound_inertia is not None):
        return mass, tensor
    values, vectors = np.linalg.eigh(tensor)
    if balance_inertia and mass > 0 and values.min() > 0:
        a, b, c = values
        if a + b < c or a + c < b or b + c < a:
            values = np.full(3, values.mean())
    if bound_mass is not None:
        mass = max(mass, float(bound_mass))
    if bound_inertia is not None:
        values = np.maximum(values, float(bound_inertia))
    return mass, vectors @ np.diag(values) @ vectors.T


def _geom_inertias(
    path: Path, links: list[str], density: float | None
) -> dict[str, tuple[float, np.ndarray, np.ndarray]]:
    """Mass, centre of mass and tensor (link frame) that MuJoCo's URDF import gives the
    ``links`` without ``<inertial>`` (from their collision geoms), for a URDF MuJoCo
    refuses as written: every explicit ``<inertial>`` is replaced by a unit one (a link's
    inertia from its geoms does not depend on the others) so that the other links'
    faults do not stop the import. Empty when MuJoCo refuses even that."""
    try:
        root = DET.fromstring(urdf_for_mujoco(path))  # mesh paths under the usual rule
        for inertial in root.iter("inertial"):
            inertial.clear()
            ET.SubElement(inertial, "mass", {"value": "1"})
            unit = {k: "1" if k in ("ixx", "iyy", "izz") else "0" for k in _INERTIA_KEYS}
            ET.SubElement(inertial, "inertia", unit)
        model = compile_urdf(ET.tostring(root, encoding="unicode"), density)
    except Exception:  # noqa: BLE001 - MuJoCo computes nothing: those links stay massless
        return {}
    out = {}
    for n in links:
        try:
            i = model.body(n).id
        except KeyError:
            continue
        rot = quat_to_mat(model.body_iquat[i])
        tensor = rot @ np.diag(model.body_inertia[i]) @ rot.T
        out[n] = (float(model.body_mass[i]), np.array(model.body_ipos[i]), tensor)
    return out


def urdf_yourdfpy_view(
    path: Path,
    *,
    balance_inertia: bool = False,
    bound_mass: float | None = None,
    bound_inertia: float | None = None,
    inertia_from_geoms: str = "auto",
    density: float | None = None,
) -> RobotView:
    """An independent reference: ``yourdfpy`` kinematics and the URDF's inertials (with
    the same repairs as the parser options, when given). A link without ``<inertial>``
    gets, with ``inertia_from_geoms="auto"``, what MuJoCo's import computes from its
    collision geoms (see :func:`_geom_inertias`), where MuJoCo can compute it."""
    import yourdfpy

    robot = yourdfpy.URDF.load(
        str(path),
        load_meshes=False,
        load_collision_meshes=False,
        build_scene_graph=True,
        build_collision_scene_graph=False,
        filename_handler=lambda fname: fname,
    )
    base = robot.base_link
    # MuJoCo's convention: a URDF root link called "world" is the world itself.
    links = [n for n in robot.link_map if n != "world" or base != "world"]
    mass, inertia = {}, {}
    robot.update_cfg(np.zeros(len(robot.actuated_joint_names)))
    without = [n for n in links if robot.link_map[n].inertial is None]
    from_geoms = (
        _geom_inertias(path, without, density) if without and inertia_from_geoms == "auto" else {}
    )
    for n in links:
        link = robot.link_map[n]
        tf = robot.get_transform(n, base)
        if n in from_geoms:
            m, com, tensor = from_geoms[n]
            rot = tf[:3, :3]
            mass[n] = m
            inertia[n] = (tf[:3, :3] @ com + tf[:3, 3], rot @ tensor @ rot.T)
            continue
        if link.inertial is None:
            mass[n] = 0.0
            inertia[n] = (tf[:3, 3].copy(), np.zeros((3, 3)))
            continue
        origin = link.inertial.origin if link.inertial.origin is not None else np.eye(4)
        world = tf @ origin
        rot = world[:3, :3]
        mass[n] = float(link.inertial.mass or 0.0)
        inertia[n] = (world[:3, 3].copy(), rot @ np.asarray(link.inertial.inertia) @ rot.T)
    for n in links:
        m, t = _repair(mass[n], inertia[n][1], balance_inertia, bound_mass, bound_inertia)
        mass[n], inertia[n] = m, (inertia[n][0], t)
    joints = []
    for jn, j in robot.joint_map.items():
        if j.type in ("fixed",):
            continue
        t = {
            "revolute": "hinge",
            "continuous": "hinge",
            "prismatic": "slide",
            "floating": "free",
        }.get(j.type, j.type)
        rng = None
        if (
            j.type in ("revolute", "prismatic")
            and j.limit is not None
            and j.limit.lower is not None
        ):
            rng = (float(j.limit.lower), float(j.limit.upper))
        axis = np.asarray(j.axis if j.axis is not None else (1, 0, 0), dtype=float)
        joints.append(JointInfo(jn, t, j.child, axis / np.linalg.norm(axis), rng))
    actuated = list(robot.actuated_joint_names)

    def fk(q: dict[str, float]) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        robot.update_cfg(np.array([float(q.get(n, 0.0)) for n in actuated]))
        out = {}
        for n in links:
            tf = robot.get_transform(n, base)
            out[n] = (tf[:3, 3].copy(), tf[:3, :3].copy())
        return out

    return RobotView("yourdfpy", links, mass, inertia, joints, [], fk)


def mimic_map(path: Path) -> dict[str, tuple[str, float, float]]:
    """URDF mimic joints: name -> (mimicked joint, multiplier, offset)."""
    out = {}
    if path.suffix.lower() != ".urdf" or b"mimic" not in path.read_bytes():
        return out  # a file without the word has no <mimic>: no second parse of a large robot
    for j in parse_xml(path).findall("joint"):
        m = j.find("mimic")
        if m is not None:
            out[j.get("name")] = (
                m.get("joint"),
                float(m.get("multiplier", "1")),
                float(m.get("offset", "0")),
            )
    return out


def quat_angle(r1: np.ndarray, r2: np.ndarray) -> float:
    """Rotation angle (rad) between two rotation matrices."""
    c = (np.trace(r1.T @ r2) - 1.0) / 2.0
    # acos loses precision near 1; use the skew part for small angles
    s = (
        np.linalg.norm(
            np.array(
                [
                    (r1.T @ r2)[2, 1] - (r1.T @ r2)[1, 2],
                    (r1.T @ r2)[0, 2] - (r1.T @ r2)[2, 0],
                    (r1.T @ r2)[1, 0] - (r1.T @ r2)[0, 1],
                ]
            )
        )
        / 2.0
    )
    return float(np.arctan2(s, c))
