"""Confined reading: untrusted robot files are read by a process that cannot reach
anything else.

The path checks of :mod:`robotwright._paths` are the first line: they give the good
error messages. But MuJoCo, trimesh and xacro open files by themselves (a sub-model's
own ``meshdir``, a glTF buffer, an OBJ's material library), and each way they find a
file that the checks did not foresee would be a way out. :func:`run_confined` runs a
reading step in a forked copy of this process that the kernel confines with Landlock
(:mod:`robotwright._landlock`) before the step starts: it may read only

- the roots the step is given (the robot's folder or ROS package, and the packages
  the user named: ``--package``, ``package_map``, ``ROS_PACKAGE_PATH``,
  ``AMENT_PREFIX_PATH``; see :func:`robotwright.parsers.packages.source_read_roots`),
- the folders the user trusted (``--asset-root``),
- the Python installation and the shared libraries it loads,

writes only into a staging folder of its own (and a work folder the caller names), and
opens no TCP connection. The step's result, its warnings,
MuJoCo's warnings and its exception travel back through a pipe (pickled: the parent
unpickles only what its own forked copy wrote). A copy of a running process starts in
about a millisecond, so confinement costs little beyond the transfer of the result.

Where the kernel has no Landlock (older than 5.13, macOS) or ``fork`` is missing
(Windows), the step runs in this process under the checks alone; :func:`confinement`
says which, and the command line says it once with ``-v``. ``ROBOTWRIGHT_CONFINE=off``
turns confinement off (for debugging a reader); any other value keeps it.
"""

from __future__ import annotations

import contextlib
import os
import pickle
import signal
import sys
import sysconfig
import threading
import warnings
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any, TypeVar

from robotwright._landlock import LandlockError, abi_version, restrict_self
from robotwright._reader_budget import _BUDGET
from robotwright._temporaries import die_with_parent, prefix
from robotwright.errors import RobotwrightError

__all__ = [
    "ConfinementError",
    "confinement",
    "readable_roots",
    "run_confined",
    "start_confined",
]

T = TypeVar("T")

#: Shared-library folders a reader may still load from (a lazily imported extension's
#: dependencies), and the loader's cache. Never the user's files: ``/etc`` and ``/home``
#: stay closed except ``ld.so.cache``.
SYSTEM_LIBRARY_PATHS = (
    "/lib",
    "/lib64",
    "/usr/lib",
    "/usr/lib64",
    "/usr/local/lib",
    "/etc/ld.so.cache",
    "/dev/null",
    "/dev/urandom",
)


#: True in a confined copy (temporary folders made there travel back by path).
_IN_COPY = False
#: The staging folder of the answer being unpickled here (see :func:`adoption_holder`).
_ADOPTING: _Staging | None = None
_ADOPTION_LOCK = threading.Lock()


class _Staging:
    """The folder a confined copy may write into; removed when no folder adopted from it
    (:func:`adoption_holder`) is held any more."""

    def __init__(self) -> None:
        import shutil
        import tempfile
        import weakref

        self.path = Path(tempfile.mkdtemp(prefix=prefix("read")))
        self._finalizer = weakref.finalize(self, shutil.rmtree, str(self.path), True)


def in_confined_copy() -> bool:
    """Whether this process is a confined copy made by :func:`run_confined`."""
    return _IN_COPY


def adoption_holder(path: str | os.PathLike[str]) -> object:
    """While an answer is unpickled: the staging folder object that must live as long as
    the temporary folder ``path`` made by the copy inside it (hold it beside the folder).

    Raises:
        ConfinementError: no answer of a confined copy is being read, or ``path`` is not
            inside its staging folder (a temporary folder travels only from a copy).
    """
    staging = _ADOPTING
    if staging is None or not Path(path).resolve().is_relative_to(staging.path.resolve()):
        raise ConfinementError(f"{path}: not a temporary folder of a confined reader")
    return staging


