"""Spectral estimates: Welch PSD, H1 transfer function, coherence, transmissibility (Sec 2.4.3).

Signals have time on the last axis, ``(T,)`` or ``(P, T)``, sampled at ``fs`` Hz; two-signal
estimates broadcast their leading axes (one input ``(T,)`` against ``P`` outputs ``(P, T)``).
Every function returns ``(f, value)`` with ``f`` in Hz, ``(F,)``, and ``value`` ``(..., F)``.
Estimates are one-sided, Hann-windowed, 50 % overlapped and mean-detrended per segment
(``scipy.signal`` defaults). ``nperseg=None`` uses an eighth of the record (at least 256 samples,
at most the record): about 15 averages, and a resolution of ``8/T_record`` Hz.
:func:`record_psd` is the PSD the figures show (``--plot`` and ``suspopt report``): segments
of :data:`PSD_SEGMENT` seconds, or the whole record when it is shorter.
"""

from __future__ import annotations

import numpy as np

__all__ = ["psd", "record_psd", "PSD_SEGMENT", "transfer_function", "coherence", "transmissibility"]

_MIN_SEGMENT = 256
#: Welch segment of the PSDs the figures show [s] (at most the record): a resolution of
#: 1/8 Hz, fine enough for a body mode of about 1 Hz (as ``analyse models``).
PSD_SEGMENT = 8.0


def _segment(n: int, nperseg: int | None) -> int:
    if nperseg is not None:
        return min(int(nperseg), n)
    return min(n, max(_MIN_SEGMENT, n // 8))


def psd(x: np.ndarray, fs: float, nperseg: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """One-sided Welch power spectral density in (unit of ``x``)²/Hz, e.g. (m/s²)²/Hz.

    Its integral over ``f`` is the variance of ``x`` (mean removed).
    """
    x = np.asarray(x, dtype=float)
    from scipy import signal

    return signal.welch(x, fs, nperseg=_segment(x.shape[-1], nperseg), axis=-1)


def record_psd(
    x: np.ndarray, fs: float, segment: float = PSD_SEGMENT
) -> tuple[np.ndarray, np.ndarray]:
    """The PSD the figures show (:func:`psd`, (unit of ``x``)²/Hz): Welch segments of
    ``segment`` seconds [s], or the whole record when it is shorter, so the frequency spacing
    is ``1/min(segment, T_record)`` Hz (a 3 s record: 0.33 Hz, where :func:`psd`'s default
    eighth of it would give 2.67 Hz and miss a body mode of 1 Hz)."""
    x = np.asarray(x, dtype=float)
    return psd(x, fs, min(x.shape[-1], round(segment * fs)))


def transfer_function(
    x: np.ndarray, y: np.ndarray, fs: float, nperseg: int | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """H1 estimate ``H(f) = P_xy / P_xx`` from input ``x`` to output ``y`` (complex).

    Unit: unit of ``y`` per unit of ``x``. H1 is unbiased by noise on the output.
    """
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    segment = _segment(x.shape[-1], nperseg)
    from scipy import signal

    f, p_xy = signal.csd(x, y, fs, nperseg=segment, axis=-1)
    _, p_xx = signal.welch(x, fs, nperseg=segment, axis=-1)
    return f, p_xy / p_xx


def coherence(
    x: np.ndarray, y: np.ndarray, fs: float, nperseg: int | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Magnitude-squared coherence ``|P_xy|²/(P_xx P_yy)`` between ``x`` and ``y`` (0-1)."""
    x = np.asarray(x, dtype=float)
    from scipy import signal

    return signal.coherence(
        x, np.asarray(y, dtype=float), fs, nperseg=_segment(x.shape[-1], nperseg), axis=-1
    )


def transmissibility(
    input_acc: np.ndarray, output_acc: np.ndarray, fs: float, nperseg: int | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Acceleration transmissibility ``TR = |z̈_i / z̈_input|`` (thesis Eq 2.86), dimensionless.

    Both accelerations in m/s²; estimated as ``|H1|`` (:func:`transfer_function`). Eq 2.86 writes
    the plain ratio; the H1 estimate is its frequency-domain reading for random excitation, e.g.
    seat-to-head transmissibility (STHT) with the head acceleration as output.
    """
    f, h = transfer_function(input_acc, output_acc, fs, nperseg)
    return f, np.abs(h)
