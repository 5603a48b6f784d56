"""Executors that evaluate designs for the search: a local process pool, or Ray.

Both are :class:`concurrent.futures.Executor` objects used through ``map``, whose
results come back in submission order whatever the order the workers finish in; the
search therefore evaluates the same designs and finds the same result on either, for
the same seed.

Ray is an optional dependency (``pip install 'robotwright[ray]'``), imported only when
a :class:`RayExecutor` is made.
"""

from __future__ import annotations

import logging
import os
import re
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import Executor, Future
from typing import Any

from robotwright._temporaries import die_with_parent

__all__ = [
    "InProcessExecutor",
    "RayExecutor",
    "check_ray_address",
    "die_with_parent",
    "import_ray",
    "pool_size",
    "usable_cores",
]


def usable_cores() -> int:
    """The number of CPU cores this process may run on (its affinity where the system
    reports one, else the machine's count)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def pool_size(workers: int | None, budget: int) -> int:
    """Processes of a local pool (:class:`concurrent.futures.ProcessPoolExecutor`) for
    ``workers`` (default: the usable cores), never more than ``budget``: processes
    beyond the number of evaluations would only sit idle."""
    wanted = workers or usable_cores()
    return max(1, min(wanted, budget))


def import_ray() -> Any:
    """The ``ray`` module, or an :class:`ImportError` saying how to install it."""
    try:
        import ray
    except ImportError as exc:
        raise ImportError(
            "searching on Ray needs the ray package: install robotwright[ray] "
            "(pip install 'robotwright[ray]')"
        ) from exc
    return ray


#: ``auto`` (the cluster this machine belongs to), ``ray://HOST:PORT`` (Ray Client) or
#: ``HOST:PORT`` (a cluster's head node).
_ADDRESS = re.compile(r"^(auto|ray://[\w.\-\[\]:]+:\d{1,5}|[\w.\-\[\]:]+:\d{1,5})$")


def check_ray_address(address: str) -> str:
    """``address`` when it names a Ray cluster to join, else :class:`ValueError`."""
    if not _ADDRESS.match(address):
        raise ValueError(
            f"Ray address {address!r}: expected 'auto', 'ray://HOST:PORT' or 'HOST:PORT'"
        )
    return address


class InProcessExecutor(Executor):
    """Runs each call in this process when it is submitted: evaluations without a pool
    (a refine's default), through the same ``map`` as the pools."""

    workers = 1

    def submit(self, fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> Future:
        done: Future = Future()
        try:
            done.set_result(fn(*args, **kwargs))
        except BaseException as exc:  # noqa: BLE001 - handed to the caller by the future
            done.set_exception(exc)
        return done


def _run_batch(fn: Callable[[Any], Any], items: list[Any]) -> list[Any]:
    """One Ray task: ``fn`` on each item of a batch (one task per batch, not per item,
    so that the task overhead is shared by the batch)."""
    return [fn(item) for item in items]


class RayExecutor(Executor):
    """Runs ``map`` on a Ray cluster, a batch of items per task, results in order.

    Args:
        address: ``None`` starts a local cluster of ``num_cpus`` CPUs on this machine
            (no dashboard, worker output not copied to this terminal) that
            :meth:`shutdown` stops; ``"auto"``, ``"ray://HOST:PORT"`` or ``"HOST:PORT"``
            joins a running cluster, whose size the cluster decides (its workers need
            robotwright installed). When Ray is already initialised in this process,
            that cluster is used as it is and left running.
        num_cpus: CPUs of a local cluster (default: the usable cores). A count above
            the cores runs more worker processes than cores.

    Raises:
        ImportError: ray is not installed.
        ValueError: ``address`` is not one of the forms above.
    """

    def __init__(self, address: str | None = None, num_cpus: int | None = None) -> None:
        ray = import_ray()
        if address is not None:
            check_ray_address(address)
            if num_cpus is not None:
                raise ValueError("num_cpus applies to a local cluster: the cluster joined decides")
        self._ray = ray
        self._own = not ray.is_initialized()
        if self._own:
            quiet = dict(log_to_driver=False, logging_level=logging.ERROR)
            if address is None:
                ray.init(num_cpus=num_cpus or usable_cores(), include_dashboard=False, **quiet)
            else:
                ray.init(address=address, **quiet)
        self._task = ray.remote(_run_batch)
        self._fn: tuple[Callable[[Any], Any], Any] | None = None

    @property
    def workers(self) -> int:
        """CPUs of the cluster (the number of tasks it runs at once)."""
        return max(1, int(self._ray.cluster_resources().get("CPU", 1)))

    def _fn_ref(self, fn: Callable[[Any], Any]) -> Any:
        # The evaluation function (it holds the grammar) goes into the object store once
        # per search, not with every task.
        if self._fn is None or self._fn[0] is not fn:
            self._fn = (fn, self._ray.put(fn))
        return self._fn[1]

    def map(  # type: ignore[override]
        self,
        fn: Callable[..., Any],
        *iterables: Iterable[Any],
        timeout: float | None = None,
        chunksize: int = 1,
        buffersize: int | None = None,
    ) -> Iterator[Any]:
        if len(iterables) != 1:
            return super().map(fn, *iterables, timeout=timeout)
        items = list(iterables[0])
        ref = self._fn_ref(fn)
        size = max(1, chunksize)
        tasks = [self._task.remote(ref, items[i : i + size]) for i in range(0, len(items), size)]

        def results() -> Iterator[Any]:
            for task in tasks:  # submission order, whatever order the tasks end in
                yield from self._ray.get(task, timeout=timeout)

        return results()

    def submit(self, fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> Future:
        remote = self._ray.remote(lambda: fn(*args, **kwargs))
        return remote.remote().future()

    def shutdown(self, wait: bool = True, *, cancel_futures: bool = False) -> None:
        """Stop the local cluster this executor started (a joined one keeps running)."""
        if self._own and self._ray.is_initialized():
            self._ray.shutdown()
        self._own = False
