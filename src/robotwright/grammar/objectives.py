"""Objectives and constraints for design search, evaluated on built limbs.

An objective maps an :class:`EvalContext` to a number and says whether larger is
better; a constraint returns ``None`` when satisfied or a message naming the
violation. Both are small frozen dataclasses, so they pickle into worker processes.
Units: metres, cubic metres, kilograms, radians, watts. The physics objectives
(``payload``, ``track``, ``energy``) and ``no-carrier-collision`` evaluate the limb
worn by its carrier (:mod:`robotwright.grammar.physics`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, Protocol, runtime_checkable

import mujoco
import numpy as np

from robotwright.grammar.context import EvalContext
from robotwright.grammar.design import Design
from robotwright.grammar.physics import (
    MIN_FREE_SHARE,
    PAYLOAD_MIN_REACH,
    TRACK_CENTER,
    TRACK_RADIUS,
    Carrier,
    TrackResult,
    carrier_collisions,
    check_settings,
    payload,
    sample_poses,
)
from robotwright.grammar.rules import Grammar


@runtime_checkable
class Objective(Protocol):
    name: str
    maximize: bool

    def __call__(self, ctx: EvalContext) -> float: ...


@runtime_checkable
class Constraint(Protocol):
    name: str

    def __call__(self, ctx: EvalContext) -> str | None: ...


@dataclass(frozen=True)
class Reach:
    """Largest distance (m) of a tool point from the mount origin over sampled poses
    (the zero pose and ``samples`` seeded ones) that the limb can take: with
    ``free_only``, a pose where it touches itself (MuJoCo contacts) or two of its parts
    overlap (:mod:`robotwright.grammar.overlap`), or touches ``carrier`` when one is
    given, does not count; 0 when none is free."""

    samples: int = 256
    seed: int = 0
    free_only: bool = True
    #: Worn by this carrier (a task file's): a pose that touches it does not count
    #: either. ``None``: the limb alone (the built-in task).
    carrier: Carrier | None = None
    name: str = "reach"
    maximize: bool = True

    def __call__(self, ctx: EvalContext) -> float:
        pts = ctx.tool_points(self.samples, self.seed)
        if not len(pts):
            return 0.0
        dist = np.linalg.norm(pts, axis=1)
        if not self.free_only:
            return float(dist.max())
        # The farthest first: usually the first pose checked is free.
        for k in np.argsort(-dist, kind="stable"):
            pose = ctx.pose_of_point(int(k), self.samples)
            if ctx.pose_is_free(pose, self.samples, self.seed, self.carrier):
                return float(dist[k])
        return 0.0


@dataclass(frozen=True)
class WorkspaceVolume:
    """Workspace volume (m^3) from sampled tool points.

    ``method="hull"`` (default): volume of their convex hull, computed by MuJoCo's mesh
    code (qhull); 0 when the points are coplanar (a planar arm). ``method="voxel"``:
    number of voxels of edge ``voxel`` m that the points hit times the voxel volume, a
    lower bound that saturates at ``samples`` voxels.
    """

    samples: int = 2048
    voxel: float = 0.02
    method: str = "hull"
    seed: int = 0
    name: str = "workspace"
    maximize: bool = True

    def __post_init__(self) -> None:
        if self.voxel <= 0 or self.samples < 1:
            raise ValueError("WorkspaceVolume: voxel must be > 0 m and samples >= 1")
        if self.method not in ("hull", "voxel"):
            raise ValueError(
                f"WorkspaceVolume: method must be 'hull' or 'voxel', got {self.method!r}"
            )

    def __call__(self, ctx: EvalContext) -> float:
        pts = ctx.tool_points(self.samples, self.seed)
        if self.method == "voxel":
            cells = np.unique(np.floor(pts / self.voxel).astype(np.int64), axis=0)
            return float(len(cells) * self.voxel**3)
        return hull_volume(pts)


def _point(owner: object, field_name: str) -> tuple[float, float, float]:
    """``owner``'s ``field_name``, a point [m], checked: 3 finite numbers within +-10 m,
    returned as a tuple (a list from Python or tyro is kept hashable)."""
    value = getattr(owner, field_name)
    if len(value) != 3 or not all(isinstance(v, (int, float)) and abs(v) <= 10.0 for v in value):
        raise ValueError(
            f"{type(owner).__name__}: {field_name} expected 3 finite numbers [m] within "
            f"+-10, got {value!r}"
        )
    return tuple(float(v) for v in value)  # type: ignore[return-value]


#: The built-in workspace to cover (mount frame, m): a 0.4 m cube about the tracking
#: target's centre, in 5 cm cells.
COVERAGE_LOW: tuple[float, float, float] = (0.2, -0.2, 0.2)
COVERAGE_HIGH: tuple[float, float, float] = (0.6, 0.2, 0.6)


@dataclass(frozen=True)
class Coverage:
    """Share (0-1) of a given box the tool points reach: the box from ``low`` to
    ``high`` (m, mount frame) is cut into cubes of edge ``voxel`` m, and a cube counts
    when a tool point lands in it at one of ``samples`` seeded poses the limb can take
    (no contact with itself, no overlapping parts, and none with ``carrier`` when
    given). An absolute target: the same box for every design, where a workspace volume
    rewards reaching anywhere."""

    low: tuple[float, float, float] = COVERAGE_LOW
    high: tuple[float, float, float] = COVERAGE_HIGH
    voxel: float = 0.05
    samples: int = 1024
    seed: int = 0
    carrier: Carrier | None = None
    name: str = "coverage"
    maximize: bool = True

    def __post_init__(self) -> None:
        check_settings("Coverage", samples=self.samples, seed=self.seed, voxel=self.voxel)
        for which in ("low", "high"):
            object.__setattr__(self, which, _point(self, which))
        cells = self._cells()
        if not (cells >= 1).all() or cells.prod() > MAX_COVERAGE_CELLS:
            raise ValueError(
                f"Coverage: high must exceed low on every axis, in at most "
                f"{MAX_COVERAGE_CELLS} cells of {self.voxel} m; got {self.low} to {self.high}"
            )

    def _cells(self) -> np.ndarray:
        """Cells of the box along x, y and z."""
        span = np.array(self.high) - np.array(self.low)
        return np.ceil(span / self.voxel - 1e-9).astype(np.int64)

    def __call__(self, ctx: EvalContext) -> float:
        low, high = np.array(self.low), np.array(self.high)
        shape = self._cells()
        pts = ctx.tool_points(self.samples, self.seed)
        if not len(pts):
            return 0.0
        inside = np.all((pts >= low) & (pts < high), axis=1)
        hit: set[tuple[int, ...]] = set()
        for k in np.flatnonzero(inside):
            cell = tuple(np.minimum(((pts[k] - low) // self.voxel).astype(np.int64), shape - 1))
            if cell in hit:
                continue
            pose = ctx.pose_of_point(int(k), self.samples)
            if ctx.pose_is_free(pose, self.samples, self.seed, self.carrier):
                hit.add(cell)
        return len(hit) / float(shape.prod())


#: Most cells a coverage box may have (each costs memory and a pose check at most).
MAX_COVERAGE_CELLS = 1_000_000


def hull_volume(points: np.ndarray) -> float:
    """Convex hull volume (m^3) of ``points`` (N, 3): MuJoCo builds the hull of a mesh
    with these vertices and, at density 1, its mass is the hull's volume."""
    pts = np.unique(np.round(np.asarray(points, dtype=float), 9), axis=0)
    if len(pts) < 4:
        return 0.0
    # Points on a plane or a line span no volume (and qhull rejects them).
    sv = np.linalg.svd(pts - pts.mean(axis=0), compute_uv=False)
    if sv[2] <= 1e-9 * max(sv[0], 1e-300):
        return 0.0
    spec = mujoco.MjSpec()
    mesh = spec.add_mesh(name="workspace", uservert=pts.ravel().tolist())
    mesh.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_CONVEX
    body = spec.worldbody.add_body(name="hull")
    body.add_freejoint()
    body.add_geom(type=mujoco.mjtGeom.mjGEOM_MESH, meshname="workspace", density=1.0)
    try:
        model = spec.compile()
    except ValueError as exc:
        # Coplanar or collinear points span no volume; anything else is a real error.
        if any(w in str(exc) for w in ("coplanar", "collinear", "volume")):
            return 0.0
        raise
    return float(model.body_mass[1])


