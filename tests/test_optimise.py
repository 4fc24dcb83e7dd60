"""Optimisation: algorithms on analytic problems, the YAML problem, checkpoints and the CLI."""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest
from conftest import TINY, run
from pymoo.algorithms.moo.nsga2 import NSGA2
from pymoo.algorithms.soo.nonconvex.ga import GA
from pymoo.core.problem import Problem as PymooProblem
from pymoo.indicators.igd import IGD
from pymoo.problems import get_problem

import suspopt
from suspopt.config import ConfigError
from suspopt.config.loader import load_config_text
from suspopt.config.optimise import ALGORITHMS
from suspopt.optimisation import (
    PENALTY,
    Gradient,
    Hybrid,
    Problem,
    PymooOptimiser,
    WeightedSum,
    balanced_weights,
    build_optimiser,
    minimize,
    optimise,
)
from suspopt.optimisation.algorithms import pymoo_algorithm, termination
from suspopt.params import numeric_paths

# --- analytic problems: the algorithm layer needs no vehicle -----------------------------------


class Quadratic(PymooProblem):
    """f = |x - (1, -2, 0.5)|^2 on [-5, 5]^3; records the batch sizes it is asked for."""

    optimum = np.array([1.0, -2.0, 0.5])

    def __init__(self):
        super().__init__(n_var=3, n_obj=1, xl=-5.0, xu=5.0)
        self.batches: list[int] = []

    def _evaluate(self, X, out, *args, **kwargs):
        self.batches.append(len(X))
        out["F"] = ((X - self.optimum) ** 2).sum(axis=1)


class Disc(PymooProblem):
    """min x0^2 + x1^2 subject to x0 + x1 >= 1: optimum (0.5, 0.5), f = 0.5."""

    def __init__(self):
        super().__init__(n_var=2, n_obj=1, n_ieq_constr=1, xl=-2.0, xu=2.0)

    def _evaluate(self, X, out, *args, **kwargs):
        out["F"] = (X**2).sum(axis=1)
        out["G"] = 1.0 - X.sum(axis=1)


class TwoObjectives(PymooProblem):
    """f1 = the quadratic, f2 = |x|^2 (with the same constraint as Disc, x0 + x1 >= 1)."""

    def __init__(self, n_obj=2):
        super().__init__(n_var=3, n_obj=n_obj, n_ieq_constr=1, xl=-5.0, xu=5.0)

    def _evaluate(self, X, out, *args, **kwargs):
        f1 = ((X - Quadratic.optimum) ** 2).sum(axis=1)
        out["F"] = np.column_stack([f1, (X**2).sum(axis=1)])[:, : self.n_obj]
        out["G"] = 1.0 - X[:, 0] - X[:, 1]


def ga(pop=40, generations=60, n_obj=1):
    return PymooOptimiser(GA(pop_size=pop), termination(n_obj, generations, None, 1e-10, 30))


def test_a_design_matrix_of_the_wrong_shape_is_a_value_error_naming_it():
    """``evaluate``, ``to_physical``, ``to_search`` and ``params`` of an X that is not
    (N, n_var): pymoo's AssertionError, or numpy's "boolean index did not match" before;
    ``scenario_values`` of a problem without scenarios was a bare AssertionError."""
    from conftest import CONFIGS

    problem = suspopt.Problem.from_config(
        suspopt.load_config(CONFIGS / "ch8" / "pareto_ps_class_a.yaml")
    )
    shape = rf"must be \(N designs, 2: {', '.join(problem.var_names)}\); got shape"
    for call in (problem.evaluate, problem.to_physical, problem.to_search, problem.params):
        with pytest.raises(ValueError, match=shape + r" \(2, 3\)"):
            call(np.ones((2, 3)))
        with pytest.raises(ValueError, match=shape + r" \(2, 1, 2\)"):
            call(np.ones((2, 1, 2)))
    assert problem.params(np.ones(2))[problem.variables[0].path].shape == (1,)
    with pytest.raises(ValueError, match="no scenarios: section"):
        problem.scenario_values(np.ones((1, 2)))


def test_ga_finds_the_minimum_of_a_quadratic():
    best = minimize(Quadratic(), ga(), seed=1)
    np.testing.assert_allclose(best.X[0], Quadratic.optimum, atol=0.05)
    assert best.F[0, 0] < 2e-3


def test_gradient_uses_one_batch_of_n_plus_1_designs_per_gradient():
    problem = Quadratic()
    gradient = Gradient(max_iterations=100)
    best = minimize(problem, gradient, seed=1)
    np.testing.assert_allclose(best.X[0], Quadratic.optimum, atol=2e-3)
    assert set(problem.batches) == {problem.n_var + 1}
    assert gradient.n_eval == sum(problem.batches)
    assert gradient.n_gen < 20


