"""Metrics of a run that keeps no (P, T) signal (:mod:`suspopt.streaming`) against the same
metrics of the whole run (:func:`suspopt.simulate`), and the integrator's windows against the
whole integration.

- The windows of either engine joined are the whole run bit for bit (a bump's edges, a random
  road, a seat with its passenger).
- Every metric of :data:`suspopt.specs.METRICS` that a passive run has, reduced in windows,
  equals the whole run's: to 1e-13 relative for the moments (a merge of blocks, not one sum),
  exactly for the extremes, the windows' maxima, the ISO 2631 weighted metrics and the kept
  signals.
- The moments do not depend on the batch and match the whole signal's for any windows; a
  diverged design comes out NaN as in the whole run.
- Every signal of the table reads only the rows of the states and accelerations the probe
  (:func:`suspopt.streaming.recorded_rows`) finds for it: with the others NaN or garbage it is
  the same bits; a signal that is not a function of its instant's sample makes every row read.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from conftest import CONFIGS

from suspopt import integrator, streaming
from suspopt.config import load_config
from suspopt.config.metrics import MetricSpec
from suspopt.integrator import compiled_available
from suspopt.metrics.iso2631 import SUM_BLOCK
from suspopt.simulation import _result, _setup, prepare, simulate
from suspopt.specs import METRICS, spec_signals

ENGINES = ["numpy"] + (["compiled"] if compiled_available() else [])


def _designs(cfg, P: int) -> dict[str, np.ndarray]:
    share = np.linspace(0.1, 0.9, P)
    return {v.path: v.lower + share * (v.upper - v.lower) for v in cfg.design_variables}


def _short(name: str, duration: float):
    cfg = load_config(CONFIGS / name)
    cfg.simulation.duration = duration
    return cfg


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize(
    "name", ["ch5/case1_s1.yaml", "ch3/part1a_qc_class_b.yaml", "ch8/nss4_class_a_passenger.yaml"]
)
def test_windows_joined_are_the_whole_run(name, engine):
    cfg = _short(name, 1.3)
    cfg.simulation.engine = engine
    pv, model, controller, attachments = prepare(cfg, _designs(cfg, 5) or None)
    run = _setup(cfg, pv, model, controller, attachments)[0]
    whole = integrator.integrate(run, engine)
    for width in (32, 96):
        parts = list(integrator.windows(run, engine, width))
        assert [j0 for j0, _ in parts] == list(range(0, whole.states.shape[-1], width))
        for field in ("states", "accelerations"):
            joined = np.concatenate([getattr(t, field) for _, t in parts], axis=-1)
            assert np.array_equal(joined, getattr(whole, field), equal_nan=True)
        assert np.array_equal(parts[-1][1].diverged_at, whole.diverged_at, equal_nan=True)


def test_a_controlled_run_comes_whole():
    cfg = _short("ch3/part1b_qc_bump.yaml", 2.5)
    pv, model, controller, attachments = prepare(cfg)
    run = _setup(cfg, pv, model, controller, attachments)[0]
    assert controller is not None
    with pytest.raises(ValueError, match="whole"):
        next(integrator.windows(run, "numpy", 32))


def _every_metric(cfg):
    """A request for every metric of METRICS on a signal it applies to."""
    pv, model, controller, attachments = prepare(cfg)
    from suspopt.result import signal_names

    available = signal_names(model, {}, attachments)
    requests = []
    for metric, definition in METRICS.items():
        if definition.kind == "switches":
            continue  # (a passive run has no switching signal)
        fields: dict = {"metric": metric}
        if definition.kind != "derived":
            fields["signal"] = "body.heave_acc" if definition.kind == "iso2631" else "travel"
        if definition.kind == "iso2631":
            fields["weighting"] = "Wk"
        spec = MetricSpec(**fields)
        requests.append((spec, spec_signals(spec, available, model.corners)))
    return requests


def test_the_next_window_is_integrated_ahead_and_errors_come_in_place():
    """The compiled engine's windows come in order, the next one integrated in another
    thread while the caller holds this one; an integration error comes where its window
    would have, and closing early waits for the window under way."""
    import threading

    from suspopt.integrator import _ahead

    where, started = [], threading.Event()

    def windows():
        for i in range(3):
            where.append(threading.current_thread() is threading.main_thread())
            started.set()
            yield i
        raise MemoryError("the fourth window")

    it = _ahead(windows())
    assert next(it) == 0
    assert started.wait(5) and where[:1] == [True]
    assert next(it) == 1 and next(it) == 2
    assert where == [True, False, False]  # (the first one inline, the next ones ahead)
    with pytest.raises(MemoryError, match="fourth window"):
        next(it)
    it = _ahead(iter(range(5)))
    assert next(it) == 0
    it.close()  # (joins the thread that took 1)
    assert [*_ahead(iter(()))] == []


@pytest.mark.parametrize("engine", ENGINES)
def test_every_metric_reduced_in_windows_is_the_whole_runs(engine, monkeypatch):
    monkeypatch.setattr(streaming, "WINDOW_BYTES", 1)  # windows of one block each
    monkeypatch.setattr(integrator, "AHEAD_DESIGNS", 1)  # (each integrated ahead)
    cfg = _short("ch5/case1_s1.yaml", 2.0)
    cfg.simulation.engine = engine
    params = _designs(cfg, 6)
    requests = _every_metric(cfg)
    assert {METRICS[s.metric].stream for s, _ in requests} == {
        "moments", "extremes", "window_max", "weighted", "keep"
    }  # fmt: skip
    reduced = streaming.reduce(cfg, params, requests)
    whole = simulate(cfg, params)
    assert isinstance(reduced, streaming.Reduced)
    for spec, names in requests:
        stream = METRICS[spec.metric].stream
        for name in names:
            got, want = reduced.metric(spec, name), whole.metric(spec, name)
            # the signals the compiled kernel forms and reduces itself (to rounding:
            # suspopt/integrator/accumulators.py), an MTVV or a kept signal in numpy
            kernel = engine == "compiled" and stream != "keep" and spec.metric != "mtvv"
            if stream == "moments" or kernel:
                size = np.abs(whole.signals[name]).max() ** (2 if spec.metric == "var" else 1)
                np.testing.assert_allclose(got, want, rtol=1e-13, atol=1e-14 * size,
                                           err_msg=spec.metric)  # fmt: skip
            else:
                assert np.array_equal(got, want, equal_nan=True), spec.metric
    assert np.array_equal(reduced.diverged_at, whole.diverged_at, equal_nan=True)


@pytest.mark.slow
@pytest.mark.parametrize("engine", ENGINES)
def test_every_metric_of_a_controlled_run_reduced_is_the_whole_runs(engine):
    """A run with a controller is one window: its metrics (the switch count of the damper
    state among them) equal the whole run's, the rows it records chosen by the probe."""
    cfg = _short("ch7/sh_add_2.yaml", 1.5)
    cfg.simulation.engine = engine
    params = _designs(cfg, 4)
    requests = _every_metric(cfg)
    spec = MetricSpec(metric="switches", signal="damper_state")
    requests.append((spec, ["damper_state.F1", "damper_state.R1"]))
    reduced = streaming.reduce(cfg, params, requests)
    whole = simulate(cfg, params)
    assert reduced.engine == whole.engine
    for spec, names in requests:
        for name in names:
            got, want = reduced.metric(spec, name), whole.metric(spec, name)
            if METRICS[spec.metric].stream == "moments":  # (a mean near 0: to its signal's size)
                size = np.abs(whole.signals[name]).max() ** (2 if spec.metric == "var" else 1)
                np.testing.assert_allclose(got, want, rtol=1e-13, atol=1e-13 * size)
            else:
                assert np.array_equal(got, want, equal_nan=True), spec.metric


