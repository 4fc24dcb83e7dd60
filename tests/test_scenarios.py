"""Robust design: the scenarios: section, its batches and its aggregates (issue 18)."""

from __future__ import annotations

import h5py
import numpy as np
import pytest
from conftest import CONFIGS, ROOT

import suspopt
from suspopt import streaming
from suspopt.config import ConfigError
from suspopt.config.loader import load_config_text
from suspopt.config.scenarios import Quantile
from suspopt.optimisation import Problem
from suspopt.optimisation.scenarios import aggregate
from suspopt.seat import passenger_mass_change

TEMPLATE = (ROOT / "suspopt" / "templates" / "optimise.yaml").read_text()
BASE = TEMPLATE.replace("duration: 3.0 ", "duration: 1.5 ")
assert BASE != TEMPLATE


def _problem(extra: str = "", base: str = BASE) -> Problem:
    return Problem.from_config(load_config_text(base + extra))


def _designs(problem: Problem, n: int = 6) -> np.ndarray:
    return np.random.default_rng(3).uniform(problem.xl, problem.xu, (n, problem.n_var))


def _counted_calls(monkeypatch, columns: bool = True) -> list:
    """Every simulation an evaluation makes: its roads (1 for the config's own) and, with
    ``columns``, its columns."""
    calls = []
    reduce = streaming.reduce

    def counted(cfg, params, requests, **roads):
        count = len(roads.get("roads") or [None])
        calls.append((count, len(next(iter(params.values())))) if columns else count)
        return reduce(cfg, params, requests, **roads)

    monkeypatch.setattr(streaming, "reduce", counted)
    return calls


def _evaluate(problem: Problem, X):
    return problem.evaluate(X, return_values_of=["F", "G"])


def test_one_scenario_is_the_plain_config_bit_for_bit():
    plain = _problem()
    X = _designs(plain)
    F0, G0 = _evaluate(plain, X)
    for extra in (
        "scenarios: {nominal: true}\n",
        "scenarios:\n  nominal: false\n  cases: [{name: only}]\n",
    ):
        F, G = _evaluate(_problem(extra), X)
        assert np.array_equal(F, F0) and np.array_equal(G, G0)


def test_max_over_two_identical_scenarios_equals_either():
    heavy = BASE.replace("mass: 2210 ", "mass: 2500 ")
    assert heavy != BASE
    X = _designs(_problem())
    F1, G1 = _evaluate(_problem(base=heavy), X)
    twice = """scenarios:
  nominal: false
  cases:
    - {name: one, set: {vehicle.body.mass: 2500}}
    - {name: two, set: {vehicle.body.mass: 2500}}
"""
    text = BASE.replace("signal: body.heave_acc}", "signal: body.heave_acc, over_scenarios: max}")
    F, G = _evaluate(_problem(twice, base=text), X)
    assert np.array_equal(F, F1) and np.array_equal(G, G1)


def test_a_constraint_violated_in_one_scenario_makes_the_design_infeasible():
    ratio = "  - {name: ratio, metric: spring_usage, min: 0.1, max: 0.3}\n"
    assert ratio in BASE
    base = BASE.replace(ratio, "")
    X = _designs(_problem(base=base), 40)
    _, G = _evaluate(_problem(base=base), X)
    limit = float(np.median(G[:, 0] + 0.8)) * 1.2  # RC_s: about half the designs hold it
    base = base.replace("max: 0.8}", f"max: {limit!r}}}")
    _, G0 = _evaluate(_problem(base=base), X)
    problem = _problem("scenarios:\n  cases: [{name: high, set: {road.height: 0.08}}]\n", base)
    _, G = _evaluate(problem, X)
    FS, GS = problem.scenario_values(problem.to_physical(X))
    only_nominal = (G0 <= 0).all(axis=1) & ~(GS[:, 1] <= 0).all(axis=1)
    assert only_nominal.any(), "the test needs a design feasible on the nominal bump only"
    assert not (G[only_nominal] <= 0).all(axis=1).any()
    # the margins combine by max: every scenario must hold
    assert np.array_equal(G[:, :-1], np.maximum(GS[:, 0, :-1], GS[:, 1, :-1]))
    assert np.array_equal(GS[:, 0], G0)


