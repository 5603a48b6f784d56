"""The views of one design that objectives and constraints share, built once each.

An :class:`EvalContext` builds the limb, compiles it, mounts it on each carrier, runs
each tracking run, samples poses and answers which of them the limb can take, each on
first use; every objective and constraint of an evaluation reads the same context.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cached_property

import mujoco
import numpy as np

from robotwright.grammar.build import Limb, build
from robotwright.grammar.design import Design
from robotwright.grammar.overlap import OverlapCheck
from robotwright.grammar.physics import (
    TRACK_CENTER,
    TRACK_RADIUS,
    Carrier,
    Mounted,
    TrackResult,
    carrier_collisions,
    mount,
    sample_joint_vectors,
    track,
)
from robotwright.grammar.rules import Grammar

__all__ = ["EvalContext"]


class EvalContext:
    """Lazily built views of one design shared by all objectives and constraints."""

    def __init__(self, grammar: Grammar, design: Design) -> None:
        self.grammar = grammar
        self.design = design

    @cached_property
    def limb(self) -> Limb:
        return build(self.grammar, self.design)

    def value(self, objective: Callable[[EvalContext], float]) -> float:
        """``objective`` on this design, computed once (a weighted sum and the values
        reported beside it share one computation)."""
        cache = self.__dict__.setdefault("_values", {})
        if objective not in cache:
            cache[objective] = float(objective(self))
        return cache[objective]

    @cached_property
    def model(self) -> mujoco.MjModel:
        return self.limb.to_spec().compile()

    def mounted(self, carrier: Carrier) -> Mounted:
        """The limb compiled on ``carrier`` (joints locked), built once per carrier."""
        cache = self.__dict__.setdefault("_mounted", {})
        if carrier not in cache:
            cache[carrier] = mount(self.limb, carrier)
        return cache[carrier]

    def tracking(
        self,
        carrier: Carrier,
        duration: float,
        scale: float,
        path: tuple[tuple[float, float, float], ...] | None = None,
        center: tuple[float, float, float] | None = TRACK_CENTER,
        radius: float | None = TRACK_RADIUS,
    ) -> TrackResult:
        """One tracking run (shared by ``track``, ``energy`` and the constraints
        measured on it)."""
        key = (carrier, duration, scale, path, center, radius)
        cache = self.__dict__.setdefault("_tracks", {})
        if key not in cache:
            cache[key] = track(
                self.limb,
                carrier,
                duration=duration,
                scale=scale,
                mounted=self.mounted(carrier),
                path=path,
                center=center,
                radius=radius,
            )
        return cache[key]

    def pose_is_free(
        self, pose: int, samples: int, seed: int, carrier: Carrier | None = None
    ) -> bool:
        """Whether pose number ``pose`` of :meth:`poses` is one the limb can take: no
        contact of the limb with itself (MuJoCo), no overlapping parts
        (:attr:`overlap_check`), and, given ``carrier``, no contact with it while worn.
        Each answer is computed once."""
        key = (pose, samples, seed, carrier)
        cache = self.__dict__.setdefault("_free", {})
        if key not in cache:
            q = self.poses(samples, seed)[pose]
            check, data = self.overlap_check, self._data
            check.pose(data, q)
            mujoco.mj_collision(self.model, data)
            free = not data.ncon and not check.at(data, first_only=True)
            if free and carrier is not None:
                free = not carrier_collisions(self.mounted(carrier), q[None])
            cache[key] = free
        return cache[key]

    @cached_property
    def _data(self) -> mujoco.MjData:
        return mujoco.MjData(self.model)

    @cached_property
    def overlap_check(self) -> OverlapCheck:
        """The overlap check of the limb alone (:class:`~robotwright.grammar.overlap.
        OverlapCheck`), made once."""
        return OverlapCheck(self.limb, self.model)

    def poses(self, samples: int, seed: int) -> np.ndarray:
        """The zero pose (clipped into the ranges) and ``samples`` joint vectors drawn
        uniformly inside them (seeded), in the limb's joint order: the poses of
        :meth:`tool_points`, :meth:`pose_is_free` and :class:`NoOverlap`."""
        key = (samples, seed)
        cache = self.__dict__.setdefault("_pose_sets", {})
        if key not in cache:
            limb = self.limb
            lo, hi = limb.joint_ranges().T if limb.joints else (np.zeros(0), np.zeros(0))
            cache[key] = sample_joint_vectors(lo, hi, samples, seed)
        return cache[key]

    def pose_of_point(self, k: int, samples: int) -> int:
        """The pose of point ``k`` of :meth:`tool_points` (branch by branch, each over
        every pose)."""
        return k % (samples + 1)

    def tool_points(self, samples: int, seed: int) -> np.ndarray:
        """Tool-point positions (m, mount frame) of every branch for ``samples`` joint
        vectors drawn uniformly inside the joint ranges (seeded), plus the zero pose."""
        key = (samples, seed)
        cache = self.__dict__.setdefault("_points", {})
        if key not in cache:
            limb = self.limb
            names = [j.name for j in limb.joints]
            q = self.poses(samples, seed)
            pts = []
            for br in limb.branches:
                cols = [names.index(n) for n in br.joints]
                pts.append(br.tool_pose(q[:, cols])[..., :3, 3])
            cache[key] = np.concatenate(pts) if pts else np.zeros((0, 3))
        return cache[key]