def test_windows_hold_whole_blocks_of_the_weighted_sums():
    assert streaming.BLOCK % SUM_BLOCK == 0


def test_moments_do_not_depend_on_the_batch_and_match_the_whole_signal():
    rng = np.random.default_rng(3)
    x = rng.normal(2.0, 0.5, (4, 1000))

    def fed(widths, rows=slice(None)):
        moments = streaming._Moments()
        start = 0
        for width in widths:
            moments.add(x[rows, start : start + width])
            start += width
        assert start >= x.shape[1]
        return {m: moments.value(m) for m in ("var", "std", "rms", "mean")}

    windows = [256] * 4
    batch, single = fed(windows), fed(windows, slice(2, 3))
    assert all(np.array_equal(batch[m][2:3], single[m]) for m in batch)
    for widths in (windows, [32] * 32, [64, 512, 448], [1000]):
        moments = fed(widths)
        np.testing.assert_allclose(moments["var"], np.var(x, axis=-1), rtol=1e-14)
        np.testing.assert_allclose(moments["std"], np.std(x, axis=-1), rtol=1e-14)
        np.testing.assert_allclose(moments["mean"], np.mean(x, axis=-1), rtol=1e-14)
        np.testing.assert_allclose(moments["rms"], np.sqrt(np.mean(x**2, axis=-1)), rtol=1e-14)


