"""The proof of a conversion (issue 20): every per-object array of MjModel compared
between the source and the output, matched by name and structure; each difference no
note reports becomes a note naming field, object and both values; ``strict`` fails."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import mujoco
import numpy as np
import pytest

from robotwright.cli import main
from robotwright.errors import ConversionError
from robotwright.hrdf.model import HRDF
from robotwright.parsers.reference import mujoco_diagonalises_inertia_exactly
from robotwright.proof import compare as proof
from robotwright.proof.convert import convert

pytestmark = pytest.mark.usefixtures("quiet_parsers")

ROBOT = """<mujoco model="r">
  <size nuser_jnt="1" nuser_geom="2"/>
  <option timestep="0.004" impratio="3" cone="elliptic"/>
  <worldbody>
    <geom name="floor" type="plane" size="5 5 0.1"/>
    <body name="base" pos="0 0 1">
      <freejoint name="root"/>
      <geom name="torso" type="box" size="0.1 0.2 0.3" mass="2" solref="0.03 1.1"
            friction="0.8 0.01 0.002" user="1 2"/>
      <site name="imu" size="0.01"/>
      <body name="arm" pos="0 0.3 0">
        <joint name="shoulder" axis="0 1 0" range="-1 1" damping="0.5" armature="0.01"
               stiffness="3" user="7"/>
        <geom type="capsule" size="0.03" fromto="0 0 0 0 0 -0.3" mass="0.5"/>
        <geom type="sphere" size="0.04" pos="0 0 -0.3" mass="0.1"/>
        <body name="hand" pos="0 0 -0.3">
          <joint name="wrist" type="slide" axis="1 0 0" range="-0.1 0.1"/>
          <geom type="box" size="0.02 0.02 0.02" mass="0.05"/>
        </body>
      </body>
    </body>
  </worldbody>
  <tendon><fixed name="t"><joint joint="shoulder" coef="1"/></fixed></tendon>
  <actuator>
    <motor name="m" joint="shoulder" gear="20" ctrlrange="-1 1" ctrllimited="true"/>
    <position name="p" joint="wrist" kp="50"/>
  </actuator>
  <sensor>
    <jointpos name="q" joint="shoulder" noise="0.01"/>
    <actuatorfrc name="f" actuator="m"/>
  </sensor>
  <keyframe><key name="k" qpos="0 0 1 1 0 0 0 0.2 0.05"/></keyframe>
