"""
ISO 2631-1 frequency weightings
===============================

The frequency weightings of ISO 2631-1:1997 Annex A that ride comfort is measured with
(Sec 2.4.2): Wk (vertical, seated or standing; the weighting of RC, Eq 2.78), Wd
(horizontal), Wf (motion sickness), Wc (seat back), We (rotational) and Wj (vertical, head
of a recumbent person). Each is a product of second-order stages
(``suspopt.metrics.iso2631.weighting_response``). The time-domain metrics do not use
that analogue response directly: they filter the signal with a recursive digital filter
designed at the signal's sample rate (``suspopt.weighting``). Drawn: the analogue
curves, and the gain the digital filter gives steady sines at 1 kHz.
"""

import matplotlib.pyplot as plt
import numpy as np

from suspopt.metrics.iso2631 import WEIGHTINGS, weight, weighting_response

# %%
# The digital filters on steady sines
# -----------------------------------
# Each weighting filters sines of unit amplitude, one a third of an octave apart from
# 0.1 to 80 Hz, sampled at 1 kHz, all in one batch. After 30 s the filter's start has died
# away (its slowest pole, Wf's 0.08 Hz high-pass, decays as exp(-0.36 t/s)); the gain and
# phase are read off the last 10 s by a least-squares fit of a sine and a cosine, which is
# exact for a steady sine whatever the number of periods.
FS = 1000.0  # [Hz]
tones = 0.1 * 2.0 ** (np.arange(0, 30) / 3.0)  # [Hz], 0.1 to 81
t = np.arange(0.0, 40.0, 1.0 / FS)
last = t >= 30.0
phase = 2 * np.pi * tones[:, None] * t[None, :]  # (tones, samples) [rad]
signals = np.sin(phase)
c, s = np.cos(phase[:, last]), np.sin(phase[:, last])
ss, cc, sc = (s * s).sum(1), (c * c).sum(1), (s * c).sum(1)
gains = {}
for name in WEIGHTINGS:
    out = weight(signals, FS, name)[:, last]
    # out = a sin + b cos = Im(H exp(j w t)) for H = a + j b: the 2 x 2 normal equations
    ys, yc = (out * s).sum(1), (out * c).sum(1)
    det = ss * cc - sc**2
    gains[name] = (ys * cc - yc * sc) / det + 1j * (yc * ss - ys * sc) / det

# %%
# The curves
# ----------

f = np.geomspace(0.1, 400.0, 600)  # [Hz]
fig, ax = plt.subplots(layout="constrained")
for name in WEIGHTINGS:
    ax.semilogx(f, 20 * np.log10(np.abs(weighting_response(f, name))), label=name)
    ax.semilogx(tones, 20 * np.log10(np.abs(gains[name])), "k.", ms=3)
ax.set_xlabel("frequency [Hz]")
ax.set_ylabel("weighting gain [dB]")
ax.set_title("ISO 2631-1 weightings (dots: the digital filters at 1 kHz)")
ax.set_ylim(-50.0, 5.0)
ax.legend(ncol=3)

# %%
# Check: the digital filter is the standard's weighting
# -----------------------------------------------------
# The filters are held to a complex response within 0.1 % of the analogue one up to a
# quarter of the sample rate, here 250 Hz (their design aims at half of it,
# ``suspopt.weighting.TARGET``), and the start has decayed to 1e-4 of its size, so every
# tone's complex gain must be within 0.1 % of ``H(j 2 pi f)``. Where a weighting is below
# -60 dB (1e-3: Wf above 2 Hz) a relative error means nothing, and the check asks for an
# absolute one of 1e-6.
for name in WEIGHTINGS:
    exact = weighting_response(tones, name)
    relevant = np.abs(exact) >= 1e-3
    error = np.abs(gains[name] - exact)
    assert np.all(error[relevant] < 1e-3 * np.abs(exact[relevant])), (name, error / np.abs(exact))
    assert np.all(error[~relevant] < 1e-6), (name, error[~relevant])
