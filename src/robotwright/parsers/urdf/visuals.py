"""Visual-only geoms that MuJoCo cannot build, found before they reach an MJCF.

MuJoCo's URDF import discards visuals, so a URDF may carry visual geometry MuJoCo cannot
build: primitives without volume (a sphere of radius 0 marking a point) and meshes it
refuses (a flat plane, whose volume is zero; an OBJ with broken normal indices). Our MJCF
keeps visuals, so each is kept where MuJoCo can build it and otherwise dropped with a
warning naming it: never an MJCF that does not compile.

- A primitive with a size MuJoCo needs at 0 (or below) is dropped: it draws nothing.
- A mesh is compiled alone by MuJoCo. One refused for its volume ("mesh volume is too
  small") is kept with ``inertia="shell"`` (MuJoCo then uses its area; a visual geom
  carries no mass here, the body's inertial is explicit); one refused otherwise (an OBJ
  with out-of-range normal indices) is rewritten with trimesh (triangles kept, normals
  and texture coordinates dropped) when a ``rewrite`` function is given and MuJoCo
  builds the copy; else it is dropped.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from xml.sax.saxutils import quoteattr

import mujoco

from robotwright.hrdf.model import MeshGeom, SimpleGeom
from robotwright.parsers.report import Reporter

__all__ = ["drop_unbuildable_visuals"]

#: Size values MuJoCo uses per primitive type.
_SIZE_USED = {"sphere": 1, "capsule": 2, "cylinder": 2, "box": 3, "ellipsoid": 3}


def _visual(g: MeshGeom | SimpleGeom) -> bool:
    return not g.contact_type and not g.contact_affinity


def _mesh_error(file: Path, scale: tuple[float, float, float], inertia: str | None) -> str:
    """MuJoCo's first error line compiling this mesh alone, on a geom that does not
    collide (as our MJCF writes visuals); empty when it compiles."""
    attrs = f'file={quoteattr(str(file))} scale="{" ".join(map(repr, scale))}"'
    if inertia:
        attrs += f' inertia="{inertia}"'
    xml = (
        f'<mujoco><asset><mesh name="m" {attrs}/></asset>'
        '<worldbody><body><geom type="mesh" mesh="m" contype="0" conaffinity="0"/>'
        "</body></worldbody></mujoco>"
    )
    try:
        mujoco.MjModel.from_xml_string(xml)
    except ValueError as exc:
        return str(exc).splitlines()[0]
    return ""


def _buildable(root: Path, file: str, scale, inertia: str | None) -> tuple[str | None, str]:
    """(inertia mode MuJoCo builds the mesh with, or None when it cannot; its error)."""
    err = _mesh_error(root / file, scale, inertia)
    if not err:
        return inertia or "", ""
    if "volume" in err and not _mesh_error(root / file, scale, "shell"):
        return "shell", err
    return None, err


def drop_unbuildable_visuals(
    meshes: list[MeshGeom],
    simple: list[SimpleGeom],
    root: Path,
    rep: Reporter,
    rewrite: Callable[[str], str] | None = None,
) -> tuple[list[MeshGeom], list[SimpleGeom]]:
    """The geom tables without visual geoms MuJoCo cannot build (each reported), with
    ``inertia="shell"`` on visual meshes that MuJoCo builds only so, and rewritten files
    (``rewrite(rel) -> new rel``) for those it cannot decode. ``root`` is the folder the
    mesh files are relative to."""
    kept_simple = []
    for g in simple:
        used = g.size[: _SIZE_USED.get(g.type, 3)]
        if _visual(g) and any(not v > 0 for v in used):
            rep.warn(
                f"visual {g.type} of size {tuple(used)} on body '{g.body}' dropped (no volume: "
                "MuJoCo cannot build it, and it draws nothing)",
                f"<visual> {g.geom_name or ''}".rstrip(),
            )
            continue
        kept_simple.append(g)
    verdicts: dict[tuple[str, tuple[float, float, float]], tuple[str | None, str | None, str]] = {}
    kept_meshes = []
    for g in meshes:
        if not _visual(g) or g.file is None:
            kept_meshes.append(g)
            continue
        key = (g.file, tuple(g.scale))
        if key not in verdicts:
            verdicts[key] = _verdict(g, root, rep, rewrite)
        file, inertia, err = verdicts[key]
        if file is None:
            rep.warn(
                f"visual mesh '{g.file}' on body '{g.body}' dropped: MuJoCo cannot build it ({err})"
            )
            continue
        if (file, inertia) != (g.file, g.inertia):
            g = replace(g, file=file, inertia=inertia)
        kept_meshes.append(g)
    return kept_meshes, kept_simple


def _verdict(
    g: MeshGeom, root: Path, rep: Reporter, rewrite: Callable[[str], str] | None
) -> tuple[str | None, str | None, str]:
    """(file to use or None to drop, inertia mode, MuJoCo's error) for a visual mesh."""
    mode, err = _buildable(root, g.file, g.scale, g.inertia)
    if mode is not None:
        if err:
            rep.warn(
                f"visual mesh '{g.file}': {err}; kept with inertia='shell' (a visual mesh "
                "carries no mass here)"
            )
        return g.file, mode or None, err
    if rewrite is None or "volume" in err:
        return None, None, err
    try:
        new = rewrite(g.file)
    except Exception as exc:  # noqa: BLE001 - an unreadable file is dropped, reported
        return None, None, f"{err}; trimesh cannot read it either: {exc}"
    mode, err2 = _buildable(root, new, g.scale, g.inertia)
    if mode is None:
        return None, None, err
    rep.warn(
        f"visual mesh '{g.file}': {err}; rewritten with trimesh as '{new}' (triangles kept, "
        "normals and texture coordinates dropped)" + ("; kept with inertia='shell'" if err2 else "")
    )
    return new, mode or None, err
