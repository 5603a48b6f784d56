"""A class per sub-terrain of mjlab's terrain generator, if asked.

mjlab names the terrain's geoms ``terrain_0``, ``terrain_1``, ... whatever sub-terrain
made them, so every terrain hit has one class. :func:`name_sub_terrains` wraps each
sub-terrain of a ``TerrainGeneratorCfg`` so that the geoms it makes are named after its
key (``pyramid_stairs_412_0``: key, geoms in the spec before it, index): a LiDAR mapping
that lists the key as a keyword of a class, before the terrain class (the first class
whose keyword matches wins), gives those geoms that class::

    name_sub_terrains(env_cfg.scene.terrain.terrain_generator)
    lidar.semantic_class_mapping = {"stairs": ["pyramid_stairs"], **DEFAULT_SEMANTIC_CLASS_MAPPING}

Isaac Lab merges every sub-terrain into one mesh, one Newton shape, so there a hit on the
terrain has the terrain's class only.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np
from mjlab.terrains.terrain_generator import SubTerrainCfg, TerrainOutput

__all__ = ["NamedSubTerrainCfg", "name_sub_terrains"]


@dataclass(kw_only=True)
class NamedSubTerrainCfg(SubTerrainCfg):
    """``sub_terrain`` whose geoms are named ``<name>_<n>_<k>`` (it draws the geometry)."""

    sub_terrain: SubTerrainCfg
    name: str

    def function(
        self, difficulty: float, spec: mujoco.MjSpec, rng: np.random.Generator
    ) -> TerrainOutput:
        self.sub_terrain.size = self.size  # the generator sets the wrapper's
        before = len(spec.geoms)
        out = self.sub_terrain.function(difficulty, spec, rng)
        for k, part in enumerate(out.geometries):
            if part.geom is not None and not part.geom.name:
                part.geom.name = f"{self.name}_{before}_{k}"
        return out


def name_sub_terrains(generator: Any) -> None:
    """Wrap every sub-terrain of mjlab's ``TerrainGeneratorCfg`` ``generator`` (in place)
    so that its geoms carry its key in their names; wrapping twice changes nothing."""
    wrapped = {}
    for key, sub in generator.sub_terrains.items():
        if not isinstance(sub, NamedSubTerrainCfg):
            sub = NamedSubTerrainCfg(
                sub_terrain=sub,
                name=key,
                proportion=sub.proportion,
                size=sub.size,
                flat_patch_sampling=sub.flat_patch_sampling,
            )
        wrapped[key] = sub
    generator.sub_terrains = wrapped
