"""
The four vehicle models over one bump
=====================================

Chapter 3 of the thesis compares its four vehicle models, the quarter car (QC, Sec 2.1.1),
the half car in roll (HC1, Sec 2.1.2), the half car in pitch (HC2, Sec 2.1.3) and the full
car (FC, Sec 2.1.4), built from the same car (Table 3.1), over the step bump of Sec 3.1.2:
5 cm high, 80 m long, met at 2 s at 10 m/s (Eq 2.103-2.104). This script starts from the
four presets' templates, gives each the Table 3.1 car and that bump under both tracks, and
draws the body's heave acceleration and heave (Figs. 3.2-3.3, Tables 3.3-3.4).

The half car in pitch and the full car meet the bump with the rear axle
``(a_F + a_R) / V`` = 0.287 s after the front one (Sec 2.5.2), which splits the body's
response into two smaller ones.
"""

import matplotlib.pyplot as plt
import numpy as np

import suspopt
from suspopt.plots import curve_styles, mark_indices

# %%
# One car, four models
# --------------------
# ``quarter``, ``half_roll`` and ``full`` already carry the Table 3.1 car; ``half_pitch``
# carries the Ch. 5 car (Table 5.1, Duffing springs), so it gets Table 3.1's half of the body
# (m_s/2, I_y/2) and the same corners. Each model drives over the same step bump.

HEIGHT = 0.05  # step height h [m]
bump = {"kind": "bump_step", "height": HEIGHT, "length": 80.0, "speed": 10.0, "start": 2.0}
corner = {
    "unsprung_mass": 40.0,  # m_u [kg]
    "tyre": {"stiffness": 1.5e5, "damping": 0.0},  # k_T [N/m], c_T [N s/m]
    "spring": {"linear": 1.0e4},  # k [N/m]
    "damper": {"c": 800.0},  # c [N s/m]
}

results = {}
for preset in ("quarter", "half_roll", "half_pitch", "full"):
    cfg = suspopt.load_template(preset)
    if preset == "half_pitch":
        cfg.vehicle.body = {"mass": 542.5, "pitch_inertia": 550.0, "a_front": 1.4, "a_rear": 1.47}
        cfg.vehicle.corners = {"F1": corner, "R1": corner}
    cfg.road = bump  # identical tracks: both sides climb the step
    cfg.simulation.duration = 9.0  # [s], before the wheels leave the plateau (at 10 s)
    cfg.metrics = [{"metric": "peak", "signal": "body.heave_acc"}]
    results[preset] = suspopt.simulate(cfg)

# %%
# Heave acceleration and heave
# ----------------------------
# The quarter car and the half car in roll coincide here (on identical tracks the roll is
# barely excited), and so do the half car in pitch and the full car: the curves get widths
# and markers that keep each visible (``suspopt.plots.curve_styles``).

fig, (ax_acc, ax_heave) = plt.subplots(2, 1, sharex=True, layout="constrained")
styles = curve_styles(len(results))
for i, (preset, res) in enumerate(results.items()):
    marks = mark_indices(res.time, i, len(results))
    for ax, signal in ((ax_acc, "body.heave_acc"), (ax_heave, "body.heave")):
        ax.plot(res.time, res.signals[signal][0], markevery=marks, label=preset, **styles[i])
ax_acc.set_ylabel("body heave acceleration [m/s$^2$]")
ax_heave.set_ylabel("body heave [m]")
ax_heave.set_xlabel("time [s]")
ax_acc.set_title("Table 3.1 car over a 5 cm step at 10 m/s")
ax_heave.legend(ncol=2)
ax_acc.set_xlim(1.5, 9.0)

for preset, res in results.items():
    print(f"{preset:10s} peak heave acceleration {res.metrics['peak.body.heave_acc'][0]:.3f} m/s^2")

# %%
# Checks against the physics
# --------------------------
# On the plateau every spring carries its static load again, so the body comes to rest
# raised by the step height. By 9 s the slowest body mode (about 1 Hz, damping ratio about
# 0.24, decay time 1/(zeta omega) under 0.7 s) has decayed for more than nine decay times
# after the rear axle's step: 1 % of h is a tolerance no model in equilibrium can miss. And
# with the step split between the axles, the half car in pitch and the full car must shake
# the body less than the quarter car, which takes the whole step at once.

for preset, res in results.items():
    final = res.signals["body.heave"][0, -1]
    assert abs(final - HEIGHT) < 0.01 * HEIGHT, (preset, final)
    assert np.all(np.isfinite(res.signals["body.heave_acc"]))
peak = {preset: res.metrics["peak.body.heave_acc"][0] for preset, res in results.items()}
assert peak["half_pitch"] < peak["quarter"] and peak["full"] < peak["quarter"], peak
