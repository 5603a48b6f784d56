"""The commands layer: the only place that parses arguments and prints.

:mod:`robotwright.cli.main` builds the ``robotwright`` parser from one module per command
group (``hrdf`` for validate/info, ``convert``, ``export``, ``lidar``, ``grammar``,
``things``, ``view``, ``render``, ``robots``, ``demo``); each has ``register(subparsers)``
and calls down into the systems, the robot-source gate and the model, never the other
way (``tests/test_layers.py`` walks the imports).
"""

from robotwright.cli.main import build_parser, main

__all__ = ["build_parser", "main"]
