"""Evaluations a designer would sign: contacts along the whole trajectory, rated speeds,
absolute targets and overlapping parts that MuJoCo's contact filter hides."""

from __future__ import annotations

import json

import mujoco
import numpy as np
import pytest

from robotwright.grammar import default_grammar
from robotwright.grammar import physics as P
from robotwright.grammar.build import build
from robotwright.grammar.design import Design
from robotwright.grammar.objectives import (
    EvalContext,
    NoCarrierCollision,
    NoContactOnTrack,
    NoOverlap,
    NoSelfCollision,
    Payload,
    Reach,
    Track,
    WithinRatings,
    make_constraint,
)
from robotwright.grammar.overlap import overlaps

from .test_grammar_physics import TRACKER

HEADER = "# robotwright-design/1 grammar=srl\n"

#: Free of the carrier at the 33 sampled poses, yet its link sweeps through the head
#: while it follows the built-in circle.
THROUGH_THE_HEAD = (
    HEADER
    + """r1 @0: B=base(diameter=0.12, thickness=0.04) P=pinned()
r2 @0: C=prismatic(stroke=0.1) L=link(diameter=0.04, length=0.25, rotation=1.5708)
r3 @3: C=universal(limit=1.5708) L=link(diameter=0.04, length=0.25, rotation=1.5708)
r3 @5: C=revolute(limit=1.5708) L=link(diameter=0.04, length=0.25, rotation=0.0)
r4 @7: E=tool(length=0.08)
"""
)

#: Touches nothing on the circle, but a joint outruns its rating there.
TOO_FAST = (
    HEADER
    + """r1 @0: B=base(diameter=0.12, thickness=0.02) P=pinned()
r2 @0: C=revolute(limit=2.618) L=link(diameter=0.04, length=0.25, rotation=1.5708)
r3 @3: C=prismatic(stroke=0.1) L=link(diameter=0.04, length=0.15, rotation=-1.5708)
r3 @5: C=universal(limit=1.5708) L=link(diameter=0.04, length=0.25, rotation=-1.5708)
r4 @7: E=tool(length=0.08)
"""
)

#: Two revolute joints 2 cm apart: their 5 cm housings overlap, on a body and its parent.
CROWDED = (
    HEADER
    + """r1 @0: B=base(diameter=0.12, thickness=0.02) P=pinned()
r2 @0: C=revolute(limit=1.5708) L=link(diameter=0.04, length=0.02, rotation=0.0)
r3 @3: C=revolute(limit=1.5708) L=link(diameter=0.04, length=0.25, rotation=0.0)
r4 @5: E=tool(length=0.08)
"""
)

#: Its farthest sampled poses fold it into itself (a universal's housing through its base).
FOLDS = (
    HEADER
    + """r1 @0: B=base(diameter=0.08, thickness=0.04) P=pinned()
r2 @0: C=universal(limit=1.5708) L=link(diameter=0.04, length=0.15, rotation=1.5708)
r3 @3: C=revolute(limit=2.618) L=link(diameter=0.04, length=0.15, rotation=1.5708)
r3 @5: C=universal(limit=1.5708) L=link(diameter=0.04, length=0.15, rotation=1.5708)
r4 @7: E=gripper(finger_length=0.06)
"""
)

#: One joint and a 2 cm link: the bracket the issue's relative targets rewarded.
BRACKET = (
    HEADER
    + """r1 @0: B=base(diameter=0.08, thickness=0.02) P=pinned()
r2 @0: C=revolute(limit=1.5708) L=link(diameter=0.04, length=0.02, rotation=0.0)
r4 @3: E=tool(length=0.01)
"""
)


@pytest.fixture(scope="module")
def grammar():
    return default_grammar()


def ctx_of(grammar, text: str) -> EvalContext:
    return EvalContext(grammar, Design.from_text(text))