def test_designs_times_scenarios_run_in_one_call(monkeypatch):
    calls = _counted_calls(monkeypatch)
    masses = """scenarios:
  cases:
    - {name: heavy, set: {vehicle.body.mass: 2500}}
    - {name: light, set: {vehicle.body.mass: 1900, vehicle.corners.R1.unsprung_mass: 80}}
    - {name: stiff_tyres, set: {vehicle.corners.F1.tyre.stiffness: 5.0e5}}
"""
    problem = _problem(masses)
    X = _designs(problem, 7)
    _evaluate(problem, X)
    assert calls == [(1, 7 * 4)]
    calls.clear()
    roads = masses + "    - {name: high, set: {road.height: 0.07}}\n"
    _evaluate(_problem(roads), X)
    assert calls == [(5, 7 * 5)]  # the higher bump's columns in the same batch
    calls.clear()
    longer = roads + "    - {name: long, set: {simulation.duration: 2.0}}\n"
    _evaluate(_problem(longer), X)
    assert calls == [(5, 7 * 5), (1, 7)]  # another time grid: a batch of its own


def test_each_scenario_column_is_that_config_simulated_alone():
    problem = _problem(
        "scenarios:\n  cases:\n    - {name: heavy, set: {vehicle.body.mass: 2500}}\n"
        "    - {name: high, set: {road.height: 0.07}}\n"
    )
    X = _designs(problem, 4)
    FS, GS = problem.scenario_values(problem.to_physical(X))
    for j, (old, new) in enumerate(
        [("mass: 2210 ", "mass: 2500 "), ("height: 0.05 ", "height: 0.07 ")]
    ):
        changed = BASE.replace(old, new)
        assert changed != BASE
        F, G = _evaluate(_problem(base=changed), X)
        assert np.array_equal(FS[:, j + 1], F) and np.array_equal(GS[:, j + 1], G)


def test_aggregates_follow_their_definitions():
    rng = np.random.default_rng(0)
    values = rng.normal(size=(5, 4, 6))
    weights = np.array([1.0, 2.0, 0.5, 3.0])
    how = ["mean", "max", "min", "std", "weighted", Quantile(quantile=0.25)]
    out = aggregate(values, how, weights)
    assert np.allclose(out[:, 0], values[:, :, 0].mean(axis=1))
    assert np.array_equal(out[:, 1], values[:, :, 1].max(axis=1))
    assert np.array_equal(out[:, 2], values[:, :, 2].min(axis=1))
    assert np.allclose(out[:, 3], values[:, :, 3].std(axis=1))
    assert np.allclose(out[:, 4], (values[:, :, 4] * weights).sum(axis=1) / weights.sum())
    assert np.allclose(out[:, 5], np.quantile(values[:, :, 5], 0.25, axis=1))
    assert not np.allclose(out[:, 4], values[:, :, 4].mean(axis=1))


def test_objective_aggregate_from_the_config():
    text = BASE.replace(
        "signal: body.heave_acc}", "signal: body.heave_acc, over_scenarios: {quantile: 0.5}}"
    )
    problem = _problem(
        "scenarios:\n  cases:\n    - {name: a, set: {road.height: 0.04}}\n"
        "    - {name: b, set: {road.height: 0.06}, weight: 3}\n",
        base=text,
    )
    X = _designs(problem, 5)
    F, _ = _evaluate(problem, X)
    FS, _ = problem.scenario_values(problem.to_physical(X))
    assert np.array_equal(F[:, 0], np.median(FS[:, :, 0], axis=1))
    assert problem.aggregation()[0] == ["quantile 0.5"]


