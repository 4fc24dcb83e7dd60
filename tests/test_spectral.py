"""``simulation.method: spectral`` (:mod:`suspopt.spectral`): stationary statistics of linear
designs on ISO 8608 roads by the frequency integral.

- For 20 random linear QC, HC2 and FC designs (class B, both amplitude conventions; the FC
  on identical and on independent tracks, with its wheelbase delay), every variance and weighted r.m.s. equals
  the steady-state sum over the time-domain road's own harmonics (each harmonic through the
  frequency response, :func:`suspopt.road.iso8608_harmonics`) to 1e-3.
- The body acceleration's response is the linear model's own (an independent path through
  :meth:`suspopt.network.LinearModel.frequency_response`).
- Time domain: for the QC, HC2 and FC the variances and the mean damper power averaged over
  several road seeds (transient cut off) lie within the statistical error those seeds give of
  the spectral ones.
- A Duffing spring, a bump road or a metric without a stationary closed form is exit 2 naming
  the key.
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import CONFIGS

from suspopt import memory, simulate, spectral
from suspopt.cli import app
from suspopt.config import load_config
from suspopt.config.metrics import MetricSpec
from suspopt.integrator import compiled_available
from suspopt.metrics.iso2631 import weighting_response
from suspopt.road import iso8608_harmonics
from suspopt.simulation import prepare

CASES = {
    "qc": ("ch3/part1a_qc_class_b.yaml", "identical", ["body.heave_acc", "travel.F1", "tyre_force.F1"]),
    "hc2": ("ch3/part1a_hc2_class_b.yaml", "identical", ["body.pitch_acc", "travel.R1"]),
    "fc": ("ch3/part1a_fc_class_b.yaml", "identical", ["body.heave_acc", "travel.R2"]),
    "fc_independent": ("ch3/part1a_fc_class_b.yaml", "independent", ["body.roll_acc", "travel.F2"]),
    "qc_iso8608": ("ch3/part1a_qc_class_b.yaml", "identical", ["body.heave_acc", "travel.F1"]),
}  # fmt: skip


def _random_designs(cfg, P: int, seed: int = 7) -> dict[str, np.ndarray]:
    """P designs: each corner's spring and damper drawn within -50 %..+100 % of the config's."""
    rng = np.random.default_rng(seed)
    _, model, _, _ = prepare(cfg)
    params = {}
    for c, corner in enumerate(model.corners):
        k = float(model.network.group("suspension").stiffness[c, 0, 0])
        damping = float(model.network.group("suspension").damping[c, 0, 0])
        params[f"vehicle.corners.{corner}.spring.linear"] = k * rng.uniform(0.5, 2.0, P)
        params[f"vehicle.corners.{corner}.damper.c"] = damping * rng.uniform(0.5, 2.0, P)
    return params


def _requests(names, corner: str = "F1"):
    requests = [(MetricSpec(metric="var", signal=n), [n]) for n in names]
    acc = [n for n in names if n.endswith("_acc")]
    requests += [(MetricSpec(metric="rms_weighted", signal=acc[0], weighting="Wk"), acc[:1])]
    requests += [(MetricSpec(metric="dissipated_power"), [f"travel_vel.{corner}"])]
    requests += [(MetricSpec(metric="dynamic_tyre_load"), [f"tyre_force.{corner}"])]
    return requests


def _expected(spec, signal, responses, weight, amplitude, model):
    """The steady-state value of ``spec`` from the responses at the road's harmonics."""
    second = (
        f"damper_force.{signal.rsplit('.', 1)[1]}" if spec.metric == "dissipated_power" else signal
    )
    cross = sum((a * np.conj(b)).real for a, b in zip(responses[signal], responses[second]))
    value = np.sum(cross * weight * amplitude**2 / 2, axis=-1)
    if spec.metric == "dynamic_tyre_load":
        corner = model.corners.index(signal.rsplit(".", 1)[1])
        return np.sqrt(value) / model.static_tyre_load[:, 0, corner]
    return value if spec.metric in ("var", "dissipated_power") else np.sqrt(value)


def _case(name: str, duration: float = 60.0):
    path, tracks, names = CASES[name]
    cfg = load_config(CONFIGS / path)
    cfg.road.tracks = tracks
    cfg.simulation.duration = duration
    if name.endswith("_iso8608"):
        cfg.road.convention = "iso8608"  # (the bundled configs use the thesis's)
    return cfg, names


@pytest.mark.parametrize("case", sorted(CASES))
def test_spectral_equals_the_sum_over_the_roads_own_harmonics(case):
    cfg, names = _case(case)
    params = _random_designs(cfg, 20)
    requests = _requests(names)
    reduced = spectral.reduce(cfg, params, requests)
    pv, model, _, attachments = prepare(cfg, params)
    span = cfg.road.speed * cfg.simulation.duration + float(np.max(model.offsets))
    harmonics = iso8608_harmonics(cfg.road, span)
    f = cfg.road.speed * harmonics.omega / (2 * np.pi)
    system = spectral._Linear(cfg, pv, model, attachments)
    extra = ["travel_vel.F1", "damper_force.F1", "tyre_force.F1"]
    responses = spectral._responses(system, f, sorted(set(names + extra)))
    for spec, (signal,) in requests:
        weight = 1.0
        if spec.weighting:
            weight = np.abs(weighting_response(f, spec.weighting)) ** 2
        expected = _expected(spec, signal, responses, weight, harmonics.amplitude, model)
        got = reduced.metric(spec, signal)
        np.testing.assert_allclose(got, expected, rtol=1e-3, err_msg=f"{spec.metric} {signal}")


