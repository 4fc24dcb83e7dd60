"""Semi-active dampers: laws, digital controller, CDF threshold (Sec 2.1.6, Ch. 4)."""

from __future__ import annotations

import copy
import subprocess
import sys
from types import SimpleNamespace

import h5py
import numpy as np
import pytest
import scipy.optimize
import scipy.special
import scipy.stats
from conftest import CONFIGS, corner, make_config
from typer.testing import CliRunner

import suspopt
from suspopt.cli import app
from suspopt.config import ConfigError
from suspopt.control import (
    LAWS,
    StudentTSummary,
    distribution_quantile,
    fit_student_t,
    law_condition,
    t_quantile,
    threshold_for_share,
)
from suspopt.control.stats import _trigamma_step

TABLE_4_1 = {
    "unsprung_mass": 25.0,
    "tyre": {"stiffness": 2.0e5, "damping": 0.0},
    "spring": {"linear": 28100.0},
}
LAW_PARAMETERS = {
    "sh_l": {"linear_weight": 0.6},
    "sh_add_1": {"crossover_frequency": 39.0},
    "sh_add_2": {"crossover_frequency": 39.0},
    "hybrid": {"skyhook_weight": 0.5},
}


def semi_active(law="sh_2", c_min=1734.0, c_max=4873.0, **extra) -> dict:
    return {
        "kind": "semi_active",
        "c_min": c_min,
        "c_max": c_max,
        "law": law,
        **LAW_PARAMETERS.get(law, {}),
        **extra,
    }


def quarter_car(
    damper: dict, duration=3.0, dt=1e-3, road_class="C", control=None, output_dt=None
) -> dict:
    """Table 4.1 quarter car on an ISO 8608 road (thesis convention) at 50 km/h."""
    data = {
        "vehicle": {
            "preset": "quarter",
            "body": {"mass": 260.0},
            "corners": {"F1": {**TABLE_4_1, "damper": damper}},
        },
        "road": {
            "kind": "iso8608",
            "road_class": road_class,
            "convention": "thesis",
            "speed": 13.889,
            "seed": 1,
        },
        "simulation": {"duration": duration, "dt": dt, "output_dt": output_dt},
    }
    if control is not None:
        data["control"] = control
    return data


def full_car(dampers: dict[str, dict], duration=2.0, output_dt=None, control=None) -> dict:
    """Table 3.1 full car on independent class B tracks (heave, roll and pitch excited)."""
    data = {
        "vehicle": {
            "preset": "full",
            "body": {
                "mass": 1085.0,
                "roll_inertia": 820.0,
                "pitch_inertia": 1100.0,
                "a_front": 1.4,
                "a_rear": 1.47,
                "b_right": 0.7,
                "b_left": 0.75,
            },
            "corners": {c: {**corner(), "damper": dampers[c]} for c in ("F1", "F2", "R1", "R2")},
        },
        "road": {
            "kind": "iso8608",
            "road_class": "B",
            "convention": "thesis",
            "speed": 24.0,
            "seed": 3,
            "tracks": "independent",
        },
        "simulation": {"duration": duration, "dt": 1e-3, "output_dt": output_dt},
    }
    if control is not None:
        data["control"] = control
    return data


def assert_same_signals(a, b):
    for name in a.signals:
        assert np.array_equal(a.signals[name], b.signals[name], equal_nan=True), name


# --- equivalences the thesis states --------------------------------------------------------


@pytest.mark.parametrize("law", ["sh_2", "sh_add_2", "hybrid"])
def test_equal_limits_are_the_passive_damper_bit_for_bit(law):
    """SH-2 (any law) with C_min = C_max = c is the passive damper c, every signal."""
    passive = suspopt.simulate(
        make_config(full_car({c: {"c": 800.0} for c in ("F1", "F2", "R1", "R2")}))
    )
    controlled = suspopt.simulate(
        make_config(full_car({c: semi_active(law, 800.0, 800.0) for c in ("F1", "F2", "R1", "R2")}))
    )
    assert_same_signals(passive, controlled)
    assert "damper_state.F1" in controlled.signals and "damper_state.F1" not in passive.signals


def test_sh_l_with_weight_one_is_sh_2():
    """Eq 2.35: alpha = 1 gives the two-state skyhook."""
    sh2 = suspopt.simulate(make_config(quarter_car(semi_active("sh_2"))))
    shl = suspopt.simulate(make_config(quarter_car(semi_active("sh_l", linear_weight=1.0))))
    assert_same_signals(sh2, shl)
    assert len(np.unique(sh2.signals["damping.F1"])) == 2


