"""Class-labelled clutter around every environment: the seed's boxes, cans and furniture.

:class:`SemanticSceneCfg` is one config for both frameworks (mjlab:
:mod:`robotwright.sensors.mjlab.semantic_scene`, Isaac Lab:
:mod:`robotwright.sensors.isaaclab.semantic_scene`). Each environment gets
``num_obstacles`` dynamic obstacles and ``num_valuables`` valuables; slot ``k`` of a
group holds asset ``k mod len(assets)`` of that group, so the default three obstacles
are a cracker box, a sugar box and a tomato-soup can, and the three valuables a sofa, an
armchair and a table. An object's name (mjlab: its geom, Isaac Lab: its prim) is its
asset's ``name``, which carries the class keyword: labels are right by construction
(:meth:`SemanticSceneCfg.expected_classes` says which class each slot gets under a
mapping; the adapters' tests compare that with what the sensor reads).

At every reset of an environment its objects are drawn anew (:func:`sample_layout`):
uniformly with their footprints in the square arena of half side ``arena_half`` around the environment origin,
outside the keep-out disc of radius ``keep_out`` around the robot's spawn, every two
footprints ``min_separation`` apart (a bounded number of tries), a uniform yaw. The dynamic
obstacles move on straight kinematic paths at a speed drawn from ``obstacle_speed``,
bouncing off the arena's sides (:func:`advance`); valuables stay put. Objects are
kinematic: they push a robot, nothing pushes them.

Units: metres, m/s, radians; positions are in the environment's frame (its origin,
world axes). This module needs torch, not mjlab or Isaac Lab.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

import mujoco
import torch

from robotwright._bounds import Bound
from robotwright.errors import SensorError
from robotwright.sensors.config import DEFAULT_SEMANTIC_CLASS_MAPPING, check_class_mapping
from robotwright.sensors.semantic import classify_path

__all__ = [
    "DEFAULT_OBSTACLES",
    "DEFAULT_VALUABLES",
    "PARK_DEPTH",
    "SceneAssetCfg",
    "SceneLayout",
    "SceneSlot",
    "SceneState",
    "SemanticSceneCfg",
    "advance",
    "clutter_share",
    "sample_layout",
]

#: Most objects of one group per environment.
MAX_OBJECTS = 64
#: Sizes and distances a scene config accepts [m].
LENGTH_BOUND = Bound(0.0, 100.0, unit="m", open_low=True)
#: Colour components.
COLOUR_BOUND = Bound(0.0, 1.0)
#: Gaps that may be zero [m].
GAP_BOUND = Bound(0.0, 100.0, unit="m")
#: Obstacle speeds [m/s].
SPEED_BOUND = Bound(0.0, 10.0, unit="m/s")
#: Candidate positions per object and environment.
LAYOUT_TRIES = 64
#: MuJoCo geom type of each asset shape.
_GEOM_TYPES = {"box": mujoco.mjtGeom.mjGEOM_BOX, "cylinder": mujoco.mjtGeom.mjGEOM_CYLINDER}


@dataclass
class SceneAssetCfg:
    """One kind of object: a primitive whose name carries its class keyword.

    Attributes:
        name: the object's name (geom / prim name), e.g. ``"cracker_box"``; letters,
            digits and ``_`` only.
        shape: ``"box"`` (``size`` = half-sizes x, y, z) or ``"cylinder"`` (``size`` =
            radius, half-height), upright, standing on the ground.
        size: [m], see ``shape``.
        rgba: display colour.
    """

    name: str
    shape: Literal["box", "cylinder"]
    size: tuple[float, ...]
    rgba: tuple[float, float, float, float] = (0.7, 0.7, 0.7, 1.0)

    @property
    def half_height(self) -> float:
        """Half the object's height [m]: it stands with its centre this high."""
        return float(self.size[2] if self.shape == "box" else self.size[1])

    @property
    def footprint_radius(self) -> float:
        """Radius of the disc that holds the object's footprint at any yaw [m]."""
        if self.shape == "box":
            return math.hypot(self.size[0], self.size[1])
        return float(self.size[0])

    def add_geom(self, body: mujoco.MjsBody) -> mujoco.MjsGeom:
        """Add the asset to a MuJoCo spec ``body`` as one geom named after it, its centre
        at the body's origin (the mjlab scene and the task's picture build it so)."""
        size = tuple(self.size) + (0.0,) * (3 - len(self.size))
        return body.add_geom(
            name=self.name, type=_GEOM_TYPES[self.shape], size=size, rgba=self.rgba
        )

    def check(self, where: str) -> None:
        """Raise :class:`SensorError` naming ``where`` and the field on a bad value."""
        if not self.name or not all(c.isalnum() or c == "_" for c in self.name):
            raise SensorError(f"{where}.name {self.name!r}: expected letters, digits and '_' only")
        want = {"box": 3, "cylinder": 2}.get(self.shape)
        if want is None:
            raise SensorError(f"{where}.shape {self.shape!r}: expected 'box' or 'cylinder'")
        size = self.size
        if (
            not isinstance(size, (tuple, list))
            or len(size) != want
            or any(LENGTH_BOUND.check(v) is None for v in size)
        ):
            raise SensorError(
                f"{where}.size {self.size!r}: expected {want} sizes, each {LENGTH_BOUND.describe()}"
            )
        rgba = self.rgba
        if (
            not isinstance(rgba, (tuple, list))
            or len(rgba) != 4
            or any(COLOUR_BOUND.check(v) is None for v in rgba)
        ):
            raise SensorError(
                f"{where}.rgba {rgba!r}: expected 4 values, each {COLOUR_BOUND.describe()}"
            )