@dataclass(frozen=True)
class Mass:
    """Total limb mass (kg), from MuJoCo's inertia computation; smaller is better."""

    name: str = "mass"
    maximize: bool = False

    def __call__(self, ctx: EvalContext) -> float:
        return float(ctx.model.body_mass.sum())


@dataclass(frozen=True)
class DoFCount:
    """Number of joint DoFs; larger is better unless ``maximize=False``."""

    name: str = "dof"
    maximize: bool = True

    def __call__(self, ctx: EvalContext) -> float:
        return float(ctx.limb.dof)


@dataclass(frozen=True)
class MaxMass:
    limit: float
    name: str = "max-mass"

    def __call__(self, ctx: EvalContext) -> str | None:
        m = float(ctx.model.body_mass.sum())
        return None if m <= self.limit else f"mass {m:.3f} kg > {self.limit} kg"


@dataclass(frozen=True)
class DoFRange:
    low: int = 0
    high: int = 1_000_000
    name: str = "dof-range"

    def __call__(self, ctx: EvalContext) -> str | None:
        n = ctx.limb.dof
        return None if self.low <= n <= self.high else f"{n} DoF outside [{self.low}, {self.high}]"


@dataclass(frozen=True)
class JointLimitsFeasible:
    """Every joint range is non-empty and contains the zero pose."""

    name: str = "joint-limits"

    def __call__(self, ctx: EvalContext) -> str | None:
        bad = [
            j.name
            for j in ctx.limb.joints
            if not (j.range[0] < j.range[1] and j.range[0] <= 0.0 <= j.range[1])
        ]
        return None if not bad else f"joint ranges empty or excluding 0: {bad}"


