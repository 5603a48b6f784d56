"""Objectives, constraints, and search through executors."""

from __future__ import annotations

import math
import random
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from robotwright.grammar import derive
from robotwright.grammar.build import build_hrdf
from robotwright.grammar.design import Design
from robotwright.grammar.loader import default_grammar
from robotwright.grammar.objectives import (
    DoFCount,
    DoFRange,
    EvalContext,
    JointLimitsFeasible,
    Mass,
    MaxMass,
    NoSelfCollision,
    Reach,
    WorkspaceVolume,
    evaluate,
    hull_volume,
    make_constraint,
)
from robotwright.grammar.search import beam_search, mcts_search, random_search

from .helpers import default_data, load_variant

PLANAR = Design.from_text(
    "# grammar=srl\n"
    "r1 @0: B=base(diameter=0.08, thickness=0.02) P=pinned()\n"
    "r2 @0: C=revolute(limit=1.5708) L=link(diameter=0.04, length=0.25, rotation=0.0)\n"
    "r3 @3: C=revolute(limit=2.618) L=link(diameter=0.04, length=0.15, rotation=0.0)\n"
    "r4 @5: E=gripper(finger_length=0.06)\n"
)


def test_objectives_on_a_hand_computed_design():
    g = default_grammar()
    ctx = EvalContext(g, PLANAR)
    # stretched out (the zero pose, always sampled) is the farthest: 0.25+0.15+0.084
    # along x, 0.047 above the mount.
    assert Reach()(ctx) == pytest.approx(math.hypot(0.484, 0.047), abs=1e-9)
    assert DoFCount()(ctx) == 2.0
    assert Mass()(ctx) == pytest.approx(build_hrdf(g, PLANAR).total_mass, rel=1e-9)
    # planar arm: tool points lie in the plane z = 0.047, so the hull has no volume
    # and the voxels form at most one layer of a disc of radius 0.484 m.
    assert WorkspaceVolume()(ctx) == 0.0
    vol = WorkspaceVolume(voxel=0.02, method="voxel")(ctx)
    assert 0 < vol <= math.pi * 0.5**2 * 0.02 * 2
    assert JointLimitsFeasible()(ctx) is None and NoSelfCollision()(ctx) is None
    assert MaxMass(0.1)(ctx) is not None and DoFRange(low=3)(ctx) is not None


def test_hull_volume_of_known_shapes():
    cube = np.array([[x, y, z] for x in (0, 2) for y in (0, 1) for z in (0, 0.5)], dtype=float)
    assert hull_volume(cube) == pytest.approx(1.0, rel=1e-9)
    rng = np.random.default_rng(0)
    inside = rng.uniform(0, 1, (200, 3)) * [2, 1, 0.5]
    assert hull_volume(np.vstack([cube, inside])) == pytest.approx(1.0, rel=1e-9)
    assert hull_volume(cube[:3]) == 0.0


def test_self_collision_is_detected_by_mujoco():
    fat = Design.from_text(
        PLANAR.to_text().replace("diameter=0.04, length=0.25", "diameter=0.2, length=0.25")
    )
    msg = NoSelfCollision()(EvalContext(default_grammar(), fat))
    assert msg is not None and "base_geom" in msg and "link1_geom" in msg


def test_joint_limits_excluding_zero_are_infeasible(tmp_path):
    g, lib = default_data()
    lib["components"]["prismatic"]["dofs"][0]["range"] = [0.05, "stroke"]
    grammar = load_variant(tmp_path, g, lib)
    text = PLANAR.to_text().replace("C=revolute(limit=2.618)", "C=prismatic(stroke=0.1)")
    msg = JointLimitsFeasible()(EvalContext(grammar, Design.from_text(text)))
    assert msg is not None and "joint2" in msg


def test_evaluation_score_and_infeasible():
    g = default_grammar()
    ev = evaluate(g, PLANAR, (Mass(), Reach()), (NoSelfCollision(),))
    assert ev.feasible and ev.score == -ev.values["mass"]
    ev = evaluate(g, PLANAR, (Reach(),), (MaxMass(0.01),))
    assert not ev.feasible and ev.score == float("-inf")


