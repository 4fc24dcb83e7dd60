"""
A robust front
==============

The Chapter 8 passive seat (PS) designed for the worst of nine scenarios, the ``robust``
template: ISO 8608 classes A, B and C, each at its Sec 8.1.2 speed (120, 85 and 50 km/h),
times 75, 95 and 115 kg on the seat (Sec 8.4.3's 95 ± 20 kg). NSGA-II minimises the worst
RC_se (Eq 8.1) and the worst X_ST (Eq 8.2) over the scenarios (``over_scenarios: max``),
each design evaluated under all nine in one batch per road
(``suspopt.optimisation.scenarios``) by the spectral method. The thesis optimises on one
road with one passenger (class A, 95 kg): that nominal front is run too, and each front's
designs are evaluated the other way, so that both are drawn in nominal and in worst-case
terms.
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import suspopt
from suspopt.analyse.scenarios import read_scenarios
from suspopt.optimisation import optimise

# %%
# The robust and the nominal fronts
# ---------------------------------

robust = suspopt.load_template("robust")
nominal = robust.model_copy(deep=True)
nominal.scenarios = None  # the config alone: class A at 120 km/h, 95 kg

with tempfile.TemporaryDirectory() as tmp:
    robust_front = optimise(robust, Path(tmp) / "robust.h5")
    _, scenarios, FS, _ = read_scenarios(Path(tmp) / "robust.h5")  # (N, S, m) per scenario
    nominal_front = optimise(nominal, Path(tmp) / "nominal.h5")

# each front's designs the other way: one evaluation each
problems = {
    "nominal": suspopt.Problem.from_config(nominal),
    "worst": suspopt.Problem.from_config(robust),
}
values = {
    (front, terms): problems[terms].evaluate(
        problems[terms].to_search(result.X), return_values_of=["F"]
    )
    for front, result in (("nominal", nominal_front), ("robust", robust_front))
    for terms in problems
}
print(f"scenarios: {', '.join(scenarios)}")
print(f"nominal front {len(nominal_front.X)} designs, robust front {len(robust_front.X)}")

# %%
# Both fronts, both ways
# ----------------------

fig, axes = plt.subplots(1, 2, layout="constrained", figsize=(9.0, 4.2))
for ax, terms in zip(axes, ("nominal", "worst")):
    for front, style in (("nominal", "o"), ("robust", "s")):
        F = values[front, terms]
        order = np.argsort(F[:, 1])
        ax.plot(1e3 * F[order, 1], F[order, 0], style + "-", ms=3.5, lw=0.8,
                label=f"{front} front")  # fmt: skip
    ax.set_xlabel("static deflection X_ST [mm]")
    ax.set_ylabel("seat comfort RC_se [m/s$^2$]")
limit = next(c.max for c in robust.constraints if c.name == "X_ST")  # [m]
axes[1].axvline(1e3 * limit, color="0.5", ls=":", label="X_ST limit, every scenario")
axes[0].set_title("nominal: class A, 95 kg")
axes[1].set_title("worst of classes A-C x 75/95/115 kg")
axes[1].legend()

# %%
# Checks
# ------
# The robust front's objectives are the worst of its designs' nine scenario values, and the
# nominal scenario is one of the nine: the file's value under "A/95kg" is the nominal
# config's for the same design (the spectral method's relative tolerance is 1e-6). And a
# linear seat's worst static deflection is that under the heaviest load,
# ``X_ST = m g / K_v`` with m = 115 kg (Sec 8.2), which the constraint keeps within its
# limit for every design of the robust front.
assert np.allclose(robust_front.F, FS.max(axis=1), rtol=0.0, atol=0.0)
assert np.allclose(FS[:, scenarios.index("A/95kg"), :], values["robust", "nominal"], rtol=1e-5)
K_v = robust_front.X[:, robust_front.var_names.index("K_v")]
heaviest = max(s.load_mass for s in robust.scenarios.product[1])
X_ST = robust_front.F[:, robust_front.obj_names.index("X_ST")]
assert np.allclose(X_ST * K_v, heaviest * robust.vehicle.gravity, rtol=1e-9)
assert np.all(limit >= X_ST)
