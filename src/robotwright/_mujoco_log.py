"""MuJoCo's own warnings during a command, gathered instead of printed.

MuJoCo reports some things it reads (an OBJ face without texture coordinates, ...)
through its C warning handler, which by default prints each one to the terminal and
appends it to ``MUJOCO_LOG.TXT`` in the working folder: a mesh-heavy robot printed a
dozen lines and left a stray file wherever the command ran. While a command runs, the
command line installs :func:`gathered` instead and counts the warnings among its notes
(one summary line, each with ``-v``).
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["gathered"]


@contextmanager
def gathered() -> Iterator[list[str]]:
    """Collect MuJoCo's warnings raised inside the block into the yielded list (in order, as
    MuJoCo words them, each on one line); the handler in place before is put back after."""
    import mujoco

    messages: list[str] = []
    before = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(lambda text: messages.append(" ".join(str(text).split())))
    try:
        yield messages
    finally:
        mujoco.set_mju_user_warning(before)
