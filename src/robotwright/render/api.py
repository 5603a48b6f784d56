"""``robotwright.render.render``: a picture of any robot source in one call."""

from __future__ import annotations

import os
from pathlib import Path

import mujoco
import numpy as np

from robotwright.render.anim import (
    Animation,
    animate,
    frame_count,
    require_writer,
    save_animation,
    simulate_states,
    sweep_states,
)
from robotwright.render.core import Picture, RenderError, RenderOptions, render_model
from robotwright.render.png import save_png
from robotwright.render.scan import render_scan
from robotwright.render.source import load_model

__all__ = ["draw_pose", "render", "render_animation"]


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


def render_animation(
    source: str | os.PathLike[str],
    output: str | os.PathLike[str] | None = None,
    options: RenderOptions | None = None,
    *,
    sweep: float | None = None,
    simulate: float | None = None,
    fps: float = 20.0,
    asset_roots: tuple[str | os.PathLike[str], ...] = (),
) -> Animation:
    """Draw ``source`` moving: a joint sweep of ``sweep`` seconds (every limited hinge
    and slide joint from the first pose to its upper limit, its lower limit and back)
    or ``simulate`` seconds of MuJoCo simulation from the first pose (keyframe 0 with
    its ``ctrl``, else ``qpos0`` with zero controls); one of the two.

    Args:
        source: what to draw (as :func:`render`; not a scan).
        output: ``.gif`` or ``.mp4`` file to write (nothing is written when None).
        options: size, camera, backend and geom groups of every frame.
        sweep: length of the sweep [s].
        simulate: simulated time [s] (played back in real time).
        fps: frames per second.
        asset_roots: folders outside the source's folder its files may come from.

    Raises:
        RenderError: neither or both of ``sweep``/``simulate``, bad lengths, too many
            frames, an unstable simulation, an output that is not ``.gif``/``.mp4``.
    """
    if (sweep is None) == (simulate is None):
        raise RenderError("an animation is a sweep or a simulation: give one of the two")
    if output is not None:
        require_writer(output)  # before drawing: a missing extra fails at once
    seconds = sweep if sweep is not None else simulate
    assert seconds is not None
    count = frame_count(seconds, fps)
    loaded = load_model(source, asset_roots=asset_roots)
    if loaded.scan is not None:
        raise RenderError(f"{os.fspath(source)}: a scan does not move; draw it as a .png")
    data = loaded.initial_data()
    if sweep is not None:
        states = sweep_states(loaded.model, loaded.qpos, count)
        times = np.arange(count) / fps
    else:
        if loaded.model.nkey:
            data.ctrl[:] = loaded.model.key_ctrl[0]
        states, times = simulate_states(loaded.model, data, count, fps)
    animation = animate(loaded.model, states, times, fps, options)
    animation.notes[:0] = loaded.warnings
    if output is not None:
        save_animation(animation, output)
    return animation


def draw_pose(
    model: mujoco.MjModel,
    qpos: np.ndarray,
    path: str | os.PathLike[str],
    title: str,
    options: RenderOptions | None = None,
) -> Picture:
    """Draw ``model`` at joint values ``qpos`` (held still) into the PNG ``path``. By
    default seen from behind and to the left at 360x300: a limb worn on a carrier's back
    and its depth both show."""
    data = mujoco.MjData(model)
    data.qpos[:] = qpos
    mujoco.mj_forward(model, data)
    opts = options or RenderOptions(width=360, height=300, camera="225,-15")
    picture = render_model(model, data, opts)
    save_png(picture, Path(path), title=title)
    return picture
