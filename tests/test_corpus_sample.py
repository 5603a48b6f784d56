"""``$ROBOTWRIGHT_CORPUS_SAMPLE``: the corpus tests' sample (tests/conftest.py) runs 1 file
in N of each corpus plus every expected failure or refusal, and says why it skips the rest.

Run in an inner pytest session whose conftest is this project's own.
"""

from __future__ import annotations

from pathlib import Path

import pytest

pytest_plugins = ["pytester"]

CONFTEST = Path(__file__).resolve().parent / "conftest.py"
#: Two corpora of 10 files; a1 and b3 are strict expected failures, a6 an expected refusal.
CORPUS_TESTS = """
import pytest

FILES = [("a", f"a{i}") for i in range(10)] + [("b", f"b{i}") for i in range(10)]
XFAIL = {"a1", "b3"}


def _params():
    return [
        pytest.param(c, f, id=f, marks=[pytest.mark.xfail(strict=True)] if f in XFAIL else [])
        for c, f in FILES
    ]


@pytest.mark.corpus(always=("a6",))
@pytest.mark.parametrize(("corpus", "rel"), _params())
def test_file(corpus, rel):
    assert rel not in XFAIL


def test_not_a_corpus_test():
    pass
"""


@pytest.fixture
def inner(pytester: pytest.Pytester) -> pytest.Pytester:
    pytester.makeconftest(CONFTEST.read_text(encoding="utf-8"))
    pytester.makeini("[pytest]\nmarkers =\n    corpus(always=()): corpus test\n")
    pytester.makepyfile(test_corpus=CORPUS_TESTS)
    return pytester


def _ran(result: pytest.RunResult) -> set[str]:
    return {
        r.nodeid.split("[", 1)[1].rstrip("]")
        for r in result.reprec.getreports("pytest_runtest_logreport")
        if r.when == "call" and "[" in r.nodeid
    }


def test_unset_runs_every_file(inner: pytest.Pytester, monkeypatch) -> None:
    monkeypatch.delenv("ROBOTWRIGHT_CORPUS_SAMPLE", raising=False)
    result = inner.runpytest_inprocess()
    result.assert_outcomes(passed=19, xfailed=2)
    assert "corpus sample" not in result.stdout.str()


@pytest.mark.parametrize("value", ["1", ""])
def test_one_in_one_runs_every_file(inner: pytest.Pytester, monkeypatch, value: str) -> None:
    monkeypatch.setenv("ROBOTWRIGHT_CORPUS_SAMPLE", value)
    inner.runpytest_inprocess().assert_outcomes(passed=19, xfailed=2)


def test_sample_keeps_one_in_n_per_corpus_and_every_expected_outcome(
    inner: pytest.Pytester, monkeypatch
) -> None:
    monkeypatch.setenv("ROBOTWRIGHT_CORPUS_SAMPLE", "4")
    result = inner.runpytest_inprocess("-rs")
    ran = _ran(result)
    always = {"a1", "b3", "a6"}  # the expected failures and the refusal always run
    # 1 file in 4 of each corpus, every 4th from one offset (the test's), plus those
    offsets = [
        k for k in range(4) if ran == always | {f"{c}{i}" for c in "ab" for i in range(k, 10, 4)}
    ]
    assert len(offsets) == 1, sorted(ran)
    skipped = 20 - len(ran)
    outcomes = result.parseoutcomes()
    assert outcomes["skipped"] == skipped and outcomes["passed"] == len(ran) - 2 + 1
    out = result.stdout.str()
    assert "every corpus case runs in .ci/run's first stage" in out  # the skip reason
    assert f"{len(ran)} of 20 corpus cases run, {skipped} skipped" in out
    assert "ROBOTWRIGHT_CORPUS_SAMPLE=4: a sample of the corpus tests runs" in out


@pytest.mark.parametrize("value", ["0", "-2", "four", "1.5"])
def test_a_bad_value_is_a_usage_error(inner: pytest.Pytester, monkeypatch, value: str) -> None:
    monkeypatch.setenv("ROBOTWRIGHT_CORPUS_SAMPLE", value)
    result = inner.runpytest_inprocess()
    assert result.ret == pytest.ExitCode.USAGE_ERROR
    assert "ROBOTWRIGHT_CORPUS_SAMPLE: expected an integer >= 1" in result.stderr.str()


#: Hostile-input tests (a ``hostile`` folder beside the conftest): parametrized ones are
#: sampled like a corpus, one whose name says it checks MuJoCo's verdict runs whole, and
#: a test with fewer cases than the sample's N still runs one of them.
HOSTILE_TESTS = """
import pytest


@pytest.mark.parametrize("junk", range(12))
def test_junk_is_refused(junk):
    pass


@pytest.mark.parametrize("junk", range(12))
def test_junk_mujoco_refuses_is_refused(junk):
    pass


@pytest.mark.parametrize("junk", range(2))
def test_two_junks(junk):
    pass


def test_plain():
    pass
"""


def _ran_per_test(result: pytest.RunResult) -> dict[str, int]:
    counts: dict[str, int] = {}
    for r in result.reprec.getreports("pytest_runtest_logreport"):
        if r.when == "call":
            name = r.nodeid.split("::", 1)[1].split("[", 1)[0]
            counts[name] = counts.get(name, 0) + 1
    return counts


def test_hostile_inputs_are_sampled_as_a_corpus(inner: pytest.Pytester, monkeypatch) -> None:
    hostile = inner.mkpydir("hostile")
    (hostile / "test_inputs.py").write_text(HOSTILE_TESTS, encoding="utf-8")
    monkeypatch.setenv("ROBOTWRIGHT_CORPUS_SAMPLE", "4")
    result = inner.runpytest_inprocess("hostile")
    assert _ran_per_test(result) == {
        "test_junk_is_refused": 3,  # 1 in 4 of 12
        "test_junk_mujoco_refuses_is_refused": 12,
        "test_two_junks": 1,
        "test_plain": 1,
    }
    monkeypatch.delenv("ROBOTWRIGHT_CORPUS_SAMPLE")
    unset = _ran_per_test(inner.runpytest_inprocess("hostile"))
    assert unset["test_junk_is_refused"] == 12 and unset["test_two_junks"] == 2
