"""Progress lines on stderr for work a user waits on: ``  12/60 links read (4 s, about
16 s left)``.

The grammar commands report their long loops with :class:`Progress`. Library loops that
can run long on a large input (a URDF's links with their meshes, the meshes copied next
to an export or into an HRDF folder, the frames of an animation) go through
:func:`steps`: silent in a program that calls the library, and, while the command line
runs a command (:func:`shown`), one line every 2 s once the loop has run 2 s, so a
command never sits silent for long and a quick one prints nothing.
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from typing import TypeVar

__all__ = ["Progress", "duration", "shown", "steps", "working"]

T = TypeVar("T")

#: Whether :func:`steps` reports (the command line turns it on while a command runs).
_SHOWN: ContextVar[bool] = ContextVar("robotwright_progress_shown", default=False)
#: The clock progress is measured with (seconds; tests replace it).
_clock = time.perf_counter
#: A loop of :func:`steps` is reported once it has run this long, then this often (s).
STEP_REPORT_S = 2.0


def duration(seconds: float) -> str:
    """``42 s``, ``3.5 min``, ``2.1 h``, ``4.0 days``, ``1.2e+03 years``."""
    for unit, size in (("years", 365.25 * 86400), ("days", 86400), ("h", 3600), ("min", 60)):
        if seconds >= 2 * size:
            value = seconds / size
            return f"{value:.3g} {unit}" if value < 1e4 else f"{value:.2g} {unit}"
    return f"{seconds:.0f} s"


class Progress:
    """Progress of ``total`` steps on stderr: at most one line every ``every`` seconds
    (the first after ``every`` seconds), with the time spent and the estimated time
    left."""

    def __init__(self, total: int, what: str, every: float = 5.0) -> None:
        self.total, self.what, self.every = total, what, every
        self.t0 = _clock()
        self._last = self.t0

    def eta(self, done: int) -> float | None:
        """Estimated seconds left after ``done`` steps (None before the first)."""
        if done <= 0:
            return None
        elapsed = _clock() - self.t0
        return elapsed / done * max(self.total - done, 0)

    def update(self, done: int, extra: str = "") -> None:
        now = _clock()
        if now - self._last < self.every or done >= self.total:
            return
        self._last = now
        left = self.eta(done)
        eta = "" if left is None else f", about {duration(left)} left"
        print(
            f"  {done}/{self.total} {self.what}{extra} ({duration(now - self.t0)}{eta})",
            file=sys.stderr,
            flush=True,
        )


@contextmanager
def shown(on: bool = True) -> Iterator[None]:
    """Inside the block, :func:`steps` reports loops that run long (``on``)."""
    token = _SHOWN.set(on)
    try:
        yield
    finally:
        _SHOWN.reset(token)


def steps(items: Iterable[T], total: int, what: str) -> Iterator[T]:
    """Yield ``items`` (``total`` of them); inside :func:`shown`, a loop over them that
    runs past :data:`STEP_REPORT_S` seconds prints a :class:`Progress` line that often
    (``what``: what one item is when done, ``"links read"``)."""
    if not _SHOWN.get():
        yield from items
        return
    progress = Progress(total, what, every=STEP_REPORT_S)
    for done, item in enumerate(items):
        progress.update(done)
        yield item


@contextmanager
def working(what: str) -> Iterator[None]:
    """Inside :func:`shown`, a block that runs past :data:`STEP_REPORT_S` seconds prints
    ``  WHAT (4 s)`` that often until it ends (from a thread: the block is one call, a
    picture drawn or a file written, with no loop to report from); silent otherwise."""
    if not _SHOWN.get():
        yield
        return
    done = threading.Event()
    t0 = _clock()

    def report() -> None:
        while not done.wait(STEP_REPORT_S):
            print(f"  {what} ({duration(_clock() - t0)})", file=sys.stderr, flush=True)

    thread = threading.Thread(target=report, name="robotwright-progress", daemon=True)
    thread.start()
    try:
        yield
    finally:
        done.set()
        thread.join()
