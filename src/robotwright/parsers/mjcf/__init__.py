"""The MJCF reader: a MuJoCo XML file, through ``mujoco.MjSpec`` and its compile, into
an HRDF.

Entry points: :func:`parse_mjcf` (a file) and :func:`parse_mjcf_spec` (a spec built in
memory by another reader, as the USD reader does), with :class:`MJCFOptions`. Most
callers go through :func:`robotwright.parsers.mjcf_to_hrdf`, which runs the reader in a
confined process. Modules: ``reader`` (the entry points), ``tree`` (bodies and joints),
``geoms``, ``actuators``, ``extra`` (what the tables cannot hold), ``common``
(options and value helpers), ``compiled`` (the reader's last compile, kept for the
proof).
"""

from typing import TYPE_CHECKING

from robotwright._lazy import attach

if TYPE_CHECKING:
    from robotwright.parsers.mjcf.common import MJCFOptions
    from robotwright.parsers.mjcf.reader import parse_mjcf, parse_mjcf_spec

__all__ = ["MJCFOptions", "parse_mjcf", "parse_mjcf_spec"]

attach(__name__, __file__)
