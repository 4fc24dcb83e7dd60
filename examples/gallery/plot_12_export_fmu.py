"""
A design as an FMU, run in FMPy
===============================

A chosen suspension leaves suspopt for the simulators an engineer's team already runs
(Simulink, OpenModelica, Dymola, a HIL rig) as an FMU: FMI 2.0, model exchange and
co-simulation, generated as C source from the design's own element network and compiled
for this machine (docs/guide/export-fmu.md). This script exports the ``quarter`` template's
quarter car (Table 3.1) with its ISO 8608 class B road built in (``road="embedded"``),
simulates the FMU in FMPy in co-simulation, where it steps with suspopt's own RK4, and in
model exchange with FMPy's CVode, and draws both against ``suspopt.simulate`` of the same
config.
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from fmpy import simulate_fmu
from fmpy.validation import validate_fmu

import suspopt
from suspopt.fmu import export_fmu

# %%
# The design and its FMU
# ----------------------
# The template's quarter car, for two seconds of its 24 m/s drive over class B. The FMU
# takes the config's road with it, so that it alone reproduces the run.

cfg = suspopt.load_template("quarter")
cfg.simulation.duration = 2.0  # [s]
folder = Path(tempfile.mkdtemp())
done = export_fmu(cfg, folder / "quarter.fmu", road="embedded")
print(
    f"{done.path.name}: {done.binary or 'source-only'}, {done.outputs} outputs, "
    f"{done.tunable} tunable parameters"
)
assert validate_fmu(str(done.path)) == []  # FMPy finds nothing wrong with it

# %%
# Co-simulation and model exchange
# --------------------------------
# In co-simulation the FMU integrates itself at the config's dt; in model exchange CVode
# integrates the FMU's equations of motion. Both are compared with suspopt's own run.

result = suspopt.simulate(cfg)
dt = cfg.simulation.dt
cosim = simulate_fmu(str(done.path), output_interval=dt)
exchange = simulate_fmu(
    str(done.path), fmi_type="ModelExchange", output_interval=dt, relative_tolerance=1e-8
)
last = np.r_[exchange["time"][1:] != exchange["time"][:-1], True]  # (one row per instant)

fig, axes = plt.subplots(2, 1, figsize=(7, 5.5), sharex=True, layout="constrained")
for ax, name in zip(axes, ("body.heave_acc", "tyre_deflection.F1")):
    reference = result.signals[name][0]
    ax.plot(result.time, reference, color="0.6", lw=3, label="suspopt simulate")
    ax.plot(cosim["time"], cosim[name], "C0", lw=1, label="FMU, co-simulation (RK4)")
    ax.plot(
        exchange["time"][last],
        exchange[name][last],
        "C3--",
        lw=1,
        label="FMU, model exchange (CVode)",
    )
    ax.set_ylabel(f"{name} [{result.signal_unit(name)}]")
    error = np.abs(cosim[name] - reference).max() / np.abs(reference).max()
    ax.set_title(f"{name}: co-simulation within {error:.1e} of suspopt's peak", fontsize=9)
    assert error < 1e-9  # the same RK4 steps on the same road
axes[0].legend(fontsize=8, loc="upper right")
axes[1].set_xlabel("time [s]")
plt.show()
