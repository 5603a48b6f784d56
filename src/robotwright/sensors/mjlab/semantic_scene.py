"""The class-labelled scene (:class:`~robotwright.sensors.semantic_scene.SemanticSceneCfg`)
in mjlab: one mocap entity per object slot, placed and moved by one event term.

``add_semantic_scene(env_cfg, SemanticSceneCfg())`` adds to an mjlab environment config

* an entity per slot, named ``obstacle_0_cracker_box``, ``valuable_0_sofa``, ... holding
  one primitive geom named after its asset (``cracker_box``): mjlab makes the fixed body
  a mocap body, so the object is kinematic (it pushes a robot; nothing pushes it), and
  the LiDAR's class comes from the geom's path;
* the event term ``semantic_scene`` (:class:`SemanticSceneEvent`, mode ``"step"``):
  at each environment's reset it draws the layout
  (:func:`~robotwright.sensors.semantic_scene.sample_layout`) around the environment's
  origin, and every environment step it moves the dynamic obstacles along their paths
  (:func:`~robotwright.sensors.semantic_scene.advance`).

With ``clutter_curriculum=True`` and a terrain generator with a curriculum, an
environment on terrain level ``l`` of ``L`` gets ``ceil(N (l + 1) / L)`` of its ``N``
obstacles in the arena; the others are parked :data:`PARK_DEPTH` m under its origin,
where no ray from above reaches them. Objects stand on the environment origin's height.
"""

from __future__ import annotations

from typing import Any

import mujoco
import torch
from mjlab.entity import EntityCfg
from mjlab.managers.event_manager import EventTermCfg

from robotwright.sensors.semantic_scene import (
    PARK_DEPTH,
    SceneAssetCfg,
    SceneState,
    SemanticSceneCfg,
    clutter_share,
)

__all__ = [
    "PARK_DEPTH",
    "SemanticSceneEvent",
    "add_semantic_scene",
    "object_distances",
    "scene_entities",
]

#: The event term's name in ``env_cfg.events``.
EVENT_NAME = "semantic_scene"


def _object_spec(asset: SceneAssetCfg) -> Any:
    """A spec function: one fixed body holding the asset's geom (named after the asset,
    its centre at the body's origin)."""

    def spec_fn() -> mujoco.MjSpec:
        spec = mujoco.MjSpec()
        asset.add_geom(spec.worldbody.add_body(name="object"))
        return spec

    return spec_fn


def scene_entities(scene: SemanticSceneCfg) -> dict[str, EntityCfg]:
    """An entity per slot of ``scene`` (validated first), keyed by the slot's name."""
    scene.check()
    return {slot.name: EntityCfg(spec_fn=_object_spec(slot.asset)) for slot in scene.slots()}


def add_semantic_scene(
    env_cfg: Any, scene: SemanticSceneCfg, clutter_curriculum: bool = False
) -> None:
    """Add the objects and the event term of ``scene`` to ``env_cfg`` (an mjlab
    ``ManagerBasedRlEnvCfg``), and room for their contacts with a robot."""
    env_cfg.scene.entities = {**env_cfg.scene.entities, **scene_entities(scene)}
    env_cfg.events[EVENT_NAME] = EventTermCfg(
        func=SemanticSceneEvent,
        mode="step",
        params={"scene": scene, "clutter_curriculum": clutter_curriculum},
    )
    if env_cfg.sim.nconmax is not None:
        env_cfg.sim.nconmax += 8 * len(scene.slots())


class SemanticSceneEvent:
    """mjlab event term (class form, mode ``"step"``): draws each environment's layout at
    its reset (:meth:`reset`) and moves the dynamic obstacles every step (``__call__``);
    the layout lives in :attr:`state`
    (:class:`~robotwright.sensors.semantic_scene.SceneState`)."""

    def __init__(self, cfg: EventTermCfg, env: Any) -> None:
        self.state = SceneState(cfg.params["scene"], env.num_envs, env.device)
        self.curriculum = bool(cfg.params.get("clutter_curriculum", False))
        self.env = env
        self.entities = [env.scene[slot.name] for slot in self.state.slots]

    def reset(self, env_ids: torch.Tensor | None = None) -> None:
        """Draw the layout of ``env_ids`` (all when ``None``) and put the objects there."""
        if env_ids is None:
            env_ids = torch.arange(self.env.num_envs, device=self.env.device)
        self.state.redraw(env_ids, self._clutter(env_ids))
        self._write(env_ids, range(len(self.state.slots)))

    def __call__(self, env: Any, env_ids: Any, **_params: Any) -> None:
        """One environment step: the dynamic obstacles move by ``velocity * step_dt``."""
        if self.state.dynamic:
            self.state.step(env.step_dt)
            self._write(torch.arange(env.num_envs, device=env.device), self.state.dynamic)

    def _clutter(self, env_ids: torch.Tensor) -> torch.Tensor | None:
        """The curriculum's share of obstacles for ``env_ids`` (see the module)."""
        if not self.curriculum:
            return None
        return clutter_share(getattr(self.env.scene, "terrain", None), env_ids)

    def _write(self, env_ids: torch.Tensor, slots: Any) -> None:
        origins = self.env.scene.env_origins[env_ids]
        for k in slots:
            pos, quat = self.state.poses(env_ids, k, origins)
            self.entities[k].write_mocap_pose_to_sim(torch.cat([pos, quat], dim=1), env_ids=env_ids)


def object_distances(env: Any, xy: torch.Tensor, dynamic: bool) -> torch.Tensor:
    """``(E,)`` distance [m] from the world x/y points ``xy`` ``(E, 2)`` to the nearest
    footprint disc of the scene's active obstacles (``dynamic``) or valuables; ``inf``
    where there is none."""
    term: SemanticSceneEvent = env.event_manager.get_term_cfg(EVENT_NAME).func
    return term.state.distance(xy, env.scene.env_origins, dynamic)
