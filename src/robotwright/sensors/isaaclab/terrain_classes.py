"""A class per sub-terrain of Isaac Lab's terrain generator, if asked.

Isaac Lab's generator joins every sub-terrain into one mesh imported at
``/World/ground/terrain``: one Newton shape, one class for every terrain hit.
:func:`name_sub_terrains` swaps in a generator that keeps each sub-terrain's mesh with
its key and an importer that imports each as its own prim,
``/World/ground/<key>_<row>_<col>``. A LiDAR mapping that lists a key as a keyword of a
class, before the terrain class (the first class whose keyword matches wins; ``ground``
matches every terrain prim), gives those shapes that class::

    name_sub_terrains(env_cfg.scene.terrain)
    lidar.semantic_class_mapping = {"stairs": ["pyramid_stairs"], **DEFAULT_SEMANTIC_CLASS_MAPPING}

A mesh without volume cannot be a collision mesh of its own (MuJoCo refuses it): the
border (rebuilt as closed boxes with the same top) and any flat sub-terrain are imported
together as ``/World/ground/border``, class ``terrain``. Costs: one collision mesh per
sub-terrain instead of one in all, and no swap for a Newton height field (Isaac Lab
swaps only a single-mesh terrain).
"""

from __future__ import annotations

from typing import Any

import trimesh
from isaaclab.terrains import TerrainGenerator, TerrainImporter
from isaaclab.terrains.trimesh.utils import make_border

__all__ = ["NamedTerrainGenerator", "NamedTerrainImporter", "name_sub_terrains"]

#: Key of the trimesh metadata entry that carries the named sub-terrain meshes.
_PARTS = "robotwright_sub_terrains"
#: Smallest volume of a mesh imported on its own [m^3].
MIN_VOLUME = 1e-6


class NamedTerrainGenerator(TerrainGenerator):
    """Isaac Lab's generator that also keeps ``(key_row_col, mesh)`` per sub-terrain,
    handed to :class:`NamedTerrainImporter` with the joined mesh."""

    def __init__(self, cfg: Any, device: str = "cpu") -> None:
        self._named: list[tuple[str, Any]] = []  # filled while the parent generates
        super().__init__(cfg, device)
        solid = [(n, m) for n, m in self._named if abs(m.volume) > MIN_VOLUME]
        flat = [m for n, m in self._named if abs(m.volume) <= MIN_VOLUME]
        self.terrain_mesh.metadata[_PARTS] = [*solid, ("border", self._closed_border(flat))]

    def _add_sub_terrain(self, mesh: Any, origin: Any, row: int, col: int, sub_cfg: Any) -> None:
        super()._add_sub_terrain(mesh, origin, row, col, sub_cfg)
        key = next(k for k, v in self.cfg.sub_terrains.items() if v is sub_cfg)
        self._named.append((f"{key}_{row}_{col}", mesh))

    def _closed_border(self, flat: list[Any]) -> Any:
        """The border as closed boxes (the parent keeps only their tops), with ``flat``."""
        c = self.cfg
        inner = (c.num_rows * c.size[0], c.num_cols * c.size[1])
        outer = (inner[0] + 2 * c.border_width, inner[1] + 2 * c.border_width)
        centre = (inner[0] / 2, inner[1] / 2, -c.border_height / 2)
        boxes = make_border(outer, inner, height=abs(c.border_height), position=centre)
        return trimesh.util.concatenate([*boxes, *flat])


class NamedTerrainImporter(TerrainImporter):
    """Isaac Lab's importer that imports a :class:`NamedTerrainGenerator`'s terrain as
    one prim per sub-terrain (and the border) instead of one joined mesh."""

    def import_mesh(self, name: str, mesh: Any) -> None:
        parts = getattr(mesh, "metadata", {}).get(_PARTS)
        if name != "terrain" or not parts:
            super().import_mesh(name, mesh)
            return
        for part_name, part in parts:
            super().import_mesh(part_name, part)

    def _is_heightfield_collider_requested(self, cfg: Any) -> bool:
        """Never: Isaac Lab would tag only the last prim imported (here the border)."""
        return False


def name_sub_terrains(terrain: Any) -> None:
    """Make Isaac Lab's ``TerrainImporterCfg`` ``terrain`` (a generator terrain) import
    each sub-terrain as its own prim named after its key (in place)."""
    if terrain.terrain_generator is None:
        raise ValueError(
            "name_sub_terrains: the terrain has no generator (terrain_type 'generator')"
        )
    terrain.class_type = NamedTerrainImporter
    terrain.terrain_generator.class_type = NamedTerrainGenerator
