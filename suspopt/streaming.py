"""Metrics of a run without its (P, T) signals: what optimisation needs.

An optimisation, ``kesort``'s re-simulation and the pseudo-fronts of ``analyse`` need only
the objectives' and constraints' values, not the signals. :func:`reduce` integrates the run
in windows of output samples (:func:`window_width`; :func:`suspopt.integrator.windows`, the same
steps as a whole run, bit for bit), computes each window's signals with the one signal table
(:class:`suspopt.result.Result` over the window) and lets each metric take what it needs
from them, as its :class:`suspopt.specs.MetricDef` says (``stream``):

- ``moments`` (variance, standard deviation, r.m.s., mean) and ``extremes`` (maximum,
  minimum, largest magnitude, range): the running state of
  :func:`suspopt.metrics.stats.moments` carried from window to window, so every value is the
  whole signal's, bit for bit; ``window_max`` (a maximum over time of a value per sample, such
  as the spring usage of Eq 5.3): the largest of the windows' values;
- ``weighted`` (the ISO 2631 weighted r.m.s., VDV, MTVV and crest factor, Eq 2.78-2.83): the
  weighting's recursive filter (:func:`suspopt.metrics.iso2631.weighting_filter`) runs on
  from window to window with its state, and so do the power sums
  (:func:`~suspopt.metrics.iso2631.power_state`) and the running r.m.s. of the MTVV
  (:func:`~suspopt.metrics.iso2631.running_state`): every weighted metric is the whole run's,
  bit for bit;
- ``keep`` (the transient metrics, the dissipated power, the dynamic tyre load, the switch
  count): the signals they read are kept whole and the metric is computed once at the end,
  exactly as on a whole run.

The compiled engine records only the rows of the states and accelerations those signals read
(:func:`recorded_rows` finds them by probing the signal table; the Ch. 5 problem's objectives
read 5 of its 12 rows): writing the samples is about a third of its time when it keeps every
row. The numpy engine computes every row anyway.

On the compiled engine (without a controller) the kernel itself forms every signal that is
affine in a sample (:func:`suspopt.affine.affine_signals` probes the signal table: travel,
tyre deflection, accelerations...) and reduces it as it integrates, by the same steps
(:mod:`suspopt.loops._compiled`: the moments and extremes, the weighting filter and its
sums), and a ``window_max`` metric that its extremes give
(:class:`suspopt.specs.MetricDef`'s ``extremes``: the spring usage of Eq 5.3); those rows are
neither recorded nor passed through numpy (:mod:`suspopt.integrator.accumulators`), and its
state is taken over as the windows' would be. Its values agree with the whole run's metrics
to rounding (about 1e-15 relative: it forms the signal as ``e + Σ c x``, the signal table
in its own order), and a design's values do not depend on its batch, block, window or
thread. The MTVV, the ``keep`` metrics and signals that are not affine are reduced from the
windows as above.

Memory therefore holds one window of every signal and state, the MTVV's last ``τ fs``
values, and the kept signals; with no ``keep`` metric it grows with the designs, not with the
run's length. A run with a semi-active controller is one window, the whole run (its hold
keeps records over the run), reduced the same way.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from .config import Config
from .specs import METRICS

__all__ = ["reduce", "Reduced", "BLOCK", "window_width", "recorded_rows"]

#: The least samples of one window (a multiple of
#: :data:`suspopt.integrator.WINDOW_MULTIPLE` and of the weighted sums' ``SUM_BLOCK``).
BLOCK = 256
#: Memory of one window's states and signals [bytes]: a window is as many whole blocks as
#: fit (a few designs: the whole run at once), at least one.
WINDOW_BYTES = 64 << 20


class _Moments:
    """The streamed moments and extremes of each design's samples
    (:func:`suspopt.metrics.stats.moments`), from which :meth:`value` gives a statistic."""

    def __init__(self) -> None:
        self.state: tuple | None = None

    def add(self, x: np.ndarray) -> None:
        """The samples ``x (P, T)`` that follow."""
        from .metrics.stats import moments

        self.state = moments(x, self.state)

    def value(self, metric: str) -> np.ndarray:
        from .metrics.stats import moment_value

        assert self.state is not None  # (every window adds to it)
        return moment_value(metric, self.state)


class _Weighted:
    """One signal under one ISO 2631 weighting as the windows arrive (module docstring):
    the filter's state, the weighted power sums (:func:`suspopt.metrics.iso2631.power_state`)
    and for each MTVV window ``τ`` [s] the running state of Eq 2.80
    (:func:`~suspopt.metrics.iso2631.running_state`) and the largest running r.m.s. so far."""

    def __init__(self, weighting: str | None) -> None:
        self.weighting = weighting
        self.taus: set[float] = set()
        self.fs = 0.0
        self.sums: tuple | None = None
        self.filter: Any = None
        self.state: Any = None
        self.running: dict[float, list[Any]] = {}

    def add(self, x: np.ndarray, time: np.ndarray) -> None:
        from .metrics.iso2631 import power_state, running_state, weighting_filter

        if self.sums is None:
            self.fs = 1.0 / (time[1] - time[0])  # the output rate, as the whole run's metric
            self.filter = weighting_filter(self.weighting, self.fs)
        aw = np.asarray(x, dtype=float)  # read only: the filter's output is a new array
        if self.filter is not None:
            aw, self.state = self.filter.apply(aw, self.state)
        self.sums = power_state(aw, self.sums)
        if self.taus:
            with np.errstate(over="ignore", invalid="ignore"):  # a diverging design
                squared = np.square(aw)  # (once for every MTVV window)
                for tau in self.taus:
                    state, largest = self.running.get(tau, (None, None))
                    rms, state = running_state(squared, self.fs, tau, state)
                    top = np.max(rms, axis=-1)
                    largest = top if largest is None else np.maximum(largest, top)
                    self.running[tau] = [state, largest]

    def value(self, spec) -> np.ndarray:
        from .metrics.iso2631 import weighted_value

        if spec.metric == "mtvv":
            return self.running[spec.tau][1]
        assert self.sums is not None  # (every window adds to them)
        return weighted_value(spec.metric, self.sums, self.fs)


class _Kept:
    """What a ``keep`` metric reads of a Result: the kept signals whole, the run's time, its
    config and model."""

    def __init__(self, signals: Mapping[str, np.ndarray], time: np.ndarray, config, model):
        self.signals, self.time, self.config, self.model = signals, time, config, model


class Reduced:
    """What :func:`reduce` gives: each requested metric's (P,) values (:meth:`metric`), the
    divergence times ``diverged_at (P,)`` [s] (NaN when sound), the signal table's names
    (``signals``) and units (:meth:`signal_unit`), the model and the engine that ran; the
    part of a :class:`~suspopt.result.Result` that :func:`suspopt.specs.evaluate_spec`
    reads."""

    def __init__(self, model, table, values: dict, diverged_at: np.ndarray, engine: str):
        self.model, self._table, self._values = model, table, values
        self.diverged_at, self.engine = diverged_at, engine

    @property
    def signals(self) -> Mapping[str, Any]:
        return self._table

    @property
    def diverged(self) -> np.ndarray:
        return ~np.isnan(self.diverged_at)

    def signal_unit(self, name: str) -> str:
        return self._table[name].unit

    def metric(self, spec, name: str) -> np.ndarray:
        """The values of a requested spec on signal ``name``."""
        return self._values[(id(spec), name)]


def window_width(cfg: Config, model, attachments, P: int, signals: int) -> int:
    """Output samples of one window of a run of P designs computing ``signals`` signals: as
    many whole :data:`BLOCK` s as :data:`WINDOW_BYTES` holds by
    :func:`suspopt.simulation.run_memory`'s estimate, at least one block."""
    from .simulation import run_memory

    per_sample = run_memory(cfg, model, attachments, 1, signals, window=1)[1]
    blocks = int(WINDOW_BYTES // (max(P, 1) * per_sample)) // BLOCK
    return BLOCK * max(1, blocks)


def _kept_names(spec, name: str) -> list[str]:
    """The signals a ``keep`` metric reads: ``name`` and, for a derived metric that reads a
    second family, that family's signal of the same corner."""
    also = METRICS[spec.metric].also
    return [name] + ([f"{also}.{name.rsplit('.', 1)[1]}"] if also else [])


def _weighted(requests) -> dict[tuple[str, Any], _Weighted]:
    """One :class:`_Weighted` per (signal, weighting) the ``weighted`` metrics of
    ``requests`` read, with the MTVV windows asked of it."""
    found: dict[tuple[str, Any], _Weighted] = {}
    for spec, names in requests:
        if METRICS[spec.metric].stream != "weighted":
            continue
        for name in names:
            accumulator = found.setdefault((name, spec.weighting), _Weighted(spec.weighting))
            if spec.metric == "mtvv":
                accumulator.taus.add(spec.tau)
    return found


def recorded_rows(result_of, n: int, P: int, names: Sequence[str]) -> np.ndarray:
    """Which rows of a run's states ``[q; q']`` (2n) and accelerations (n) the signals
    ``names`` read, ``(3n,)`` bool: found by reading them from probe samples, not from a
    second description of the signal table. ``result_of(states, accelerations)`` is the
    :class:`~suspopt.result.Result` of P designs' probe samples ``(2n, P, T)``,
    ``(n, P, T)``.

    Sample ``2k`` of a probe moves row ``k`` alone, sample ``2k + 1`` none; there are three
    probes, moving it up, down (by 0.5 from values of about 0.01, so that a sign or a
    threshold flips) and to NaN, read one after the other from one Result. A row is read when
    a signal's sample ``2k`` changes or turns NaN in any of them, so a row that is not
    recorded (:func:`suspopt.integrator.compiled.windows`, whatever its memory holds) reaches
    no signal, not even through a zero coefficient. A signal is a function of the sample at
    its instant; one that is not (a move reaching a sample that did not move), or that is
    not finite on the probe, makes every row read."""
    rows, T = 3 * n, 6 * n
    pattern = 0.01 * np.sin(1.0 + np.arange(rows * T, dtype=float)).reshape(rows, 1, T)
    probes = [pattern]
    for value in (0.5, -0.5, np.nan):
        moved = pattern.copy()
        moved[np.arange(rows), 0, 2 * np.arange(rows)] += value
        probes.append(moved)
    # the four probes one after the other in time, read in one Result (a signal that is not
    # a function of its instant's sample shows where a later block's samples did not move)
    x = np.broadcast_to(np.concatenate(probes, axis=-1), (rows, P, 4 * T))
    signals = result_of(x[: 2 * n], x[2 * n :]).signals
    read = np.zeros(rows, np.bool_)
    for name in names:
        if name not in signals:  # a controller's records (no controller in the probe): no state
            continue
        values = np.asarray(signals[name])
        base = values[..., :T]
        if values.shape[-1] != 4 * T or not np.isfinite(base).all():
            return np.ones(rows, np.bool_)
        axes = tuple(range(base.ndim - 1))
        differs = np.zeros(T, np.bool_)
        for k in (1, 2, 3):
            differs |= (values[..., k * T : (k + 1) * T] != base).any(axis=axes)  # (NaN differs)
        if differs[1::2].any():  # a signal that is not a function of its instant's sample
            return np.ones(rows, np.bool_)
        read |= differs[0::2]
    return read


def _probe_result(cfg: Config, setup, states, accelerations, z=None, zd=None):
    """The Result of the probe samples ``states (2n, P, T)``, ``accelerations (n, P, T)``
    of the designs of ``setup = (designs, model, attachments, run, road inputs (n_u, G, ..))``,
    without a controller (whose records read no state), under road heights and rates ``z,
    zd (n_u, T)`` at those samples (zero when None), for :func:`recorded_rows` and
    :func:`suspopt.affine.affine_signals`."""
    from .integrator import Trajectory
    from .simulation import _result

    pv, model, attachments, run, road = setup
    T, step = states.shape[-1], 2 * cfg.simulation.output_every
    grid = [np.zeros(road.shape[:2] + (T * step,)) for _ in range(2)]
    for inputs, given in zip(grid, (z, zd)):
        if given is not None:
            inputs[:, :, ::step] = given[:, None]
    times = np.arange(T * step) * (0.5 * cfg.simulation.dt)
    traj = Trajectory(states, accelerations, None, {}, np.full(pv.P, np.nan))
    return _result(cfg, pv, model, None, attachments, run, (grid[0], grid[1], times), traj)


def _recorded(cfg: Config, setup, names: Sequence[str]) -> np.ndarray | None:
    """The rows of the states and accelerations the signals ``names`` read
    (:func:`recorded_rows` on :func:`_probe_result`; ``setup = (designs, model,
    attachments, run, road inputs)``), or None on the numpy engine or without numba (which
    computes every row)."""
    from .integrator import compiled_available

    if cfg.simulation.engine == "numpy" or not compiled_available():
        return None
    pv, run = setup[0], setup[3]
    if not names:  # (every signal formed in the kernel: no row to record)
        return np.zeros(3 * run.asm.n, np.bool_)

    def result_of(states, accelerations):  # (no road: its signals read no state)
        return _probe_result(cfg, setup, states, accelerations)

    return recorded_rows(result_of, run.asm.n, pv.P, names)


def _kernel_streams(cfg: Config, setup, streams: _Streams):
    """The signals of ``streams`` the compiled kernel forms and reduces itself
    (:func:`suspopt.affine.kernel_accumulators`; ``setup = (designs, model, attachments,
    run, (z, zd, t_grid))``), or None: on the numpy engine, without numba, with a
    controller, or where the compiled engine does not run the network."""
    from .integrator import compiled_runs

    pv, model, attachments, run, road = setup
    from .simulation import stepper

    if run.controller is not None or not compiled_runs(run, stepper(cfg)):
        return None
    from .affine import kernel_accumulators

    probed = (pv, model, attachments, run, road[0])

    def result_of(states, accelerations, z, zd):
        return _probe_result(cfg, probed, states, accelerations, z, zd).signals

    shape = (run.asm.n, road[0].shape[0], pv.P)
    step = 2 * cfg.simulation.output_every
    return kernel_accumulators(result_of, shape, streams.kernel_candidates(model), road, step)


def _by_extremes(spec, model, name: str) -> bool:
    """Whether a ``window_max`` metric's value is that of the signal's extremes alone."""
    extremes = METRICS[spec.metric].extremes
    return extremes is not None and extremes(spec, model, name)


class _Streams:
    """The accumulators of one :func:`reduce`: per signal its moments, extremes, weighted
    sums, the windows' maxima of the ``window_max`` metrics and the pieces of the kept
    signals (:class:`suspopt.specs.MetricDef`'s ``stream``)."""

    def __init__(self, requests) -> None:
        def streamed(kind: str) -> list[str]:
            return sorted({n for spec, names in requests if METRICS[spec.metric].stream == kind
                           for n in names})  # fmt: skip

        self.requests = requests
        # (one state per signal gives its moments and its extremes)
        both = sorted({*streamed("moments"), *streamed("extremes")})
        self.moments = {name: _Moments() for name in both}
        self.weighted = _weighted(requests)
        self.maxima = [(spec, n) for spec, names in requests
                       if METRICS[spec.metric].stream == "window_max" for n in names]  # fmt: skip
        self.window_max: dict[tuple[int, str], Any] = {}
        kept = {k for spec, names in requests if METRICS[spec.metric].stream == "keep"
                for n in names for k in _kept_names(spec, n)}  # fmt: skip
        self.pieces: dict[str, list[np.ndarray]] = {name: [] for name in sorted(kept)}
        self.times: list[np.ndarray] = []
        self.kernel: Any = None  # (:meth:`hand_over`)
        self.handed: list[str] = []
        self.by_extremes: list[tuple[Any, str]] = []

    def kernel_candidates(self, model) -> tuple[list[str], list[tuple[str, Any]]]:
        """The signals whose moments or extremes are asked (or a ``window_max`` metric that
        its extremes give, :class:`suspopt.specs.MetricDef`, for the designs of ``model``),
        and the (signal, weighting) pairs asked without an MTVV: what the compiled kernel
        may reduce itself."""
        self.by_extremes = [(spec, name) for spec, name in self.maxima
                            if _by_extremes(spec, model, name)]  # fmt: skip
        names = set(self.moments) | {n for _, n in self.by_extremes}
        return sorted(names), [key for key, w in self.weighted.items() if not w.taus]

    def hand_over(self, kernel) -> None:
        """Leave the signals of ``kernel`` (:class:`suspopt.integrator.accumulators.
        Accumulators`) to it: the windows do not reduce them (:meth:`take` fills them in
        from the kernel's accumulators after the run)."""
        self.kernel = kernel
        names = {s.name for s in kernel.signals}
        for s in kernel.signals:
            if self.moments.pop(s.name, None) is not None:
                self.handed.append(s.name)
        for key in kernel.pair_keys:
            del self.weighted[key]
        self.by_extremes = [(spec, n) for spec, n in self.by_extremes if n in names]
        self.maxima = [m for m in self.maxima if m not in self.by_extremes]

    def numpy_reads(self) -> list[str]:
        """The signals the windows' reductions read (those not handed to the kernel)."""
        return sorted(
            set(self.moments) | {name for name, _ in self.weighted}
            | {name for _, name in self.maxima} | set(self.pieces)
        )  # fmt: skip

    def take(self, samples: int, cfg: Config, model, P: int) -> None:
        """The handed signals' moments, extremes, weighted sums and the ``window_max``
        metrics their extremes give, from the kernel's accumulators over ``samples`` samples
        of the P designs of ``model``."""
        kernel = self.kernel
        index = {s.name: i for i, s in enumerate(kernel.signals)}
        for spec, name in self.by_extremes:  # (the metric of the largest and smallest sample)
            two = np.stack(kernel.moments(index[name], P)[2:], axis=-1)
            record = _Kept({name: two}, np.zeros(2), cfg, model)
            self.window_max[(id(spec), name)] = METRICS[spec.metric].compute(spec, record, name)
        for name in self.handed:  # (the kernel's state: the same steps)
            moment = self.moments[name] = _Moments()
            moment.state = (samples, *kernel.moments(index[name], P))
        for p, key in enumerate(kernel.pair_keys):
            weighted = self.weighted[key] = _Weighted(key[1])
            weighted.fs = kernel.fs
            weighted.sums = (samples, *kernel.weighted(p, P))

    def add(self, window) -> None:
        """One window's Result."""
        signals = window.signals
        self.times.append(window.time)
        for name, moment in self.moments.items():
            moment.add(signals[name])
        for (name, _), accumulator in self.weighted.items():
            accumulator.add(signals[name], window.time)
        for spec, name in self.maxima:
            value, key = window.metric(spec, name), (id(spec), name)
            self.window_max[key] = np.maximum(self.window_max.get(key, value), value)
        for name, pieces in self.pieces.items():
            pieces.append(np.array(signals[name]))

    def values(self, cfg: Config, model) -> dict[tuple[int, str], np.ndarray]:
        """Every requested metric's (P,) values, by ``(id(spec), signal name)``."""
        whole = _Kept(
            {name: np.concatenate(p, axis=-1) for name, p in self.pieces.items()},
            np.concatenate(self.times),
            cfg,
            model,
        )
        values: dict[tuple[int, str], np.ndarray] = {}
        for spec, names in self.requests:
            stream = METRICS[spec.metric].stream
            for name in names:
                key = (id(spec), name)
                if stream in ("moments", "extremes"):
                    values[key] = self.moments[name].value(spec.metric)
                elif stream == "weighted":
                    values[key] = self.weighted[(name, spec.weighting)].value(spec)
                elif stream == "window_max":
                    values[key] = self.window_max[key]
                else:
                    values[key] = METRICS[spec.metric].compute(spec, whole, name)
        return values


def reduce(
    cfg: Config,
    params: Mapping[str, Any] | None,
    requests: Sequence[tuple[Any, Sequence[str]]],
    roads: Sequence[Any] | None = None,
) -> Reduced:
    """The metric specs of ``requests`` (``(spec, its signal names)``, names as
    :func:`suspopt.specs.spec_signals` gives them) for the designs ``params`` (as
    :func:`suspopt.simulate`), without keeping the run's signals (module docstring), as a
    :class:`Reduced`. ``roads`` (road sections whose edges, if any, fall at the same
    instants) drive the designs in equal blocks of consecutive columns instead of the
    config's road (robust design, one batch for several roads on one time grid). A run with
    a controller is one window (its hold keeps records over the run)."""
    from . import integrator
    from .simulation import _result, _setup, check_memory, prepare, stepper, with_engine

    pv, model, controller, attachments = prepare(cfg, params)
    cfg = with_engine(cfg, pv.P, evaluation=True)
    streams = _Streams(requests)
    if controller is not None:
        width = None
        check_memory(cfg, model, attachments, pv.P, signals=len(requests))
    else:
        width = window_width(cfg, model, attachments, pv.P, len(requests))
        check_memory(cfg, model, attachments, pv.P, signals=len(requests), window=width,
                     kept=len(streams.pieces))  # fmt: skip
    run, z, zd, t_grid = _setup(cfg, pv, model, controller, attachments, roads)
    kernel = _kernel_streams(cfg, (pv, model, attachments, run, (z, zd, t_grid)), streams)
    if kernel is not None:
        streams.hand_over(kernel)
    recorded = _recorded(cfg, (pv, model, attachments, run, z), streams.numpy_reads())
    if kernel is not None and not streams.numpy_reads():
        kernel.alone, width = True, None  # (no record, nothing held per sample: one call)
    table = diverged = engine = None
    for first, traj in integrator.windows(run, stepper(cfg), width, recorded, kernel):
        window = _result(cfg, pv, model, controller, attachments, run, (z, zd, t_grid), traj, first)
        table, diverged, engine = window._table, traj.diverged_at, traj.engine
        streams.add(window)
        del window, traj  # (the next window is being integrated meanwhile: hold two at most)
    # (a run has at least one sample)
    assert table is not None and diverged is not None and engine is not None
    if kernel is not None:
        streams.take(kernel.zs.shape[0], cfg, model, pv.P)
    return Reduced(model, table, streams.values(cfg, model), diverged, engine)
