"""The streamed metrics' one arithmetic (:mod:`suspopt.loops._compiled`) against independent
references, on hostile signals:

- the weighting filter against its FIR written here in numpy and ``scipy.signal.sosfilt``,
  bit for bit, for every weighting, from rest and from a state, in pieces down to one sample,
  over leading shapes of any rank, with NaN, infinities and huge values; its state after each
  piece too;
- the moments and the weighted power sums against numpy's statistics to rounding, and in
  pieces against the whole record bit for bit;
- the kernel's reductions call the same steps: a signal the compiled kernel forms itself has
  the bits of the same samples reduced in memory.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import sosfilt

from suspopt.metrics.iso2631 import power_state, weighted_value, weighting_filter
from suspopt.metrics.stats import moment_value, moments

WEIGHTINGS = ("Wk", "Wd", "Wf", "Wc", "We", "Wj")
#: numpy's warnings on the hostile values (NaN, infinities), which both sides propagate
pytestmark = pytest.mark.filterwarnings("ignore:(invalid value|overflow):RuntimeWarning")


def _hostile(rng, shape) -> np.ndarray:
    """Values over twelve decades with both signs, a NaN, both infinities and a huge one."""
    x = rng.standard_normal(shape) * 10.0 ** rng.uniform(-6, 6, shape)
    flat = x.reshape(-1)
    if flat.size >= 8:
        flat[[1, 3, 5, 7]] = [np.nan, np.inf, -np.inf, 1e300]
    return x


def _reference(f, a, state):
    """The weighting filter by numpy and scipy: the FIR as the sum of shifted copies in its
    fixed order, then ``sosfilt`` with its state."""
    history, poles = state
    m, n = len(f.numerator) - 1, a.shape[-1]
    x = np.concatenate([history, a], axis=-1)
    out = f.numerator[0] * x[..., m:]
    for k, c in enumerate(f.numerator[1:], start=1):
        out = out + c * x[..., m - k : m - k + n]
    out, poles = sosfilt(f.sections, out, axis=-1, zi=poles)
    return out, (x[..., x.shape[-1] - m :], poles)


def _same(a, b) -> bool:
    return np.array_equal(np.asarray(a), np.asarray(b), equal_nan=True)


@pytest.mark.parametrize("weighting", WEIGHTINGS)
@pytest.mark.parametrize("fs", [500.0, 1000.0, 2000.0])
def test_the_filter_is_numpy_and_scipys_filter_bit_for_bit(weighting, fs):
    f = weighting_filter(weighting, fs)
    rng = np.random.default_rng(len(weighting) + int(fs))
    m, s = len(f.numerator) - 1, len(f.sections)
    # 37 rows: one group of lanes and a part-filled one
    a = _hostile(rng, (37, 700))
    start = (rng.standard_normal((37, m)), rng.standard_normal((s, 37, 2)))
    state_c = state_n = start
    t = 0
    for width in (1, m - 1, 3, 256, 1, 440 - m):  # pieces shorter and longer than the FIR
        piece = a[:, t : t + width]
        t += width
        out_c, state_c = f.apply(piece, state_c)
        out_n, state_n = _reference(f, piece, state_n)
        assert _same(out_c, out_n) and _same(state_c[0], state_n[0])
        assert _same(state_c[1], state_n[1])
    whole_c = f.apply(a[:, :t])[0]
    assert _same(whole_c, _reference(f, a[:, :t], f.initial_state((37,)))[0])


def test_the_filter_keeps_any_leading_shape_and_leaves_the_callers_state():
    f = weighting_filter("Wk", 1000.0)
    rng = np.random.default_rng(3)
    a = _hostile(rng, (2, 3, 5, 300))
    history = rng.standard_normal((2, 3, 5, len(f.numerator) - 1))
    poles = rng.standard_normal((len(f.sections), 2, 3, 5, 2))
    kept = (history.copy(), poles.copy())
    out_c, (h_c, p_c) = f.apply(a, (history, poles))
    out_n, (h_n, p_n) = _reference(f, a, (history, poles))
    assert out_c.shape == a.shape and h_c.shape == history.shape and p_c.shape == poles.shape
    assert _same(out_c, out_n) and _same(h_c, h_n) and _same(p_c, p_n)
    assert _same(history, kept[0]) and _same(poles, kept[1])  # (not written in place)


@pytest.mark.parametrize("rows", [(), (1,), (3,)])
def test_fewer_rows_than_lanes_filter_as_the_reference_does(rows):
    """A single record (1-D) and fewer rows than :data:`~_compiled.LANES`: the lanes are as
    many as the rows (no scratch 32 times a long record's size), the same bits."""
    f = weighting_filter("Wd", 800.0)
    a = _hostile(np.random.default_rng(11), (*rows, 2000))
    out_c, (h_c, p_c) = f.apply(a)
    out_n, (h_n, p_n) = _reference(f, a, f.initial_state(rows))
    assert out_c.shape == a.shape and h_c.shape == h_n.shape and p_c.shape == p_n.shape
    assert _same(out_c, out_n) and _same(h_c, h_n) and _same(p_c, p_n)


@pytest.mark.parametrize("T", [1, 7, 255, 256, 257, 700, 1500])
def test_the_moments_and_power_sums_are_numpys_to_rounding_and_pieces_the_whole(T):
    rng = np.random.default_rng(T)
    x = rng.standard_normal((37, T)) * 3.0 + 1.5
    state = moments(x)
    for statistic, reference in (
        ("var", np.var(x, axis=-1)),
        ("std", np.std(x, axis=-1)),
        ("mean", np.mean(x, axis=-1)),
        ("rms", np.sqrt(np.mean(np.square(x), axis=-1))),
    ):
        assert np.allclose(moment_value(statistic, state), reference, rtol=1e-13, atol=0)
    assert _same(moment_value("max", state), np.max(x, axis=-1))
    assert _same(moment_value("min", state), np.min(x, axis=-1))
    sums = power_state(x)
    assert np.allclose(
        weighted_value("rms_weighted", sums, 100.0), np.sqrt(np.mean(x**2, axis=-1)), rtol=1e-13
    )
    assert np.allclose(
        weighted_value("vdv", sums, 100.0), (np.sum(x**4, axis=-1) / 100.0) ** 0.25, rtol=1e-13
    )
    assert _same(sums[2], np.max(np.abs(x), axis=-1))
    cut = [0, 1, min(T, 256), min(T, 300), T]  # (pieces across a block's end)
    moment, powered = None, None
    for a, b in zip(cut[:-1], cut[1:]):
        if b > a:
            moment, powered = moments(x[:, a:b], moment), power_state(x[:, a:b], powered)
    assert all(_same(u, v) for u, v in zip(moment, state))
    assert _same(powered[1], sums[1]) and _same(powered[2], sums[2])


def test_a_nan_or_an_infinity_stays_as_numpy_keeps_it():
    x = _hostile(np.random.default_rng(5), (4, 300))
    x[2] = np.linspace(-1, 1, 300)
    x[3] = 0.0
    x[3, 10] = np.nan
    state, sums = moments(x), power_state(x)
    assert _same(moment_value("max", state), np.max(x, axis=-1))
    assert _same(moment_value("min", state), np.min(x, axis=-1))
    assert np.isnan(moment_value("var", state)[[0, 3]]).all()
    assert _same(sums[2], np.max(np.abs(x), axis=-1))
    assert np.isfinite(weighted_value("rms_weighted", sums, 1.0)[2])


def test_the_kernels_reductions_are_the_steps_of_the_metrics():
    """The kernel's ``accumulate`` and the lane loop generated for a network call the steps of
    :mod:`suspopt.loops._compiled` by name: none spells their arithmetic again."""
    import inspect

    from suspopt.integrator import _accumulate

    text = inspect.getsource(_accumulate.accumulate) + inspect.getsource(_accumulate._weigh)
    generated = _accumulate.source(np.array([1, 0, 1, 256, 0, 0, 1, 1, 5]), 2, 2, 16)
    for body in (text, generated):
        for step in ("welford(", "extremes(", "tap(", "section(", "powers(", "carry("):
            assert step in body, step
        assert "d * (" not in body and "* sq" not in body  # (Welford's, the fourth powers)