@dataclass(frozen=True)
class NoSelfCollision:
    """No contact between limb geoms at the zero pose (MuJoCo collision detection;
    parent-child body pairs are excluded, as MuJoCo does by default)."""

    name: str = "no-self-collision"

    def __call__(self, ctx: EvalContext) -> str | None:
        model = ctx.model
        data = mujoco.MjData(model)
        mujoco.mj_forward(model, data)
        if data.ncon == 0:
            return None
        pairs = sorted(
            {
                tuple(sorted((model.geom(int(c.geom1)).name, model.geom(int(c.geom2)).name)))
                for c in data.contact[: data.ncon]
            }
        )
        return f"self-collision at zero pose: {pairs}"


@dataclass(frozen=True)
class Payload:
    """Largest mass (kg) at every tool point that the limb, worn by ``carrier``, holds
    still at the zero pose and ``samples`` seeded random poses with every joint torque
    within its peak, counting the poses with the tool points at least ``min_reach`` m
    from the mount (:func:`robotwright.grammar.physics.payload`); larger is better.
    Every pose counts: with fewer than ``min_free_share`` of them free of contact with
    the limb itself or the carrier, the payload is 0; it is at most ``limit`` kg, a
    bound the command line names when a design reaches it."""

    samples: int = 32
    seed: int = 0
    carrier: Carrier = Carrier()
    limit: float = 100.0
    min_free_share: float = MIN_FREE_SHARE
    #: Only poses with every tool point at least this far (m) from the mount count.
    min_reach: float = PAYLOAD_MIN_REACH
    name: str = "payload"
    maximize: bool = True

    def __post_init__(self) -> None:
        check_settings(
            "Payload",
            samples=self.samples,
            seed=self.seed,
            limit=self.limit,
            min_free_share=self.min_free_share,
            min_reach=self.min_reach,
        )

    def __call__(self, ctx: EvalContext) -> float:
        m = ctx.mounted(self.carrier)
        return payload(
            ctx.limb,
            self.carrier,
            samples=self.samples,
            seed=self.seed,
            limit=self.limit,
            min_free_share=self.min_free_share,
            mounted=m,
            min_reach=self.min_reach,
        ).mass


