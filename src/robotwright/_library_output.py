"""What libraries write straight to the process's stdout and stderr (C++ diagnostics of
usd-core, warp's start-up lines): caught while they run, so that a command's output is
its own and what matters in those lines becomes a note."""

from __future__ import annotations

import os
import sys
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["captured_library_output"]


@contextmanager
def captured_library_output() -> Iterator[list[str]]:
    """Redirect file descriptors 1 and 2 into a temporary file for the block; the yielded
    list holds the lines written there once the block ends (also when it raises). Python's
    own ``sys.stdout``/``sys.stderr`` are flushed on both sides, so nothing of ours is
    caught from before or left behind."""
    lines: list[str] = []
    for stream in (sys.stdout, sys.stderr):
        stream.flush()
    saved = [os.dup(1), os.dup(2)]
    try:
        with tempfile.TemporaryFile() as sink:
            os.dup2(sink.fileno(), 1)
            os.dup2(sink.fileno(), 2)
            try:
                yield lines
            finally:
                for stream in (sys.stdout, sys.stderr):
                    stream.flush()
                os.dup2(saved[0], 1)
                os.dup2(saved[1], 2)
                sink.seek(0)
                text = sink.read().decode("utf-8", errors="replace")
                lines.extend(line for line in text.splitlines() if line.strip())
    finally:
        for fd in saved:
            os.close(fd)
