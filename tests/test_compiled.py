"""The compiled integrator (``simulation.engine: compiled``) against the numpy reference.

Every bundled config of configs/ch3, ch4, ch5 and ch8 runs for three designs (spread over its
design variables' bounds, or its one design) on both engines: the states and accelerations
agree to 1e-12 of each signal's largest magnitude, and the divergence times are the same.
A run the compiled engine does not cover (a controller, an exact NSS mechanism) must run on
the numpy engine and say so.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml
from conftest import CONFIGS, make_config

import suspopt
from suspopt.control import LAWS, PARAMETERS
from suspopt.errors import ConfigError
from suspopt.simulation import prepare, simulate

numba = pytest.importorskip("numba")

pytestmark = pytest.mark.slow

CHAPTERS = sorted(
    p.relative_to(CONFIGS).as_posix()
    for chapter in ("ch3", "ch4", "ch5", "ch8")
    for p in (CONFIGS / chapter).glob("*.yaml")
)
#: Simulated time of each comparison [s] (after a bump's start): long enough for the bumps'
#: edges and the transients, short enough for the suite.
DURATION = 1.5


def _designs(cfg, P: int = 3) -> dict[str, np.ndarray]:
    """P designs spread inside the bounds of ``cfg``'s design variables (none: {})."""
    share = np.linspace(0.2, 0.8, P)
    out = {}
    for dv in cfg.design_variables:
        if dv.scale == "log":
            out[dv.path] = np.exp(np.log(dv.lower) + share * np.log(dv.upper / dv.lower))
        else:
            out[dv.path] = dv.lower + share * (dv.upper - dv.lower)
    return out


def _run(cfg, engine: str, params):
    c = cfg.model_copy(deep=True)
    c.simulation.engine = engine
    return simulate(c, params)


def _agree(a, b, tolerance: float = 1e-12) -> None:
    """Same divergence times, the same first non-finite sample of each design, every sample
    before it within ``tolerance`` of each signal's largest magnitude, and NaN everywhere
    from the divergence on. (Between a design's first NaN and the divergence check the two
    spread it differently: the numpy engine's dense products carry it to every DOF at once,
    the compiled engine's sparse loops to the coupled ones.)"""
    np.testing.assert_array_equal(a.diverged_at, b.diverged_at)
    for name in ("states", "accelerations"):
        x, y = getattr(a, name), getattr(b, name)
        bad_x, bad_y = np.isnan(x).any(axis=0), np.isnan(y).any(axis=0)  # (P, T)
        first = bad_x.argmax(axis=-1)
        np.testing.assert_array_equal(first, bad_y.argmax(axis=-1), err_msg=name)
        valid = np.arange(x.shape[-1]) < np.where(bad_x.any(axis=-1), first, x.shape[-1])[:, None]
        for p in range(x.shape[1]):
            xv, yv = x[:, p, valid[p]], y[:, p, valid[p]]
            if xv.size:
                scale = np.max(np.abs(xv), axis=-1, keepdims=True)
                scale = np.where(scale > 0, scale, 1.0)
                worst = np.max(np.abs(xv - yv) / scale)
                assert worst <= tolerance, f"{name}, design {p}: {worst:.3g} of the largest"
        after = a.time[None, :] >= a.diverged_at[:, None]  # (P, T), False where it never did
        assert np.isnan(x[:, after]).all() and np.isnan(y[:, after]).all(), name


@pytest.mark.parametrize("name", CHAPTERS)
def test_compiled_and_numpy_engines_agree_on_every_chapter_config(name):
    cfg = suspopt.load_config(CONFIGS / name)
    start = getattr(cfg.road, "start", 0.0)
    cfg.simulation.duration = min(cfg.simulation.duration, start + DURATION)
    params = _designs(cfg)
    numpy_run, compiled_run = _run(cfg, "numpy", params), _run(cfg, "compiled", params)
    assert numpy_run.engine == "numpy"
    if compiled_run.engine == "numpy":  # not covered: there is a reason
        from suspopt.integrator import compiled
        from suspopt.network import Assembled
        from suspopt.simulation import full_network, prepare

        pv, model, controller, attachments = prepare(cfg, params)
        asm = Assembled(full_network(model, attachments), pv.P)
        assert compiled.unsupported(asm, controller) is not None
    _agree(numpy_run, compiled_run)


