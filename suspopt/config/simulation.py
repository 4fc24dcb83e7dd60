"""The ``simulation:`` and ``output:`` sections."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import AfterValidator, Field, model_validator

from ..execution import DEFAULT_CHUNK, check_scheduler_address
from .base import Duration, Section, Step

__all__ = ["Simulation", "Output", "Execution"]


def _installed(choice: str) -> str:
    """``choice`` (an engine or an executor), or a ValueError that names the extra to install
    when what it needs is missing: numba for the ``compiled`` engine, dask.distributed for
    the ``dask`` executor (looked for here, not when suspopt starts)."""
    if choice == "compiled":
        from .._numba_cache import INSTALL_FAST, compiled_available

        if not compiled_available():
            raise ValueError(f"the compiled engine needs numba: {INSTALL_FAST}")
    if choice == "dask":
        from ..execution import INSTALL_DASK, dask_available

        if not dask_available():
            raise ValueError(f"the dask executor needs dask.distributed: {INSTALL_DASK}")
    return choice


class Simulation(Section):
    """Fixed-step integration settings (classical 4th-order Runge-Kutta)."""

    duration: Duration = Field(description="simulated time [s]")
    dt: Step = Field(1.0e-3, description="integration step [s]")
    output_dt: Step | None = Field(
        None, description="output sample interval [s], a whole multiple of dt (default dt)"
    )
    engine: Annotated[Literal["numpy", "compiled", "auto"], AfterValidator(_installed)] = Field(
        "auto",
        description="the integrator: auto (compiled where it pays end to end: every "
        "evaluation of objectives and every run of a config with an optimiser, other runs "
        "from 6,000 steps (fewer for a batch); numpy where numba cannot be imported), numpy (the reference) or "
        "compiled (numba: every vehicle, seat, road and controller; a non-linear element "
        "without a compiled law runs on numpy); the two agree to rounding",
    )
    method: Literal["time", "exact", "spectral"] = Field(
        "time",
        description="how runs are integrated and objectives evaluated: time (RK4 over "
        "duration), exact (a linear model without a controller: each design's exact "
        "transition over a step, the road linear between the steps, at any dt; "
        "suspopt.integrator.exact) or spectral (stationary statistics by the frequency "
        "integral over the road's band; a linear model on an iso8608 road; var, std, rms, "
        "mean, rms_weighted, dissipated_power and dynamic_tyre_load only; simulate "
        "integrates it in time)",
    )

    @model_validator(mode="after")
    def _check_steps(self) -> Simulation:
        if self.dt > self.duration:
            raise ValueError("dt must not exceed duration")
        if self.output_dt is not None:
            if self.output_dt > self.duration:
                raise ValueError(
                    f"output_dt ({self.output_dt}) must not exceed duration "
                    f"({self.duration}): a run needs two output samples"
                )
            ratio = self.output_dt / self.dt
            if ratio < 1 - 1e-9 or abs(ratio - round(ratio)) > 1e-6:
                raise ValueError(
                    f"output_dt ({self.output_dt}) must be a whole multiple of dt ({self.dt})"
                )
        return self

    @property
    def n_steps(self) -> int:
        """Number of integration steps (duration rounded to whole steps)."""
        return int(round(self.duration / self.dt))

    @property
    def output_every(self) -> int:
        """Integration steps per output sample."""
        return 1 if self.output_dt is None else int(round(self.output_dt / self.dt))

    @property
    def output_rate(self) -> float:
        """Output sample rate [Hz]."""
        return 1.0 / (self.dt * self.output_every)


class Output(Section):
    """What ``suspopt simulate`` writes to HDF5."""

    signals: list[str] | str = Field(
        "all", description="signal names to store, or 'all' (every signal the model has)"
    )
    float32: bool = Field(False, description="store signals as float32 to halve file size")

    @model_validator(mode="after")
    def _check(self) -> Output:
        if isinstance(self.signals, str) and self.signals != "all":
            raise ValueError("signals must be 'all' or a list of signal names")
        return self


class Execution(Section):
    """Where a population is simulated (:mod:`suspopt.execution`): in this process, a local
    pool of processes or a Dask cluster. Every executor gives the same bits; the command
    line's ``--executor``, ``--scheduler`` and ``--workers`` win over this section."""

    executor: Annotated[Literal["local", "processes", "dask"], AfterValidator(_installed)] = Field(
        "local",
        description="local (this process), processes (a local pool of workers) or dask (a "
        'Dask scheduler, or a local Dask cluster; pip install "suspopt[dask]")',
    )
    workers: int | None = Field(
        None,
        ge=1,
        le=4096,
        description="worker processes that processes, or dask without a scheduler, starts "
        "(default: the machine's cores)",
    )
    scheduler: Annotated[str, AfterValidator(check_scheduler_address)] | None = Field(
        None,
        min_length=1,
        max_length=500,
        description="address of a running Dask scheduler, e.g. tcp://host:8786 (dask only; "
        "without it suspopt starts a local cluster)",
    )
    chunk: int = Field(
        DEFAULT_CHUNK,
        ge=1,
        le=1_000_000,
        description="designs per chunk sent to a worker: the same whatever the number of "
        "workers, so every design meets the same arithmetic",
    )

    @model_validator(mode="after")
    def _check(self) -> Execution:
        if self.scheduler is not None and self.executor != "dask":
            raise ValueError("scheduler is the address of a Dask scheduler: set executor: dask")
        if self.workers is not None and self.executor == "local":
            raise ValueError("workers needs executor: processes or dask")
        if self.workers is not None and self.scheduler is not None:
            raise ValueError("workers are started without a scheduler; a running one has its own")
        from ..execution import max_local_workers

        if self.workers is not None and self.workers > max_local_workers():
            raise ValueError(
                f"workers ({self.workers}) is more than {max_local_workers()} (4 per core of "
                f"this machine); use a Dask scheduler for more"
            )
        return self
