"""Things write what MuJoCo compiled (issue "Fidelity on every robot", item 2.9).

Each case compares the model MuJoCo compiles from the source with the one compiled from
the Things' MJCF: box/ellipsoid ``fromto`` sizes, ``inheritrange`` in default classes,
full precision of the carried sections (tendons, keyframes, equalities), ``<size
memory>`` beside ``njmax``, cube textures with one file per face, and meshes that no
geom uses. Real files come from robosuite, robosuite-models and dm-control (skipped
with a reason when absent).
"""

from __future__ import annotations

import struct
import warnings
import zlib
from pathlib import Path

import mujoco
import numpy as np
import pytest

from robotwright.errors import ConversionWarning
from robotwright.things import MeshAsset, World

from ._compare import assert_same_model

TESTDATA = Path(__file__).resolve().parents[2] / ".testdata"
ROBOSUITE = TESTDATA / "robosuite" / "robosuite" / "models" / "assets" / "robots"
ROBOSUITE_MODELS = TESTDATA / "robosuite-models" / "robosuite_models" / "assets" / "robots"


def _real(path: Path) -> Path:
    if not path.is_file():
        pytest.skip(f"test data not fetched (run python tools/fetch_test_data.py): {path}")
    return path


def _read(source: str | Path, **kw) -> World:
    with warnings.catch_warnings():
        warnings.simplefilter("error", ConversionWarning)  # nothing may be dropped
        if isinstance(source, Path):
            return World.from_xml_path(source, **kw)
        return World.from_xml_string(source, **kw)


def _same_through_text(world: World, original: mujoco.MjModel) -> mujoco.MjModel:
    """The model compiled from the World's MJCF text, checked against ``original``."""
    ours = mujoco.MjModel.from_xml_string(world.to_xml_string())
    assert_same_model(original, ours)
    return ours


# ---------------------------------------------------------------- fromto sizes
FROMTO = """<mujoco><worldbody><body>
  <geom type="box" size="0.04 0.025 0.08" fromto="0.02 0 0 -0.01 0 -0.35"/>
  <geom type="ellipsoid" size="0.03 0.01 0.5" fromto="0 0 0 0.1 0.2 0.3"/>
  <geom type="capsule" size="0.02 0.7" fromto="0 0 0 0 0.1 0"/>
  <geom type="cylinder" size="0.05 0.1 0.3" fromto="0 0 0 0.3 0 0"/>
</body></worldbody></mujoco>"""


def test_fromto_box_and_ellipsoid_get_mujocos_size():
    original = mujoco.MjModel.from_xml_string(FROMTO)
    # MuJoCo makes both cross-section half-sizes size[0]; the authored size[1] is unused.
    np.testing.assert_allclose(original.geom_size[0], [0.04, 0.04, np.hypot(0.03, 0.35) / 2])
    world = _read(FROMTO)
    np.testing.assert_array_equal(world.model.geom_size, original.geom_size)
    _same_through_text(world, original)


@pytest.mark.realdata
def test_b1_fromto_boxes_real():
    path = _real(ROBOSUITE_MODELS / "b1" / "robot.xml")
    assert 'type="box"' in path.read_text() and "fromto" in path.read_text()
    original = mujoco.MjModel.from_xml_path(str(path))
    world = _read(path)
    assert_same_model(original, world.model)
    boxes = original.geom_type == mujoco.mjtGeom.mjGEOM_BOX
    np.testing.assert_array_equal(world.model.geom_size[boxes], original.geom_size[boxes])


# ---------------------------------------------------------------- inheritrange
INHERIT = """<mujoco><default>
  <default class="leg"><position kp="500" kv="40" inheritrange="1"/>
    <motor ctrlrange="-70 70" ctrllimited="true"/></default>
  <default class="half"><position kp="10" inheritrange="0.5"/></default>
  <default class="free"><position kp="10" inheritrange="1"/></default>
</default>
<worldbody><body><joint name="a" range="-1 2"/><geom size=".1"/>
  <body><joint name="b" range="-0.5 0.25"/><geom size=".1"/></body></body></worldbody>
<actuator>
  <motor class="leg" name="m" joint="a"/>
  <position class="leg" name="p" joint="a"/>
  <position class="half" name="h" joint="b"/>
  <motor class="free" name="unlimited" joint="b"/>
  <intvelocity name="iv" joint="b" kp="3" inheritrange="1"/>
</actuator></mujoco>"""


