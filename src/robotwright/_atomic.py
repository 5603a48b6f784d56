"""All-or-nothing file and folder writing: write to a temporary name, then rename.

Readers never see a partial file, and a failed write (an exception, Ctrl-C, a full disk)
leaves neither the temporary nor a half-written target nor a new empty folder behind; an
existing target is only replaced once the new content is complete. The temporary lives
in the target's folder so that the final rename stays on one file system
(``os.replace`` is atomic there).

Outputs made of several files (a model and its copied meshes) are written into a hidden
staging folder next to them and moved into place only when all are complete
(:func:`atomic_files`). A process killed outright (``kill -9``) cannot clean up: its
temporaries carry its process id, and the next write into the same folder removes those
of processes that no longer run.

Outputs get the user's normal permissions (``0o666`` for files and ``0o777`` for folders,
less the umask), not the private ``0o600``/``0o700`` of Python's temporary files.

A write that fails for lack of space (or a read-only or quota-limited file system)
raises :class:`~robotwright.errors.OutputPathError` naming the output, not the source.

Writers never follow a symbolic link they did not create: staged files are moved into
the output through folders opened without following links (a link planted at
``out/meshes`` is refused, not written through), and a link at an output's own name is
replaced, not followed. A folder written with a ``kind`` gets the marker of
:mod:`robotwright._outputs` and replaces only an earlier output of that kind. Mesh and
asset files copied into an output are limited in size (:func:`mesh_size_limit`).
"""

from __future__ import annotations

import errno
import os
import re
import secrets
import shutil
import stat
import tempfile
from collections.abc import Iterator
from contextlib import AbstractContextManager, contextmanager, suppress
from contextvars import ContextVar
from pathlib import Path
from typing import IO, Any

from robotwright._limits import limit_for_block, megabytes
from robotwright._temporaries import remove_entry, running
from robotwright.errors import InputFileError, OutputPathError

__all__ = [
    "atomic_dir",
    "atomic_files",
    "atomic_open",
    "atomic_path",
    "check_output_path",
    "copy_file_atomic",
    "copy_mesh_file",
    "mesh_size_limit",
    "write_text_atomic",
]

#: errors of the output side of a write: no space, no quota, too big, read-only.
WRITE_ERRNOS = frozenset(
    {errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EROFS}
    | ({errno.ENOTSUP} if hasattr(errno, "ENOTSUP") else set())
)
#: name of a temporary made here: ``.<target name>.<pid>.<8 random characters>[.tmp]``.
_TEMP_NAME = re.compile(r"^\.(?P<target>.+)\.(?P<pid>\d+)\.[a-z0-9_]{8}(\.tmp)?$")
_STAGE = "rw-stage"
#: Default largest mesh (or other asset) file copied into an output, in MB (10**6 bytes).
DEFAULT_MAX_MESH_MB = 512
_MESH_LIMIT: ContextVar[int] = ContextVar("mesh_limit", default=DEFAULT_MAX_MESH_MB * 10**6)
_NOFOLLOW_DIR = os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW if hasattr(os, "O_NOFOLLOW") else 0


@contextmanager
def mesh_size_limit(mb: float | None) -> Iterator[None]:
    """Within the block, mesh and asset files of at most ``mb`` megabytes (10**6 bytes)
    are copied into outputs and read by models (``None``: the default,
    :data:`DEFAULT_MAX_MESH_MB`); a larger file, or a height field or image declaring more
    data (see :mod:`robotwright._assets`), raises
    :class:`~robotwright.errors.InputFileError` naming it and the limit.

    Example::

        with robotwright.mesh_size_limit(2000):  # a 1.5 GB scan mesh
            robot = HRDF.from_dir("big_robot")
    """
    with limit_for_block(_MESH_LIMIT, megabytes(mb, "mesh size limit")):
        yield


def _too_big(src: object, limit: int) -> InputFileError:
    return InputFileError(
        src,
        f"is larger than the {limit / 10**6:g} MB limit for a mesh or asset file copied "
        "into an output (--max-mesh-mb raises it)",
    )