</mujoco>
"""


def _model(xml: str) -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_string(xml)


def test_fields_are_derived_from_mujoco() -> None:
    m = _model(ROBOT)
    found = proof.fields(m)
    # Every family has fields, each of that family's count, named as MuJoCo names them.
    for fam, attrs in found.items():
        assert attrs, fam
        n = getattr(m, proof.FAMILIES[fam][0])
        assert all(getattr(m, a).shape[0] == n for a in attrs)
    assert "geom_solref" in found["geom"] and "jnt_user" in found["jnt"]
    assert "jnt_qposadr" not in found["jnt"]  # addresses follow from the rest
    assert "impratio" in proof.option_fields(m)


def test_same_model_has_no_difference() -> None:
    assert proof.compare_models(_model(ROBOT), _model(ROBOT)) == []


def test_reordered_model_matches_by_name_and_structure() -> None:
    # A body's geoms in another order: matched, and the order is the one difference
    # (MuJoCo finds contacts in geom order).
    swapped = ROBOT.replace(
        '<geom type="capsule" size="0.03" fromto="0 0 0 0 0 -0.3" mass="0.5"/>\n'
        '        <geom type="sphere" size="0.04" pos="0 0 -0.3" mass="0.1"/>',
        '<geom type="sphere" size="0.04" pos="0 0 -0.3" mass="0.1"/>\n'
        '        <geom type="capsule" size="0.03" fromto="0 0 0 0 0 -0.3" mass="0.5"/>',
    )
    assert swapped != ROBOT
    found = proof.compare_models(_model(ROBOT), _model(swapped))
    assert [d.field for d in found] == ["geom order"]
    assert proof.compare_models(_model(ROBOT), _model(swapped), geom_order=False) == []
    # Actuators (and the keyframe's ctrl with them) in another order: still equal.
    reordered = ROBOT.replace(
        '<motor name="m" joint="shoulder" gear="20" ctrlrange="-1 1" ctrllimited="true"/>\n'
        '    <position name="p" joint="wrist" kp="50"/>',
        '<position name="p" joint="wrist" kp="50"/>\n'
        '    <motor name="m" joint="shoulder" gear="20" ctrlrange="-1 1" ctrllimited="true"/>',
    )
    assert reordered != ROBOT
    # (the keyframe's ctrl follows the actuators: compared per actuator)
    assert proof.compare_models(_model(ROBOT), _model(reordered)) == []


#: (what is changed in the source text, by what, the field the proof must name)
CHANGES = [
    ('solref="0.03 1.1"', 'solref="0.05 1.1"', "geom_solref", "geom 'torso'"),
    ('friction="0.8 0.01 0.002"', 'friction="0.5 0.01 0.002"', "geom_friction", "geom 'torso'"),
    ('user="1 2"', 'user="1 3"', "geom_user", "geom 'torso'"),
    ('stiffness="3" user="7"', 'stiffness="4" user="7"', "jnt_stiffness", "joint 'shoulder'"),
    ('stiffness="3" user="7"', 'stiffness="3" user="8"', "jnt_user", "joint 'shoulder'"),
    ('damping="0.5"', 'damping="0.6"', "dof_damping", "joint 'shoulder'"),
    ('armature="0.01"', 'armature="0.02"', "dof_armature", "joint 'shoulder'"),
    ('range="-0.1 0.1"', 'range="-0.2 0.1"', "jnt_range", "joint 'wrist'"),
    ('mass="0.05"', 'mass="0.06"', "body_mass", "body 'hand'"),
    ('<site name="imu" size="0.01"/>', '<site name="imu" size="0.01" pos="0 0 0.1"/>',
     "site_pos", "site 'imu'"),
    ('gear="20"', 'gear="21"', "actuator_gear", "actuator 'm'"),
    ('kp="50"', 'kp="60"', "actuator_gainprm", "actuator 'p'"),
    ('noise="0.01"', 'noise="0.02"', "sensor_noise", "sensor 'q'"),
    ('coef="1"', 'coef="1"/></fixed><fixed name="u"><joint joint="wrist" coef="1"', "(object)",
     "tendon 'u'"),
    ('impratio="3"', 'impratio="4"', "opt.impratio", "<option>"),
    ('cone="elliptic"', 'cone="pyramidal"', "opt.cone", "<option>"),
    ('qpos="0 0 1 1 0 0 0 0.2 0.05"', 'qpos="0 0 1 1 0 0 0 0.3 0.05"', "key_qpos", "key 'k'"),
    ('<actuatorfrc name="f" actuator="m"/>', '<actuatorfrc name="f" actuator="p"/>',
     "sensor_objid", "sensor 'f'"),
]  # fmt: skip


@pytest.mark.parametrize(("old", "new", "field", "obj"), CHANGES, ids=[c[2] for c in CHANGES])
def test_each_changed_value_is_named(old: str, new: str, field: str, obj: str) -> None:
    assert ROBOT.count(old) == 1
    changed = ROBOT.replace(old, new)
    diffs = proof.compare_models(_model(ROBOT), _model(changed))
    assert any(d.field == field and obj in d.obj for d in diffs), diffs
    # Nothing else is blamed on an unrelated object.
    assert all(obj in d.obj or d.field == "(object)" for d in diffs), diffs


def test_root_body_leaves_the_scene_out() -> None:
    scene = ROBOT.replace(
        "</worldbody>",
        '<body name="ball" pos="2 0 0"><freejoint/><geom size="0.1"/></body></worldbody>',
    )
    diffs = proof.compare_models(_model(scene), _model(ROBOT), root_body="base")
    assert diffs == []
    assert any(d.obj == "body 'ball'" for d in proof.compare_models(_model(scene), _model(ROBOT)))


def test_tolerance_has_an_absolute_floor() -> None:
    a = np.array([[0.0, 1.0], [1e9, 2.0]])
    assert proof._bad_rows(a, a + np.array([[6e-36, 0.0], [0.5, 0.0]])).tolist() == []
    assert proof._bad_rows(a, a + np.array([[1e-6, 0.0], [0.0, 0.0]])).tolist() == [0]
    # NaN equals NaN (MuJoCo keeps what it read); NaN against a number differs.
    n = np.array([[np.nan]])
    assert proof._bad_rows(n, n).tolist() == [] and proof._bad_rows(
        n, np.ones((1, 1))
    ).tolist() == [0]


def test_a_note_naming_object_and_field_covers_the_difference() -> None:
    diffs = proof.compare_models(_model(ROBOT), _model(ROBOT.replace('stiffness="3"', "")))
    assert [d.field for d in diffs] == ["jnt_stiffness"]
    assert proof.uncovered(diffs, ['r.xml: <joint name="shoulder">: stiffness dropped']) == []
    # A note about another joint, or another field of this one, does not.
    assert proof.uncovered(diffs, ['r.xml: <joint name="wrist">: stiffness dropped']) == diffs
    assert proof.uncovered(diffs, ['r.xml: <joint name="shoulder">: damping dropped']) == diffs
    problems = proof.as_problems("r.xml", diffs)
    assert len(problems) == 1
    text = str(problems[0])
    assert "jnt_stiffness" in text and "shoulder" in text and "3.0" in text and "0.0" in text


def _write(tmp_path: Path, xml: str, name: str = "r.xml") -> Path:
    p = tmp_path / name
    p.write_text(xml)
    return p


@pytest.mark.parametrize("out", ["hrdf", "r_out.xml"])
def test_faithful_conversion_has_no_unreported_difference(tmp_path: Path, out: str) -> None:
    src = _write(tmp_path, ROBOT)
    messages = convert(src, tmp_path / out)
    assert not [m for m in messages if "proof:" in m], messages


#: A robot whose conversion has no note at all (strict passes it).
PLAIN = """<mujoco model="p">
  <worldbody>
    <body name="base">
      <geom type="box" size="0.1 0.1 0.1" mass="1"/>
      <body name="arm" pos="0 0 0.2">
        <joint name="shoulder" axis="0 1 0" range="-1 1" damping="0.5"/>
        <geom type="capsule" size="0.03" fromto="0 0 0 0 0 0.3" mass="0.5"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


