"""
Semi-active control laws compared
=================================

The Chapter 4 quarter car (Table 4.1) on an ISO 8608 class C road at 50 km/h (Sec 4.1.2),
with a damper that a digital controller switches every 4 ms between a soft ``C_min`` and a
stiff ``C_max`` (Sec 4.2), by the two-state skyhook law SH-2 (Eq 2.34), the mixed skyhook
and acceleration-driven law SH-ADD-2 (Eq 2.39) and the groundhook law (the road-holding
law Sec 4.4 names; it damps the wheel, not the body), against
passive dampers fixed at either coefficient. The laws run without the CDF threshold of the
template (``control.threshold``), as Eq 2.34-2.39 write them. Drawn: the r.m.s. and the
ISO 2631-1 Wk-weighted r.m.s. body acceleration (Eq 2.78) of each, and a stretch of the
body's acceleration and of the damping coefficient the controller chose.
"""

import matplotlib.pyplot as plt
import numpy as np

import suspopt

# %%
# The passive dampers, in one batch
# ---------------------------------

base = suspopt.load_template("semi_active")
base.simulation.duration = 10.0  # [s]: 139 m of road
base.control.threshold = None  # the base laws
base.metrics = [
    {"name": "rms", "metric": "rms", "signal": "body.heave_acc"},
    {"name": "RC", "metric": "rms_weighted", "signal": "body.heave_acc", "weighting": "Wk"},
    {"name": "TD", "metric": "rms", "signal": "tyre_deflection"},  # road holding [m]
]
semi = base.vehicle.corners["F1"].damper
C_MIN, C_MAX = semi.c_min, semi.c_max  # [N s/m]

passive = base.model_copy(deep=True)
passive.control = None
passive.vehicle.corners["F1"].damper = {"kind": "passive", "c": C_MIN}
res_passive = suspopt.simulate(passive, {"vehicle.corners.F1.damper.c": np.array([C_MIN, C_MAX])})
runs = {
    "passive C_min": (res_passive, 0),
    "passive C_max": (res_passive, 1),
}

# %%
# The semi-active laws, one run each
# ----------------------------------
# A law is a word of the config, not a number: each is its own run.

laws = {
    "SH-2": {"law": "sh_2"},
    "SH-ADD-2": {"law": "sh_add_2", "crossover_frequency": 39.0},  # alpha [rad/s] (Sec 4.2.2)
    "groundhook": {"law": "groundhook"},
}
for label, law in laws.items():
    cfg = base.model_copy(deep=True)
    cfg.vehicle.corners["F1"].damper = {
        "kind": "semi_active",
        "c_min": C_MIN,
        "c_max": C_MAX,
        **law,
    }
    runs[label] = (suspopt.simulate(cfg), 0)

# %%
# Comfort, and what the controller did
# ------------------------------------

labels = list(runs)
rms = np.array([res.metrics["rms"][p] for res, p in runs.values()])
rc = np.array([res.metrics["RC"][p] for res, p in runs.values()])

fig, axes = plt.subplots(3, 1, layout="constrained", figsize=(6.4, 8.0))
x = np.arange(len(labels))
axes[0].bar(x - 0.2, rms, 0.4, label="r.m.s.")
axes[0].bar(x + 0.2, rc, 0.4, label="Wk-weighted r.m.s. (RC)")
axes[0].set_xticks(x, [label.replace(" ", "\n") for label in labels])
axes[0].set_ylabel("body acceleration [m/s$^2$]")
axes[0].set_title("Quarter car on class C at 50 km/h, 10 s")
axes[0].set_ylim(0.0, 1.35 * max(rms.max(), rc.max()))
axes[0].legend(ncol=2)

window = (4.0, 5.0)  # [s]
for label in ("passive C_min", "SH-2", "groundhook"):
    res, p = runs[label]
    shown = (res.time >= window[0]) & (res.time <= window[1])
    axes[1].plot(res.time[shown], res.signals["body.heave_acc"][p, shown], lw=0.9, label=label)
for offset, label in ((0.0, "SH-2"), (1.0, "groundhook")):
    res, p = runs[label]
    shown = (res.time >= window[0]) & (res.time <= window[1])
    state = (res.signals["damping.F1"][p, shown] - C_MIN) / (C_MAX - C_MIN)  # 0 soft, 1 stiff
    axes[2].step(res.time[shown], state + 1.5 * offset, where="post", label=label,
                 color="C1" if label == "SH-2" else "C2")  # fmt: skip
axes[1].set_ylabel("body acceleration [m/s$^2$]")
axes[1].legend(ncol=3)
axes[2].set_yticks([0, 1, 1.5, 2.5], [f"{C_MIN:g}", f"{C_MAX:g}"] * 2)
axes[2].set_ylabel("damping coefficient [N s/m]")
axes[2].set_xlabel("time [s]")
axes[2].set_title("The coefficient each law chose (SH-2 below, groundhook above)")
for label, (res, p) in runs.items():
    print(
        f"{label:14s} r.m.s. body acceleration {res.metrics['rms'][p]:.3f} m/s^2, "
        f"tyre deflection {1e3 * res.metrics['TD.F1'][p]:.2f} mm"
    )

# %%
# Checks against the physics
# --------------------------
# A semi-active damper only changes its coefficient: at every sample the coefficient lies
# between C_min and C_max, and the damper's force opposes the travel rate, so it never
# puts energy into the car (F v >= 0; the tolerance is rounding of a product of order
# 1e3 N x 1 m/s). And a law that never switched would be a passive damper: each law must
# use both coefficients on a random road.
for label in laws:
    res, p = runs[label]
    c = res.signals["damping.F1"][p]
    power = res.signals["damper_force.F1"][p] * res.signals["travel_vel.F1"][p]
    assert np.all((c >= C_MIN - 1e-9) & (c <= C_MAX + 1e-9)), label
    assert power.min() >= -1e-9, (label, power.min())
    assert np.isclose(c, C_MIN).any() and np.isclose(c, C_MAX).any(), label
