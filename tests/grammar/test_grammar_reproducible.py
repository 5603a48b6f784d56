"""A search a researcher can repeat: MCTS's batch is a parameter (not the worker count),
recorded in the log and checked on resume; the same seed gives the same search with 1
or 2 worker processes; every search says why it stopped; the pool's workers die with
the process that started them, even after ``kill -9``."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import pytest

from robotwright.errors import InputFileError
from robotwright.grammar.loader import default_grammar
from robotwright.grammar.objectives import DoFCount, NoSelfCollision, Reach
from robotwright.grammar.search import MCTS_BATCH, mcts_search, random_search


def _hashes(result) -> list[str]:
    return [e.design.hash() for e in result.evaluations]


def test_mcts_gives_the_same_search_on_one_or_two_workers(tmp_path: Path) -> None:
    g = default_grammar()
    kw = dict(budget=24, max_links=2, seed=3)
    one = mcts_search(g, [Reach()], [NoSelfCollision()], workers=1, **kw)
    two = mcts_search(g, [Reach()], [NoSelfCollision()], workers=2, force_workers=True, **kw)
    assert one.n_evaluated == 24 and _hashes(one) == _hashes(two)
    assert one.stopped == two.stopped == "budget reached"


def test_the_batch_is_logged_and_a_resume_with_another_batch_is_refused(tmp_path: Path) -> None:
    g = default_grammar()
    log = tmp_path / "search.jsonl"
    kw = dict(budget=12, max_links=2, seed=1, workers=1)
    first = mcts_search(g, [DoFCount()], log=log, batch=4, **kw)
    header = json.loads(log.read_text().splitlines()[0])
    assert header["method"] == "mcts" and header["batch"] == 4
    with pytest.raises(InputFileError, match="batch 4; this one has batch 8"):
        mcts_search(g, [DoFCount()], resume=log, batch=MCTS_BATCH, **kw)
    again = mcts_search(g, [DoFCount()], resume=log, log=tmp_path / "again.jsonl", batch=4, **kw)
    assert _hashes(again) == _hashes(first)


def test_a_search_says_why_it_stopped_below_its_budget() -> None:
    """Budget 300 over the 192 designs of one link (4 x 24 x 2): neither search can
    reach it, and each says why."""
    g = default_grammar()
    rnd = random_search(g, [DoFCount()], budget=300, max_links=1, seed=0, workers=1)
    assert rnd.n_evaluated == 192
    assert "found only 192 distinct designs" in rnd.stopped
    mcts = mcts_search(g, [DoFCount()], budget=300, max_links=1, seed=0, workers=1)
    assert 0 < mcts.n_evaluated <= 192
    assert "max_links 1" in mcts.stopped and mcts.stopped != "budget reached"


def test_batch_must_be_a_positive_integer() -> None:
    with pytest.raises(ValueError, match="batch must be an integer >= 1"):
        mcts_search(default_grammar(), [DoFCount()], budget=2, batch=0, workers=1)


def _children(pid: int) -> list[int]:
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
            except OSError:
                continue
            if int(stat.rsplit(")", 1)[1].split()[1]) == pid:
                found.append(int(entry.name))
    return found


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux's parent-death signal")
def test_pool_workers_die_with_a_search_killed_by_sigkill(tmp_path: Path) -> None:
    """Each pool worker says it is ready once its parent-death signal is set (the pool's
    initializer, wrapped); the test waits on those lines, not on a clock, so a busy
    machine only makes it slower. Then the search is killed and its workers must die."""
    (tmp_path / "pool_probe.py").write_text(
        textwrap.dedent(
            """
            import os
            from robotwright._temporaries import die_with_parent

            def ready(parent):
                die_with_parent(parent)
                # One write of the whole line: print() writes the text and its newline
                # apart when output is unbuffered (pytest-xdist runs with -u), and two
                # workers' lines then interleave.
                os.write(1, f"worker {os.getpid()} ready\\n".encode())
            """
        )
    )
    script = textwrap.dedent(
        """
        import pool_probe
        import robotwright.grammar.search as search
        from robotwright.grammar.loader import default_grammar
        from robotwright.grammar.objectives import WorkspaceVolume

        search.die_with_parent = pool_probe.ready
        search.random_search(default_grammar(), [WorkspaceVolume(samples=4096)],
                             budget=100_000, max_links=4, seed=0, workers=2,
                             force_workers=True)
        """
    )
    path = os.pathsep.join(filter(None, [str(tmp_path), os.environ.get("PYTHONPATH")]))
    search = subprocess.Popen(
        [sys.executable, "-c", script],
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        text=True,
        env={**os.environ, "PYTHONPATH": path},
    )
    # Only a hung search (no line, no exit) is cut short, after 15 minutes.
    watchdog = threading.Timer(900, search.kill)
    watchdog.start()
    workers: list[int] = []
    try:
        for line in search.stdout:
            if line.startswith("worker ") and line.strip().endswith(" ready"):
                workers.append(int(line.split()[1]))
                if len(workers) == 2:
                    break
        assert len(workers) == 2, f"the search ended before its pool started: {search.poll()}"
        assert set(workers) <= set(_children(search.pid))
    finally:
        watchdog.cancel()
        os.kill(search.pid, signal.SIGKILL)
        search.wait()
        search.stdout.close()
    deadline = time.monotonic() + 60
    while any(_alive(w) for w in workers) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert not [w for w in workers if _alive(w)], "pool workers outlived their search"