@dataclass(frozen=True)
class _TrackingRun:
    """The settings of one tracking run (:func:`robotwright.grammar.physics.track`),
    which :class:`Track` and :class:`Energy` both measure."""

    duration: float = 2.0
    scale: float = 0.15
    carrier: Carrier = Carrier()
    #: Waypoints [m] (offsets from ``center``) to follow instead of the circle and line.
    path: tuple[tuple[float, float, float], ...] | None = None
    #: The reference's centre [m] in the mount frame (the limb's base); ``None``: the
    #: tool point at the design's display pose.
    center: tuple[float, float, float] | None = TRACK_CENTER
    #: The circle's radius [m]; ``None``: ``scale`` times the design's reach.
    radius: float | None = TRACK_RADIUS

    def __post_init__(self) -> None:
        check_settings(type(self).__name__, duration=self.duration, scale=self.scale)
        if self.radius is not None:
            check_settings(type(self).__name__, radius=self.radius)
        if self.center is not None:
            object.__setattr__(self, "center", _point(self, "center"))

    def run(self, ctx: EvalContext) -> TrackResult:
        """The tracking run these settings ask for, made once per design in ``ctx``."""
        return ctx.tracking(
            self.carrier, self.duration, self.scale, self.path, self.center, self.radius
        )


@dataclass(frozen=True)
class Track(_TrackingRun):
    """RMS distance (m) between the first tool point and a circle-then-line reference
    (built in: 5 cm radius about (0.4, 0, 0.4) m in the mount frame, the same for
    every design) over ``duration`` s, under PD + gravity compensation within the peak
    torques and the rated speeds, contacts on
    (:func:`robotwright.grammar.physics.track`); smaller is better."""

    name: str = "track"
    maximize: bool = False

    def __call__(self, ctx: EvalContext) -> float:
        return self.run(ctx).error


@dataclass(frozen=True)
class Energy(_TrackingRun):
    """Mean mechanical power (W), ``sum |tau_i dq_i|`` averaged over the steps of the
    same run as :class:`Track`; smaller is better."""

    name: str = "energy"
    maximize: bool = False

    def __call__(self, ctx: EvalContext) -> float:
        return self.run(ctx).power


@dataclass(frozen=True)
class NoCarrierCollision:
    """The limb touches no geom of its carrier at the zero pose and ``samples`` seeded
    random poses (MuJoCo collision detection on the mounted model)."""

    samples: int = 32
    seed: int = 0
    carrier: Carrier = Carrier()
    name: str = "no-carrier-collision"

    def __post_init__(self) -> None:
        check_settings("NoCarrierCollision", samples=self.samples, seed=self.seed)

    def __call__(self, ctx: EvalContext) -> str | None:
        m = ctx.mounted(self.carrier)
        hits = carrier_collisions(m, sample_poses(m, self.samples, self.seed))
        if not hits:
            return None
        k, a, b = hits[0]
        poses = len({h[0] for h in hits})
        return f"touches the carrier at {poses} of {self.samples + 1} poses (first: pose {k}, {a} and {b})"


@dataclass(frozen=True)
class NoContactOnTrack(_TrackingRun):
    """The limb touches neither itself nor its carrier at any step of the tracking run
    (the run of :class:`Track` and :class:`Energy`, simulated with contacts on), and no
    two of its parts overlap there, parent and child included (the geometric check of
    :class:`NoOverlap`, at every step): collisions checked along the whole trajectory,
    not at sampled poses alone."""

    name: str = "no-contact-on-track"

    def __call__(self, ctx: EvalContext) -> str | None:
        run = self.run(ctx)
        found = []
        if run.first_contact is not None:
            t, a, b = run.first_contact
            found.append(
                f"touches on {run.contact_share:.1%} of the tracking run's steps "
                f"(first at {t:.3f} s: {a} and {b})"
            )
        if run.first_overlap is not None:
            t, a, b, depth = run.first_overlap
            found.append(f"{a} and {b} overlap by {depth * 1e3:.1f} mm at {t:.3f} s")
        return "; ".join(found) or None