@pytest.mark.parametrize("law", list(LAWS))
def test_fixed_threshold_zero_is_the_base_law(law):
    """Eq 4.3-4.4: T = 0 gives back the base law; so does an adaptive threshold never fitted."""
    base = suspopt.simulate(make_config(quarter_car(semi_active(law), duration=1.5)))
    fixed = suspopt.simulate(
        make_config(
            quarter_car(
                semi_active(law),
                duration=1.5,
                control={"threshold": {"mode": "fixed", "value": 0.0}},
            )
        )
    )
    assert_same_signals(base, fixed)
    unfitted = suspopt.simulate(
        make_config(
            quarter_car(
                semi_active(law),
                duration=1.5,
                control={"threshold": {"mode": "adaptive", "c_max_share": 0.3, "learn_time": 10.0}},
            )
        )
    )
    assert_same_signals(base, unfitted)


def test_hybrid_with_all_skyhook_is_continuous_skyhook():
    """Hybrid with beta = 1 is SH-L with alpha = 0 (both C_max ż_s / ṠT, clipped)."""
    hybrid = suspopt.simulate(make_config(quarter_car(semi_active("hybrid", skyhook_weight=1.0))))
    shl = suspopt.simulate(make_config(quarter_car(semi_active("sh_l", linear_weight=0.0))))
    np.testing.assert_allclose(hybrid.signals["damping.F1"], shl.signals["damping.F1"], rtol=1e-9)
    state = hybrid.signals["damper_state.F1"]
    assert np.any((state > 0) & (state < 1)), "a continuous law takes values inside the range"


# --- the digital controller ----------------------------------------------------------------


def test_coefficient_changes_only_at_sample_instants():
    """Zero-order hold: damping.c (kept every step; sample k holds the coefficient in force
    over step k) changes only at sample instants, k % (ΔT/dt) == 0."""
    res = suspopt.simulate(
        make_config(quarter_car(semi_active("sh_2"), duration=2.0, control={"sample_time": 0.005}))
    )
    c = res.signals["damping.F1"][0]
    changed = np.flatnonzero(np.diff(c) != 0) + 1
    assert changed.size > 20
    assert np.all(changed % 5 == 0)
    assert set(np.unique(c)) == {1734.0, 4873.0}


def test_actuator_lag_is_the_exact_first_order_response():
    tau, dt = 0.01, 1e-3
    res = suspopt.simulate(
        make_config(
            quarter_car(
                semi_active("sh_2"),
                duration=1.0,
                control={"sample_time": 0.004, "actuator_lag": tau},
            )
        )
    )
    c = res.signals["damping.F1"][0]
    command = 1734.0 + res.signals["damper_state.F1"][0] * (4873.0 - 1734.0)
    expected = command[1:] - (command[1:] - c[:-1]) * np.exp(-dt / tau)
    np.testing.assert_allclose(c[1:], expected, rtol=1e-12)
    assert np.all((c >= 1734.0) & (c <= 4873.0)) and len(np.unique(c)) > 100


def test_sample_time_must_be_a_whole_multiple_of_dt():
    cfg = make_config(quarter_car(semi_active(), dt=3e-3))  # default ΔT = 4 ms
    with pytest.raises(ConfigError, match="control.sample_time.*whole multiple of simulation.dt"):
        suspopt.simulate(cfg)
    with pytest.raises(ConfigError, match="sample_time cannot vary"):
        suspopt.simulate(
            make_config(quarter_car(semi_active(), control={})),
            params={"control.sample_time": [0.004, 0.008]},
        )


