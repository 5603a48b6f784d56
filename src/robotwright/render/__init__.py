"""Pictures of robots and scenes without a display.

``render(source, "picture.png")`` draws a bundled robot, an HRDF folder, an MJCF
(robot or composed scene) or a URDF file; ``render_model(model, data)`` draws a
compiled MuJoCo model, with LiDAR points if given. MuJoCo's OpenGL renderer draws when
an off-screen GL platform starts (EGL, OSMesa), otherwise a numpy z-buffer renderer
does (``Picture.backend`` says which).
"""

from typing import TYPE_CHECKING

from robotwright._lazy import attach

if TYPE_CHECKING:
    from robotwright.render.anim import Animation, save_animation
    from robotwright.render.api import render, render_animation
    from robotwright.render.camera import VIEWS, CameraError
    from robotwright.render.core import Picture, RenderError, RenderOptions, render_model
    from robotwright.render.png import save_png
    from robotwright.render.source import SourceError, load_model

__all__ = [
    "VIEWS",
    "Animation",
    "CameraError",
    "Picture",
    "RenderError",
    "RenderOptions",
    "SourceError",
    "load_model",
    "render",
    "render_animation",
    "render_model",
    "save_animation",
    "save_png",
]

attach(__name__, __file__)
