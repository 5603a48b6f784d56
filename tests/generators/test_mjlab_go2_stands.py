"""A trainable Go2 from one command (issue 39, item 1), in mjlab (warp's CPU device).

``robotwright mjlab-cfg go2 --floating-base --actuators position --actuator-gain '*=50,1'
--joint-pos ...`` (Isaac Lab's Go2 standing pose, as tests/isaaclab/test_go2_stands.py)
writes an ``EntityCfg`` that is used as it is in an mjlab scene on a plane: the robot
starts where its ``init_state`` says, on the ground, and under its PD drives holds its
pose for 5 s of simulated time: the base within 2 cm of where it settles, no joint at
its limit, no contact but the feet. Runs in the MuJoCo 3.11 environment of ``.ci/run``.

With ``ROBOTWRIGHT_STANDING_CURVE=FILE`` the base-height curve is written there (JSON).
"""

from __future__ import annotations

import importlib.util
import json
import math
import os

import pytest

pytestmark = pytest.mark.mjlab
pytest.importorskip("mjlab", reason="mjlab not installed (the MuJoCo 3.11 environment of .ci/run)")

from robotwright.catalog import find_entry  # noqa: E402
from robotwright.cli import main  # noqa: E402

STAND = ["--floating-base", "--actuators", "position", "--actuator-gain", "*=50,1"]
STAND += ["--joint-pos", "*L_hip_joint=0.1", "--joint-pos", "*R_hip_joint=-0.1"]
STAND += ["--joint-pos", "F?_thigh_joint=0.8", "--joint-pos", "R?_thigh_joint=1.0"]
STAND += ["--joint-pos", "*calf_joint=-1.5"]
DT = 0.005
SECONDS = 5.0


def _module(path):
    spec = importlib.util.spec_from_file_location("go2_entity", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_one_command_go2_stands_for_five_seconds_in_mjlab(tmp_path, capsys) -> None:
    if find_entry("go2") is None:
        pytest.skip("go2 comes from example-robot-data (not installed)")
    import mujoco
    import torch
    from mjlab.scene import Scene, SceneCfg
    from mjlab.sim import MujocoCfg, Simulation, SimulationCfg
    from mjlab.terrains import TerrainEntityCfg

    out = tmp_path / "go2_entity.py"
    assert main(["mjlab-cfg", "go2", *STAND, "-o", str(out)]) == 0
    assert "no actuators" not in capsys.readouterr().err
    robot_cfg = _module(out).ROBOT_CFG
    spawn_z = robot_cfg.init_state.pos[2]
    assert 0.25 < spawn_z < 0.45
    scene_cfg = SceneCfg(
        num_envs=1, terrain=TerrainEntityCfg(terrain_type="plane"), entities={"robot": robot_cfg}
    )
    scene = Scene(scene_cfg, device="cpu")
    sim = Simulation(
        num_envs=1,
        cfg=SimulationCfg(mujoco=MujocoCfg(timestep=DT)),
        spec=scene.spec,
        device="cpu",
    )
    scene.initialize(sim.mj_model, sim.model, sim.data)
    robot = scene["robot"]
    # What an environment's reset event does: the default root and joint state.
    robot.write_root_state_to_sim(robot.data.default_root_state.clone())
    robot.write_joint_state_to_sim(
        robot.data.default_joint_pos.clone(), robot.data.default_joint_vel.clone()
    )
    sim.forward()
    scene.update(DT)
    assert float(robot.data.root_link_pos_w[0, 2]) == pytest.approx(spawn_z, abs=1e-4)
    stand = robot.data.default_joint_pos.clone()
    heights, qs = [], []
    for _ in range(round(SECONDS / DT)):
        robot.set_joint_position_target(stand)
        scene.write_data_to_sim()
        sim.step()
        scene.update(DT)
        heights.append(float(robot.data.root_link_pos_w[0, 2]))
        qs.append(robot.data.joint_pos[0].clone())
    if os.environ.get("ROBOTWRIGHT_STANDING_CURVE"):
        curve = {"framework": "mjlab 1.6 (MuJoCo Warp, CPU)", "dt": DT, "base_z": heights}
        with open(os.environ["ROBOTWRIGHT_STANDING_CURVE"], "w", encoding="utf-8") as fh:
            json.dump(curve, fh)
    assert all(math.isfinite(z) for z in heights)
    settled = sum(heights[-200:]) / 200  # the last second
    after_landing = heights[round(1.0 / DT) :]
    assert max(abs(z - settled) for z in after_landing) < 0.02, (min(after_landing), settled)
    assert 0.2 < settled < spawn_z + 0.01
    limits = robot.data.joint_pos_limits[0]
    q = torch.stack(qs[round(1.0 / DT) :])
    assert float(torch.minimum(q - limits[:, 0], limits[:, 1] - q).min()) > 0.01
    # Contacts of the final state (its positions, read back), by MuJoCo's collision.
    host = mujoco.MjData(sim.mj_model)
    host.qpos[:] = sim.data.qpos[0].cpu().numpy()
    mujoco.mj_forward(sim.mj_model, host)
    m = sim.mj_model
    robot_bodies = {b for b in range(m.nbody) if m.body(b).name.startswith("robot/")}
    touching = set()
    for c in host.contact[: host.ncon]:
        b1, b2 = int(m.geom_bodyid[c.geom1]), int(m.geom_bodyid[c.geom2])
        for mine, other in ((b1, b2), (b2, b1)):
            if mine in robot_bodies and other not in robot_bodies:
                touching.add(m.body(mine).name.removeprefix("robot/"))
    assert touching and all(n.endswith("_foot") for n in touching), touching
