"""Hostile search logs given to ``grammar search --resume``: every malformed line is
refused with one error line naming the file and the line (exit 2, no traceback), before
any evaluation or output; the resumed log is left as it was."""

from __future__ import annotations

import json
import os
import random

import pytest

from robotwright.cli import main

ARGV = ["grammar", "search", "--budget", "4", "--max-links", "1", "--workers", "1"]
ARGV += ["--objective", "reach", "--tie-break", "none", "--method", "random"]


@pytest.fixture(scope="module")
def good(tmp_path_factory) -> list[str]:
    """The lines of a valid log (a search line, then 4 evaluations)."""
    log = tmp_path_factory.mktemp("log") / "good.jsonl"
    assert main([*ARGV, "--log", str(log)]) == 0
    lines = log.read_text().splitlines()
    assert len(lines) == 5
    return lines


def _resume(tmp_path, capsys, text: str | bytes):
    log = tmp_path / "log.jsonl"
    data = text.encode() if isinstance(text, str) else text
    log.write_bytes(data)
    out = tmp_path / "new.jsonl"
    code = main([*ARGV, "--resume", str(log), "--log", str(out)])
    err = capsys.readouterr().err
    if code == 2:
        assert not out.exists()  # refused before any output
    assert log.read_bytes() == data  # the log resumed is never written by a refusal
    return code, err


def _refused_at(code: int, err: str, tmp_path, line: int) -> None:
    assert code == 2, err
    assert err.startswith(f"error: {tmp_path / 'log.jsonl'}: line {line}: "), err
    assert err.count("\n") == 1 and "Traceback" not in err


def _edit(lines: list[str], n: int, fn) -> str:
    """The log with line ``n`` (1-based) replaced by ``fn(record)`` dumped as JSON."""
    out = list(lines)
    rec = json.loads(out[n - 1])
    out[n - 1] = json.dumps(fn(rec)) if not isinstance(fn, str) else fn
    return "\n".join(out) + "\n"


def _set(key, value):
    def f(rec):
        rec[key] = value
        return rec

    return f


def _drop(key):
    def f(rec):
        del rec[key]
        return rec

    return f


def _value(value):
    def f(rec):
        rec["values"] = {"reach": value}
        return rec

    return f


NOT_JSON = ["{", "}", "[1,", "nul", "{'kind': 'search'}", '{"kind": "evaluation"', "\x00"]
NOT_OBJECTS = ["[]", "1", '"text"', "null", "true", "[{}]"]
BAD_VALUES = [
    "NaN",
    "Infinity",
    "-Infinity",
    "1e999",
    "-1e999",
    '"1.5"',
    '"infinity"',
    "true",
    "null",
    "[1]",
    '{"x": 1}',
]
EVAL_EDITS = {
    "unknown kind": _set("kind", "evaluations"),
    "kind missing": _drop("kind"),
    "unknown field": _set("extra", 1),
    "design not text": _set("design", 5),
    "design missing": _drop("design"),
    "design empty": _set("design", ""),
    "design unparsable step": _set("design", "# grammar=srl\nnot a step\n"),
    "design bad parameter": _set("design", "# grammar=srl\nr1 @0: B=base(diameter=x) P=pinned()\n"),
    "design nan parameter": _set(
        "design", "# grammar=srl\nr1 @0: B=base(diameter=nan, thickness=0.02) P=pinned()\n"
    ),
    "design inf parameter": _set(
        "design", "# grammar=srl\nr1 @0: B=base(diameter=inf, thickness=0.02) P=pinned()\n"
    ),
    "design of another grammar": lambda r: {
        **r,
        "design": r["design"].replace("grammar=srl", "grammar=other"),
    },
    "hash wrong": _set("hash", "0" * 16),
    "hash missing": _drop("hash"),
    "values missing": _drop("values"),
    "values a list": _set("values", [1.0]),
    "values of another objective": _set("values", {"mass": 1.0}),
    "values extra objective": lambda r: {**r, "values": {**r["values"], "mass": 1.0}},
    "values empty": _set("values", {}),
    "violations a string": _set("violations", "collides"),
    "violations of numbers": _set("violations", [1, 2]),
    "violations missing": _drop("violations"),
    "feasible contradicts": lambda r: {**r, "feasible": not r["feasible"]},
    "feasible not a bool": _set("feasible", 1),
    "iteration text": _set("iteration", "3"),
    "iteration float": _set("iteration", 3.0),
    "iteration missing": _drop("iteration"),
    "seed text": _set("seed", "0"),
}
HEADER_EDITS = {
    "format other": _set("format", "robotwright-search-log/2"),
    "format missing": _drop("format"),
    "grammar other": _set("grammar", "srl2"),
    "objectives other": lambda r: {**r, "objectives": [{**r["objectives"][0], "name": "mass"}]},
    "objective settings other": lambda r: {
        **r,
        "objectives": [{**r["objectives"][0], "settings": "Reach(samples=9)"}],
    },
    "constraints other": _set("constraints", []),
    "constraints missing": _drop("constraints"),
    "unknown field": _set("python", "__import__('os')"),
}