def test_load_mass_follows_the_rule_of_analyse_masses():
    cfg = suspopt.load_config(CONFIGS / "ch8" / "pareto_ps_class_a.yaml")
    text = cfg.text.replace("duration: 30.0", "duration: 2.0")
    plain = Problem.from_config(load_config_text(text))
    problem = Problem.from_config(
        load_config_text(text + "scenarios:\n  cases: [{name: heavy, load_mass: 115}]\n")
    )
    X = _designs(problem, 3)
    FS, _ = problem.scenario_values(problem.to_physical(X))
    params = plain.params(X)
    params.update({k: np.repeat(v, 3) for k, v in passenger_mass_change(plain.cfg, 115.0).items()})
    result = suspopt.simulate(
        plain._sim_cfg.model_copy(update={"metrics": [plain.cfg.objectives.main[0]]}), params
    )
    # (to rounding: the compiled engine's evaluation forms and sums the weighted signal in its
    # kernel, suspopt/integrator/accumulators.py)
    np.testing.assert_allclose(FS[:, 1, 0], result.metrics["RC_se"], rtol=1e-13)
    # X_ST follows the load: K_v stays, m grows
    assert np.allclose(FS[:, 1, 1], FS[:, 0, 1] * 115 / 95)


@pytest.mark.parametrize(
    "extra, message",
    [
        ("  cases: [{name: a, set: {vehicle.body.mas: 1}}]\n", "did you mean vehicle.body.mass"),
        (
            "  cases: [{name: a, set: {vehicle.corners.F1.damper.c: 3000}}]\n",
            "is a design variable",
        ),
        ("  cases: [{name: a, set: {optimiser.seed: 3}}]\n", "cannot change optimiser"),
        ("  cases: [{name: a, set: {vehicle.body.mass: heavy}}]\n", "takes a number"),
        ("  cases: [{name: a, set: {vehicle.body.mass: -5}}]\n", "must be in"),
        ("  cases: [{name: a, set: {road.road_class: C}}]\n", "road.road_class: unknown key"),
        ("  cases: [{name: a}, {name: a}]\n", "two scenarios are named 'a'"),
        ("  cases: [{name: nominal}]\n", "two scenarios are named 'nominal'"),
        ("  cases: [{name: a, load_mass: 80}]\n", "load_mass needs a seat"),
        ("  cases: [{name: a, set: {road.height: .inf}}]\n", "must be finite"),
        (
            "  product: [[{name: a, set: {road.height: 0.04}}], [{name: b, set: {road.height: 0.06}}]]\n",
            "set by another product list",
        ),
        (
            "  product: ["
            + ", ".join(["[" + ", ".join(f"{{name: n{i}}}" for i in range(7)) + "]"] * 4)
            + "]\n",
            "2402 scenarios, more than 256",  # (the nominal and 7^4; the count stopped at 7^3)
        ),
        ("  nominal: false\n", "no scenario"),
        ("  cases: [{name: a/b}]\n", "must be a name without '/' that does not start with"),
    ],
)
def test_bad_scenarios_name_their_key(extra, message):
    text = BASE + "scenarios:\n" + extra
    with pytest.raises(ConfigError) as err:
        Problem.from_config(load_config_text(text))
    assert message in str(err.value)
    assert str(err.value).startswith("<config>:")
    assert "scenarios" in str(err.value)


def test_a_constraint_cannot_combine_by_std():
    text = BASE.replace("max: 0.8}", "max: 0.8, over_scenarios: std}")
    with pytest.raises(ConfigError, match="not std"):
        load_config_text(text)


def test_validate_checks_stability_in_each_scenario(tmp_path):
    from suspopt.validation import check_config

    cfg = load_config_text(
        BASE
        + "scenarios:\n  cases: [{name: hard_tyre, set: {vehicle.corners.F1.tyre.stiffness: 1.0e9}}]\n"
    )
    with pytest.raises(ConfigError, match="in scenario hard_tyre: simulation.dt"):
        check_config(cfg)