def test_each_corner_uses_its_own_velocities_with_roll_and_pitch():
    """FC with a different law per corner (and one passive): each condition is its law's
    product of the corner's travel rate, body motion at the corner (heave + y roll - x pitch)
    and wheel velocity at the sample instant (output_dt = ΔT). ADD's acceleration is the one
    measured before the new coefficients act, the signal's the one after: they agree where no
    coefficient changed at that instant."""
    dampers = {
        "F1": semi_active("sh_2", 400.0, 1200.0),
        "F2": semi_active("add", 400.0, 1200.0),
        "R1": semi_active("groundhook", 400.0, 1200.0),
        "R2": {"c": 800.0},
    }
    res = suspopt.simulate(make_config(full_car(dampers, output_dt=0.004)))
    s = res.signals
    x = {"F1": 1.4, "F2": 1.4, "R1": -1.47, "R2": -1.47}
    y = {"F1": 0.7, "F2": -0.75, "R1": 0.7, "R2": -0.75}

    def body(c, deriv):
        return (
            s[f"body.heave_{deriv}"]
            + y[c] * s[f"body.roll_{deriv}"]
            - x[c] * s[f"body.pitch_{deriv}"]
        )

    expected = {
        "F1": s["travel_vel.F1"] * body("F1", "vel"),
        "F2": s["travel_vel.F2"] * body("F2", "acc"),
        "R1": -s["travel_vel.R1"] * s["wheel.R1.heave_vel"],
    }
    damping = np.stack([s[f"damping.{c}"] for c in ("F1", "F2", "R1")])
    steady = np.r_[True, (np.diff(damping, axis=-1) == 0).all(axis=0)[0]]
    assert 20 < steady.sum() < steady.size - 20
    for c, value in expected.items():
        condition = s[f"control_condition.{c}"]
        where = steady if c == "F2" else slice(None)
        np.testing.assert_allclose(
            condition[:, where], value[:, where], rtol=1e-9, atol=1e-12 * np.abs(value).max()
        )
        on = condition > 0
        assert np.array_equal(s[f"damper_state.{c}"], on.astype(float))
    assert np.isnan(s["control_condition.R2"]).all() and np.isnan(s["damper_state.R2"]).all()
    assert np.all(s["damping.R2"] == 800.0)
    assert res.signal_unit("control_condition.F1") == "F1: m^2/s^2; F2: m^2/s^3; R1: m^2/s^2"
    assert res.signal_unit("damper_state.F1") == "1"


@pytest.mark.slow
def test_groundhook_holds_the_road_and_skyhook_the_body():
    """Sign check of the laws: on the Ch. 3 car (Table 3.1, c 400-1200 N s/m) groundhook gives
    the smaller tyre deflection and SH-2 the smaller weighted body acceleration."""
    cfg = suspopt.load_config(CONFIGS / "ch3" / "part1b_qc_class_b.yaml")
    cfg.simulation.duration = 10.0
    out = {}
    for law in ("sh_2", "groundhook"):
        cfg.vehicle.corners["F1"].damper.law = law
        res = suspopt.simulate(cfg)
        out[law] = (res.metrics["RC"][0], np.std(res.signals["tyre_deflection.F1"]))
    assert out["sh_2"][0] < 0.9 * out["groundhook"][0]
    assert out["groundhook"][1] < 0.9 * out["sh_2"][1]


def test_semi_active_corner_enters_the_linear_model_at_c_min():
    cfg = make_config(quarter_car(semi_active("sh_2")))
    model = suspopt.build_vehicle(cfg)
    assert model.damper[0, 0, 0] == 1734.0
    assert suspopt.modal_analysis(model).frequency.shape == (1, 2)


def test_corner_defaults_and_semi_active_override():
    data = full_car({c: {} for c in ("F1", "F2", "R1", "R2")})
    data["vehicle"]["corner_defaults"] = {**corner(), "damper": {"c": 800.0}}
    data["vehicle"]["corners"] = {"F1": {"damper": semi_active("sh_2", 400.0, 1200.0)}}
    cfg = make_config(data)
    assert cfg.vehicle.corners["F1"].damper.kind == "semi_active"
    assert cfg.vehicle.corners["R1"].damper.c == 800.0


# --- CDF threshold -------------------------------------------------------------------------


def _t_maximum_likelihood(x: np.ndarray) -> tuple[float, float, float]:
    """Reference (ν, μ, s) by Nelder-Mead on the t log-likelihood (scipy.stats.t.fit stops
    early on some of these samples)."""

    def nll(p):
        return -scipy.stats.t.logpdf(x, np.exp(p[0]), p[1], np.exp(p[2])).sum()

    start = [np.log(5.0), np.median(x), np.log(np.std(x))]
    opt = scipy.optimize.minimize(
        nll, start, method="Nelder-Mead", options={"xatol": 1e-10, "fatol": 1e-10, "maxiter": 20000}
    )
    return float(np.exp(opt.x[0])), float(opt.x[1]), float(np.exp(opt.x[2]))


