"""The proof simulates: the source and the result, compiled, are stepped side by side
from their reference pose with contacts on, once with zero control and once with a
fixed pseudo-random control sequence, and their joint positions compared at every step.
The robot is simulated as the conversion writes it: alone, so geoms of the source's
world body (a floor, a table: scene, which the output does not hold) make no contact in
either model.

The per-object arrays can agree while the simulation does not: a collision mesh whose
convex hull changed, a contact parameter MuJoCo derives, an order that decides which
contact is solved first. But contacts make many robots chaotic: values that agree to
1e-15 (a mesh centre rounded) grow into visibly different motions within 200 steps.
So the source is also rolled out from a start moved by :data:`PERTURBATION` (rad or m)
in every coordinate, and the result's divergence counts only where it is above
:data:`ROLLOUT_TOL` and above :data:`CHAOS_MARGIN` times the source's own divergence
from that start, and where the source's **round-off twin** does not explain it: the
source with the result's values in every array the two hold within round-off of each
other (:func:`round_off_twin`), rolled out beside the result. A twin that moves as the
result does (within :data:`ROLLOUT_TOL`) says the output simulates as the source does
up to its last digits; a changed value, a hull of another size or objects in another
order stay the source's in the twin, so it diverges and the difference stands: one
naming the control, the step it first exceeded the tolerance, the largest difference,
the joint it is largest at and the source's own.

Run only where every joint position and actuator of the source has its counterpart in
the result (and the result has no others). A step costs in proportion to the entries of
MuJoCo's mass matrix (``MjModel.nM``: each degree of freedom with its ancestors), which a
long chain makes grow as its length squared: a model with more than
``ROLLOUT_WORK / ROLLOUT_STEPS`` entries is stepped fewer times
(:func:`rollout_steps`), so the simulation costs at most about as much as a 10,000-entry
model's 200 steps, and the proof stays linear in the robot's size. Not made
(:class:`RolloutNotMade`, which the proof reports as a note) where that leaves fewer than
:data:`MIN_ROLLOUT_STEPS` steps (a chain of about 450 joints), where the source has more
than :data:`MAX_ROLLOUT_CONTACTS` contacts at its reference pose (links that overlap at
rest: MuJoCo's arena fills, and every step costs as much as thousands of contacts), or
where MuJoCo stops stepping the source (its error, e.g. the arena too small); where it
stops the result alone, that is a difference.
"""

from __future__ import annotations

import copy

import mujoco
import numpy as np

from robotwright.proof.objects import Difference

__all__ = [
    "CHAOS_MARGIN",
    "can_roll_out",
    "MAX_ROLLOUT_CONTACTS",
    "MIN_ROLLOUT_STEPS",
    "PERTURBATION",
    "ROLLOUT_STEPS",
    "ROLLOUT_TOL",
    "ROLLOUT_WORK",
    "ROUND_OFF",
    "RolloutNotMade",
    "round_off_twin",
    "rollout_differences",
    "rollout_steps",
]

#: Steps of each rollout (at the model's own timestep), for a model whose mass matrix has
#: at most ``ROLLOUT_WORK / ROLLOUT_STEPS`` (10,000) entries: every robot arm, hand,
#: quadruped and humanoid (the 44-joint JVRC-1: 299 entries; a 100-joint chain: 4,950).
ROLLOUT_STEPS = 200
#: The simulation's budget: its steps times the entries of the source's mass matrix
#: (``MjModel.nM``), what a step's cost grows with.
ROLLOUT_WORK = 2_000_000
#: Fewest steps a rollout is made with (a mass matrix of up to 100,000 entries).
MIN_ROLLOUT_STEPS = 20
#: Largest joint position difference (m or rad) that is not a difference.
ROLLOUT_TOL = 1e-6
#: The source's own start moved by this much in every joint position (rad or m).
PERTURBATION = 1e-12
#: How many times the source's own divergence the result's must exceed to count.
CHAOS_MARGIN = 100.0
#: Contacts of the source at its reference pose above which no rollout is made (a robot
#: at rest has tens: the talos 34).
MAX_ROLLOUT_CONTACTS = 1000
#: Steps each value of the pseudo-random control is held for.
_HOLD = 10
#: Two arrays differ by round-off only where every element is within this share of
#: the array's largest magnitude (a mesh centre rounded differs by ~1e-15).
ROUND_OFF = 1e-12


class RolloutNotMade(Exception):
    """The source cannot be simulated here; the message says why."""


