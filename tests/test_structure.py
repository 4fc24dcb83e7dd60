"""The code's shape (function sizes; modules are cut by concept, with no cap) and the integrator against independent
references: every bundled config runs; a linear quarter car agrees with ``scipy.signal.lsim``
of the model's own linear matrices; RK4 converges at fourth order on a smooth road."""

from __future__ import annotations

import ast

import numpy as np
import pytest
import scipy.signal as ss
from conftest import CONFIGS, ROOT

import suspopt
from suspopt.road import road_inputs

MAX_FUNCTION_LINES = 80


def test_no_function_over_80_lines():
    """80 lines of code at most (a docstring not counted)."""
    too_long = []
    for path in sorted((ROOT / "suspopt").rglob("*.py")):
        text = path.read_text()
        where = path.relative_to(ROOT)
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                lines = node.end_lineno - node.lineno + 1
                first = node.body[0]  # (the docstring is not code: a public one is long)
                if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant):
                    lines -= first.end_lineno - first.lineno + 1
                if lines > MAX_FUNCTION_LINES:
                    too_long.append(f"{where}:{node.lineno} {node.name}: {lines} lines")
    assert not too_long, too_long


BUNDLED = sorted(p.relative_to(CONFIGS).as_posix() for p in CONFIGS.rglob("*.yaml"))


@pytest.mark.slow
@pytest.mark.parametrize("name", BUNDLED)
def test_every_bundled_config_loads_and_runs_a_short_simulation(name):
    cfg = suspopt.load_config(CONFIGS / name)
    steps = max(1, round(min(cfg.simulation.duration, 0.2) / cfg.simulation.dt))
    cfg.simulation.duration = steps * cfg.simulation.dt
    if getattr(cfg.road, "start", 0.0) >= cfg.simulation.duration:
        cfg.road.start = 0.5 * cfg.simulation.duration
    result = suspopt.simulate(cfg)  # the config's own design (variables at their values)
    assert result.states.shape[1] == 1
    assert np.isfinite(result.states).all() and not result.diverged.any()


def _state_space(model):
    """``x' = A x + B [u; u']`` of the model's linear matrices, ``x = [q; q']``."""
    lin = model.linear
    n, inputs = lin.mass.shape[1], lin.input_stiffness.shape[2]
    m_inv = np.diag(1.0 / lin.mass[0])
    A = np.block(
        [[np.zeros((n, n)), np.eye(n)], [-m_inv @ lin.stiffness[0], -m_inv @ lin.damping[0]]]
    )
    forcing = m_inv @ np.hstack([lin.input_stiffness[0], lin.input_damping[0]])
    B = np.vstack([np.zeros((n, 2 * inputs)), forcing])
    return ss.StateSpace(A, B, np.eye(2 * n), np.zeros((2 * n, 2 * inputs)))


def test_linear_quarter_car_agrees_with_lsim_of_its_own_matrices(load):
    cfg = load("ch3/part1a_qc_class_b.yaml")  # linear: no Duffing term, no lift-off
    cfg.simulation.duration = 3.0
    result = suspopt.simulate(cfg)
    model, t = result.model, result.time
    # lsim interpolates the inputs linearly: a grid 16 times finer than the samples
    fine = np.linspace(0.0, t[-1], 16 * (t.size - 1) + 1)
    z, z_rate = road_inputs(cfg.road, model.offsets, model.sides, fine)
    _, _, x = ss.lsim(_state_space(model), np.hstack([z.T, z_rate.T]), fine)
    reference = x[::16, : model.n_dof]
    error = np.abs(result.states[: model.n_dof, 0, :].T - reference).max(axis=0)
    assert (error <= 1e-5 * np.abs(reference).max(axis=0)).all(), error


def test_rk4_converges_at_fourth_order_on_a_smooth_road(load):
    cfg = load("ch3/part1a_qc_class_b.yaml")
    cfg.simulation.duration = 2.0
    cfg.simulation.output_dt = 2e-3
    states = {}
    for dt in (2e-3, 1e-3, 5e-4):
        cfg.simulation.dt = dt
        states[dt] = suspopt.simulate(cfg).states[:, 0, :]
    coarse = np.abs(states[2e-3] - states[1e-3]).max()
    fine = np.abs(states[1e-3] - states[5e-4]).max()
    assert coarse / fine == pytest.approx(16.0, rel=0.1)
