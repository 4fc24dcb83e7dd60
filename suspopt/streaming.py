"""Metrics of a run without its (P, T) signals: what optimisation needs.

An optimisation, ``kesort``'s re-simulation and the pseudo-fronts of ``analyse`` need only
the objectives' and constraints' values, not the signals. :func:`reduce` integrates the run
in windows of output samples (:func:`window_width`; :func:`suspopt.integrator.windows`, the same
steps as a whole run, bit for bit), computes each window's signals with the one signal table
(:class:`suspopt.result.Result` over the window) and lets each metric take what it needs
from them, as its :class:`suspopt.specs.MetricDef` says (``stream``):

- ``moments`` (variance, standard deviation, r.m.s., mean): each block of :data:`BLOCK`
  samples' count, mean and sum of squared deviations (two passes over the block), merged
  into the running ones in time order (the pairwise update of Chan, Golub and LeVeque); a
  design's values depend on :data:`BLOCK` (a constant), not on its batch or the window, and
  agree with the statistic of the whole signal to rounding (about 1e-15 relative,
  ``tests/test_streaming.py``);
- ``extremes`` (maximum, minimum, largest magnitude, range) and ``window_max`` (a maximum over
  time of a value per sample, such as the spring usage of Eq 5.3): the largest (smallest) of
  the windows' values, exactly the whole signal's;
- ``weighted`` (the ISO 2631 weighted r.m.s., VDV, MTVV and crest factor, Eq 2.78-2.83): the
  weighting's recursive filter (:func:`suspopt.metrics.iso2631.weighting_filter`) runs on
  from window to window with its state, which gives the whole signal's weighted samples bit
  for bit; the sums of ``a_w²`` and ``a_w⁴`` are the blocks of
  :func:`~suspopt.metrics.iso2631.block_sums` added in time order, as the whole-signal metrics
  add them (a window holds whole blocks: :data:`BLOCK` is a multiple of ``SUM_BLOCK``), and
  the largest ``|a_w|`` and the MTVV (the running r.m.s. from the running sum of ``a_w²`` and
  its last ``τ fs`` values) follow the whole signal's arithmetic: every weighted metric is the
  whole run's, bit for bit;
- ``keep`` (the transient metrics, the dissipated power, the dynamic tyre load, the switch
  count): the signals they read are kept whole and the metric is computed once at the end,
  exactly as on a whole run.

Memory therefore holds one window of every signal and state, the MTVV's last ``τ fs``
values, and the kept signals; with no ``keep`` metric it grows with the designs, not with the
run's length. A run with a semi-active controller is simulated whole (its hold keeps records
over the run): :func:`reduce` then returns the :class:`~suspopt.result.Result` of
:func:`suspopt.simulate`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from .config import Config
from .specs import METRICS

__all__ = ["reduce", "Reduced", "BLOCK", "window_width"]

#: Samples of one block of the moments' merge, and the least of one window (a multiple of
#: :data:`suspopt.integrator.WINDOW_MULTIPLE`).
BLOCK = 256
#: Memory of one window's states and signals [bytes]: a window is as many whole blocks as
#: fit (a few designs: the whole run at once), at least one.
WINDOW_BYTES = 64 << 20


class _Moments:
    """Count, mean and sum of squared deviations of each design's samples, (P,) each."""

    def __init__(self) -> None:
        self.n = 0
        self.mean: Any = 0.0
        self.m2: Any = 0.0

    def add(self, x: np.ndarray) -> None:
        """The samples ``x (P, T)`` that follow: each block of :data:`BLOCK` samples' own
        mean and squared deviations (two passes), merged into the running ones in time
        order (a window holds whole blocks, but for the run's last)."""
        x = np.ascontiguousarray(x)
        P, T = x.shape
        whole = T - T % BLOCK
        parts = []
        if whole:
            blocks = x[:, :whole].reshape(P, -1, BLOCK)
            means = np.mean(blocks, axis=-1)
            squares = np.sum(np.square(blocks - means[:, :, None]), axis=-1)
            parts = [(BLOCK, means[:, b], squares[:, b]) for b in range(means.shape[1])]
        if whole < T:
            rest = x[:, whole:]
            mean = np.mean(rest, axis=-1)
            parts.append((T - whole, mean, np.sum(np.square(rest - mean[:, None]), axis=-1)))
        for m, mean, m2 in parts:
            if self.n == 0:
                self.n, self.mean, self.m2 = m, mean, m2
                continue
            n = self.n + m
            delta = mean - self.mean
            self.mean = self.mean + delta * (m / n)
            self.m2 = self.m2 + m2 + np.square(delta) * (self.n * m / n)
            self.n = n

    def value(self, metric: str) -> np.ndarray:
        var = self.m2 / self.n
        if metric == "var":
            return var
        if metric == "std":
            return np.sqrt(var)
        if metric == "mean":
            return self.mean
        return np.sqrt(var + np.square(self.mean))  # rms


