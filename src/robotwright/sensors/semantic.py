"""``SemanticLidarSensor``: a LiDAR whose every ray carries the class of what it hit.

The ray engines return the id of the hit geom for each ray, so labels are exact per ray
(no simplified per-mesh version is needed): a geom's class is decided once, from
its path, and a lookup table turns hit geom ids into class ids on every update.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, fields
from typing import TYPE_CHECKING, Any

import mujoco
import numpy as np

from robotwright.errors import SensorError
from robotwright.sensors.config import SemanticLidarCfg
from robotwright.sensors.lidar import LidarSensor, LidarSensorData

if TYPE_CHECKING:  # the warp extra is optional
    from mujoco_warp import Data as WarpData

__all__ = ["SemanticLidarData", "SemanticLidarSensor", "classify_path", "geom_class_table"]


def classify_path(path: str, mapping: dict[str, list[str]]) -> int:
    """Class id of a path: the first class (mapping order, ids from 1) one of whose
    keywords occurs in it, case-insensitively; 0 when none does."""
    lowered = path.lower()
    for cls_id, keywords in enumerate(mapping.values(), start=1):
        if any(k.lower() in lowered for k in keywords):
            return cls_id
    return 0


def geom_class_table(
    paths: Sequence[str], mapping: dict[str, list[str]], hittable: np.ndarray | None = None
) -> np.ndarray:
    """``(ngeom + 1,)`` int32 class id per geom path, 0 for geoms not ``hittable``; the
    extra last entry answers geom id -1 (a miss) with class 0."""
    table = np.zeros(len(paths) + 1, dtype=np.int32)
    for g, path in enumerate(paths):
        if hittable is None or hittable[g]:
            table[g] = classify_path(path, mapping)
    return table


@dataclass
class SemanticLidarData(LidarSensorData):
    """:class:`LidarSensorData` plus semantic fields.

    Fields follow ``cfg.output`` like the parent's (numpy, or zero-copy torch/warp views).

    Attributes:
        semantic_labels: ``(E, N)`` int32 class id per ray: 1..K in mapping order,
            0 for a miss or a hit on a geom no keyword matches. ``None`` when
            ``return_semantic_labels`` is False.
        mesh_ids: ``(E, N)`` int32 id of the hit geom (MuJoCo geom id), -1 on a miss.
            ``None`` unless ``return_mesh_ids`` is True.
    """

    semantic_labels: Any = None
    mesh_ids: Any = None


class SemanticLidarSensor(LidarSensor):
    """LiDAR with per-ray semantic labels from keyword matching on geom paths.

    Args:
        cfg: a :class:`SemanticLidarCfg`.
        model: the compiled MuJoCo model.
        data: one ``MjData`` or a list of them (one per environment).

    Attributes:
        semantic_class_mapping: class name -> keywords (the config's, or the default).
        class_names: ``("unknown", <class 1>, ..., <class K>)``, indexed by class id.
        mesh_id_to_semantic_class: geom id -> class id, for every hittable geom.
    """

    cfg: SemanticLidarCfg

    def __init__(
        self,
        cfg: SemanticLidarCfg,
        model: mujoco.MjModel,
        data: mujoco.MjData | Sequence[mujoco.MjData] | WarpData,
    ) -> None:
        if not isinstance(cfg, SemanticLidarCfg):
            raise SensorError(f"cfg: expected a SemanticLidarCfg, got {type(cfg).__name__}")
        assert cfg.semantic_class_mapping is not None  # filled by SemanticLidarCfg.__post_init__
        self.semantic_class_mapping: dict[str, list[str]] = {
            k: list(v) for k, v in cfg.semantic_class_mapping.items()
        }
        self.class_names: tuple[str, ...] = ("unknown", *self.semantic_class_mapping)
        self.mesh_id_to_semantic_class: dict[int, int] = {}
        super().__init__(cfg, model, data)  # classifies geoms in _initialize_warp_meshes

    @property
    def return_semantic_labels(self) -> bool:
        return bool(self.cfg.return_semantic_labels)

    @property
    def return_mesh_ids(self) -> bool:
        return bool(self.cfg.return_mesh_ids)

    @property
    def data(self) -> SemanticLidarData:
        return self._data  # type: ignore[return-value]

    def _make_data(self) -> SemanticLidarData:
        base = super()._make_data()
        shape = (self.num_envs, self.num_rays)
        if self.cfg.output != "numpy":
            assert self._pipeline is not None
            labels = self._device_view(self._pipeline.labels)
            ids = self._device_view(self._pipeline.geom_ids)
        else:
            labels = np.zeros(shape, dtype=np.int32)
            ids = np.full(shape, -1, dtype=np.int32)
        data = SemanticLidarData(
            **{f.name: getattr(base, f.name) for f in fields(base) if f.init},
            semantic_labels=labels if self.cfg.return_semantic_labels else None,
            mesh_ids=ids if self.cfg.return_mesh_ids else None,
        )
        data._cache.update(base._cache)
        return data

    def _classify_mesh_path(self, mesh_prim_path: str) -> int:
        """Class id of a path: first class (mapping order) with a keyword in it; 0 if none.

        Matching is case-insensitive substring search.
        """
        return classify_path(mesh_prim_path, self.semantic_class_mapping)

    def _initialize_warp_meshes(self) -> None:
        """Classify every hittable geom once (seed name; the "meshes" here are MuJoCo geoms).

        Builds ``mesh_id_to_semantic_class`` and a lookup table indexed by geom id whose
        last entry (index -1, a miss) is class 0; the warp engine keeps it on the device.
        """
        self._label_lut = geom_class_table(
            self._geom_paths, self.semantic_class_mapping, self.hittable_geom_mask
        )
        self.geom_semantic_class = self._label_lut[:-1]
        self.mesh_id_to_semantic_class.update(
            {int(g): int(self._label_lut[g]) for g in np.flatnonzero(self.hittable_geom_mask)}
        )

    def _update_buffers_impl(self, env_ids: Sequence[int] | np.ndarray | None) -> None:
        """Cast (parent), then turn hit geom ids into labels."""
        super()._update_buffers_impl(env_ids)
        self._compute_semantic_labels(env_ids)

    def _compute_semantic_labels(self, env_ids: Sequence[int] | np.ndarray | None) -> None:
        """Fill labels (and mesh ids) of ``env_ids`` (all when None) from the hit geom ids.

        Device outputs were labelled by the ``finish_rays`` kernel already: nothing to do.
        """
        if self.cfg.output != "numpy":
            return
        rows = self._rows(env_ids)
        ids = self._raw_geom_ids[rows]
        if self._data.semantic_labels is not None:
            if env_ids is None:
                # "wrap": index -1 (a miss) is the last entry, with no bounds check to pay
                np.take(self._label_lut, ids, out=self._data.semantic_labels, mode="wrap")
            else:
                self._data.semantic_labels[rows] = self._label_lut[ids]
        if self._data.mesh_ids is not None:
            self._data.mesh_ids[rows] = ids

    def get_semantic_labels(self, env_ids: Sequence[int] | np.ndarray | None = None) -> Any:
        """Class id per ray ``(num_envs, num_rays)`` int32 (0 = miss/unknown)."""
        if self._data.semantic_labels is None:
            raise SensorError(
                "semantic labels are off: set SemanticLidarCfg.return_semantic_labels=True"
            )
        return self._take(self._data.semantic_labels, env_ids)

    def get_mesh_ids(self, env_ids: Sequence[int] | np.ndarray | None = None) -> Any:
        """Hit geom id per ray ``(num_envs, num_rays)`` int32 (-1 = miss)."""
        if self._data.mesh_ids is None:
            raise SensorError("mesh ids are off: set SemanticLidarCfg.return_mesh_ids=True")
        return self._take(self._data.mesh_ids, env_ids)

    def geom_path(self, geom_id: int) -> str:
        """The classification path of a geom (``/world/<bodies>/<geom>[/<mesh>]``)."""
        return self._geom_paths[int(geom_id)]
