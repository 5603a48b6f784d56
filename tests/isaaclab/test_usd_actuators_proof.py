"""The USD export's drives and proof against the source's compiled actuators, on robot
files nobody here wrote (issue 40, items 2 and 3): OpenAI's Shadow hand, whose names the
converter must rename (``robot0:FFJ3``), and Gymnasium's humanoid, whose hips and waist
carry two and three hinges on one body (one D6 joint in Newton's reading).

Runs in Isaac Lab's environment; the robot files come from tools/fetch_test_data.py.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

if os.environ.get("ROBOTWRIGHT_REQUIRE_ISAACLAB") != "1":
    pytest.importorskip(
        "mujoco_usd_converter", reason="mujoco-usd-converter not installed (Isaac Lab stage)"
    )

import mujoco  # noqa: E402
import numpy as np  # noqa: E402
from pxr import Usd, UsdPhysics  # noqa: E402

from robotwright.generators.usd import to_usd  # noqa: E402
from robotwright.sources import load_robot  # noqa: E402

TESTDATA = Path(__file__).resolve().parents[2] / ".testdata"
HAND_ASSETS = TESTDATA / "gymnasium-robotics" / "gymnasium_robotics" / "envs" / "assets"
HUMANOID = TESTDATA / "gymnasium" / "gymnasium" / "envs" / "mujoco" / "assets" / "humanoid.xml"


def _need(path: Path) -> Path:
    if not path.exists():
        pytest.skip(f"{path} comes from tools/fetch_test_data.py (not fetched)")
    return path


def _newton(usd: Path):
    from robotwright._warp import quiet_warp

    quiet_warp()
    import newton

    builder = newton.ModelBuilder()
    found = builder.add_usd(str(usd))
    return builder.finalize(device="cpu"), found


def _hand():
    """OpenAI's Shadow hand (its source file and its HRDF), without the reach scene."""
    source = _need(HAND_ASSETS / "hand" / "reach.xml")
    return source, load_robot(str(source), asset_roots=[HAND_ASSETS], root_body="robot0:hand mount")


def test_shadow_hand_drives_every_actuated_joint_under_its_own_name(tmp_path):
    source, hrdf = _hand()
    out = tmp_path / "hand.usda"
    done = to_usd(hrdf, out)
    # The source's own compile: 20 position actuators, one per joint, kp and force range.
    src = mujoco.MjModel.from_xml_path(str(source))
    want = {}
    for a in range(src.nu):
        joint = src.joint(int(src.actuator_trnid[a, 0])).name
        want[joint] = (float(src.actuator_gainprm[a, 0]), float(abs(src.actuator_forcerange[a]).max()))  # fmt: skip
    assert len(want) == 20 and all(":" in j for j in want)
    assert sorted(done.drives) == sorted(want)
    proof = done.proof
    assert proof.differences == []
    assert (proof.bodies, proof.joints, proof.drives) == (src.nbody - 2, src.njnt, 20)
    assert proof.max_pose_error < 1e-6
    # Read independently: Newton's drives, found through the prims' display names.
    model, found = _newton(out)
    stage = Usd.Stage.Open(str(out))
    ke, effort = model.joint_target_ke.numpy(), model.joint_effort_limit.numpy()
    qd_start = model.joint_qd_start.numpy()
    seen = set()
    for path, i in found["path_joint_map"].items():
        name = stage.GetPrimAtPath(path).GetDisplayName()
        if name in want:
            d = qd_start[i]
            assert ke[d] == pytest.approx(want[name][0], rel=1e-6), name
            assert effort[d] == pytest.approx(want[name][1], rel=1e-6), name
            seen.add(name)
    assert seen == set(want)


def test_proof_names_an_edited_drive_and_a_drive_without_actuator(tmp_path):
    from robotwright.generators.usd_proof import prove_usd

    _, hrdf = _hand()
    out = tmp_path / "hand.usda"
    done = to_usd(hrdf, out)
    stage = Usd.Stage.Open(str(out))
    joints = {p.GetDisplayName(): p for p in stage.Traverse() if p.IsA(UsdPhysics.Joint)}
    UsdPhysics.DriveAPI.Get(joints["robot0:FFJ3"], "angular").GetStiffnessAttr().Set(0.5)
    # robot0:FFJ0 is coupled to FFJ1 by tendons and has no actuator of its own.
    extra = UsdPhysics.DriveAPI.Apply(joints["robot0:FFJ0"], "angular")
    extra.CreateStiffnessAttr(1.0)
    stage.Save()
    found = prove_usd(out, done.mjcf_model, hrdf).differences
    assert any(
        "'robot0:FFJ3' (position actuator 'robot0:A_FFJ3')" in d and "stiffness 1 in MJCF" in d
        for d in found
    ), found
    assert any("joint 'robot0:FFJ0': no actuator in MJCF, a drive in USD" in d for d in found)
    assert len(found) == 2, found