@dataclass(frozen=True)
class WithinRatings(_TrackingRun):
    """No joint moves faster than its rated speed (the component's ``peak_velocity``)
    at any step of the tracking run; torques are held within their peaks by MuJoCo."""

    name: str = "within-ratings"

    def __call__(self, ctx: EvalContext) -> str | None:
        ratio = self.run(ctx).speed_ratio
        if ratio <= 1.0:
            return None
        return f"a joint reaches {ratio:.2f}x its rated speed on the tracking run"


@dataclass(frozen=True)
class TracksWithin(_TrackingRun):
    """The tracking run's RMS error is at most ``limit`` m: the limb does the job whose
    power :class:`Energy` measures (a limb that cannot follow the path, or stays
    still, spends next to nothing)."""

    limit: float = 0.01
    name: str = "max-track-error"

    def __post_init__(self) -> None:
        super().__post_init__()
        check_settings("TracksWithin", max_track_error=self.limit)

    def __call__(self, ctx: EvalContext) -> str | None:
        error = self.run(ctx).error
        if error <= self.limit:
            return None
        return f"tracking error {error:.4g} m > {self.limit:g} m: it does not follow the path"


@dataclass(frozen=True)
class NoOverlap:
    """No two parts of the limb overlap at the zero pose and ``samples`` seeded poses,
    parent and child included: a geometric check of every housing, link and end part
    that MuJoCo's contact filter does not hide (:mod:`robotwright.grammar.overlap`)."""

    samples: int = 32
    seed: int = 0
    name: str = "no-overlap"

    def __post_init__(self) -> None:
        check_settings("NoOverlap", samples=self.samples, seed=self.seed)

    def __call__(self, ctx: EvalContext) -> str | None:
        found = ctx.overlap_check.over(ctx.poses(self.samples, self.seed))
        if not found:
            return None
        deepest = max(found, key=lambda o: o.depth)
        poses = len({o.pose for o in found})
        return (
            f"parts overlap at {poses} of {self.samples + 1} poses (deepest: {deepest.a} "
            f"and {deepest.b} by {deepest.depth * 1e3:.1f} mm at pose {deepest.pose})"
        )


@dataclass(frozen=True)
class WorstPosture:
    """One objective measured with the carrier in several postures (``parts``, one per
    posture, named by ``postures``): the worst posture's value (the smallest when larger
    is better, else the largest). NaN in any posture is the result."""

    parts: tuple[Objective, ...]
    postures: tuple[str, ...]

    def __post_init__(self) -> None:
        names = {p.name for p in self.parts}
        if not self.parts or len(names) != 1 or len(self.postures) != len(self.parts):
            raise ValueError(
                "WorstPosture: expected one objective of one name per posture, got "
                f"{len(self.parts)} objective(s) ({sorted(names)}) for "
                f"{len(self.postures)} posture(s)"
            )

    @property
    def name(self) -> str:
        return self.parts[0].name

    @property
    def maximize(self) -> bool:
        return self.parts[0].maximize

    @property
    def limit(self) -> float | None:
        """The objective's own bound (``payload``'s ``limit``), if it has one."""
        return getattr(self.parts[0], "limit", None)

    def __call__(self, ctx: EvalContext) -> float:
        values = [ctx.value(p) for p in self.parts]
        if any(math.isnan(v) for v in values):
            return math.nan
        return min(values) if self.maximize else max(values)

    def by_posture(self, ctx: EvalContext) -> dict[str, float]:
        """The value in each posture, by posture name."""
        return {n: ctx.value(p) for n, p in zip(self.postures, self.parts)}


