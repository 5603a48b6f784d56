"""warp without its banner and module-load lines on stdout (a command's output is ours)."""

from __future__ import annotations

from typing import Any


def quiet_warp() -> Any:
    """Import warp and silence it before anything initialises it; returns the module.
    warp >= 1.17 has log levels (its quiet flag is deprecated there), older versions only
    the flag."""
    import warp as wp

    if hasattr(wp, "LOG_WARNING"):
        wp.config.log_level = wp.LOG_WARNING
    else:
        wp.config.quiet = True
    return wp
