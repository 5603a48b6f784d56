"""The program's temporary folders, and the processes it starts, end with it.

* Every temporary folder is named ``robotwright-<kind>-<pid>-<random>`` (:func:`prefix`)
  in the system's temporary folder, ``<pid>`` the process that made it.
* A command stopped by SIGTERM (what ``timeout`` and ``kill`` send) or Ctrl-C unwinds
  like an error (:func:`terminate_like_interrupt`): every ``with`` block removes its
  temporaries and a confined reader is killed.
* A process stopped by SIGKILL cannot clean up: a later command removes the
  temporaries of processes of this user that no longer run, once they are an hour old
  (:func:`sweep_stale`; the hour spares a live process of another PID namespace).
* A child (a confined reader, a search's pool worker) gets Linux's parent-death signal
  (:func:`die_with_parent`): it is killed when its parent dies, even by SIGKILL,
  instead of running on under PID 1.
"""

from __future__ import annotations

import contextlib
import os
import re
import shutil
import signal
import sys
import tempfile
import threading
import time
from collections.abc import Iterator

__all__ = [
    "die_with_parent",
    "prefix",
    "remove_entry",
    "running",
    "sweep_stale",
    "terminate_like_interrupt",
]

_NAME = re.compile(r"^robotwright-[a-z]+-(?P<pid>\d+)-")


def prefix(kind: str) -> str:
    """The name prefix of a temporary folder of ``kind`` made by this process."""
    return f"robotwright-{kind}-{os.getpid()}-"


def running(pid: int) -> bool:
    """Whether process ``pid`` runs (another user's, or one that cannot be asked about,
    counts as running: its files are left alone)."""
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:
        return True
    return True


#: Age [s] below which a temporary is never swept: a process of another PID namespace
#: sharing the temporary folder (a container) may hold a live one under a process id
#: that looks dead from here.
MIN_STALE_AGE_S = 3600.0


def sweep_stale(folder: str | None = None, min_age_s: float = MIN_STALE_AGE_S) -> list[str]:
    """Remove the temporaries (:func:`prefix`) in ``folder`` (default: the system's
    temporary folder) that belong to this user and to processes that no longer run, and
    were last changed at least ``min_age_s`` seconds ago; returns their names. Links
    are never followed, other users' files never touched."""
    folder = folder or tempfile.gettempdir()
    now = time.time()
    removed = []
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return removed
    uid = os.getuid() if hasattr(os, "getuid") else None
    for entry in entries:
        match = _NAME.match(entry.name)
        if match is None or running(int(match["pid"])):
            continue
        try:
            st = entry.stat(follow_symlinks=False)
        except OSError:
            continue
        if (uid is not None and st.st_uid != uid) or now - st.st_mtime < min_age_s:
            continue
        remove_entry(entry)
        removed.append(entry.name)
    return removed


def remove_entry(entry: os.DirEntry) -> None:
    """Remove a folder (with what it holds) or a file or link of a listing, never
    following a link; what cannot be removed is left."""
    if entry.is_dir(follow_symlinks=False):
        shutil.rmtree(entry.path, ignore_errors=True)
    else:
        with contextlib.suppress(OSError):
            os.unlink(entry.path)


def die_with_parent(parent: int) -> None:
    """Called in a child process: it is killed when the process that started it dies,
    even by ``kill -9`` (Linux's parent-death signal), instead of running on as an
    orphan. ``parent`` is that process's id: a child that finds it gone once the signal
    is set (it died in between) exits at once. Under a fork server (Python's default
    from 3.14) the signal follows the server, which ends with its parent. Elsewhere than
    Linux it does nothing."""
    if not sys.platform.startswith("linux"):
        return
    import ctypes

    pr_set_pdeathsig = 1
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(pr_set_pdeathsig, int(signal.SIGKILL), 0, 0, 0)
    except (OSError, AttributeError):
        return
    if not running(parent):  # it died before the signal was set
        os._exit(1)


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised where the command runs so that it unwinds as Ctrl-C does."""


def _raise_terminated(signum: int, frame: object) -> None:
    raise Terminated(f"signal {signum}")


@contextlib.contextmanager
def terminate_like_interrupt() -> Iterator[None]:
    """Within the block, SIGTERM raises :class:`Terminated` (a ``KeyboardInterrupt``) in
    the main thread, so that ``finally`` and ``with`` blocks remove temporaries and stop
    children; the earlier handler is restored after. Does nothing off the main thread
    or where SIGTERM already has a handler of the caller's."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    try:
        previous = signal.getsignal(signal.SIGTERM)
    except (ValueError, OSError):
        yield
        return
    if previous not in (signal.SIG_DFL, None):
        yield
        return
    signal.signal(signal.SIGTERM, _raise_terminated)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)
