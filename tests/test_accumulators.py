"""The signals the compiled kernel forms and reduces itself in a streamed evaluation
(suspopt/affine.py finds them, suspopt/integrator/accumulators.py and _accumulate.py reduce
them): the probe, the generated reductions against the general loops, and the values
against the whole run's metrics."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import CONFIGS

from suspopt import streaming
from suspopt.affine import affine_signals
from suspopt.config import load_config
from suspopt.config.metrics import MetricSpec
from suspopt.simulation import prepare, simulate
from suspopt.specs import spec_signals

pytest.importorskip("numba")


def test_the_probe_finds_affine_signals_and_their_coefficients():
    """Affine signals come with their constant and per-design coefficients, exactly; a cubic,
    a clipped value, a product, a signal of the previous sample, of the time or not finite
    are left to numpy."""
    n, n_u, P = 2, 1, 3
    k = np.array([1.0, 2.0, 3.0])[:, None]  # (a coefficient per design)

    def result_of(states, accelerations, z, zd):
        q, v, a = states[:n], states[n:], accelerations
        with np.errstate(divide="ignore", invalid="ignore"):
            return {
                "affine": 7.0 + k * q[1] - 0.25 * a[0] + 1.5 * z[0] + zd[0],
                "copy": a[1] + 0.0,
                "cubic": q[0] + 1e-3 * q[0] ** 3,
                "clipped": np.minimum(q[0], 5.0),
                "product": q[0] * v[0],
                "previous": np.roll(q[0], 1, axis=-1),
                "timed": q[0] + 1e-3 * np.arange(q.shape[-1]),
                "not finite": q[0] / q[1],
            }

    names = ["affine", "copy", "cubic", "clipped", "product", "previous", "timed", "not finite"]
    found = affine_signals(result_of, n, n_u, P, names)
    assert sorted(found) == ["affine", "copy"]
    affine = found["affine"]
    assert affine.sources == [1, 2 * n, -1, -2]  # q_1, the first acceleration, z, zd
    expected = [k[:, 0], np.full(P, -0.25), np.full(P, 1.5), np.ones(P)]
    assert all(np.array_equal(c, e) for c, e in zip(affine.coefficients, expected))
    assert np.array_equal(affine.constant, np.full(P, 7.0))
    assert found["copy"].sources == [2 * n + 1] and np.array_equal(
        found["copy"].constant, 0 * k[:, 0]
    )


def _requests(cfg):
    """Every streamed kind on the Ch. 5 signals: moments, extremes, a weighted pair (and an
    MTVV, left to numpy), the spring usage (from the travel's extremes), a spring force."""
    pv, model, controller, attachments = prepare(cfg)
    from suspopt.result import signal_names

    available = signal_names(model, {}, attachments)
    specs = [
        MetricSpec(metric="var", signal="body.heave_acc"),
        MetricSpec(metric="rms", signal="travel"),
        MetricSpec(metric="max_abs", signal="tyre_deflection"),
        MetricSpec(metric="peak_to_peak", signal="body.pitch"),
        MetricSpec(metric="rms_weighted", signal="body.heave_acc", weighting="Wk"),
        MetricSpec(metric="vdv", signal="body.heave_acc", weighting="Wk"),
        MetricSpec(metric="crest_factor", signal="body.pitch_acc", weighting="We"),
        MetricSpec(metric="mtvv", signal="body.heave_acc", weighting="Wk"),
        MetricSpec(metric="spring_usage"),
        MetricSpec(metric="max", signal="spring_force"),
    ]
    return [(s, spec_signals(s, available, model.corners)) for s in specs]


def _case(duration: float, P: int, diverging: bool = False):
    cfg = load_config(CONFIGS / "ch5" / "case4_s1.yaml")
    cfg.simulation.duration, cfg.simulation.engine = duration, "compiled"
    share = np.linspace(0.05, 0.95, P)
    params = {v.path: v.lower + share * (v.upper - v.lower) for v in cfg.design_variables}
    if diverging:  # (RK4 unstable for a tyre this stiff at this step: every third design)
        cfg.simulation.dt, cfg.simulation.output_dt = 9.0e-3, None
        cfg.simulation.duration, cfg.road.length = 1.8, 2.0
        params["vehicle.corners.F1.tyre.stiffness"] = np.where(np.arange(P) % 3, 4.0e5, 4.0e7)
    return cfg, params


@pytest.mark.slow
@pytest.mark.filterwarnings("error::RuntimeWarning")
@pytest.mark.parametrize("diverging", [False, True])
def test_the_generated_reductions_give_the_bits_of_the_general_loops(monkeypatch, diverging):
    """70 designs take the fused step and the reductions generated for their accumulators;
    the same designs with every run walking the network take the general loops: the same
    bits, diverged designs' NaN included, and no warning (a diverging design's forces
    overflow: ``Result.diverged`` says so, not a RuntimeWarning)."""
    from suspopt.integrator import _fused, compiled

    cfg, params = _case(1.2, 70, diverging)
    requests = _requests(cfg)
    used = []
    windows = compiled.windows

    def spy(run, width=None, recorded=None, accumulators=None):
        used.append((compiled._fusable(run.offsets, run.controller, run.asm.P), accumulators))
        return windows(run, width, recorded, accumulators)

    monkeypatch.setattr(compiled, "windows", spy)
    fused = streaming.reduce(cfg, params, requests)
    monkeypatch.setattr(_fused, "MIN_DESIGNS", 10**9)
    walked = streaming.reduce(cfg, params, requests)
    assert [u[0] for u in used] == [True, False] and used[0][1] is not None
    assert np.array_equal(fused.diverged_at, walked.diverged_at, equal_nan=True)
    assert fused.diverged.any() == diverging
    for spec, names in requests:
        for name in names:
            a, b = fused.metric(spec, name), walked.metric(spec, name)
            assert np.array_equal(a, b, equal_nan=True), (spec.metric, name)


@pytest.mark.slow
def test_kernel_reduced_metrics_are_the_whole_runs_to_rounding(monkeypatch):
    """Every requested metric of a streamed evaluation against the whole run's: the kernel's
    to rounding; the spring force (not affine) and the MTVV in numpy, bit for bit. Only the
    rows numpy still reads are recorded."""
    from suspopt import integrator

    cfg, params = _case(2.0, 70)
    requests = _requests(cfg)
    seen = {}
    windows = integrator.windows

    def spy(run, engine="numpy", width=None, recorded=None, accumulators=None):
        seen.setdefault("recorded", recorded)  # (the evaluation's, not the whole run's)
        seen.setdefault("accumulators", accumulators)
        return windows(run, engine, width, recorded, accumulators)

    monkeypatch.setattr(integrator, "windows", spy)
    reduced = streaming.reduce(cfg, params, requests)
    whole = simulate(cfg, params)
    formed = sorted(s.name for s in seen["accumulators"].signals)
    assert "spring_force.F1" not in formed and "travel.F1" in formed and "body.pitch" in formed
    n = whole.n
    recorded = seen["recorded"]
    assert recorded[:n].any()  # (the spring force's displacements)
    assert recorded[2 * n :].tolist() == [True, False, False, False]  # (the MTVV's heave)
    for spec, names in requests:
        for name in names:
            got, want = reduced.metric(spec, name), whole.metric(spec, name)
            if spec.metric in ("mtvv",) or name.startswith("spring_force"):
                assert np.array_equal(got, want), (spec.metric, name)
            else:
                np.testing.assert_allclose(got, want, rtol=1e-13, err_msg=f"{spec.metric} {name}")


@pytest.mark.slow
def test_roads_per_lane_reduce_as_each_road_alone():
    """Two roads (heights) under consecutive halves of a batch: each lane reads its own
    road's inputs (the tyre deflection), as a whole run on that road alone."""
    cfg, params = _case(1.5, 8)
    requests = [(s, n) for s, n in _requests(cfg) if s.metric in ("rms", "max_abs", "var")]
    low = cfg.road.model_copy(update={"height": 0.03})
    reduced = streaming.reduce(cfg, params, requests, roads=[cfg.road, low])
    for half, road in enumerate([cfg.road, low]):
        alone = cfg.model_copy(update={"road": road})
        part = {k: v[4 * half : 4 * half + 4] for k, v in params.items()}
        whole = simulate(alone, part)
        for spec, names in requests:
            for name in names:
                got = reduced.metric(spec, name)[4 * half : 4 * half + 4]
                np.testing.assert_allclose(got, whole.metric(spec, name), rtol=1e-13)