def test_make_constraint_parses_and_rejects():
    assert make_constraint("max-mass=2.5") == MaxMass(2.5)
    assert make_constraint("min-dof=3") == DoFRange(low=3)
    with pytest.raises(ValueError, match="needs a whole number"):
        make_constraint("max-dof=many")
    with pytest.raises(ValueError, match="unknown constraint"):
        make_constraint("pretty")


def test_beam_search_respects_budget_and_is_reproducible():
    g = default_grammar()
    kw = dict(budget=40, max_links=3, seed=5, beam_width=2)
    with ThreadPoolExecutor(2) as ex:
        a = beam_search(g, [Reach()], [NoSelfCollision()], executor=ex, **kw)
        b = beam_search(g, [Reach()], [NoSelfCollision()], executor=ex, **kw)
    assert a.n_evaluated == 40
    assert len({e.design.hash() for e in a.evaluations}) == 40
    assert a.best is not None and a.best.feasible
    assert a.best.score == max(e.score for e in a.evaluations)
    assert [e.design.hash() for e in a.evaluations] == [e.design.hash() for e in b.evaluations]
    assert all(
        sum(n.symbol == "L" for n in derive.replay(g, e.design).walk()) <= 3 for e in a.evaluations
    )


def test_beam_search_beats_the_median_random_design():
    g = default_grammar()
    with ThreadPoolExecutor(2) as ex:
        beam = beam_search(g, [Reach()], budget=60, max_links=3, seed=1, executor=ex)
        rand = random_search(g, [Reach()], budget=60, max_links=3, seed=1, executor=ex)
    scores = sorted(e.score for e in rand.evaluations)
    assert beam.best.score > scores[len(scores) // 2]
    assert rand.n_evaluated == 60


def test_default_executor_is_a_process_pool():
    g = default_grammar()
    res = random_search(g, [DoFCount()], budget=4, max_links=2, seed=0, workers=2)
    assert res.n_evaluated == 4
    d = derive.sample(g, 2, random.Random(0))
    assert evaluate(g, d, (DoFCount(),)).values["dof"] >= 1


def test_mcts_respects_budget_is_reproducible_and_beats_random_on_workspace():
    g = default_grammar()
    obj = WorkspaceVolume(samples=256)
    kw = dict(budget=120, max_links=3, seed=2)
    with ThreadPoolExecutor(2) as ex:
        a = mcts_search(g, [obj], [NoSelfCollision()], executor=ex, batch=4, **kw)
        b = mcts_search(g, [obj], [NoSelfCollision()], executor=ex, batch=4, **kw)
        r = random_search(g, [obj], [NoSelfCollision()], executor=ex, **kw)
    assert a.n_evaluated == 120 == len({e.design.hash() for e in a.evaluations})
    assert [e.design.hash() for e in a.evaluations] == [e.design.hash() for e in b.evaluations]
    mean_random = sum(e.score for e in r.evaluations if e.feasible) / sum(
        e.feasible for e in r.evaluations
    )
    mean_mcts = sum(e.score for e in a.evaluations if e.feasible) / sum(
        e.feasible for e in a.evaluations
    )
    assert mean_mcts > mean_random  # the tree concentrates on good designs


@pytest.mark.parametrize("search", [beam_search, mcts_search, random_search])
def test_search_reports_progress_up_to_the_budget(search):
    g = default_grammar()
    seen: list[tuple[int, float | None]] = []

    def progress(n, best):
        seen.append((n, None if best is None else best.score))

    with ThreadPoolExecutor(2) as ex:
        res = search(g, [Reach()], budget=25, max_links=3, seed=2, executor=ex, progress=progress)
    counts = [n for n, _ in seen]
    assert counts == sorted(counts) and counts[-1] == res.n_evaluated == 25
    assert seen[-1][1] == res.best.score
