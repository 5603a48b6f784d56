"""URDF links without ``<inertial>``: mass and inertia from their collision geoms, as
MuJoCo's own URDF import gives them (``inertiafromgeom="auto"``, density 1000 or
``--density``), or none with ``--inertia-from-geoms never``.

The reference is MuJoCo itself: the same URDF imported with ``MjModel.from_xml_string``
(only ``fusestatic="false"`` added, so that every link stays a body to compare), never a
formula of ours.
"""

from __future__ import annotations

import struct
import subprocess
import sys
from pathlib import Path

import mujoco
import numpy as np
import pytest

from robotwright.errors import ConversionError
from robotwright.parsers import URDFOptions
from robotwright.parsers.api import urdf_to_hrdf_with_warnings
from robotwright.parsers.reference import mujoco_diagonalises_inertia_exactly
from robotwright.proof.roundtrip.run import our_mjcf_model, roundtrip

CUBE = np.array(
    [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]],
    dtype=float,
)
CUBE_FACES = [
    (0, 2, 1), (0, 3, 2), (4, 5, 6), (4, 6, 7), (0, 1, 5), (0, 5, 4),
    (1, 2, 6), (1, 6, 5), (2, 3, 7), (2, 7, 6), (3, 0, 4), (3, 4, 7),
]  # fmt: skip


def _stl(path: Path, vertices: np.ndarray, faces: list[tuple[int, int, int]]) -> None:
    with path.open("wb") as fh:
        fh.write(b"\0" * 80 + struct.pack("<I", len(faces)))
        for face in faces:
            fh.write(struct.pack("<3f", 0, 0, 0))
            for i in face:
                fh.write(struct.pack("<3f", *vertices[i]))
            fh.write(b"\0\0")


def _joint(name: str, kind: str, parent: str, child: str, origin: str = "0 0 0") -> str:
    limit = '<limit lower="-1" upper="1" effort="0" velocity="0"/>' if kind == "revolute" else ""
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{origin}"/><axis xyz="0 1 0"/>{limit}</joint>'
    )


#: Links without <inertial>: "arm" (a rotated box and a scaled, rotated mesh), "forearm"
#: (a cylinder whose visual is the same shape), "hand" (a sphere and a capsule), on fixed
#: joints "vis" (visual only), "tool" (nothing) and "knob" (a collision sphere).
LINKS = """
<link name="base"><inertial><mass value="2"/>
  <inertia ixx="0.1" iyy="0.2" izz="0.3" ixy="0" ixz="0" iyz="0"/></inertial></link>
<link name="arm">
  <collision><origin xyz="0.1 0 0" rpy="0.3 0.2 0.1"/><geometry><box size="0.1 0.2 0.3"/>
  </geometry></collision>
  <collision><origin xyz="0 0.2 0" rpy="0.5 0 0"/><geometry>
  <mesh filename="cube.stl" scale="0.1 0.2 0.05"/></geometry></collision>
  <visual><geometry><sphere radius="0.5"/></geometry></visual></link>
<link name="forearm">
  <collision><origin xyz="0 0 0.3"/><geometry><cylinder radius="0.05" length="0.4"/>
  </geometry></collision>
  <visual><origin xyz="0 0 0.3"/><geometry><cylinder radius="0.05" length="0.4"/>
  </geometry></visual></link>
<link name="hand">
  <collision><origin xyz="0.02 0 0"/><geometry><sphere radius="0.04"/></geometry></collision>
  <collision><origin xyz="0 0 0.1" rpy="1.2 0 0"/><geometry>
  <capsule radius="0.02" length="0.1"/></geometry></collision></link>
<link name="vis"><visual><geometry><sphere radius="0.5"/></geometry></visual></link>
<link name="tool"/>
<link name="knob"><collision><geometry><sphere radius="0.03"/></geometry></collision></link>
"""
JOINTS = [
    _joint("shoulder", "revolute", "base", "arm"),
    _joint("elbow", "revolute", "arm", "forearm", "0 0 0.2"),
    _joint("wrist", "revolute", "forearm", "hand", "0 0 0.5"),
    _joint("vis_mount", "fixed", "forearm", "vis"),
    _joint("tool_mount", "fixed", "hand", "tool", "0 0 0.15"),
    _joint("knob_mount", "fixed", "arm", "knob", "0.1 0.1 0"),
]
WITHOUT_INERTIAL = ("arm", "forearm", "hand", "knob")


def _urdf(folder: Path, compiler: str = "", links: str = LINKS, joints=None) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    _stl(folder / "cube.stl", CUBE, CUBE_FACES)
    mj = f"<mujoco><compiler {compiler}/></mujoco>" if compiler else ""
    body = links + "".join(JOINTS if joints is None else joints)
    path = folder / "arm.urdf"
    path.write_text(f'<robot name="arm">{mj}{body}</robot>')
    return path


