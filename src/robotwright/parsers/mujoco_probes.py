"""What the installed MuJoCo does, asked once with a tiny model and remembered: whether
its URDF import keeps an inertial's rotation, imports mimic joints, clamps efforts,
keeps mesh files apart; whether it diagonalises an inertia exactly and reads
subnormal numbers. The readers and the proof adapt to the answers, so that one code
works from MuJoCo 3.11 to 4.x."""

from __future__ import annotations

import functools
import struct
import tempfile
from pathlib import Path

import mujoco
import numpy as np

from robotwright._rotations import quat_to_mat
from robotwright._temporaries import prefix

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
    with tempfile.TemporaryDirectory(prefix=prefix("probe")) as tmp:
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