def _mapped_bytes() -> int:
    """The address space this process maps now (0 where /proc cannot tell)."""
    try:
        with open("/proc/self/statm") as f:
            return int(f.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return 0


class ConfinementError(RobotwrightError):
    """The confined reader stopped without an answer (killed, crashed) or could not be
    confined although the kernel offers Landlock."""


def confinement() -> str:
    """How untrusted files are read here: ``"landlock ABI N"`` (a confined process),
    or why not (``"off: ..."``)."""
    if os.environ.get("ROBOTWRIGHT_CONFINE", "").lower() in ("off", "0", "no", "false"):
        return "off: ROBOTWRIGHT_CONFINE=off"
    if not hasattr(os, "fork"):
        return "off: this system has no fork()"
    abi = abi_version()
    if abi < 1:
        return "off: the kernel offers no Landlock (Linux 5.13 or later with it enabled)"
    return f"landlock ABI {abi}"


def _user_roots() -> list[Path]:
    """The folders the user trusted for this run (``--asset-root``,
    ``trusted_asset_roots``); the packages they named come with a source's roots
    (:func:`robotwright.parsers.packages.source_read_roots`)."""
    from robotwright._paths import trusted_roots

    return [Path(p) for p in trusted_roots(())]


def site_package_folders() -> list[Path]:
    """The folders pip installs packages into for this interpreter (site-packages,
    the user's site folder), resolved."""
    import site

    places = {sysconfig.get_paths().get(k) for k in ("purelib", "platlib")}
    with contextlib.suppress(AttributeError):
        places.update(site.getsitepackages())
    with contextlib.suppress(AttributeError):
        places.add(site.getusersitepackages())  # pip install --user
    return [Path(p).resolve() for p in places if p]


def _python_roots() -> list[Path]:
    """The Python installation (prefixes, site-packages, the interpreter's folder) and
    the folder holding robotwright itself, never the working folder, home or ``/``.
    Other ``sys.path`` entries (a script's folder, ``PYTHONPATH``) stay closed: they
    may hold the user's files, and a reader imports nothing from there."""
    paths = {sys.prefix, sys.base_prefix, sys.exec_prefix, sys.base_exec_prefix}
    paths.update(v for k, v in sysconfig.get_paths().items() if v)
    paths.add(str(Path(sys.executable).resolve().parent.parent))
    # The folder holding this package (an editable install's src/): a worker the reader
    # starts imports robotwright from there.
    paths.add(str(Path(__file__).resolve().parent.parent))
    paths.update(str(p) for p in site_package_folders())
    for name in ("mujoco", "numpy", "trimesh"):
        module = sys.modules.get(name)
        if module is not None and getattr(module, "__file__", None):
            paths.add(str(Path(module.__file__).resolve().parent.parent))
    closed = {Path("/"), Path.cwd().resolve()}
    with contextlib.suppress(RuntimeError, KeyError, OSError):
        closed.add(Path.home().resolve())
    out = []
    for p in paths:
        try:
            resolved = Path(p).resolve()
        except (OSError, RuntimeError):
            continue
        if resolved not in closed:
            out.append(resolved)
    return out


def readable_roots(roots: Iterable[str | os.PathLike[str]]) -> list[Path]:
    """Everything a confined reader of a source with ``roots`` may read (see the module
    docstring)."""
    return [
        *(Path(r) for r in roots),
        *_user_roots(),
        *_python_roots(),
        *(Path(p) for p in SYSTEM_LIBRARY_PATHS),
    ]


def run_confined(
    step: Callable[..., T],
    *args: Any,
    roots: Iterable[str | os.PathLike[str]],
    what: str,
    writable: Iterable[str | os.PathLike[str]] = (),
    **kwargs: Any,
) -> T:
    """``step(*args, **kwargs)`` run in a confined copy of this process that may read only
    below ``roots`` and the folders of :func:`readable_roots` (see the module docstring);
    its result, warnings (issued again here, in order) and MuJoCo's warnings (handed to
    the handler in place here) come back. Where confinement is off, the step runs here.

    Args:
        roots: the folders of the source (its folder or ROS package).
        what: what is read, for messages (``"robot.xml"``).
        writable: folders the step writes into besides its own temporary folders
            (which are made in a staging folder of this call's).

    Raises:
        Whatever the step raises (rebuilt here with its type and attributes).
        ConfinementError: the copy stopped without an answer (a crash, a signal).
    """
    return start_confined(step, *args, roots=roots, what=what, writable=writable, **kwargs)()


def start_confined(
    step: Callable[..., T],
    *args: Any,
    roots: Iterable[str | os.PathLike[str]],
    what: str,
    writable: Iterable[str | os.PathLike[str]] = (),
    **kwargs: Any,
) -> Callable[[], T]:
    """:func:`run_confined`, in two halves: the copy is made now, and the returned call
    waits for its answer (call it once). Start a copy before other threads run MuJoCo: a copy made
    while another thread holds one of MuJoCo's locks would wait for it for ever (the
    answer may then be waited for on any thread). Where confinement is off, the step
    runs when the call is made."""
    if _IN_COPY or not confinement().startswith("landlock"):
        return lambda: step(*args, **kwargs)  # confined already, or off
    readable = readable_roots(roots)
    for folder in writable:  # a rule needs the folder: make it as the step would
        Path(folder).mkdir(parents=True, exist_ok=True)
    staging = _Staging()
    parent = os.getpid()
    read_fd, write_fd = os.pipe()
    with warnings.catch_warnings():
        # The copy runs one step of Python code and ends with os._exit; it uses no
        # thread of the parent (callers start it before other threads run MuJoCo).
        warnings.simplefilter("ignore", DeprecationWarning)
        pid = os.fork()
    if pid == 0:  # pragma: no cover - the copy's code runs in another process
        die_with_parent(parent)  # never an orphan reader running on under PID 1
        os.close(read_fd)
        _child(write_fd, readable, [staging.path, *writable], _BUDGET.get(), step, args, kwargs)
    os.close(write_fd)
    budget = _BUDGET.get()
    return lambda: _answer(pid, read_fd, staging, what, budget)


def _answer(pid: int, read_fd: int, staging: _Staging, what: str, budget: tuple) -> Any:
    """The copy's answer: its result, or its exception raised here."""
    try:
        with os.fdopen(read_fd, "rb") as pipe:
            data = pipe.read()
        _, status = os.waitpid(pid, 0)
    except BaseException:
        with contextlib.suppress(OSError):
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
        raise
    if not data:
        raise ConfinementError(f"{what}: {_stopped(status, budget)}")
    global _ADOPTING
    with _ADOPTION_LOCK:
        _ADOPTING = staging
        try:
            kind, value, caught, mujoco_messages, side = pickle.loads(data)  # noqa: S301
        finally:
            _ADOPTING = None
            del data
    _replay(caught, mujoco_messages)
    _replay_side(side)
    if kind == "raise":
        raise _rebuilt(value)
    return value


def _stopped(status: int, budget: tuple[int, int]) -> str:
    """Why the copy ended without an answer, with the limit that ended it."""
    memory, cpu = budget
    if os.WIFSIGNALED(status):
        sig = os.WTERMSIG(status)
        if sig == signal.SIGXCPU:
            return (
                f"reading it ran past {cpu} s of CPU time; refused (a file declaring more "
                "work than a robot needs)"
            )
        return f"the confined reader stopped without an answer (signal {sig})"
    code = os.WEXITSTATUS(status)
    if code == _OUT_OF_MEMORY:
        return (
            f"reading it needed more than {memory / 10**6:,.0f} MB of memory; refused "
            "(--max-reader-mb raises the limit)"
        )
    return f"the confined reader stopped without an answer (exit {code})"


#: Exit status of a copy that ran out of its memory budget.
_OUT_OF_MEMORY = 71


def _child(
    write_fd: int,
    readable: list[Path],
    writable: list[Path],
    budget: tuple[int, int],
    step: Callable[..., Any],
    args: tuple[Any, ...],
    kwargs: dict[str, Any],
) -> None:  # pragma: no cover - runs in the forked copy
    """The forked copy: confine, run, answer, exit (never returns, never runs the
    parent's clean-up: ``os._exit``)."""
    global _IN_COPY
    _IN_COPY = True
    code = 0
    try:
        # Every temporary file or folder of the step (staged meshes, an expanded xacro)
        # is made in the staging folder, the one place the copy may write.
        import tempfile

        os.environ.setdefault("ROBOTWRIGHT_SYSTEM_TMP", tempfile.gettempdir())
        tempfile.tempdir = os.environ["TMPDIR"] = str(writable[0])  # workers it starts too
        # Ctrl-C reaches the whole process group: the parent decides and ends the copy.
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        mujoco_messages: list[str] = []
        mujoco = sys.modules.get("mujoco")
        if mujoco is not None and mujoco.get_mju_user_warning() is not None:
            # The parent gathers MuJoCo's warnings (the command line): gather them here
            # for its handler. Without one, MuJoCo issues Python warnings, replayed too.
            mujoco.set_mju_user_warning(lambda text: mujoco_messages.append(str(text)))
        side = _SideOutput()
        with warnings.catch_warnings(record=True) as caught:
            _limit_resources(budget)  # first: /proc is closed once confined
            try:
                restrict_self(readable, writable)
            except LandlockError as exc:
                raise ConfinementError(f"could not confine the reader: {exc}") from None
            try:
                payload: tuple[str, Any] = ("return", step(*args, **kwargs))
            except BaseException as exc:  # noqa: BLE001 - every exception goes back
                payload = ("raise", _portable(exc))
        side.close()
        if payload[0] == "raise" and _is_out_of_memory(payload[1]):
            os._exit(_OUT_OF_MEMORY)
        data = _dumps(payload, caught, mujoco_messages, side.taken())
        view = memoryview(data)
        while view:
            written = os.write(write_fd, view)
            view = view[written:]
    except MemoryError:
        code = _OUT_OF_MEMORY
    except BaseException:  # noqa: BLE001 - no answer: the parent reports the exit code
        code = 70
    finally:
        for stream in (sys.stdout, sys.stderr):  # what went to the terminal, out first
            with contextlib.suppress(Exception):
                stream.flush()
        os._exit(code)


def _silenced(logger: Any) -> bool:  # pragma: no cover - used in the forked copy
    """Whether the step silenced ``logger`` (its records reach only ``NullHandler``s and
    stop there, as :func:`robotwright.sources` does while a source is read): such records
    are not carried back, where the parent's handlers, or Python's last resort, would
    print them."""
    import logging

    node = logger
    while node is not None:
        if any(not isinstance(h, logging.NullHandler) for h in node.handlers):
            return False
        if not node.propagate:
            return bool(node.handlers)
        node = node.parent
    return False


class _SideOutput:  # pragma: no cover - used in the forked copy
    """What the step says besides its result, carried back to the parent: its log records
    (the parent's handlers show them: a command's own collectors live there) and, where
    the parent's stdout/stderr are not files (a test's capture), what it prints. Printing
    to a real file goes straight there, so progress lines still come as they happen."""

    def __init__(self) -> None:
        import io
        import logging

        self.records: list[Any] = []
        records = self.records

        def handle(logger: logging.Logger, record: logging.LogRecord) -> None:
            if not logger.disabled and logger.filter(record) and not _silenced(logger):
                records.append(record)

        logging.Logger.handle = handle  # type: ignore[method-assign]
        self.streams: dict[str, io.StringIO] = {}
        for name in ("stdout", "stderr"):
            stream = getattr(sys, name)
            try:
                stream.fileno()
            except Exception:  # noqa: BLE001 - in memory (io.UnsupportedOperation, ...)
                self.streams[name] = io.StringIO()
                setattr(sys, name, self.streams[name])

    def close(self) -> None:
        import logging

        del logging.Logger.handle  # the class's own method again (for what follows)

    def taken(self) -> dict[str, Any]:
        records = []
        for record in self.records:
            record.msg, record.args = record.getMessage(), None
            record.exc_info = record.exc_text = None
            records.append(record)
        return {
            "records": records,
            **{name: stream.getvalue() for name, stream in self.streams.items()},
        }


def _limit_resources(budget: tuple[int, int]) -> None:  # pragma: no cover - in the copy
    """Memory (address space beyond what is mapped now) and CPU time of the copy: the
    kernel ends it past either (SIGXCPU, or a failed allocation that MuJoCo and Python
    report as an error)."""
    import resource

    memory, cpu = budget
    mapped = _mapped_bytes()
    with contextlib.suppress(ValueError, OSError):
        if mapped:
            resource.setrlimit(resource.RLIMIT_AS, (mapped + memory, mapped + memory))
        resource.setrlimit(resource.RLIMIT_CPU, (cpu, cpu))


def _dumps(
    payload: tuple[str, Any], caught: list[Any], mujoco_messages: list[str], side: dict
) -> bytes:
    warnings_out = []
    for w in caught:
        message = w.message
        try:
            pickle.loads(pickle.dumps(message))
        except Exception:  # noqa: BLE001 - an unpicklable warning travels as its text
            message = str(message)
        warnings_out.append((message, w.category, w.filename, w.lineno))
    try:
        return _pickled((*payload, warnings_out, mujoco_messages, side))
    except Exception:  # noqa: BLE001 - the result could not travel: say so, as an error
        kind, value = payload
        error = value if kind == "raise" else None
        text = f"{error!r}" if error is not None else f"unpicklable result {type(value)!r}"
        fallback = ("raise", ("builtin", ConfinementError, (text,), {}))
        return pickle.dumps((*fallback, warnings_out, mujoco_messages, {}))


def _is_out_of_memory(portable: tuple) -> bool:
    """Whether the step failed for want of memory: Python's MemoryError, or MuJoCo's
    allocation failure (its messages say it could not allocate)."""
    _, cls, args, _ = portable
    if issubclass(cls, MemoryError):
        return True
    text = " ".join(str(a) for a in args).lower()
    return "could not allocate" in text or "bad_alloc" in text or "unknown exception" in text


def _pickled(value: Any) -> bytes:
    """``value`` pickled, a compiled MuJoCo model as its MJB bytes (MuJoCo's own
    format, several times faster both ways than the model's pickle)."""
    import io

    buffer = io.BytesIO()
    pickler = pickle.Pickler(buffer, protocol=pickle.HIGHEST_PROTOCOL)
    mujoco = sys.modules.get("mujoco")
    if mujoco is not None:
        pickler.dispatch_table = {mujoco.MjModel: _reduce_model}
    pickler.dump(value)
    return buffer.getvalue()


def _reduce_model(model: Any) -> tuple:
    import numpy as np

    mujoco = sys.modules["mujoco"]
    data = np.empty(mujoco.mj_sizeModel(model), dtype=np.uint8)
    mujoco.mj_saveModel(model, None, data)
    return (_model_from_mjb, (pickle.PickleBuffer(data),))


def _model_from_mjb(data: Any) -> Any:
    import mujoco

    return mujoco.MjModel.from_binary_path("model.mjb", {"model.mjb": bytes(data)})


def _portable(exc: BaseException) -> tuple[str, type, tuple, dict]:
    """An exception as its type, ``args`` and attributes: rebuilt without calling its
    ``__init__`` (our errors take keyword-only arguments that pickle would drop)."""
    state = dict(getattr(exc, "__dict__", {}))
    try:
        pickle.dumps((type(exc), exc.args, state))
    except Exception:  # noqa: BLE001
        return ("builtin", ConfinementError, (f"{type(exc).__name__}: {exc}",), {})
    return ("rebuilt", type(exc), exc.args, state)


def _rebuilt(value: tuple[str, type, tuple, dict]) -> BaseException:
    _, cls, args, state = value
    exc = cls.__new__(cls, *args)
    exc.args = args
    exc.__dict__.update(state)
    return exc


def _replay_side(side: dict) -> None:
    """The copy's log records through this process's loggers, and what it printed to a
    stream that was not a file, printed here."""
    import logging

    for record in side.get("records", ()):
        logger = logging.getLogger(record.name)
        if logger.isEnabledFor(record.levelno):
            logger.handle(record)
    for name in ("stdout", "stderr"):
        if side.get(name):
            getattr(sys, name).write(side[name])


def _replay(caught: list[tuple[Any, type, str, int]], mujoco_messages: list[str]) -> None:
    for message, category, filename, lineno in caught:
        warnings.warn_explicit(message, category, filename, lineno)
    if mujoco_messages and "mujoco" in sys.modules:
        handler = sys.modules["mujoco"].get_mju_user_warning()
        for text in mujoco_messages:
            if handler is not None:
                handler(text)
            else:  # the handler went while the copy ran: as MuJoCo's own default does
                warnings.warn(text, UserWarning, stacklevel=3)
