"""The batched fixed-step integrator of an assembled element network (:mod:`suspopt.network`):
classical RK4 for all P designs at once, on one of two engines that give the same numbers to
rounding (``simulation.engine``):

- ``numpy`` (:mod:`.rk4`, the reference): each stage is a few whole-population numpy
  operations; it covers every model, controller and road.
- ``compiled`` (:mod:`.compiled`, needs numba: ``pip install "suspopt[fast]"``): the whole
  run in one compiled call, the element network as sparse loops, designs in blocks of lanes
  the compiler vectorises, the blocks spread over the cores. It covers the networks whose
  non-linear parts have a compiled law (Duffing springs, tyre lift-off, the seats' exact and
  Taylor mechanisms), with or without a semi-active controller (asked at its samples, its
  actuator lag applied in the kernel); any other run goes to the numpy engine, and
  :attr:`Trajectory.engine` says which one ran.
- ``auto``: ``compiled`` when numba is installed, else ``numpy``.

Both take the same steps, samples, road edges (split steps with their exact impulses) and
divergence rule; see :mod:`.rk4` for what those are.
"""

from __future__ import annotations

import functools

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

__all__ = ["Controller", "Held", "HeldRecords", "Trajectory", "Edges", "EdgePlan", "Run"]
__all__ += ["integrate", "integrate_numpy", "DIVERGENCE_LIMIT", "ENGINES", "compiled_available"]

#: The values of ``simulation.engine``.
ENGINES = ("numpy", "compiled", "auto")

#: How to install the compiled engine.
INSTALL_FAST = 'pip install "suspopt[fast]"'


@functools.cache
def compiled_available() -> bool:
    """Whether numba can be imported (the compiled engine's one dependency); looked up once
    per process, not at every simulation."""
    import importlib.util

    return importlib.util.find_spec("numba") is not None


def integrate(run: Run, engine: str = "numpy") -> Trajectory:
    """Classical RK4 of ``run`` (:class:`Run`) on ``engine`` (module docstring). A
    ``compiled`` request without numba is a ``RuntimeError`` naming the install command (the
    config's checks turn it into bad input first)."""
    if engine not in ENGINES:
        raise ValueError(f"engine must be one of {ENGINES}, not {engine!r}")
    if engine == "compiled" and not compiled_available():
        raise RuntimeError(f"the compiled engine needs numba: {INSTALL_FAST}")
    if engine != "numpy" and compiled_available():
        from . import compiled

        if compiled.unsupported(run.asm, run.controller) is None:
            return compiled.integrate(run)
    return integrate_numpy(run)
