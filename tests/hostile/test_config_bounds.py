"""Every number a task file or a grammar library gives has a type and a range with an
upper bound, checked before anything is allocated or run; values shown in messages are
cut (issue 38, items 3 and 4). Each input ends with exit 2 and one ``error:`` block
naming the file and the field, no traceback, within a few seconds.
"""

from __future__ import annotations

import resource
import time
from pathlib import Path

import pytest

from robotwright.cli import main
from robotwright.grammar.loader import default_library_path

_COUNT = ["grammar", "count", "--max-links", "1"]
SEARCH = ["grammar", "search", "--budget", "1", "--workers", "1", "--method", "random"]

#: (task file text, the field its error names)
TASKS = [
    ("task: t\npayload: {samples: 2000000}\n", "payload.samples"),
    ("task: t\npayload: {samples: 1e12}\n", "payload.samples"),
    ("task: t\npayload: {samples: " + "9" * 400 + "}\n", "payload.samples"),
    ("task: t\npayload: {limit: " + "9" * 400 + "}\n", "payload.limit"),
    ("task: t\npayload: {limit: 1e400}\n", "payload.limit"),
    ("task: t\npayload: {seed: " + "1" * 30 + "}\n", "payload.seed"),
    ("task: t\npayload: {min_free_share: 2}\n", "payload.min_free_share"),
    ("task: t\ntrack: {duration: 20000.0}\n", "track.duration"),
    ("task: t\ntrack: {duration: 1e12}\n", "track.duration"),
    ("task: t\ntrack: {scale: 1e9}\n", "track.scale"),
    ("task: t\ncollision: {samples: 10000000}\n", "collision.samples"),
    ("task: t\ncarrier: {quat: [1.0e+200, 1.0e+200, 0, 0]}\n", "carrier.quat"),
    ("task: t\ncarrier: {quat: [1.0e+308, 1.0e+308, 1.0e+308, 1.0e+308]}\n", "carrier.quat"),
    ("task: t\ncarrier: {pos: [" + "9" * 400 + ", 0, 0]}\n", "carrier.pos"),
    ("task: [t]\n", "task"),
    ("task: " + "x" * 5000 + "\n", "task"),
    ("task: t\npayload: {" + "k" * 1000 + ": 1}\n", "payload.kkkk"),
]


@pytest.mark.parametrize(("text", "field"), TASKS, ids=[f for _, f in TASKS])
def test_a_task_number_out_of_range_is_one_line(tmp_path, capsys, text, field) -> None:
    path = tmp_path / "task.yaml"
    path.write_text(text, encoding="utf-8")
    start = time.monotonic()
    code = main([*SEARCH, "--task", str(path)])
    err = capsys.readouterr().err
    assert code == 2, err
    assert err.startswith("error:") and "Traceback" not in err
    assert field in err and str(path) in err
    assert len(err) < 4000  # the value is cut, not formatted whole
    assert time.monotonic() - start < 10


def test_yaml_exponent_numbers_are_numbers(tmp_path, capsys) -> None:
    """YAML 1.1 reads ``1e1`` as text: the loader reads it as the number it is."""
    path = tmp_path / "task.yaml"
    path.write_text("task: t\ntrack: {duration: 1e1}\npayload: {limit: 5e1}\n", "utf-8")
    from robotwright.grammar.task import load_task

    task = load_task(path)
    assert task.track["duration"] == 10.0 and task.payload["limit"] == 50.0


def test_the_objectives_bound_their_settings_from_python_too() -> None:
    from robotwright.grammar.objectives import Payload, Track

    with pytest.raises(ValueError, match="samples"):
        Payload(samples=2_000_000)
    with pytest.raises(ValueError, match="duration"):
        Track(duration=20_000.0)
    with pytest.raises(ValueError, match="samples"):
        Payload(samples=10**400)


def _alias_bomb(levels: int) -> str:
    """A YAML of a few hundred bytes whose value expands to 10**levels leaves."""
    lines = ['a0: &a0 ["lol","lol","lol","lol","lol","lol","lol","lol","lol","lol"]']
    for i in range(1, levels):
        refs = ",".join(f"*a{i - 1}" for _ in range(10))
        lines.append(f"a{i}: &a{i} [{refs}]")
    return "\n".join(lines) + "\n"