def _compiled_or_skip(xml: str) -> mujoco.MjModel:
    """The source compiled by MuJoCo; the test is moot where this MuJoCo refuses it
    (MuJoCo 3.x rejects some sources 4.x reads: we accept what MuJoCo accepts)."""
    try:
        return mujoco.MjModel.from_xml_string(xml)
    except ValueError as exc:
        pytest.skip(f"MuJoCo {mujoco.__version__} refuses the source: {exc}")


def test_inheritrange_in_a_class_gives_what_mujoco_compiles():
    original = _compiled_or_skip(INHERIT)
    # the motor keeps its class's ctrlrange, not the joint range of the class's <position>
    np.testing.assert_array_equal(original.actuator_ctrlrange[0], [-70, 70])
    world = _read(INHERIT)
    model = world.model
    for field in ("actuator_ctrlrange", "actuator_ctrllimited", "actuator_actrange"):
        np.testing.assert_array_equal(getattr(model, field), getattr(original, field), field)
    np.testing.assert_array_equal(model.actuator_actlimited, original.actuator_actlimited)
    _same_through_text(world, original)


@pytest.mark.realdata
@pytest.mark.parametrize("robot", ["spot", "spot_arm"])
def test_spot_motors_keep_their_ctrlrange_real(robot):
    path = _real(ROBOSUITE / robot / "robot.xml")
    original = mujoco.MjModel.from_xml_path(str(path))
    world = _read(path)
    motors = original.actuator_biastype == mujoco.mjtBias.mjBIAS_NONE
    assert motors.sum() >= 6
    np.testing.assert_array_equal(world.model.actuator_ctrlrange, original.actuator_ctrlrange)
    assert_same_model(original, world.model)


# ---------------------------------------------------------------- full precision
PRECISE = """<mujoco><worldbody>
  <site name="s0" pos="0 0 1"/>
  <body name="a" pos="0 0 0.5"><joint name="j1" axis="1 0 0"/><geom name="ga" size=".1"/>
    <site name="s1" pos="0.1234567891 0 0"/>
    <body name="b" pos="0 0 -0.3"><joint name="j2" axis="0 1 0"/><geom name="gb" size=".05"/>
    </body>
  </body></worldbody>
<tendon>
  <fixed name="t" stiffness="3.14159265358979" springlength="0.123456789012" damping="0.7777777777">
    <joint joint="j1" coef="1.23456789012"/><joint joint="j2" coef="-0.987654321098"/></fixed>
  <spatial name="cable" stiffness="2.718281828459" range="0 1.41421356237" limited="true">
    <site site="s0"/><site site="s1"/></spatial>
</tendon>
<equality><joint joint1="j2" joint2="j1" polycoef="0.1234567891 1.000000123 0 0 0"/></equality>
<actuator><motor name="tm" tendon="t" gear="1.000000123" ctrlrange="-0.333333333 0.333333333"/>
</actuator>
<keyframe><key name="k" qpos="0.1234567891 -0.98765432109" ctrl="0.1111111111"/></keyframe>
<contact><pair geom1="ga" geom2="gb" margin="0.00123456789" friction="0.91234567 0.91234567
  0.005123456 0.0001 0.0001"/></contact>
<statistic extent="2.123456789" center="0.1234567891 0 0.5"/>
</mujoco>"""


def test_carried_sections_keep_full_precision():
    original = mujoco.MjModel.from_xml_string(PRECISE)
    world = _read(PRECISE)
    ours = _same_through_text(world, original)
    for field in (
        "tendon_stiffness",
        "tendon_lengthspring",
        "tendon_damping",
        "tendon_range",
        "wrap_prm",
        "eq_data",
        "actuator_gear",
        "actuator_ctrlrange",
        "key_qpos",
        "key_ctrl",
        "pair_margin",
        "pair_friction",
    ):
        np.testing.assert_array_equal(getattr(ours, field), getattr(original, field), field)
    assert ours.stat.extent == original.stat.extent == 2.123456789
    np.testing.assert_array_equal(ours.stat.center, original.stat.center)
    # MuJoCo's own writer would have rounded these to six digits
    assert ours.tendon_stiffness[0].ravel()[0] == 3.14159265358979
    assert ours.key_qpos[0, 0] == 0.1234567891


@pytest.mark.realdata
def test_dog_tendon_coefficients_full_precision_real():
    dm_control = pytest.importorskip("dm_control", reason="dm-control (test extra) not installed")
    path = Path(dm_control.__file__).parent / "suite" / "dog.xml"
    original = mujoco.MjModel.from_xml_path(str(path))
    with pytest.warns(ConversionWarning, match="skin"):  # the one part Things drop, named
        world = World.from_xml_path(path)
    ours = world.model
    assert original.nwrap > 0
    np.testing.assert_array_equal(ours.wrap_prm, original.wrap_prm)
    np.testing.assert_array_equal(ours.tendon_lengthspring, original.tendon_lengthspring)
    np.testing.assert_array_equal(ours.key_qpos, original.key_qpos)


