"""Animations: a joint sweep or a short simulation, drawn frame by frame to GIF or MP4.

The states are computed first (MuJoCo kinematics for a sweep, ``mj_step`` for a
simulation), then every frame is drawn by :func:`~robotwright.render.core.render_model`
with one camera framing the robot in all of them, so the robot moves and the view
stays still. Files are written with ``imageio`` (the ``video`` extra, imported when an
animation is written): a GIF needs only Pillow, an MP4 also ``imageio-ffmpeg``.
"""

from __future__ import annotations

import io
import math
import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import mujoco
import numpy as np

from robotwright._atomic import write_bytes_atomic
from robotwright._progress import steps
from robotwright.render.core import (
    RenderError,
    RenderOptions,
    RenderSession,
    _scene,
    drawn_bounds,
    render_model,
)

__all__ = [
    "ANIMATION_SUFFIXES",
    "MAX_FRAMES",
    "Animation",
    "animate",
    "require_writer",
    "save_animation",
    "simulate_states",
    "sweep_states",
]

#: Output suffixes written as animations.
ANIMATION_SUFFIXES = (".gif", ".mp4")
#: Most frames in one animation (a typo in --fps or the seconds more often than a wish).
MAX_FRAMES = 1000
#: Longest animation [s] and highest frame rate [frames/s] accepted.
MAX_SECONDS = 60.0
MAX_FPS = 60.0

_HINGE = int(mujoco.mjtJoint.mjJNT_HINGE)
_SLIDE = int(mujoco.mjtJoint.mjJNT_SLIDE)


@dataclass
class Animation:
    """Frames drawn from a sequence of states.

    Attributes:
        frames: ``(N, H, W, 3)`` uint8 RGB pictures.
        fps: frames per second of playback.
        times: ``(N,)`` time of each frame [s] from the first.
        backend: the renderer that drew the frames.
        notes: what was not drawn and why OpenGL was not used, one line each.
    """

    frames: np.ndarray
    fps: float
    times: np.ndarray
    backend: str
    notes: list[str] = field(default_factory=list)


def frame_count(seconds: float, fps: float) -> int:
    """Frames of an animation ``seconds`` long at ``fps`` (at least 2).

    Raises:
        RenderError: ``seconds`` or ``fps`` not finite and positive, or beyond the caps.
    """
    for name, value, cap in (("seconds", seconds, MAX_SECONDS), ("fps", fps, MAX_FPS)):
        ok = isinstance(value, (int, float)) and not isinstance(value, bool)
        if not (ok and math.isfinite(value) and 0 < value <= cap):
            raise RenderError(f"animation {name} {value!r}: expected a number in (0, {cap:g}]")
    count = max(2, int(round(seconds * fps)))
    if count > MAX_FRAMES:
        raise RenderError(
            f"animation of {seconds:g} s at {fps:g} frames/s is {count} frames; at most "
            f"{MAX_FRAMES} (shorten it or lower --fps)"
        )
    return count


def sweep_states(model: mujoco.MjModel, qpos: np.ndarray, frames: int) -> np.ndarray:
    """``(frames, nq)`` poses moving every limited hinge and slide joint together from
    ``qpos`` to its upper limit, down to its lower limit and back (one sine period).
    Joints without limits, ball and free joints keep their value in ``qpos``."""
    q0 = np.asarray(qpos, dtype=np.float64).copy()
    phase = np.sin(2.0 * np.pi * np.arange(frames) / frames)
    states = np.tile(q0, (frames, 1))
    for j in range(model.njnt):
        if int(model.jnt_type[j]) not in (_HINGE, _SLIDE) or not model.jnt_limited[j]:
            continue
        lo, hi = (float(x) for x in model.jnt_range[j])
        adr = int(model.jnt_qposadr[j])
        start = float(np.clip(q0[adr], lo, hi))
        up, down = hi - start, start - lo
        states[:, adr] = start + np.where(phase > 0, phase * up, phase * down)
    return states


def simulate_states(
    model: mujoco.MjModel, data: mujoco.MjData, frames: int, fps: float
) -> tuple[np.ndarray, np.ndarray]:
    """Step ``data`` with ``mj_step`` (its ``ctrl`` held) and record ``qpos`` at
    ``k / fps`` seconds for ``k < frames``; returns ``(qpos (frames, nq), times)``.

    Raises:
        RenderError: MuJoCo's state became invalid (a NaN or huge acceleration: MuJoCo
            resets the state and warns), naming the time.
    """
    start = float(data.time)
    states = np.empty((frames, model.nq))
    times = np.arange(frames) / fps
    warned = int(data.warning[mujoco.mjtWarning.mjWARN_BADQACC].number)
    for k, t in enumerate(times):
        while data.time - start < t - 0.5 * model.opt.timestep:
            mujoco.mj_step(model, data)
            if int(data.warning[mujoco.mjtWarning.mjWARN_BADQACC].number) > warned:
                raise RenderError(
                    f"the simulation became unstable at t = {data.time - start:.3f} s "
                    "(MuJoCo reset a bad acceleration); nothing was written"
                )
        states[k] = data.qpos
    return states, times