class _Stopped(Exception):
    """MuJoCo stopped stepping one of the models: which, at which step, and why."""

    def __init__(self, model: int, step: int, reason: str) -> None:
        super().__init__(reason)
        self.model, self.step, self.reason = model, step, reason


def round_off_twin(source: mujoco.MjModel, result: mujoco.MjModel) -> tuple[mujoco.MjModel, int]:
    """A copy of ``source`` in which each numeric array that differs from the result's
    by round-off only (:data:`ROUND_OFF`; same shape) takes the result's values, as does
    each body whose inertia tensor is the result's written in other principal axes
    (:func:`_same_inertias`), and how many arrays and bodies that was. Every other array
    stays the source's: a value changed beyond round-off, a mesh hull of another size,
    objects in another order."""
    twin = copy.copy(source)
    taken = 0
    for name in dir(source):
        if name.startswith("_"):
            continue
        a, b = getattr(source, name, None), getattr(result, name, None)
        if not isinstance(a, np.ndarray) or not isinstance(b, np.ndarray):
            continue
        if a.shape != b.shape or a.dtype.kind != "f" or not a.size or np.array_equal(a, b):
            continue
        scale = float(np.abs(a).max())
        if np.isfinite(scale) and np.all(np.abs(a - b) <= ROUND_OFF * max(scale, 1.0)):
            getattr(twin, name)[...] = b
            taken += 1
    return twin, taken + _same_inertias(twin, result)


def _same_inertias(twin: mujoco.MjModel, result: mujoco.MjModel) -> int:
    """Give ``twin`` the result's principal moments and axes of each body whose inertia
    tensor (in the body frame) is the twin's within round-off, with the body's part of
    the bounding volume tree, which MuJoCo builds in those axes: one tensor written as
    other principal axes (a fixed link merged by another route, its axes found in another
    order) is the same body. Returns how many bodies took them."""
    # The trees' leaves name geoms: taken only where each geom is on the same body in
    # both. (Per body: MuJoCo 3.11 keeps more nodes after the bodies' trees, for meshes.)
    if twin.nbody != result.nbody or not np.array_equal(twin.geom_bodyid, result.geom_bodyid):
        return 0

    def tensors(model: mujoco.MjModel) -> np.ndarray:
        rot = np.empty((model.nbody, 9))
        for b in range(model.nbody):
            mujoco.mju_quat2Mat(rot[b], model.body_iquat[b])
        rot = rot.reshape(-1, 3, 3)
        return rot @ (model.body_inertia[:, :, None] * rot.transpose(0, 2, 1))

    mine, theirs = tensors(twin), tensors(result)
    taken = 0
    for b in range(twin.nbody):
        same_tree = (twin.body_bvhadr[b], twin.body_bvhnum[b]) == (
            result.body_bvhadr[b],
            result.body_bvhnum[b],
        )
        if not same_tree or np.array_equal(twin.body_iquat[b], result.body_iquat[b]):
            continue
        scale = max(float(np.abs(mine[b]).max()), 1e-300)
        if np.abs(mine[b] - theirs[b]).max() > ROUND_OFF * scale:
            continue
        twin.body_inertia[b] = result.body_inertia[b]
        twin.body_iquat[b] = result.body_iquat[b]
        nodes = slice(twin.body_bvhadr[b], twin.body_bvhadr[b] + twin.body_bvhnum[b])
        for name in ("bvh_aabb", "bvh_child", "bvh_nodeid", "bvh_depth"):
            getattr(twin, name)[nodes] = getattr(result, name)[nodes]
        taken += 1
    return taken


def _steps(
    models: tuple[mujoco.MjModel, ...],
    ctrl: np.ndarray,
    actuators: tuple[np.ndarray, ...],
    moved: tuple[bool, ...] | None = None,
) -> list[np.ndarray]:
    """Each model stepped from its reference pose under ``ctrl`` (the source's actuator
    columns, given to each model's own actuators): its joint positions after every
    step. ``moved``: per model, whether its start is moved by :data:`PERTURBATION` in
    every joint position first."""
    datas = [mujoco.MjData(m) for m in models]
    for m, d, move in zip(models, datas, moved or (False,) * len(models), strict=True):
        if move:
            d.qpos[:] += PERTURBATION
            mujoco.mj_normalizeQuat(m, d.qpos)
    out = [np.empty((len(ctrl), m.nq)) for m in models]
    for t in range(len(ctrl)):
        for k, (m, d) in enumerate(zip(models, datas, strict=True)):
            d.ctrl[actuators[k]] = ctrl[t, actuators[0]]
            try:
                mujoco.mj_step(m, d)
            except mujoco.FatalError as exc:  # MuJoCo's own error: its first line says it
                raise _Stopped(k, t + 1, str(exc).strip().splitlines()[0]) from None
            out[k][t] = d.qpos
    return out