#: The seed's dynamic obstacles at their YCB sizes (half-sizes / radius, half-height).
DEFAULT_OBSTACLES = (
    SceneAssetCfg("cracker_box", "box", (0.08, 0.03, 0.105), (0.85, 0.2, 0.15, 1.0)),
    SceneAssetCfg("sugar_box", "box", (0.045, 0.0175, 0.0875), (0.95, 0.85, 0.3, 1.0)),
    SceneAssetCfg("tomato_soup_can", "cylinder", (0.034, 0.0505), (0.8, 0.1, 0.1, 1.0)),
)
#: The seed's valuables as boxes of furniture size.
DEFAULT_VALUABLES = (
    SceneAssetCfg("sofa", "box", (0.9, 0.4, 0.4), (0.3, 0.4, 0.8, 1.0)),
    SceneAssetCfg("armchair", "box", (0.4, 0.4, 0.45), (0.2, 0.6, 0.5, 1.0)),
    SceneAssetCfg("table", "box", (0.6, 0.4, 0.375), (0.55, 0.35, 0.2, 1.0)),
)


@dataclass
class SemanticSceneCfg:
    """Per-environment clutter of named, class-carrying objects (see the module).

    Attributes:
        obstacles, valuables: the assets of each group, used in turn by its slots.
        num_obstacles, num_valuables: objects per environment, 0..:data:`MAX_OBJECTS`.
        arena_half: half side of the square the objects stand in, around the
            environment origin [m].
        keep_out: no object centre closer than this to the origin (the robot's spawn)
            plus the object's footprint radius [m].
        min_separation: smallest gap between two objects' footprint discs [m].
        obstacle_speed: (low, high) speed of a dynamic obstacle, drawn per obstacle at
            each reset [m/s]; ``(0, 0)`` keeps them still.
        mapping: class name -> keywords (``None``: the sensors' default mapping).
    """

    obstacles: tuple[SceneAssetCfg, ...] = DEFAULT_OBSTACLES
    valuables: tuple[SceneAssetCfg, ...] = DEFAULT_VALUABLES
    num_obstacles: int = 3
    num_valuables: int = 3
    arena_half: float = 3.0
    keep_out: float = 0.6
    min_separation: float = 0.2
    obstacle_speed: tuple[float, float] = (0.1, 0.4)
    mapping: dict[str, list[str]] | None = field(default=None)

    def check(self) -> None:
        """Validate every field (configs change after construction: called when used).

        Raises:
            SensorError: naming the field and what it expects.
        """
        for group in ("obstacles", "valuables"):
            assets = getattr(self, group)
            count = getattr(self, f"num_{group}")
            if (
                isinstance(count, bool)
                or not isinstance(count, int)
                or not 0 <= count <= MAX_OBJECTS
            ):
                raise SensorError(
                    f"SemanticSceneCfg.num_{group} {count!r}: expected a whole number in "
                    f"[0, {MAX_OBJECTS}]"
                )
            if not isinstance(assets, (tuple, list)) or not all(
                isinstance(a, SceneAssetCfg) for a in assets
            ):
                raise SensorError(f"SemanticSceneCfg.{group}: expected a tuple of SceneAssetCfg")
            if count and not assets:
                raise SensorError(f"SemanticSceneCfg.{group}: empty, but num_{group} is {count}")
            for i, asset in enumerate(assets):
                asset.check(f"SemanticSceneCfg.{group}[{i}]")
        for name, bound in (
            ("arena_half", LENGTH_BOUND),
            ("keep_out", GAP_BOUND),
            ("min_separation", GAP_BOUND),
        ):
            if bound.check(getattr(self, name)) is None:
                raise SensorError(
                    f"SemanticSceneCfg.{name} {getattr(self, name)!r}: {bound.expected()}"
                )
        if self.mapping is not None:
            check_class_mapping(self.mapping, "SemanticSceneCfg.mapping")
        speed = self.obstacle_speed
        low, high = speed if isinstance(speed, (tuple, list)) and len(speed) == 2 else (None, None)
        if SPEED_BOUND.check(low) is None or SPEED_BOUND.check(high) is None or low > high:
            raise SensorError(
                f"SemanticSceneCfg.obstacle_speed {self.obstacle_speed!r}: expected (low, high), "
                f"low <= high, each {SPEED_BOUND.describe()}"
            )

    def slots(self) -> list[SceneSlot]:
        """The objects of one environment, obstacles first: ``obstacle_0_cracker_box``, ..."""
        out = [
            SceneSlot(f"obstacle_{k}", self.obstacles[k % len(self.obstacles)], dynamic=True)
            for k in range(self.num_obstacles)
        ]
        out += [
            SceneSlot(f"valuable_{k}", self.valuables[k % len(self.valuables)], dynamic=False)
            for k in range(self.num_valuables)
        ]
        return out

    def class_mapping(self) -> dict[str, list[str]]:
        """The mapping the labels are judged by."""
        return DEFAULT_SEMANTIC_CLASS_MAPPING if self.mapping is None else self.mapping

    def expected_classes(self) -> dict[str, str]:
        """Slot name -> the class its object's name falls in under :meth:`class_mapping`
        (``"unknown"`` when no keyword matches)."""
        mapping = self.class_mapping()
        names = ["unknown", *mapping]
        return {s.name: names[classify_path(s.asset.name, mapping)] for s in self.slots()}


