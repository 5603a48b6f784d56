"""Task files (``grammar search --task FILE``): read and checked like grammars, their
settings reach the objectives, a path of waypoints is followed."""

from __future__ import annotations

import json

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


def test_a_task_file_gives_absolute_targets_or_asks_for_relative_ones(tmp_path) -> None:
    path = tmp_path / "task.yaml"
    path.write_text(
        "task: t\ntrack: {center: [0.3, 0.1, 0.5], radius: 0.08}\npayload: {min_reach: 0.4}\n",
        encoding="utf-8",
    )
    task = load_task(path)
    t, p = task.objective("track"), task.objective("payload")
    assert (t.center, t.radius, p.min_reach) == ((0.3, 0.1, 0.5), 0.08, 0.4)
    assert task.constraint("no-contact-on-track").center == (0.3, 0.1, 0.5)
    assert task.constraint("max-track-error=0.02").radius == 0.08
    assert task.constraint("max-track-error=0.02").limit == 0.02
    path.write_text("task: t\ntrack: {center: display, scale: 0.2}\n", encoding="utf-8")
    t = load_task(path).objective("track")
    assert (t.center, t.radius, t.scale) == (None, None, 0.2)  # the design-relative circle


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
        ("task: t\ntrack: {center: [0, 0]}\n", "track.center"),
        ("task: t\ntrack: {center: [0, 0, 11]}\n", "track.center"),
        ("task: t\ntrack: {center: here}\n", "track.center"),
        ("task: t\ntrack: {radius: -0.1}\n", "track.radius"),
        ("task: t\ntrack: {radius: 0.1, scale: 0.2}\n", "track.scale"),
        ("task: t\npayload: {min_reach: .inf}\n", "payload.min_reach"),
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


# A limb free of the carrier with the arms at their reference pose, touched by them
# when they swing back (shoulders pitched back, elbows bent).
BEHIND = """# robotwright-design/1 grammar=srl
r1 @0: B=base(diameter=0.12, thickness=0.04) P=pinned()
r2 @0: C=revolute(limit=1.5708) L=link(diameter=0.04, length=0.25, rotation=1.5708)
r3 @3: C=prismatic(stroke=0.1) L=link(diameter=0.04, length=0.15, rotation=-1.5708)
r4 @5: E=gripper(finger_length=0.06)
"""
ARMS_BACK = {
    "left_shoulder_pitch_joint": 1.0,
    "right_shoulder_pitch_joint": 1.0,
    "left_elbow_joint": -2.5,
    "right_elbow_joint": -2.5,
}
_ARMS = ", ".join(f"{k}: {v}" for k, v in ARMS_BACK.items())
POSTURES = f"""task: two-postures
carrier:
  robot: mini_humanoid
  at: back_mount
  postures:
    standing: {{}}
    arms_back: {{{_ARMS}}}
payload: {{samples: 8}}
collision: {{samples: 8}}
"""


def test_a_posture_holds_the_carrier_where_its_joints_put_it() -> None:
    import warnings
    import xml.etree.ElementTree as ET

    import mujoco

    from robotwright.generators import MJCFHumanoidGenerator
    from robotwright.hrdf.model import HRDF

    held = mujoco.MjModel.from_xml_string(
        P._carrier_xml(P.Carrier(posture=tuple(ARMS_BACK.items())))[0]
    )
    assert held.njnt == 0  # locked there
    # The carrier with its joints, moved to the posture's values.
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        gen = MJCFHumanoidGenerator.from_hrdf(HRDF.from_robot_name("mini_humanoid"))
        xml = ET.tostring(gen.generate(add_scene=False), encoding="unicode")
        moving = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(moving)
    for name, value in ARMS_BACK.items():
        data.qpos[moving.joint(name).qposadr[0]] = value
    mujoco.mj_kinematics(moving, data)
    mine = mujoco.MjData(held)
    mujoco.mj_kinematics(held, mine)
    assert held.nbody == moving.nbody
    for b in range(1, held.nbody):
        other = moving.body(held.body(b).name).id
        # MJCF text keeps 6 significant digits
        np.testing.assert_allclose(mine.xpos[b], data.xpos[other], atol=1e-5)
        np.testing.assert_allclose(mine.xmat[b], data.xmat[other], atol=1e-5)
    standing = mujoco.MjModel.from_xml_string(P._carrier_xml(P.Carrier())[0])
    still = mujoco.MjData(standing)
    mujoco.mj_kinematics(standing, still)
    assert np.abs(still.xpos - mine.xpos).max() > 0.1  # the arms did move