def test_the_pareto_file_holds_every_scenario(tmp_path):
    from suspopt.optimisation import optimise

    text = BASE.replace("population: 50 ", "population: 8 ").replace(
        "generations: 20 ", "generations: 2 "
    )
    text = text.replace("algorithm: ga ", "algorithm: nsga2 ")
    text = text.replace(
        "  supplementary:",
        "    - {name: travel, metric: var, signal: travel, reduce: mean, over_scenarios: max}\n  supplementary:",
    )
    text += "scenarios:\n  cases: [{name: high, set: {road.height: 0.07}, weight: 2}]\n"
    path = tmp_path / "robust.yaml"
    path.write_text(text)
    out = tmp_path / "robust.h5"
    optimise(suspopt.load_config(path), out)
    with h5py.File(out) as h5:
        F, G = h5["pareto/F"][...], h5["pareto/G"][...]
        FS, GS = h5["pareto/scenarios/F"][...], h5["pareto/scenarios/G"][...]
        names = [n.decode() for n in h5["pareto/scenarios/scenario"][...]]
        assert names == ["nominal", "high"]
        assert list(h5["pareto/scenarios/weight"][...]) == [1.0, 2.0]
        assert FS.shape == (len(F), 2, 2) and GS.shape == (len(G), 2, G.shape[1])
        assert list(h5["pareto/F"].attrs["over_scenarios"]) == ["mean", "max"]
        assert np.array_equal(F[:, 0], FS[:, :, 0].mean(axis=1))
        assert np.array_equal(F[:, 1], FS[:, :, 1].max(axis=1))
        assert np.array_equal(G[:, :-1], GS[:, :, :-1].max(axis=1))
        assert h5["pareto/scenarios/F"].attrs["units"][0] == h5["pareto/F"].attrs["units"][0]
    # kesort sorts on the aggregates
    from suspopt.choosing.selection import read_pareto

    assert read_pareto(out).F.shape == F.shape


@pytest.mark.cli
@pytest.mark.slow
def test_simulate_a_pick_under_one_scenario(tmp_path):
    from typer.testing import CliRunner

    from suspopt.cli import app
    from suspopt.templates import template_text

    text = template_text("robust").replace("population: 30 ", "population: 8 ")
    text = text.replace("generations: 15 ", "generations: 2 ")
    config = tmp_path / "robust.yaml"
    config.write_text(text)
    front = tmp_path / "front.h5"
    runner = CliRunner()
    res = runner.invoke(app, ["optimise", str(config), "-o", str(front)])
    assert res.exit_code == 0, res.output
    assert "over 9 scenarios: RC_se max, X_ST max" in res.output
    out = tmp_path / "knee.h5"
    args = ["simulate", str(front), "--pick", "knee", "--scenario", "C/115kg", "-o", str(out)]
    res = runner.invoke(app, args)
    assert res.exit_code == 0, res.output
    with h5py.File(front) as h5:
        rows = h5["pareto/scenarios/F"][...][:, 8]  # C/115kg, the last of the product
    with h5py.File(out) as h5:
        row = int(h5["designs/row"][0])
        stored = h5["objectives/stored_F"][0]
        simulated = h5["objectives/F"][0]
        assert h5["signals/seat.acc"].shape[0] == 1
    assert np.array_equal(stored, rows[row])
    assert simulated[1] == stored[1]  # X_ST under the 115 kg load, no simulation needed
    assert abs(simulated[0] / stored[0] - 1) < 0.05  # RC_se: 10 s in time, stationary stored
    for bad, message in (
        (["--scenario", "C/115"], "did you mean C/115kg"),
        (["--scenario", "nominal"], "no such scenario"),
        (["--scenario", "A/75kg,C/115kg"], "one scenario per run"),
    ):
        res = runner.invoke(app, ["simulate", str(front), "--pick", "knee", *bad])
        assert res.exit_code == 2 and message in res.output, res.output
        assert len(res.output.strip().splitlines()) == 1
    plain = tmp_path / "plain.yaml"
    plain.write_text(template_text("quarter"))
    res = runner.invoke(app, ["simulate", str(plain), "--scenario", "A"])
    assert res.exit_code == 2 and "has no scenarios: section" in res.output
    # analyse scenarios: the stored values of the picks, nothing simulated
    report = tmp_path / "spread.h5"
    res = runner.invoke(app, ["analyse", "scenarios", str(front), "-o", str(report)])
    assert res.exit_code == 0, res.output
    assert "hold every constraint in all 9 scenarios" in res.output
    with h5py.File(report) as h5, h5py.File(front) as src:
        picks = [p.decode() for p in h5["scenarios/pick"][...]]
        assert "knee" in picks and h5["scenarios/F"].shape == (len(picks), 9, 2)
        rows = h5["scenarios/row"][...]
        assert np.array_equal(h5["scenarios/F"][...], src["pareto/scenarios/F"][...][rows])
        assert list(h5["scenarios/F"].attrs["over_scenarios"]) == ["max", "max"]
        knee = int(rows[picks.index("knee")])
    # --pick: the designs named, a row number as "row R", each name once
    res = runner.invoke(
        app, ["analyse", "scenarios", str(front), "--pick", "0,knee,0", "-o", str(report),
              "--force"],
    )  # fmt: skip
    assert res.exit_code == 0, res.output
    with h5py.File(report) as h5, h5py.File(front) as src:
        assert [p.decode() for p in h5["scenarios/pick"][...]] == ["design 0", "knee"]
        assert list(h5["scenarios/row"][...]) == [0, knee]
        assert np.array_equal(h5["scenarios/F"][...], src["pareto/scenarios/F"][...][[0, knee]])
    for command in (  # it holds no design set: each command says what it is and made from
        ["report", str(report), "-o", str(tmp_path / "spread.html")],
        ["export", str(report), "--pick", "knee", "-o", str(tmp_path / "knee.yaml")],
        ["simulate", str(report), "--pick", "knee"],
        ["kesort", str(report)],
    ):
        res = runner.invoke(app, command)
        assert res.exit_code == 2 and len(res.output.strip().splitlines()) == 1, res.output
        assert f"holds the results of suspopt analyse scenarios of {front}" in res.output
    plain_front = tmp_path / "plain.h5"
    text = template_text("spectral").replace("population: 40 ", "population: 6 ")
    text = text.replace("generations: 25 ", "generations: 1 ")
    (tmp_path / "spectral.yaml").write_text(text)
    assert runner.invoke(app, ["optimise", str(tmp_path / "spectral.yaml"), "-o",
                               str(plain_front)]).exit_code == 0  # fmt: skip
    res = runner.invoke(app, ["analyse", "scenarios", str(plain_front)])
    assert res.exit_code == 2 and "/pareto/scenarios: missing" in res.output
    with h5py.File(front, "a") as h5:  # a damaged file: scenarios that do not fit /pareto
        data = h5["pareto/scenarios/F"][...]
        del h5["pareto/scenarios/F"]
        h5["pareto/scenarios/F"] = data[:, :4]
    res = runner.invoke(app, ["analyse", "scenarios", str(front)])
    assert res.exit_code == 2 and "does not fit" in res.output, res.output


