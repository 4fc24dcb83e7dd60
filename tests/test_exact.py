"""``simulation.method: exact`` (:mod:`suspopt.integrator.exact`): the linear network's exact
stepper against ``scipy.signal.lsim`` of the model's own linear matrices (M, C, K and the
input matrices, :meth:`suspopt.network.Network.linear_model`, not the stepper's packing) to
1e-10; RK4 converging to it as dt⁴ on a road linear in time; refused, with one located line,
for a non-linear or semi-active model or a road with steps, by ``validate`` and ``simulate``
alike."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import CONFIGS
from scipy import signal

import suspopt
from suspopt.checks import full_network
from suspopt.integrator import exact, integrate_numpy
from suspopt.simulation import _setup, prepare

CASES = {
    "QC": "ch3/part1a_qc_class_b.yaml",
    "HC2": "ch3/part1a_hc2_class_b.yaml",
    "PS seat": "ch8/pareto_ps_class_a.yaml",
}


def _run(name: str, duration: float, dt: float | None = None, method: str = "exact"):
    cfg = suspopt.load_config(CONFIGS / name)
    cfg.simulation.duration, cfg.simulation.method = duration, method
    if dt is not None:
        cfg.simulation.dt = dt
        cfg.simulation.output_dt = None
    pv, model, controller, attachments = prepare(cfg)
    run, z, zd, _ = _setup(cfg, pv, model, controller, attachments)
    return cfg, run, z, zd, full_network(model, attachments).linear_model()


@pytest.mark.parametrize("case", sorted(CASES))
def test_the_exact_stepper_is_lsim_of_the_linear_model(case):
    cfg, run, z, zd, lin = _run(CASES[case], 2.0)
    traj = next(exact.windows(run))[1]
    n = run.asm.n
    Minv = 1.0 / lin.mass[0]
    A = np.block([[np.zeros((n, n)), np.eye(n)],
                  [-Minv[:, None] * lin.stiffness[0], -Minv[:, None] * lin.damping[0]]])  # fmt: skip
    B = np.block([[np.zeros((n, 2 * z.shape[0]))],
                  [Minv[:, None] * lin.input_stiffness[0], Minv[:, None] * lin.input_damping[0]]])  # fmt: skip
    u = np.concatenate([z[:, 0, ::2], zd[:, 0, ::2]]).T  # (the inputs at the steps)
    t = np.arange(run.n_steps + 1) * run.dt
    system = signal.StateSpace(A, B, np.eye(2 * n), np.zeros((2 * n, B.shape[1])))
    _, _, x = signal.lsim(system, u, t, interp=True)
    want = x[:: run.every].T  # (2n, samples)
    got = traj.states[:, 0, :]
    assert got.shape == want.shape
    assert np.max(np.abs(got - want)) <= 1e-10 * np.max(np.abs(want)), case
    acc = (A @ x.T + B @ u.T)[n:, :: run.every]
    assert np.max(np.abs(traj.accelerations[:, 0] - acc)) <= 1e-10 * np.max(np.abs(acc))


def test_rk4_converges_to_the_exact_step_as_dt_to_the_fourth():
    """On a road linear in time (a ramp from rest: linear between any steps), the exact
    stepper is the response at every dt, and RK4's error falls as dt⁴ (its order, measured between
    three steps, nears 4 from below)."""
    errors = []
    for dt in (1.6e-3, 0.8e-3, 0.4e-3):
        cfg, run, _, _, _ = _run(CASES["HC2"], 0.4, dt=dt)
        t = np.arange(2 * run.n_steps + 1) * (0.5 * dt)
        n_u = run.asm.input_map.shape[1]
        rates = np.linspace(0.02, 0.03, n_u)  # (ramps of 2-3 cm/s)
        u, u_dot = np.outer(rates, t), np.repeat(rates[:, None], t.size, axis=1)
        ramp = run._replace(offsets=run.asm.offsets(u, u_dot))
        reference = next(exact.windows(ramp))[1].states[:, 0, -1]
        rk4 = integrate_numpy(ramp).states[:, 0, -1]
        errors.append(np.max(np.abs(rk4 - reference)) / np.max(np.abs(reference)))
    orders = np.log2([errors[0] / errors[1], errors[1] / errors[2]])
    assert all(3.6 < p < 4.3 for p in orders) and orders[1] > orders[0], (errors, orders)


@pytest.mark.parametrize(
    "name, why",
    [
        ("ch7/sh_2.yaml", "a semi-active controller switches the damping"),
        ("ch8/pareto_nss1_class_a.yaml", "the nss1 seat's mechanism is not linear"),
        ("ch5/case1_s1.yaml", "the Duffing spring"),
        ("ch3/part1a_qc_bump.yaml", "a road without steps between the integration steps"),
    ],
)
def test_a_model_that_is_not_linear_or_a_stepped_road_is_refused_at_its_key(name, why, tmp_path):
    from typer.testing import CliRunner

    from suspopt.cli import app

    text = (CONFIGS / name).read_text().replace("simulation: {", "simulation: {method: exact, ")
    path = tmp_path / "case.yaml"
    path.write_text(text)
    for command in (["validate", str(path)], ["simulate", str(path)]):
        res = CliRunner().invoke(app, command)
        errors = [ln for ln in res.output.splitlines() if ln.startswith("error:")]
        assert res.exit_code == 2 and len(errors) == 1, res.output
        assert "simulation.method: exact needs a " in errors[0] and why in errors[0]


def test_the_exact_stepper_has_no_rk4_stability_limit(tmp_path):
    """A stiff design RK4 cannot step at dt (``validate`` and ``simulate --sweep`` refuse it
    under method time) runs under method exact, its states finite."""
    from typer.testing import CliRunner

    from suspopt.cli import app

    text = (CONFIGS / CASES["QC"]).read_text()
    text = text.replace("simulation: {duration: 60.0,", "simulation: {duration: 1.0,")
    sweep = ["--sweep", "vehicle.corners.F1.spring.linear=1e9:1e10:2"]
    for method, code in (("time", 2), ("exact", 0)):
        path = tmp_path / f"{method}.yaml"
        path.write_text(text.replace("simulation: {", f"simulation: {{method: {method}, "))
        out = tmp_path / f"{method}.h5"
        res = CliRunner().invoke(app, ["simulate", str(path), *sweep, "-o", str(out)])
        assert res.exit_code == code, res.output
    import h5py

    with h5py.File(tmp_path / "exact.h5") as h5:
        assert np.isfinite(h5["signals/body.heave"][()]).all()
        assert np.isnan(h5["diverged_at"][()]).all()