@pytest.mark.parametrize("lag", [0.0, 0.01])
@pytest.mark.parametrize(
    "name", ["ch4/sh_2_class_b.yaml", "ch4/sh_add_2_bump.yaml", "ch4/sh_2_cdf_class_a.yaml"]
)
def test_the_controller_decides_the_same_on_both_engines(name, lag):
    """Its records (state, condition, threshold) and the damping (held, or lagged every step)
    agree, with and without an actuator lag."""
    cfg = suspopt.load_config(CONFIGS / name)
    cfg.control.actuator_lag = lag
    cfg.simulation.duration = min(cfg.simulation.duration, getattr(cfg.road, "start", 0.0) + 1.0)
    params = _designs(cfg)
    numpy_run, compiled_run = _run(cfg, "numpy", params), _run(cfg, "compiled", params)
    assert compiled_run.engine == "compiled"
    _agree(numpy_run, compiled_run)
    assert set(numpy_run.controller_records) == set(compiled_run.controller_records)
    for key, held in numpy_run.controller_records.items():
        x, y = held.full(), compiled_run.controller_records[key].full()
        np.testing.assert_allclose(y, x, rtol=1e-9, atol=1e-9 * np.abs(x).max(), err_msg=key)
    damping = [getattr(r.held_damping, "full", lambda r=r: r.held_damping)() for r in
               (numpy_run, compiled_run)]  # fmt: skip
    np.testing.assert_allclose(damping[1], damping[0], rtol=1e-12)


@pytest.mark.parametrize("lag", [0.0, 0.01])
def test_a_law_the_kernel_does_not_list_is_sampled_in_numpy_between_stretches(monkeypatch, lag):
    """Every sample in numpy, between compiled stretches of steps (what a law missing from
    ``_kernel.CONTROL_LAWS`` gets): the same run as on the numpy engine."""
    from suspopt.integrator import compiled

    cfg = suspopt.load_config(CONFIGS / "ch4" / "sh_add_2_bump.yaml")
    cfg.control.actuator_lag = lag
    cfg.simulation.duration = getattr(cfg.road, "start", 0.0) + 0.5
    params = _designs(cfg)
    numpy_run = _run(cfg, "numpy", params)
    monkeypatch.setattr(compiled, "_sample_rules", lambda controller: None)
    compiled_run = _run(cfg, "compiled", params)
    assert compiled_run.engine == "compiled"
    _agree_with_records(numpy_run, compiled_run)


@pytest.mark.parametrize(
    "name, lift_off",
    [
        ("ch5/case1_s1.yaml", False),
        ("ch5/case1_s1.yaml", True),
        ("ch8/nss4_class_a_passenger.yaml", False),
    ],
)
def test_a_design_gives_the_same_bits_in_any_batch(name, lift_off):
    """Alone, a design runs lane by lane (a block of one); in a batch, in lane loops: the
    same bits, over a bump with the tyres' cap law (lift-off) and over an ISO 8608 road with
    an exact NSS4 mechanism (the link law) with its passenger."""
    cfg = suspopt.load_config(CONFIGS / name)
    cfg.simulation.duration = 1.0
    cfg.simulation.engine = "compiled"
    if lift_off:
        cfg.vehicle.tyre_lift_off = True
        cfg.road.height = 0.15
    params = _designs(cfg, 21) or {"seat.damping": np.linspace(200.0, 2000.0, 21)}
    batch = simulate(cfg, params)
    assert batch.engine == "compiled"
    for p in (0, 7, 20):
        alone = simulate(cfg, {k: v[p : p + 1] for k, v in params.items()})
        assert np.isfinite(alone.states).all()
        np.testing.assert_array_equal(alone.states[:, 0], batch.states[:, p])
        np.testing.assert_array_equal(alone.accelerations[:, 0], batch.accelerations[:, p])