# ---------------------------------------------------------------- <size>
def test_size_memory_beside_njmax_from_two_elements():
    xml = """<mujoco><size memory="10M"/><size njmax="500" nconmax="60"/>
      <worldbody><body><joint/><geom size=".1"/></body></worldbody></mujoco>"""
    original = _compiled_or_skip(xml)
    world = _read(xml)
    ours = _same_through_text(world, original)
    assert (ours.narena, ours.njmax, ours.nconmax) == (
        original.narena,
        original.njmax,
        original.nconmax,
    )
    assert original.narena == 10 * 2**20 and original.njmax == 500


# ---------------------------------------------------------------- cube textures
def _png(path: Path, rgb: tuple[int, int, int], size: int = 4) -> None:
    """A tiny solid-colour RGB PNG (MuJoCo reads PNG textures)."""
    raw = b"".join(b"\x00" + bytes(rgb) * size for _ in range(size))

    def chunk(kind: bytes, data: bytes) -> bytes:
        return (
            struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
        )

    header = struct.pack(">IIBBBBB", size, size, 8, 2, 0, 0, 0)
    path.write_bytes(
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", header)
        + chunk(b"IDAT", zlib.compress(raw))
        + chunk(b"IEND", b"")
    )


FACES = ("right", "left", "up", "down", "front", "back")


def test_cube_texture_with_a_file_per_face_is_kept_and_exported(tmp_path):
    src = tmp_path / "src"
    src.mkdir()
    for k, face in enumerate(FACES):
        _png(src / f"{face}.png", (40 * k, 255 - 40 * k, 7 * k))
    files = " ".join(f'file{face}="{face}.png"' for face in FACES)
    (src / "model.xml").write_text(
        f"""<mujoco><asset><texture name="dice" type="cube" {files}/>
        <material name="m" texture="dice"/></asset>
        <worldbody><body><joint/><geom size=".1" material="m"/></body></worldbody></mujoco>"""
    )
    original = mujoco.MjModel.from_xml_path(str(src / "model.xml"))
    world = _read(src / "model.xml")
    np.testing.assert_array_equal(world.model.tex_data, original.tex_data)
    out = world.export(tmp_path / "out" / "model.xml")
    assert sorted(p.name for p in (tmp_path / "out" / "assets").iterdir()) == sorted(
        f"{face}.png" for face in FACES
    )
    exported = mujoco.MjModel.from_xml_path(str(out))
    assert exported.ntex == 1
    np.testing.assert_array_equal(exported.tex_data, original.tex_data)


# ---------------------------------------------------------------- unused meshes
def test_meshes_no_geom_uses_are_kept(tmp_path):
    xml = """<mujoco><asset>
      <mesh name="used" vertex="0 0 0 1 0 0 0 1 0 0 0 1"/>
      <mesh name="spare" vertex="0 0 0 2 0 0 0 2 0 0 0 2" scale="1 1 0.5"/></asset>
      <worldbody><body><joint/><geom type="mesh" mesh="used"/></body></worldbody></mujoco>"""
    original = mujoco.MjModel.from_xml_string(xml)
    world = _read(xml)
    assert [type(a) for a in world.assets] == [MeshAsset]
    ours = _same_through_text(world, original)
    assert {ours.mesh(i).name for i in range(ours.nmesh)} == {"used", "spare"}
    spare_a, spare_b = original.mesh("spare"), ours.mesh("spare")
    np.testing.assert_allclose(
        ours.mesh_vert[spare_b.vertadr[0] : spare_b.vertadr[0] + spare_b.vertnum[0]],
        original.mesh_vert[spare_a.vertadr[0] : spare_a.vertadr[0] + spare_a.vertnum[0]],
    )


@pytest.mark.realdata
def test_spot_unused_mesh_is_kept_real(tmp_path):
    path = _real(ROBOSUITE / "spot" / "robot.xml")
    original = mujoco.MjModel.from_xml_path(str(path))
    world = _read(path)
    assert world.model.nmesh == original.nmesh
    out = world.export(tmp_path / "spot" / "robot.xml")
    exported = mujoco.MjModel.from_xml_path(str(out))
    assert_same_model(original, exported)
    assert exported.nmesh == len(list((tmp_path / "spot" / "assets").iterdir()))
