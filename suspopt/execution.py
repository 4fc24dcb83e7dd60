"""Where many designs are simulated: in this process, in a local pool of processes, or on a
Dask cluster, with the same bits in every case.

Every path that simulates a population goes through one seam, :func:`map_chunks`: the
population's rows are split into chunks of a fixed width (``execution.chunk``, the same
whatever the number of workers), each chunk is evaluated by a plain function of a shared
object (the problem or config, sent once per worker) and its chunk of rows, and the results
come back in the chunks' order. A design's arithmetic never involves another design (both
integrator engines compute each design on its own), so a design gives the same bits in any
chunk, on any executor. Users of the seam: ``Problem.evaluate`` (every optimiser, ``kesort``'s
re-simulation, the pseudo-fronts of ``analyse roads|masses|controllers|tolerances``, the
builds of ``analyse builds``) and ``simulate`` of a batch or sweep.

Executors (``execution.executor``, or ``--executor`` on the command line, which wins):

- ``local`` (the default): in this process, the whole population in one call (or in the
  batches its memory allows), as without this module;
- ``processes``: a pool of ``workers`` local processes (default: the machine's cores),
  started with ``spawn`` (the parent may hold BLAS or numba threads, which ``fork`` does not
  copy safely); the shared object goes to each worker once, as its pool's start-up argument;
  a worker that dies has its chunks run again in a new pool;
- ``dask``: a running Dask scheduler at ``scheduler`` (``tcp://host:8786``), or without one a
  ``distributed.LocalCluster`` of ``workers`` single-threaded processes that suspopt starts
  and stops. The shared object is scattered to every worker once (``broadcast``); a chunk's
  task takes its rows and returns its values. Dask recomputes the chunks of a worker that
  dies; a lost scheduler is :class:`ExecutionLost`. Needs ``pip install "suspopt[dask]"``.

Workers run one thread each (``OPENBLAS_NUM_THREADS``, ``OMP_NUM_THREADS``, ``MKL_NUM_THREADS``
and ``NUMBA_NUM_THREADS`` set to 1 in the processes suspopt starts): the parallelism is the
workers'. Files a config names (a measured road profile) are read by the workers: on a cluster
they must be at the same path on every machine (a shared file system).
"""

from __future__ import annotations

import atexit
import contextlib
import math
import operator
import os
import re
from collections.abc import Callable, Iterator, Sequence
from typing import Any

__all__ = [
    "EXECUTORS",
    "INSTALL_DASK",
    "DEFAULT_CHUNK",
    "ExecutionLost",
    "SchedulerUnreachable",
    "SCHEDULER_SCHEMES",
    "check_scheduler_address",
    "check_settings",
    "Executor",
    "executor_for",
    "map_chunks",
    "use",
]

#: The values of ``execution.executor``.
EXECUTORS = ("local", "processes", "dask")
#: How to install the Dask executor.
INSTALL_DASK = 'pip install "suspopt[dask]"'
#: Designs per chunk unless ``execution.chunk`` says otherwise. The numpy engine's cost per
#: design falls with the batch (its per-step overhead is shared by the batch), so a chunk
#: must not be small: on the Ch. 6 Part B problem 2 local workers gave 1.09x over one
#: process with chunks of 100 and 1.72x with chunks of 500 (``benchmarks/bench_scale.py``);
#: 250 splits a population of 1000 into 4 chunks. A Dask task costs a few milliseconds.
DEFAULT_CHUNK = 250
#: Thread variables set to 1 in the worker processes suspopt starts.
_ONE_THREAD = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS")
#: Seconds a Dask client waits for its scheduler (to connect, and to reconnect after a loss).
CONNECT_TIMEOUT = 10
#: The address schemes of a Dask scheduler suspopt's workers can reach (distributed's
#: ``inproc`` lives inside one process, which suspopt's separate workers are not).
SCHEDULER_SCHEMES = ("tcp", "tls", "ws", "wss", "ucx")
_ADDRESS = re.compile(
    r"(?:(?P<scheme>[A-Za-z][A-Za-z0-9+.-]*)://)?"
    r"(?P<host>\[[0-9A-Fa-f:.%A-Za-z]+\]|[A-Za-z0-9_.-]+)"
    r"(?::(?P<port>[0-9]{1,5}))?"
)


