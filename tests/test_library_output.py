"""captured_library_output: what a library writes to file descriptors 1 and 2 (C++
diagnostics, start-up lines) is caught for the block and given back as lines."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import pytest


def test_lines_written_to_the_descriptors_are_caught_and_nothing_else() -> None:
    script = textwrap.dedent(
        """
        import os, sys
        from robotwright._library_output import captured_library_output

        print("before", flush=True)
        with captured_library_output() as lines:
            os.write(1, b"Status: saving\\n")
            os.write(2, b"Warning: a mass is negative\\n\\n")
        print("after", lines, flush=True)
        """
    )
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert run.stdout.splitlines() == [
        "before",
        "after ['Status: saving', 'Warning: a mass is negative']",
    ]
    assert run.stderr == ""


def test_the_descriptors_come_back_when_the_block_raises(capfd) -> None:
    from robotwright._library_output import captured_library_output

    with pytest.raises(KeyError), captured_library_output() as lines:
        os.write(2, b"lost line\n")
        raise KeyError("inside")
    os.write(2, b"seen\n")
    assert lines == ["lost line"]
    assert capfd.readouterr().err == "seen\n"
