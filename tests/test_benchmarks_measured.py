"""Every benchmark prints what it ran on with its figures: the CPU model, the cores, the
load average before and after, and the versions (benchmarks/_machine.py)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"
SCRIPTS = sorted(p for p in BENCHMARKS.glob("*.py") if not p.name.startswith("_"))


@pytest.mark.parametrize("script", SCRIPTS, ids=lambda p: p.name)
def test_every_benchmark_says_where_it_ran(script: Path) -> None:
    text = script.read_text(encoding="utf-8")
    # measured() prints the machine before and the load after; the two JSON-writing
    # suites print the machine into their record and the load after by hand.
    assert "measured(" in text or ("print_machine(" in text and "load average after" in text), (
        script.name
    )


def _with_machine(code: str) -> list[str]:
    """The lines ``code`` prints in a fresh interpreter that imports from benchmarks/."""
    run = subprocess.run(
        [sys.executable, "-c", "import sys; sys.path.insert(0, sys.argv[1])\n" + code,
         str(BENCHMARKS)],
        capture_output=True,
        text=True,
    )  # fmt: skip
    assert run.returncode == 0, run.stderr
    return run.stdout.splitlines()


def test_measured_prints_cpu_load_and_versions() -> None:
    lines = _with_machine(
        "from _machine import measured\nwith measured(('numpy',)):\n    print('figures')"
    )
    first, versions, figures, after = lines
    assert "CPU cores, load" in first and first.startswith("Python ")
    assert versions.startswith("versions: robotwright ") and "numpy" in versions
    assert figures == "figures" and after.startswith("load average after: ")


def test_a_peer_in_its_own_interpreter_is_named_with_its_version() -> None:
    import importlib.metadata

    numpy_line, absent, unknown = _with_machine(
        "from _machine import print_peer\n"
        "print_peer(sys.executable, 'numpy'); print_peer(None, 'hurodes')\n"
        "print_peer(sys.executable, 'no-such-distribution-here')"
    )
    assert numpy_line.startswith(f"peer: numpy {importlib.metadata.version('numpy')} (run by ")
    assert absent == "peer: hurodes not run (no interpreter given)"
    assert unknown.startswith("peer: no-such-distribution-here unknown")
