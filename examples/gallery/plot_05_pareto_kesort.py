"""
A Pareto front and its k-ε pick
===============================

A small NSGA-II run (Sec 6.1) of the Chapter 8 passive seat (PS) on the quarter car over an
ISO 8608 class A road: the seat's spring ``K_v`` and damper ``C_v`` (Table 8.2's bounds)
traded between the seat's comfort RC_se, its Wk-weighted r.m.s. acceleration (Eq 8.1), and
its static deflection X_ST (Eq 8.2), every design evaluated by the stationary spectral
method (the ``spectral`` template). From the front, :func:`suspopt.kesort` chooses one
design by k-ε optimality (Sec 6.1.1, Eq 6.10-6.12, with ``ε = P max NF``, Eq 6.19, and
``P`` the smallest that leaves one design alone at the top), and
:func:`suspopt.pareto_picks` gives the front's edges and its knee (Fig. 8.21).
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import suspopt
from suspopt.optimisation import optimise

# %%
# The front
# ---------

cfg = suspopt.load_template("spectral")
cfg.optimiser.population = 40
cfg.optimiser.generations = 20  # 800 evaluations: a second or two by the spectral method
with tempfile.TemporaryDirectory() as tmp:
    front = optimise(cfg, Path(tmp) / "front.h5")
X, F, names = front.X, front.F, front.obj_names
print(f"{len(F)} designs on the front; objectives {names} [{', '.join(front.obj_units)}]")

# %%
# The k-ε sort and the Pareto-theory picks
# ----------------------------------------

ke = suspopt.kesort(F, P="auto", names=names)
picks = suspopt.pareto_picks(F, names)
print(f"P = {ke.P:.2f}: design {ke.chosen}, k-eps level {ke.k_eps[ke.chosen]:.3f}")
print("picks:", picks)

fig, (ax, ax_k) = plt.subplots(2, 1, sharex=True, layout="constrained", figsize=(6.4, 7.0))
order = np.argsort(F[:, 1])
ax.plot(1e3 * F[order, 1], F[order, 0], "o-", color="C0", ms=3, lw=0.8, label="front")
ax_k.plot(1e3 * F[order, 1], ke.k_eps[order], "o-", color="C0", ms=3, lw=0.8)
ax.plot(1e3 * F[ke.chosen, 1], F[ke.chosen, 0], "r*", ms=14, label=f"k-ε choice (P = {ke.P:.2f})")
ax_k.plot(1e3 * F[ke.chosen, 1], ke.k_eps[ke.chosen], "r*", ms=14)
for name, marker in (("knee", "s"), (f"best_{names[0]}", "^"), (f"best_{names[1]}", "v")):
    row = picks[name]
    ax.plot(1e3 * F[row, 1], F[row, 0], marker, mfc="none", mec="k", ms=10, label=name)
ax.set_ylabel("seat comfort RC_se [m/s$^2$]")
ax.set_title("PS seat on class A at 120 km/h: NSGA-II front")
ax.legend()
ax_k.set_xlabel("static deflection X_ST [mm]")
ax_k.set_ylabel("k-ε level [-] (Eq 6.10)")
ax_k.set_title("Each design's k-ε level: the choice holds the highest")

# %%
# Checks
# ------
# Every design of the front is non-dominated, the k-ε choice and the picks among them; and a
# linear seat's static deflection is its load over its stiffness, ``X_ST = m g / K_v``
# (Sec 8.2), for every design, to rounding.


def dominated(F, i):
    """Whether some row of F is no worse than row i in every objective and better in one."""
    return bool(np.any(np.all(F[i] >= F, axis=1) & np.any(F[i] > F, axis=1)))


assert not any(dominated(F, i) for i in range(len(F)))
assert not dominated(F, ke.chosen) and ke.unique
assert ke.k_eps[ke.chosen] == ke.k_eps.max()
assert all(not dominated(F, row) for row in picks.values())
K_v = X[:, front.var_names.index("K_v")]
X_ST = F[:, names.index("X_ST")]
load = cfg.seat.mass * cfg.vehicle.gravity  # [N]
assert np.allclose(X_ST * K_v, load, rtol=1e-9)
