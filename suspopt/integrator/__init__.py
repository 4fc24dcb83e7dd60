"""The batched fixed-step integrator of an assembled element network (:mod:`suspopt.network`):
classical RK4 for all P designs at once, on one of two engines that give the same numbers to
rounding (``simulation.engine``):

- ``numpy`` (:mod:`.rk4`, the reference): each stage is a few whole-population numpy
  operations; it covers every model, controller and road.
- ``compiled`` (:mod:`.compiled`, numba, a dependency of suspopt): the whole
  run in one compiled call, the element network as sparse loops, designs in blocks of lanes
  the compiler vectorises, the blocks spread over the cores. It covers the networks whose
  non-linear parts have a compiled law (Duffing springs, tyre lift-off, the seats' exact and
  Taylor mechanisms), with or without a semi-active controller (asked at its samples, its
  actuator lag applied in the kernel); any other run goes to the numpy engine, and
  :attr:`Trajectory.engine` says which one ran.
- ``auto`` (the default): ``compiled`` where it pays end to end, else ``numpy``
  (:func:`auto_engine`: every evaluation of objectives and every run of an optimisation's
  config, and other simulations from :data:`AUTO_STEPS` steps); ``numpy`` where numba cannot
  be imported, said once (:mod:`suspopt._notices`).

Both take the same steps, samples, road edges (split steps with their exact impulses) and
divergence rule; see :mod:`.rk4` for what those are.
"""

from __future__ import annotations

import functools
from collections.abc import Iterator
from typing import Any

import numpy as np

from .._numba_cache import INSTALL_FAST, compiled_available
from .rk4 import (
    DIVERGENCE_LIMIT,
    Controller,
    EdgePlan,
    Edges,
    Held,
    HeldRecords,
    Run,
    Trajectory,
)
from .rk4 import integrate as integrate_numpy
from .rk4 import windows as windows_numpy

__all__ = ["Controller", "Held", "HeldRecords", "Trajectory", "Edges", "EdgePlan", "Run"]
__all__ += [
    "integrate",
    "integrate_numpy",
    "windows",
    "WINDOW_MULTIPLE",
    "DIVERGENCE_LIMIT",
    "ENGINES",
    "compiled_available",
    "compiled_runs",
    "auto_engine",
    "AUTO_STEPS",
    "AUTO_DESIGNS",
]

#: A window's samples are a multiple of this (the compiled kernel's sample buffer).
WINDOW_MULTIPLE = 32
#: The values of ``simulation.engine``.
ENGINES = ("numpy", "compiled", "auto")

#: ``auto``'s rule for a simulation that is not an evaluation (:func:`auto_engine`): the
#: compiled engine from this many integration steps of one design, fewer as the designs grow
#: (each :data:`AUTO_DESIGNS` designs count as another run). Measured end to end, whole
#: processes, the kernel cached, on the 2-core development machine
#: (``benchmarks/bench_engines.py``; docs/performance.md): the numpy engine costs about
#: 0.12 ms per step of a few designs, more as the batch grows, and the compiled engine about
#: 1 s more to start (numba's import and its cache's load); one design of the half car
#: breaks even between 3,000 steps (numpy 12 % faster) and 10,000 (compiled 38 % faster),
#: and 100 designs over 3,000 steps take the same time on both.
AUTO_STEPS = 6_000
#: The designs that count as one more run of :data:`AUTO_STEPS` (the numpy engine's time per
#: step grows with the batch, the compiled engine's per design much less).
AUTO_DESIGNS = 100

_fallback_told: list[bool] = []


def auto_engine(steps: int, designs: int, evaluation: bool) -> str:
    """The engine that ``simulation.engine: auto`` runs: ``compiled`` where numba can be
    imported and the run is worth it, else ``numpy``.

    Parameters
    ----------
    steps : int
        Integration steps of the run (``simulation.duration / dt``).
    designs : int
        Designs of the whole batch (not of a chunk: every executor then runs one engine).
    evaluation : bool
        Whether the run evaluates objectives of an optimisation's config (``optimise``,
        ``kesort``, the analyses of a front, or a simulation of a config with an
        ``optimiser:`` section): always compiled, so that every command of one study runs
        one engine and a design's values repeat bit for bit from one command to the next.

    Returns
    -------
    str
        ``"compiled"`` or ``"numpy"``. Without numba, ``"numpy"`` and one notice per
        process (:mod:`suspopt._notices` ``engine-fallback``, else a ``UserWarning``).
    """
    if not compiled_available():
        if not _fallback_told:
            _fallback_told.append(True)
            message = (
                "simulation.engine auto runs on the numpy engine: numba cannot be imported on "
                "this machine (the compiled engine needs it; pip install numba)"
            )
            from .. import _notices

            if not _notices.tell("engine-fallback", message=message):
                import warnings

                warnings.warn(message, stacklevel=3)
        return "numpy"
    if evaluation or steps * (1 + designs / AUTO_DESIGNS) >= AUTO_STEPS:
        return "compiled"
    return "numpy"


def integrate(run: Run, engine: str = "numpy") -> Trajectory:
    """Classical RK4 of ``run`` (:class:`Run`) on ``engine`` (module docstring; ``exact``:
    the exact stepper of a linear network, :mod:`.exact`). A
    ``compiled`` request without numba is a ``RuntimeError`` naming the install command (the
    config's checks turn it into bad input first)."""
    return next(windows(run, engine))[1]