def copy_mesh_file(src: str | os.PathLike[str], dst: str | os.PathLike[str]) -> None:
    """Copy the regular file ``src`` to ``dst`` when it is within the mesh size limit
    (:func:`mesh_size_limit`; checked before a byte is written, and again while copying
    in case the file grows). A FIFO or device is refused unread."""
    from robotwright._inputs import _open_regular

    limit = _MESH_LIMIT.get()
    fd, st = _open_regular(src)
    with os.fdopen(fd, "rb") as fin:
        if st.st_size > limit:
            raise _too_big(src, limit)
        with open(dst, "wb") as fout:
            shutil.copyfileobj(_Capped(fin, limit, src), fout, 1 << 20)


class _Capped:
    """A reader of at most ``limit`` bytes: reading more raises the size error."""

    def __init__(self, fin: IO[bytes], limit: int, src: object) -> None:
        self.fin, self.left, self.src, self.limit = fin, limit, src, limit

    def read(self, n: int = -1) -> bytes:
        chunk = self.fin.read(n)
        self.left -= len(chunk)
        if self.left < 0:
            raise _too_big(self.src, self.limit)
        return chunk


def check_output_path(path: str | os.PathLike[str], *, folder: bool = False) -> None:
    """Raise :class:`OutputPathError` when ``path`` cannot become a file (or a folder).

    Catches, before any work is done, the mistakes that would otherwise surface as a
    bare ``OSError`` half-way through: a file output that is an existing folder, and a
    parent path one of whose components is a file. A missing parent folder is fine
    (writers create it).
    """
    path = Path(path)
    if not folder and path.is_dir():
        raise OutputPathError(f"{path}: is a folder; expected the path of a file to write")
    for parent in path.parents:
        if parent.exists():
            if not parent.is_dir():
                raise OutputPathError(f"{path}: cannot create it: {parent} is a file, not a folder")
            break


@contextmanager
def _naming_output(
    path: str | os.PathLike[str], *, source: str | os.PathLike[str] | None = None
) -> Iterator[None]:
    """Raise an error of the output side (:data:`WRITE_ERRNOS`: no space, no quota, too
    big, read-only) from the block as an :class:`OutputPathError` naming ``path`` (and
    ``source`` for a copy); other errors, and an :class:`OutputPathError`, pass as they
    are."""
    try:
        yield
    except OSError as exc:
        if isinstance(exc, OutputPathError) or exc.errno not in WRITE_ERRNOS:
            raise
        copying = f" (copying {source})" if source is not None else ""
        raise OutputPathError(f"{path}: cannot write it: {exc.strerror or exc}{copying}") from exc


def _umask() -> int:
    """The process umask, read without changing it where the system tells it
    (``os.umask`` can only be read by setting it, which races with other threads)."""
    try:
        with open("/proc/self/status", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def remove_stale_temporaries(folder: str | os.PathLike[str], target: str) -> None:
    """Remove the temporaries for ``target`` in ``folder`` left by killed processes."""
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return
    for entry in entries:
        match = _TEMP_NAME.match(entry.name)
        if match is None or match["target"] != target or running(int(match["pid"])):
            continue
        remove_entry(entry)


def _restore_moved_aside(target: Path) -> None:
    """Put back an old ``target`` that a killed :func:`atomic_dir` had moved aside (it is
    killed between its two renames) before that process's temporaries are removed."""
    if target.exists() or target.is_symlink():
        return
    try:
        entries = list(os.scandir(target.parent))
    except OSError:
        return
    for entry in entries:
        match = _TEMP_NAME.match(entry.name)
        if (
            match is not None
            and match["target"] == target.name
            and entry.is_dir(follow_symlinks=False)
            and not running(int(match["pid"]))
            and os.path.lexists(os.path.join(entry.path, "x"))
        ):
            os.replace(os.path.join(entry.path, "x"), target)
            return


def _prefix(name: str) -> str:
    return f".{name}.{os.getpid()}."


def _make_parents(folder: Path) -> list[Path]:
    """Create ``folder`` and its missing parents; return the ones created, deepest first."""
    created: list[Path] = []
    p = folder
    while not p.exists():
        created.append(p)
        if p.parent == p:
            break
        p = p.parent
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        _remove_empty(created)
        raise OutputPathError(f"{folder}: cannot create the folder: {exc.strerror or exc}") from exc
    return created


def _remove_empty(folders: list[Path]) -> None:
    for p in folders:  # deepest first
        try:
            p.rmdir()
        except OSError:
            break


def _mkstemp(path: Path) -> str:
    """Create an empty temporary file for ``path`` in its folder and return its name.

    It is created with mode 0666 less the umask, as any file the user writes (the
    kernel applies the umask), under a random name that :data:`_TEMP_NAME` matches."""
    remove_stale_temporaries(path.parent, path.name)
    prefix = os.path.join(path.parent, _prefix(path.name))
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0)
    for _ in range(100):
        tmp = f"{prefix}{secrets.token_hex(4)}.tmp"
        try:
            os.close(os.open(tmp, flags, 0o666))
        except FileExistsError:
            continue
        except OSError as exc:
            raise OutputPathError(
                f"{path}: cannot write in folder {path.parent}: {exc.strerror or exc}"
            ) from exc
        return tmp
    raise OutputPathError(f"{path}: no free temporary file name in folder {path.parent}")


