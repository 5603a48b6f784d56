"""Names of the preset scan patterns, importable without numpy (the CLI's ``--pattern``
choices are built before any command runs)."""

from __future__ import annotations

#: Names accepted by :func:`robotwright.sensors.pattern_from_name` (and ``--pattern``).
PATTERN_NAMES: tuple[str, ...] = ("mid360", "avia", "vlp16", "vlp32", "os128", "grid", "pinhole")
