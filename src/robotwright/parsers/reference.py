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

import functools
import struct
import tempfile
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import defusedxml.ElementTree as DET
import mujoco
import numpy as np

from robotwright._mjmodel import actuator_count
from robotwright._rotations import quat_to_mat, rpy_to_quat
from robotwright._xmlsafe import parse_xml
from robotwright.errors import UnsafePathError
from robotwright.parsers.packages import UnresolvedMesh, resolve_uri

_MJ_JOINT = {0: "free", 1: "ball", 2: "slide", 3: "hinge"}
#: Actuator transmission type -> MuJoCo object type of its target.
_TRN_OBJ = {
    0: mujoco.mjtObj.mjOBJ_JOINT,
    1: mujoco.mjtObj.mjOBJ_JOINT,
    3: mujoco.mjtObj.mjOBJ_TENDON,
    4: mujoco.mjtObj.mjOBJ_SITE,
    5: mujoco.mjtObj.mjOBJ_BODY,
}


@dataclass
class JointInfo:
    """A 1-DoF or multi-DoF joint: type, axis in its body frame, range or None, and (for
    MuJoCo views) its dynamics: armature, damping, frictionloss, stiffness, springref and
    qpos0 of its first degree of freedom."""

    name: str
    type: str
    body: str
    axis: np.ndarray
    range: tuple[float, float] | None
    dynamics: np.ndarray | None = None


@dataclass
class RobotView:
    """What the fidelity table compares (see the module docstring).

    Attributes:
        kind: where the view comes from (``"mujoco"``, ``"yourdfpy"``).
        bodies: body names in model order (world excluded).
        mass: body name -> mass (kg).
        inertia_world: body name -> (com in world (m), inertia tensor about the com in
            world axes (kg m^2)) at the zero configuration.
        joints: moving joints in model order.
        sites: site names.
        fk: callable ``q -> {name: (pos, rot)}`` for bodies and sites, ``q`` a dict of
            joint name -> value (rad or m; free/ball joints take quaternion arrays).
        actuators: list of dicts (name, type, joint, gains, ranges), MuJoCo views only.
        sensors: list of (name, type, object name), MuJoCo views only.
    """

    kind: str
    bodies: list[str]
    mass: dict[str, float]
    inertia_world: dict[str, tuple[np.ndarray, np.ndarray]]
    joints: list[JointInfo]
    sites: list[str]
    fk: object
    actuators: list[dict] = field(default_factory=list)
    sensors: list[tuple[str, str, str]] = field(default_factory=list)
    site_body: dict[str, str] = field(default_factory=dict)
    model: mujoco.MjModel | None = None


def body_name(model: mujoco.MjModel, i: int) -> str:
    """A body's name, or ``body_<id>`` for an unnamed one (as the MJCF parser names it)."""
    return model.body(i).name or f"body_{i}"


def joint_name(model: mujoco.MjModel, i: int) -> str:
    return model.joint(i).name or f"joint_{i}"


def _actuator_type(model: mujoco.MjModel, i: int) -> str:
    bias = model.actuator_biasprm[i]
    gain = model.actuator_gainprm[i]
    if model.actuator_biastype[i] == 0 and model.actuator_gaintype[i] == 0:
        return "motor" if gain[0] == 1.0 else "motor(gain)"
    if model.actuator_biastype[i] == 1 and bias[1] == -gain[0] and bias[1] != 0:
        return "position"
    if model.actuator_biastype[i] == 1 and bias[1] == 0 and bias[2] == -gain[0]:
        return "velocity"
    return "general"


def view_from_model(
    model: mujoco.MjModel, kind: str = "mujoco", root: str | None = None
) -> RobotView:
    """A view of a compiled MuJoCo model; with ``root`` (a top-level body name), only that
    body's subtree and the joints, sites, actuators and sensors on it. Without it, the
    only top-level body's subtree (world sites and geoms are scene, not robot)."""
    view = _view_from_model(model, kind)
    top = [i for i in range(1, model.nbody) if model.body_parentid[i] == 0]
    if root is None and len(top) != 1:
        return view
    # ``root`` as the parsers name it: an unnamed top-level body is 'body_<id>'.
    rid = top[0] if root is None else next(i for i in top if body_name(model, i) == root)
    keep = {body_name(model, i) for i in range(1, model.nbody) if model.body_rootid[i] == rid}
    view.bodies = [b for b in view.bodies if b in keep]
    view.mass = {k: v for k, v in view.mass.items() if k in keep}
    view.inertia_world = {k: v for k, v in view.inertia_world.items() if k in keep}
    view.joints = [j for j in view.joints if j.body in keep]
    view.sites = [s for s in view.sites if view.site_body[s] in keep]
    jn = {j.name for j in view.joints}
    # Actuators on other transmissions (tendons, sites) stay: dropping them is a loss.
    view.actuators = [a for a in view.actuators if a["joint"] is None or a["joint"] in jn]
    return view