def test_a_path_through_the_carrier_is_refused_though_every_sampled_pose_is_free(grammar):
    ctx = ctx_of(grammar, THROUGH_THE_HEAD)
    assert NoCarrierCollision()(ctx) is None and NoOverlap()(ctx) is None
    run = Track().run(ctx)
    assert run.contact_share > 0.5
    _, a, b = run.first_contact
    assert not (a.startswith("srl_") and b.startswith("srl_"))  # a carrier geom
    message = NoContactOnTrack()(ctx)
    assert message is not None and "touches on" in message
    # a limb whose path clears the carrier and itself passes
    free = Track().run(ctx_of(grammar, TRACKER))
    assert free.contact_share == 0 and NoContactOnTrack()(ctx_of(grammar, TRACKER)) is None


def test_the_tracking_run_sees_every_touch_a_replay_sees(grammar):
    """Replaying the recorded joint path through a fresh model finds contacts at the
    steps the run counted, and none on a clean run."""
    for text in (THROUGH_THE_HEAD, TRACKER):
        limb = build(grammar, Design.from_text(text))
        run = P.track(limb)
        m = P.mount(limb)
        data = mujoco.MjData(m.model)
        touching = 0
        for q in run.qpos[:-1]:  # each step's contacts are those of its start
            data.qpos[:] = q
            mujoco.mj_kinematics(m.model, data)
            mujoco.mj_collision(m.model, data)
            touching += bool(P.contacts(m, data))
        assert touching / (len(run.qpos) - 1) == pytest.approx(run.contact_share, abs=0.02)


def test_rate_limited_keeps_each_step_within_the_speed_and_follows_when_slow() -> None:
    t = np.linspace(0, 1, 101)
    q = np.stack([np.sin(2 * np.pi * t), 0.01 * t], axis=1)  # 6.3 rad/s peak, 0.01 m/s
    out = P.rate_limited(q, 0.01, np.array([2.0, 1.0]))
    assert np.abs(np.diff(out[:, 0])).max() <= 2.0 * 0.01 + 1e-12
    np.testing.assert_allclose(out[:, 1], q[:, 1], atol=1e-15)  # slow enough: unchanged
    assert np.abs(out[:, 0] - q[:, 0]).max() > 0.1  # the fast one lags


def test_a_joint_past_its_rating_is_refused_and_the_reference_keeps_within(grammar):
    ctx = ctx_of(grammar, TOO_FAST)
    run = Track().run(ctx)
    assert run.first_contact is None and run.first_overlap is None
    rated = np.array([j.peak_velocity for j in ctx.limb.joints])
    assert run.speed_ratio == pytest.approx((np.abs(run.qvel) / rated).max(), rel=1e-12)
    assert run.speed_ratio > 1
    message = WithinRatings()(ctx)
    assert message is not None and "rated speed" in message
    # a limb that keeps up stays within its ratings and passes
    good = ctx_of(grammar, TRACKER)
    assert Track().run(good).speed_ratio <= 1 and WithinRatings()(good) is None


def test_housings_of_a_body_and_its_parent_overlap_where_mujoco_sees_no_contact(grammar):
    ctx = ctx_of(grammar, CROWDED)
    assert NoSelfCollision()(ctx) is None  # MuJoCo filters a body and its parent
    message = NoOverlap()(ctx)
    assert message is not None and "joint1_housing" in message and "joint2_housing" in message
    found = overlaps(ctx.limb, ctx.model, np.zeros((1, ctx.limb.dof)))
    pair = next(o for o in found if {o.a, o.b} == {"joint1_housing", "joint2_housing"})
    # the housings' centres are 2 cm apart along the link, each 5 cm across: 3 cm deep
    assert pair.depth == pytest.approx(0.03, abs=2e-3)
    assert make_constraint("no-overlap") == NoOverlap()


