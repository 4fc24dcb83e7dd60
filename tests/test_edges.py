"""Bump edges seen at their instants: RK4 against the exact solution of a linear vehicle.

The reference is independent of the simulator: the linear quarter car (Eq 2.1-2.4) and half car
(Eq 2.13-2.18) are written out here by hand, and their response to the bump (Eq 2.101-2.104) is
the matrix exponential of the system augmented with the road's own dynamics, piecewise between
the edges: a step's height is a constant state and a half-sine's ``(sin, cos)`` a rotating pair,
reseeded at each edge; the step's Dirac in the road's rate is the velocity jump
``M^-1 B_c Δz`` of the tyre damping at the edge. The simulator's error then falls at RK4's
order, about 16x per halving of dt, with the edges on the dt grid and off it.

Run as a script it prints the errors and their ratios for each case, for the suspopt first on
the Python path: ``PYTHONPATH=. python tests/test_edges.py`` from the repository root (point
PYTHONPATH at another checkout to measure that one).
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import corner, make_config
from scipy.linalg import expm

import suspopt

M_S, M_U, K_T, K, C = 300.0, 40.0, 1.5e5, 1.5e4, 1200.0  # [kg] body/corner, wheel; [N/m]; [N s/m]
A_F, A_R, PITCH_INERTIA = 1.2, 1.4, 650.0  # half car [m], [kg m^2]
HEIGHT, SPEED = 0.05, 10.0
DTS = 2.0 ** -np.arange(8, 12)  # 3.9 ms ... 0.49 ms, output every 3.9 ms
DURATION = 1.0
# (name, preset, start [s], length [m]): dyadic times put the edges on every dt grid
CASES = [
    ("QC edges on the grid", "quarter", 0.125, 1.25),
    ("QC edges off the grid", "quarter", 0.1003, 1.2345),
    ("HC2 rear edges off the grid", "half_pitch", 0.125, 1.25),
]
TYRE_DAMPING = np.array([0.0, 300.0])  # two designs in one batch [N s/m]


def config(
    preset: str,
    kind: str,
    start: float,
    length: float,
    dt: float,
    height: float = HEIGHT,
    lift_off: bool = False,
    c_t: float = 0.0,
):
    body = (
        {"mass": M_S}
        if preset == "quarter"
        else {"mass": 2 * M_S, "pitch_inertia": PITCH_INERTIA, "a_front": A_F, "a_rear": A_R}
    )
    return make_config(
        {
            "vehicle": {
                "preset": preset,
                "body": body,
                "tyre_lift_off": lift_off,
                "corner_defaults": corner(m_u=M_U, k_t=K_T, c_t=c_t, k=K, c=C),
            },
            "road": {
                "kind": kind,
                "height": height,
                "length": length,
                "speed": SPEED,
                "start": start,
            },
            "simulation": {"duration": DURATION, "dt": float(dt), "output_dt": float(DTS[0])},
        }
    )


def linear_model(preset: str, c_t: float):
    """M, K, C, B_k, B_c and the wheels' delays of the linear vehicle, written out by hand:
    ST = J q (Eq 2.3, 2.17), TD = W q - z_road (Eq 2.4, 2.18), M q'' = -J^T F_s - W^T F_t."""
    if preset == "quarter":
        mass = np.array([M_S, M_U])
        J, W, delay = np.array([[1.0, -1.0]]), np.array([[0.0, 1.0]]), np.zeros(1)
    else:  # q = [z, theta, z_F, z_R]
        mass = np.array([2 * M_S, PITCH_INERTIA, M_U, M_U])
        J = np.array([[1.0, -A_F, -1.0, 0.0], [1.0, A_R, 0.0, -1.0]])
        W = np.array([[0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
        delay = np.array([0.0, (A_F + A_R) / SPEED])
    stiffness = K * J.T @ J + K_T * W.T @ W
    damping = C * J.T @ J + c_t * W.T @ W
    return mass, stiffness, damping, K_T * W.T, c_t * W.T, delay


def exact(
    preset: str,
    kind: str,
    start: float,
    length: float,
    c_t: float,
    times: np.ndarray,
    height: float = HEIGHT,
    pulls: bool = True,
) -> np.ndarray:
    """States [q; q'] (2n, T) of the linear vehicle at ``times`` from rest; ``pulls=False``
    drops the tyre's impulse where it would pull (a tyre that may lift off)."""
    mass, stiffness, damping, b_k, b_c, delay = linear_model(preset, c_t)
    n, wheels = mass.size, delay.size
    omega = np.pi * SPEED / length if kind == "bump_half_sine" else 0.0
    # x = [q, q', (s_w, c_w) per wheel]: z_road,w = h s_w, its rate h omega c_w
    size = 2 * n + 2 * wheels
    a = np.zeros((size, size))
    a[:n, n : 2 * n] = np.eye(n)
    a[n : 2 * n, :n] = -stiffness / mass[:, None]
    a[n : 2 * n, n : 2 * n] = -damping / mass[:, None]
    for w in range(wheels):
        s, c = 2 * n + 2 * w, 2 * n + 2 * w + 1
        a[n : 2 * n, s] = height * b_k[:, w] / mass
        a[n : 2 * n, c] = height * omega * b_c[:, w] / mass
        a[s, c], a[c, s] = omega, -omega
    up = start + delay
    down = up + length / SPEED
    edges = sorted({*up, *down})
    x, now, out = np.zeros(size), 0.0, np.empty((2 * n, times.size))
    for t_edge in edges + [np.inf]:
        due = (times >= now) & (times < t_edge)
        if due.any():
            out[:, due] = (expm(a * (times[due] - now)[:, None, None]) @ x)[:, : 2 * n].T
        if t_edge == np.inf:
            break
        x = expm(a * (t_edge - now)) @ x
        now = t_edge
        for w in range(wheels):
            s = 2 * n + 2 * w
            if t_edge in (up[w], down[w]):
                on = t_edge == up[w]
                x[s : s + 2] = (0.0, 1.0) if on and omega else (float(on), 0.0)
                jump = height if on else -height
                if kind == "bump_step" and (pulls or jump > 0):
                    x[n : 2 * n] += jump * b_c[:, w] / mass  # the Dirac of the road's rate
    return out


def tyre_damping(preset: str) -> dict[str, np.ndarray]:
    """The designs' c_T at every corner."""
    corners = ("F1",) if preset == "quarter" else ("F1", "R1")
    return {f"vehicle.corners.{c}.tyre.damping": TYRE_DAMPING for c in corners}


def errors(preset: str, kind: str, start: float, length: float) -> np.ndarray:
    """Max error of the simulated states (relative to each one's peak) per dt (rows) and
    tyre damping (columns), both designs in one batch per dt."""
    result = []
    for dt in DTS:
        res = suspopt.simulate(config(preset, kind, start, length, dt), params=tyre_damping(preset))
        times = np.arange(res.time.size) * DTS[0]
        row = []
        for p, c_t in enumerate(TYRE_DAMPING):
            reference = exact(preset, kind, start, length, c_t, times)
            sim = res.states[:, p]
            scale = np.abs(reference).max(axis=1, keepdims=True)
            row.append(np.max(np.abs(sim - reference) / scale))
        result.append(row)
    return np.array(result)


@pytest.mark.parametrize("kind", ["bump_step", "bump_half_sine"])
@pytest.mark.parametrize("name, preset, start, length", CASES, ids=[c[0] for c in CASES])
@pytest.mark.slow
def test_error_falls_at_rk4_order_across_bump_edges(name, preset, start, length, kind):
    err = errors(preset, kind, start, length)
    ratios = err[:-1] / err[1:]
    # fourth order: 16 per halving; an edge seen a fraction of a step off gives 2 (first order)
    assert np.all(ratios > 11.0), (name, kind, err, ratios)
    assert np.all(err[0] < 1e-2), err


def test_edges_at_the_first_and_last_instants():
    """A step met at t = 0 and left at the run's last instant: both impulses are applied (the
    samples there hold the state just after them, with the road's right limit)."""
    err = []
    for dt in DTS[1:3]:
        res = suspopt.simulate(config("quarter", "bump_step", 0.0, SPEED * DURATION, dt, c_t=300.0))
        times = np.arange(res.time.size) * DTS[0]
        reference = exact("quarter", "bump_step", 0.0, SPEED * DURATION, 300.0, times)
        scale = np.abs(reference).max(axis=1, keepdims=True)
        err.append(np.max(np.abs(res.states[:, 0] - reference) / scale))
        assert res.signals["road.F1"][0, 0] == HEIGHT and res.signals["road.F1"][0, -1] == 0.0
    assert err[0] / err[1] > 11.0, err


def test_reference_is_the_simulators_model():
    """The hand-written linear matrices are the simulator's (so the comparison above compares
    integrations, not models)."""
    for preset in ("quarter", "half_pitch"):
        model = suspopt.build_vehicle(config(preset, "bump_step", 0.125, 1.25, DTS[0], c_t=300.0))
        mass, stiffness, damping, b_k, b_c, delay = linear_model(preset, 300.0)
        np.testing.assert_allclose(model.mass[0, 0], mass)
        np.testing.assert_allclose(model.stiffness[0], stiffness)
        np.testing.assert_allclose(model.damping[0], damping)
        np.testing.assert_allclose(model.input_stiffness[0], b_k)
        np.testing.assert_allclose(model.input_damping[0], b_c)
        np.testing.assert_allclose(model.offsets / SPEED, delay)


def test_lift_off_tyre_takes_the_pushing_impulse_not_the_pulling_one():
    """With lift-off the tyre cannot pull: where the road drops away (the step's far edge) the
    Dirac would pull the wheel down and is not applied; where it rises it is. A low step keeps
    the tyre on the road otherwise, so the linear reference holds between the edges."""
    low, c_t, dt = 0.005, 300.0, DTS[2]
    res = suspopt.simulate(
        config("quarter", "bump_step", 0.1003, 1.2345, dt, height=low, lift_off=True, c_t=c_t)
    )
    times = np.arange(res.time.size) * DTS[0]
    held = exact("quarter", "bump_step", 0.1003, 1.2345, c_t, times, height=low, pulls=False)
    pulled = exact("quarter", "bump_step", 0.1003, 1.2345, c_t, times, height=low)
    assert res.signals["tyre_force.F1"].min() > 0.0  # never lifted between the edges
    scale = np.abs(held).max(axis=1, keepdims=True)
    error = np.max(np.abs(res.states[:, 0] - held) / scale)
    assert error < 1e-3 * np.max(np.abs(pulled - held) / scale)


def test_same_batch_same_bits():
    cfg = config("half_pitch", "bump_step", 0.1003, 1.2345, DTS[1])
    params = tyre_damping("half_pitch")
    a, b = suspopt.simulate(cfg, params=params), suspopt.simulate(cfg, params=params)
    assert np.array_equal(a.states, b.states) and np.array_equal(a.accelerations, b.accelerations)


if __name__ == "__main__":
    print(f"suspopt from {suspopt.__file__}")
    print(
        "max state error / peak, designs c_T = "
        + ", ".join(f"{c:g}" for c in TYRE_DAMPING)
        + " N s/m; ratio = error(2 dt) / error(dt)"
    )
    for kind in ("bump_step", "bump_half_sine"):
        for name, preset, start, length in CASES:
            err = errors(preset, kind, start, length)
            print(f"\n{kind}, {name}")
            for j, dt in enumerate(DTS):
                cells = "  ".join(
                    f"{e:9.2e}" + (f" ({err[j - 1, p] / e:5.1f})" if j else " " * 8)
                    for p, e in enumerate(err[j])
                )
                print(f"  dt = {dt * 1e3:6.3f} ms  {cells}")