def _view_from_model(model: mujoco.MjModel, kind: str = "mujoco") -> RobotView:
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    bodies = [body_name(model, i) for i in range(1, model.nbody)]
    mass = {body_name(model, i): float(model.body_mass[i]) for i in range(1, model.nbody)}
    inertia = {}
    for i in range(1, model.nbody):
        rot = data.ximat[i].reshape(3, 3)
        inertia[body_name(model, i)] = (
            data.xipos[i].copy(),
            rot @ np.diag(model.body_inertia[i]) @ rot.T,
        )
    joints = []
    for i in range(model.njnt):
        t = _MJ_JOINT[int(model.jnt_type[i])]
        joints.append(
            JointInfo(
                joint_name(model, i),
                t,
                body_name(model, int(model.jnt_bodyid[i])),
                model.jnt_axis[i].copy(),
                tuple(model.jnt_range[i]) if model.jnt_limited[i] else None,
                np.array(
                    [
                        model.dof_armature[model.jnt_dofadr[i]],
                        model.dof_damping[model.jnt_dofadr[i]],
                        model.dof_frictionloss[model.jnt_dofadr[i]],
                        model.jnt_stiffness[i],
                        model.qpos_spring[model.jnt_qposadr[i]],
                        model.qpos0[model.jnt_qposadr[i]],
                    ]
                ),
            )
        )
    sites = [model.site(i).name or f"site_{i}" for i in range(model.nsite)]
    adr = {joint_name(model, i): int(model.jnt_qposadr[i]) for i in range(model.njnt)}

    def fk(q: dict[str, np.ndarray | float]) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        data.qpos[:] = model.qpos0
        for name, value in q.items():
            a = adr[name]
            v = np.atleast_1d(np.asarray(value, dtype=float))
            data.qpos[a : a + v.size] = v
        mujoco.mj_kinematics(model, data)
        # Names looked up once (``bodies``), not per call: a model accessor per body per
        # configuration dominated round trips of large robots.
        xpos, xmat = data.xpos.copy(), data.xmat.reshape(-1, 3, 3).copy()
        out = {name: (xpos[i], xmat[i]) for i, name in enumerate(bodies, start=1)}
        for i, s in enumerate(sites):
            out.setdefault(s, (data.site_xpos[i].copy(), data.site_xmat[i].reshape(3, 3).copy()))
        return out

    actuators = []
    for i in range(actuator_count(model)):
        jid = int(model.actuator_trnid[i, 0])
        actuators.append(
            {
                "name": model.actuator(i).name,
                "type": _actuator_type(model, i),
                "joint": joint_name(model, jid) if model.actuator_trntype[i] == 0 else None,
                "kinds": (
                    int(model.actuator_trntype[i]),
                    int(model.actuator_dyntype[i]),
                    int(model.actuator_gaintype[i]),
                    int(model.actuator_biastype[i]),
                    int(model.actuator_group[i]),
                    _obj_name(model, _TRN_OBJ.get(int(model.actuator_trntype[i]), 0), jid),
                ),
                "gear": model.actuator_gear[i].copy(),
                "gainprm": model.actuator_gainprm[i].copy(),
                "biasprm": model.actuator_biasprm[i].copy(),
                "dynprm": model.actuator_dynprm[i].copy(),
                "actrange": model.actuator_actrange[i].copy()
                if model.actuator_actlimited[i]
                else None,
                "ctrlrange": model.actuator_ctrlrange[i].copy()
                if model.actuator_ctrllimited[i]
                else None,
                "forcerange": model.actuator_forcerange[i].copy()
                if model.actuator_forcelimited[i]
                else None,
            }
        )
    sensors = []
    for i in range(model.nsensor):
        sensors.append(
            (
                model.sensor(i).name,
                str(mujoco.mjtSensor(int(model.sensor_type[i]))),
                _obj_name(model, int(model.sensor_objtype[i]), int(model.sensor_objid[i])),
            )
        )
    site_body = {s: body_name(model, int(model.site_bodyid[i])) for i, s in enumerate(sites)}
    return RobotView(
        kind, bodies, mass, inertia, joints, sites, fk, actuators, sensors, site_body, model
    )


def _obj_name(model: mujoco.MjModel, objtype: int, objid: int) -> str:
    if objid < 0:
        return ""
    name = mujoco.mj_id2name(model, objtype, objid)
    return name or f"#{objid}"