def test_targets_do_not_scale_with_the_design(grammar):
    bracket, tracker = ctx_of(grammar, BRACKET), ctx_of(grammar, TRACKER)
    # the bracket cannot reach the circle 0.57 m out: its error is about that distance
    assert Track()(bracket) > 0.4 > 0.01 > Track()(tracker)
    # nor hold anything 0.25 m out; the tracker can
    assert Payload()(bracket) == 0.0 < Payload()(tracker)
    # the relative target of before still exists, and rewarded the bracket
    relative = Track(center=None, radius=None)
    assert relative(bracket) < 0.01


def test_reach_counts_only_poses_the_limb_can_take(grammar):
    ctx = ctx_of(grammar, FOLDS)
    free, every = Reach()(ctx), Reach(free_only=False)(ctx)
    assert 0 < free < every - 0.04
    pts = ctx.tool_points(256, 0)
    k = int(np.argmin(np.abs(np.linalg.norm(pts, axis=1) - free)))
    assert ctx.pose_is_free(k % 257, 256, 0)
    # at least one farther pose was set aside, and it is not free
    farther = np.flatnonzero(np.linalg.norm(pts, axis=1) > free + 1e-12)
    assert len(farther) > 0
    assert all(not ctx.pose_is_free(int(i) % 257, 256, 0) for i in farther)


#: Worn facing into the torso, its farthest free poses reach through the carrier.
INTO_THE_BODY = (
    HEADER
    + """r1 @0: B=base(diameter=0.12, thickness=0.04) P=pinned()
r2 @0: C=prismatic(stroke=0.1) L=link(diameter=0.04, length=0.15, rotation=-1.5708)
r3 @3: C=prismatic(stroke=0.1) L=link(diameter=0.04, length=0.25, rotation=1.5708)
r3 @5: C=universal(limit=1.5708) L=link(diameter=0.04, length=0.15, rotation=0.0)
r4 @7: E=gripper(finger_length=0.06)
"""
)


def test_reach_on_a_carrier_counts_no_pose_that_touches_it(grammar, tmp_path) -> None:
    from robotwright.grammar.objectives import Carrier
    from robotwright.grammar.task import DEFAULT_TASK, load_task

    facing_in = Carrier(quat=(0.7071068, 0.0, 0.7071068, 0.0))
    ctx = ctx_of(grammar, INTO_THE_BODY)
    alone, worn = Reach()(ctx), Reach(carrier=facing_in)(ctx)
    assert 0 < worn < alone - 0.05
    pts = ctx.tool_points(256, 0)
    k = int(np.argmin(np.abs(np.linalg.norm(pts, axis=1) - worn))) % 257
    m = ctx.mounted(facing_in)
    assert not P.carrier_collisions(m, ctx.poses(256, 0)[k][None])
    # a task file that names a carrier wears the limb for reach; the built-in task does not
    assert DEFAULT_TASK.objective("reach") == Reach()
    path = tmp_path / "task.yaml"
    path.write_text("task: t\ncarrier: {quat: [0.7071068, 0.0, 0.7071068, 0.0]}\n")
    assert load_task(path).objective("reach").carrier == load_task(path).carrier


#: Three slides in a row: it cannot move in the circle's plane, and spends nothing.
IDLE_SLIDES = (
    HEADER
    + """r1 @0: B=base(diameter=0.12, thickness=0.02) P=pinned()
r2 @0: C=prismatic(stroke=0.1) L=link(diameter=0.04, length=0.15, rotation=0.0)
r3 @3: C=prismatic(stroke=0.1) L=link(diameter=0.04, length=0.15, rotation=0.0)
r3 @5: C=prismatic(stroke=0.1) L=link(diameter=0.04, length=0.15, rotation=0.0)
r4 @7: E=tool(length=0.08)
"""
)


