"""A trainable Go2 from one command (issue 39, item 1), in Isaac Lab 3 on Newton (CPU).

``robotwright isaaclab-cfg go2 --floating-base --actuators position --actuator-gain
'*=50,1' --joint-pos ...`` (Isaac Lab's Go2 standing pose, :data:`STAND`) writes a
config that is used as it is (only its prim path set, as every Isaac Lab scene does):
the robot spawns where its ``init_state`` says, standing on the ground, and under its PD
drives holds its pose for 5 s of simulated time: the base within 2 cm of where it
settles, no joint at its limit, nothing but the feet near the ground.

With ``ROBOTWRIGHT_STANDING_CURVE=FILE`` the base-height curve is written there (JSON),
for docs/sensors.md's picture.
"""

from __future__ import annotations

import importlib.util
import json
import math
import os

import pytest

if os.environ.get("ROBOTWRIGHT_REQUIRE_ISAACLAB") != "1":
    pytest.importorskip("isaaclab_newton", reason="Isaac Lab 3 not installed")
    pytest.importorskip("mujoco_usd_converter", reason="mujoco-usd-converter not installed")

from robotwright.catalog import find_entry  # noqa: E402
from robotwright.cli import main  # noqa: E402

#: Isaac Lab's Go2 standing pose; gains stiff enough to hold it without a policy (with
#: Unitree's 25, 0.5 the Go2 squats onto its rear calves, pitched 17-21 degrees, in
#: Newton and in MuJoCo alike).
STAND = ["--floating-base", "--actuators", "position", "--actuator-gain", "*=50,1"]
STAND += ["--joint-pos", "*L_hip_joint=0.1", "--joint-pos", "*R_hip_joint=-0.1"]
STAND += ["--joint-pos", "F?_thigh_joint=0.8", "--joint-pos", "R?_thigh_joint=1.0"]
STAND += ["--joint-pos", "*calf_joint=-1.5"]
DT = 0.005
SECONDS = 5.0


def _module(path):
    spec = importlib.util.spec_from_file_location("go2_cfg", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _bodies_touching_the_ground(root: list[float], joints: dict[str, float]) -> set[str]:
    """The bodies whose collision geoms touch a plane at z = 0 with the robot in the
    final state (root pose, joint positions) read from Isaac Lab, by MuJoCo's collision
    detection on the same robot's MJCF: no contact but the feet."""
    import mujoco

    from robotwright.generators import MJCFHumanoidGenerator
    from robotwright.sources import load_robot

    hrdf = load_robot("go2", floating_base=True)
    spec = MJCFHumanoidGenerator.from_hrdf(hrdf).to_spec(add_scene=False)
    spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_PLANE, size=[5, 5, 0.1], name="ground")
    model = spec.compile()
    data = mujoco.MjData(model)
    free = next(j for j in range(model.njnt) if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE)
    adr = int(model.jnt_qposadr[free])
    data.qpos[adr : adr + 7] = [*root[:3], root[6], *root[3:6]]  # MuJoCo: w x y z
    for name, q in joints.items():
        data.joint(name).qpos[0] = q
    mujoco.mj_forward(model, data)
    ground = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "ground")
    touching = set()
    for c in data.contact[: data.ncon]:
        if ground in (c.geom1, c.geom2):
            other = c.geom2 if c.geom1 == ground else c.geom1
            touching.add(model.body(int(model.geom_bodyid[other])).name)
    return touching


def _write_curve(heights: list[float]) -> None:
    curve = {"framework": "Isaac Lab 3 (Newton, CPU)", "dt": DT, "base_z": heights}
    with open(os.environ["ROBOTWRIGHT_STANDING_CURVE"], "w", encoding="utf-8") as fh:
        json.dump(curve, fh)