def test_a_diverged_design_is_nan_as_in_the_whole_run():
    cfg = _short("ch5/case1_s1.yaml", 1.8)
    cfg.simulation.dt = 9.0e-3  # RK4 unstable for the stiffest tyre: the design diverges
    cfg.road.length = 2.0  # (the bump spans enough steps)
    cfg.simulation.output_dt = None
    params = {"vehicle.corners.F1.tyre.stiffness": np.array([4.0e5, 4.0e7])}
    requests = [(s, n) for s, n in _every_metric(cfg) if s.metric in ("var", "max", "rms_weighted")]
    reduced = streaming.reduce(cfg, params, requests)
    whole = simulate(cfg, params)
    assert whole.diverged.tolist() == [False, True]
    assert np.array_equal(reduced.diverged_at, whole.diverged_at, equal_nan=True)
    for spec, names in requests:
        for name in names:
            got = reduced.metric(spec, name)
            assert np.isfinite(got[0]) and np.isnan(got[1]), spec.metric


@pytest.mark.skipif(not compiled_available(), reason="needs numba")
def test_a_designs_objectives_are_the_same_bits_alone_and_in_a_batch():
    """The window's width follows the batch (a few designs: the whole run at once), the
    moments' blocks do not: on the compiled engine a design's F and G do not depend on the
    batch it is evaluated in."""
    import suspopt

    cfg = _short("ch5/case1_s1.yaml", 3.0)
    cfg.simulation.engine = "compiled"
    problem = suspopt.Problem.from_config(cfg)
    X = np.random.default_rng(3).uniform(problem.xl, problem.xu, (300, problem.n_var))
    assert (
        streaming.window_width(cfg, *prepare(cfg)[1::2], 300, 6)
        < 1501
        < (streaming.window_width(cfg, *prepare(cfg)[1::2], 1, 6))
    )  # (the windows differ)
    batch = problem.evaluate(X, return_values_of=["F", "G"])
    alone = problem.evaluate(X[7:8], return_values_of=["F", "G"])
    for whole, one in zip(batch, alone):
        assert np.array_equal(whole[7:8], one)