@pytest.mark.slow
def test_student_t_fit_is_the_maximum_likelihood_fit():
    """The vectorised Newton fit against a direct maximisation, one column at a time, also for
    near-normal data (ν = 30), where the likelihood is flat in ν."""
    rng = np.random.default_rng(4)
    df, loc, scale = (
        np.array([1.0, 2.5, 5.0, 30.0]),
        np.array([0.5, 1.0, -3.0, 0.0]),
        np.array([1e-4, 2.0, 0.5, 1e-3]),
    )
    x = loc + scale * rng.standard_t(df, size=(4000, 4))
    mu, s, nu = fit_student_t(x, axis=0)
    ours = np.stack([distribution_quantile(x, level, "student_t") for level in (0.27, 0.73)])
    for j in range(4):
        ref_nu, ref_mu, ref_s = _t_maximum_likelihood(x[:, j])
        assert abs(mu[j] - ref_mu) < 1e-3 * ref_s
        assert abs(s[j] / ref_s - 1) < 1e-3
        assert abs(nu[j] / ref_nu - 1) < (1e-3 if ref_nu < 10 else 0.02)
        reference = scipy.stats.t.ppf([0.27, 0.73], ref_nu, ref_mu, ref_s)
        np.testing.assert_allclose(ours[:, j], reference, atol=1e-3 * ref_s)


def test_trigamma_step_matches_scipy():
    """The t fit's ψ'(a + 1/2) - ψ'(a) against scipy's polygamma over the range of ν/2 the
    fit allows (ν from 0.3 to 1000)."""
    a = np.geomspace(0.15, 500.0, 5001)
    reference = scipy.special.polygamma(1, a + 0.5) - scipy.special.polygamma(1, a)
    np.testing.assert_allclose(_trigamma_step(a), reference, rtol=1e-11, atol=0)


def _summary_errors(x: np.ndarray, block: int) -> np.ndarray:
    """Feed the history ``x`` (samples, columns) to a :class:`StudentTSummary` ``block`` rows
    at a time, as the controller's refits do; at each refit, the distance of its quantiles at
    0.27 and 0.73 (the thresholds of a 27 % C_max share) from the exact full-history fit's, in
    units of the exact fit's scale (absolute where that is 0): (refits, 2, columns)."""
    summary, errors = StudentTSummary(x.shape[1]), []
    for n in range(block, x.shape[0] + 1, block):
        bounded, exact = summary.fit(x[:n]), fit_student_t(x[:n])
        errors.append(
            [
                np.abs(t_quantile(bounded, level) - t_quantile(exact, level))
                / np.where(exact[1] > 0, exact[1], 1.0)
                for level in (0.27, 0.73)
            ]
        )
    return np.array(errors)


def test_summary_fit_follows_the_exact_fit_on_t_samples():
    """The bounded refit against the exact maximum-likelihood fit of the whole history, at
    every refit of a growing history of t samples with known parameters (ν from 1 to 30,
    scales from 1e-4 to 2): the quantiles agree within 1e-3 of the scale (measured: 1.3e-4),
    while the exact fit itself lies within its sampling error of the true quantiles."""
    rng = np.random.default_rng(7)
    df, loc, scale = (
        np.array([1.0, 1.5, 2.5, 5.0, 30.0]),
        np.array([0.0, 1e-4, 1.0, -3.0, 0.0]),
        np.array([1e-4, 3e-4, 2.0, 0.5, 1e-3]),
    )
    x = loc + scale * rng.standard_t(df, size=(8000, 5))
    assert np.max(_summary_errors(x, 250)) < 1e-3
    true = scipy.stats.t.ppf(0.73, df, loc, scale)
    exact = t_quantile(fit_student_t(x), 0.73)
    assert np.all(np.abs(exact - true) < 0.05 * scale)


