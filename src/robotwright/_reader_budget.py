"""The budget of a confined reader (:mod:`robotwright._confine`): the memory it may
allocate and the CPU time it may use, set for a block by the command line
(``--max-reader-mb``). The path checks (:mod:`robotwright._paths`) read it too: they
refuse a file that declares more than the budget before MuJoCo allocates it."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from contextvars import ContextVar

#: Memory a confined reader may allocate beyond what the process held when it was
#: copied (bytes; ``--max-reader-mb``), and the CPU time it may use (s). MuJoCo allocates
#: what a file declares (``<size nuserdata>``, keyframes, replicated bodies) as it
#: reads: past the budget the reader stops with one error, not the machine.
READER_MEMORY_BYTES = 2_000 * 10**6
READER_CPU_S = 120
_BUDGET: ContextVar[tuple[int, int]] = ContextVar(
    "robotwright_reader_budget", default=(READER_MEMORY_BYTES, READER_CPU_S)
)


@contextlib.contextmanager
def reader_budget(memory_mb: float | None = None, cpu_s: int | None = None) -> Iterator[None]:
    """Within the block, confined readers may allocate ``memory_mb`` MB (10**6 bytes)
    and use ``cpu_s`` seconds of CPU (``None``: the default, :data:`READER_MEMORY_BYTES`
    and :data:`READER_CPU_S`).

    Raises:
        ValueError: a value that is not positive.
    """
    memory, cpu = _BUDGET.get()
    if memory_mb is not None:
        if not 0 < memory_mb < float("inf"):
            raise ValueError(f"max_reader_mb must be a positive number of MB, got {memory_mb}")
        memory = round(memory_mb * 10**6)
    if cpu_s is not None:
        if cpu_s <= 0:
            raise ValueError(f"reader CPU time must be positive, got {cpu_s}")
        cpu = int(cpu_s)
    token = _BUDGET.set((memory, cpu))
    try:
        yield
    finally:
        _BUDGET.reset(token)


def reader_memory_bytes() -> int:
    """The memory a confined reader may allocate now (bytes; see :func:`reader_budget`)."""
    return _BUDGET.get()[0]