def test_the_one_command_go2_stands_for_five_seconds(tmp_path, capsys) -> None:
    if find_entry("go2") is None:
        pytest.skip("go2 comes from example-robot-data (not installed)")
    import isaaclab.sim as sim_utils
    import torch
    from isaaclab.assets import AssetBaseCfg
    from isaaclab.scene import InteractiveScene, InteractiveSceneCfg
    from isaaclab.utils import configclass
    from isaaclab_newton.physics import MJWarpSolverCfg, NewtonCfg

    out = tmp_path / "go2_cfg.py"
    assert main(["isaaclab-cfg", "go2", *STAND, "-o", str(out)]) == 0
    said = capsys.readouterr()
    assert "{ENV_REGEX_NS}/Robot/base" in said.out  # where a sensor goes (flat layout)
    assert "no actuators" not in said.err and "fixed base" not in said.err
    robot_cfg = _module(out).ROBOT_CFG.replace(prim_path="{ENV_REGEX_NS}/Robot")
    spawn_z = robot_cfg.init_state.pos[2]
    assert 0.25 < spawn_z < 0.45  # feet on the ground, legs bent

    # Flat ground: a static box whose top is z = 0 (Isaac Lab's "plane" needs Nucleus,
    # and MuJoCo refuses the generator's flat mesh, which has no volume).
    ground = AssetBaseCfg(
        prim_path="/World/ground",
        spawn=sim_utils.CuboidCfg(
            size=(20.0, 20.0, 0.2), collision_props=sim_utils.CollisionPropertiesCfg()
        ),
        init_state=AssetBaseCfg.InitialStateCfg(pos=(0.0, 0.0, -0.1)),
    )

    @configclass
    class SceneCfg(InteractiveSceneCfg):
        floor = ground
        robot = robot_cfg

    sim_cfg = sim_utils.SimulationCfg(
        dt=DT, device="cpu", physics=NewtonCfg(solver_cfg=MJWarpSolverCfg(), use_cuda_graph=False)
    )
    with sim_utils.build_simulation_context(sim_cfg=sim_cfg) as sim:
        sim._app_control_on_stop_handle = None
        scene = InteractiveScene(SceneCfg(num_envs=1, env_spacing=0.0))
        sim.reset()
        robot = scene["robot"]
        # Spawned where its config says: no second offset of the base inside its prim.
        assert float(robot.data.root_pos_w.torch[0, 2]) == pytest.approx(spawn_z, abs=1e-3)
        # What an environment's reset event does: the default pose and joint state.
        robot.write_root_pose_to_sim_index(root_pose=robot.data.default_root_pose.torch.clone())
        robot.write_joint_state_to_sim_index(
            position=robot.data.default_joint_pos.torch.clone(),
            velocity=robot.data.default_joint_vel.torch.clone(),
        )
        scene.update(0.0)
        assert float(robot.data.root_pos_w.torch[0, 2]) == pytest.approx(spawn_z, abs=1e-3)
        stand = robot.data.default_joint_pos.torch.clone()
        heights, qs = [], []
        for _ in range(round(SECONDS / DT)):
            robot.actuators.target_command.set_position_index(value=stand)
            scene.write_data_to_sim()
            sim.step()
            scene.update(sim.get_physics_dt())
            heights.append(float(robot.data.root_pos_w.torch[0, 2]))
            qs.append(robot.data.joint_pos.torch[0].clone())
        root = robot.data.root_pose_w.torch[0].tolist()  # x y z, qx qy qz qw
        joints = dict(zip(robot.joint_names, robot.data.joint_pos.torch[0].tolist(), strict=True))
        limits = robot.data.joint_pos_limits.torch[0]
    assert all(math.isfinite(z) for z in heights)
    settled = sum(heights[-200:]) / 200  # the last second
    after_landing = heights[round(1.0 / DT) :]
    if os.environ.get("ROBOTWRIGHT_STANDING_CURVE"):
        _write_curve(heights)
    assert max(abs(z - settled) for z in after_landing) < 0.02, (min(after_landing), settled)
    assert 0.2 < settled < spawn_z + 0.01
    q = torch.stack(qs[round(1.0 / DT) :])
    margin = torch.minimum(q - limits[:, 0], limits[:, 1] - q).min()
    assert float(margin) > 0.01, "a joint reached its limit"
    touching = _bodies_touching_the_ground(root, joints)
    assert touching == {"FL_foot", "FR_foot", "RL_foot", "RR_foot"}, touching
