"""
A metric of your own: the body's peak jerk
==========================================

Passengers feel a sudden change of acceleration, the jerk, as a knock even where the
acceleration itself is small. suspopt has no jerk metric; this script writes one, the largest
``|Δa| / Δt`` of a signal over the run, registers it with ``@suspopt.metric`` and then uses
it by name in the optimisation as if it were built in: an NSGA-II run (Sec 6.1) of the
Chapter 5 half car (Table 5.1, Duffing springs) over the half-sine bump of Sec 5.1.3 trades
the body's acceleration variance f1 (Eq 5.4) against its peak jerk
(docs/guide/custom-metrics.md).
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import suspopt
from suspopt.optimisation import optimise

# %%
# The metric
# ----------
# A function of a signal's samples ``x`` (P designs by T samples, SI units) and the sample
# times ``t`` [s] that returns one value per design, for the whole batch at once. Its unit
# is a function of the signal's: the jerk of an acceleration in m/s^2 is in (m/s^2)/s.


@suspopt.metric(name="peak_jerk", unit=lambda u: f"({u})/s", description="largest jerk")
def peak_jerk(x, t):
    return np.abs(np.diff(x, axis=-1)).max(axis=-1) / (t[1] - t[0])


# %%
# The front
# ---------
# The ``optimise`` template's half car and design variables (Table 5.2's bounds), its
# constraints (RC_s <= 0.8 m/s^2, the spring usage of Eq 5.3 between 0.1 and 0.3), the
# custom metric as a second objective, and a small budget.

cfg = suspopt.load_template("optimise")
cfg.simulation.duration = 1.5  # [s]: the bump at 0.5 s and the body's first second after it
cfg.objectives.main = [
    {"name": "f1", "metric": "var", "signal": "body.heave_acc"},
    {"name": "jerk", "metric": "peak_jerk", "signal": "body.heave_acc"},
]
cfg.objectives.supplementary = []
cfg.optimiser.algorithm = "nsga2"
cfg.optimiser.population = 20
cfg.optimiser.generations = 10
with tempfile.TemporaryDirectory() as tmp:
    front = optimise(cfg, Path(tmp) / "front.h5")
F, names, units = front.F, front.obj_names, front.obj_units
print(f"{len(F)} designs on the front; objectives {names} [{', '.join(units)}]")

fig, ax = plt.subplots(layout="constrained")
order = np.argsort(F[:, 0])
ax.plot(F[order, 0], F[order, 1], "o-", ms=4, lw=0.8)
ax.set_xlabel(f"body acceleration variance f1 [{units[0]}] (Eq 5.4)")
ax.set_ylabel(f"body peak jerk [{units[1]}]")
ax.set_title("Half car over a bump: comfort against the custom jerk metric")

# %%
# Checks
# ------
# The front's jerk is the function above of the body's heave acceleration, as a plain
# ``simulate`` of the same designs gives it, and its unit is the one registered.

assert units == ["(m/s^2)^2", "(m/s^2)/s"] and len(F) >= 2
params = {v.path: front.X[:, j] for j, v in enumerate(cfg.design_variables)}
again = suspopt.simulate(cfg, params=params)
expected = peak_jerk(again.signals["body.heave_acc"], again.time)
assert np.allclose(F[:, 1], expected, rtol=1e-9), (F[:, 1], expected)
assert np.allclose(F[:, 0], again.signals["body.heave_acc"].var(axis=-1), rtol=1e-9)