def test_plain_robot_converts_strictly(tmp_path: Path) -> None:
    assert convert(_write(tmp_path, PLAIN), tmp_path / "out.xml", strict=True) == []


def _lose_shoulder_damping(monkeypatch: pytest.MonkeyPatch) -> None:
    """A writer that loses one value silently (what the proof is for)."""
    real = HRDF.save

    def save(self: HRDF, path, **kw):
        joints = [
            dataclasses.replace(j, viscous_friction=0.0) if j.name == "shoulder" else j
            for j in self.joints
        ]
        return real(dataclasses.replace(self, joints=joints), path, **kw)

    monkeypatch.setattr(HRDF, "save", save)


def test_a_silent_loss_becomes_a_note(tmp_path: Path, monkeypatch) -> None:
    _lose_shoulder_damping(monkeypatch)
    messages = convert(_write(tmp_path, ROBOT), tmp_path / "out")
    lost = [m for m in messages if "proof:" in m and "simulation," not in m]
    assert len(lost) == 1 and "dof_damping" in lost[0] and "'shoulder'" in lost[0], messages
    assert "source 0.5" in lost[0] and "result 0.0" in lost[0]
    # and what it does: the arm swings otherwise (the proof simulates by default)
    moved = [m for m in messages if "proof: simulation," in m]
    assert moved and all("(joint 'shoulder'" in m or "(joint 'elbow'" in m for m in moved)


def test_strict_fails_on_a_silent_loss_and_writes_nothing(tmp_path: Path, monkeypatch) -> None:
    _lose_shoulder_damping(monkeypatch)
    src = _write(tmp_path, PLAIN)
    with pytest.raises(ConversionError, match="dof_damping"):
        convert(src, tmp_path / "out", strict=True)
    assert not (tmp_path / "out").exists()