def test_summary_fit_follows_changes_of_the_history():
    """The summary keeps to the exact fit when the road turns rougher (conditions 100 times
    larger after the first fit: the fit leaves the summary's coordinate and it rebins; or
    1e4 times larger half way: the heavy-tail bins absorb it), bins a column that was
    constant (at rest) once it varies, and gives NaN from the first non-finite sample on,
    leaving the other columns alone. While the rest is more than a quarter of the samples,
    the likelihood also has a maximum collapsed onto the atom at 0 (``s -> 0``), and fits land
    on it or not by their start: compared from there on."""
    rng = np.random.default_rng(8)
    x = 1e-3 * rng.standard_t(2.0, size=(6000, 5))
    x[250:, 0] *= 100.0  # rougher road after the first fit
    x[3000:, 1] *= 1e4  # far rougher half way
    x[4000, 4] = np.nan  # a diverged design
    x[:500, 2] = 0.0  # at rest before the road starts
    errors = _summary_errors(x[:, :4], 250)
    assert np.max(errors[:, :, [0, 1, 3]]) < 1e-3
    assert np.max(errors[7:, :, 2]) < 1e-3  # from 2000 rows, the rest a quarter
    summary = StudentTSummary(5)
    loc, scale, _ = summary.fit(x[:250])
    assert loc[2] == 0.0 and scale[2] == 0.0  # constant so far, like the exact fit
    for n in (3750, 4000, 4001, 4250):
        loc, scale, df = summary.fit(x[:n])
        assert np.isfinite(loc[:4]).all() and np.isnan(loc[4]) == (n > 4000)
    assert np.isnan(scale[4]) and np.isnan(df[4])


def test_quantiles_are_vectorised_over_columns():
    rng = np.random.default_rng(5)
    x = rng.normal(size=(501, 2, 3)) * np.array([1.0, 2.0, 3.0])
    level = np.array([[0.1, 0.5, 0.73], [0.27, 0.9, 0.5]])
    emp = distribution_quantile(x, level, "empirical")
    norm = distribution_quantile(x, level, "normal")
    for i in range(2):
        for j in range(3):
            assert emp[i, j] == pytest.approx(np.quantile(x[:, i, j], level[i, j]), rel=1e-12)
            assert norm[i, j] == pytest.approx(
                np.mean(x[:, i, j]) + np.std(x[:, i, j]) * scipy.stats.norm.ppf(level[i, j]),
                rel=1e-12,
            )


@pytest.mark.parametrize("level", [0.0, 0.27, 0.5, 0.73, 1.0])
def test_the_empirical_quantile_is_the_sorted_samples_linear_interpolation(level):
    """One level for every column (selected, not sorted) or one per column: the 'linear'
    quantile of the sorted samples, NaN sorted last, on columns with ties, signed zeros,
    infinities, NaN and a single sample, bit for bit."""
    rng = np.random.default_rng(12)
    x = np.round(rng.normal(size=(37, 60)) * 2.0)  # ties and -0.0
    x[rng.random(x.shape) < 0.15] = np.nan
    x[rng.random(x.shape) < 0.05] = np.inf
    x[rng.random(x.shape) < 0.05] = -np.inf
    x[:, 0] = np.nan
    x[:30, 1] = np.nan

    def by_sorting(column, q):
        s = np.sort(column)  # NaN last
        position = q * (s.size - 1)
        lo = int(np.floor(position))
        a, b = s[lo], s[min(lo + 1, s.size - 1)]
        return a + (b - a) * (position - lo)

    per_column = np.linspace(0.0, 1.0, x.shape[1])
    with np.errstate(invalid="ignore"):
        for samples in (x, x[:1]):
            for levels in (np.full(x.shape[1], level), per_column):
                got = distribution_quantile(samples, levels, "empirical")
                want = [by_sorting(samples[:, j], levels[j]) for j in range(x.shape[1])]
                np.testing.assert_array_equal(got, want)
                assert np.array_equal(np.signbit(got), np.signbit(want))


def test_threshold_leaves_the_share_on_the_stiff_side():
    """SH-2 stiffens above T (level 1 - share, Eq 4.6), SH-ADD-2 below it (Eq 4.4)."""
    x = np.random.default_rng(6).normal(size=(2, 10001))
    above = threshold_for_share(x, 0.27, "sh_2", "empirical")
    below = threshold_for_share(x, 0.27, "sh_add_2", "empirical")
    np.testing.assert_allclose(np.mean(x > above[:, None], axis=-1), 0.27, atol=1e-3)
    np.testing.assert_allclose(np.mean(x < below[:, None], axis=-1), 0.27, atol=1e-3)