@dataclass(frozen=True)
class InEveryPosture:
    """One constraint that must hold with the carrier in each of several postures
    (``parts``, one per posture, named by ``postures``); the message names the first
    posture where it does not."""

    parts: tuple[Constraint, ...]
    postures: tuple[str, ...]

    def __post_init__(self) -> None:
        if not self.parts or len(self.postures) != len(self.parts):
            raise ValueError(
                f"InEveryPosture: expected one constraint per posture, got {len(self.parts)} "
                f"for {len(self.postures)} posture(s)"
            )

    @property
    def name(self) -> str:
        return self.parts[0].name

    def __call__(self, ctx: EvalContext) -> str | None:
        for posture, part in zip(self.postures, self.parts):
            message = part(ctx)
            if message is not None:
                return f"posture {posture!r}: {message}"
        return None


def signed(objective: Objective, value: float) -> float:
    """``value`` oriented so that larger is better (negated for a minimised objective)."""
    return value if objective.maximize else -value


@dataclass(frozen=True)
class WeightedSum:
    """Several objectives as one score: ``sum(w_i * v_i)``, each value oriented so that
    larger is better (a minimised objective's value enters negated). Units differ
    between objectives (m, kg, W, ...): the weights carry the exchange rate, e.g.
    ``payload`` and ``mass`` with weights 1, 2 trade 2 kg of payload for 1 kg of limb."""

    parts: tuple[Objective, ...]
    weights: tuple[float, ...]
    name: str = "weighted-sum"
    maximize: bool = True

    def __post_init__(self) -> None:
        if len(self.parts) < 2 or len(self.parts) != len(self.weights):
            raise ValueError(
                f"weighted sum: expected one weight per objective and at least two objectives, "
                f"got {len(self.weights)} weight(s) for {len(self.parts)}"
            )
        if not all(isinstance(w, (int, float)) and math.isfinite(w) for w in self.weights):
            raise ValueError(f"weighted sum: weights must be finite numbers, got {self.weights}")

    def __call__(self, ctx: EvalContext) -> float:
        return sum(w * signed(o, ctx.value(o)) for o, w in zip(self.parts, self.weights))


def dominates(a: Evaluation, b: Evaluation, objectives: Sequence[Objective]) -> bool:
    """``a`` is at least as good as ``b`` in every objective and better in one."""
    better = False
    for o in objectives:
        x, y = signed(o, a.values[o.name]), signed(o, b.values[o.name])
        if x < y:
            return False
        better |= x > y
    return better


def pareto_front(
    evaluations: Sequence[Evaluation], objectives: Sequence[Objective]
) -> list[Evaluation]:
    """The feasible evaluations no other feasible one dominates (first objective's best
    first; of designs with equal values, the first evaluated)."""
    feasible = [e for e in evaluations if e.feasible]
    front: list[Evaluation] = []
    seen: set[tuple[float, ...]] = set()
    for e in feasible:
        key = tuple(e.values[o.name] for o in objectives)
        if key in seen or any(dominates(f, e, objectives) for f in feasible):
            continue
        seen.add(key)
        front.append(e)
    first = objectives[0]
    return sorted(front, key=lambda e: -signed(first, e.values[first.name]))


OBJECTIVES: dict[str, type] = {
    "reach": Reach,
    "workspace": WorkspaceVolume,
    "coverage": Coverage,
    "mass": Mass,
    "dof": DoFCount,
    "payload": Payload,
    "track": Track,
    "energy": Energy,
}


_FLAGS = {
    "no-self-collision": NoSelfCollision,
    "no-overlap": NoOverlap,
    "no-carrier-collision": NoCarrierCollision,
    "no-contact-on-track": NoContactOnTrack,
    "within-ratings": WithinRatings,
    "joint-limits": JointLimitsFeasible,
}
#: The constraints measured on the tracking run (set by a task's ``track`` section).
TRACK_CONSTRAINTS = ("no-contact-on-track", "within-ratings", "max-track-error")
_EXPECTED = (
    "no-self-collision, no-overlap, no-carrier-collision, no-contact-on-track, "
    "within-ratings, joint-limits, max-mass=KG, max-track-error=M, max-dof=N or min-dof=N"
)


