"""Importing MuJoCo when ``MUJOCO_GL`` names an OpenGL platform that cannot start.

``import mujoco`` sets up the platform ``MUJOCO_GL`` names (``osmesa``, ``egl``, ...)
at import time, and fails with an ``AttributeError`` or ``RuntimeError`` (not an
``ImportError``) when its library is missing or the value is unknown. Every robotwright
command imports MuJoCo, including those that never draw, and ``render --backend
software`` draws without OpenGL: none of them may fail because of it.

So when the import fails that way, MuJoCo is imported again with its OpenGL set-up
disabled, and ``MUJOCO_GL`` is put back. :mod:`robotwright.render.gl` opens its own
context per picture (reading ``MUJOCO_GL`` then), so the OpenGL backend still reports
the platform's failure in its own words, and ``--backend auto`` falls back to software.
"""

from __future__ import annotations

import os

__all__ = ["import_mujoco"]

_DISABLED = ("disable", "disabled", "off", "false", "0")


def import_mujoco() -> None:
    """Import ``mujoco`` once; when ``MUJOCO_GL`` makes the import fail, import it with
    OpenGL disabled (``MUJOCO_GL`` itself is left as the user set it).

    Raises:
        ImportError: MuJoCo is not installed (nothing to recover from).
    """
    chosen = os.environ.get("MUJOCO_GL")
    if chosen is None or chosen.strip().lower() in _DISABLED:
        return  # the import sets up nothing that can fail here: leave it lazy
    try:
        import mujoco  # noqa: F401
    except ImportError:
        raise
    except Exception:  # noqa: BLE001 - MuJoCo's GL set-up raises AttributeError, RuntimeError, OSError
        os.environ["MUJOCO_GL"] = "disable"
        try:
            import mujoco  # noqa: F401,F811
        finally:
            os.environ["MUJOCO_GL"] = chosen
