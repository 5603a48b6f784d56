"""The search log (--log): one JSON line per evaluation as it comes; --resume after a
stop gives the result of an uninterrupted search without evaluating logged designs."""

from __future__ import annotations

import json
import math
from concurrent.futures import Executor

import pytest

from robotwright.cli import main
from robotwright.grammar.design import Design
from robotwright.grammar.loader import default_grammar
from robotwright.grammar.objectives import DoFRange, Evaluation, Mass, NoSelfCollision, Reach
from robotwright.grammar.search import beam_search, mcts_search, random_search
from robotwright.grammar.searchlog import SearchLog, read_log


class Stop(Exception):
    """Raised by :class:`Inline` after its limit: a search stopped mid-batch."""


class Inline(Executor):
    """Evaluates in this process, recording each design evaluated; stops after
    ``limit`` evaluations."""

    def __init__(self, limit: int | None = None) -> None:
        self.limit = limit
        self.done: list[str] = []

    def map(self, fn, items, timeout=None, chunksize=1):
        def gen():
            for d in items:
                if self.limit is not None and len(self.done) >= self.limit:
                    raise Stop
                self.done.append(d.hash())
                yield fn(d)

        return gen()


SEARCHES = [
    (beam_search, dict(beam_width=3)),
    (mcts_search, dict(workers=2)),
    (random_search, dict()),
]
OBJ = [Reach()]
CON = [NoSelfCollision()]


def _key(res):
    return [(e.design.hash(), e.values, e.violations, e.score) for e in res.evaluations]


def _lines(path):
    return [json.loads(x) for x in path.read_text().splitlines()]


def test_log_lines_are_the_evaluations_and_come_as_they_are_made(tmp_path):
    g = default_grammar()
    log = tmp_path / "log.jsonl"
    seen: list[int] = []

    def progress(n, best):
        # readable while the search runs: every evaluation so far is a whole line
        seen.append(len(_lines(log)) - 1)
        assert seen[-1] == n

    con = [NoSelfCollision(), DoFRange(high=2)]
    res = beam_search(
        g, OBJ, con, budget=25, max_links=3, seed=2, executor=Inline(), log=log, progress=progress
    )
    assert seen and seen[-1] == 25
    head, *recs = _lines(log)
    assert head["kind"] == "search" and head["format"] == "robotwright-search-log/1"
    assert (head["grammar"], head["method"], head["seed"], head["budget"]) == ("srl", "beam", 2, 25)
    assert [o["name"] for o in head["objectives"]] == ["reach"]
    assert [c["name"] for c in head["constraints"]] == ["no-self-collision", "dof-range"]
    assert [r["iteration"] for r in recs] == list(range(25))
    for r, ev in zip(recs, res.evaluations, strict=True):
        assert r["kind"] == "evaluation" and r["seed"] == 2
        d = Design.from_text(r["design"])
        assert d == ev.design and r["hash"] == ev.design.hash()
        assert r["values"] == ev.values
        assert r["violations"] == list(ev.violations)
        assert r["feasible"] == ev.feasible
    # both kinds of result are in a search of this size
    assert {r["feasible"] for r in recs} == {True, False}


@pytest.mark.parametrize(("search", "kw"), SEARCHES)
@pytest.mark.parametrize("stop_after", [0, 1, 7, 19])
def test_resume_after_a_stop_equals_an_uninterrupted_search(tmp_path, search, kw, stop_after):
    g = default_grammar()
    common = dict(budget=30, max_links=3, seed=4, **kw)
    full = search(g, OBJ, CON, executor=Inline(), **common)
    log = tmp_path / "log.jsonl"
    with pytest.raises(Stop):
        search(g, OBJ, CON, executor=Inline(limit=stop_after), log=log, **common)
    logged = [r["hash"] for r in _lines(log) if r["kind"] == "evaluation"]
    assert len(logged) == stop_after
    again = Inline()
    res = search(g, OBJ, CON, executor=again, resume=log, **common)
    assert _key(res) == _key(full)
    assert res.best == full.best
    assert not set(again.done) & set(logged)  # logged designs were not evaluated again
    assert len(again.done) == 30 - stop_after
    # the log resumed was appended to: a search line per run, every evaluation once
    kinds = [r["kind"] for r in _lines(log)]
    assert kinds.count("search") == 2
    assert [r["hash"] for r in _lines(log) if r["kind"] == "evaluation"] == [
        e.design.hash() for e in full.evaluations
    ]


