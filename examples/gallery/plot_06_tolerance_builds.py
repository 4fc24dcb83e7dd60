"""
Tolerance builds
================

A front's designs are drawings: the seat that gets built has a spring and a damper somewhere
inside their tolerance bands, each off by an amount nobody chose. Here the front of the
Chapter 8 passive seat (the ``spectral`` template: RC_se, Eq 8.1, against X_ST, Eq 8.2, on
ISO 8608 class A) is optimised with the spring ``K_v`` toleranced to ±5 % and the damper
``C_v`` to ±15 %, and three of its designs, the two edges and the knee (Fig. 8.21), are
each built 200 times with every part off at once, drawn uniformly within its band
(``suspopt.analyse.builds.builds``, what ``suspopt analyse builds`` runs). The thesis
has no such analysis. Drawn: the builds' objectives around the front.
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import yaml

import suspopt
from suspopt.analyse.builds import builds
from suspopt.choosing.picks import read_front
from suspopt.optimisation import optimise

# %%
# A front with toleranced parts
# -----------------------------
# The tolerances belong to the design variables (``design_variables[i].tolerance`` [%]).
# The analysis re-reads the config stored in the front's file, which is the YAML text the
# config was loaded from: the edited config is written out and loaded again, so that the
# file holds the edits.

cfg = suspopt.load_template("spectral")
cfg.optimiser.population = 40
cfg.optimiser.generations = 20
TOLERANCE = {"K_v": 5.0, "C_v": 15.0}  # [%]
for variable in cfg.design_variables:
    variable.tolerance = TOLERANCE[variable.name]

picks = ["best_RC_se", "knee", "best_X_ST"]
with tempfile.TemporaryDirectory() as tmp:
    case = Path(tmp) / "case.yaml"
    case.write_text(yaml.safe_dump(cfg.model_dump(mode="json"), sort_keys=False))
    cfg = suspopt.load_config(case)
    front = optimise(cfg, Path(tmp) / "front.h5")
    pareto = read_front(front.path, picks)
    built = builds(pareto, samples=200, seed=1)  # 600 builds, one evaluation

# %%
# The builds around the front
# ---------------------------

fig, ax = plt.subplots(layout="constrained")
order = np.argsort(front.F[:, 1])
ax.plot(1e3 * front.F[order, 1], front.F[order, 0], "k.-", lw=0.8, ms=3, label="front")
for d, name in enumerate(picks):
    F = built.F[:, d, :]
    ax.plot(1e3 * F[:, 1], F[:, 0], ".", ms=3, alpha=0.5, label=f"{name}: 200 builds")
ax.set_xlabel("static deflection X_ST [mm]")
ax.set_ylabel("seat comfort RC_se [m/s$^2$]")
ax.set_title("K_v ±5 %, C_v ±15 %: where the built seats land")
ax.legend()

low, high = built.percentiles(built.change)[[0, 2]]
for d, name in enumerate(picks):
    spread = ", ".join(
        f"{obj} {low[d, j]:+.1f} to {high[d, j]:+.1f} %" for j, obj in enumerate(pareto.obj_names)
    )
    print(f"{name:10s} 5-95 % of the builds: {spread}; feasible {built.feasible[:, d].mean():.0%}")

# %%
# Checks
# ------
# Every part of every build lies within its tolerance band about its design's value (to
# rounding), and the builds fill the band: 200 uniform draws all miss the outer quarter of
# one side of a band with probability 0.875^200, about 3e-12.
# And a built linear seat's static deflection is still its load over its built stiffness,
# ``X_ST = m g / K_v`` (Sec 8.2), so X_ST's spread is exactly K_v's.
t = built.tolerance / 100.0  # (n,)
offset = built.X / pareto.X[None, :, :] - 1.0  # (samples, designs, variables)
assert np.all(np.abs(offset) <= t * (1.0 + 1e-12)), "a build outside its band"
assert np.all(offset.max(axis=0) > 0.75 * t) and np.all(offset.min(axis=0) < -0.75 * t)
K_v = built.X[..., pareto.var_names.index("K_v")]
X_ST = built.F[..., pareto.obj_names.index("X_ST")]
assert np.allclose(X_ST * K_v, cfg.seat.mass * cfg.vehicle.gravity, rtol=1e-9)
