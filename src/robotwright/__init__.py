"""robotwright: describe, generate, compose and sense robots for simulation."""

__version__ = "0.1.0"

from robotwright._mujoco_gl import import_mujoco

import_mujoco()  # before any module imports mujoco: an unusable MUJOCO_GL must not stop it

from robotwright._atomic import mesh_size_limit  # noqa: E402
from robotwright._paths import trusted_asset_roots  # noqa: E402

__all__ = ["__version__", "mesh_size_limit", "trusted_asset_roots"]