def make_constraint(text: str) -> Constraint:
    """Parse ``no-self-collision``, ``no-overlap``, ``no-carrier-collision``,
    ``no-contact-on-track``, ``within-ratings``, ``joint-limits``, ``max-track-error=M``
    (m, a finite number >= 0),
    ``max-mass=KG`` (a finite number >= 0), ``max-dof=N``, ``min-dof=N`` (integers >= 0).

    Raises:
        ValueError: an unknown name, a value where none is taken, or a bad number.
    """
    name, eq, value = text.partition("=")
    if name in _FLAGS:
        if eq:
            raise ValueError(f"constraint {text!r}: {name} takes no value")
        return _FLAGS[name]()
    if name not in _VALUED:
        raise ValueError(f"unknown constraint {text!r}: expected {_EXPECTED}")
    kind, expected, example, make = _VALUED[name]
    try:
        number = kind(value)
    except ValueError:
        number = None
    if number is None or not math.isfinite(number) or number < 0:
        raise ValueError(f"constraint {text!r}: {name} needs a {expected}, e.g. {name}={example}")
    return make(number)


#: The constraints that take a value: its type, what it must be, an example, the
#: constraint made of it.
_VALUED: dict[str, tuple[type, str, str, Callable[[Any], Constraint]]] = {
    "max-mass": (float, "finite number >= 0 (kg)", "2", MaxMass),
    "max-track-error": (float, "finite number >= 0 (m)", "0.01", lambda v: TracksWithin(limit=v)),
    "max-dof": (int, "whole number >= 0", "2", lambda v: DoFRange(high=v)),
    "min-dof": (int, "whole number >= 0", "2", lambda v: DoFRange(low=v)),
}


@dataclass(frozen=True)
class Evaluation:
    """Result of evaluating one design: objective values, violations, the score (the
    first objective, negated when minimised; ``-inf`` when infeasible) and the
    tie-break (the second objective, oriented alike; 0 when there is none), which
    orders designs of equal score (two limbs both at a physical bound)."""

    design: Design
    values: dict[str, float] = field(default_factory=dict)
    violations: tuple[str, ...] = ()
    score: float = float("-inf")
    tiebreak: float = 0.0

    @property
    def feasible(self) -> bool:
        return not self.violations

    @property
    def rank_key(self) -> tuple[float, float]:
        """What orders designs, larger first: (score, tie-break)."""
        return (self.score, self.tiebreak)


def best_of(evaluations: Sequence[Evaluation]) -> Evaluation | None:
    """The best feasible evaluation by score, then tie-break (the first evaluated of
    equals); ``None`` when none is feasible."""
    feasible = [e for e in evaluations if e.feasible]
    return max(feasible, key=lambda e: e.rank_key) if feasible else None


def scored(
    design: Design,
    values: dict[str, float],
    violations: tuple[str, ...],
    objectives: Sequence[Objective],
) -> Evaluation:
    """An :class:`Evaluation` with its score and tie-break from ``values``."""
    first = objectives[0]
    score = signed(first, values[first.name]) if not violations else float("-inf")
    tie = signed(objectives[1], values[objectives[1].name]) if len(objectives) > 1 else 0.0
    return Evaluation(design, values, violations, score, tie)


def evaluate(
    grammar: Grammar,
    design: Design,
    objectives: tuple[Objective, ...],
    constraints: tuple[Constraint, ...] = (),
) -> Evaluation:
    """Evaluate a design: every objective and constraint on one shared context. The
    first objective scores it, the second breaks ties (see :class:`Evaluation`)."""
    ctx = EvalContext(grammar, design)
    values = {o.name: ctx.value(o) for o in objectives}
    violations = tuple(v for c in constraints if (v := c(ctx)) is not None)
    return scored(design, values, violations, objectives)