@pytest.mark.parametrize(
    "law,distribution,shares",
    [
        ("sh_2", "empirical", [0.27, 0.5]),
        ("sh_2", "student_t", [0.27]),
        ("sh_add_2", "empirical", [0.27, 0.45]),
    ],
)
@pytest.mark.slow
def test_adaptive_threshold_reaches_the_requested_share(law, distribution, shares):
    """On 40 s of class C road the C_max share after the first fit lies within 6 points of
    the request (so the C_min share N % does too). Measured over road seeds 1-8: SH-2 within
    2.3 points (standard deviation 0.8-1.3), SH-ADD-2 1-2 points low on average (standard
    deviation 1.8, the lowest -5.1): the threshold is fitted to the history so far, and the
    rest of the road differs."""
    data = quarter_car(
        semi_active(law),
        duration=40.0,
        dt=2e-3,
        output_dt=4e-3,
        control={
            "threshold": {
                "mode": "adaptive",
                "c_max_share": 0.3,
                "learn_time": 5.0,
                "distribution": distribution,
            }
        },
    )
    res = suspopt.simulate(make_config(data), params={"control.threshold.c_max_share": shares})
    late = res.time >= 5.0
    achieved = res.signals["damper_state.F1"][:, late].mean(axis=-1)
    np.testing.assert_allclose(achieved, shares, atol=0.06)
    threshold = res.signals["control_threshold.F1"]
    assert np.all(threshold[:, res.time < 5.0] == 0) and np.all(threshold[:, -1] != 0)
    refits = np.unique(threshold[0], return_index=True)[1]
    # refits at T_learn and every κ T_learn after (κ = 1), the last at the final instant
    assert np.allclose(np.sort(res.time[refits])[1:], 5.0 * np.arange(1, 9))


@pytest.mark.parametrize("engine", ["numpy", "compiled"])
def test_a_refit_period_far_below_a_sample_refits_at_every_sample(engine):
    """T_learn = 5e-324 s (found by fuzzing: the count of periods to the next fit overflowed):
    the same run as T_learn = 1e-9 s, a fit at every controller sample."""
    if engine == "compiled":
        pytest.importorskip("numba")
    runs = []
    for learn_time in (5e-324, 1e-9):
        data = quarter_car(
            semi_active("sh_2"),
            duration=0.2,
            control={
                "threshold": {"mode": "adaptive", "c_max_share": 0.3, "learn_time": learn_time}
            },
        )
        data["simulation"]["engine"] = engine
        runs.append(suspopt.simulate(make_config(data)))
    threshold = runs[0].signals["control_threshold.F1"]
    assert len(np.unique(threshold)) > 50  # refitted again and again
    for name in ("control_threshold.F1", "body.heave_acc"):
        np.testing.assert_array_equal(runs[0].signals[name], runs[1].signals[name])


@pytest.mark.slow
@pytest.mark.parametrize("law", ["sh_2", "sh_add_2"])
def test_adaptive_student_t_threshold_follows_the_exact_fit(law):
    """The controller's bounded Student-t refit on 40 s of class C road, three designs, one
    learning for 7.5 s instead of 5 s (so it refits at other instants): at each refit its
    threshold lies within 1e-3 of the fit's scale of the exact maximum-likelihood fit of every
    sample so far (measured: 2e-5 for SH-2, 1.5e-4 for SH-ADD-2); two runs of the same config
    give the same bits. With the output every ΔT the record at output ``j`` is the sample
    taken at ``j ΔT``, so the refit at output ``j`` saw records ``0 .. j``."""
    data = quarter_car(
        semi_active(law),
        duration=40.0,
        dt=2e-3,
        output_dt=4e-3,
        control={"threshold": {"mode": "adaptive", "c_max_share": 0.3, "learn_time": 5.0}},
    )
    params = {
        "vehicle.corners.F1.spring.linear": [20000.0, 28100.0, 36000.0],
        "control.threshold.learn_time": [5.0, 7.5, 5.0],
    }
    res = suspopt.simulate(make_config(data), params=params)
    again = suspopt.simulate(make_config(data), params=params)
    assert_same_signals(res, again)
    condition, threshold = (
        res.signals[f"{name}.F1"] for name in ("control_condition", "control_threshold")
    )
    for p, learn in enumerate(params["control.threshold.learn_time"]):
        refits = np.flatnonzero(np.diff(threshold[p]) != 0) + 1
        np.testing.assert_allclose(
            res.time[refits], np.arange(learn, 40.0 + 1e-9, learn), atol=1e-9
        )
        for j in refits:
            history = condition[p, : j + 1]
            exact = threshold_for_share(history, 0.3, law, "student_t")
            scale = fit_student_t(history)[1]
            assert abs(threshold[p, j] - exact) < 1e-3 * scale