@dataclass(frozen=True)
class SceneSlot:
    """One object of an environment: its slot name (``obstacle_0``), asset and group."""

    slot: str
    asset: SceneAssetCfg
    dynamic: bool

    @property
    def name(self) -> str:
        """``<slot>_<asset name>``: the entity / prim name, carrying the class keyword."""
        return f"{self.slot}_{self.asset.name}"


@dataclass
class SceneLayout:
    """Poses of one draw: ``xy`` ``(n, S, 2)`` [m] in each env's frame, ``yaw`` ``(n, S)``
    [rad], ``velocity`` ``(n, S, 2)`` [m/s] (zero for valuables); ``S`` = slots."""

    xy: torch.Tensor
    yaw: torch.Tensor
    velocity: torch.Tensor


def sample_layout(cfg: SemanticSceneCfg, n: int, device: torch.device | str) -> SceneLayout:
    """Draw the objects of ``n`` environments (see the module), one slot after the other:
    of :data:`LAYOUT_TRIES` uniform candidates for a slot, the first whose disc keeps
    ``keep_out`` from the origin and ``min_separation`` from the slots placed before it;
    when none does, the candidate with the largest worst gap."""
    slots = cfg.slots()
    s = len(slots)
    xy = torch.zeros(n, s, 2, device=device)
    rows = torch.arange(n, device=device)
    radii = [sl.asset.footprint_radius for sl in slots]
    placed = torch.tensor(radii, device=device)
    for k, r in enumerate(radii):
        half = max(cfg.arena_half - r, 0.0)  # the whole footprint inside the arena
        cand = (torch.rand(n, LAYOUT_TRIES, 2, device=device) * 2.0 - 1.0) * half
        worst = cand.norm(dim=-1) - r - cfg.keep_out  # (n, T)
        if k:
            gaps = torch.cdist(cand, xy[:, :k]) - r - placed[:k] - cfg.min_separation
            worst = torch.minimum(worst, gaps.amin(dim=-1))
        ok = worst >= 0
        pick = torch.where(ok.any(1), ok.float().argmax(1), worst.argmax(1))
        xy[:, k] = cand[rows, pick]
    yaw = (torch.rand(n, s, device=device) * 2.0 - 1.0) * math.pi
    dynamic = torch.tensor([sl.dynamic for sl in slots], device=device)
    low, high = cfg.obstacle_speed
    speed = (torch.rand(n, s, device=device) * (high - low) + low) * dynamic
    heading = torch.rand(n, s, device=device) * 2.0 * math.pi
    velocity = torch.stack([speed * heading.cos(), speed * heading.sin()], dim=-1)
    return SceneLayout(xy, yaw, velocity)


