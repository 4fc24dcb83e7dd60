"""The compiled loops of the reductions (:mod:`suspopt.loops._compiled`) against the
numpy arithmetic they replace, bit for bit, on hostile signals:

- the pairwise sum against ``np.sum`` for every length a block may have;
- the weighting filter against :meth:`WeightingFilter._apply_numpy` for every weighting, from
  rest and from a state, in pieces down to one sample, over leading shapes of any rank, with
  NaN, infinities and huge values; its state after each piece too;
- the streamed block moments and power sums against their numpy branches;
- an optimisation's objectives and constraints with and without the compiled loops.
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import CONFIGS

import suspopt
import suspopt.loops as metric_loops
from suspopt import streaming
from suspopt.metrics.iso2631 import weighting_filter

pytest.importorskip("numba")
from suspopt.loops import _compiled as _reductions  # noqa: E402  (needs numba)

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


@pytest.fixture
def numpy_only(monkeypatch):
    """The callers' numpy arithmetic: no compiled loops."""
    monkeypatch.setattr(metric_loops, "compiled_reductions", lambda: None)


def _same(a, b) -> bool:
    return np.array_equal(np.asarray(a), np.asarray(b), equal_nan=True)


def test_the_pairwise_sum_is_numpys_for_every_block_length():
    rng = np.random.default_rng(1)
    for n in [*range(0, 300), 511, 512, 513, 1000, 1024, 1500, _reductions.LONGEST]:
        x = rng.standard_normal(n) * 10.0 ** rng.uniform(-6, 6, n)
        assert _reductions._pairwise(x, 0, n) == np.sum(x), n
        if n > 20:  # a run that starts inside the array
            assert _reductions._pairwise(x, 7, n - 9) == np.sum(x[7 : n - 2]), n


@pytest.mark.parametrize("weighting", WEIGHTINGS)
@pytest.mark.parametrize("fs", [500.0, 1000.0, 2000.0])
def test_the_compiled_filter_is_the_numpy_filter_bit_for_bit(weighting, fs):
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
        out_n, state_n = f._apply_numpy(piece, state_n)
        assert _same(out_c, out_n) and _same(state_c[0], state_n[0])
        assert _same(state_c[1], state_n[1])
    whole_c = f.apply(a[:, :t])[0]
    assert _same(whole_c, f._apply_numpy(a[:, :t], f.initial_state((37,)))[0])


def test_the_compiled_filter_keeps_any_leading_shape_and_leaves_the_callers_state():
    f = weighting_filter("Wk", 1000.0)
    rng = np.random.default_rng(3)
    a = _hostile(rng, (2, 3, 5, 300))
    history = rng.standard_normal((2, 3, 5, len(f.numerator) - 1))
    poles = rng.standard_normal((len(f.sections), 2, 3, 5, 2))
    kept = (history.copy(), poles.copy())
    out_c, (h_c, p_c) = f.apply(a, (history, poles))
    out_n, (h_n, p_n) = f._apply_numpy(a, (history, poles))
    assert out_c.shape == a.shape and h_c.shape == history.shape and p_c.shape == poles.shape
    assert _same(out_c, out_n) and _same(h_c, h_n) and _same(p_c, p_n)
    assert _same(history, kept[0]) and _same(poles, kept[1])  # (not written in place)


@pytest.mark.parametrize("T", [1, 7, 255, 256, 257, 700, 1500])
def test_the_streamed_block_sums_are_numpys(T, monkeypatch):
    rng = np.random.default_rng(T)
    x = _hostile(rng, (13, T))
    compiled = streaming._block_moments(x), streaming._power_sums(x)
    monkeypatch.setattr(metric_loops, "compiled_reductions", lambda: None)
    with np.errstate(invalid="ignore", over="ignore"):
        reference = streaming._block_moments(x), streaming._power_sums(x)
    assert [m for m, _, _ in compiled[0]] == [m for m, _, _ in reference[0]]
    for (_, mean_c, m2_c), (_, mean_n, m2_n) in zip(compiled[0], reference[0]):
        assert _same(mean_c, mean_n) and _same(m2_c, m2_n)
    for got, want in zip(compiled[1], reference[1]):
        assert _same(got, want)


def _evaluated(cfg, X):
    problem = suspopt.Problem.from_config(cfg)
    return problem.evaluate(problem.xl + X * (problem.xu - problem.xl),
                            return_values_of=["F", "G"])  # fmt: skip


@pytest.mark.parametrize("name", ["ch5/case1_s1.yaml", "ch6/part_b.yaml"])
def test_an_optimisations_values_are_the_same_bits_without_the_compiled_loops(name, monkeypatch):
    cfg = suspopt.load_config(CONFIGS / name)
    cfg.simulation.duration = 1.2
    monkeypatch.setattr(streaming, "WINDOW_BYTES", 1)  # windows of one block: 5, the last short
    X = np.random.default_rng(5).random((6, len(cfg.design_variables)))
    compiled = _evaluated(cfg, X)
    monkeypatch.setattr(metric_loops, "compiled_reductions", lambda: None)
    reference = _evaluated(cfg, X)
    assert all(_same(a, b) for a, b in zip(compiled, reference))


@pytest.mark.parametrize("rows", [(), (1,), (3,)])
def test_fewer_rows_than_lanes_filter_as_numpy_does(rows):
    """A single record (1-D) and fewer rows than :data:`~_reductions.LANES`: the lanes are
    as many as the rows (no scratch 32 times a long record's size), the same bits."""
    f = weighting_filter("Wd", 800.0)
    a = _hostile(np.random.default_rng(11), (*rows, 2000))
    out_c, (h_c, p_c) = f.apply(a)
    out_n, (h_n, p_n) = f._apply_numpy(a, f.initial_state(rows))
    assert out_c.shape == a.shape and h_c.shape == h_n.shape and p_c.shape == p_n.shape
    assert _same(out_c, out_n) and _same(h_c, h_n) and _same(p_c, p_n)