def test_proof_can_be_turned_off(tmp_path: Path, monkeypatch) -> None:
    _lose_shoulder_damping(monkeypatch)
    messages = convert(_write(tmp_path, ROBOT), tmp_path / "out", proof=False)
    assert not [m for m in messages if "proof:" in m]


def test_cli_strict_exit_2_on_a_silent_loss(tmp_path: Path, monkeypatch, capsys) -> None:
    _lose_shoulder_damping(monkeypatch)
    src = _write(tmp_path, PLAIN)
    assert main(["convert", str(src), "-o", str(tmp_path / "out"), "--strict"]) == 2
    err = capsys.readouterr().err
    assert "dof_damping" in err and "Traceback" not in err
    assert not (tmp_path / "out").exists()


# -- the silent faults of issue 20 ---------------------------------------------------------
CARRIED = """<mujoco>
  <worldbody>
    <body name="a"><joint name="j"/><geom size="0.1"/>
      <body name="b"><joint name="k"/><geom size="0.1" pos="0 0 0.3"/></body>
    </body>
  </worldbody>
  <tendon><fixed name="t"><joint joint="j" coef="1"/><joint joint="k" coef="-1"/></fixed></tendon>
  <actuator>
    <motor name="m" joint="j"/>
    <general name="g" tendon="t" dyntype="filter" dynprm="0.1"/>
  </actuator>
  <sensor>
    <actuatorfrc name="fm" actuator="m"/>
    <actuatorfrc name="fg" actuator="g"/>
    <jointpos name="after" joint="k"/>
  </sensor>
</mujoco>
"""


def test_actuatorfrc_of_a_carried_actuator_moves_with_it(tmp_path: Path) -> None:
    messages = convert(_write(tmp_path, CARRIED), tmp_path / "out")
    assert not [m for m in messages if "proof:" in m], messages
    out = HRDF.from_dir(tmp_path / "out")
    from robotwright.proof.roundtrip.run import our_mjcf_model

    model = our_mjcf_model(out)
    # Every sensor kept, in order, reading the same objects (the proof compared them).
    names = [model.sensor(i).name for i in range(model.nsensor)]
    assert names == ["fm", "fg", "after"]
    fg = model.sensor("fg")
    assert model.actuator(int(fg.objid[0])).name == "g"


UNNAMED = """<mujoco>
  <worldbody>
    <body><joint name="h"/><geom size="0.1"/></body>
    <body name="box" pos="1 0 0"><freejoint/><geom type="box" size="0.1 0.1 0.1"/></body>
  </worldbody>
</mujoco>
"""


def test_unnamed_top_level_body_selectable_by_the_listed_name(tmp_path: Path, capsys) -> None:
    src = _write(tmp_path, UNNAMED)
    # Whole, the world is a scene of two roots: the unnamed body gets the listed name.
    assert main(["convert", str(src), "-o", str(tmp_path / "w")]) == 0
    assert [b.name for b in HRDF.from_dir(tmp_path / "w").bodies] == ["body_1", "box"]
    assert main(["convert", str(src), "-o", str(tmp_path / "x"), "--root-body", "body_1"]) == 0
    hrdf = HRDF.from_dir(tmp_path / "x")
    assert [j.name for j in hrdf.joints] == ["h"]
    assert main(["roundtrip", str(src), "--root-body", "body_1", "--configs", "3"]) == 0


def test_range_of_an_unlimited_tendon_is_noted(tmp_path: Path) -> None:
    xml = CARRIED.replace('<fixed name="t">', '<fixed name="t" limited="false" range="-1 1">')
    messages = convert(_write(tmp_path, xml), tmp_path / "out")
    assert any("unlimited tendon" in m and "'t'" not in m and '"t"' in m for m in messages)
    assert not [m for m in messages if "proof:" in m], messages


