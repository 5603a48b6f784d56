"""The class-labelled scene (:class:`~robotwright.sensors.semantic_scene.SemanticSceneCfg`)
in Isaac Lab 3: one kinematic rigid object per slot, placed and moved by one event term.

``add_semantic_scene(env_cfg, SemanticSceneCfg())`` adds to an Isaac Lab
``ManagerBasedRLEnvCfg``

* a ``RigidObjectCfg`` per slot at ``{ENV_REGEX_NS}/obstacle_0_cracker_box``,
  ``{ENV_REGEX_NS}/valuable_0_sofa``, ...: a cuboid or cylinder with collision, a
  kinematic body (it pushes a robot; nothing pushes it), whose prim path carries the
  class keyword the semantic LiDAR reads;
* the event term ``semantic_scene`` (:class:`SemanticSceneEvent`, mode ``"interval"``
  every environment step, global time): at each environment's reset it draws the layout
  around the environment's origin, and every step it moves the dynamic obstacles
  (:class:`~robotwright.sensors.semantic_scene.SceneState`).

With ``clutter_curriculum=True`` and a terrain generator with a curriculum, an
environment on terrain level ``l`` of ``L`` gets ``ceil(N (l + 1) / L)`` of its ``N``
obstacles in the arena; the others are parked under its origin.
"""

from __future__ import annotations

from typing import Any

import isaaclab.sim as sim_utils
import torch
from isaaclab.assets import RigidObjectCfg
from isaaclab.managers import EventTermCfg, ManagerTermBase

from robotwright.sensors.semantic_scene import (
    SceneAssetCfg,
    SceneState,
    SemanticSceneCfg,
    clutter_share,
)

__all__ = ["EVENT_NAME", "SemanticSceneEvent", "add_semantic_scene", "object_distances"]

#: The event term's name in ``env_cfg.events``.
EVENT_NAME = "semantic_scene"
#: Prim paths of the objects, for a LiDAR's ``mesh_prim_paths``.
OBJECT_PRIM_PATHS = ("{ENV_REGEX_NS}/obstacle_.*", "{ENV_REGEX_NS}/valuable_.*")


def _spawn(asset: SceneAssetCfg) -> Any:
    """Isaac Lab spawner of the asset: kinematic, colliding, coloured."""
    common = {
        "rigid_props": sim_utils.UsdPhysicsRigidBodyCfg(kinematic_enabled=True),
        "mass_props": sim_utils.MassCfg(mass=1.0),
        "collision_props": sim_utils.UsdPhysicsCollisionCfg(),
        "visual_material": sim_utils.PreviewSurfaceCfg(diffuse_color=tuple(asset.rgba[:3])),
    }
    if asset.shape == "box":
        return sim_utils.CuboidCfg(size=tuple(2.0 * v for v in asset.size), **common)
    radius, half_height = asset.size
    return sim_utils.CylinderCfg(radius=radius, height=2.0 * half_height, axis="Z", **common)


def add_semantic_scene(
    env_cfg: Any, scene: SemanticSceneCfg, clutter_curriculum: bool = False
) -> None:
    """Add the objects (scene attributes named after the slots) and the event term of
    ``scene`` to ``env_cfg``."""
    scene.check()
    for slot in scene.slots():
        setattr(
            env_cfg.scene,
            slot.name,
            RigidObjectCfg(
                prim_path=f"{{ENV_REGEX_NS}}/{slot.name}",
                spawn=_spawn(slot.asset),
                init_state=RigidObjectCfg.InitialStateCfg(pos=(0.0, 0.0, slot.asset.half_height)),
            ),
        )
    step = env_cfg.decimation * env_cfg.sim.dt
    setattr(
        env_cfg.events,
        EVENT_NAME,
        EventTermCfg(
            func=SemanticSceneEvent,
            mode="interval",
            interval_range_s=(step, step),
            is_global_time=True,
            params={"scene": scene, "clutter_curriculum": clutter_curriculum},
        ),
    )


class SemanticSceneEvent(ManagerTermBase):
    """Isaac Lab event term (class form): draws each environment's layout at its reset
    (:meth:`reset`) and moves the dynamic obstacles every step (``__call__``); the
    layout lives in :attr:`state`."""

    def __init__(self, cfg: EventTermCfg, env: Any) -> None:
        super().__init__(cfg, env)
        self.state = SceneState(cfg.params["scene"], env.num_envs, env.device)
        self.curriculum = bool(cfg.params.get("clutter_curriculum", False))
        self.objects = [env.scene[slot.name] for slot in self.state.slots]

    def reset(self, env_ids: Any = None) -> None:
        """Draw the layout of ``env_ids`` (indices, a slice or ``None``: all) and put the
        objects there."""
        all_ids = torch.arange(self.num_envs, device=self.device)
        ids = all_ids if env_ids is None else all_ids[env_ids]
        self.state.redraw(ids, self._clutter(ids))
        self._write(ids, range(len(self.state.slots)))

    def __call__(
        self,
        env: Any,
        env_ids: Any,
        scene: SemanticSceneCfg | None = None,
        clutter_curriculum: bool = False,
    ) -> None:
        """One environment step: the dynamic obstacles move by ``velocity * step_dt``
        (the parameters were read at construction)."""
        if self.state.dynamic:
            self.state.step(env.step_dt)
            self._write(torch.arange(self.num_envs, device=self.device), self.state.dynamic)

    def _clutter(self, env_ids: torch.Tensor) -> torch.Tensor | None:
        if not self.curriculum:
            return None
        return clutter_share(getattr(self._env.scene, "terrain", None), env_ids)

    def _write(self, env_ids: torch.Tensor, slots: Any) -> None:
        origins = self._env.scene.env_origins[env_ids]
        for k in slots:
            pos, quat = self.state.poses(env_ids, k, origins)
            xyzw = torch.cat([quat[:, 1:], quat[:, :1]], dim=1)  # Isaac Lab 3: x, y, z, w
            self.objects[k].write_root_pose_to_sim_index(
                root_pose=torch.cat([pos, xyzw], dim=1), env_ids=env_ids
            )


def object_distances(env: Any, xy: torch.Tensor, dynamic: bool) -> torch.Tensor:
    """``(E,)`` distance [m] from world x/y points ``xy`` ``(E, 2)`` to the nearest
    footprint disc of the active obstacles (``dynamic``) or valuables; ``inf`` where none."""
    term: SemanticSceneEvent = env.event_manager.get_term_cfg(EVENT_NAME).func
    return term.state.distance(xy, env.scene.env_origins, dynamic)