def _library(tmp_path: Path, replace: tuple[str, str], extra: str = "") -> Path:
    text = default_library_path().read_text(encoding="utf-8")
    old, new = replace
    assert old in text
    path = tmp_path / "lib.yaml"
    path.write_text(extra + text.replace(old, new, 1), encoding="utf-8")
    return path


def test_an_alias_bomb_in_a_library_is_reported_in_a_short_line(tmp_path, capsys) -> None:
    lib = _library(tmp_path, ("    kind: base\n", f"    kind: *a{8}\n"), _alias_bomb(9))
    grammar = tmp_path / "g.yaml"
    from robotwright.grammar.loader import default_grammar_path

    grammar.write_text(default_grammar_path().read_text(encoding="utf-8"), encoding="utf-8")
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    start = time.monotonic()
    code = main(_COUNT + ["--grammar", str(grammar), "--library", str(lib)])
    err = capsys.readouterr().err
    assert code == 2 and "Traceback" not in err
    assert "kind" in err and "a list of 10" in err
    assert len(err) < 4000
    assert time.monotonic() - start < 10
    grown_kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before
    assert grown_kb < 200_000  # nothing of the 10**9 leaves was materialised as text


LIBRARY_CASES = [
    (("peak_torque: 30.0", "peak_torque: 1e400"), "actuator"),
    (("peak_torque: 30.0", "peak_torque: " + "9" * 400), "actuator"),
    (("diameter: {range: [0.02, 0.5]", "diameter: {range: [0.02, 1e300]"), "params.diameter"),
    (("twist: 1.5708", "twist: 1e12"), "dofs[1]"),
    (("rgba: [0.35, 0.35, 0.4, 1.0]", "rgba: [0.35, 0.35, 0.4, 1e9]"), "rgba"),
    (("values: [0.08, 0.12]", "values: [" + ", ".join("0.1" for _ in range(1200)) + "]"), "params"),
]


@pytest.mark.parametrize(("replace", "field"), LIBRARY_CASES, ids=[f for _, f in LIBRARY_CASES])
def test_a_library_number_out_of_range(tmp_path, capsys, replace, field) -> None:
    lib = _library(tmp_path, replace)
    from robotwright.grammar.loader import default_grammar_path

    code = main(_COUNT + ["--grammar", str(default_grammar_path()), "--library", str(lib)])
    err = capsys.readouterr().err
    assert code == 2 and "Traceback" not in err and field in err and str(lib) in err


@pytest.mark.parametrize(
    "start", ["[S]", "{a: 1}", "12", "'" + "S" * 5000 + "'"], ids=["list", "map", "int", "long"]
)
def test_a_grammar_start_that_is_not_a_name(tmp_path, capsys, start) -> None:
    from robotwright.grammar.loader import default_grammar_path

    text = default_grammar_path().read_text(encoding="utf-8")
    lines = [ln for ln in text.splitlines() if not ln.startswith("start:")]
    path = tmp_path / "g.yaml"
    path.write_text("\n".join([f"start: {start}", *lines]) + "\n", encoding="utf-8")
    code = main(_COUNT + ["--grammar", str(path), "--library", str(default_library_path())])
    err = capsys.readouterr().err
    assert code == 2 and "Traceback" not in err and "start" in err and len(err) < 4000


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("max_distance", 1e300),
        ("min_distance", 1e300),
        ("range_noise_std", 1e300),
        ("offset_pos", (1e300, 0.0, 0.0)),
        ("seed", 2**70),
        ("num_threads", 10**9),
    ],
)
def test_sensor_config_numbers_are_bounded(field, value) -> None:
    from robotwright.errors import SensorError
    from robotwright.sensors import LidarCfg

    with pytest.raises(SensorError, match=field):
        LidarCfg(prim_path="lidar", **{field: value})


def test_a_huge_mount_quaternion_is_normalised_not_zeroed() -> None:
    from robotwright.sensors import LidarCfg

    cfg = LidarCfg(prim_path="lidar", offset_rot=(1e200, 1e200, 0.0, 0.0))
    assert cfg.offset_rot == pytest.approx((2**-0.5, 2**-0.5, 0.0, 0.0))