ISO = (
    (CONFIGS / "ch8" / "pareto_ps_class_a.yaml")
    .read_text()
    .replace("duration: 30.0", "duration: 2.0")
)
ROADS = """scenarios:
  cases:
    - {name: seed7, set: {road.seed: 7}}
    - {name: class_c, set: {road.road_class: C}, weight: 2}
    - {name: heavy, load_mass: 115}
    - {name: slow_c, set: {road.road_class: C, road.speed: 13.9}}
"""


@pytest.mark.parametrize("engine", ["numpy", "compiled"])
@pytest.mark.parametrize("wide", [True, False])
def test_roads_of_one_time_grid_are_columns_of_one_batch(engine, wide, monkeypatch):
    """Scenarios with roads of their own (seed, class, speed) on one time grid are ONE
    simulation, each scenario's columns under its own road, bit for bit the scenario's
    config alone; on both engines, and in numpy whether the inputs are widened per column
    or broadcast per road."""
    if engine == "compiled":
        pytest.importorskip("numba")
    from suspopt.integrator import rk4

    if not wide:
        monkeypatch.setattr(rk4, "_WIDE_OFFSETS", 0)
    assert "output_dt: 2.0e-3, engine: auto}" in ISO
    text = ISO.replace("engine: auto}", f"engine: {engine}}}")
    assert text != ISO
    calls = _counted_calls(monkeypatch, columns=False)
    problem = _problem(ROADS, base=text)
    X = _designs(problem, 4)
    FS, GS = problem.scenario_values(problem.to_physical(X))
    assert calls == [5]  # nominal, seed7, class_c, heavy, slow_c: one call, five roads' blocks
    changes = [("seed: 1", "seed: 7"), ("road_class: A", "road_class: C"), None,
               ("speed: 33.333333", "speed: 13.9")]  # fmt: skip
    for j, change in enumerate(changes, start=1):
        if change is None:
            continue
        alone = text.replace(*change)
        if j == 4:
            alone = alone.replace("road_class: A", "road_class: C")
        assert alone != text
        F, G = _evaluate(_problem(base=alone), X)
        assert np.array_equal(FS[:, j], F) and np.array_equal(GS[:, j], G), j


