"""robotwright: describe, generate, compose and sense robots for simulation."""

__version__ = "0.1.0"