def _compiled_signatures() -> set[tuple[str, object]]:
    """(function, signature) of every specialisation the kernel's compiled functions hold in
    this process."""
    from suspopt.integrator import _accumulate, _kernel
    from suspopt.loops import _compiled as _reductions

    return {
        (f"{module.__name__}.{name}", sig)
        for module in (_kernel, _accumulate, _reductions)
        for name, f in vars(module).items()
        if hasattr(f, "py_func") and hasattr(f, "signatures")
        for sig in f.signatures
    }


@pytest.mark.parametrize("name", ["ch5/case1_s1.yaml", "ch7/sh_add_2.yaml"])
def test_a_batch_of_one_design_takes_the_specialisations_of_a_batch_of_two(name):
    """A batch of one design (an optimisation's baseline, a gradient step, the last batch of
    a split population, ``simulate`` of a config) runs the compiled functions a batch of two
    compiled, and compiles none of its own: on a fresh machine another specialisation of
    the kernel costs about a minute. (It did: one design's coefficients were a read-only
    view, another type to numba.) Streamed (``Problem.evaluate``, the kernel's own
    reductions) and recorded (``simulate`` with a controller)."""
    cfg = suspopt.load_config(CONFIGS / name)
    cfg.simulation.engine = "compiled"
    cfg.simulation.duration = 0.1
    if cfg.road.kind.startswith("bump"):
        cfg.road.start = 0.01
    problem = suspopt.Problem.from_config(cfg)
    X = problem.to_search(np.array([_designs(cfg, 2)[v.path] for v in problem.variables]).T)
    for two, one in ((X, X[:1]), (X, X[1:])):
        problem.evaluate(two, return_values_of=["F"])
        simulate(cfg, problem.params(two))
        before = _compiled_signatures()
        problem.evaluate(one, return_values_of=["F"])
        simulate(cfg, problem.params(one))
        assert _compiled_signatures() == before


def test_a_diverging_design_stops_at_the_same_instant_on_both_engines():
    cfg = suspopt.load_config(CONFIGS / "quickstart.yaml")
    cfg.simulation.duration, cfg.simulation.dt = 1.0, 5.0e-3  # RK4 unstable on the tyre hop
    params = {"vehicle.corners.F1.tyre.stiffness": np.array([4.0e5, 4.0e7])}
    numpy_run, compiled_run = _run(cfg, "numpy", params), _run(cfg, "compiled", params)
    assert np.isnan(numpy_run.diverged_at[0]) and np.isfinite(numpy_run.diverged_at[1])
    _agree(numpy_run, compiled_run)


def test_the_compiled_engine_without_numba_is_bad_input(monkeypatch, tmp_path):
    from suspopt import _numba_cache

    monkeypatch.setattr(_numba_cache, "compiled_available", lambda: False)
    text = (
        (CONFIGS / "quickstart.yaml")
        .read_text()
        .replace(
            "simulation: {duration: 3.0, dt: 1.0e-3}",
            "simulation: {duration: 3.0, dt: 1.0e-3, engine: compiled}",
        )
    )
    path = tmp_path / "fast.yaml"
    path.write_text(text)
    with pytest.raises(ConfigError, match=r"simulation.engine.*pip install numba"):
        suspopt.load_config(path)
    path.write_text(text.replace("engine: compiled", "engine: auto"))
    assert suspopt.load_config(path).simulation.engine == "auto"


