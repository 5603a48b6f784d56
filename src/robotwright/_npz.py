"""Reading a ``.npz`` file (a scan) from an untrusted source with a cap on the memory
its arrays take once loaded.

An ``.npz`` is a zip of ``.npy`` arrays. A few megabytes of deflated zeros can declare
gigabytes of array, which ``numpy.load`` allocates before reading a byte of it. Here
each entry's declared size (zip directory) and each array's declared shape and dtype
(``.npy`` header) are read first, and the file is refused unless their total fits the
limit; arrays holding Python objects (pickles) are refused always.

The limit is :data:`MAX_NPZ_BYTES` unless a caller changes it for the current context
with :func:`npz_limit` (the command line's ``--max-scan-mb``).
"""

from __future__ import annotations

import contextlib
import contextvars
import math
import os
import zipfile
from collections.abc import Collection, Iterator
from typing import TYPE_CHECKING

from robotwright._inputs import _open_regular
from robotwright._limits import limit_for_block, megabytes
from robotwright.errors import InputFileError

if TYPE_CHECKING:
    import numpy as np

__all__ = ["MAX_NPZ_BYTES", "load_npz", "npz_limit"]

#: Largest total size of the arrays of one ``.npz`` once loaded [bytes] (1,000 MB: about
#: 40 million scan points with their labels).
MAX_NPZ_BYTES = 1000 * 10**6

_LIMIT: contextvars.ContextVar[int] = contextvars.ContextVar("npz_limit", default=MAX_NPZ_BYTES)


@contextlib.contextmanager
def npz_limit(mb: float | None) -> Iterator[None]:
    """Within the block, :func:`load_npz` accepts arrays of up to ``mb`` megabytes
    (10**6 bytes) in total once loaded (``None``: the default, :data:`MAX_NPZ_BYTES`)."""
    with limit_for_block(_LIMIT, megabytes(mb, "scan size limit")):
        yield


# What reading one damaged, encrypted or oddly compressed entry can raise.
_ENTRY_ERRORS = (
    ValueError,
    OSError,
    EOFError,
    RuntimeError,
    zipfile.BadZipFile,
)


def _mb(n: float) -> str:
    return f"{n / 10**6:,.1f} MB"


def _declared_bytes(archive: zipfile.ZipFile, info: zipfile.ZipInfo, path: object) -> int:
    """The memory the array in entry ``info`` takes once loaded, from its ``.npy`` header."""
    import numpy as np

    try:
        with archive.open(info) as fp:
            version = np.lib.format.read_magic(fp)
            if version == (1, 0):
                shape, _, dtype = np.lib.format.read_array_header_1_0(fp)
            else:
                shape, _, dtype = np.lib.format.read_array_header_2_0(fp)
    except _ENTRY_ERRORS as exc:
        raise InputFileError(
            path, f"has an entry {info.filename!r} that is not a .npy array ({exc})"
        ) from None
    if dtype.hasobject:
        raise InputFileError(
            path, f"has an entry {info.filename!r} holding Python objects (a pickle); refused"
        )
    return math.prod(shape) * dtype.itemsize


def load_npz(
    path: str | os.PathLike[str], names: Collection[str] | None = None
) -> dict[str, np.ndarray]:
    """The arrays of the ``.npz`` file ``path`` by name (``"points"`` for the entry
    ``points.npy``), once their declared sizes are known to fit the limit. With
    ``names``, only the arrays of those names that the file holds (others are not read).

    Raises:
        InputFileError: not a regular file, not a zip of ``.npy`` arrays, an array of
            Python objects, or arrays larger in total than the limit (the message gives
            the sizes and the limit).
        OSError: the file cannot be opened.
    """
    import numpy as np

    limit = _LIMIT.get()
    fd, _ = _open_regular(path)
    with os.fdopen(fd, "rb") as raw:
        try:
            archive = zipfile.ZipFile(raw)
        except (zipfile.BadZipFile, ValueError) as exc:
            raise InputFileError(path, f"is not a .npz (zip) file: {exc}") from None
        with archive:
            infos = [i for i in archive.infolist() if names is None or _name(i) in names]
            # The zip directory's sizes bound what reading can produce (zipfile stops at
            # the declared size and checks the CRC), the .npy headers what numpy allocates.
            total = sum(i.file_size for i in infos)
            if total > limit:
                raise InputFileError(path, _too_large(total, limit))
            declared = 0
            for info in infos:
                declared += _declared_bytes(archive, info, path)
                if declared > limit:
                    raise InputFileError(path, _too_large(declared, limit))
            arrays: dict[str, np.ndarray] = {}
            for info in infos:
                try:
                    with archive.open(info) as fp:
                        arrays[_name(info)] = np.lib.format.read_array(fp, allow_pickle=False)
                except _ENTRY_ERRORS as exc:
                    raise InputFileError(
                        path, f"has an entry {info.filename!r} that cannot be read: {exc}"
                    ) from None
    return arrays


def _name(info: zipfile.ZipInfo) -> str:
    return info.filename[:-4] if info.filename.endswith(".npy") else info.filename


def _too_large(size: int, limit: int) -> str:
    return (
        f"holds {_mb(size)} of arrays once loaded: larger than the {_mb(limit)} limit "
        "for a scan (--max-scan-mb raises it)"
    )
