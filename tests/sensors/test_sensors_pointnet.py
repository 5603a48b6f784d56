"""The point-cloud policy (marked ``mjlab``): PointNet over the semantic LiDAR's points
with their classes, as rsl_rl's actor and critic, on the seeker task.

Runs in the MuJoCo 3.11 environment of ``.ci/run`` (rsl_rl comes with mjlab) on warp's
CPU device; skipped with a reason where mjlab is not installed.
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest

pytestmark = pytest.mark.mjlab
pytest.importorskip("mjlab", reason="mjlab not installed (the MuJoCo 3.11 environment of .ci/run)")

import mjlab  # noqa: E402, F401 - loads the entry points
import torch  # noqa: E402
from mjlab.tasks.registry import list_tasks, load_env_cfg, load_rl_cfg  # noqa: E402
from mjlab_train import run_train  # noqa: E402
from tensordict import TensorDict  # noqa: E402

from robotwright.sensors.mjlab import seeker  # noqa: E402
from robotwright.sensors.mjlab.rl import POINTNET_MODEL  # noqa: E402
from robotwright.sensors.pointnet import PointNetEncoder, PointNetModel  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]


def _cloud(batch: int = 4, points: int = 10, classes: int = 4, valid: int = 7) -> torch.Tensor:
    """Points (x, y, z, one-hot class) with the last ``points - valid`` rows padding."""
    gen = torch.Generator().manual_seed(0)
    xyz = torch.randn(batch, points, 3, generator=gen)
    cls = torch.nn.functional.one_hot(
        torch.randint(0, classes, (batch, points), generator=gen), classes
    ).float()
    cloud = torch.cat([xyz, cls], dim=-1)
    cloud[:, valid:] = 0.0
    return cloud


def test_the_encoder_ignores_order_and_padding() -> None:
    torch.manual_seed(0)
    enc = PointNetEncoder(7, (16, 32))
    cloud = _cloud()
    out = enc(cloud)
    assert out.shape == (4, 32) and torch.isfinite(out).all()
    shuffled = cloud[:, torch.randperm(10)]
    assert torch.allclose(enc(shuffled), out, atol=1e-6)  # a set, not a sequence
    more_padding = torch.cat([cloud, torch.zeros(4, 5, 7)], dim=1)
    assert torch.allclose(enc(more_padding), out, atol=1e-6)
    moved = cloud.clone()
    moved[0, 0, :3] += 5.0  # a real point moved: the encoding changes
    assert not torch.allclose(enc(moved)[0], out[0])
    assert torch.equal(enc(torch.zeros(2, 10, 7)), torch.zeros(2, 32))  # nothing seen


def test_the_model_reads_points_and_flat_groups_as_rsl_rl_expects() -> None:
    obs = TensorDict({"actor": torch.randn(4, 2), "points": _cloud()}, batch_size=[4])
    groups = {"actor": ["actor", "points"], "critic": ["actor", "points"]}
    dist = {"class_name": "GaussianDistribution", "init_std": 1.0, "std_type": "scalar"}
    actor = PointNetModel(obs, groups, "actor", 2, (32,), distribution_cfg=dist)
    assert actor.obs_groups == ["actor"] and actor.point_groups == ["points"]
    assert actor(obs).shape == (4, 2)
    assert actor(obs, stochastic_output=True).shape == (4, 2)
    critic = PointNetModel(obs, groups, "critic", 1, (32,))
    value = critic(obs)
    assert value.shape == (4, 1) and torch.isfinite(value).all()
    with pytest.raises(ValueError, match="no 3-D observation group"):
        PointNetModel(obs, {"actor": ["actor"]}, "actor", 2, (32,))


def test_the_pointnet_seeker_observes_points_with_classes() -> None:
    assert seeker.POINTNET_TASK_ID in list_tasks()
    rl = load_rl_cfg(seeker.POINTNET_TASK_ID)
    assert rl.actor.class_name == rl.critic.class_name == POINTNET_MODEL
    assert rl.obs_groups == {"actor": ("actor", "points"), "critic": ("critic", "points")}
    mlp = load_rl_cfg(seeker.TASK_ID)
    assert rl.actor.hidden_dims == mlp.actor.hidden_dims and rl.algorithm == mlp.algorithm
    from mjlab.envs import ManagerBasedRlEnv

    cfg = load_env_cfg(seeker.POINTNET_TASK_ID)
    cfg.scene.num_envs, cfg.seed = 2, 7
    env = ManagerBasedRlEnv(cfg=cfg, device="cpu")
    try:
        obs, _ = env.reset()
        points = obs["points"]
        classes = len(env.scene["lidar"].class_names)
        assert points.shape == (2, seeker.RING_RAYS, 3 + classes)
        seen = points[..., 3:].argmax(-1)[points[..., 3:].sum(-1) > 0]
        names = env.scene["lidar"].class_names
        assert names.index("valuable") in seen.tolist()  # the target is among the points
    finally:
        env.close()


def test_mjlab_s_train_runs_the_pointnet_seeker(tmp_path) -> None:
    args = [seeker.POINTNET_TASK_ID, "--env.scene.num-envs", "4"]
    args += ["--agent.max-iterations", "2", "--agent.num-steps-per-env", "8"]
    args += ["--gpu-ids", "None", "--log-root", str(tmp_path)]
    done = run_train(args, tmp_path, timeout=600)
    runs = list((tmp_path / "semantic_seeker_pointnet").iterdir())
    assert len(runs) == 1 and (runs[0] / "model_1.pt").is_file()
    assert "Learning iteration 1/2" in done.stdout
    state = torch.load(runs[0] / "model_1.pt", map_location="cpu", weights_only=False)
    weights = [v for k, v in state["actor_state_dict"].items() if "encoders" in k]
    assert weights and all(torch.isfinite(w).all() for w in weights)
    assert not math.isnan(float(weights[0].abs().sum()))