class _Extremes:
    """The largest and smallest sample of each design, (P,) each (NaN stays NaN)."""

    def __init__(self) -> None:
        self.high: Any = None
        self.low: Any = None

    def add(self, x: np.ndarray) -> None:
        high, low = np.max(x, axis=-1), np.min(x, axis=-1)
        first = self.high is None
        self.high = high if first else np.maximum(self.high, high)
        self.low = low if first else np.minimum(self.low, low)

    def value(self, metric: str) -> np.ndarray:
        if metric == "max":
            return self.high
        if metric == "min":
            return self.low
        if metric == "max_abs":
            return np.maximum(np.abs(self.high), np.abs(self.low))
        return self.high - self.low  # peak_to_peak


class _Weighted:
    """One signal under one ISO 2631 weighting as the windows arrive (module docstring):
    the filter's state, the count, the sums of ``a_w²`` and ``a_w⁴`` and the largest
    ``|a_w|`` (P,) each, and for each MTVV window ``τ`` [s] the running sum of ``a_w²``, its
    last ``τ fs`` values and the largest running r.m.s. so far."""

    def __init__(self, weighting: str | None) -> None:
        self.weighting = weighting
        self.taus: set[float] = set()
        self.fs = 0.0
        self.n = 0
        self.squares: Any = 0.0
        self.fourth: Any = 0.0
        self.peak: Any = None
        self.filter: Any = None
        self.state: Any = None
        self.running: dict[float, list[Any]] = {}

    def add(self, x: np.ndarray, time: np.ndarray) -> None:
        from .metrics.iso2631 import block_sums, weighting_filter

        if self.n == 0:
            self.fs = 1.0 / (time[1] - time[0])  # the output rate, as the whole run's metric
            self.filter = weighting_filter(self.weighting, self.fs)
        aw = np.asarray(x, dtype=float)  # read only: the filter's output is a new array
        if self.filter is not None:
            aw, self.state = self.filter.apply(aw, self.state)
        self.n += aw.shape[-1]
        with np.errstate(over="ignore", invalid="ignore"):  # a diverging design: inf, NaN
            squared = np.square(aw)
            # the blocks added in time order: the whole signal's sums, bit for bit
            for block in block_sums(squared).T:
                self.squares = self.squares + block
            for block in block_sums(np.square(squared)).T:
                self.fourth = self.fourth + block
            for tau in self.taus:
                self._running(tau, squared)
        peak = np.max(np.abs(aw), axis=-1)
        self.peak = peak if self.peak is None else np.maximum(self.peak, peak)

    def _running(self, tau: float, squared: np.ndarray) -> None:
        """Eq 2.80 over this window, from the running sum: the arithmetic of
        :func:`suspopt.metrics.iso2631.running_rms` on the whole signal."""
        width = max(1, round(tau * self.fs))
        P = squared.shape[0]
        total, history, largest = self.running.get(tau, (np.zeros(P), np.zeros((P, width)), None))
        summed = np.cumsum(np.concatenate([total[:, None], squared], axis=-1), axis=-1)[:, 1:]
        energy = summed / self.fs
        joined = np.concatenate([history, energy], axis=-1)
        lagged = joined[:, : energy.shape[-1]]
        rms = np.sqrt(np.maximum(energy - lagged, 0.0) / (width / self.fs))
        top = np.max(rms, axis=-1)
        largest = top if largest is None else np.maximum(largest, top)
        self.running[tau] = [summed[:, -1], joined[:, joined.shape[-1] - width :], largest]

    def value(self, spec) -> np.ndarray:
        rms = np.sqrt(self.squares / self.n)
        if spec.metric == "rms_weighted":
            return rms
        if spec.metric == "vdv":
            return (self.fourth / self.fs) ** 0.25
        if spec.metric == "mtvv":
            return self.running[spec.tau][2]
        with np.errstate(invalid="ignore", divide="ignore"):
            return self.peak / rms  # crest factor


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
    :func:`suspopt.simulate.run_memory`'s estimate, at least one block."""
    from .simulate import run_memory

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


