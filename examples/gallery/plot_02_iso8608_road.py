"""
An ISO 8608 road and its spectrum
=================================

An ISO 8608 road of class C: the displacement PSD ``G_d(n) = G_d(n0) (n / n0)^-w`` with
``n0`` = 0.1 cycles/m, waviness ``w`` = 2 and the class's geometric mean
``G_d(n0)`` = 256e-6 m^3 (Eq 2.93, Table 2.4), generated as a sum of harmonics with random
phases (Eq 2.97-2.100, ``suspopt.road.iso8608_harmonics``). The road here takes the
``iso8608`` amplitude convention, whose profile has the standard's PSD; the thesis's
convention (``convention: thesis``, Eq 2.99) gives amplitudes ``1/sqrt(2 pi)`` as large
(see ``docs/iso-facts.md``). The Welch estimate of 1 km of profile is drawn against the
class's PSD line and the band of PSD levels class C spans.
"""

import matplotlib.pyplot as plt
import numpy as np

import suspopt
from suspopt.metrics import psd
from suspopt.road import ISO8608_CLASS_LEVELS, iso8608_level, profile

# %%
# The road of a template, made class C
# ------------------------------------

road = suspopt.load_template("quarter").road
road.road_class = "C"
road.convention = "iso8608"  # the standard's one-sided PSD

LENGTH, STEP = 1000.0, 0.05  # [m]: 1 km of road, heights every 5 cm
s = np.arange(0.0, LENGTH + STEP / 2, STEP)
z = profile(road, s)

N0 = 0.1  # ISO 8608 reference spatial frequency n0 [cycles/m]
G0 = iso8608_level(road)  # G_d(n0) [m^3] of the generated profile
n, G = psd(z, 1.0 / STEP, nperseg=int(100.0 / STEP))  # 100 m segments: 0.01 cycles/m


def line(level, n):
    return level * (n / N0) ** -road.waviness


# %%
# The profile and its PSD
# -----------------------

fig, (ax_z, ax_psd) = plt.subplots(2, 1, layout="constrained", figsize=(6.4, 6.4))
ax_z.plot(s[s <= 200.0], 1e3 * z[s <= 200.0], lw=0.8)
ax_z.set_xlabel("distance along the road [m]")
ax_z.set_ylabel("height [mm]")
ax_z.set_title("ISO 8608 class C road, its first 200 m")

inside = (n >= road.n_min) & (n <= road.n_max)
ax_psd.loglog(n[inside], G[inside], lw=0.8, label="Welch estimate of 1 km")
band = np.geomspace(road.n_min, road.n_max, 50)
ax_psd.loglog(band, line(G0, band), "k", label="class C: $G_d(n_0)(n/n_0)^{-2}$")
ax_psd.fill_between(
    band,
    line(ISO8608_CLASS_LEVELS["B"] * 2, band),  # the class's range: 128e-6 to 512e-6 m^3
    line(ISO8608_CLASS_LEVELS["D"] / 2, band),
    color="0.85",
    label="class C's range",
)
ax_psd.set_xlabel("spatial frequency n [cycles/m]")
ax_psd.set_ylabel("displacement PSD $G_d$ [m$^3$]")
ax_psd.set_title("The road's PSD against the class's")
ax_psd.legend()

# %%
# Checks against the standard
# ---------------------------
# The profile's variance must be the PSD's integral over the generated band,
# ``G_d(n0) n0^2 (1/n_min - 1/n_max)`` for w = 2. Over 1 km the random phases' cross
# terms leave the variance of one road within 0.3 % of it (300 seeds, 0.05 % standard
# deviation: ``suspopt.road.iso8608_harmonics``): 1 % is beyond any seed's spread.
variance = z.var()
integral = G0 * N0**2 * (1.0 / road.n_min - 1.0 / road.n_max)
print(f"variance {variance:.4g} m^2, PSD integral {integral:.4g} m^2")
assert abs(variance / integral - 1.0) < 0.01

# A straight line fitted to the Welch estimate in log-log coordinates, 0.05-2 cycles/m
# (clear of the band's edges, where the estimate's 0.01 cycles/m resolution and its window
# smear the cut), must have the standard's slope -w and level G_d(n0). Each of the 195
# estimates scatters by some 20 % about the line (19 half-overlapping segments); the fit
# averages them, so 0.1 on the slope and 10 % on the level are wide margins that a wrong
# amplitude convention (a factor 2 pi in level) or a wrong waviness would still break.
fit = (n >= 0.05) & (n <= 2.0)
slope, intercept = np.polyfit(np.log(n[fit] / N0), np.log(G[fit]), 1)
print(f"fitted slope {slope:.3f}, level at n0 {np.exp(intercept):.4g} m^3 (G_d(n0) {G0:g})")
assert abs(slope + road.waviness) < 0.1
assert abs(np.exp(intercept) / G0 - 1.0) < 0.1
