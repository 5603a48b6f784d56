"""MuJoCo's OpenGL renderer on an off-screen context (one per picture, or one
:class:`GLSession` for all the frames of an animation).

``mujoco.Renderer`` takes its GL platform from ``MUJOCO_GL`` once, when ``mujoco`` is
first imported, and defaults to GLFW, which needs a display. A picture may be asked
for long after that import (the demo, a notebook), so this module opens the context
itself: the platform named by ``MUJOCO_GL`` if set, else EGL, then OSMesa (and GLFW
when a display is present), and draws with MuJoCo's own ``mjr_render``. A platform
that cannot start is reported, and the caller falls back to the software renderer.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import mujoco
import numpy as np

__all__ = ["GLImage", "GLSession", "GLUnavailable", "gl_platforms", "render_gl"]


class GLUnavailable(RuntimeError):
    """No OpenGL platform could draw; the message says why for each one tried."""


@dataclass
class GLImage:
    """An image drawn by MuJoCo's renderer.

    Attributes:
        rgb: ``(H, W, 3)`` uint8 colours, row 0 at the top.
        depth: ``(H, W)`` distance along the view axis [m], ``inf`` where nothing is.
        platform: the GL platform that drew it (``egl``, ``osmesa`` or ``glfw``).
    """

    rgb: np.ndarray
    depth: np.ndarray
    platform: str


def gl_platforms() -> list[str]:
    """Platforms to try, in order: ``MUJOCO_GL`` when it names one, else EGL, OSMesa,
    and GLFW when a display is set."""
    chosen = os.environ.get("MUJOCO_GL", "").strip().lower()
    if chosen in ("egl", "osmesa", "glfw"):
        return [chosen]
    if chosen in ("disable", "disabled", "off", "false", "0"):
        return []
    order = ["egl", "osmesa"]
    if os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"):
        order.append("glfw")
    return order


def _context(platform: str, width: int, height: int):  # -> a mujoco GLContext
    if platform == "egl":
        from mujoco.egl import GLContext
    elif platform == "osmesa":
        from mujoco.osmesa import GLContext
    else:
        from mujoco.glfw import GLContext
    return GLContext(width, height)


class GLSession:
    """One off-screen context and MuJoCo render context on the first platform of
    :func:`gl_platforms` that starts, drawing any number of frames of ``model`` at
    ``width`` x ``height`` (an animation's frames share one; making a context costs more
    than drawing a frame). Free it with :meth:`close` (or use it in a ``with`` block).

    Raises:
        GLUnavailable: no platform could create a context (each one's reason given).
    """

    def __init__(
        self, model: mujoco.MjModel, width: int, height: int, platforms: list[str] | None = None
    ) -> None:
        self.model, self.width, self.height = model, width, height
        reasons = []
        for platform in gl_platforms() if platforms is None else platforms:
            try:
                ctx = _context(platform, width, height)
            except Exception as exc:  # noqa: BLE001 - any failure means "not this platform"
                reasons.append(f"{platform}: {type(exc).__name__}: {exc}".strip())
                continue
            try:
                ctx.make_current()
                self._con = _render_context(model, width, height)
            except Exception as exc:  # noqa: BLE001 - a context that starts but cannot draw
                reasons.append(f"{platform}: {type(exc).__name__}: {exc}".strip())
                ctx.free()
                continue
            self._ctx, self.platform = ctx, platform
            return
        raise _unavailable(reasons)

    def draw(self, scene: mujoco.MjvScene) -> GLImage:
        """Draw ``scene`` (filled by ``mjv_updateScene`` for the session's model)."""
        self._ctx.make_current()
        return _draw(self._con, scene, self.width, self.height, self.platform)

    def close(self) -> None:
        """Free the contexts (idempotent)."""
        con, self._con = getattr(self, "_con", None), None
        ctx, self._ctx = getattr(self, "_ctx", None), None
        if con is not None:
            con.free()
        if ctx is not None:
            ctx.free()

    def __enter__(self) -> GLSession:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def render_gl(model: mujoco.MjModel, scene: mujoco.MjvScene, width: int, height: int) -> GLImage:
    """Draw ``scene`` (filled by ``mjv_updateScene`` for ``model``) off-screen once: the
    first platform that starts and draws (a platform that starts but fails to draw
    gives way to the next).

    Raises:
        GLUnavailable: no platform could draw (each one's reason given).
    """
    reasons = []
    for platform in gl_platforms():
        try:
            with GLSession(model, width, height, [platform]) as session:
                return session.draw(scene)
        except Exception as exc:  # noqa: BLE001 - any failure means "not this platform"
            failed = isinstance(exc, GLUnavailable)  # its reason names the platform
            reasons.append(str(exc) if failed else f"{platform}: {type(exc).__name__}: {exc}")
    raise _unavailable(reasons)


def _unavailable(reasons: list[str]) -> GLUnavailable:
    """The error saying why no platform drew: each one's reason, first line only."""
    if not reasons:
        reasons = ["MUJOCO_GL disables OpenGL" if os.environ.get("MUJOCO_GL") else "none"]
    return GLUnavailable("; ".join(r.splitlines()[0] for r in reasons))


def _render_context(model: mujoco.MjModel, width: int, height: int) -> mujoco.MjrContext:
    vis = model.vis.global_
    saved = (vis.offwidth, vis.offheight)
    # The off-screen buffer is sized from the model when the context is made.
    vis.offwidth, vis.offheight = max(width, saved[0]), max(height, saved[1])
    try:
        return mujoco.MjrContext(model, mujoco.mjtFontScale.mjFONTSCALE_100)
    finally:
        vis.offwidth, vis.offheight = saved


def _draw(
    con: mujoco.MjrContext, scene: mujoco.MjvScene, width: int, height: int, platform: str
) -> GLImage:
    mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN, con)
    rect = mujoco.MjrRect(0, 0, width, height)
    mujoco.mjr_render(rect, scene, con)
    rgb = np.empty((height, width, 3), dtype=np.uint8)
    z = np.empty((height, width), dtype=np.float32)
    mujoco.mjr_readPixels(rgb, z, rect, con)
    cam = scene.camera[0]
    near, far = float(cam.frustum_near), float(cam.frustum_far)
    z = np.flipud(z).astype(np.float64)
    # OpenGL depth in [0, 1] -> distance along the view axis (as mujoco.Renderer does).
    if cam.orthographic:
        depth = near + z * (far - near)
    else:
        with np.errstate(divide="ignore"):
            depth = near / (1.0 - z * (1.0 - near / far))
    depth[z >= 1.0] = np.inf
    return GLImage(np.flipud(rgb).copy(), depth, platform)