def check_scheduler_address(address: str) -> str:
    """``address`` when it has the form of a Dask scheduler's address, ``[scheme://]host:port``
    (a scheme of :data:`SCHEDULER_SCHEMES`, tcp when none; an IPv6 host in brackets; a port
    from 1 to 65535); ValueError saying what is wrong otherwise. The form only: whether a
    scheduler answers there is known when a command connects."""
    found = _ADDRESS.fullmatch(address)
    if found is None:
        raise ValueError(
            f"{address!r} is not a scheduler address: give [scheme://]host:port, e.g. "
            f"tcp://host:8786 (an IPv6 host in brackets: tcp://[::1]:8786)"
        )
    scheme, port = found["scheme"], found["port"]
    if scheme is not None and scheme.lower() not in SCHEDULER_SCHEMES:
        raise ValueError(
            f"{address!r}: a scheduler's address starts with one of "
            f"{', '.join(s + '://' for s in SCHEDULER_SCHEMES)}, not {scheme}://"
        )
    if port is None or not 1 <= int(port) <= 65535:
        raise ValueError(
            f"{address!r}: give the scheduler's port, from 1 to 65535 (Dask's default is 8786)"
        )
    return address


#: Worker processes started on this machine per core, at most (more only compete).
WORKERS_PER_CORE = 4


def max_local_workers() -> int:
    """The most worker processes suspopt starts on this machine."""
    return WORKERS_PER_CORE * (os.cpu_count() or 1)


#: Times a ``processes`` pool is restarted after a worker died, per call.
_POOL_RESTARTS = 3


class ExecutionLost(RuntimeError):
    """The executor went away during a run (a Dask scheduler that stopped answering)."""


class SchedulerUnreachable(ExecutionLost):
    """No Dask scheduler answered at the address given."""


def dask_available() -> bool:
    """Whether ``distributed`` can be imported (the Dask executor's dependency)."""
    import importlib.util

    return importlib.util.find_spec("distributed") is not None


class Executor:
    """Runs ``function(shared, item)`` for each item, the results in the items' order; the
    ``local`` one in this process."""

    name = "local"

    def map(
        self,
        function: Callable[[Any, Any], Any],
        shared: Any,
        items: Sequence[Any],
        progress: Callable[[int, int], None] | None = None,
    ) -> list[Any]:
        results = []
        for i, item in enumerate(items):
            results.append(function(shared, item))
            if progress is not None:
                progress(i + 1, len(items))
        return results

    def close(self) -> None:
        """Stop what the executor started (nothing here)."""


# --- processes ---------------------------------------------------------------------------------

#: In a ``processes`` worker: the shared object its pool was started with.
_WORKER_SHARED: list[Any] = []


def _start_worker(shared: Any) -> None:
    """A ``processes`` worker's set-up: one thread for BLAS and numba (the workers are the
    parallelism) and the shared object, handed over once by the pool."""
    for name in _ONE_THREAD:
        os.environ[name] = "1"
    _WORKER_SHARED[:] = [shared]


_READY: list[bool] = []


def _in_worker(function: Callable[[Any, Any], Any], shared: Any, item: Any) -> Any:
    """``function(shared, item)`` in a worker process, which first makes the allocator reuse
    freed memory as the command line does (:func:`suspopt.reuse_memory`: without it a worker
    ran the Ch. 6 Part B chunks about 1.5 times slower)."""
    if not _READY:  # this process is a worker: what it simulates stays in it (settings)
        from .memory import reuse_memory

        reuse_memory()
        _READY.append(True)
    return function(shared, item)


def _call_shared(function: Callable[[Any, Any], Any], item: Any) -> Any:
    """In a ``processes`` worker: ``function(shared, item)`` with its pool's shared object."""
    return _in_worker(function, _WORKER_SHARED[0], item)


class ProcessExecutor(Executor):
    """A pool of local worker processes (module docstring). The shared object goes to each
    worker once, as the argument of the pool's initializer (multiprocessing's own pipe, no
    file); a call with another shared object starts a new pool."""

    name = "processes"

    def __init__(self, workers: int | None = None):
        self.workers = workers or os.cpu_count() or 1
        self._pool: Any = None  # a concurrent.futures.ProcessPoolExecutor once started
        self._shared: Any = None  # the object the pool's workers hold

    def _pool_for(self, shared: Any):
        if self._pool is not None and self._shared is not shared:
            self.close()
        if self._pool is None:
            import multiprocessing
            from concurrent.futures import ProcessPoolExecutor

            self._pool = ProcessPoolExecutor(
                self.workers,
                mp_context=multiprocessing.get_context("spawn"),
                initializer=_start_worker,
                initargs=(shared,),
            )
            self._shared = shared
        return self._pool

    def map(self, function, shared, items, progress=None):
        from concurrent.futures import as_completed
        from concurrent.futures.process import BrokenProcessPool

        results: dict[int, Any] = {}
        for _ in range(_POOL_RESTARTS + 1):
            todo = [i for i in range(len(items)) if i not in results]
            try:
                pool = self._pool_for(shared)
                futures = {pool.submit(_call_shared, function, items[i]): i for i in todo}
                for future in as_completed(futures):
                    results[futures[future]] = future.result()
                    if progress is not None:
                        progress(len(results), len(items))
                return [results[i] for i in range(len(items))]
            except BrokenProcessPool:  # a worker died: its chunks again, in a new pool
                self.close()
        raise ExecutionLost(
            f"the processes executor lost a worker {_POOL_RESTARTS + 1} times in one "
            f"evaluation (out of memory?)"
        )

    def close(self) -> None:
        if self._pool is not None:
            self._pool.shutdown(cancel_futures=True)
            self._pool, self._shared = None, None