def test_each_design_converges_on_its_own_and_an_undamped_one_fails_alone():
    """A design's values are those of the grid where it converged, whatever its batch
    mates need: bit for bit the values it has alone. A design whose damper is almost 0
    never converges (its resonance is narrower than the finest grid): it is NaN, a failed
    design, where before it was an error for the whole batch (found by
    ``benchmarks/fuzz_configs.py --optimise --seed 71``)."""
    cfg, names = _case("qc")
    params = _random_designs(cfg, 4)
    params["vehicle.corners.F1.damper.c"][2] = 1e-9
    requests = _requests(names)
    batch = spectral.reduce(cfg, params, requests)
    for p in range(4):
        alone = spectral.reduce(cfg, {k: v[p : p + 1] for k, v in params.items()}, requests)
        for spec, (signal,) in requests:
            got, own = batch.metric(spec, signal)[p], alone.metric(spec, signal)[0]
            if p == 2:
                assert np.isnan(got) and np.isnan(own), (spec.metric, signal)
            else:
                assert got == own and np.isfinite(got), (spec.metric, signal, p)


def test_a_batch_refines_only_its_designs_not_yet_converged(monkeypatch):
    """A finer grid is computed for the designs not yet converged alone: a batch costs the
    sum of its designs' costs alone (design-frequencies computed), not its slowest design's
    cost times the batch (one undamped design in 2000 made a batch 170 times dearer)."""
    cfg, names = _case("qc")
    params = _random_designs(cfg, 4)
    params["vehicle.corners.F1.damper.c"][2] = 1e-9
    requests = _requests(names)
    counted = spectral._integrands
    cost = []

    def counting(system, requests, f):
        cost.append(system.pv.P * len(f))
        return counted(system, requests, f)

    monkeypatch.setattr(spectral, "_integrands", counting)
    spectral.reduce(cfg, params, requests)
    batch = sum(cost)
    cost.clear()
    for p in range(4):
        spectral.reduce(cfg, {k: v[p : p + 1] for k, v in params.items()}, requests)
    assert batch == sum(cost)


def test_designs_slow_to_converge_are_refined_in_parts_that_fit_the_memory(monkeypatch):
    """Four designs that never converge need about 13 MB at the finest grid; under a 10 MB
    limit they were bad input for the whole batch (found by reading the refinement's
    memory estimate). They are refined one by one now, each within half the limit where
    it fits, and every value is the same bits as without a limit."""
    cfg, names = _case("qc")
    params = _random_designs(cfg, 6)
    params["vehicle.corners.F1.damper.c"][1:5] = 1e-9
    requests = _requests(names)
    whole = spectral.reduce(cfg, params, requests)
    counted = spectral._integrands
    sizes = []

    def counting(system, requests, f):
        sizes.append((len(f), system.pv.P))
        return counted(system, requests, f)

    monkeypatch.setattr(spectral, "_integrands", counting)
    monkeypatch.setattr(memory, "_limit", 10 << 20)
    parts = spectral.reduce(cfg, params, requests)
    for spec, (signal,) in requests:
        got = parts.metric(spec, signal)
        np.testing.assert_array_equal(got, whole.metric(spec, signal))
        assert np.isnan(got[1:5]).all() and np.isfinite(got[[0, 5]]).all()
    finest = (spectral.MAX_POINTS - 1) // 2
    assert {P for f, P in sizes if f == finest} == {1}


def test_the_body_acceleration_response_is_the_linear_models():
    cfg, _ = _case("fc")
    params = _random_designs(cfg, 5)
    pv, model, _, attachments = prepare(cfg, params)
    f = np.geomspace(0.3, 40.0, 50)
    system = spectral._Linear(cfg, pv, model, attachments)
    (response,) = spectral._responses(system, f, ["body.heave_acc"])["body.heave_acc"]
    delays = np.exp(-2j * np.pi * f[:, None] * model.offsets[None, :] / cfg.road.speed)
    q = model.network.linear_model().frequency_response(f, delays)  # (P, F, n)
    heave = model.body_dofs.index("heave")
    np.testing.assert_allclose(response, -((2 * np.pi * f) ** 2) * q[:, :, heave], rtol=1e-10)


