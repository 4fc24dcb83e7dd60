"""The ISO 2631-1 weightings as recursive filters (``suspopt.weighting``): accuracy and cost.

Table 1: for each weighting and sample rate, the FIR correction's degree, the largest relative
error of the complex response from 0 Hz to fs/4 against the analogue Annex A product, the
largest absolute error from fs/4 to fs/2, and the design's time (once per process).
Table 2: weighting P records of T samples (white noise, seed 2026, Wk at 1 kHz) by the filter
against the method suspopt used before it (zero-padded FFT, the analogue response applied at the
bins; kept here only as a baseline), best of 5, measured in the same run; with the largest
relative difference of the weighted r.m.s. between the two. Run:
``python benchmarks/bench_weighting.py``. Prints the tables; asserts nothing.
"""

from __future__ import annotations

import math
import platform
import time

import numpy as np
from scipy.fft import irfft, next_fast_len, rfft, rfftfreq

import suspopt
from suspopt.metrics.iso2631 import WEIGHTINGS, weight, weighting_response
from suspopt.weighting import design

RATES = (100.0, 200.0, 500.0, 1000.0, 2000.0, 4000.0)


def fft_baseline(a: np.ndarray, fs: float, name: str) -> np.ndarray:
    """The earlier method: zero padding until the high-pass's poles (Q = 1/√2, the slowest of
    Wk's) have decayed by 1e-8."""
    slowest = 2 * math.pi * WEIGHTINGS[name].f1 / math.sqrt(2)
    padding = math.ceil(math.log(1e8) / slowest * fs)
    m = next_fast_len(a.shape[-1] + padding, real=True)
    spectrum = rfft(a, m, axis=-1) * weighting_response(rfftfreq(m, 1 / fs), name)
    return irfft(spectrum, m, axis=-1)[..., : a.shape[-1]]


def best(call, repeat: int = 5) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return min(times)


def accuracy_table() -> None:
    print("| weighting | fs [Hz] | M | rel. error 0-fs/4 | abs. error fs/4-fs/2 | design [ms] |")
    print("|---|---|---|---|---|---|")
    for name in WEIGHTINGS:
        for fs in RATES:
            design.cache_clear()
            start = time.perf_counter()
            flt = design(name, fs)
            took = (time.perf_counter() - start) * 1e3
            print(
                f"| {name} | {fs:g} | {len(flt.numerator) - 1} | {flt.error:.1e} | "
                f"{flt.out_of_band:.1e} | {took:.0f} |"
            )


def cost_table() -> None:
    rng = np.random.default_rng(2026)
    fs = 1000.0
    design("Wk", fs)
    print("| P × T | FFT [ms] | recursive [ms] | FFT / recursive | r.m.s. rel. difference |")
    print("|---|---|---|---|---|")
    for P, T in ((1, 15_000), (100, 15_000), (1000, 1_500), (1000, 15_000)):
        a = rng.standard_normal((P, T))
        t_fft = best(lambda a=a: fft_baseline(a, fs, "Wk"))
        t_rec = best(lambda a=a: weight(a, fs, "Wk"))
        rms_fft = np.sqrt(np.mean(fft_baseline(a, fs, "Wk") ** 2, axis=-1))
        rms_rec = np.sqrt(np.mean(weight(a, fs, "Wk") ** 2, axis=-1))
        print(
            f"| {P} × {T} | {t_fft * 1e3:.1f} | {t_rec * 1e3:.1f} | {t_fft / t_rec:.2f} | "
            f"{np.max(np.abs(rms_rec / rms_fft - 1)):.1e} |"
        )


def main() -> None:
    print(
        f"suspopt {suspopt.__version__} | Python {platform.python_version()} | "
        f"numpy {np.__version__} | {platform.machine()}"
    )
    accuracy_table()
    print()
    cost_table()


if __name__ == "__main__":
    main()