def _humanoid_in_newtons_order(tmp_path: Path) -> Path:
    """The humanoid with each body's hinges listed in the order Newton turns them."""
    text = HUMANOID.read_text()
    for first, second in (
        ("abdomen_z", "abdomen_y"),
        ("right_hip_z", "right_hip_y"),
        ("left_hip_z", "left_hip_y"),
    ):
        lines = text.split("\n")
        a = next(i for i, line in enumerate(lines) if f'name="{first}"' in line and "<joint" in line)  # fmt: skip
        b = next(i for i, line in enumerate(lines) if f'name="{second}"' in line and "<joint" in line)  # fmt: skip
        lines[a], lines[b] = lines[b], lines[a]
        text = "\n".join(lines)
    out = tmp_path / "humanoid_sorted.xml"
    out.write_text(text)
    return out


def test_humanoid_multi_hinge_bodies_are_matched_axis_by_axis(tmp_path):
    _need(HUMANOID)
    done = to_usd(load_robot(str(HUMANOID)), tmp_path / "h.usda")
    proof = done.proof
    src = mujoco.MjModel.from_xml_path(str(HUMANOID))
    # Every hinge is found (none "not in the USD"), as an axis of Newton's D6 joints.
    assert proof.joints == src.njnt and proof.drives == src.nu == 17
    assert not any("not in the USD" in d or "type" in d for d in proof.differences)
    # Each motor's effort limit is its gear times its control bound (25-300 x 0.4 N m),
    # read back so; the free base's six axes keep Newton's default.
    assert not any("drive" in d for d in proof.differences)
    model, _ = _newton(tmp_path / "h.usda")
    limits = sorted(float(v) for v in model.joint_effort_limit.numpy() if v < 1e5)
    want = sorted(
        float(src.actuator_gear[a, 0] * abs(src.actuator_ctrlrange[a]).max()) for a in range(src.nu)
    )
    assert len(set(want)) > 1 and np.allclose(limits, want, rtol=1e-6)
    # Newton turns a merged joint's hinges in its own order: the proof names each body
    # where that order is not MuJoCo's, and the poses that follow differ.
    order = [d for d in proof.differences if "as one D6 joint turning them" in d]
    assert [d.split("'")[1] for d in order] == ["lwaist", "right_thigh", "left_thigh"]
    assert "'abdomen_z', 'abdomen_y' as one D6 joint turning them in the order 'abdomen_y', 'abdomen_z'" in order[0]  # fmt: skip
    assert proof.max_pose_error > 0.01
    # The poses differ at the bodies those joints move, and nowhere else (the torso,
    # the head and the arms hang above the abdomen).
    moved = {d.split("'")[1] for d in proof.differences if "world pose differs" in d}
    legs = {f"{side}_{part}" for side in ("left", "right") for part in ("thigh", "shin", "foot")}
    assert moved == {"lwaist", "pelvis"} | legs
    assert all("of 20 random configurations" in d for d in proof.differences if "world pose" in d)
    # Listed in Newton's order, the same humanoid reads back with the same kinematics:
    # no difference at all, the torso's 0.004 rad tilts included (the converter rounds
    # them by 3e-5 rad; the export puts the exact frames back).
    sorted_done = to_usd(load_robot(str(_humanoid_in_newtons_order(tmp_path))), tmp_path / "s.usda")  # fmt: skip
    assert sorted_done.proof.differences == []
    assert 0 < sorted_done.proof.max_pose_error < 2e-6


def test_renamed_prims_and_merged_joints_read_back_under_the_source_names(tmp_path):
    """USD in (issue 40, item 3): the hand's renamed prims read back as ``robot0:...``,
    the humanoid's merged hinges as their own joints (not ``lwaist_0``, ``lwaist_1``),
    each actuator on its joint."""
    from robotwright.parsers.api import usd_to_hrdf_with_warnings

    _, hand = _hand()
    to_usd(hand, tmp_path / "hand.usda")
    back, _ = usd_to_hrdf_with_warnings(tmp_path / "hand.usda")
    assert sorted(b.name for b in back.bodies) == sorted(b.name for b in hand.bodies)
    assert sorted(a.joint for a in back.actuators) == sorted(a.joint for a in hand.actuators)
    humanoid = load_robot(str(_need(HUMANOID)))
    to_usd(humanoid, tmp_path / "h.usda")
    back, _ = usd_to_hrdf_with_warnings(tmp_path / "h.usda")
    assert sorted(j.name for j in back.joints) == sorted(j.name for j in humanoid.joints)
    assert sorted(a.joint for a in back.actuators) == sorted(a.joint for a in humanoid.actuators)
    # Read in Newton's order (the order it turns them in), each hinge on its own axis.
    waist = [(j.name, j.axis) for j in back.joints if j.body == "lwaist"]
    assert [n for n, _ in waist] == ["abdomen_y", "abdomen_z"]
    assert np.allclose([a for _, a in waist], [(0, 1, 0), (0, 0, 1)], atol=1e-6)