def _mujoco_import(path: Path, density: float | None = None, fuse: bool = False):
    """MuJoCo's own URDF import of ``path`` (mesh paths absolute: strippath off)."""
    text = path.read_text().replace("cube.stl", str(path.parent / "cube.stl"))
    compiler = f'<mujoco><compiler fusestatic="{str(fuse).lower()}" strippath="false"/></mujoco>'
    text = text.replace('<robot name="arm">', '<robot name="arm">' + compiler, 1)
    spec = mujoco.MjSpec.from_string(text)
    if density is not None:
        for geom in spec.geoms:
            if geom.density > 0:  # the collision geoms (MuJoCo gives visual ones 0)
                geom.density = density
    return spec.compile()


def _tensor(model: mujoco.MjModel, i: int) -> np.ndarray:
    rot = np.zeros(9)
    mujoco.mju_quat2Mat(rot, model.body_iquat[i])
    rot = rot.reshape(3, 3)
    return rot @ np.diag(model.body_inertia[i]) @ rot.T


def _body_fields(model: mujoco.MjModel, name: str, principal: bool) -> np.ndarray:
    """Mass, centre of mass (of a body with mass) and inertia tensor (body frame); with
    ``principal`` the principal moments and frame as compiled (MuJoCo's order)."""
    i = model.body(name).id
    ipos = model.body_ipos[i] if model.body_mass[i] > 0 else []
    fields = [[model.body_mass[i]], ipos, _tensor(model, i).ravel()]
    if principal:
        fields += [model.body_iquat[i], model.body_inertia[i]]
    return np.concatenate(fields)


def _assert_same_bodies(ref: mujoco.MjModel, ours: mujoco.MjModel, names) -> None:
    """Equal to 1e-9 (relative to the largest value); the links without <inertial>
    also in MuJoCo's principal moments and frame, as compiled."""
    for name in names:
        principal = name in WITHOUT_INERTIAL
        a, b = _body_fields(ref, name, principal), _body_fields(ours, name, principal)
        scale = max(np.abs(a).max(), 1e-300)
        assert np.abs(a - b).max() <= 1e-9 * scale, (name, a, b)


@pytest.fixture
def arm(tmp_path: Path) -> Path:
    return _urdf(tmp_path / "arm")


def test_masses_and_inertias_equal_mujocos_urdf_import(arm: Path) -> None:
    ref = _mujoco_import(arm)
    result = urdf_to_hrdf_with_warnings(arm)
    ours = our_mjcf_model(result.hrdf)
    names = [ref.body(i).name for i in range(1, ref.nbody)]
    _assert_same_bodies(ref, ours, names)
    # The links without <inertial> got mass (MuJoCo's import gives these the collision
    # geoms' mass), the visual-only and the empty one none, as MuJoCo.
    for name in WITHOUT_INERTIAL:
        assert ours.body_mass[ours.body(name).id] > 0
    for name in ("vis", "tool"):
        assert ref.body_mass[ref.body(name).id] == 0.0
        assert ours.body_mass[ours.body(name).id] == 0.0


def test_fused_import_equals_merged_links(arm: Path) -> None:
    """MuJoCo's default import fuses fixed links into their parent; our merge policy
    combines the computed inertias the same way."""
    ref = _mujoco_import(arm, fuse=True)
    ours = our_mjcf_model(urdf_to_hrdf_with_warnings(arm, fixed_joints="merge").hrdf)
    a, b = ref.body("arm").id, ours.body("arm").id
    assert ref.body_mass[a] == pytest.approx(ours.body_mass[b], rel=1e-12)
    assert np.allclose(ref.body_ipos[a], ours.body_ipos[b], rtol=0, atol=1e-12)
    # MuJoCo diagonalises the fused tensor itself: 3.11 to ~1e-6 rad of the principal axes
    # (mujoco_diagonalises_inertia_exactly), 4.x to rounding.
    exact = mujoco_diagonalises_inertia_exactly()
    atol = 1e-12 if exact else 1e-6 * np.abs(_tensor(ours, b)).max()
    assert np.allclose(_tensor(ref, a), _tensor(ours, b), rtol=0, atol=atol)
    # MuJoCo fuses the jointless root link (2 kg) into the world body, whose mass is 0.
    assert sum(ref.body_mass) + 2.0 == pytest.approx(sum(ours.body_mass), rel=1e-12)


@pytest.mark.parametrize("density", [1.0, 300.0, 7850.0])
def test_density_option_equals_mujoco_at_that_density(arm: Path, density: float) -> None:
    ref = _mujoco_import(arm, density=density)
    ours = our_mjcf_model(urdf_to_hrdf_with_warnings(arm, density=density).hrdf)
    _assert_same_bodies(ref, ours, WITHOUT_INERTIAL + ("base",))
    default = our_mjcf_model(urdf_to_hrdf_with_warnings(arm).hrdf)
    for name in WITHOUT_INERTIAL:
        ratio = ours.body_mass[ours.body(name).id] / default.body_mass[default.body(name).id]
        assert ratio == pytest.approx(density / 1000.0, rel=1e-12)


