"""MuJoCo's OpenGL renderer on an off-screen context chosen per call.

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

__all__ = ["GLUnavailable", "GLImage", "gl_platforms", "render_gl"]


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


def render_gl(model: mujoco.MjModel, scene: mujoco.MjvScene, width: int, height: int) -> GLImage:
    """Draw ``scene`` (filled by ``mjv_updateScene`` for ``model``) off-screen.

    Raises:
        GLUnavailable: no platform could create a context (each one's reason given).
    """
    reasons = []
    for platform in gl_platforms():
        try:
            ctx = _context(platform, width, height)
        except Exception as exc:  # noqa: BLE001 - any failure means "not this platform"
            reasons.append(f"{platform}: {type(exc).__name__}: {exc}".strip())
            continue
        try:
            ctx.make_current()
            return _draw(model, scene, width, height, platform)
        except Exception as exc:  # noqa: BLE001 - a context that starts but cannot draw
            reasons.append(f"{platform}: {type(exc).__name__}: {exc}".strip())
        finally:
            ctx.free()
    if not reasons:
        reasons.append("MUJOCO_GL disables OpenGL" if os.environ.get("MUJOCO_GL") else "none")
    raise GLUnavailable("; ".join(r.splitlines()[0] for r in reasons))


def _draw(
    model: mujoco.MjModel, scene: mujoco.MjvScene, width: int, height: int, platform: str
) -> GLImage:
    vis = model.vis.global_
    saved = (vis.offwidth, vis.offheight)
    # The off-screen buffer is sized from the model when the context is made.
    vis.offwidth, vis.offheight = max(width, saved[0]), max(height, saved[1])
    try:
        con = mujoco.MjrContext(model, mujoco.mjtFontScale.mjFONTSCALE_100)
    finally:
        vis.offwidth, vis.offheight = saved
    try:
        mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN, con)
        rect = mujoco.MjrRect(0, 0, width, height)
        mujoco.mjr_render(rect, scene, con)
        rgb = np.empty((height, width, 3), dtype=np.uint8)
        z = np.empty((height, width), dtype=np.float32)
        mujoco.mjr_readPixels(rgb, z, rect, con)
    finally:
        con.free()
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