def advance(
    xy: torch.Tensor, velocity: torch.Tensor, dt: float, arena_half: float
) -> tuple[torch.Tensor, torch.Tensor]:
    """Move ``xy`` by ``velocity * dt`` [m], reflecting at the arena's sides (the
    velocity's component across a side flips). Returns the new (xy, velocity)."""
    moved = xy + velocity * dt
    over = moved.abs() > arena_half
    moved = torch.where(over, torch.sign(moved) * (2.0 * arena_half - moved.abs()), moved)
    return moved.clamp(-arena_half, arena_half), torch.where(over, -velocity, velocity)


#: How far under its environment's origin an inactive obstacle is parked [m]: where no
#: ray from above the terrain reaches it.
PARK_DEPTH = 10.0


def clutter_share(terrain: object, env_ids: torch.Tensor) -> torch.Tensor | None:
    """The clutter curriculum's share for ``env_ids``: (terrain level + 1) / the levels,
    read from a terrain with a curriculum (mjlab's and Isaac Lab's both keep
    ``terrain_levels`` and ``max_terrain_level``); ``None`` without one."""
    levels = getattr(terrain, "terrain_levels", None)
    if levels is None:
        return None
    top = max(int(getattr(terrain, "max_terrain_level", 1)), 1)
    return (levels[env_ids].float() + 1.0) / top