@pytest.mark.parametrize("text", NOT_JSON + NOT_OBJECTS)
@pytest.mark.parametrize("line", [1, 3, 5])
def test_lines_not_json_objects_are_refused(tmp_path, capsys, good, text, line):
    code, err = _resume(tmp_path, capsys, _edit(good, line, text))
    _refused_at(code, err, tmp_path, line)


@pytest.mark.parametrize("value", BAD_VALUES)
def test_objective_values_must_be_finite_numbers(tmp_path, capsys, good, value):
    rec = json.loads(good[2])
    text = json.dumps(rec).replace(json.dumps(rec["values"]), '{"reach": ' + value + "}")
    code, err = _resume(tmp_path, capsys, _edit(good, 3, text))
    _refused_at(code, err, tmp_path, 3)


@pytest.mark.parametrize("name", sorted(EVAL_EDITS))
@pytest.mark.parametrize("line", [2, 5])
def test_evaluation_lines_are_checked(tmp_path, capsys, good, name, line):
    code, err = _resume(tmp_path, capsys, _edit(good, line, EVAL_EDITS[name]))
    _refused_at(code, err, tmp_path, line)


@pytest.mark.parametrize("name", sorted(HEADER_EDITS))
def test_search_lines_must_match_the_search_resumed(tmp_path, capsys, good, name):
    code, err = _resume(tmp_path, capsys, _edit(good, 1, HEADER_EDITS[name]))
    _refused_at(code, err, tmp_path, 1)


def test_evaluation_before_a_search_line(tmp_path, capsys, good):
    code, err = _resume(tmp_path, capsys, "\n".join(good[1:]) + "\n")
    _refused_at(code, err, tmp_path, 1)


def test_a_design_logged_twice_with_other_results(tmp_path, capsys, good):
    rec = json.loads(good[1])
    rec["values"] = {"reach": rec["values"]["reach"] + 1.0}
    text = "\n".join([*good, json.dumps(rec)]) + "\n"
    code, err = _resume(tmp_path, capsys, text)
    _refused_at(code, err, tmp_path, 6)
    assert "line 2" in err


def test_a_design_logged_twice_alike_is_accepted(tmp_path, capsys, good):
    code, err = _resume(tmp_path, capsys, "\n".join([*good, good[1]]) + "\n")
    assert code == 0, err


@pytest.mark.parametrize("cut", [1, 10, 50, -1])
def test_an_incomplete_last_line_is_named(tmp_path, capsys, good, cut):
    # the search stopped while writing its last line: no newline at the end
    text = "\n".join(good[:-1]) + "\n" + good[-1][:cut]
    code, err = _resume(tmp_path, capsys, text)
    _refused_at(code, err, tmp_path, 5)
    assert "incomplete" in err


@pytest.mark.parametrize("depth", [200, 5000, 100_000])
def test_deep_nesting(tmp_path, capsys, good, depth):
    text = "\n".join([*good, "[" * depth + "]" * depth]) + "\n"
    code, err = _resume(tmp_path, capsys, text)
    _refused_at(code, err, tmp_path, 6)


@pytest.mark.parametrize("data", [b"\xff\xfe\x00", b'{"kind": "search"}\n\xc3\x28\n'])
def test_not_utf8(tmp_path, capsys, data):
    code, err = _resume(tmp_path, capsys, data)
    assert code == 2 and err.startswith("error:") and "UTF-8" in err and err.count("\n") == 1


def test_not_a_regular_file(tmp_path, capsys):
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    for path in (fifo, tmp_path):
        code = main([*ARGV, "--resume", str(path)])
        err = capsys.readouterr().err
        assert code == 2 and err.startswith(f"error: {path}:") and err.count("\n") == 1


@pytest.mark.parametrize("seed", range(40))
def test_random_byte_edits_are_accepted_or_refused_with_a_line(tmp_path, capsys, good, seed):
    # Seeded random edits of an evaluation line: a change the checks cannot tell from a
    # real result (a digit of a violation message) is taken; any other is refused,
    # naming the line; never a traceback.
    rng = random.Random(seed)
    line = rng.randrange(2, 6)
    chars = list(good[line - 1])
    for _ in range(rng.randint(1, 4)):
        k = rng.randrange(len(chars))
        op = rng.random()
        if op < 0.4:
            chars[k] = rng.choice('{}[]",:0123456789.e-+ntfaxX\\')
        elif op < 0.7:
            del chars[k]
        else:
            chars.insert(k, rng.choice('{}[]",:0123456789e\\'))
    text = _edit(good, line, "".join(chars))
    code, err = _resume(tmp_path, capsys, text)
    if code != 0:
        _refused_at(code, err, tmp_path, line)