def test_auto_without_numba_runs_numpy_and_says_so_once(monkeypatch):
    """On a platform without numba's wheels ``engine: auto`` runs on numpy, and says which
    engine and why once per process: to a listener (the command line's note on stderr),
    else as a UserWarning."""
    import warnings

    import suspopt.integrator as integrator
    from suspopt import _notices

    monkeypatch.setattr(integrator, "compiled_available", lambda: False)
    monkeypatch.setattr(integrator, "_fallback_told", [])
    # (none of the command's listeners that an earlier in-process command left registered)
    monkeypatch.setattr(_notices, "_listeners", [])
    told = []

    def listener(kind, **data):
        told.append((kind, data))

    _notices.listen(listener)
    try:
        cfg = suspopt.load_template("half_pitch")
        results = [suspopt.simulate(cfg, params=_designs(cfg, 3)) for _ in range(2)]
    finally:
        _notices.unlisten(listener)
    assert [r.engine for r in results] == ["numpy", "numpy"]
    assert [kind for kind, _ in told] == ["engine-fallback"]
    assert "numba cannot be imported" in told[0][1]["message"]
    monkeypatch.setattr(integrator, "_fallback_told", [])
    with pytest.warns(UserWarning, match="runs on the numpy engine"):
        assert integrator.auto_engine(100, 1, evaluation=True) == "numpy"
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert integrator.auto_engine(100, 1, evaluation=True) == "numpy"  # (once)


