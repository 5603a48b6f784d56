"""Size caps on the asset files a model makes MuJoCo read, checked before it reads them.

MuJoCo reads the mesh (STL, OBJ, MSH), height field (PNG, binary) and texture files a
model names itself, with no size limit, and allocates what a model declares: a 600 MB
sparse STL is read for seconds before MuJoCo says it is no mesh, a 400 KB PNG can
declare a 20,000 x 20,000 image (1.6 GB once decoded), and ``<hfield nrow="50000"
ncol="50000"/>`` asks for 10 GB. Every reader that hands a file-backed model to MuJoCo
(:func:`robotwright._paths.check_mjcf_spec` for MJCF, ``HRDF.mesh_source`` for HRDF
mesh rows, :func:`robotwright.parsers.packages.resolve_uri` for URDF meshes) calls
:func:`check_asset_file` on each file, and :func:`check_declared_sizes` on the model's
spec, so that one limit applies: the one mesh and asset files copied into an output
already have (:func:`robotwright._atomic.mesh_size_limit`, ``--max-mesh-mb``, 512 MB
by default).

What counts against the limit, in bytes:

- a file: its size on disk (``stat``; a sparse file counts at its apparent size);
- a PNG image (height field or texture): width x height x 4 (the decoded samples, read
  from the image header, 33 bytes, before anything is decoded);
- a height field declared by ``nrow`` x ``ncol``: 4 bytes a sample (MuJoCo stores
  ``float32``);
- a built-in texture (``builtin=...``): width x height x 3 for a 2-D texture, width x
  width x 6 x 3 for a cube or skybox (MuJoCo makes six square faces).
"""

from __future__ import annotations

import os
import stat
import struct
from pathlib import Path
from typing import Any

from robotwright.errors import InputFileError

__all__ = ["check_asset_file", "check_declared_sizes", "mesh_limit_bytes"]

_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
#: signature (8), chunk length (4), ``IHDR`` (4), width (4), height (4)
_PNG_HEADER = 24
_FLAG = "--max-mesh-mb raises it; robotwright.mesh_size_limit(MB) in Python"


def mesh_limit_bytes() -> int:
    """The current limit on a mesh or asset file, in bytes (see
    :func:`robotwright._atomic.mesh_size_limit`)."""
    from robotwright._atomic import _MESH_LIMIT

    return _MESH_LIMIT.get()


def _mb(n: int) -> str:
    return f"{n / 10**6:g} MB"


def _refusal(path: object, what: str, limit: int) -> InputFileError:
    return InputFileError(
        path,
        f"is larger than the {_mb(limit)} limit for a mesh or asset file a model reads: "
        f"{what} ({_FLAG})",
    )


def _declared(where: object, what: str, limit: int) -> InputFileError:
    return InputFileError(
        where,
        f"declares {what}, more than the {_mb(limit)} limit for a mesh or asset a model reads "
        f"({_FLAG})",
    )


def check_asset_file(path: str | os.PathLike[str], *, image: bool = True) -> Path:
    """``path`` when the file MuJoCo will read there is within the limit (a missing file
    or one that is not a regular file passes: its reader, or
    :func:`robotwright._paths.check_regular`, reports it).

    Only ``stat`` is asked for the size; of a PNG image, the 24-byte header is read for
    the image size. ``image=False`` (a mesh file, which MuJoCo never decodes as an
    image) skips opening it for that header.

    Raises:
        robotwright.errors.InputFileError: naming the file, its size and the limit.
    """
    path = Path(path)
    try:
        st = path.stat()
    except (OSError, ValueError):
        return path
    if not stat.S_ISREG(st.st_mode):
        return path
    limit = mesh_limit_bytes()
    if st.st_size > limit:
        raise _refusal(path, f"{st.st_size:,} bytes", limit)
    size = _png_size(path) if image else None
    if size is not None:
        width, height = size
        decoded = width * height * 4
        if decoded > limit:
            raise _declared(
                path,
                f"a {width:,} x {height:,} image ({decoded:,} bytes once decoded, at 4 bytes "
                "a pixel)",
                limit,
            )
    return path


def _png_size(path: Path) -> tuple[int, int] | None:
    """(width, height) from a PNG file's header, or None when it is not a PNG."""
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except OSError:
        return None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):  # replaced since the stat above
            return None
        head = os.read(fd, _PNG_HEADER)
    except OSError:
        return None
    finally:
        os.close(fd)
    if len(head) < _PNG_HEADER or not head.startswith(_PNG_SIGNATURE) or head[12:16] != b"IHDR":
        return None
    width, height = struct.unpack(">II", head[16:24])
    return width, height


def _builtin(value: Any) -> bool:
    """Whether a texture's ``builtin`` is set (``mjBUILTIN_NONE`` is 0 in every
    MuJoCo this supports; older bindings give an int-like enum)."""
    try:
        return int(value) != 0
    except (TypeError, ValueError):
        return False


def check_declared_sizes(spec: Any, *, source: str) -> None:
    """Refuse a ``mujoco.MjSpec`` whose height fields or built-in textures declare more
    data than the limit, before it is compiled.

    Raises:
        robotwright.errors.InputFileError: naming ``source``, the element, what it
            declares and the limit.
    """
    import mujoco

    limit = mesh_limit_bytes()
    for hf in getattr(spec, "hfields", []):
        if hf.file:
            continue  # the file's size (and a PNG's header) is checked with the file
        nrow, ncol = int(hf.nrow), int(hf.ncol)
        need = max(nrow, 0) * max(ncol, 0) * 4
        if need > limit:
            raise _declared(
                f'{source}: <hfield name="{hf.name}">',
                f"nrow x ncol = {nrow:,} x {ncol:,} samples ({need:,} bytes at 4 bytes a sample)",
                limit,
            )
    square = {int(mujoco.mjtTexture.mjTEXTURE_CUBE), int(mujoco.mjtTexture.mjTEXTURE_SKYBOX)}
    for tex in getattr(spec, "textures", []):
        if not _builtin(tex.builtin):
            continue
        width, height = int(tex.width), int(tex.height)
        cube = int(tex.type) in square
        need = max(width, 0) * (max(width, 0) * 6 if cube else max(height, 0)) * 3
        if need > limit:
            shape = f"6 faces of {width:,} x {width:,}" if cube else f"{width:,} x {height:,}"
            raise _declared(
                f'{source}: <texture name="{tex.name}">',
                f"a built-in texture of {shape} texels ({need:,} bytes at 3 bytes a texel)",
                limit,
            )