def test_one_note_per_link_naming_it_and_its_mass(arm: Path) -> None:
    result = urdf_to_hrdf_with_warnings(arm)
    ours = our_mjcf_model(result.hrdf)
    notes = [w for w in result.warnings if "no <inertial>" in w.message]
    by_link = {w.element: w.message for w in notes}
    assert len(by_link) == len(notes)  # one each
    for name in WITHOUT_INERTIAL:
        message = by_link[f'<link name="{name}">']
        assert repr(float(ours.body_mass[ours.body(name).id])) in message
        assert "1000.0 kg/m^3" in message
    # The visual-only link is noted with mass 0; the empty frame link has nothing to note.
    assert "mass 0" in by_link['<link name="vis">']
    assert '<link name="tool">' not in by_link
    assert '<link name="base">' not in by_link  # it has an <inertial>


def test_strict_refuses_computed_inertia(arm: Path) -> None:
    with pytest.raises(ConversionError) as info:
        urdf_to_hrdf_with_warnings(arm, strict=True)
    assert any((p.element or "") == '<link name="arm">' for p in info.value.problems)


def test_never_keeps_links_massless(arm: Path) -> None:
    result = urdf_to_hrdf_with_warnings(arm, inertia_from_geoms="never")
    masses = {b.name: b.mass for b in result.hrdf.bodies}
    for name in WITHOUT_INERTIAL:
        assert masses[name] == 0.0
    assert not any("no <inertial>" in w.message for w in result.warnings)
    # The moving ones are named as bodies MuJoCo refuses.
    refused = {w.element for w in result.warnings if "MuJoCo refuses it" in w.message}
    assert {'<link name="arm">', '<link name="forearm">', '<link name="hand">'} <= refused


def test_roundtrip_passes_against_mujocos_import(arm: Path) -> None:
    report = roundtrip(arm, configs=3, reference="mujoco")
    assert report.ok, report.table()
    report = roundtrip(arm, configs=3, reference="mujoco", density=450.0)
    assert report.ok, report.table()


def _cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "robotwright", *args], capture_output=True, text=True, timeout=300
    )


def test_cli_auto_converts_never_refuses(arm: Path, tmp_path: Path) -> None:
    out = tmp_path / "out.xml"
    done = _cli("convert", str(arm), "-o", str(out), "--density", "500")
    assert done.returncode == 0, done.stderr
    model = mujoco.MjModel.from_xml_path(str(out))
    ref = _mujoco_import(arm, density=500.0)
    _assert_same_bodies(ref, model, WITHOUT_INERTIAL)
    refused = tmp_path / "refused.xml"
    done = _cli("convert", str(arm), "-o", str(refused), "--inertia-from-geoms", "never")
    assert done.returncode == 2
    assert not refused.exists()
    assert "Traceback" not in done.stderr


def test_visual_only_moving_link_is_refused_as_mujoco_refuses_it(tmp_path: Path) -> None:
    links = LINKS
    joints = [*JOINTS[:3], _joint("vis_mount", "revolute", "forearm", "vis")] + JOINTS[4:]
    path = _urdf(tmp_path / "v", links=links, joints=joints)
    with pytest.raises(ValueError):
        _mujoco_import(path)
    result = urdf_to_hrdf_with_warnings(path)
    assert {b.name: b.mass for b in result.hrdf.bodies}["vis"] == 0.0
    elements = [w.element for w in result.warnings if "MuJoCo refuses it" in w.message]
    assert elements == ['<link name="vis">']
    done = _cli("convert", str(path), "-o", str(tmp_path / "out.xml"))
    assert done.returncode == 2 and not (tmp_path / "out.xml").exists()


def test_xacro_source_gets_the_same(tmp_path: Path) -> None:
    plain = _urdf(tmp_path / "x")
    xacro = plain.with_suffix(".urdf.xacro")
    text = plain.read_text().replace(
        '<robot name="arm">', '<robot name="arm" xmlns:xacro="http://www.ros.org/wiki/xacro">'
    )
    xacro.write_text(text.replace('radius="0.05"', 'radius="${0.1 / 2}"'))
    a = our_mjcf_model(urdf_to_hrdf_with_warnings(plain).hrdf)
    b = our_mjcf_model(urdf_to_hrdf_with_warnings(xacro).hrdf)
    _assert_same_bodies(a, b, WITHOUT_INERTIAL)


@pytest.mark.parametrize("value", [0, -1.0, float("nan"), float("inf"), "dense"])
def test_bad_density_option_refused(value) -> None:
    with pytest.raises(ValueError, match="density"):
        URDFOptions(density=value)


def test_bad_mode_refused() -> None:
    with pytest.raises(ValueError, match="inertia_from_geoms"):
        URDFOptions(inertia_from_geoms="sometimes")  # type: ignore[arg-type]
