"""robotwright: describe, generate, compose and sense robots for simulation."""

__version__ = "0.1.0"

from robotwright._paths import trusted_asset_roots

__all__ = ["__version__", "trusted_asset_roots"]
