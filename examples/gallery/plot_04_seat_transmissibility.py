"""
A seat's transmissibility
=========================

The passive seat (PS, Eq 2.40) of Chapter 8 with the seven-part passenger of Sec 2.3
(Table 2.3) on the Chapter 8 quarter car, on an ISO 8608 class A road at 120 km/h. Drawn for
three seat dampers ``C_v``: the seat transmissibility ``|z̈_seat / z̈_s|`` (Fig. 2.18b) and
the seat-to-head transmissibility STHT ``|z̈_head / z̈_s|`` (Eq 2.86, Fig. 8.26), from the
floor under the seat to the seat and to the head, as
``suspopt.analyse.transmissibility.seat_transmissibility`` gives them: from the seat
linearised about its static equilibrium (exact, lines) and as the H1 estimate from a 30 s
simulation (Welch, 8 s segments; dots, where the coherence is at least 0.9).
"""

import matplotlib.pyplot as plt
import numpy as np

import suspopt
from suspopt.analyse.transmissibility import seat_transmissibility

# %%
# Three seat dampers in one batch
# -------------------------------

cfg = suspopt.load_template("seat")
cfg.simulation.duration = 30.0  # [s]: 1 km of road, as Ch. 8 drives
cfg.metrics = []
damping = np.array([500.0, 1000.0, 2000.0])  # C_v [N s/m], inside Table 8.2's 200-2500
SEGMENT = 8.0  # Welch segment [s]: 0.125 Hz resolution
tr = seat_transmissibility(cfg, segment=SEGMENT, params={"seat.damping": damping})

f_lin, f_sim = tr.linear_frequency, tr.simulated_frequency
columns = {"seat": tr.dof_names.index("seat"), "head": tr.dof_names.index("head")}
# the linear curves on the simulated estimate's frequencies, (P, F, m)
lin = np.stack(
    [
        np.stack([np.interp(f_sim, f_lin, tr.linear[p, :, j]) for j in range(len(tr.dof_names))])
        for p in range(len(damping))
    ]
).transpose(0, 2, 1)

# %%
# The curves
# ----------

fig, axes = plt.subplots(2, 1, sharex=True, layout="constrained", figsize=(6.4, 7.0))
titles = {
    "seat": "seat: $|\\ddot z_{seat} / \\ddot z_s|$",
    "head": "STHT: $|\\ddot z_{head} / \\ddot z_s|$",
}
for ax, (dof, j) in zip(axes, columns.items()):
    for p, c in enumerate(damping):
        (line,) = ax.loglog(f_lin, tr.linear[p, :, j], label=f"$C_v$ = {c:g} N s/m, linear")
        coherent = tr.coherence[p, :, j] >= 0.9
        ax.loglog(
            f_sim[coherent], tr.simulated[p, coherent, j], ".", ms=2.5, color=line.get_color()
        )
    ax.axhline(1.0, color="0.6", lw=0.8)
    ax.set_ylabel("transmissibility [-]")
    ax.set_title(titles[dof])
axes[0].legend(title="dots: simulated (H1)", fontsize="small")
axes[1].set_xlabel("frequency [Hz]")
axes[1].set_xlim(0.3, 30.0)
axes[1].set_ylim(1e-2, 10.0)
print("undamped natural frequencies, floor held still [Hz]:", np.round(tr.natural_frequency[0], 2))

# %%
# Checks against the physics
# --------------------------
# Far below its first mode a seat moves with the floor: the linear transmissibility of
# every part at the grid's lowest frequency departs from 1 by about ``(f / f_1)^2``, the
# square of its ratio to the first mode (0.3 % at 0.1 Hz); the check allows three times it.
low = 3.0 * (f_lin[0] / tr.natural_frequency[:, :1]) ** 2  # (P, 1)
assert np.all(np.abs(tr.linear[:, 0, :] - 1.0) < low), tr.linear[:, 0, :]

# The simulation is the same linear system, so its H1 estimate must agree with the exact
# curve to within the estimate's own error, at every frequency of 0.5-20 Hz where the
# coherence ``g2`` is at least 0.9: three standard deviations of the random error,
# ``sqrt((1 - g2) / (2 n_d g2))`` for ``n_d`` averages (Bendat & Piersol, Random Data: the
# normalised random error of a frequency-response gain; 50 % overlap counted as independent),
# plus the bias of the Hann window's finite
# resolution at a resonance, ``(B_e / B_r)^2 / 3`` (``B_e`` = 1.5 / segment, ``B_r`` the
# resonance's half-power width ``2 zeta f_n``), at least 2 % for the leakage of a segment that
# holds few cycles of the lowest frequencies.
n_d = 2.0 * cfg.simulation.duration / SEGMENT - 1.0
g2 = np.clip(tr.coherence, 1e-12, 1.0)
random_error = np.sqrt((1.0 - g2) / (2.0 * n_d * g2))
# the load on the isolator [kg], seat and passenger, from its static deflection K_v X_ST = m g
load = cfg.seat.stiffness * tr.static_deflection / cfg.vehicle.gravity
zeta = damping / (2.0 * np.sqrt(cfg.seat.stiffness * load))  # the seat mode's damping ratio
f_n = tr.natural_frequency[:, 0]
bias = np.maximum((1.5 / SEGMENT / (2.0 * zeta * f_n)) ** 2 / 3.0, 0.02)
tolerance = 3.0 * random_error + bias[:, None, None]
band = ((f_sim >= 0.5) & (f_sim <= 20.0))[None, :, None]
checked = band & (tr.coherence >= 0.9)
error = np.abs(tr.simulated / lin - 1.0)
print(f"largest error / tolerance: {np.max(error[checked] / tolerance[checked]):.2f}")
assert checked.sum() > 0.5 * band.sum() * checked.shape[0] * checked.shape[2]  # mostly coherent
assert np.all(error[checked] <= tolerance[checked])