@pytest.mark.skipif(not compiled_available(), reason="needs numba")
def test_blas_has_one_thread_while_the_compiled_windows_run_and_its_own_after():
    threadpoolctl = pytest.importorskip("threadpoolctl")

    def blas_threads():
        info = threadpoolctl.threadpool_info()
        return {i["filepath"]: i["num_threads"] for i in info if i["user_api"] == "blas"}

    cfg = _short("ch5/case1_s1.yaml", 1.0)
    pv, model, controller, attachments = prepare(cfg, _designs(cfg, 3))
    run = _setup(cfg, pv, model, controller, attachments)[0]
    with threadpoolctl.threadpool_limits(2, user_api="blas"):  # as a 2-core machine starts
        before = blas_threads()
        during = [blas_threads() for _ in integrator.windows(run, "compiled", 32)]
        after = blas_threads()
        first = integrator.windows(run, "compiled", 32)
        next(first)
        first.close()  # a caller that stops early gives the threads back too
        closed = blas_threads()
    # (the first compiled call in a process may load one more BLAS library: scipy's)
    assert len(during) > 1 and all(set(d.values()) == {1} for d in during)
    assert all(after[k] == n and closed[k] == n for k, n in before.items())


@pytest.mark.skipif(not compiled_available(), reason="needs numba")
def test_without_threadpoolctl_the_compiled_windows_are_the_same(monkeypatch):
    cfg = _short("ch5/case1_s1.yaml", 1.0)
    pv, model, controller, attachments = prepare(cfg, _designs(cfg, 3))
    run = _setup(cfg, pv, model, controller, attachments)[0]
    held = [t.states for _, t in integrator.windows(run, "compiled", 256)]
    monkeypatch.setattr(integrator, "_blas_pools", lambda: None)  # (what a missing import gives)
    free = [t.states for _, t in integrator.windows(run, "compiled", 256)]
    assert len(held) == len(free) > 1
    assert all(np.array_equal(a, b, equal_nan=True) for a, b in zip(held, free))


def _lift_off(cfg):
    cfg.vehicle.tyre_lift_off = True
    return cfg


def _two_way(cfg):
    cfg.seat.coupling = "two_way"
    return cfg


@pytest.mark.slow
@pytest.mark.parametrize(
    "name, change",
    [
        ("ch3/part2a_fc_arb_bump.yaml", None),  # full car, anti-roll bars
        ("ch3/part1a_qc_bump.yaml", _lift_off),  # a tyre that may lift off
        ("ch6/part_b.yaml", None),  # half car, PS seat and passenger, one way
        ("ch6/part_b.yaml", _two_way),
        ("ch8/nss4_class_a_passenger.yaml", None),  # Taylor mechanism, passenger
        ("ch8/nss1_class_a.yaml", None),  # the exact NSS1 mechanism
    ],
)
def test_every_signal_reads_only_the_rows_recorded_for_it(name, change):
    """Each signal of the table, computed from a run whose rows the probe did not find for it
    hold NaN or garbage instead, is the same bits as from the whole run."""
    cfg = load_config(CONFIGS / name)
    cfg.simulation.duration = getattr(cfg.road, "start", 0.0) + 0.8
    cfg = change(cfg) if change else cfg
    cfg.simulation.engine = "auto"
    pv, model, controller, attachments = prepare(cfg, _designs(cfg, 3) or None)
    run, z, zd, t_grid = _setup(cfg, pv, model, controller, attachments)
    traj = integrator.integrate(run, "numpy")
    whole = _result(cfg, pv, model, None, attachments, run, (z, zd, t_grid), traj)
    n, garbage = run.asm.n, np.random.default_rng(7)
    rows_seen = set()
    for signal in whole._table:
        rows = streaming._recorded(cfg, (pv, model, attachments, run, z), [signal])
        assert rows is not None and rows.shape == (3 * n,)
        rows_seen.add(int(rows.sum()))
        for filler in (np.nan, 1e3):
            states, acc = traj.states.copy(), traj.accelerations.copy()
            states[~rows[: 2 * n]] = filler * garbage.standard_normal(states[~rows[: 2 * n]].shape)
            acc[~rows[2 * n :]] = filler * garbage.standard_normal(acc[~rows[2 * n :]].shape)
            part = replace(traj, states=states, accelerations=acc)
            window = _result(cfg, pv, model, None, attachments, run, (z, zd, t_grid), part)
            same = np.array_equal(window.signals[signal], whole.signals[signal], equal_nan=True)
            assert same, signal
    assert max(rows_seen) < 3 * n  # (every signal leaves some row out)