def test_range_of_an_unlimited_joint_is_noted(tmp_path: Path) -> None:
    xml = PLAIN.replace(
        'range="-1 1" damping="0.5"', 'limited="false" range="-1.5 1.5" damping="0.5"'
    )
    messages = convert(_write(tmp_path, xml), tmp_path / "out")
    noted = [m for m in messages if "unlimited joint" in m]
    assert len(noted) == 1 and '"shoulder"' in noted[0] and "-1.5" in noted[0], messages
    assert not [m for m in messages if "proof:" in m], messages
    # What MuJoCo simulates is the same: the joint is unlimited on both sides.
    from robotwright.proof.roundtrip.run import our_mjcf_model

    out = our_mjcf_model(HRDF.from_dir(tmp_path / "out"))
    assert not out.jnt_limited[out.joint("shoulder").id]
    # A limited joint's range is kept, without that note.
    assert not [m for m in convert(_write(tmp_path, PLAIN), tmp_path / "o2") if "unlimited" in m]


def test_range_of_a_free_joint_is_noted(tmp_path: Path) -> None:
    xml = PLAIN.replace(
        '<body name="base">', '<body name="base"><joint name="root" type="free" range="-2 2"/>'
    )
    messages = convert(_write(tmp_path, xml), tmp_path / "out")
    assert any("unlimited joint" in m and '"root"' in m for m in messages), messages
    assert not [m for m in messages if "proof:" in m], messages


# -- real robots: the corpus files' proofs run in test_corpora.py, on the round trip's parse.


# -- URDF sources: compared with MuJoCo's own import -----------------------------------------
def test_inertia_compared_as_tensor_not_principal_axes() -> None:
    # One tensor, written as principal moments in two axis orders (the quat turns them).
    a = _model(PLAIN.replace('mass="1"/>', 'mass="1"/><inertial pos="0 0 0" mass="1" '
                             'diaginertia="0.1 0.2 0.3"/>'))  # fmt: skip
    b = _model(
        PLAIN.replace(
            'mass="1"/>',
            'mass="1"/><inertial pos="0 0 0" mass="1" '
            'diaginertia="0.2 0.1 0.3" quat="0.7071068 0 0 0.7071068"/>',
        )
    )
    assert not [d for d in proof.compare_models(a, b) if d.field.startswith("body_i")]
    # Another tensor (same moments, axes turned by 45 degrees) is a difference, named once.
    c = _model(
        PLAIN.replace(
            'mass="1"/>',
            'mass="1"/><inertial pos="0 0 0" mass="1" '
            'diaginertia="0.1 0.2 0.3" quat="0.9238795 0 0 0.3826834"/>',
        )
    )
    diffs = [d for d in proof.compare_models(a, c) if d.field.startswith("body_i")]
    assert [(d.field, d.obj) for d in diffs] == [("body_inertia", "body 'base'")], diffs


URDF = """<robot name="u">
  <link name="base">
    <inertial><origin xyz="0 0 0.1" rpy="0.3 0.2 0.1"/><mass value="2"/>
      <inertia ixx="0.3" iyy="0.25" izz="0.2" ixy="0.01" ixz="0.02" iyz="0.03"/></inertial>
    <visual><geometry><box size="0.2 0.2 0.2"/></geometry></visual>
    <collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision>
  </link>
  <link name="arm">
    <inertial><mass value="0.5"/><inertia ixx="0.01" iyy="0.02" izz="0.03" ixy="0"
      ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 0.15"/><geometry><cylinder radius="0.03" length="0.3"/>
      </geometry></collision>
    <collision><origin xyz="0 0 0.3"/><geometry><sphere radius="0.04"/></geometry></collision>
  </link>
  <link name="tip"/>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="arm"/>
    <origin xyz="0 0 0.2"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="5"
    velocity="1"/><dynamics damping="0.5" friction="0.1"/></joint>
  <joint name="fix" type="fixed"><parent link="arm"/><child link="tip"/>
    <origin xyz="0 0 0.3"/></joint>
</robot>
"""


