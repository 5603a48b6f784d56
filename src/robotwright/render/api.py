"""``robotwright.render.render``: a picture of any robot source in one call."""

from __future__ import annotations

import os
from pathlib import Path

from robotwright.render.core import Picture, RenderOptions, render_model
from robotwright.render.png import save_png
from robotwright.render.source import load_model

__all__ = ["render"]


def render(
    source: str | os.PathLike[str],
    output: str | os.PathLike[str] | None = None,
    options: RenderOptions | None = None,
    *,
    title: str | None = None,
    asset_roots: tuple[str | os.PathLike[str], ...] = (),
) -> Picture:
    """Draw ``source`` (robot name, HRDF folder, MJCF or URDF file; see
    :mod:`robotwright.render.source`) in its first keyframe, or ``qpos0``.

    Args:
        source: what to draw.
        output: PNG file to write (nothing is written when None).
        options: size, camera and backend (:class:`RenderOptions`).
        title: a line of text drawn at the top of the PNG.
        asset_roots: folders outside the source's folder its files may come from.

    Returns:
        The picture; :attr:`Picture.backend` names the renderer that drew it.
    """
    loaded = load_model(source, asset_roots=asset_roots)
    picture = render_model(loaded.model, loaded.initial_data(), options)
    if output is not None:
        save_png(picture, Path(output), title=title)
    return picture