def _moves_alike(
    twin: mujoco.MjModel,
    result: mujoco.MjModel,
    ctrl: np.ndarray,
    actuators: tuple[np.ndarray, np.ndarray],
    coordinates: tuple[np.ndarray, np.ndarray],
) -> bool:
    """Whether the round-off twin and the result move alike (within
    :data:`ROLLOUT_TOL`) under ``ctrl``; not where MuJoCo stops either."""
    try:
        like, them = _steps((twin, result), ctrl, actuators)
    except _Stopped:
        return False
    gap = np.abs(like[:, coordinates[0]] - them[:, coordinates[1]])
    return gap.max(initial=0.0) <= ROLLOUT_TOL


def _largest_gaps(gap: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per step of ``gap`` (steps x coordinates): its largest value and that value's
    coordinate (a step whose largest is not a number counts as ``-inf``)."""
    if not gap.size:
        return np.full(len(gap), -np.inf), np.zeros(len(gap), dtype=int)
    column = gap.argmax(axis=1)
    per_step = gap[np.arange(len(gap)), column]
    return np.where(np.isnan(per_step), -np.inf, per_step), column


def _controls(model: mujoco.MjModel, steps: int) -> np.ndarray:
    """A fixed pseudo-random control sequence: per actuator a value drawn inside its
    control range (``[-1, 1]`` without one), held :data:`_HOLD` steps."""
    rng = np.random.default_rng(0)
    lo = np.where(model.actuator_ctrllimited, model.actuator_ctrlrange[:, 0], -1.0)
    hi = np.where(model.actuator_ctrllimited, model.actuator_ctrlrange[:, 1], 1.0)
    held = rng.uniform(lo, hi, size=(steps // _HOLD + 1, model.nu))
    return np.repeat(held, _HOLD, axis=0)[:steps]


def _robot_alone(model: mujoco.MjModel) -> mujoco.MjModel:
    """A copy of ``model`` whose world body's geoms collide with nothing."""
    alone = copy.copy(model)  # MuJoCo's copy of every array
    world = alone.geom_bodyid == 0
    alone.geom_contype[world] = 0
    alone.geom_conaffinity[world] = 0
    return alone


def _simulation_difference(what: str, steps: int, result: str) -> Difference:
    """One difference of the rollout under control ``what``: ``result`` says how the
    output moved against the source's joint positions."""
    return Difference(
        f"simulation, {what}, {steps} steps",
        "model",
        "the robot",
        "the source's joint positions",
        result,
        (),
    )


def _joint_at(model: mujoco.MjModel, qpos_index: int) -> str:
    j = int(np.searchsorted(model.jnt_qposadr, qpos_index, side="right")) - 1
    return mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) or f"joint #{j}"


def can_roll_out(
    source: mujoco.MjModel,
    result: mujoco.MjModel,
    qpos_map: dict[int, int],
    actuator_map: dict[int, int],
) -> bool:
    """Whether the two models can be simulated side by side: every joint position and
    actuator of the source matched in the result (which has no others)."""
    return (
        source.nq == result.nq == len(qpos_map)
        and source.nu == result.nu == len(actuator_map)
        and all(r >= 0 for r in actuator_map.values())
    )