# -- URDF references ----------------------------------------------------------------------
_INERTIA_KEYS = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
_PROBE_TENSOR = np.array([[0.02, 0.001, -0.002], [0.001, 0.03, 0.0015], [-0.002, 0.0015, 0.025]])


# MuJoCo 3.11 differs from 4.x in four ways that matter to a URDF reference (the four
# probes below; a fifth, whether the XML reader takes subnormal numbers, is the URDF
# parser's). Each is detected by what the installed MuJoCo does (a probe, run once),
# not by its version number: the workaround is applied only where MuJoCo needs it, so
# that on a MuJoCo that gets these right the reference stays MuJoCo's own, independent
# of our parser's code.
@functools.cache
def mujoco_urdf_keeps_inertial_rotation() -> bool:
    """Whether MuJoCo's URDF import honours ``<inertial><origin rpy>``.

    MuJoCo 3.11 drops that rotation and keeps the tensor as if it were written in the
    link frame (google-deepmind/mujoco#3559, fixed by #3560; 4.x keeps it)."""
    urdf = (
        '<robot name="probe"><mujoco><compiler fusestatic="false"/></mujoco>'
        '<link name="a"><inertial><origin rpy="0 0 1.5707963267948966"/><mass value="1"/>'
        '<inertia ixx="1" ixy="0" ixz="0" iyy="2" iyz="0" izz="2.5"/></inertial></link>'
        "</robot>"
    )
    model = mujoco.MjModel.from_xml_string(urdf)
    rot = quat_to_mat(model.body_iquat[1])
    tensor = rot @ np.diag(model.body_inertia[1]) @ rot.T
    return bool(np.allclose(tensor, np.diag([2.0, 1.0, 2.5]), atol=1e-9))


@functools.cache
def mujoco_diagonalises_inertia_exactly() -> bool:
    """Whether MuJoCo's compiler turns a full inertia tensor into principal moments and
    axes to rounding (``R diag R^T`` within 1e-13 of the tensor, relative).

    MuJoCo 3.11's ``mju_eig3`` stops its Jacobi sweeps once the next rotation is below
    ~1e-6 rad, so the principal axes it compiles are off by up to that much (the tensor
    rebuilt from them is 4.5e-8 off on this probe); 4.x's is exact to ~2e-15."""
    i = _PROBE_TENSOR
    full = " ".join(repr(float(x)) for x in (i[0, 0], i[1, 1], i[2, 2], i[0, 1], i[0, 2], i[1, 2]))
    model = mujoco.MjModel.from_xml_string(
        '<mujoco><worldbody><body><freejoint/><inertial pos="0 0 0" mass="1" '
        f'fullinertia="{full}"/></body></worldbody></mujoco>'
    )
    rot = quat_to_mat(model.body_iquat[1])
    rebuilt = rot @ np.diag(model.body_inertia[1]) @ rot.T
    return bool(np.abs(rebuilt - i).max() <= 1e-13 * np.abs(i).max())


@functools.cache
def mujoco_urdf_imports_mimic() -> bool:
    """Whether MuJoCo's URDF import turns ``<mimic>`` into a joint equality (4.x does,
    with ``polycoef = (offset, multiplier, 0, 0, 0)``; 3.11 ignores ``<mimic>``)."""
    link = (
        '<link name="{0}"><inertial><mass value="1"/>'
        '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>'
    )
    joint = (
        '<joint name="{0}" type="revolute"><parent link="{1}"/><child link="{2}"/>'
        '<limit lower="-1" upper="1" effort="1" velocity="1"/>{3}</joint>'
    )
    urdf = (
        '<robot name="probe"><mujoco><compiler fusestatic="false"/></mujoco>'
        + "".join(link.format(n) for n in "abc")
        + joint.format("j1", "a", "b", "")
        + joint.format("j2", "b", "c", '<mimic joint="j1" multiplier="2" offset="0.5"/>')
        + "</robot>"
    )
    return mujoco.MjModel.from_xml_string(urdf).neq == 1


@functools.cache
def mujoco_urdf_clamps_effort() -> bool:
    """Whether MuJoCo's URDF import makes ``<limit effort>`` the joint's actuator force
    range (``actfrcrange`` +-effort; 3.11 and 4.x do)."""
    urdf = (
        '<robot name="probe"><mujoco><compiler fusestatic="false"/></mujoco>'
        '<link name="a"/><link name="b"><inertial><mass value="1"/>'
        '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>'
        '<joint name="j" type="revolute"><parent link="a"/><child link="b"/>'
        '<limit lower="-1" upper="1" effort="3" velocity="1"/></joint></robot>'
    )
    model = mujoco.MjModel.from_xml_string(urdf)
    return bool(model.jnt_actfrclimited[0]) and model.jnt_actfrcrange[0].tolist() == [-3.0, 3.0]


