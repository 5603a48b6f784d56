"""xacro sources expanded to URDF without ROS, in a process of their own.

Entry points: :func:`is_xacro`, :func:`xacro_as_urdf` (a xacro file -> a URDF file and
the reader's options) and :func:`expand_xacro`. Modules: ``expand`` (the expansion and
its guard), ``expressions`` (the ``${...}`` evaluator that replaces Python's ``eval``: an
allow-list over the syntax tree), ``evaluator`` and ``names`` (what an expression may
name).
"""

from typing import TYPE_CHECKING

from robotwright._lazy import attach

if TYPE_CHECKING:
    from robotwright.parsers.xacro.expand import expand_xacro, is_xacro, xacro_as_urdf

__all__ = ["expand_xacro", "is_xacro", "xacro_as_urdf"]

attach(__name__, __file__)