def test_gradient_and_hybrid_hold_a_constraint():
    best = minimize(Disc(), Gradient(max_iterations=100), seed=1)
    np.testing.assert_allclose(best.X[0], [0.5, 0.5], atol=1e-5)
    hybrid = Hybrid(ga(pop=20, generations=5), Gradient(), shrink=0.2, max_iterations=60)
    best = minimize(Disc(), hybrid, seed=3)
    assert hybrid.ga.n_gen == 5 and hybrid.gradient.n_gen >= 1
    np.testing.assert_allclose(best.X[0], [0.5, 0.5], atol=1e-4)
    assert best.G[0, 0] <= 1e-8
    lo, hi = hybrid.gradient.box  # the GA best +- 0.2/2 of the range, cut by bounds
    assert np.all(hi - lo <= 0.2 * 4.0 + 1e-12)


@pytest.mark.parametrize("shrink", [1e-300, 1e-20])
def test_a_hybrid_box_below_the_floating_point_resolution_keeps_its_designs_finite(shrink):
    """A shrink so small that best ± shrink/2 of the range rounds to the best itself made a
    box of zero span, whose unit box divided 0 by 0: every SLSQP design was NaN (found by
    ``benchmarks/fuzz_configs.py --optimise --seed 11``)."""
    problem = Quadratic()
    hybrid = Hybrid(ga(pop=10, generations=2), Gradient(), shrink=shrink, max_iterations=6)
    best = minimize(problem, hybrid, seed=1)
    lo, hi = hybrid.gradient.box
    assert np.all(hi > lo) and np.all(np.isfinite(best.X)) and np.isfinite(best.F).all()
    ga_best = hybrid.ga.optimum().X[0]
    np.testing.assert_allclose(best.X[0], ga_best, rtol=1e-15)  # (no room to move)


@pytest.mark.slow
def test_nsga2_approaches_the_zdt1_front():
    zdt1 = get_problem("zdt1")
    front = minimize(
        zdt1, PymooOptimiser(NSGA2(pop_size=100), termination(2, 150, None, 1e-9, 50)), seed=1
    )
    assert len(front.F) > 50
    assert IGD(zdt1.pareto_front())(front.F) < 0.01


def test_same_seed_same_run_and_no_global_random_state():
    np.random.seed(123)  # noqa: NPY002  (the global state the run must not touch)
    before = np.random.get_state()[1].copy()  # noqa: NPY002
    runs = [
        minimize(
            TwoObjectives(),
            PymooOptimiser(NSGA2(pop_size=20), termination(2, 10, None, 1e-9, 50)),
            seed=seed,
        )
        for seed in (7, 7, 8)
    ]
    np.testing.assert_array_equal(runs[0].X, runs[1].X)
    np.testing.assert_array_equal(runs[0].F, runs[1].F)
    assert not np.array_equal(runs[0].F, runs[2].F)
    np.testing.assert_array_equal(np.random.get_state()[1], before)  # noqa: NPY002


def test_weighted_sum_with_one_unit_weight_is_the_single_objective():
    single = minimize(TwoObjectives(n_obj=1), ga(generations=15), seed=5)
    weighted = minimize(WeightedSum(TwoObjectives(), [1.0, 0.0]), ga(generations=15), seed=5)
    np.testing.assert_array_equal(single.X, weighted.X)
    np.testing.assert_array_equal(single.F, weighted.F)
    with pytest.raises(ValueError, match="2 weights for 1"):
        WeightedSum(TwoObjectives(n_obj=1), [1.0, 1.0])


def test_balanced_weights_are_inverse_medians():
    class Scaled(PymooProblem):
        def __init__(self):
            super().__init__(n_var=1, n_obj=3, xl=0.0, xu=1.0)

        def _evaluate(self, X, out, *args, **kwargs):
            out["F"] = X[:, :1] * np.array([1.0, 1e-3, 1e4])

    w = balanced_weights(Scaled(), 2001, np.random.default_rng(0))
    np.testing.assert_allclose(w * np.array([1.0, 1e-3, 1e4]), 2.0, rtol=0.1)  # median x ~ 0.5
    w5 = balanced_weights(Scaled(), 2001, np.random.default_rng(0), dominant=0, factor=10.0)
    np.testing.assert_allclose(w5, w * [10.0, 1.0, 1.0])


def test_pymoo_algorithms_by_name_with_checked_options():
    gde3 = pymoo_algorithm(ALGORITHMS["gde3"].target, {"CR": 0.5}, 20, 2)  # a DE variant option
    front = minimize(
        TwoObjectives(), PymooOptimiser(gde3, termination(2, 10, None, 1e-9, 50)), seed=1
    )
    assert front.feasible.all()
    with pytest.raises(ValueError, match="did you mean eliminate_duplicates"):
        pymoo_algorithm(ALGORITHMS["ga"].target, {"eliminate_duplicate": True}, 10, 1)
    with pytest.raises(ValueError, match="set by suspopt"):
        pymoo_algorithm(ALGORITHMS["nsga2"].target, {"seed": 3}, 10, 2)


