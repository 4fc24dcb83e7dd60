"""
Modes and frequency response of the quarter car
===============================================

The quarter car of Table 3.1 (``quarter`` template) linearised: its undamped natural
frequencies and mode shapes (:func:`suspopt.modal_analysis`, ``K φ = ω² M φ``, Table 3.5),
and its response to a harmonic road height (:func:`suspopt.frequency_response`,
``(K - ω² M + jω C) Q = (B_k + jω B_c) R``) for three dampers at once: the body's heave
and the wheel's per metre of road, and the body's acceleration per metre of road, the
quantity ride comfort weighs (Sec 2.4).
"""

import matplotlib.pyplot as plt
import numpy as np

import suspopt
from suspopt.params import ParamView

# %%
# Three dampers, one model
# ------------------------

cfg = suspopt.load_template("quarter")
damping = np.array([400.0, 800.0, 1600.0])  # c [N s/m]
model = suspopt.build_vehicle(cfg, ParamView(cfg, {"vehicle.corners.F1.damper.c": damping}))
modes = suspopt.modal_analysis(model)
f = np.geomspace(0.1, 50.0, 800)  # [Hz]
Q = suspopt.frequency_response(model, f)  # (P, F, n) [m per m of road]
body, wheel = model.dof_names.index("body.heave"), model.dof_names.index("wheel.F1")
for k in range(modes.frequency.shape[1]):
    print(f"mode {k + 1}: {modes.frequency[0, k]:.3f} Hz, {modes.label[0, k]}")

# %%
# The responses
# -------------

fig, (ax_q, ax_a) = plt.subplots(2, 1, sharex=True, layout="constrained", figsize=(6.4, 7.0))
for p, c in enumerate(damping):
    (line,) = ax_q.loglog(f, np.abs(Q[p, :, body]), label=f"body, c = {c:g} N s/m")
    ax_q.loglog(f, np.abs(Q[p, :, wheel]), "--", color=line.get_color())
    ax_a.loglog(f, (2 * np.pi * f) ** 2 * np.abs(Q[p, :, body]), color=line.get_color())
for ax in (ax_q, ax_a):
    for fn in modes.frequency[0]:
        ax.axvline(fn, color="0.6", lw=0.8, ls=":")
ax_q.set_ylabel("heave per road height [m/m]")
ax_q.set_title("Quarter car, Table 3.1: body (solid) and wheel (dashed)")
ax_q.legend(fontsize="small")
ax_q.set_ylim(1e-3, 10.0)
ax_a.set_ylabel("body acceleration per road height [(m/s$^2$)/m]")
ax_a.set_xlabel("frequency [Hz] (dotted: undamped natural frequencies)")

# %%
# Checks against the physics
# --------------------------
# The undamped frequencies of the two-mass system solve
# ``m_s m_u ω⁴ - (m_s (k + k_T) + m_u k) ω² + k k_T = 0``; the solver's must be its roots to
# rounding (1e-9 relative). A slow road lifts the whole car with it: ``|Q| -> 1`` as
# ``f -> 0``, the departure of order ``(f / f_body)^2`` (the body's inertia; a damped
# resonance's rise), twice that is the check at 0.1 Hz. And well above the wheel-hop mode
# the body hardly moves: its response at 50 Hz is below 1 % for every damper.
corner = cfg.vehicle.corners["F1"]
m_s, m_u = cfg.vehicle.body.mass, corner.unsprung_mass
k, k_t = corner.spring.linear, corner.tyre.stiffness
omega2 = np.roots([m_s * m_u, -(m_s * (k + k_t) + m_u * k), k * k_t])
expected = np.sort(np.sqrt(omega2)) / (2 * np.pi)  # [Hz]
assert np.allclose(modes.frequency, expected[None, :], rtol=1e-9), (modes.frequency, expected)
low = 2.0 * (f[0] / modes.frequency[:, :1]) ** 2  # (P, 1)
assert np.all(np.abs(np.abs(Q[:, 0, :]) - 1.0) < low), np.abs(Q[:, 0, :])
assert np.all(np.abs(Q[:, -1, body]) < 0.01)