def test_a_task_with_postures_judges_the_limb_in_each(tmp_path) -> None:
    path = tmp_path / "task.yaml"
    path.write_text(POSTURES, encoding="utf-8")
    task = load_task(path)
    assert [n for n, _ in task.postures] == ["standing", "arms_back"]
    assert dict(task.postures[1][1].posture) == ARMS_BACK
    g = default_grammar()
    from robotwright.grammar.objectives import EvalContext

    ctx = EvalContext(g, Design.from_text(BEHIND))
    # Free of the carrier standing, touched by its arms swung back: refused, naming it.
    standing = task.postures[0][1]
    assert NoCarrierCollision(carrier=standing, samples=8)(ctx) is None
    message = task.constraint("no-carrier-collision")(ctx)
    assert message is not None and message.startswith("posture 'arms_back': touches the carrier")
    # The payload is the worst posture's.
    payload = task.objective("payload")
    each = payload.by_posture(ctx)
    assert set(each) == {"standing", "arms_back"}
    assert payload(ctx) == min(each.values())
    assert payload.name == "payload" and payload.maximize and payload.limit == 100.0
    track = task.objective("track")
    assert track(ctx) == max(track.by_posture(ctx).values()) and not track.maximize


@pytest.mark.parametrize(
    ("postures", "field", "words"),
    [
        ("{up: {no_such_joint: 1}}", "carrier.postures.up", "no hinge or slide joint"),
        ("{up: {left_elbow_joint: 1.0}}", "carrier.postures.up", "expects a value in"),
        ("{up: {left_elbow_joint: .inf}}", "carrier.postures.up.left_elbow_joint", "within"),
        ("{up: [1, 2]}", "carrier.postures.up", "mapping of joint"),
        ("[standing]", "carrier.postures", "mapping of 1 to 16"),
        ("{" + ", ".join(f"p{i}: {{}}" for i in range(17)) + "}", "carrier.postures", "1 to 16"),
    ],
)
def test_bad_postures_are_refused_naming_the_field(tmp_path, postures, field, words) -> None:
    path = tmp_path / "task.yaml"
    path.write_text(f"task: t\ncarrier: {{postures: {postures}}}\n", encoding="utf-8")
    with pytest.raises(GrammarError) as err:
        load_task(path)
    hits = [p for p in err.value.problems if p.column == field]
    assert hits and words in hits[0].message, err.value.problems


def test_a_search_with_postures_logs_them_and_resumes(tmp_path, capsys) -> None:
    task = tmp_path / "task.yaml"
    task.write_text(POSTURES, encoding="utf-8")
    log = tmp_path / "log.jsonl"
    args = ["grammar", "search", "--objective", "payload", "--budget", "8", "--task", str(task)]
    args += ["--method", "random", "--max-links", "3", "--seed", "1", "--workers", "1"]
    out = tmp_path / "winners"
    assert main([*args, "--log", str(log), "-o", str(out), "--top", "1"]) == 0
    header = log.read_text().splitlines()[0]
    assert "WorstPosture" in header and "arms_back" in header
    # The winner pictured in each posture, in the task's order.
    values = json.loads((out / "best_1" / "values.json").read_text())
    assert values["postures"] == ["standing", "arms_back"]
    each = values["by_posture"]["payload"]
    assert set(each) == {"standing", "arms_back"}
    assert values["values"]["payload"] == pytest.approx(min(each.values()), rel=1e-12)
    assert (out / "best_1" / "on_carrier.png").is_file()
    assert (out / "best_1" / "on_carrier_2.png").is_file()
    capsys.readouterr()
    assert main([*args, "--resume", str(log)]) == 0
    assert "Traceback" not in capsys.readouterr().err