def test_energy_counts_only_for_a_limb_that_does_the_job(grammar):
    from robotwright.grammar.objectives import Energy, TracksWithin

    idle, tracker = ctx_of(grammar, IDLE_SLIDES), ctx_of(grammar, TRACKER)
    assert Energy()(idle) < Energy()(tracker)  # spending nothing, it would win energy
    within = make_constraint("max-track-error=0.01")
    assert within == TracksWithin(limit=0.01)
    assert "does not follow the path" in within(idle)
    assert within(tracker) is None
    with pytest.raises(ValueError, match="max-track-error needs a finite number"):
        make_constraint("max-track-error=nan")
    with pytest.raises(ValueError, match="max_track_error"):
        make_constraint("max-track-error=20")


TRIAL_TASK = """task: reach-over-the-shoulder
carrier:
  robot: mini_humanoid
  at: back_mount
  postures:
    standing: {}
    arms_raised: {left_shoulder_pitch_joint: -2.6, right_shoulder_pitch_joint: -2.6}
payload: {samples: 16, min_reach: 0.3}
track: {duration: 1.0, center: [0.45, 0.05, 0.35], radius: 0.04}
collision: {samples: 16}
"""


def _housings_apart(limb, model, data) -> bool:
    """Every two motor housings of different connectors are apart (signed distance of
    the cylinders, whatever their bodies): the test's own check, not the toolkit's."""
    housings = [(j.node, f"srl_{j.name}_housing") for j in limb.joints]
    ft = np.zeros(6)
    for i, (node_a, a) in enumerate(housings):
        for node_b, b in housings[i + 1 :]:
            if node_a != node_b:
                ga, gb = model.geom(a).id, model.geom(b).id
                if mujoco.mj_geomDistance(model, data, ga, gb, 1.0, ft) < -1e-4:
                    return False
    return True


def _posed(ctx: EvalContext, carrier, q: np.ndarray) -> mujoco.MjData:
    """The mounted model's data at joint vector ``q``, kinematics computed."""
    m = ctx.mounted(carrier)
    data = mujoco.MjData(m.model)
    data.qpos[:] = q
    mujoco.mj_kinematics(m.model, data)
    return data


def test_a_designers_task_gets_winners_that_pass_an_independent_replay(tmp_path) -> None:
    """A new task file; the winners of track, energy, payload and reach are replayed in
    MuJoCo by the test itself: no touch of the carrier or the limb, no joint past its
    rated speed, no two housings overlapping, at every step or counted pose."""
    from robotwright.cli import main
    from robotwright.grammar.task import load_task

    task_file = tmp_path / "task.yaml"
    task_file.write_text(TRIAL_TASK, encoding="utf-8")
    task = load_task(task_file)
    grammar = default_grammar()
    winners = {}
    for objective, budget in (("track", 40), ("energy", 40), ("payload", 30), ("reach", 30)):
        out = tmp_path / objective
        args = ["grammar", "search", "--objective", objective, "--task", str(task_file)]
        args += ["--budget", str(budget), "--max-links", "3", "--workers", "1"]
        assert main([*args, "-o", str(out), "--no-picture", "--top", "1"]) == 0
        text = (out / "best_1" / "design.txt").read_text(encoding="utf-8")
        winners[objective] = build(grammar, Design.from_text(text))
        if objective in ("track", "energy"):  # what the toolkit says of its runs
            runs = json.loads((out / "best_1" / "values.json").read_text())["tracking_run"]
            assert [r["posture"] for r in runs] == ["standing", "arms_raised"]
            assert all(r["speed_over_rating"] <= 1 and r["contact_share"] == 0 for r in runs)
            assert all(r["first_contact"] is None and r["first_overlap"] is None for r in runs)
    for objective in ("track", "energy"):
        limb = winners[objective]
        rated = np.array([j.peak_velocity for j in limb.joints])
        for _, carrier in task.postures:
            run = P.track(limb, carrier, duration=1.0, center=(0.45, 0.05, 0.35), radius=0.04)
            assert (np.abs(run.qvel) <= rated + 1e-9).all(), objective
            m = P.mount(limb, carrier)
            data = mujoco.MjData(m.model)
            for q in run.qpos:
                data.qpos[:] = q
                mujoco.mj_kinematics(m.model, data)
                mujoco.mj_collision(m.model, data)
                assert not P.contacts(m, data), objective
                assert _housings_apart(limb, m.model, data), objective
            if objective == "energy":
                assert run.error <= 0.01  # it did the job whose power it was scored by
    payload = winners["payload"]
    for _, carrier in task.postures:
        m = P.mount(payload, carrier)
        data = mujoco.MjData(m.model)
        held = P.payload(payload, carrier, samples=16, min_reach=0.3, mounted=m)
        assert held.mass > 0 and len(held.poses)
        for q in held.poses:  # the poses it was scored on
            data.qpos[:] = q
            mujoco.mj_kinematics(m.model, data)
            mujoco.mj_collision(m.model, data)
            assert not P.contacts(m, data)
            assert _housings_apart(payload, m.model, data)
            tools = [data.site_xpos[s] - data.xpos[m.base_body] for s in m.sites]
            assert min(np.linalg.norm(t) for t in tools) >= 0.3
    reach = winners["reach"]
    ctx = EvalContext(grammar, reach.design)
    for _, carrier in task.postures:  # the task wears the limb: reach counts that too
        value = Reach(carrier=carrier)(ctx)
        pts = ctx.tool_points(256, 0)
        k = int(np.argmin(np.abs(np.linalg.norm(pts, axis=1) - value))) % 257
        q = ctx.poses(256, 0)[k]
        limb_only = ctx.model
        data = mujoco.MjData(limb_only)
        data.qpos[:] = q
        mujoco.mj_kinematics(limb_only, data)
        mujoco.mj_collision(limb_only, data)
        assert data.ncon == 0  # the pose its reach was scored on is one it can take
        assert _housings_apart(reach, ctx.mounted(carrier).model, _posed(ctx, carrier, q))
        m = ctx.mounted(carrier)
        worn = _posed(ctx, carrier, q)
        mujoco.mj_collision(m.model, worn)
        assert not P.contacts(m, worn)