# --- dask --------------------------------------------------------------------------------------


class DaskExecutor(Executor):
    """Chunks as tasks of a Dask cluster (module docstring): ``scheduler`` an address, or
    None for a LocalCluster of ``workers`` processes that lives as long as the executor."""

    name = "dask"

    def __init__(self, scheduler: str | None = None, workers: int | None = None):
        from distributed import Client, LocalCluster

        self.scheduler, self._cluster = scheduler, None
        if scheduler is None:
            self._cluster = LocalCluster(
                n_workers=workers or os.cpu_count() or 1,
                threads_per_worker=1,
                processes=True,
                dashboard_address=None,
                env=dict.fromkeys(_ONE_THREAD, "1"),
            )
            self.client = Client(self._cluster)
        else:
            self.client = Client(scheduler, timeout=f"{CONNECT_TIMEOUT}s")
        self._shared: tuple[Any, Any] | None = None

    @property
    def address(self) -> str:
        return self.scheduler or str(getattr(self.client.scheduler, "address", "?"))

    def _scattered(self, shared: Any):
        if self._shared is None or self._shared[0] is not shared:
            future = self.client.scatter(shared, broadcast=True, hash=False)
            self._shared = (shared, future)
        return self._shared[1]

    def map(self, function, shared, items, progress=None):
        import uuid
        from concurrent.futures import CancelledError

        from distributed import as_completed
        from distributed.comm import CommClosedError

        # the scheduler went away: its connection closed, or the futures cancelled with it
        lost = (CommClosedError, OSError, TimeoutError, CancelledError)
        try:
            scattered = self._scattered(shared)
            token = uuid.uuid4().hex
            futures = self.client.map(
                _in_worker,
                [function] * len(items),
                [scattered] * len(items),
                list(items),
                key=[f"suspopt-chunk-{token}-{i}" for i in range(len(items))],
                pure=False,
            )
            where = {f.key: i for i, f in enumerate(futures)}
            results: dict[int, Any] = {}
            for future in as_completed(futures):
                results[where[future.key]] = future.result()
                if progress is not None:
                    progress(len(results), len(items))
            return [results[i] for i in range(len(items))]
        except lost as exc:
            raise ExecutionLost(f"lost the Dask scheduler {self.address}: {exc}") from None

    def close(self) -> None:
        with contextlib.suppress(Exception):
            self.client.close()
        if self._cluster is not None:
            with contextlib.suppress(Exception):
                self._cluster.close()


# --- which executor ----------------------------------------------------------------------------

_LOCAL = Executor()
#: Settings the command line gave (they win over a config's ``execution:`` section).
_OVERRIDES: dict[str, Any] = {}
#: Progress callbacks of the current command (finished chunks, all chunks).
_PROGRESS: list[Callable[[int, int], None]] = []
#: The executors opened so far, by settings.
_OPEN: dict[tuple, Executor] = {}


def _close_all() -> None:
    while _OPEN:
        _OPEN.popitem()[1].close()


atexit.register(_close_all)


def check_settings(
    executor: str | None = None,
    scheduler: str | None = None,
    workers: int | None = None,
    chunk: int | None = None,
    dashes: str = "",
) -> None:
    """ValueError naming the setting for settings :func:`use` cannot run: an unknown
    executor, dask without dask.distributed, a scheduler that is not an address or comes
    with another executor or with workers, workers that are not a whole number from 1 to
    :func:`max_local_workers`, a chunk below 1. ``dashes="--"`` words them as the command
    line's options."""
    o = dashes
    if executor is not None and executor not in EXECUTORS:
        raise ValueError(f"{o}executor {executor}: choose one of {', '.join(EXECUTORS)}")
    if executor == "dask" and not dask_available():
        raise ValueError(f"{o}executor dask needs dask.distributed: {INSTALL_DASK}")
    if scheduler is not None and executor not in ("dask", None):
        raise ValueError(f"{o}scheduler is the address of a Dask scheduler: give {o}executor dask")
    if scheduler is not None:
        try:
            check_scheduler_address(scheduler)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"{o}scheduler {exc}") from None
    if workers is not None and not 1 <= _whole(workers) <= max_local_workers():
        raise ValueError(
            f"{o}workers {workers!r}: give a number of worker processes from 1 to "
            f"{max_local_workers()} (4 per core of this machine)"
        )  # (use() took 0 or 10**6: the cap of the config and the command line did not apply)
    if workers is not None and scheduler is not None:
        raise ValueError(f"{o}workers starts local workers; a running {o}scheduler has its own")
    if workers is not None and executor == "local":
        raise ValueError(f"{o}workers needs {o}executor processes or dask")
    if chunk is not None and not _whole(chunk) >= 1:
        raise ValueError(f"chunk {chunk}: give a whole number of designs, 1 or more")