def test_per_design_settings_are_checked():
    cfg = make_config(
        quarter_car(semi_active(), control={"threshold": {"mode": "adaptive", "c_max_share": 0.3}})
    )
    with pytest.raises(ConfigError, match="c_max_share"):
        suspopt.simulate(cfg, params={"control.threshold.c_max_share": [0.3, 1.2]})
    with pytest.raises(ConfigError, match="c_max: must be at least c_min"):
        suspopt.simulate(cfg, params={"vehicle.corners.F1.damper.c_max": [5000.0, 1000.0]})


def test_fixed_threshold_needs_one_condition_unit():
    dampers = {
        "F1": semi_active("sh_2"),
        "F2": semi_active("sh_add_2"),
        "R1": semi_active("sh_2"),
        "R2": semi_active("sh_2"),
    }
    cfg = make_config(full_car(dampers, control={"threshold": {"mode": "fixed", "value": 0.1}}))
    with pytest.raises(ConfigError, match="different units"):
        suspopt.simulate(cfg)


def test_law_condition_rejects_unknown_law():
    with pytest.raises(ValueError, match="unknown control law"):
        law_condition("sky", np.ones(1), np.ones(1), np.ones(1))


# --- command line --------------------------------------------------------------------------


def run(*args):
    """The CLI in-process (exit code, stdout, stderr) like a subprocess run."""
    result = CliRunner().invoke(app, [str(a) for a in args])
    return SimpleNamespace(returncode=result.exit_code, stdout=result.stdout, stderr=result.stderr)