class SceneState:
    """The objects of ``n`` environments between resets, the same in every framework:
    the adapters call :meth:`redraw` at an environment's reset, :meth:`step` every
    environment step, and write :meth:`poses` to their simulator.

    Attributes:
        slots: the scene's slots, in order.
        xy: ``(n, S, 2)`` positions relative to each environment's origin [m].
        yaw: ``(n, S)`` [rad]. velocity: ``(n, S, 2)`` [m/s].
        active: ``(n, S)`` bool: in the arena (False: parked, see :meth:`redraw`).
    """

    def __init__(self, cfg: SemanticSceneCfg, n: int, device: torch.device | str) -> None:
        cfg.check()
        self.cfg, self.device = cfg, device
        self.slots = cfg.slots()
        s = len(self.slots)
        self.xy = torch.zeros(n, s, 2, device=device)
        self.yaw = torch.zeros(n, s, device=device)
        self.velocity = torch.zeros(n, s, 2, device=device)
        self.active = torch.ones(n, s, dtype=torch.bool, device=device)
        self.half_height = torch.tensor([sl.asset.half_height for sl in self.slots], device=device)
        self.radius = torch.tensor([sl.asset.footprint_radius for sl in self.slots], device=device)
        self.dynamic = [k for k, sl in enumerate(self.slots) if sl.dynamic]

    def redraw(self, env_ids: torch.Tensor, clutter: torch.Tensor | None = None) -> None:
        """New layouts for ``env_ids``. ``clutter`` ``(len(env_ids),)`` in [0, 1] (a
        curriculum's share: terrain level + 1 over the levels) keeps the first
        ``ceil(share * N)`` of the ``N`` obstacles in the arena and parks the others
        :data:`PARK_DEPTH` m under the origin; ``None`` keeps all."""
        if len(env_ids) == 0 or not self.slots:
            return
        layout = sample_layout(self.cfg, len(env_ids), self.device)
        self.xy[env_ids], self.yaw[env_ids] = layout.xy, layout.yaw
        self.velocity[env_ids] = layout.velocity
        on = torch.ones(len(env_ids), len(self.slots), dtype=torch.bool, device=self.device)
        if clutter is not None and self.dynamic:
            count = torch.ceil(clutter.float().clamp(0.0, 1.0) * len(self.dynamic))
            rank = torch.arange(len(self.dynamic), device=self.device)
            on[:, self.dynamic] = rank[None, :] < count[:, None]
        self.active[env_ids] = on

    def step(self, dt: float) -> None:
        """Move the dynamic obstacles of every environment along their paths for ``dt`` [s]."""
        if self.dynamic:
            k = self.dynamic
            self.xy[:, k], self.velocity[:, k] = advance(
                self.xy[:, k], self.velocity[:, k], dt, self.cfg.arena_half
            )

    def poses(
        self, env_ids: torch.Tensor, k: int, origins: torch.Tensor
    ) -> tuple[torch.Tensor, torch.Tensor]:
        """World position ``(n, 3)`` [m] and orientation ``(n, 4)`` (w, x, y, z) of slot
        ``k`` in ``env_ids``, whose environment origins are ``origins`` ``(n, 3)``: the
        object stands on the origin's height, or is parked under it."""
        z = torch.where(
            self.active[env_ids, k],
            self.half_height[k],
            torch.full_like(self.yaw[env_ids, k], -PARK_DEPTH),
        )
        pos = origins + torch.cat([self.xy[env_ids, k], z[:, None]], dim=1)
        half = self.yaw[env_ids, k] * 0.5
        zero = torch.zeros_like(half)
        return pos, torch.stack([half.cos(), zero, zero, half.sin()], dim=1)

    def distance(self, xy: torch.Tensor, origins: torch.Tensor, dynamic: bool) -> torch.Tensor:
        """``(n,)`` distance [m] from world points ``xy`` ``(n, 2)`` to the nearest footprint
        disc of the active obstacles (``dynamic``) or valuables; ``inf`` where none."""
        picked = [k for k, sl in enumerate(self.slots) if sl.dynamic == dynamic]
        if not picked:
            return torch.full((xy.shape[0],), math.inf, device=xy.device)
        centres = origins[:, None, :2] + self.xy[:, picked]
        gap = (xy[:, None] - centres).norm(dim=-1) - self.radius[picked]
        gap = torch.where(self.active[:, picked], gap, torch.full_like(gap, math.inf))
        return gap.amin(dim=1)