@pytest.mark.parametrize("out", ["hrdf", "r_out.xml"])
def test_urdf_source_matches_mujocos_import(tmp_path: Path, out: str) -> None:
    src = _write(tmp_path, URDF, "u.urdf")
    reference = proof.source_model(src, "urdf", {})
    assert reference is not None
    from robotwright.proof.convert import load_any

    hrdf, _ = load_any(src)
    ours, _ = proof.result_model(hrdf, "mjcf", None, discard_visual=True)
    # MuJoCo 4's import orders the rotated inertia's principal axes its own way; where
    # the reference completes MuJoCo 3.11's import (its tensors given to the compiler
    # diagonalised, reference.compile_urdf), they come in our order.
    same_order = np.allclose(reference.body("base").inertia, ours.body("base").inertia)
    assert same_order != mujoco_diagonalises_inertia_exactly()
    assert proof.compare_models(reference, ours, families=("body", "jnt", "dof", "geom"),
                                options=False) == []  # fmt: skip
    messages = convert(src, tmp_path / out)
    assert not [m for m in messages if "proof:" in m], messages


def test_urdf_source_silent_loss_becomes_a_note(tmp_path: Path, monkeypatch) -> None:
    _lose_shoulder_damping(monkeypatch)
    messages = convert(_write(tmp_path, URDF, "u.urdf"), tmp_path / "out")
    lost = [m for m in messages if "proof:" in m]
    assert len(lost) == 1 and "dof_damping" in lost[0] and "'shoulder'" in lost[0], messages
    # (a joint without effort and velocity limits: nothing else a strict conversion drops)
    free = URDF.replace('type="revolute"', 'type="continuous"').replace(
        '<limit lower="-1" upper="1" effort="5"\n    velocity="1"/>', ""
    )
    assert free.count("<limit") == 0
    with pytest.raises(ConversionError, match="dof_damping"):
        convert(_write(tmp_path, free, "u.urdf"), tmp_path / "out2", strict=True)
    assert not (tmp_path / "out2").exists()


def test_urdf_source_changed_inertia_is_named(tmp_path: Path, monkeypatch) -> None:
    real = HRDF.save

    def save(self: HRDF, path, **kw):
        bodies = [
            dataclasses.replace(b, mass=b.mass * 1.01) if b.name == "arm" else b
            for b in self.bodies
        ]
        return real(dataclasses.replace(self, bodies=bodies), path, **kw)

    monkeypatch.setattr(HRDF, "save", save)
    messages = convert(_write(tmp_path, URDF, "u.urdf"), tmp_path / "out")
    lost = [m for m in messages if "proof:" in m]
    assert any("body_mass" in m and "'arm'" in m for m in lost), messages


# -- URDF outputs: MuJoCo's import of our URDF against our MJCF ---------------------------------
def _lose_urdf_damping(monkeypatch: pytest.MonkeyPatch) -> None:
    """A URDF writer that loses every joint's damping silently."""
    from robotwright.generators.urdf import URDFHumanoidGenerator

    real = URDFHumanoidGenerator.generate

    def generate(self, *a, **kw):
        root = real(self, *a, **kw)
        for joint in root.iter("joint"):
            for dyn in joint.findall("dynamics"):
                dyn.attrib.pop("damping", None)
        return root

    monkeypatch.setattr(URDFHumanoidGenerator, "generate", generate)


@pytest.mark.parametrize("source", ["u.urdf", "r.xml"])
def test_urdf_output_has_no_unreported_difference(tmp_path: Path, source: str) -> None:
    src = _write(tmp_path, URDF if source.endswith(".urdf") else PLAIN, source)
    messages = convert(src, tmp_path / "out.urdf")
    assert not [m for m in messages if "proof:" in m], messages


def test_urdf_output_silent_loss_becomes_a_note(tmp_path: Path, monkeypatch) -> None:
    _lose_urdf_damping(monkeypatch)
    messages = convert(_write(tmp_path, PLAIN), tmp_path / "out.urdf")
    lost = [m for m in messages if "proof:" in m]
    assert len(lost) == 1 and "dof_damping" in lost[0] and "'shoulder'" in lost[0], messages
    assert "0.5" in lost[0]
    with pytest.raises(ConversionError, match="dof_damping"):
        convert(_write(tmp_path, PLAIN), tmp_path / "strict.urdf", strict=True)
    assert not (tmp_path / "strict.urdf").exists()