def windows(
    run: Run,
    engine: str = "numpy",
    width: int | None = None,
    recorded: np.ndarray | None = None,
    accumulators: Any = None,
) -> Iterator[tuple[int, Trajectory]]:
    """The integration of :func:`integrate` as consecutive windows of at most ``width``
    output samples, a multiple of :data:`WINDOW_MULTIPLE` (all of them when None):
    ``(first sample, trajectory of the window)``; the windows joined are the whole run bit
    for bit, on either engine (:func:`.rk4.windows`). A controlled run comes whole.
    ``recorded (3n,)``: the rows of the states ``[q; q']`` and then of the accelerations the
    caller reads; the compiled engine may leave the others NaN (:func:`.compiled.windows`),
    the numpy engine computes them all anyway. The compiled engine integrates the next
    window while the caller has this one in a batch of :data:`AHEAD_DESIGNS` or more
    (:func:`_ahead`), when the caller reads any recorded row. ``accumulators``
    (:class:`.accumulators.Accumulators`, compiled engine only): signals the kernel forms
    and reduces itself as it integrates, found in it after the last window."""
    if engine == "exact":  # (simulation.method exact: the linear network's exact stepper)
        from . import exact

        return exact.windows(run, width, recorded)
    if engine not in ENGINES:
        raise ValueError(f"engine must be one of {ENGINES}, not {engine!r}")
    if engine == "compiled" and not compiled_available():
        raise RuntimeError(f"the compiled engine needs numba: {INSTALL_FAST}")
    if compiled_runs(run, engine):
        from . import compiled

        stream = compiled.windows(run, width, recorded, accumulators)
        if run.asm.P >= AHEAD_DESIGNS and (recorded is None or recorded.any()):
            stream = _ahead(stream)
        return _one_blas_thread(stream)
    return windows_numpy(run, width)


def compiled_runs(run: Run, engine: str) -> bool:
    """Whether :func:`windows` runs ``run`` on the compiled engine (asked for, or ``auto``,
    with numba installed and the network covered)."""
    if engine in ("numpy", "exact") or not compiled_available():
        return False
    from . import compiled

    return compiled.unsupported(run.asm, run.controller) is None


#: The fewest designs of a batch whose next window the compiled engine integrates while the
#: caller reduces this one (:func:`_ahead`). Measured on this 2-core machine (2026-12-03),
#: interleaved: ``suspopt optimise configs/ch5/case4_s2.yaml`` (1000 designs) 56-62 s
#: without the overlap and 52-55 s with it; ``configs/ch6/part_b.yaml`` (100 designs)
#: 11.9-13.4 s without and 14.7-15.5 s with it (the kernel's two threads and the caller's
#: then share two cores, and the small windows gain less than that costs). A run whose
#: signals the kernel reduces itself (:mod:`.accumulators`), recording no row, has nothing to
#: overlap: ``Problem.evaluate`` of configs/ch5/case4_s1.yaml at 1000 designs took 24-25 ms
#: inline against 31-43 ms with the thread (2026-12-05).
AHEAD_DESIGNS = 500


def _ahead(windows: Iterator[tuple[int, Trajectory]]) -> Iterator[tuple[int, Trajectory]]:
    """``windows`` with the next window integrated in a thread while the caller reduces the
    one it has (the kernel holds no GIL; each window has arrays of its own): the kernel and
    numpy's reductions overlap instead of taking turns. The same windows, in order; an
    exception of the integration comes out where that window would have. One thread at a
    time runs the kernel (numba's ``workqueue`` threading layer allows no more)."""
    import threading

    box: dict[str, Any] = {}

    def fetch() -> None:
        try:
            box["item"] = next(windows, None)
        except BaseException as exc:  # noqa: BLE001 - raised again in the caller's thread
            box["error"] = exc

    fetch()
    try:
        while True:
            item, error = box.pop("item", None), box.pop("error", None)
            if error is not None:
                raise error
            if item is None:
                return
            thread = threading.Thread(target=fetch, daemon=True)
            thread.start()
            try:
                yield item
            finally:
                thread.join()
    finally:  # a caller that stops early closes the windows (and gives BLAS its threads)
        close = getattr(windows, "close", None)
        if close is not None:
            close()


def _one_blas_thread(windows: Iterator[tuple[int, Trajectory]]):
    """``windows`` with the BLAS libraries held to one thread from the first window until the
    last has been used (the caller reduces each window between two of them). The kernel runs
    its blocks on every core; a BLAS product of the caller's (a deformation of a window, a
    few rows by P x T) spread over the cores as well leaves threads spinning that the
    kernel's next stretch then waits for: 1000 designs of the Ch. 5 problem took 0.33 s per
    evaluation with OpenBLAS's two threads and 0.19 s with one (``Problem.evaluate``; the
    command line sets one thread at start-up anyway, :data:`suspopt._entry.
    BLAS_THREAD_VARIABLES`). With threadpoolctl missing (it comes with the ``fast`` extra)
    the threads are left as they are. The first window comes before the hold: numba's first
    call in a process loads scipy's BLAS (``numba.np.linalg``), and the libraries are listed
    once per process (:func:`_blas_pools`), after that."""
    first = next(windows, None)
    if first is None:
        return
    pools = _blas_pools()
    if pools is None:
        yield first
        yield from windows
        return
    with pools.limit(limits=1):
        yield first
        yield from windows


@functools.cache
def _blas_pools():
    """The BLAS libraries loaded in this process, or None without threadpoolctl (listing
    them reads the process's memory map, about 4 ms, so it is done once)."""
    try:
        from threadpoolctl import ThreadpoolController
    except ImportError:
        return None
    return ThreadpoolController().select(user_api="blas")