def animate(
    model: mujoco.MjModel,
    states: np.ndarray,
    times: np.ndarray,
    fps: float,
    options: RenderOptions | None = None,
) -> Animation:
    """Draw each pose of ``states`` ``(N, nq)``, one camera framing all of them."""
    opts = options or RenderOptions()
    data = mujoco.MjData(model)
    with RenderSession(model, opts) as session:
        corners = []
        for q in states:
            data.qpos[:] = q
            mujoco.mj_forward(model, data)
            scene = _scene(model, data, mujoco.MjvCamera(), opts.geom_groups, session.scene)
            corners.append(drawn_bounds(model, scene))
        every = np.concatenate(corners) if corners else np.zeros((0, 3))
        box = np.zeros((0, 3))
        if len(every):
            lo, hi = every.min(axis=0), every.max(axis=0)
            box = np.array(
                [[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]
            )
        pictures = []
        for q in steps(states, len(states), "frames drawn"):
            data.qpos[:] = q
            mujoco.mj_forward(model, data)
            pictures.append(render_model(model, data, opts, bounds=box, session=session))
    notes = list(dict.fromkeys(n for p in pictures for n in p.notes))
    return Animation(
        np.stack([p.image for p in pictures]), fps, np.asarray(times), pictures[0].backend, notes
    )


def require_writer(path: str | os.PathLike[str]) -> None:
    """Check that an animation can be written to ``path`` before any frame is drawn.

    Raises:
        RenderError: not ``.gif``/``.mp4``; imageio (or Pillow) missing; for ``.mp4``,
            imageio-ffmpeg missing. The message names the ``video`` extra.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in ANIMATION_SUFFIXES:
        raise RenderError(f"{path}: expected a .gif or .mp4 animation file")
    try:
        import imageio.v3  # noqa: F401
        import PIL  # noqa: F401
    except ImportError:
        raise RenderError(
            f"{path}: writing a GIF or MP4 needs imageio and Pillow: "
            "pip install 'robotwright[video]'"
        ) from None
    if suffix == ".mp4":
        try:
            import imageio_ffmpeg  # noqa: F401
        except ImportError:
            raise RenderError(
                f"{path}: writing an MP4 needs imageio-ffmpeg: pip install "
                "'robotwright[video]' (a .gif needs only imageio and Pillow)"
            ) from None


def save_animation(animation: Animation, path: str | os.PathLike[str]) -> Path:
    """Write ``animation`` to ``path`` (``.gif``: looping, Pillow; ``.mp4``: H.264 by
    ``imageio-ffmpeg``), through a temporary file so that a failed write leaves no
    partial file.

    Raises:
        RenderError: another suffix, imageio or (for MP4) imageio-ffmpeg missing, or an
            MP4 of odd width or height (H.264 needs even sizes).
    """
    path = Path(path)
    suffix = path.suffix.lower()
    require_writer(path)
    import imageio.v3 as iio

    frames = np.ascontiguousarray(animation.frames)
    if suffix == ".gif":
        buffer = io.BytesIO()
        # Pillow's GIF writer: duration per frame [ms], loop=0 repeats forever.
        iio.imwrite(
            buffer,
            frames,
            extension=".gif",
            plugin="pillow",
            duration=round(1000.0 / animation.fps),
            loop=0,
        )
        write_bytes_atomic(path, buffer.getvalue())
        return path
    h, w = frames.shape[1:3]
    if h % 2 or w % 2:
        raise RenderError(f"{path}: an MP4 needs an even width and height, got {w}x{h}")
    import imageio.v2 as iio2

    with tempfile.TemporaryDirectory() as folder:
        tmp = Path(folder) / "animation.mp4"
        writer = iio2.get_writer(
            tmp,
            format="FFMPEG",
            mode="I",
            fps=animation.fps,
            codec="libx264",
            pixelformat="yuv420p",
            macro_block_size=1,
            ffmpeg_log_level="error",
        )
        try:
            for frame in frames:
                writer.append_data(frame)
        finally:
            writer.close()
        write_bytes_atomic(path, tmp.read_bytes())
    return path
