"""Task files (``grammar search --task FILE``): read and checked like grammars, their
settings reach the objectives, a path of waypoints is followed."""

from __future__ import annotations

import numpy as np
import pytest

from robotwright.cli import main
from robotwright.errors import GrammarError
from robotwright.grammar import default_grammar
from robotwright.grammar import physics as P
from robotwright.grammar.build import build
from robotwright.grammar.design import Design
from robotwright.grammar.objectives import Energy, NoCarrierCollision, Payload, Track
from robotwright.grammar.task import DEFAULT_TASK, load_task

from .helpers import ARM

GOOD = """task: side-trace
carrier: {robot: arm6, at: tool0, pos: [0, 0, 0.02], quat: [2, 0, 0, 0]}
payload: {samples: 16, seed: 1, limit: 50}
track:
  duration: 1.5
  path: [[0, 0, 0], [0, 0.1, 0], [0, 0.1, 0.1], [0, 0, 0]]
collision: {samples: 8, seed: 3}
"""


def test_the_built_in_task_is_the_default_objectives() -> None:
    assert DEFAULT_TASK.objective("payload") == Payload()
    assert DEFAULT_TASK.objective("track") == Track()
    assert DEFAULT_TASK.objective("energy") == Energy()
    assert DEFAULT_TASK.constraint("no-carrier-collision") == NoCarrierCollision()


def test_a_task_file_sets_the_objectives(tmp_path) -> None:
    path = tmp_path / "task.yaml"
    path.write_text(GOOD, encoding="utf-8")
    task = load_task(path)
    assert task.name == "side-trace"
    assert task.carrier.robot == "arm6" and task.carrier.at == "tool0"
    assert task.carrier.quat == (1.0, 0.0, 0.0, 0.0)  # normalised
    p = task.objective("payload")
    assert (p.samples, p.seed, p.limit, p.carrier) == (16, 1, 50.0, task.carrier)
    t = task.objective("track")
    assert t.duration == 1.5 and t.path[1] == (0.0, 0.1, 0.0) and t.carrier == task.carrier
    c = task.constraint("no-carrier-collision")
    assert (c.samples, c.seed) == (8, 3)
    assert task.objective("reach").name == "reach"  # the geometric ones need no task


def test_a_path_of_waypoints_is_the_reference_followed() -> None:
    limb = build(default_grammar(), Design.from_text(ARM))
    path = ((0.0, 0.0, 0.0), (0.0, 0.08, 0.0), (0.0, 0.08, 0.08))
    run = P.track(limb, duration=1.0, path=path)
    start = run.reference[0]
    np.testing.assert_allclose(run.reference[-1] - start, (0.0, 0.08, 0.08), atol=1e-12)
    mid = run.reference[len(run.reference) // 2]
    np.testing.assert_allclose(mid - start, (0.0, 0.08, 0.0), atol=1e-3)  # end of leg 1
    built_in = P.track(limb, duration=1.0)
    assert not np.allclose(built_in.reference[-1], run.reference[-1])
    assert np.isfinite(run.error) and run.error != built_in.error
    # the error is measured against this reference
    err = np.linalg.norm(run.path - run.reference, axis=1)
    assert run.error == pytest.approx(float(np.sqrt(np.mean(err**2))))


@pytest.mark.parametrize(
    ("text", "field"),
    [
        ("task: ''\n", "task"),
        ("task: t\ncolour: red\n", "colour"),
        ("task: t\ncarrier: {robot: nope}\n", "carrier.robot"),
        ("task: t\ncarrier: {at: nowhere}\n", "carrier.at"),
        ("task: t\ncarrier: {quat: [0, 0, 0, 0]}\n", "carrier.quat"),
        ("task: t\npayload: {samples: -1}\n", "payload.samples"),
        ("task: t\npayload: {limit: .nan}\n", "payload.limit"),
        ("task: t\npayload: {limit: 0}\n", "payload.limit"),
        ("task: t\ntrack: {path: [[0, 0, 0]]}\n", "track.path"),
        ("task: t\ntrack: {path: [[0, 0, 0], [0, 0, 99]]}\n", "track.path"),
        ("task: t\ntrack: {speed: 2}\n", "track.speed"),
        ("task: t\ncollision: 3\n", "collision"),
        ("- not a mapping\n", None),
    ],
)
def test_bad_task_files_are_refused_naming_the_field(tmp_path, text, field) -> None:
    path = tmp_path / "task.yaml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(GrammarError) as err:
        load_task(path)
    problems = err.value.problems
    assert all(p.file == str(path) for p in problems)
    if field is not None:
        assert field in {p.column for p in problems}, problems


def test_search_cli_takes_a_task_and_refuses_a_bad_one(tmp_path, capsys) -> None:
    good = tmp_path / "task.yaml"
    good.write_text(GOOD.replace("robot: arm6, at: tool0", "robot: mini_humanoid, at: back_mount"))
    args = ["grammar", "search", "--objective", "payload", "--budget", "4"]
    args += ["--method", "random", "--max-links", "2", "--workers", "1"]
    log = tmp_path / "log.jsonl"
    assert main([*args, "--task", str(good), "--log", str(log)]) in (0, 1)
    header = log.read_text().splitlines()[0]
    assert "samples=16" in header and "limit=50.0" in header  # the task's settings searched
    bad = tmp_path / "bad.yaml"
    bad.write_text("task: t\npayload: {samples: -1}\n")
    capsys.readouterr()
    assert main([*args, "--task", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "payload.samples" in err and str(bad) in err and "Traceback" not in err