def test_urdf_form_names_each_changed_value() -> None:
    from robotwright.proof.urdf_output import compare_urdf_form

    a = _model(PLAIN)
    assert compare_urdf_form(a, a) == []
    for old, new, field in [
        ('damping="0.5"', 'damping="0.6"', "dof_damping"),
        ('range="-1 1"', 'range="-1 1.2"', "jnt_range"),
        ('pos="0 0 0.2"', 'pos="0 0 0.25"', "body_pos"),
        ('mass="0.5"', 'mass="0.6"', "body_mass"),
        ('axis="0 1 0"', 'axis="1 0 0"', "jnt_axis"),
    ]:
        diffs = compare_urdf_form(a, _model(PLAIN.replace(old, new)))
        assert field in {d.field for d in diffs}, (field, diffs)


TWO_ARMS = """<mujoco model="p">
  <worldbody>
    <body name="base">
      <geom type="box" size="0.1 0.1 0.1" mass="1"/>
      <body name="arm" pos="0 0 0.2">
        <joint name="shoulder" axis="0 1 0" range="-1 1" damping="0.5"/>
        <geom type="capsule" size="0.03" fromto="0 0 0 0 0 0.3" mass="0.5" friction="1"/>
        <body name="hand" pos="0 0 0.3" quat="0.9 0 0.1 0">
          <joint name="wrist" axis="1 0 0" range="-2 2"/>
          <geom type="sphere" size="0.04" mass="0.2"/>
          <geom type="box" size="0.01 0.02 0.03" pos="0.05 0 0" mass="0.1"/>
        </body>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


def test_urdf_form_lists_every_change_object_by_object() -> None:
    from robotwright.proof.urdf_output import compare_urdf_form

    a = _model(TWO_ARMS)
    # A quaternion and its negative are the same rotation: no difference.
    flipped = _model(TWO_ARMS.replace('quat="0.9 0 0.1 0"', 'quat="-0.9 0 -0.1 0"'))
    assert compare_urdf_form(a, flipped) == []
    changed = TWO_ARMS
    for old, new in [
        ('range="-2 2"', 'range="-2 2.5"'),  # wrist
        ('damping="0.5"', 'damping="0.7"'),  # shoulder
        ('mass="0.2"', 'mass="0.3"'),  # hand: mass, inertia, centre of mass
        ('friction="1"', 'friction="0.8"'),  # arm's geom
        ('size="0.01 0.02 0.03" pos="0.05 0 0"', 'size="0.01 0.02 0.03" pos="0.06 0 0"'),
    ]:
        assert old in changed
        changed = changed.replace(old, new)
    diffs = compare_urdf_form(a, _model(changed))
    got = [(d.obj, d.field) for d in diffs]
    assert got == [
        ("body 'hand'", "body_mass"),
        ("body 'hand'", "body_ipos"),
        ("body 'hand'", "body_inertia"),
        ("joint 'shoulder'", "dof_damping"),
        ("joint 'wrist'", "jnt_range"),
        ("geom #1 of body 'arm'", "geom_friction"),
        ("geom #3 of body 'hand'", "(object)"),  # moved: no geom of the hand matches it
    ], got
    assert (diffs[0].source, diffs[0].result) == ("0.3", "0.4")  # sphere + box


def test_export_urdf_proof(tmp_path: Path, monkeypatch, capsys) -> None:
    hrdf_dir = tmp_path / "robot"
    convert(_write(tmp_path, PLAIN), hrdf_dir)
    assert main(["-v", "export", str(hrdf_dir), "-o", str(tmp_path / "a.urdf")]) == 0
    assert "proof:" not in capsys.readouterr().err
    _lose_urdf_damping(monkeypatch)
    assert main(["-v", "export", str(hrdf_dir), "-o", str(tmp_path / "b.urdf")]) == 0
    err = capsys.readouterr().err
    assert "proof:" in err and "dof_damping" in err and "shoulder" in err
    out = tmp_path / "c.urdf"
    assert main(["export", str(hrdf_dir), "-o", str(out), "--strict"]) == 2
    err = capsys.readouterr().err
    assert "dof_damping" in err and "Traceback" not in err and not out.exists()


def test_hrdf_folder_to_urdf_is_proved(tmp_path: Path, monkeypatch) -> None:
    convert(_write(tmp_path, PLAIN), tmp_path / "robot")
    assert not [m for m in convert(tmp_path / "robot", tmp_path / "a.urdf") if "proof:" in m]
    _lose_urdf_damping(monkeypatch)
    lost = [m for m in convert(tmp_path / "robot", tmp_path / "b.urdf") if "proof:" in m]
    assert len(lost) == 1 and "dof_damping" in lost[0] and "'shoulder'" in lost[0], lost
    with pytest.raises(ConversionError, match="dof_damping"):
        convert(tmp_path / "robot", tmp_path / "c.urdf", strict=True)
    assert not (tmp_path / "c.urdf").exists()


def test_dropped_massless_root_link_is_one_reported_absence(tmp_path: Path) -> None:
    # The parser drops a massless root link (noted); MuJoCo's import keeps it: its
    # absence is the difference, not the parent and root ids of every body below it.
    urdf = URDF.replace(
        '<link name="base">',
        '<link name="footprint"/><joint name="fp" type="fixed"><parent link="footprint"/>'
        '<child link="base"/><origin xyz="0 0 0.1"/></joint><link name="base">',
    )
    src = _write(tmp_path, urdf, "u.urdf")
    reference = proof.source_model(src, "urdf", {})
    assert reference is not None and reference.body("footprint").id > 0
    messages = convert(src, tmp_path / "out")
    assert any("footprint" in m and "proof:" not in m for m in messages), messages
    assert not [m for m in messages if "proof:" in m], messages


def test_source_compile_reused_only_for_the_same_file(tmp_path: Path) -> None:
    from robotwright.parsers.mjcf.reader import parse_mjcf

    src = _write(tmp_path, PLAIN)
    parse_mjcf(src)
    first = proof.source_model(src, "mjcf", {})
    # Taken once: the next proof compiles the file again.
    second = proof.source_model(src, "mjcf", {})
    assert first is not None and second is not None and first is not second
    assert proof.compare_models(first, second) == []
    # A file changed after the parse is compiled as it is now.
    parse_mjcf(src)
    src.write_text(PLAIN.replace('mass="1"', 'mass="2.5"'))  # (another size too)
    now = proof.source_model(src, "mjcf", {})
    assert now is not None and now.body("base").mass[0] == 2.5


def _with_tip(mass: str, inertia: str) -> str:
    return URDF.replace(
        '<link name="tip"/>',
        f'<link name="tip"><inertial><origin xyz="0 0 0.05"/><mass value="{mass}"/>'
        f'<inertia ixx="{inertia}" iyy="{inertia}" izz="{inertia}" ixy="0" ixz="0" '
        'iyz="0"/></inertial></link>',
    )


def test_urdf_merge_compared_with_mujocos_fused_import(tmp_path: Path) -> None:
    src = _write(tmp_path, _with_tip("0.2", "0.001"), "u.urdf")
    reference = proof.source_model(src, "urdf", {"fixed_joints": "merge"})
    assert reference is not None
    # MuJoCo fused the tip into the arm and kept the fixed base a body.
    names = {reference.body(i).name for i in range(reference.nbody)}
    assert "tip" not in names and {"base", "arm"} <= names
    messages = convert(src, tmp_path / "out", fixed_joints="merge")
    assert not [m for m in messages if "proof:" in m], messages


def test_urdf_merge_of_a_massless_link_with_inertia_is_reported(tmp_path: Path) -> None:
    # MuJoCo's fusion leaves out the inertia of a link without mass; the parser keeps
    # it: the proof says so instead of either being silent.
    src = _write(tmp_path, _with_tip("0", "0.001"), "u.urdf")
    messages = convert(src, tmp_path / "out", fixed_joints="merge")
    lost = [m for m in messages if "proof:" in m]
    assert len(lost) == 1 and "body_inertia" in lost[0] and "'arm'" in lost[0], messages