def reduce(
    cfg: Config,
    params: Mapping[str, Any] | None,
    requests: Sequence[tuple[Any, Sequence[str]]],
    roads: Sequence[Any] | None = None,
):
    """The metric specs of ``requests`` (``(spec, its signal names)``, names as
    :func:`suspopt.specs.spec_signals` gives them) for the designs ``params`` (as
    :func:`suspopt.simulate`), without keeping the run's signals (module docstring): a
    :class:`Reduced`, or the whole :class:`~suspopt.result.Result` for a controlled run.
    ``roads`` (road sections whose edges, if any, fall at the same instants) drive the
    designs in equal blocks of
    consecutive columns instead of the config's road (robust design, one batch for
    several roads on one time grid)."""
    from . import integrator
    from .simulate import _result, _run, _setup, check_memory, prepare

    pv, model, controller, attachments = prepare(cfg, params)
    if controller is not None:  # the whole run (what simulate does, once prepared)
        check_memory(cfg, model, attachments, pv.P, signals=len(requests))
        return _run(cfg, pv, model, controller, attachments, roads)
    kept = sorted(
        {k for spec, names in requests if METRICS[spec.metric].stream == "keep"
         for n in names for k in _kept_names(spec, n)}
    )  # fmt: skip
    width = window_width(cfg, model, attachments, pv.P, len(requests))
    check_memory(cfg, model, attachments, pv.P, signals=len(requests), window=width, kept=len(kept))
    run, z, zd, t_grid = _setup(cfg, pv, model, controller, attachments, roads)

    def streamed(kind: str) -> list[str]:
        return sorted(
            {n for spec, names in requests if METRICS[spec.metric].stream == kind for n in names}
        )

    moments = {name: _Moments() for name in streamed("moments")}
    extremes = {name: _Extremes() for name in streamed("extremes")}
    weighted = _weighted(requests)
    maxima = [(spec, n) for spec, names in requests if METRICS[spec.metric].stream == "window_max"
              for n in names]  # fmt: skip
    window_max: dict[tuple[int, str], Any] = {}
    pieces: dict[str, list[np.ndarray]] = {name: [] for name in kept}
    times, table, traj = [], None, None
    for first, traj in integrator.windows(run, cfg.simulation.engine, width):
        window = _result(cfg, pv, model, controller, attachments, run, (z, zd, t_grid), traj, first)
        table, signals = window._table, window.signals
        times.append(window.time)
        for name, moment in moments.items():
            moment.add(signals[name])
        for name, extreme in extremes.items():
            extreme.add(signals[name])
        for (name, _), accumulator in weighted.items():
            accumulator.add(signals[name], window.time)
        for spec, name in maxima:
            value, key = window.metric(spec, name), (id(spec), name)
            window_max[key] = np.maximum(window_max.get(key, value), value)
        for name in kept:
            pieces[name].append(np.array(signals[name]))
    assert traj is not None and table is not None  # (a run has at least one sample)
    whole = _Kept(
        {name: np.concatenate(p, axis=-1) for name, p in pieces.items()},
        np.concatenate(times),
        cfg,
        model,
    )
    values: dict[tuple[int, str], np.ndarray] = {}
    for spec, names in requests:
        stream = METRICS[spec.metric].stream
        for name in names:
            key = (id(spec), name)
            if stream == "moments":
                values[key] = moments[name].value(spec.metric)
            elif stream == "extremes":
                values[key] = extremes[name].value(spec.metric)
            elif stream == "weighted":
                values[key] = weighted[(name, spec.weighting)].value(spec)
            elif stream == "window_max":
                values[key] = window_max[key]
            else:
                values[key] = METRICS[spec.metric].compute(spec, whole, name)
    return Reduced(model, table, values, traj.diverged_at, traj.engine)