@functools.cache
def mujoco_xml_reads_subnormals() -> bool:
    """Whether MuJoCo's XML reader takes a subnormal number (nonzero, below
    ``sys.float_info.min`` in magnitude). MuJoCo 3.11 refuses one ("number is too
    large"); 4.x reads it."""
    try:
        mujoco.MjModel.from_xml_string(
            '<mujoco><worldbody><geom size="0.1" pos="1e-310 0 0"/></worldbody></mujoco>'
        )
    except ValueError:
        return False
    return True


def _tetrahedron_stl(size: float = 1.0) -> bytes:
    """A binary STL tetrahedron (for the probe below)."""
    o, x, y, z = (0, 0, 0), (size, 0, 0), (0, size, 0), (0, 0, size)
    tris = [(o, x, y), (o, z, x), (o, y, z), (x, z, y)]
    out = b"\0" * 80 + struct.pack("<I", len(tris))
    for a, b, c in tris:
        out += struct.pack("<12fH", 0, 0, 0, *a, *b, *c, 0)
    return out


@functools.cache
def mujoco_urdf_keeps_mesh_files_apart() -> bool:
    """Whether MuJoCo's URDF import gives each collision geom the mesh of its own file and
    ``scale``. MuJoCo 3.11 does not: it makes one mesh per scale of a file name but gives
    a geom the first scale's mesh again from the third use on (scales a, b, a, b: the
    last geom gets a), and takes two files of one name in different folders for one
    mesh. 4.x gets both right. The probe tries both."""
    with tempfile.TemporaryDirectory(prefix="robotwright-probe-") as tmp:
        one, other = Path(tmp, "one", "probe.stl"), Path(tmp, "other", "probe.stl")
        for path, size in ((one, 1.0), (other, 2.0)):
            path.parent.mkdir()
            path.write_bytes(_tetrahedron_stl(size))
        uses = [(one, "1 -1 1"), (one, "1 1 1"), (one, "1 -1 1"), (one, "1 1 1"), (other, "1 1 1")]
        links = "".join(
            f'<link name="l{i}"><inertial><mass value="1"/>'
            '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>'
            f'<collision><geometry><mesh filename="{f}" scale="{s}"/></geometry></collision>'
            "</link>"
            for i, (f, s) in enumerate(uses)
        )
        joints = "".join(
            f'<joint name="j{i}" type="fixed"><parent link="l0"/><child link="l{i}"/></joint>'
            for i in range(1, len(uses))
        )
        urdf = (
            '<robot name="probe"><mujoco><compiler fusestatic="false" strippath="false"/>'
            f"</mujoco>{links}{joints}</robot>"
        )
        model = mujoco.MjModel.from_xml_string(urdf)
    # Each geom's mesh: its y scale, and its size relative to the first (MuJoCo moves the
    # vertices to the mesh's principal frame, so compare sizes, not coordinates).
    got = []
    for g in range(model.ngeom):
        mesh = int(model.geom_dataid[g])
        verts = model.mesh_vert[model.mesh_vertadr[mesh] : model.mesh_vertadr[mesh] + 4]
        got.append((float(model.mesh_scale[mesh][1]), float(np.ptp(verts, axis=0).max())))
    sizes = [round(size / got[0][1], 6) for _, size in got]
    return [y for y, _ in got] == [-1.0, 1.0, -1.0, 1.0, 1.0] and sizes == [1, 1, 1, 1, 2]


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


def compile_urdf(
    text: str, density: float | None = None, *, fuse_static: bool = False
) -> mujoco.MjModel:
    """MuJoCo's import of a URDF text (as :func:`urdf_for_mujoco` writes it), compiled.

    ``fuse_static``: links on fixed joints fused into their parents by MuJoCo
    (``fusestatic``, the import's default), the root link kept a body (MuJoCo would fuse
    a fixed base into the world): the reference of ``fixed_joints="merge"``. It adds one
    ``framepos`` sensor per top-level body (what keeps it; sensors are not a URDF's).

    ``density``: kg/m^3 given to the collision geoms (MuJoCo's import gives them its
    default, 1000; a URDF cannot say otherwise), for the links without ``<inertial>``.

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
    ):
        return mujoco.MjModel.from_xml_string(text)
    root = DET.fromstring(text)
    assets: dict[str, bytes] = {}
    if not mujoco_urdf_keeps_mesh_files_apart():
        assets = _split_mesh_scales(root)
        if assets:
            text = ET.tostring(root, encoding="unicode")
    spec = mujoco.MjSpec.from_string(text, assets=assets or None)
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