def _whole(value) -> float:
    """``value`` as an integer, NaN when it is not a whole number (refused by the checks)."""
    try:
        return operator.index(value)
    except TypeError:
        return math.nan


@contextlib.contextmanager
def use(
    executor: str | None = None,
    scheduler: str | None = None,
    workers: int | None = None,
    chunk: int | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> Iterator[None]:
    """Within the block, these settings win over every config's ``execution:`` section (None
    leaves a setting to the config), ``progress(done, total)`` hears of every finished chunk,
    and the executors opened are closed at its end (the command line's ``--executor``,
    ``--scheduler``, ``--workers``). Settings it cannot run are a ValueError first
    (:func:`!check_settings`)."""
    check_settings(executor, scheduler, workers, chunk)
    given = {"executor": executor, "scheduler": scheduler, "workers": workers, "chunk": chunk}
    saved = dict(_OVERRIDES), list(_PROGRESS)
    _OVERRIDES.update({k: v for k, v in given.items() if v is not None})
    if progress is not None:
        _PROGRESS.append(progress)
    try:
        yield
    finally:
        _OVERRIDES.clear()
        _OVERRIDES.update(saved[0])
        _PROGRESS[:] = saved[1]
        if not _OVERRIDES:
            _close_all()


def settings(execution=None) -> dict[str, Any]:
    """The settings in force for a config's ``execution`` section (or None): the section's,
    then the command line's (:func:`use`); in a worker process always ``local``."""
    found = {"executor": "local", "scheduler": None, "workers": None, "chunk": DEFAULT_CHUNK}
    if execution is not None:
        found.update({k: getattr(execution, k) for k in found})
    found.update(_OVERRIDES)
    if _READY:  # a worker never hands its chunk on
        found.update(executor="local", scheduler=None, workers=None)
    return found


def executor_for(execution=None) -> Executor:
    """The executor of a config's ``execution`` section as the command line may override it
    (:func:`settings`), opened on first use and kept until the command ends (or the process
    exits)."""
    s = settings(execution)
    if s["executor"] == "local":
        return _LOCAL
    key = (s["executor"], s["scheduler"], s["workers"])
    if key not in _OPEN:
        if s["executor"] == "processes":
            _OPEN[key] = ProcessExecutor(s["workers"])
        elif s["executor"] == "dask":
            if not dask_available():
                raise RuntimeError(f"the dask executor needs dask.distributed: {INSTALL_DASK}")
            try:
                _OPEN[key] = DaskExecutor(s["scheduler"], s["workers"])
            except (OSError, TimeoutError) as exc:
                raise SchedulerUnreachable(
                    f"--scheduler / execution.scheduler: no Dask scheduler answers at "
                    f"{s['scheduler']} within {CONNECT_TIMEOUT} s ({exc})"
                ) from None
            except (ValueError, TypeError) as exc:  # (tls:// without Dask's TLS settings)
                if s["scheduler"] is None:
                    raise
                raise SchedulerUnreachable(
                    f"--scheduler / execution.scheduler: cannot connect to {s['scheduler']} "
                    f"({' '.join(str(exc).split())})"
                ) from None
        else:
            raise ValueError(f"executor must be one of {EXECUTORS}, not {s['executor']!r}")
    return _OPEN[key]


def chunks(n: int, width: int) -> list[slice]:
    """The rows ``0 .. n-1`` in chunks of ``width`` (the last one shorter)."""
    return [slice(i, min(i + width, n)) for i in range(0, n, max(width, 1))]


def map_chunks(
    function: Callable[[Any, Any], Any], shared: Any, items: Sequence[Any], execution=None
) -> list[Any]:
    """``[function(shared, item) for item in items]`` on the executor in force for the
    config's ``execution`` section (:func:`executor_for`), in order; every finished chunk is
    reported to the command's progress callbacks."""
    executor = executor_for(execution)

    def progress(done: int, total: int) -> None:
        for callback in _PROGRESS:
            callback(done, total)

    return executor.map(function, shared, items, progress if _PROGRESS else None)


def chunk_width(execution=None) -> int:
    """Designs per chunk for a config's ``execution`` section (:func:`settings`)."""
    return int(settings(execution)["chunk"])


def is_local(execution=None) -> bool:
    """Whether the evaluation stays in this process."""
    return settings(execution)["executor"] == "local"