@contextmanager
def _new_file(path: str | os.PathLike[str], *, make_parents: bool = False) -> Iterator[Path]:
    """:func:`atomic_path`; with ``make_parents`` the folder of ``path`` is created first
    (and the folders created are removed again when the block fails)."""
    path = Path(path)
    check_output_path(path)
    created = _make_parents(path.parent) if make_parents else []
    try:
        with _naming_output(path):
            tmp = _mkstemp(path)
            try:
                yield Path(tmp)
                os.replace(tmp, path)
            except BaseException:
                if os.path.exists(tmp):
                    os.unlink(tmp)
                raise
    except BaseException:
        _remove_empty(created)
        raise


def atomic_path(path: str | os.PathLike[str]) -> AbstractContextManager[Path]:
    """Yield an empty temporary file next to ``path``; on success rename it onto ``path``.

    The caller writes the temporary by name (for writers that only take a path).
    On any exception the temporary is removed and ``path`` is left as it was; a full
    disk raises :class:`OutputPathError` naming ``path``. The folder of ``path`` must
    exist.
    """
    return _new_file(path)


@contextmanager
def atomic_open(path: str | os.PathLike[str], mode: str = "w") -> Iterator[IO[Any]]:
    """Open a temporary file next to ``path`` for writing (``"w"`` UTF-8 text or ``"wb"``);
    it is renamed onto ``path`` when the block ends without an exception."""
    if mode not in ("w", "wb"):
        raise ValueError(f"atomic_open: mode must be 'w' or 'wb', got {mode!r}")
    encoding = "utf-8" if mode == "w" else None
    with atomic_path(path) as tmp, open(tmp, mode, encoding=encoding) as fh:
        yield fh


