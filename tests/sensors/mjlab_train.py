"""Running mjlab's own ``train`` entry point in a subprocess, for the task tests."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

_CODE = (
    "import sys; from mjlab.scripts.train import main; sys.argv = ['train'] + sys.argv[1:]; main()"
)


def run_train(args: list[str], cwd: Path, timeout: float = 900) -> subprocess.CompletedProcess:
    """``train ARGS`` in ``cwd``; fails the test with the end of its output when it fails."""
    done = subprocess.run(
        [sys.executable, "-c", _CODE, *args],
        capture_output=True,
        text=True,
        timeout=timeout,
        cwd=cwd,
    )
    assert done.returncode == 0, (done.stdout[-3000:], done.stderr[-3000:])
    return done