class Mixed(PymooProblem):
    """One to three objectives with a constraint, for the algorithm registry."""

    def __init__(self, n_obj):
        super().__init__(n_var=3, n_obj=n_obj, n_ieq_constr=1, xl=0.0, xu=1.0)

    def _evaluate(self, X, out, *args, **kwargs):
        out["F"] = np.column_stack(
            [((X - 0.3) ** 2).sum(axis=1), ((X - 0.7) ** 2).sum(axis=1), (X**2).sum(axis=1)]
        )[:, : self.n_obj]
        out["G"] = 0.2 - X[:, 0]


@pytest.mark.parametrize("name", [k for k in ALGORITHMS if k not in ("gradient", "hybrid")])
def test_every_registered_pymoo_algorithm_is_seeded_and_resumes_by_replay(name, monkeypatch):
    """Each algorithm draws only from the run's Generator, and replaying its evaluated batches
    (the data-only checkpoint) rebuilds it exactly: no design is evaluated again."""
    from suspopt.optimisation.run import _Recorder

    n_obj = 1 if ALGORITHMS[name].single_objective else 3
    problem = Mixed(n_obj)

    def optimiser():
        return PymooOptimiser(
            pymoo_algorithm(ALGORITHMS[name].target, {}, 12, n_obj),
            termination(n_obj, 8, None, 1e-12, 30),
        )

    default_rng = np.random.default_rng

    def seeded_only(seed=None, *args):  # pymoo's fallback for a missing random_state
        assert seed is not None, f"{name} draws from an unseeded Generator"
        return default_rng(seed, *args)

    first, recorder = optimiser(), _Recorder(problem)
    resumed, replay = optimiser(), _Recorder(problem)
    first.setup(recorder, default_rng(1))  # (pymoo's setup makes a Generator of its
    resumed.setup(replay, default_rng(1))  # own, which the run's replaces)
    monkeypatch.setattr(np.random, "default_rng", seeded_only)
    for _ in range(3):
        first.next()
    replay._stored.extend(recorder.batches)  # what the checkpoint holds
    evaluated = []
    monkeypatch.setattr(problem, "_evaluate", lambda X, out, *a, **k: evaluated.append(X))
    for _ in range(3):
        resumed.next()
    assert not replay.replaying and evaluated == []
    monkeypatch.undo()
    while first.has_next():
        first.next()
        resumed.next()
    assert not resumed.has_next()
    np.testing.assert_array_equal(first.optimum().F, resumed.optimum().F)


# --- the YAML problem on a tiny Chapter 5 half car -----------------------------------------------


def tiny(text: str = TINY, **replace) -> suspopt.Config:
    for old, new in replace.items():
        assert old in text, old
        text = text.replace(old, new)
    return load_config_text(text, Path("case.yaml"))


def test_problem_names_units_and_one_batch_equal_to_single_designs():
    problem = suspopt.Problem.from_config(tiny())
    assert problem.var_names == ["k_F1", "c_F1", "knl_F1"]
    assert problem.var_units == ["N/m", "N s/m", "N/m^3"]
    assert problem.obj_names == ["f1", "f3"] and problem.obj_units == ["(m/s^2)^2", "m^2"]
    assert problem.constraint_names == [
        "RC <= 1.4",
        "ratio.F1 >= 0.1",
        "ratio.F1 <= 0.3",
        "ratio.R1 >= 0.1",
        "ratio.R1 <= 0.3",
        "simulation_failed",
    ]
    assert problem.supplementary_names == ["f2"]
    np.testing.assert_allclose(problem.xu[2], np.log10(3.0e7))
    X = problem.xl + np.random.default_rng(0).random((4, 3)) * (problem.xu - problem.xl)
    F, G, S = problem.evaluate(X, return_values_of=["F", "G", "S"])
    assert F.shape == (4, 2) and G.shape == (4, 6) and S.shape == (4, 1)
    single = np.vstack(
        [np.hstack(problem.evaluate(x[None], return_values_of=["F", "G"])) for x in X]
    )
    np.testing.assert_allclose(np.hstack([F, G]), single, rtol=1e-12)
    assert (G[:, -1] == -1).all()
    np.testing.assert_allclose(problem.to_physical(X)[:, 2], 10 ** X[:, 2])