class _Probe:
    """A stand-in Result whose one signal is ``compute(states, accelerations)``."""

    def __init__(self, compute, states, accelerations):
        self.signals = {"s": compute(states, accelerations)}


@pytest.mark.parametrize(
    "compute, read",
    [
        (lambda q, a: q[1] + 0.0 * q[0], [0, 1]),  # a zero coefficient still reads its row
        (lambda q, a: np.where(q[2] > 0.1, 1.0, 0.0), [2]),  # a threshold
        (lambda q, a: a[0] * 2.0, [4]),  # the first acceleration (n = 2: rows 4, 5)
        (lambda q, a: np.cumsum(q[3], axis=-1), [0, 1, 2, 3, 4, 5]),  # not pointwise: all
        (lambda q, a: q[0] / 0.0, [0, 1, 2, 3, 4, 5]),  # not finite on the probe: all
    ],
)
def test_the_probe_finds_the_rows_a_signal_reads(compute, read):
    with np.errstate(all="ignore"):
        rows = streaming.recorded_rows(lambda q, a: _Probe(compute, q, a), 2, 3, ["s"])
    assert list(np.flatnonzero(rows)) == read


def _reaches(monkeypatch) -> list:
    """What :func:`suspopt.integrator.compiled.reached` returns in each run, recorded."""
    from suspopt.integrator import compiled

    found, reached = [], compiled.reached
    monkeypatch.setattr(compiled, "reached", lambda *a: found.append(reached(*a)) or found[-1])
    return found


@pytest.mark.slow
@pytest.mark.skipif(not compiled_available(), reason="the compiled engine needs numba")
@pytest.mark.parametrize("road", ["bump_half_sine", "bump_step"])
def test_an_evaluation_integrates_only_the_part_its_signals_depend_on(road, monkeypatch):
    """Part B of Ch. 6 (a one-way seat and passenger) on the compiled engine: objectives and
    constraints of the vehicle alone reach its 4 DOFs and 4 elements (a rectangular bump with
    tyres that may lift off: the edges' impulses and the rows that cannot pull, taken apart
    too), with the values of the whole network's run bit for bit; a seat signal, or the seat
    mounted two ways, reaches every DOF."""
    from suspopt import Problem
    from suspopt.config.road import BumpStep
    from suspopt.integrator import compiled

    cfg = _short("ch6/part_b.yaml", 1.2)
    cfg.simulation.engine = "compiled"
    if road == "bump_step":
        cfg.road = BumpStep(kind="bump_step", height=0.08, length=0.5, start=0.3, speed=11.111)
        cfg.vehicle.tyre_lift_off = True
    X = np.random.default_rng(3).random((7, len(cfg.design_variables)))

    def evaluated(cfg):
        problem = Problem.from_config(cfg)
        return problem.evaluate(problem.xl + X * (problem.xu - problem.xl),
                                return_values_of=["F", "G"])  # fmt: skip

    found = _reaches(monkeypatch)
    reached = evaluated(cfg)
    dofs, elements = found[-1]
    model_dofs = prepare(cfg, None)[1].n_dof
    assert list(dofs) == list(range(model_dofs)) and elements.size == 4
    monkeypatch.setattr(compiled, "reached", lambda *a: None)
    whole = evaluated(cfg)
    assert all(np.array_equal(a, b, equal_nan=True) for a, b in zip(reached, whole))
    assert np.isfinite(whole[0]).all()  # (a real run, not NaN against NaN)

    found = _reaches(monkeypatch)
    seated = cfg.model_copy(deep=True)
    seated.objectives.main.append(seated.objectives.supplementary[0])  # VDV of the head
    evaluated(seated)
    evaluated(_two_way(cfg.model_copy(deep=True)))
    assert found == [None, None]