def rollout_steps(source: mujoco.MjModel) -> int:
    """Steps of each rollout of ``source``: :data:`ROLLOUT_STEPS`, fewer where its mass
    matrix has more than ``ROLLOUT_WORK / ROLLOUT_STEPS`` entries (a long chain).

    Raises:
        RolloutNotMade: that would be fewer than :data:`MIN_ROLLOUT_STEPS`.
    """
    steps = min(ROLLOUT_STEPS, ROLLOUT_WORK // max(source.nM, 1))
    if steps < MIN_ROLLOUT_STEPS:
        raise RolloutNotMade(
            f"its mass matrix has {source.nM:,} entries (each degree of freedom with those "
            f"it hangs from: long chains of joints; more than "
            f"{ROLLOUT_WORK // MIN_ROLLOUT_STEPS:,}): each step costs too much to simulate"
        )
    return steps


def rollout_differences(
    source: mujoco.MjModel,
    result: mujoco.MjModel,
    qpos_map: dict[int, int],
    actuator_map: dict[int, int],
    steps: int | None = None,
) -> list[Difference]:
    """The rollouts of ``source`` and ``result`` compared (see the module docstring).
    ``qpos_map``: source joint position index -> the result's; ``actuator_map``: source
    actuator -> the result's; ``steps``: of each rollout (default :func:`rollout_steps`).
    Empty when they agree or cannot be compared (:func:`can_roll_out`).

    Raises:
        RolloutNotMade: the source's mass matrix is too large to step
            :data:`MIN_ROLLOUT_STEPS` times within :data:`ROLLOUT_WORK`, it has more than
            :data:`MAX_ROLLOUT_CONTACTS` contacts at its reference pose, or MuJoCo stops
            stepping it.
    """
    if not can_roll_out(source, result, qpos_map, actuator_map):
        return []
    if steps is None:
        steps = rollout_steps(source)
    src_q = np.fromiter(qpos_map.keys(), dtype=int)
    res_q = np.fromiter(qpos_map.values(), dtype=int)
    src_u = np.fromiter(actuator_map.keys(), dtype=int)
    res_u = np.fromiter(actuator_map.values(), dtype=int)
    source, result = _robot_alone(source), _robot_alone(result)
    start = mujoco.MjData(source)
    try:  # the contacts alone: the solver on thousands of them costs seconds
        mujoco.mj_kinematics(source, start)
        mujoco.mj_collision(source, start)
    except mujoco.FatalError as exc:  # its arena cannot hold them
        raise RolloutNotMade(
            "MuJoCo cannot hold the source's contacts at its reference pose (links that "
            f"overlap at rest collide): {str(exc).strip().splitlines()[0]}"
        ) from None
    # MuJoCo 3.x keeps no contact when its arena is full (ncon 0, and a warning)
    full = bool(start.warning[mujoco.mjtWarning.mjWARN_CONTACTFULL].number)
    if full or start.ncon > MAX_ROLLOUT_CONTACTS:
        many = (
            "more contacts at its reference pose than MuJoCo's arena holds"
            + (f" ({start.ncon} contacts held)" if start.ncon else "")
            if full
            else f"{start.ncon} contacts at its reference pose (more than {MAX_ROLLOUT_CONTACTS})"
        )
        raise RolloutNotMade(
            f"the source has {many}: links that overlap at rest collide; exclude those "
            "contacts in the source to have it simulated"
        )
    zero = np.zeros((steps, source.nu))
    twin: tuple[mujoco.MjModel, int] | None = None
    out = []
    for what, ctrl in (("zero control", zero), ("pseudo-random control", _controls(source, steps))):
        try:
            mine, theirs, moved = _steps(
                (source, result, source), ctrl, (src_u, res_u, src_u), (False, False, True)
            )
        except _Stopped as stop:
            if stop.model != 1:
                raise RolloutNotMade(
                    f"MuJoCo stops stepping the source at step {stop.step} ({what}): {stop.reason}"
                ) from None
            out.append(
                _simulation_difference(
                    what,
                    steps,
                    f"MuJoCo stops stepping the output at step {stop.step}, where the "
                    f"source steps on: {stop.reason}",
                )
            )
            continue
        per_step, column = _largest_gaps(np.abs(mine[:, src_q] - theirs[:, res_q]))
        t = int(per_step.argmax())  # the first step reaching the largest
        worst = max(float(per_step[t]), 0.0)
        where = int(src_q[column[t]]) if len(src_q) else 0
        over = np.flatnonzero(per_step > ROLLOUT_TOL)
        first = int(over[0]) + 1 if len(over) else -1
        own_steps = np.abs(mine - moved).max(axis=1, initial=0.0)
        own = float(np.max(own_steps[~np.isnan(own_steps)], initial=0.0))
        if worst > ROLLOUT_TOL and worst > CHAOS_MARGIN * own:
            # The source with the result's values wherever the two differ by round-off
            # only: where it moves as the result does, the divergence is the model's
            # sensitivity to its last digits, not a change the conversion made.
            twin = twin or round_off_twin(source, result)
            if twin[1] and _moves_alike(twin[0], result, ctrl, (src_u, res_u), (src_q, res_q)):
                continue
            out.append(
                _simulation_difference(
                    what,
                    steps,
                    f"joint positions differing from step {first} on, by up to {worst:.3g} "
                    f"(joint '{_joint_at(source, where)}'; the source itself moves by "
                    f"{own:.3g} from a start {PERTURBATION:g} away)",
                )
            )
    return out
