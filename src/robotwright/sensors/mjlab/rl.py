"""rsl_rl runner configs of the robotwright mjlab tasks: PPO with an MLP on the flat
observations, or PointNet on a ``"points"`` group first (the policy switch)."""

from __future__ import annotations

from typing import Any

from mjlab.rl import RslRlModelCfg, RslRlOnPolicyRunnerCfg, RslRlPpoAlgorithmCfg

from robotwright.sensors.semantic_nav import POINTNET_MODEL, POLICIES, check_policy

__all__ = ["POINTNET_MODEL", "POLICIES", "ppo_runner_cfg"]


def ppo_runner_cfg(
    *,
    policy: str,
    hidden_dims: tuple[int, ...],
    obs_normalization: bool,
    entropy_coef: float,
    experiment_name: str,
    num_steps_per_env: int,
    max_iterations: int,
) -> RslRlOnPolicyRunnerCfg:
    """PPO (mjlab's velocity-task settings: clip 0.2, 5 epochs of 4 mini-batches, adaptive
    learning rate from 1e-3, gamma 0.99, lambda 0.95), actor and critic alike;
    ``policy="pointnet"`` reads the ``"points"`` group through
    :class:`~robotwright.sensors.pointnet.PointNetModel`."""
    check_policy(policy)
    model: dict[str, Any] = {
        "hidden_dims": hidden_dims,
        "activation": "elu",
        "obs_normalization": obs_normalization,
    }
    obs_groups = {"actor": ("actor",), "critic": ("critic",)}
    if policy == "pointnet":
        model["class_name"] = POINTNET_MODEL
        obs_groups = {"actor": ("actor", "points"), "critic": ("critic", "points")}
    return RslRlOnPolicyRunnerCfg(
        actor=RslRlModelCfg(
            **model,
            distribution_cfg={
                "class_name": "GaussianDistribution",
                "init_std": 1.0,
                "std_type": "scalar",
            },
        ),
        critic=RslRlModelCfg(**model),
        algorithm=RslRlPpoAlgorithmCfg(
            value_loss_coef=1.0,
            use_clipped_value_loss=True,
            clip_param=0.2,
            entropy_coef=entropy_coef,
            num_learning_epochs=5,
            num_mini_batches=4,
            learning_rate=1.0e-3,
            schedule="adaptive",
            gamma=0.99,
            lam=0.95,
            desired_kl=0.01,
            max_grad_norm=1.0,
        ),
        experiment_name=experiment_name,
        logger="tensorboard",
        save_interval=50,
        num_steps_per_env=num_steps_per_env,
        max_iterations=max_iterations,
        obs_groups=obs_groups,
    )