def test_coverage_is_the_share_of_a_given_box_reached_from_poses_it_can_take(
    grammar, tmp_path
) -> None:
    from robotwright.grammar.objectives import Coverage
    from robotwright.grammar.task import load_task

    tracker, bracket = ctx_of(grammar, TRACKER), ctx_of(grammar, BRACKET)
    assert Coverage()(bracket) == 0.0  # nowhere near the box 0.2-0.6 m out
    share = Coverage()(tracker)
    assert 0 < share <= 1.0
    # by hand: the cells holding a tool point of a pose the limb can take
    pts = tracker.tool_points(1024, 0)
    low, high = np.array(Coverage().low), np.array(Coverage().high)
    cells = set()
    for k, p in enumerate(pts):
        if np.all((p >= low) & (p < high)) and tracker.pose_is_free(k % 1025, 1024, 0):
            cells.add(tuple(((p - low) // 0.05).astype(int)))
    assert share == pytest.approx(len(cells) / 512)
    # a box the tracker cannot reach at all, and bad boxes
    assert Coverage(low=(-2.0, -2.0, -2.0), high=(-1.5, -1.5, -1.5))(tracker) == 0.0
    for bad in (dict(low=(0.6, 0, 0), high=(0.2, 1, 1)), dict(voxel=0.0), dict(low=(0, 0))):
        with pytest.raises(ValueError):
            Coverage(**bad)
    path = tmp_path / "task.yaml"
    path.write_text(
        "task: t\ncoverage: {low: [0.1, -0.1, 0.3], high: [0.3, 0.1, 0.5], voxel: 0.04}\n"
    )
    c = load_task(path).objective("coverage")
    assert (c.low, c.high, c.voxel, c.carrier) == ((0.1, -0.1, 0.3), (0.3, 0.1, 0.5), 0.04, None)
    path.write_text("task: t\ncoverage: {low: [0, 0, 99]}\n")
    with pytest.raises(Exception, match="coverage.low"):
        load_task(path)
