"""``robotwright.render.render``: a picture of any robot source in one call."""

from __future__ import annotations

import os
from pathlib import Path

from robotwright.render.core import Picture, RenderOptions, render_model
from robotwright.render.png import save_png
from robotwright.render.scan import render_scan
from robotwright.render.source import load_model

__all__ = ["render"]


def render(
    source: str | os.PathLike[str],
    output: str | os.PathLike[str] | None = None,
    options: RenderOptions | None = None,
    *,
    scene: str | os.PathLike[str] | None = None,
    title: str | None = None,
    asset_roots: tuple[str | os.PathLike[str], ...] = (),
) -> Picture:
    """Draw ``source`` (robot name, HRDF folder, MJCF or URDF file, design folder, or a
    scan ``.npz`` with its ``scene``; see :mod:`robotwright.render.source`) in its first
    keyframe, or ``qpos0``. A scan's points are drawn in the scene coloured by class,
    with a legend in the PNG.

    Args:
        source: what to draw.
        output: PNG file to write (nothing is written when None).
        options: size, camera and backend (:class:`RenderOptions`).
        scene: the MJCF scene a scan was taken in (only with a scan source).
        title: a line of text drawn at the top of the PNG.
        asset_roots: folders outside the source's folder its files may come from.

    Returns:
        The picture; :attr:`Picture.backend` names the renderer that drew it.
    """
    loaded = load_model(source, scene=scene, asset_roots=asset_roots)
    data = loaded.initial_data()
    if loaded.scan is not None:
        scan = loaded.scan
        return render_scan(
            loaded.model,
            data,
            scan.points,
            scan.labels,
            scan.class_names,
            output,
            options,
            title=title,
        )
    picture = render_model(loaded.model, data, options)
    # How the drawing differs from the robot (physics replaced to show it) comes first.
    picture.notes[:0] = loaded.warnings
    if output is not None:
        save_png(picture, Path(output), title=title)
    return picture
