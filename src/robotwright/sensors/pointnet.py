"""A point-cloud policy for the semantic LiDAR: rsl_rl's model with a PointNet encoder.

The specification's direction (its package is ``go2_pvcnn``): the policy reads the scan
as a set of points with their classes, not as a fixed vector of rays. ``PointNetModel``
is rsl_rl's ``MLPModel`` (so it is the actor or the critic of rsl_rl's PPO in mjlab and
in Isaac Lab alike: ``class_name="robotwright.sensors.pointnet:PointNetModel"``) whose
3-D observation groups, ``(envs, points, features)`` such as
:func:`robotwright.sensors.mjlab.observations.lidar_point_cloud` gives (x, y, z [m] in
the sensor frame, then the one-hot class; all-zero rows are padding), are encoded per
point by a shared MLP, then max-pooled over the valid points (PointNet, Qi et al. 2017):
the result does not depend on the points' order. 1-D groups (velocities, commands) are
concatenated with the pooled features, as rsl_rl does, and the MLP head follows.

Needs torch and rsl_rl (``rsl-rl-lib`` 5, which mjlab and Isaac Lab bring); imported only
where a runner config names it.
"""

from __future__ import annotations

from typing import Any

import torch
from rsl_rl.models.mlp_model import MLPModel
from torch import nn

__all__ = ["PointNetEncoder", "PointNetModel"]


class PointNetEncoder(nn.Module):
    """Shared per-point MLP (``features -> hidden[0] -> ... -> hidden[-1]``, ELU), then a
    max over the valid points. A point is valid when its row is not all zero (the
    padding of a fixed-size sample); a cloud with no valid point encodes to zeros.

    Input ``(B, N, F)``; output ``(B, hidden[-1])``.
    """

    def __init__(self, features: int, hidden: tuple[int, ...] = (64, 128)) -> None:
        super().__init__()
        if features < 1 or not hidden or min(hidden) < 1:
            raise ValueError(
                f"PointNetEncoder: features {features}, hidden {hidden}: expected >= 1"
            )
        layers: list[nn.Module] = []
        width = features
        for h in hidden:
            layers += [nn.Linear(width, h), nn.ELU()]
            width = h
        self.point_mlp = nn.Sequential(*layers)
        self.output_dim = width

    def forward(self, points: torch.Tensor) -> torch.Tensor:
        valid = points.abs().sum(dim=-1, keepdim=True) > 0  # (B, N, 1)
        encoded = self.point_mlp(points)  # (B, N, H)
        floor = torch.finfo(encoded.dtype).min
        pooled = torch.where(valid, encoded, torch.full_like(encoded, floor)).amax(dim=1)
        return torch.where(valid.any(dim=1), pooled, torch.zeros_like(pooled))


class PointNetModel(MLPModel):
    """rsl_rl's MLP model with a :class:`PointNetEncoder` per 3-D observation group.

    Args (beyond ``MLPModel``'s):
        pointnet_cfg: ``{"hidden": (64, 128)}``: the shared point MLP's widths.
    """

    def __init__(
        self,
        obs: Any,
        obs_groups: dict[str, list[str]],
        obs_set: str,
        output_dim: int,
        hidden_dims: tuple[int, ...] | list[int] = (256, 256, 256),
        activation: str = "elu",
        obs_normalization: bool = False,
        distribution_cfg: dict | None = None,
        pointnet_cfg: dict | None = None,
    ) -> None:
        hidden = tuple((pointnet_cfg or {}).get("hidden", (64, 128)))
        groups = obs_groups[obs_set]
        self.point_groups = [g for g in groups if obs[g].dim() == 3]
        if not self.point_groups:
            raise ValueError(
                f"PointNetModel: no 3-D observation group (envs, points, features) in "
                f"{obs_set!r} ({list(groups)}); use MLPModel"
            )
        encoders = {g: PointNetEncoder(int(obs[g].shape[-1]), hidden) for g in self.point_groups}
        self._point_latent = sum(e.output_dim for e in encoders.values())
        super().__init__(
            obs,
            obs_groups,
            obs_set,
            output_dim,
            hidden_dims,
            activation,
            obs_normalization,
            distribution_cfg,
        )
        self.encoders = nn.ModuleDict(encoders)

    def _get_obs_dim(self, obs: Any, obs_groups: dict[str, list[str]], obs_set: str):
        """The 1-D groups and their width (the 3-D ones go to the encoders)."""
        flat = [g for g in obs_groups[obs_set] if obs[g].dim() == 2]
        return flat, sum(int(obs[g].shape[-1]) for g in flat)

    def _get_latent_dim(self) -> int:
        return self.obs_dim + self._point_latent

    def get_latent(self, obs: Any, masks: Any = None, hidden_state: Any = None) -> torch.Tensor:
        pooled = [self.encoders[g](obs[g]) for g in self.point_groups]
        if not self.obs_groups:
            return torch.cat(pooled, dim=-1)
        return torch.cat([super().get_latent(obs), *pooled], dim=-1)

    def update_normalization(self, obs: Any) -> None:
        if self.obs_normalization and self.obs_groups:
            super().update_normalization(obs)