def test_the_rule_of_auto():
    """``auto``: compiled for evaluations and optimisation configs, else from
    ``AUTO_STEPS`` steps, fewer for a batch (docs/guide/engines.md#the-rule-of-auto)."""
    from suspopt.integrator import AUTO_DESIGNS, AUTO_STEPS, auto_engine
    from suspopt.simulation import with_engine

    assert auto_engine(10, 1, evaluation=True) == "compiled"
    assert auto_engine(AUTO_STEPS - 100, 1, evaluation=False) == "numpy"
    assert auto_engine(AUTO_STEPS, 0, evaluation=False) == "compiled"
    assert auto_engine(AUTO_STEPS // 2, AUTO_DESIGNS, evaluation=False) == "compiled"
    quick = suspopt.load_config(CONFIGS / "quickstart.yaml")  # 3,000 steps, no optimiser
    assert quick.simulation.engine == "auto"  # (the default)
    assert with_engine(quick, 1).simulation.engine == "numpy"
    assert with_engine(quick, 10 * AUTO_DESIGNS).simulation.engine == "compiled"
    assert with_engine(quick, 1, evaluation=True).simulation.engine == "compiled"
    study = suspopt.load_template("kesort")  # an optimisation: compiled whatever its batch
    assert with_engine(study, 1).simulation.engine == "compiled"
    assert study.simulation.engine == "auto"  # (a copy: the config is left as it was)
    assert with_engine(quick, 1)._text == quick._text
    fixed = quick.model_copy(
        update={"simulation": quick.simulation.model_copy(update={"engine": "numpy"})}
    )
    assert with_engine(fixed, 10**6) is fixed


def _agree_with_records(numpy_run, compiled_run) -> None:
    """:func:`_agree`, and every controller record within 1e-9 of the numpy engine's."""
    _agree(numpy_run, compiled_run)
    for key, held in numpy_run.controller_records.items():
        x, y = held.full(), compiled_run.controller_records[key].full()
        scale = np.nanmax(np.abs(x)) if np.isfinite(x).any() else 1.0
        np.testing.assert_allclose(y, x, rtol=1e-9, atol=1e-9 * scale, err_msg=key)


def _two_laws(name: str, duration: float, laws, c_min: float) -> dict:
    """configs/ch7/``name`` as data, run for ``duration`` [s] with no optimisation, its
    corners F1 and R1 on ``laws`` (None: a passive 2500 N s/m damper), C_min ``c_min`` and
    C_max 3500 N s/m, each law's parameters at their defaults."""
    data = yaml.safe_load((CONFIGS / "ch7" / name).read_text())
    data["simulation"]["duration"] = duration
    data.pop("design_variables"), data.pop("objectives"), data.pop("constraints", None)
    data["vehicle"]["corner_defaults"].pop("damper")
    for corner, law in zip(("F1", "R1"), laws):
        damper = {"kind": "semi_active", "c_min": c_min, "c_max": 3500, "law": law}
        damper.update(
            {name: PARAMETERS[name].default for name in LAWS[law].parameters} if law else {}
        )
        passive = {"kind": "passive", "c": 2500}
        data["vehicle"]["corners"][corner] = {"damper": damper if law else passive}
    return data


@pytest.mark.parametrize(
    "laws, threshold",
    [
        (("sh_l", "hybrid"), 1e-4),  # the continuous laws, a fixed threshold [m^2/s^2]
        (("add", "sh_add_1"), None),  # the laws that read the body's acceleration
        (("groundhook", "sh_add_2"), None),
        (("sh_2", None), 0.0),  # a passive rear corner
    ],
)
def test_the_kernel_takes_every_laws_samples_as_the_controller_does(laws, threshold):
    """The compiled engine takes a fixed-threshold controller's samples inside the kernel, with
    the laws' own rules: mixed laws, their parameters per design, a passive corner, a design
    whose C_min = C_max (the records then say when the law asked for the stiff state), with
    and without the actuator's lag; states to 1e-12 and records to 1e-9 of the numpy engine."""
    data = _two_laws("sh_2.yaml", 0.8, laws, 1500)
    if threshold is not None:
        data["control"]["threshold"] = {"mode": "fixed", "value": threshold}
    base = make_config(data)
    params = {"control.actuator_lag": np.array([0.0, 0.0, 0.01])}
    params["vehicle.corners.F1.damper.c_min"] = np.array([1500.0, 3500.0, 1000.0])
    for corner, law in zip(("F1", "R1"), laws):
        for name in LAWS[law].parameters if law else ():
            path = f"vehicle.corners.{corner}.damper.{name}"
            params[path] = {"linear_weight": [0.0, 0.4, 1.0], "skyhook_weight": [0.0, 0.6, 1.0],
                            "crossover_frequency": [20.0, 39.0, 60.0]}[name]  # fmt: skip
    numpy_run, compiled_run = _run(base, "numpy", params), _run(base, "compiled", params)
    assert compiled_run.engine == "compiled"
    from suspopt.integrator import compiled

    pv, model, controller, attachments = prepare(base, params)
    assert compiled._sample_rules(controller) is not None  # (the kernel took the samples)
    _agree_with_records(numpy_run, compiled_run)
    state = compiled_run.signals["damper_state.F1"]
    assert np.isin(state[1], (0.0, 1.0)).all() and (state[1] == 1.0).any()  # C_min = C_max


@pytest.mark.parametrize(
    "distribution, laws, lag",
    [
        ("student_t", ("sh_2", "sh_add_2"), 0.0),
        ("normal", ("sh_l", None), 0.01),
        ("empirical", ("add", "groundhook"), 0.0),
    ],
)
def test_an_adaptive_threshold_refits_between_the_kernels_samples(
    monkeypatch, distribution, laws, lag
):
    """With an adaptive CDF threshold the kernel takes every sample but the refits (each
    design's own instants: learn times of 0.2, 0.25 and 0.33 s, refitted every 0.4, 0.5 and
    0.66 s), which the controller takes from the history of the kernel's conditions: the
    records and the states agree with the numpy engine (1e-9, 1e-12), and the controller is
    asked at the refits only."""
    from suspopt.controller import SemiActiveController

    data = _two_laws("sh_add_2_cdf.yaml", 1.5, laws, 1000)
    data["control"]["actuator_lag"] = lag
    data["control"]["threshold"].update({"distribution": distribution, "refit_factor": 2.0})
    base = make_config(data)
    params = {"control.threshold.learn_time": np.array([0.2, 0.25, 0.33])}
    numpy_run = _run(base, "numpy", params)
    asked = []
    sample = SemiActiveController.sample
    monkeypatch.setattr(
        SemiActiveController, "sample", lambda c, k, t, s: asked.append(k) or sample(c, k, t, s)
    )
    compiled_run = _run(base, "compiled", params)
    assert compiled_run.engine == "compiled"
    every = round(base.control.sample_time / base.simulation.dt)
    instants = [learn * (1 + 2 * i) for learn in (0.2, 0.25, 0.33) for i in range(4)]
    steps = np.ceil((np.array(instants) / base.simulation.dt - 0.5) / every - 1e-9) * every
    refits = sorted({int(k) for k in steps if k <= base.simulation.n_steps})  # (at or after)
    assert asked == refits
    _agree_with_records(numpy_run, compiled_run)
    threshold = compiled_run.signals["control_threshold.F1"]
    assert len({tuple(row) for row in np.unique(threshold, axis=1).T}) > 3  # it was refitted


def test_a_refit_at_the_first_sample_keeps_the_starts_impulse_single():
    """A threshold refitted at step 0 (learn time under half a step) on a road that steps at
    t = 0 through a damped tyre: the kernel is asked for no step before the controller's
    sample, and the start's velocity jump is applied once, as on the numpy engine."""
    data = yaml.safe_load((CONFIGS / "ch4" / "sh_add_2_bump.yaml").read_text())
    data["road"]["start"] = 0.0
    data["simulation"]["duration"] = 0.3
    data["vehicle"]["corners"]["F1"]["tyre"]["damping"] = 300.0
    data["control"]["threshold"] = {"mode": "adaptive", "c_max_share": 0.27,
                                    "learn_time": 1e-4, "distribution": "empirical"}  # fmt: skip
    for key in ("design_variables", "objectives", "constraints"):
        data.pop(key, None)
    base = make_config(data)
    numpy_run, compiled_run = _run(base, "numpy", {}), _run(base, "compiled", {})
    assert compiled_run.engine == "compiled"
    _agree(numpy_run, compiled_run)


def test_every_row_of_a_packed_map_has_an_entry():
    """The kernel starts a row's sum at its first entry: a row without one gets a zero entry,
    in row order, the others kept as they were."""
    from suspopt.integrator.compiled import _every_row

    rows, cols = np.array([0, 0, 2]), np.array([1, 3, 0])
    vals = np.arange(6.0).reshape(3, 2)
    r, c, v = _every_row((rows, cols, vals), 4)
    assert r.tolist() == [0, 0, 1, 2, 3] and c.tolist() == [1, 3, 0, 0, 0]
    np.testing.assert_array_equal(v, [[0, 1], [2, 3], [0, 0], [4, 5], [0, 0]])
    assert _every_row((rows, cols, vals), 3)[0].tolist() == [0, 0, 1, 2]
    full = (np.array([0, 1]), np.array([0, 0]), np.ones((2, 2)))
    assert _every_row(full, 2)[0] is full[0]  # (nothing missing: the entries as they are)


def _walked(monkeypatch) -> None:
    """Every run from here on walks the network (no fused step, :mod:`._fused`)."""
    from suspopt.integrator import _fused

    monkeypatch.setattr(_fused, "MIN_DESIGNS", 10**9)


@pytest.mark.parametrize(
    "name, lift_off",
    [
        ("ch5/case1_s1.yaml", True),
        ("ch3/part2a_fc_arb_bump.yaml", False),
        ("ch8/nss4_class_a_passenger.yaml", False),
        ("ch8/nss1_class_a.yaml", False),
    ],
)
def test_the_fused_step_gives_the_bits_of_the_walked_network(monkeypatch, name, lift_off):
    """A run of enough designs takes the network's fused functions; the same designs give the
    same bits when the kernel walks the network: Duffing springs and tyres that lift off over
    a bump (split steps and their impulses), a full car with anti-roll bars, the exact NSS4
    mechanism with its passenger and NSS1 over an ISO 8608 road."""
    from suspopt.integrator import _fused

    cfg = suspopt.load_config(CONFIGS / name)
    cfg.simulation.duration = min(cfg.simulation.duration, getattr(cfg.road, "start", 0.0) + 1.0)
    cfg.simulation.engine = "compiled"
    if lift_off:
        cfg.vehicle.tyre_lift_off = True
        cfg.road.height = 0.15
    P = _fused.MIN_DESIGNS + 3  # (a padded last block)
    path = "seat.damping" if cfg.seat is not None else "vehicle.anti_roll_bars.front"
    params = _designs(cfg, P) or {path: np.linspace(200.0, 2000.0, P)}
    made = []
    monkeypatch.setattr(_fused, "steps", lambda *a, f=_fused.steps: made.append(1) or f(*a))
    fused = simulate(cfg, params)
    assert made and fused.engine == "compiled" and np.isfinite(fused.states).all()
    _walked(monkeypatch)
    walked = simulate(cfg, params)
    assert len(made) == 1
    assert fused.states.tobytes() == walked.states.tobytes()
    assert fused.accelerations.tobytes() == walked.accelerations.tobytes()


def test_an_evaluation_on_the_fused_step_gives_the_walked_networks_objectives(monkeypatch):
    """``Problem.evaluate`` (streamed, only the DOFs its signals reach integrated) gives the
    same objectives and constraints, bit for bit, on either path."""
    cfg = suspopt.load_config(CONFIGS / "ch5" / "case4_s1.yaml")
    cfg.simulation.engine = "compiled"
    problem = suspopt.Problem.from_config(cfg)
    X = np.random.default_rng(5).uniform(problem.xl, problem.xu, (80, problem.n_var))
    F, G = problem.evaluate(X, return_values_of=["F", "G"])
    _walked(monkeypatch)
    F0, G0 = problem.evaluate(X, return_values_of=["F", "G"])
    assert F.tobytes() == F0.tobytes() and G.tobytes() == G0.tobytes()


def test_the_fused_modules_cache_folder_expands_a_home_that_no_shell_expanded(monkeypatch):
    """``SUSPOPT_CACHE_DIR=~/cache`` from an environment file (no shell to expand ``~``)
    made a folder named ``~`` in the working folder."""
    from suspopt.integrator import _fused

    monkeypatch.setenv("SUSPOPT_CACHE_DIR", "~/suspopt-cache")
    assert _fused.cache_dir() == Path.home() / "suspopt-cache" / "fused"


def test_the_fused_modules_cache_is_rewritten_when_changed_and_skipped_when_unwritable(
    monkeypatch, tmp_path
):
    """The generated module is kept whole under its hash; a file changed since (or damaged:
    not UTF-8) is written again (what runs is the text generated in the process, never the
    file), and where the
    cache cannot be written the kernel walks the network (``steps`` is None)."""
    from suspopt.integrator import _fused

    cfg = suspopt.load_config(CONFIGS / "ch5" / "case4_s1.yaml")
    pv, model, controller, attachments = prepare(cfg, _designs(cfg, 2))
    from suspopt.integrator.compiled import _packed
    from suspopt.network import Assembled
    from suspopt.simulation import full_network

    _, idx, lay = _packed(Assembled(full_network(model, attachments), pv.P), 1e-3, _fused.LANES)
    monkeypatch.setenv("SUSPOPT_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(_fused, "_LOADED", {})
    first, regular = _fused.steps(idx, lay)
    (path,) = (tmp_path / "fused").glob("fused_*.py")
    assert path.read_text() == _fused.source(idx, lay)
    path.write_text("raise SystemExit('not run')\n")
    monkeypatch.setattr(_fused, "_LOADED", {})
    assert _fused.steps(idx, lay) is not None
    assert path.read_text() == _fused.source(idx, lay)
    path.write_bytes(b"\xff\xfe not UTF-8")  # (damaged: a UnicodeDecodeError before)
    monkeypatch.setattr(_fused, "_LOADED", {})
    assert _fused.steps(idx, lay) is not None
    assert path.read_text() == _fused.source(idx, lay)
    blocked = tmp_path / "a file"
    blocked.write_text("")
    monkeypatch.setenv("SUSPOPT_CACHE_DIR", str(blocked))
    monkeypatch.setattr(_fused, "_LOADED", {})
    assert _fused.steps(idx, lay) is None