@pytest.mark.slow
@pytest.mark.parametrize("case", ["qc", "hc2", "fc"])
def test_spectral_values_lie_within_the_time_domains_statistical_error(case):
    """Time-domain variances (and the mean damper power) over ``seeds`` roads of
    ``duration`` s, the first ``settle`` s cut off: their mean over the seeds must lie within
    4.5 standard errors (computed from the seeds' spread) of the spectral value, for each of
    20 designs and each signal."""
    seeds, duration, settle = 8, 40.0, 4.0
    cfg, names = _case(case, duration)
    cfg.simulation.dt, cfg.simulation.output_dt = 2e-3, 4e-3
    if compiled_available():
        cfg.simulation.engine = "compiled"
    params = _random_designs(cfg, 20)
    requests = [(MetricSpec(metric="var", signal=n), [n]) for n in names]
    requests += [(MetricSpec(metric="dissipated_power"), ["travel_vel.F1"])]
    reduced = spectral.reduce(cfg, params, requests)
    samples: dict[str, list] = {n: [] for _, (n,) in requests}
    for seed in range(seeds):
        cfg.road.seed = seed
        result = simulate(cfg, params)
        kept = result.time >= settle
        for spec, (n,) in requests:
            x = result.signals[n][:, kept]
            if spec.metric == "dissipated_power":
                samples[n].append(np.mean(x * result.signals["damper_force.F1"][:, kept], -1))
            else:
                samples[n].append(np.var(x, axis=-1))
    for spec, (n,) in requests:
        runs = np.array(samples[n])  # (seeds, P)
        error = runs.std(axis=0, ddof=1) / np.sqrt(seeds)
        z = (runs.mean(axis=0) - reduced.metric(spec, n)) / error
        assert np.all(np.abs(z) < 4.5), (n, z)


def _one_error(capsys, *args) -> tuple[int, str]:
    with pytest.raises(SystemExit) as exc:
        app(list(map(str, args)))
    return exc.value.code, capsys.readouterr().err.strip()


def _study(tmp_path, extra=(), drop=()):
    text = (CONFIGS / "ch5/case1_s1.yaml").read_text()
    start, end = text.index("road:"), text.index("simulation:")
    text = (
        text[:start]
        + "road: {kind: iso8608, road_class: B, convention: iso8608, speed: 20.0}\n"
        + text[end:]
    )
    old = "simulation: {duration: 3.0, dt: 2.0e-3, engine: auto}"
    assert old in text
    text = text.replace(old, "simulation: {duration: 3.0, dt: 2.0e-3, method: spectral}")
    for old, new in extra:
        assert old in text
        text = text.replace(old, new)
    lines = [line for line in text.splitlines() if not any(d in line for d in drop)]
    path = tmp_path / "study.yaml"
    path.write_text("\n".join(lines) + "\n")
    return path


def test_a_duffing_spring_is_exit_2_naming_the_key(tmp_path, capsys):
    path = _study(tmp_path, drop=("spring_usage", "K_nl"))
    code, err = _one_error(capsys, "optimise", path, "-o", tmp_path / "out.h5")
    line = next(i for i, t in enumerate(path.read_text().splitlines(), 1) if "cubic: 1.0e7" in t)
    assert code == 2
    assert err == (
        f"error: {path}:{line}: vehicle.corners.F1.spring.cubic: simulation.method spectral "
        "needs a linear model on a random road: the Duffing spring "
        "vehicle.corners.F1.spring.cubic > 0 is not linear"
    )
    assert not (tmp_path / "out.h5").exists()


def test_a_metric_without_a_closed_form_is_exit_2(tmp_path, capsys):
    path = _study(tmp_path)  # (its spring_usage constraint needs a time history)
    code, err = _one_error(capsys, "validate", path)
    assert code == 2
    assert "constraints[1].metric: spring_usage needs a time history" in err
    assert err.splitlines()[1:] == [f"1 error in {path}"]


def test_a_bump_road_is_exit_2(tmp_path, capsys):
    text = (
        (CONFIGS / "ch5/case1_s1.yaml")
        .read_text()
        .replace(
            "simulation: {duration: 3.0, dt: 2.0e-3, engine: auto}",
            "simulation: {duration: 3.0, dt: 2.0e-3, method: spectral}",
        )
    )
    assert "method: spectral" in text
    lines = [line for line in text.splitlines() if "spring_usage" not in line]
    path = tmp_path / "bump.yaml"
    path.write_text("\n".join(lines) + "\n")
    code, err = _one_error(capsys, "validate", path)
    assert code == 2
    assert "road.kind: simulation.method spectral needs a linear model on a random road" in err


def test_a_linear_study_optimises_with_the_spectral_method(tmp_path, capsys):
    path = _study(
        tmp_path,
        extra=[("cubic: 1.0e7", "cubic: 0.0"), ("generations: 600", "generations: 3"),
               ("population: 200", "population: 12")],
        drop=("spring_usage", "K_nl"),
    )  # fmt: skip
    with pytest.raises(SystemExit) as exc:
        app(["optimise", str(path), "-o", str(tmp_path / "out.h5")])
    assert exc.value.code in (0, None)
    import h5py

    with h5py.File(tmp_path / "out.h5") as h5:
        F = h5["pareto/F"][()]
    assert F.shape[1] == 1 and np.all(np.isfinite(F)) and np.all(F > 0)