@pytest.mark.parametrize("engine", ["numpy", "compiled"])
@pytest.mark.parametrize("kind", ["bump_half_sine", "bump_step"])
def test_bumps_of_other_heights_are_columns_of_one_batch(engine, kind, monkeypatch):
    """Bumps that differ in height only share their edges' instants: one batch, each
    scenario's columns under its own bump (split steps and impulses per column), bit for
    bit the scenario alone."""
    if engine == "compiled":
        pytest.importorskip("numba")
    base = BASE.replace("kind: bump_half_sine ", f"kind: {kind} ").replace(
        "  dt: 2.0e-3 ", f"  engine: {engine}\n  dt: 2.0e-3 "
    )
    assert base.count(kind) and "engine" in base
    calls = _counted_calls(monkeypatch, columns=False)
    extra = (
        "scenarios:\n  cases:\n    - {name: low, set: {road.height: 0.03}}\n"
        "    - {name: heavy, set: {vehicle.body.mass: 2500}}\n"
        "    - {name: late, set: {road.start: 0.7}}\n"
    )
    problem = _problem(extra, base=base)
    X = _designs(problem, 3)
    FS, GS = problem.scenario_values(problem.to_physical(X))
    assert calls == [3, 1]  # nominal, low, heavy in one batch; the later bump alone
    alone = base.replace("height: 0.05 ", "height: 0.03 ")
    assert alone != base
    F, G = _evaluate(_problem(base=alone), X)
    assert np.array_equal(FS[:, 1], F) and np.array_equal(GS[:, 1], G)


def test_a_scenario_road_too_large_for_memory_is_bad_input(monkeypatch):
    from suspopt import memory
    from suspopt.validation import check_config

    memory.set_limit(200 << 20)
    try:
        text = ISO + "scenarios:\n  cases: [{name: dense, set: {road.n_waves: 2000000}}]\n"
        cfg = load_config_text(text)
        with pytest.raises(ConfigError, match="in scenario dense: simulation: simulating 1 design"):
            check_config(cfg)
        problem = Problem.from_config(cfg)  # the library path checks each road too
        with pytest.raises(ConfigError, match="needs about"):
            _evaluate(problem, _designs(problem, 2))
    finally:
        memory.set_limit(None)


@pytest.mark.slow
def test_resume_continues_a_robust_run_bit_for_bit(tmp_path):
    from suspopt.optimisation import optimise

    text = BASE.replace("population: 50 ", "population: 6 ").replace(
        "generations: 20 ", "generations: 3 "
    )
    text += "scenarios:\n  cases: [{name: high, set: {road.height: 0.07}}]\n"
    path = tmp_path / "robust.yaml"
    path.write_text(text)
    cfg = suspopt.load_config(path)

    def stop(progress):
        if progress.generation == 2:
            raise KeyboardInterrupt

    cut, whole = tmp_path / "cut.h5", tmp_path / "whole.h5"
    assert optimise(cfg, cut, callback=stop).status == "interrupted"
    optimise(cfg, cut, resume=True)
    optimise(cfg, whole)
    with h5py.File(cut) as a, h5py.File(whole) as b:
        assert a.attrs["status"] == "finished"
        for key in ("X", "F", "G", "scenarios/F", "scenarios/G"):
            assert np.array_equal(a[f"pareto/{key}"][...], b[f"pareto/{key}"][...], equal_nan=True)