def test_resume_into_another_log_writes_every_evaluation(tmp_path):
    g = default_grammar()
    common = dict(budget=20, max_links=3, seed=1)
    first = tmp_path / "first.jsonl"
    with pytest.raises(Stop):
        random_search(g, OBJ, CON, executor=Inline(limit=8), log=first, **common)
    before = first.read_bytes()
    second = tmp_path / "second.jsonl"
    res = random_search(g, OBJ, CON, executor=Inline(), resume=first, log=second, **common)
    assert first.read_bytes() == before  # the log resumed is not written
    recs = [r for r in _lines(second) if r["kind"] == "evaluation"]
    assert [r["hash"] for r in recs] == [e.design.hash() for e in res.evaluations]


def test_a_resumed_log_of_another_seed_only_saves_work(tmp_path):
    # A logged design is the same evaluation whatever search found it (192 designs of
    # one link: two seeds draw some of the same).
    g = default_grammar()
    log = tmp_path / "log.jsonl"
    common = dict(budget=60, max_links=1)
    first = random_search(g, OBJ, CON, seed=0, executor=Inline(), log=log, **common)
    full = random_search(g, OBJ, CON, seed=9, executor=Inline(), **common)
    again = Inline()
    res = random_search(g, OBJ, CON, seed=9, executor=again, resume=log, **common)
    assert _key(res) == _key(full)
    shared = {e.design.hash() for e in first.evaluations} & {
        e.design.hash() for e in full.evaluations
    }
    assert shared
    assert sorted(again.done) == sorted({e.design.hash() for e in full.evaluations} - shared)


def test_non_finite_values_are_logged_as_words_and_read_back(tmp_path):
    g = default_grammar()
    d = random_search(g, [Mass()], budget=1, max_links=1, executor=Inline()).best.design
    log = tmp_path / "log.jsonl"
    objectives = [Mass()]
    evs = [
        Evaluation(d, {"mass": math.inf}, (), -math.inf),
    ]
    with SearchLog(log, "srl", objectives, []) as w:
        for i, ev in enumerate(evs):
            w.write(ev, i)
    rec = _lines(log)[1]
    assert rec["values"] == {"mass": "inf"}
    back = read_log(log, "srl", objectives, [])
    assert back[d.hash()].values == {"mass": math.inf}
    assert back[d.hash()].score == -math.inf  # mass is minimised


def test_cli_log_and_resume(tmp_path, capsys):
    log = tmp_path / "runs" / "log.jsonl"
    argv = ["grammar", "search", "--budget", "10", "--max-links", "2", "--workers", "1"]
    assert main([*argv, "--log", str(log)]) == 0
    first = capsys.readouterr().out
    assert len(log.read_text().splitlines()) == 11
    # a log is never replaced without --overwrite
    assert main([*argv, "--log", str(log)]) == 2
    assert "--overwrite" in capsys.readouterr().err
    # resumed: nothing left to evaluate, the same result; the log gets a search line
    assert main([*argv, "--resume", str(log)]) == 0
    assert capsys.readouterr().out.splitlines()[1:] == first.splitlines()[1:]
    assert len(log.read_text().splitlines()) == 12
    # --resume of a file that is not there
    assert main([*argv, "--resume", str(tmp_path / "none.jsonl")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error:") and "none.jsonl" in err and err.count("\n") == 1
    # --log and --resume the same file: appended to
    assert main([*argv, "--resume", str(log), "--log", str(log)]) == 0
    assert len(log.read_text().splitlines()) == 13


def test_random_search_draws_in_rounds_with_the_same_result(monkeypatch):
    """Random search evaluates and reports progress round by round (its pool starts
    before all ``budget`` designs are drawn); the designs chosen do not depend on the
    round's size."""
    import robotwright.grammar.search as search

    g = default_grammar()
    whole = random_search(g, [Mass()], budget=40, seed=3, executor=Inline())
    monkeypatch.setattr(search, "RANDOM_BATCH", 7)
    reports: list[int] = []
    rounds = random_search(
        g,
        [Mass()],
        budget=40,
        seed=3,
        executor=Inline(),
        progress=lambda n, best: reports.append(n),
    )
    assert _key(rounds) == _key(whole)
    assert reports[:3] == [7, 14, 21] and reports[-1] == 40
