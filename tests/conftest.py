"""Shared test fixtures: paths to real data, skipped with a reason when absent."""

from __future__ import annotations

import os
import zlib
from pathlib import Path

import pytest

PROJECT_ROOT = Path(__file__).resolve().parents[1]
TESTDATA = PROJECT_ROOT / ".testdata"
#: HRDF folders written by hurodes 0.1.9 (tools/fetch_test_data.py makes them):
#: ``g1_29`` (+ ``exported/robot.xml``, hurodes' own MJCF of it), ``synth_baseline_hinge``,
#: and ``sources/`` with the MJCF files hurodes converted. ``$ROBOTWRIGHT_HURODES_FIXTURES``
#: points elsewhere.
HURODES_FIXTURES = Path(
    os.environ.get("ROBOTWRIGHT_HURODES_FIXTURES") or TESTDATA / "hurodes-fixtures"
)
FETCH_HINT = "run python tools/fetch_test_data.py"

#: Runs a sample of the corpus tests (``@pytest.mark.corpus``): 1 file in N of each
#: corpus, plus every file the test lists as an expected failure or refusal. .ci/run's
#: MuJoCo 3.11 stage sets it; the first stage runs every file.
CORPUS_SAMPLE_ENV = "ROBOTWRIGHT_CORPUS_SAMPLE"
#: The hostile-input tests: each case of a parametrized test here is one hostile input,
#: so the sample counts them as a corpus (see :func:`mark_hostile_inputs_as_corpus`).
HOSTILE_TESTS = Path(__file__).resolve().parent / "hostile"


def corpus_sample_size(value: str | None) -> int:
    """N of ``$ROBOTWRIGHT_CORPUS_SAMPLE`` (unset or empty: 1, every file)."""
    if value is None or not value.strip():
        return 1
    try:
        size = int(value)
    except ValueError:
        size = 0
    if size < 1:
        raise pytest.UsageError(
            f"{CORPUS_SAMPLE_ENV}: expected an integer >= 1 (run 1 corpus file in N), got {value!r}"
        )
    return size


def corpus_sample(items: list[pytest.Item], size: int) -> list[pytest.Item]:
    """The corpus test items a sample of 1 in ``size`` leaves out.

    Per test function and corpus (its ``corpus`` parameter), in collection order, every
    ``size``-th file is kept, starting at an offset taken from the function's name so
    that two tests of the same corpus check different files (and below the number of
    cases, so that a test with fewer cases than ``size`` still runs one). Kept always: a
    case with an ``xfail`` mark, or whose id is in the marker's ``always`` (expected
    refusals).
    """
    groups: dict[tuple, list[pytest.Item]] = {}
    for item in items:
        mark = item.get_closest_marker("corpus")
        if mark is None:
            continue
        params = getattr(getattr(item, "callspec", None), "params", {})
        key = (str(item.path), getattr(item, "originalname", item.name), params.get("corpus"))
        groups.setdefault(key, []).append(item)
    left_out = []
    for (_, name, _), members in groups.items():
        # Below len(members): every test function runs at least one of its cases.
        offset = zlib.crc32(name.encode()) % min(size, len(members))
        for index, item in enumerate(members):
            always = item.get_closest_marker("corpus").kwargs.get("always", ())
            case_id = getattr(getattr(item, "callspec", None), "id", "")
            if index % size == offset or case_id in always or item.get_closest_marker("xfail"):
                continue
            left_out.append(item)
    return left_out


def mark_hostile_inputs_as_corpus(items: list[pytest.Item]) -> None:
    """Marks ``corpus`` the cases of the parametrized tests under ``tests/hostile``: one
    hostile input each, checked by robotwright's own guards, whose every case runs in the
    first stage. Left whole: a test whose name says MuJoCo's verdict is what it checks
    (``mujoco`` in it: ``..._mujoco_refuses``, ``..._agree_with_mujoco``), so that every
    input MuJoCo itself judges is judged by each MuJoCo line."""
    for item in items:
        if (
            HOSTILE_TESTS in Path(item.path).parents
            and getattr(item, "callspec", None) is not None
            and "mujoco" not in getattr(item, "originalname", item.name)
            and item.get_closest_marker("corpus") is None
        ):
            item.add_marker(pytest.mark.corpus)


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    size = corpus_sample_size(os.environ.get(CORPUS_SAMPLE_ENV))
    if size == 1:
        return
    mark_hostile_inputs_as_corpus(items)
    reason = (
        f"corpus sample ({CORPUS_SAMPLE_ENV}={size}: 1 case in {size} of each corpus test "
        "runs here); every corpus case runs in .ci/run's first stage (newest versions)"
    )
    left_out = corpus_sample(items, size)
    for item in left_out:
        item.add_marker(pytest.mark.skip(reason=reason))
    total = sum(1 for item in items if item.get_closest_marker("corpus"))
    config.stash[_SAMPLE_KEY] = (size, total - len(left_out), total)


_SAMPLE_KEY = pytest.StashKey[tuple]()


def pytest_report_header(config: pytest.Config) -> str | None:
    size = corpus_sample_size(os.environ.get(CORPUS_SAMPLE_ENV))
    if size == 1:
        return None
    return f"{CORPUS_SAMPLE_ENV}={size}: a sample of the corpus tests runs (see tests/conftest.py)"


def pytest_terminal_summary(terminalreporter, config: pytest.Config) -> None:
    sample = config.stash.get(_SAMPLE_KEY, None)
    if sample is not None:
        size, kept, total = sample
        terminalreporter.write_line(
            f"corpus sample ({CORPUS_SAMPLE_ENV}={size}): {kept} of {total} corpus cases run, "
            f"{total - kept} skipped (they run in .ci/run's first stage)"
        )


def _need(path: Path, why: str) -> Path:
    if not path.exists():
        pytest.skip(f"{why}: {path} is absent")
    return path


@pytest.fixture
def g1_hrdf_dir() -> Path:
    """hurodes-written Unitree G1 (29 DoF) HRDF folder (mjlab's G1 MJCF converted)."""
    return _need(HURODES_FIXTURES / "g1_29", f"hurodes G1 fixture not made ({FETCH_HINT})")


@pytest.fixture
def g1_source_mjcf() -> Path:
    """The MJCF file hurodes converted into ``g1_hrdf_dir``: the reference for its values."""
    return _need(HURODES_FIXTURES / "sources" / "g1_29.xml", f"G1 source absent ({FETCH_HINT})")


@pytest.fixture
def synth_hrdf_dir() -> Path:
    """hurodes-written small synthetic hinge robot (two bodies, one motor)."""
    return _need(
        HURODES_FIXTURES / "synth_baseline_hinge",
        f"hurodes synthetic fixture not made ({FETCH_HINT})",
    )


@pytest.fixture
def testdata_dir() -> Path:
    """Folder filled by tools/fetch_test_data.py (mjlab wheel contents, ...)."""
    return _need(TESTDATA, "test data not fetched (run python tools/fetch_test_data.py)")


@pytest.fixture
def hurodes_python() -> str:
    """A python with hurodes 0.1.9: ``$HURODES_PYTHON``, else the venv fetch_test_data makes."""
    env = os.environ.get("HURODES_PYTHON")
    if env:
        return env
    candidate = TESTDATA / "hurodes-venv" / "bin" / "python"
    if not candidate.exists():
        pytest.skip(
            "hurodes not available: run tools/fetch_test_data.py (makes .testdata/hurodes-venv) "
            "or set HURODES_PYTHON to a python with hurodes 0.1.9"
        )
    return str(candidate)