def test_a_diverging_design_is_penalised_and_the_batch_survives():
    cfg = tiny(
        **{
            "dt: 1.0e-3": "dt: 5.0e-3",
            "path: vehicle.corners.F1.damper.c, lower: 2.0e3, upper: 1.0e4": "path: vehicle.corners.F1.tyre.stiffness, lower: 2.0e5, upper: 2.0e7",
        }
    )
    problem = suspopt.Problem.from_config(cfg)
    X = np.array([[5e4, 4e5, 7.0], [5e4, 2e7, 7.0]])  # the stiff tyre blows up RK4 at 5 ms
    F, G = problem.evaluate(X, return_values_of=["F", "G"])
    assert np.isfinite(F).all() and np.isfinite(G).all()
    assert (F[1] == PENALTY).all() and G[1, -1] == PENALTY
    assert (F[0] < PENALTY).all() and G[0, -1] == -1


BAD = {
    "path": (
        {"path: vehicle.corners.F1.spring.linear": "path: vehicle.corners.F1.spring.linaer"},
        "did you mean vehicle.corners.F1.spring.linear",
        18,
    ),
    "swapped": (
        {"lower: 3.2e4, upper: 1.5e5": "lower: 1.5e5, upper: 3.2e4"},
        "did you swap the bounds",
        18,
    ),
    "per_corner_objective": (
        {"signal: tyre_deflection, reduce: mean}": "signal: tyre_deflection}"},
        "objectives.main[1].reduce: f3 gives one value per corner",
        24,
    ),
    "one_per_run": (
        {"path: vehicle.corners.F1.damper.c,": "path: road.speed,"},
        "road is one per run",
        19,
    ),
    "bound_rejected": (
        {
            "path: vehicle.corners.F1.damper.c, lower: 2.0e3": "path: vehicle.corners.F1.unsprung_mass, lower: 0"
        },
        "vehicle.corners.F1.unsprung_mass: must be in [0.001, 1e+06], got 0",
        19,
    ),
    "signal": (
        {"signal: body.heave_acc}": "signal: body.heave_ac}"},
        "did you mean body.heave_acc",
        23,
    ),
    "ga_two_objectives": ({"algorithm: nsga2": "algorithm: ga"}, "add optimiser.weighted_sum", 30),
    "weights": (
        {"algorithm: nsga2,": "algorithm: ga, weighted_sum: {weights: [1, 2, 3]},"},
        "3 weights for 2 main objectives",
        30,
    ),
    "option": (
        {"seed: 1}": "seed: 1, options: {n_offspring: 4}}"},
        "did you mean n_offsprings",
        30,
    ),
    "algorithm": ({"algorithm: nsga2": "algorithm: nsga"}, "nsga2", 30),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_optimisation_input_names_key_and_line(case):
    replace, needle, line = BAD[case]
    with pytest.raises(ConfigError) as exc:
        cfg = tiny(**replace)
        build_optimiser(cfg, suspopt.Problem.from_config(cfg))
    message = str(exc.value)
    assert needle in message and message.startswith(f"case.yaml:{line}:"), message


# --- runs: reproducible, resumable, written as docs/architecture.md#public-contract says --------


@pytest.mark.parametrize("seconds, writes", [(0.0, [1, 2, 3, 4, 4]), (1e9, [1, 4])])
def test_the_output_is_rewritten_at_most_every_few_seconds_and_at_the_end(
    tmp_path, monkeypatch, seconds, writes
):
    from suspopt.optimisation import run as run_module

    monkeypatch.setattr(run_module, "REWRITE_SECONDS", seconds)
    real, generations = run_module._write, []

    def counted(output, cfg, problem, snap, *args):
        generations.append(snap.generation)
        return real(output, cfg, problem, snap, *args)

    monkeypatch.setattr(run_module, "_write", counted)
    result = optimise(tiny(), tmp_path / "out.h5")
    assert generations == writes and result.status == "finished"  # the first, then the last


def test_an_error_that_stops_a_run_leaves_the_last_completed_generation(tmp_path, monkeypatch):
    from suspopt.optimisation import run as run_module

    monkeypatch.setattr(run_module, "REWRITE_SECONDS", 1e9)  # nothing but the first written

    def fail_at_3(progress):
        if progress.generation == 3:
            raise RuntimeError("the scheduler went away")

    with pytest.raises(RuntimeError, match="went away"):
        optimise(tiny(), tmp_path / "out.h5", callback=fail_at_3)
    with h5py.File(tmp_path / "out.h5") as h5:
        assert h5.attrs["status"] == "running" and h5.attrs["generations"] == 3
    resumed = optimise(tiny(), tmp_path / "out.h5", resume=True)
    whole = optimise(tiny(), tmp_path / "whole.h5")
    np.testing.assert_array_equal(resumed.F, whole.F)


@pytest.mark.parametrize("variant", ["nsga2", "hybrid_weighted"])
@pytest.mark.slow
def test_resume_equals_an_uninterrupted_run(tmp_path, variant):
    cfg = (
        tiny()
        if variant == "nsga2"
        else tiny(
            **{
                "{algorithm: nsga2, population: 8, generations: 4, seed: 1}": "{algorithm: hybrid, population: 8, generations: 5, seed: 1, hybrid: {ga_generations: "
                "2}, weighted_sum: {balance: {samples: 8, dominant: f1}}}"
            }
        )
    )
    whole = optimise(cfg, tmp_path / "whole.h5")
    again = optimise(cfg, tmp_path / "again.h5")

    def stop_at_3(progress):
        if progress.generation == 3:
            raise KeyboardInterrupt

    part = optimise(cfg, tmp_path / "part.h5", callback=stop_at_3)
    assert part.status == "interrupted" and len(part.history["generation"]) == 3
    with h5py.File(tmp_path / "part.h5") as h5:
        assert h5.attrs["status"] == "interrupted"
    resumed = optimise(cfg, tmp_path / "part.h5", resume=True)
    assert resumed.status == "finished"
    for other in (again, resumed):
        for key in ("X", "F", "G"):
            np.testing.assert_array_equal(getattr(whole, key), getattr(other, key))
            np.testing.assert_array_equal(  # (and the config's own design, evaluated at the end)
                getattr(whole.baseline, key), getattr(other.baseline, key)
            )
        np.testing.assert_array_equal(whole.history["evaluations"], other.history["evaluations"])
    assert part.baseline is None  # (an interrupted run spends no more time)
    if variant == "hybrid_weighted":
        assert whole.F.shape == (1, 2) and whole.weights.shape == (2,)
    with pytest.raises(ConfigError, match="another config"):
        optimise(tiny(**{"seed: 1}": "seed: 2}"}), tmp_path / "part.h5", resume=True)


@pytest.mark.slow
def test_cli_optimise_writes_the_design_md_layout(tmp_path):
    config = tmp_path / "case.yaml"
    config.write_text(TINY.replace("generations: 4", "generations: 2"))
    out = tmp_path / "front.h5"
    proc = run("optimise", config, "-o", out)
    assert proc.returncode == 0, proc.stderr
    assert "Pareto set" in proc.stdout or "best design" in proc.stdout
    assert "NSGA2 gen 2/2" in proc.stderr
    with h5py.File(out) as h5:
        assert h5.attrs["status"] == "finished" and h5.attrs["optimiser_seed"] == 1
        assert h5.attrs["config"] == config.read_text()
        X, F, G = (h5[f"pareto/{k}"] for k in "XFG")
        N = X.shape[0]
        assert X.shape == (N, 3) and F.shape == (N, 2) and G.shape == (N, 6) and N >= 1
        assert list(X.attrs["names"]) == ["k_F1", "c_F1", "knl_F1"]  # UTF-8 text
        assert list(F.attrs["units"]) == ["(m/s^2)^2", "m^2"]
        assert G.attrs["names"][-1] == "simulation_failed"
        for key in ("best", "hypervolume", "evaluations", "time", "generation", "feasible"):
            assert h5[f"history/{key}"].shape[0] == 2 and "units" in h5[f"history/{key}"].attrs
        assert h5["history/evaluations"][-1] == 16
        checkpoint = h5["checkpoint"]  # data only: every evaluated batch
        assert checkpoint.attrs["format"] == "replay-1" and checkpoint.attrs["generations"] == 2
        assert checkpoint["batches"][()].tolist() == [8, 8]
        assert checkpoint["X"].shape == (16, 3) and checkpoint["F"].shape == (16, 2)
        assert checkpoint["G"].shape == (16, 6)
        assert list(checkpoint["X"].attrs["units"])[2] == "log10(N/m^3)"
        assert "state" not in checkpoint
        own = {k: h5[f"baseline/{k}"][()] for k in "XFG"}  # the config's own design
        assert list(h5["baseline/F"].attrs["names"]) == list(F.attrs["names"])
        front = {k: h5[f"pareto/{k}"][()] for k in "FG"}
    # the config as written, simulated on its own: its objectives are the baseline's
    cfg = suspopt.load_config(config)
    np.testing.assert_allclose(own["X"], [[5.0e4, 3000.0, 1.0e7]], rtol=1e-12)
    values = Problem.from_config(cfg).values(suspopt.simulate(cfg), {}, 1)
    np.testing.assert_allclose(own["F"], values[0], rtol=1e-9)
    np.testing.assert_allclose(own["G"], values[1], rtol=1e-9, atol=1e-12)
    feasible = "feasible" if (own["G"] <= 0).all() else "infeasible"
    if N == 1:  # each objective's change from the config's design
        changes = [f"{n} {100 * (a - b) / abs(b):+.3g} %" for n, a, b in
                   zip(["f1", "f3"], front["F"][0], own["F"][0])]  # fmt: skip
        line = f"against the config's own design ({feasible}): {', '.join(changes)}"
    else:  # the front's designs that dominate it
        dominate = ((front["G"] <= 0).all(1) & (front["F"] <= own["F"]).all(1)
                    & (front["F"] < own["F"]).any(1)).sum()  # fmt: skip
        names = ", ".join(f"{n} = {v:.4g} {u}" for n, v, u in zip(["f1", "f3"], own["F"][0],
                                                                 ["(m/s^2)^2", "m^2"]))  # fmt: skip
        line = f"the config's own design: {names} ({feasible}); {dominate} of the {N} designs"
    assert line in " ".join(proc.stdout.split())


@pytest.mark.parametrize(
    "change, needle",
    [
        (
            {"upper: 1.5e5}": "upper: 1.5e4}"},
            "case.yaml:18: design_variables[0]: lower (32000) > upper (15000): did you swap",
        ),
        (
            {"name: f1, metric: var, signal": "name: f1, metric: vra, signal"},
            "case.yaml:23: objectives.main[0].metric: unknown metric 'vra'; did you mean var",
        ),
        (
            {"seed: 1}": "seed: 1, max_evals: 10}"},
            "case.yaml:30: optimiser.max_evals: unknown key; did you mean max_evaluations",
        ),
    ],
)
def test_cli_optimise_bad_input_exits_2_with_one_line(tmp_path, change, needle):
    from typer.testing import CliRunner

    from suspopt.cli import app

    config = tmp_path / "case.yaml"
    text = TINY
    for old, new in change.items():
        text = text.replace(old, new)
    config.write_text(text)
    result = CliRunner().invoke(app, ["optimise", str(config), "-o", str(tmp_path / "o.h5")])
    assert result.exit_code == 2
    message = result.stderr.strip()
    assert len(message.splitlines()) == 1 and "Traceback" not in message
    assert needle in message, message
    assert not (tmp_path / "o.h5").exists()


@pytest.mark.parametrize(
    "optimiser",
    [
        "{algorithm: gradient, max_evaluations: 1, seed: 1, weighted_sum: {weights: [1, 1]}}",
        "{algorithm: nsga2, population: 8, max_evaluations: 1, seed: 1}",
    ],
)
def test_a_budget_smaller_than_one_step_still_writes_a_result(tmp_path, optimiser):
    """A budget of one evaluation ends the run before its first generation is complete (the
    gradient method's first step needs n + 1 designs): the result is still written, with a
    history of no generation (before, writing that history raised a ValueError)."""
    cfg = tiny(**{"{algorithm: nsga2, population: 8, generations: 4, seed: 1}": optimiser})
    optimise(cfg, tmp_path / "out.h5")
    with h5py.File(tmp_path / "out.h5") as h5:
        best = h5["history/best"]
        assert best.ndim == 2 and best.shape[1] == len(best.attrs["names"])
        assert len(h5["history/generation"]) == best.shape[0]


# --- designs at the bounds of their search --------------------------------------------------


def test_a_value_within_one_percent_of_its_search_range_is_at_the_bound():
    from suspopt.config.optimise import DesignVariable
    from suspopt.optimisation.bounds import at_bounds, bounds_note

    variables = [
        DesignVariable(name="c", path="vehicle.corners.F1.damper.c", lower=0.0, upper=100.0),
        DesignVariable(
            name="k", path="vehicle.corners.F1.spring.cubic", lower=1.0, upper=1e4, scale="log"
        ),
    ]
    X = np.array(
        [
            [0.0, 1.0],  # on both lower bounds (log10: 0 of 0..4)
            [0.9, 10**0.03],  # 0.9 % and 0.75 % of the range: at them
            [1.5, 10**0.08],  # 1.5 % and 2 %: between
            [99.5, 10**3.97],  # 99.5 % and 99.25 %: at the upper bounds
            [-5.0, 1e5],  # beyond the bounds
            [np.nan, 100.0],  # NaN, and half way on the log scale (1e4 / 2 is at 92.5 %)
        ]
    )
    assert at_bounds(variables, X).tolist() == [
        [-1, -1],
        [-1, -1],
        [0, 0],
        [1, 1],
        [-1, 1],
        [0, 0],
    ]
    assert at_bounds(variables, [[50.0, 5e3]]).tolist() == [[0, 0]]  # (log: 92.5 %)
    assert at_bounds(variables, [[50.0, 5e3]], share=0.1).tolist() == [[0, 1]]
    note = bounds_note(["c", "k"], variables, X)
    assert note.startswith(
        "at a bound (within 1 % of its range): c lower in 3 of 6 designs, c upper in 1 of 6 "
        "designs, k lower in 2 of 6 designs, k upper in 2 of 6 designs; the front may reach"
    )
    assert bounds_note(["c", "k"], variables, X[2:3]) is None
    one = bounds_note(["c", "k"], variables, X[3:4])
    assert one.startswith("at a bound (within 1 % of its range): c upper, k upper; the optimum")
    with pytest.raises(ValueError, match="X: \\(3,\\) columns for 2 design variables"):
        at_bounds(variables, np.zeros((2, 3)))


@pytest.mark.slow
def test_optimise_and_kesort_name_the_variables_the_optimum_has_at_a_bound(tmp_path, capsys):
    """SLSQP on the tiny half car, softer and less damped for less body acceleration: the
    optimum stops at the lower bounds of the damper and the Duffing term, inside the spring's
    range. ``optimise`` and ``kesort`` say which, as the file's values give them."""
    from suspopt._entry import main

    config = tmp_path / "case.yaml"
    config.write_text(
        TINY.replace("    - {name: f3, metric: var, signal: tyre_deflection, reduce: mean}\n", "")
        .replace("  - {name: ratio, metric: spring_usage, min: 0.1, max: 0.3}\n", "")
        .replace(
            "{algorithm: nsga2, population: 8, generations: 4, seed: 1}",
            "{algorithm: gradient, max_evaluations: 200, seed: 1}",
        )
    )
    out = tmp_path / "best.h5"
    assert main(["optimise", str(config), "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    cfg = suspopt.load_config(config)
    with h5py.File(out) as h5:
        (x,) = h5["pareto/X"][()]
    at = []
    for v, value in zip(cfg.design_variables, x):
        scale = np.log10 if v.scale == "log" else (lambda a: a)
        position = (scale(value) - scale(v.lower)) / (scale(v.upper) - scale(v.lower))
        at += [f"{v.name} lower"] * bool(position <= 0.01)
        at += [f"{v.name} upper"] * bool(position >= 0.99)
    assert 0 < len(at) < len(x)  # (the run has both: the note can name too many or too few)
    with h5py.File(out) as h5:  # and against the config's own design, beside the optimum
        F, own = h5["pareto/F"][0, 0], h5["baseline/F"][0, 0]
    change = f"{100 * (F - own) / abs(own):+.3g}"
    assert f"against the config's own design (feasible): f1 {change} %" in printed
    assert "config's design" in printed and float(change) < 0
    note = f"at a bound (within 1 % of its range): {', '.join(at)}; the optimum may lie beyond"
    assert f"note: {note}" in " ".join(printed.split())
    assert main(["kesort", str(out)]) == 0
    printed = " ".join(capsys.readouterr().out.split())
    assert f"note: the k-ε optimum is {note}" in printed
    assert f"the k-ε optimum against the config's own design (feasible): f1 {change} %" in printed
    assert main(["kesort", str(out), "-o", str(tmp_path / "ke.h5")]) == 0
    with h5py.File(tmp_path / "ke.h5") as h5:  # (the supplementary f2 too, not in the file)
        assert list(h5["kesort/F"].attrs["names"].astype(str)) == ["f1", "f2"]
        chosen_f2 = h5["kesort/F"][int(h5["kesort/chosen"][()]), 1]
    values = numeric_paths(cfg)
    problem = suspopt.Problem.from_config(cfg)
    own_X = problem.to_search(np.array([[values[v.path] for v in problem.variables]]))
    own_f2 = problem.evaluate(own_X, return_values_of=["S"])[0, 0]
    f2 = f"{100 * (chosen_f2 - own_f2) / abs(own_f2):+.3g}"
    printed = " ".join(capsys.readouterr().out.split())
    assert f"own design (feasible): f1 {change} %, f2 {f2} %" in printed
    other = tmp_path / "other.yaml"  # (evaluated under another config: no baseline of its own)
    other.write_text(config.read_text().replace("speed: 11.111", "speed: 12.0"))
    assert main(["kesort", str(out), "--config", str(other), "--keep-infeasible"]) == 0
    assert "config's own design" not in capsys.readouterr().out


def test_the_front_is_set_against_the_configs_own_design():
    """The designs of a front that dominate the config's design: feasible, no objective
    worse, one better (a design equal to it, or infeasible, does not)."""
    from types import SimpleNamespace

    from suspopt.cli.optimisation import _baseline_line
    from suspopt.optimisation import Solutions

    own = Solutions(np.zeros((1, 1)), np.array([[1.0, 1.0]]), np.array([[-1.0]]))
    F = np.array([[0.5, 1.0], [1.0, 1.0], [0.2, 0.2], [0.5, 2.0], [0.9, 0.9]])
    G = np.array([[-1.0], [-1.0], [0.5], [-1.0], [0.0]])
    result = SimpleNamespace(X=np.zeros((5, 1)), F=F, G=G, obj_names=["a", "b"],
                             obj_units=["m", "s"], baseline=own)  # fmt: skip
    assert _baseline_line(result) == (
        "the config's own design: a = 1 m, b = 1 s (feasible); 2 of the 5 designs dominate "
        "it (feasible, no objective worse, one better)"
    )
    result.baseline = Solutions(own.X, np.array([[PENALTY, PENALTY]]), np.array([[1.0]]))
    assert _baseline_line(result) == (
        "the config's own design failed to simulate (diverged or gave NaN)"
    )
    result.baseline = None
    assert _baseline_line(result) is None


def test_optimise_takes_set_and_its_resume_needs_the_same(tmp_path, capsys):
    """``--set`` edits the config before the run as ``simulate``'s does, a field the config
    leaves unset included (a budget by evaluations given generations); the file records the
    edited config, so ``--resume`` takes the same ``--set`` (the hint says it) and refuses
    the run without it."""
    from suspopt._entry import main
    from suspopt.cli.optimisation import _again

    config = tmp_path / "case.yaml"
    config.write_text(TINY.replace("generations: 4, seed: 1}", "max_evaluations: 40, seed: 1}"))
    out = tmp_path / "front.h5"
    sets = ["--set", "optimiser.generations=2", "--set", "road.speed=20"]
    assert main(["optimise", str(config), "-o", str(out), *sets]) == 0, capsys.readouterr().err
    with h5py.File(out) as h5:
        assert h5["history/evaluations"][()].tolist() == [8, 16]  # (2 generations, not 5)
        recorded = load_config_text(h5.attrs["config"])
    assert recorded.optimiser.generations == 2 and recorded.road.speed == 20
    assert main(["optimise", str(config), "-o", str(out), *sets, "--resume"]) == 0
    capsys.readouterr()
    assert main(["optimise", str(config), "-o", str(out), "--resume"]) == 2
    assert "another config" in capsys.readouterr().err
    assert main(["optimise", str(config), "-o", str(out), "--set", "optimiser.generationz=2"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("error: --set optimiser.generationz: not a numeric field of this")
    assert len(err.splitlines()) == 1
    hint = _again(Path("my study.yaml"), Path("o.h5"), ["road.speed=25"])
    assert hint == "suspopt optimise 'my study.yaml' -o o.h5 --set road.speed=25 --resume"


@pytest.mark.slow
def test_a_run_resumed_with_a_longer_budget_goes_on_to_the_longer_runs_result(tmp_path, capsys):
    """A finished run of 2 generations, resumed with ``--set optimiser.generations=4``, goes
    on from its checkpoint to the bits of a 4-generation run; a budget below what the file
    holds, or any other change, is refused in one line."""
    from suspopt._entry import main

    config = tmp_path / "case.yaml"
    config.write_text(TINY.replace("generations: 4", "generations: 2"))
    short, whole = tmp_path / "short.h5", tmp_path / "whole.h5"
    more = ["--set", "optimiser.generations=4"]
    assert main(["optimise", str(config), "-o", str(short)]) == 0
    assert main(["optimise", str(config), "-o", str(whole), *more]) == 0
    assert main(["optimise", str(config), "-o", str(short), *more, "--resume"]) == 0
    with h5py.File(short) as a, h5py.File(whole) as b:
        assert a.attrs["generations"] == b.attrs["generations"] == 4
        for key in ("pareto/X", "pareto/F", "pareto/G", "history/evaluations", "checkpoint/X"):
            np.testing.assert_array_equal(a[key][()], b[key][()])
        assert a.attrs["config"] == b.attrs["config"]  # (the longer budget's, recorded)
    capsys.readouterr()
    for edit, needle in (
        (
            ["--set", "optimiser.generations=3"],
            "holds 4 generations and optimiser.generations is 3",
        ),
        (["--set", "road.speed=12"], "another config (it differs in more than optimiser."),
    ):
        assert main(["optimise", str(config), "-o", str(short), *more, *edit, "--resume"]) == 2
        err = capsys.readouterr().err.strip()
        assert needle in err and len(err.splitlines()) == 1, err


def test_a_config_value_outside_the_log_search_has_no_baseline(tmp_path):
    """A linear spring (k_nl = 0) where k_nl is searched on a log scale: the config's own
    design is no point of the search, so the file has no /baseline (and the run its optimum)."""
    result = optimise(tiny(**{"cubic: 1.0e7}": "cubic: 0}"}), tmp_path / "out.h5")
    assert result.baseline is None and result.status == "finished"
    with h5py.File(tmp_path / "out.h5") as h5:
        assert "baseline" not in h5 and len(h5["pareto/X"]) >= 1
    whole = optimise(tiny(), tmp_path / "whole.h5")
    assert whole.baseline is not None and whole.baseline.X.shape == (1, 3)