QC_TEXT = (CONFIGS / "ch4" / "sh_2_cdf_class_c.yaml").read_text()
BAD = {
    "sample_time": (
        QC_TEXT.replace("sample_time: 0.004", "sample_time: 0.0045"),
        "control.sample_time: the controller's sample time",
        23,
    ),
    "c_max_below_c_min": (
        QC_TEXT.replace("c_max: 4873", "c_max: 1000"),
        "vehicle.corners.F1.damper: c_max (1000.0) must be at least c_min",
        11,
    ),
    "unknown_law": (
        QC_TEXT.replace("law: sh_2", "law: skyhook"),
        "vehicle.corners.F1.damper.law: unknown law 'skyhook'; expected one of sh_2,",
        15,
    ),
    "misspelt_key": (
        QC_TEXT.replace("c_min: 1734", "cmin: 1734"),
        "vehicle.corners.F1.damper.cmin: unknown key; did you mean c_min",
        13,
    ),
    "missing_crossover": (
        QC_TEXT.replace("law: sh_2", "law: sh_add_2"),
        "law 'sh_add_2' needs crossover_frequency",
        11,
    ),
    "share_out_of_range": (
        QC_TEXT.replace("c_max_share: 0.27", "c_max_share: 27"),
        "control.threshold.c_max_share: must be less than 1 (got 27)",
        26,
    ),
    "adaptive_without_share": (
        QC_TEXT.replace("    c_max_share: 0.27", "    value: 0.1"),
        "control.threshold: mode 'adaptive' needs c_max_share",
        24,
    ),
    "unknown_control_key": (
        QC_TEXT.replace("sample_time:", "sampling_time:"),
        "control.sampling_time: unknown key; did you mean sample_time",
        23,
    ),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_control_input_exits_2_at_its_line(tmp_path, case):
    """``validate`` gives the problem at its line (a misspelt key also makes the key it
    should have been missing: two errors), then their count."""
    text, needle, line = BAD[case]
    path = tmp_path / "case.yaml"
    path.write_text(text)
    proc = run("validate", path)
    assert proc.returncode == 2, proc.stdout + proc.stderr
    *errors, count = proc.stderr.strip().splitlines()
    assert "Traceback" not in proc.stderr and all(e.startswith("error: ") for e in errors)
    assert count == f"{len(errors)} error{'s' * (len(errors) > 1)} in {path}"
    assert len(errors) == (2 if case == "misspelt_key" else 1), errors
    assert any(needle in e and f"case.yaml:{line}:" in e for e in errors), errors


def test_bad_sample_time_exits_2_from_the_shell(tmp_path):
    path = tmp_path / "case.yaml"
    path.write_text(BAD["sample_time"][0])
    proc = subprocess.run(
        [sys.executable, "-m", "suspopt", "simulate", str(path)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 2 and len(proc.stderr.strip().splitlines()) == 1
    assert "control.sample_time" in proc.stderr and "Traceback" not in proc.stderr


SENSITIVITY = {
    **quarter_car(semi_active("sh_2"), duration=6.0, dt=2e-3, output_dt=4e-3),
    "control": {
        "threshold": {
            "mode": "adaptive",
            "c_max_share": 0.27,
            "learn_time": 2.0,
            "distribution": "empirical",
        }
    },
}


@pytest.mark.slow
def test_cdf_sensitivity_writes_hdf5_and_plot(tmp_path):
    import yaml

    path = tmp_path / "cdf.yaml"
    path.write_text(yaml.safe_dump(SENSITIVITY, sort_keys=False))
    out, fig = tmp_path / "cdf.h5", tmp_path / "cdf.png"
    proc = run("analyse", "cdf-sensitivity", path, "-o", out, "--plot", fig)
    assert proc.returncode == 0, proc.stderr
    assert "CDF sensitivity" in proc.stdout and "base law" in proc.stdout
    assert fig.stat().st_size > 1000
    with h5py.File(out) as h5:
        grp = h5["cdf_sensitivity"]
        np.testing.assert_allclose(grp["c_max_share"][()], np.arange(0.2, 0.71, 0.05))
        datasets = []
        grp.visititems(
            lambda name, obj: datasets.append(obj) if isinstance(obj, h5py.Dataset) else None
        )
        assert all("units" in d.attrs for d in datasets) and len(datasets) == 20  # + corner
        achieved = grp["achieved_share"][()]  # a short run: far from converged
        assert np.all(np.diff(achieved) > 0) and achieved[0] < grp["base_share"][()]
        assert grp["reduction/SW"].attrs["units"] == "%"
        assert grp["base/RC"].attrs["units"] == "m/s^2"


def test_cdf_sensitivity_needs_an_adaptive_threshold(tmp_path):
    import yaml

    data = copy.deepcopy(SENSITIVITY)
    data["control"] = {"sample_time": 0.004}
    path = tmp_path / "case.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    proc = run("analyse", "cdf-sensitivity", path)
    assert proc.returncode == 2 and len(proc.stderr.strip().splitlines()) == 1
    assert "needs an adaptive threshold" in proc.stderr


def test_the_c_max_share_of_a_time_outside_the_run_or_of_passive_dampers_is_refused():
    """A ``share_after`` beyond the run (or NaN) averaged no sample: NaN and numpy's "mean of
    empty slice"; a result without a semi-active damper, the same."""
    from suspopt.analyse.cdf import c_max_share, semi_active_metrics

    result = suspopt.simulate(suspopt.load_config(CONFIGS / "ch4" / "sh_2_bump.yaml"))
    assert 0.0 < c_max_share(result, 0.5)[0] < 1.0
    for late in (5.0, 1e9, float("nan"), -1.0):
        with pytest.raises(ValueError, match=r"share_after must be a time \[s\] in \[0, 5\)"):
            c_max_share(result, late)
    with pytest.raises(ValueError, match="no semi-active damper"):
        c_max_share(suspopt.simulate(suspopt.load_config(CONFIGS / "quickstart.yaml")))
    for wrong in (result.config, None):  # (AttributeErrors from inside before)
        with pytest.raises(TypeError, match=r"result must be a Result \(from suspopt.simulate"):
            c_max_share(wrong)
        with pytest.raises(TypeError, match=r"result must be a Result \(from suspopt.simulate"):
            semi_active_metrics(wrong)


def test_the_semi_active_metrics_take_a_run_read_back_from_its_file(tmp_path):
    """``examples/ch4_tables.py`` reads a stored run back (config, time, signals, corners)
    and asks its metrics: the same values as of the result itself (the reproduction's report
    failed on it when the metrics asked for a ``Result`` by its class)."""
    from types import SimpleNamespace

    from suspopt.analyse.cdf import semi_active_metrics
    from suspopt.io import read_simulation_signals, write_simulation

    cfg = suspopt.load_config(CONFIGS / "ch4" / "sh_2_bump.yaml")
    cfg.simulation.duration = 2.0
    result = suspopt.simulate(cfg)
    time, signals = read_simulation_signals(write_simulation(tmp_path / "run.h5", result))
    run = SimpleNamespace(config=cfg, time=time, signals=signals,
                          model=SimpleNamespace(corners=result.model.corners))  # fmt: skip
    stored, direct = semi_active_metrics(run), semi_active_metrics(result)
    assert stored.keys() == direct.keys()
    assert all(np.array_equal(stored[k], direct[k]) for k in direct)