def write_bytes_atomic(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path``, creating its folder; see :func:`atomic_path`.
    Folders it created are removed again when the write fails."""
    with _new_file(path, make_parents=True) as tmp, open(tmp, "wb") as fh:
        fh.write(data)


def write_text_atomic(path: Path, text: str) -> None:
    """Write ``text`` (UTF-8, line ends as given) to ``path``; see
    :func:`write_bytes_atomic`."""
    write_bytes_atomic(path, text.encode("utf-8"))


def _copy(src: Path, tmp: Path, dst: Path) -> None:
    with _naming_output(dst, source=src):
        copy_mesh_file(src, tmp)


def copy_file_atomic(src: Path, dst: Path) -> None:
    """Copy ``src`` to ``dst``, creating its folder; see :func:`atomic_path`.

    Only a regular file is copied: a FIFO or a device as ``src`` raises
    :class:`~robotwright.errors.InputFileError` before anything is read or written.
    """
    with _new_file(dst, make_parents=True) as tmp:
        _copy(src, tmp, dst)


class StagedFiles:
    """The files of one output, written under a staging folder, moved into place at once.

    Use through :func:`atomic_files`. Paths are relative to the output folder.
    """

    def __init__(self, out_dir: Path, stage: Path) -> None:
        self.out_dir = out_dir
        self.stage = stage
        self._files: list[str] = []

    def path(self, rel: str | os.PathLike[str]) -> Path:
        """The staging path to write for ``out_dir/rel`` (its folder is created)."""
        rel_path = Path(rel)
        if rel_path.is_absolute() or ".." in rel_path.parts:
            raise ValueError(f"staged output path {rel!s} must stay inside {self.out_dir}")
        _check_folders(self.out_dir, rel_path.parts[:-1])  # refused before any work
        target = self.stage / rel_path
        target.parent.mkdir(parents=True, exist_ok=True)
        self._files.append(str(rel_path))
        return target

    def write_text(self, rel: str | os.PathLike[str], text: str) -> None:
        """Stage ``text`` (UTF-8) as ``out_dir/rel``."""
        staged = self.path(rel)
        with _naming_output(self.out_dir / rel):
            staged.write_text(text, encoding="utf-8")

    def copy(self, src: Path, rel: str | os.PathLike[str]) -> None:
        """Stage a copy of the regular file ``src`` as ``out_dir/rel`` (refused before
        anything is copied when it would replace a different file and the overwrite rule
        forbids it: :func:`robotwright._outputs.check_copy_destination`)."""
        from robotwright._outputs import check_copy_destination

        staged = self.path(rel)  # refuses a link among the output's folders first
        check_copy_destination(self.out_dir / rel, src)
        _copy(src, staged, self.out_dir / rel)

    def _commit(self) -> None:
        """Move every staged file onto its place, in the order staged (the caller stages
        the file that names the others last, so it appears last). Every destination is
        checked before the first move; the moves go through folders opened without
        following links, so a link planted meanwhile is not written through either."""
        files = list(dict.fromkeys(self._files))
        for rel in files:
            check_output_path(self.out_dir / rel)
            _check_folders(self.out_dir, Path(rel).parts[:-1])
        for rel in files:
            parts = Path(rel).parts
            if not _NOFOLLOW_DIR or os.rename not in os.supports_dir_fd:
                (self.out_dir / rel).parent.mkdir(parents=True, exist_ok=True)
                os.replace(self.stage / rel, self.out_dir / rel)
                continue
            fd = _open_folder_inside(self.out_dir, parts[:-1])
            try:
                os.replace(self.stage / rel, parts[-1], dst_dir_fd=fd)
            finally:
                os.close(fd)


def _check_folders(out_dir: Path, parts: tuple[str, ...]) -> None:
    """Raise :class:`OutputPathError` when a folder ``out_dir/parts[0]/...`` that exists
    is a symbolic link or not a folder: files are never written through it."""
    p = out_dir
    for part in parts:
        p = p / part
        try:
            mode = os.lstat(p).st_mode
        except FileNotFoundError:
            return
        if stat.S_ISLNK(mode):
            raise OutputPathError(
                f"{p}: is a symbolic link; not writing the output through it (remove it, "
                "or give another output folder)"
            )
        if not stat.S_ISDIR(mode):
            raise OutputPathError(f"{p}: is a file; expected a folder for the output's files")


def _open_folder_inside(out_dir: Path, parts: tuple[str, ...]) -> int:
    """A descriptor of the folder ``out_dir/parts...``, each part opened without
    following a link (created when missing)."""
    fd = os.open(out_dir, os.O_RDONLY | os.O_DIRECTORY)
    p = out_dir
    try:
        for part in parts:
            p = p / part
            with suppress(FileExistsError):
                os.mkdir(part, 0o777, dir_fd=fd)
            try:
                child = os.open(part, _NOFOLLOW_DIR, dir_fd=fd)
            except OSError as exc:
                if exc.errno in (errno.ELOOP, errno.ENOTDIR):
                    _check_folders(p.parent, (part,))
                raise
            os.close(fd)
            fd = child
    except BaseException:
        os.close(fd)
        raise
    return fd


@contextmanager
def atomic_files(out_dir: str | os.PathLike[str]) -> Iterator[StagedFiles]:
    """Write several files of ``out_dir`` all or nothing.

    The block stages each file (``staged.write_text(rel, ...)``, ``staged.copy(src,
    rel)``, or writes ``staged.path(rel)`` itself) in a hidden folder inside
    ``out_dir``; when the block succeeds the files are renamed into place (existing
    files of the same names are replaced, others are left alone). On any exception
    nothing of ``out_dir`` changes, and folders created for it are removed.
    """
    out_dir = Path(out_dir)
    check_output_path(out_dir, folder=True)
    created = _make_parents(out_dir)
    remove_stale_temporaries(out_dir, _STAGE)
    try:
        stage = Path(tempfile.mkdtemp(prefix=_prefix(_STAGE), dir=out_dir))
    except OSError as exc:
        _remove_empty(created)
        raise OutputPathError(f"{out_dir}: cannot write in it: {exc.strerror or exc}") from exc
    staged = StagedFiles(out_dir, stage)
    try:
        yield staged
        staged._commit()
    except BaseException:
        shutil.rmtree(stage, ignore_errors=True)
        _remove_empty(created)
        raise
    shutil.rmtree(stage, ignore_errors=True)


@contextmanager
def atomic_dir(target: str | os.PathLike[str], *, kind: str | None = None) -> Iterator[Path]:
    """Yield an empty temporary folder next to ``target``; on success it becomes ``target``.

    An existing ``target`` (file or folder) is replaced only after the block succeeded;
    callers decide beforehand whether replacing is allowed. On any exception the
    temporary folder is removed and ``target`` is left as it was. Creates the parent
    folder (removed again on failure when it was created here).

    With ``kind`` (``"hrdf"``, ``"design"``, ``"designs"``, ``"demo"``) the folder gets
    the marker of :mod:`robotwright._outputs`, and an existing ``target`` is replaced only
    when it is empty or an earlier output of that kind holding nothing else (checked
    before the block and again before the replacement): anything else raises
    :class:`~robotwright.errors.OutputExistsError` and nothing is written.
    """
    from robotwright._outputs import check_folder_output, write_marker

    target = Path(target)
    check_output_path(target, folder=True)
    if kind is not None:
        check_folder_output(target, kind, overwrite=True)
    created = _make_parents(target.parent)
    _restore_moved_aside(target)
    remove_stale_temporaries(target.parent, target.name)
    try:
        tmp = Path(tempfile.mkdtemp(prefix=_prefix(target.name), dir=target.parent))
        # mkdtemp makes the folder private (0700); the output is an ordinary folder.
        tmp.chmod(0o777 & ~_umask())
    except OSError as exc:
        _remove_empty(created)
        raise OutputPathError(
            f"{target}: cannot create a folder in {target.parent}: {exc.strerror or exc}"
        ) from exc
    try:
        with _naming_output(target):
            yield tmp
            if kind is not None:
                write_marker(tmp, kind)
                check_folder_output(target, kind, overwrite=True)  # changed meanwhile?
            if target.exists() or target.is_symlink():
                # Move the old one aside first: os.replace cannot overwrite a non-empty
                # folder. (Killed between the two renames, the next atomic_dir puts it back.)
                old = Path(tempfile.mkdtemp(prefix=_prefix(target.name), dir=target.parent))
                os.replace(target, old / "x")
                os.replace(tmp, target)
                shutil.rmtree(old, ignore_errors=True)
            else:
                os.replace(tmp, target)
    except BaseException as exc:
        shutil.rmtree(tmp, ignore_errors=True)
        _remove_empty(created)
        if isinstance(exc, OutputPathError) and str(tmp) in str(exc):
            # A file inside the folder failed: name it where the user will look for it.
            raise OutputPathError(str(exc).replace(str(tmp), str(target))) from exc
        raise
