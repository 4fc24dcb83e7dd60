"""The kernel's streamed reductions (:mod:`.accumulators`): each signal the kernel computes,
sample by sample, and its running statistics, lane by lane, as the integration runs.

:func:`accumulate` runs where the kernel flushes a block's buffered samples
(:func:`._kernel._advance`): for each of those samples it forms every signal as its constant
plus its terms in turn (``e + c_1 x_1 + c_2 x_2 + ...``: rows of the buffered samples or the
road's inputs at that instant), then

- its moments and extremes, the weighting filter of each (signal, weighting) pair, the
  pair's sums of ``a_w²`` and ``a_w⁴`` (over each block of ``SUM_BLOCK`` samples, carried
  into their totals at the block's end) and its largest ``|a_w|``: each by the step that
  every engine and the whole-record metrics use (:mod:`suspopt.loops._compiled`:
  :func:`~suspopt.loops._compiled.welford` with ``1/j`` computed once per sample,
  :func:`~suspopt.loops._compiled.extremes`, :func:`~suspopt.loops._compiled.tap`,
  :func:`~suspopt.loops._compiled.section`, :func:`~suspopt.loops._compiled.powers`,
  :func:`~suspopt.loops._compiled.carry`), compiled into the lane loops.

``red = (ri, coef, acc, filt, zs)``: ``ri`` the indices (``[S, K, Wn, SUM_BLOCK]``, then
``(signal, source)`` of each of the K terms, then ``(signal, filter offset, M, sections,
first row)`` of each of the Wn pairs); ``coef (blocks, K + S, B)`` the terms' coefficients
then the signals' constants; ``acc (blocks, rows, B)`` each signal's value, mean, M2,
largest and smallest value (5 rows), then each pair's FIR history (M, the latest first), its
sections' states (2 per section) and the :data:`PER_PAIR` rows; ``filt`` every pair's
numerator then sections (6 per section); ``zs (J, 2 n_u, G)`` the road's inputs (heights,
then rates) at every sample under each of the G roads.
A term's source ``m >= 0`` is row ``m`` of the buffer (:func:`._kernel._keep`), ``m < 0``
the road input ``-m - 1`` under the lane's road. With ``S = 0`` nothing is done.

On the fused path (:mod:`._fused`: blocks of :data:`._fused.LANES` designs, one road) the
kernel calls instead a function generated for the accumulators' structure (:func:`fused`,
:func:`source`): the same steps, called by name, in the same order, each sample's whole work in one
loop over the lanes with every row's offset a constant, which the compiler vectorises (the
general loops above pay a loop's set-up and overlap checks per operation, 16 lanes at a
time). Both give the same bits (``tests/test_accumulators.py``). Only integers from the
indices reach the source; the filters' coefficients are read from ``filt``.
"""

from __future__ import annotations

import numba
import numpy as np

from .. import _numba_cache
from ..loops._compiled import carry, extremes, powers, section, tap, welford
from . import _fused

_numba_cache.prepare()  # (cached for the machine, damaged files compiled again: suspopt._numba_cache)

__all__ = ["accumulate", "fused", "summed", "source", "ACCUMULATE", "PER_SIGNAL", "PER_PAIR"]

#: Rows of ``acc`` per signal: its value, mean, M2, largest and smallest value.
PER_SIGNAL = 5
#: Rows of ``acc`` per weighted pair besides its filter's state: the weighted sample, the
#: block's and the total sum of squares, the same of fourth powers, the largest ``|a_w|``.
PER_PAIR = 6


@numba.njit(cache=True, nogil=True)
def accumulate(rec, j0, count, lr, blk, state):
    """Samples ``j0 .. j0 + count - 1`` (rows ``0 .. count - 1`` of ``rec (SAMPLES, rows,
    B)``) into block ``blk``'s accumulators (``state[6:]`` is ``red``); ``lr (B,)`` the road
    of each lane."""
    ri, coef, acc, filt, zs = state[6], state[7][blk], state[8][blk], state[9], state[10]
    S, K, Wn, sum_block = ri[0], ri[1], ri[2], ri[3]
    if S == 0:
        return
    B = rec.shape[2]
    for t in range(count):
        j = j0 + t
        for s in range(S):
            o = PER_SIGNAL * s
            for b in range(B):
                acc[o, b] = coef[K + s, b]
        for k in range(K):
            o, m = PER_SIGNAL * ri[4 + 2 * k], ri[5 + 2 * k]
            if m >= 0:
                for b in range(B):
                    acc[o, b] = acc[o, b] + coef[k, b] * rec[t, m, b]
            else:
                for b in range(B):
                    acc[o, b] = acc[o, b] + coef[k, b] * zs[j, -m - 1, lr[b]]
        w = 1.0 / (j + 1)
        for s in range(S):
            o = PER_SIGNAL * s
            for b in range(B):
                x = acc[o, b]
                acc[o + 1, b], acc[o + 2, b] = welford(x, w, acc[o + 1, b], acc[o + 2, b])
                acc[o + 3, b], acc[o + 4, b] = extremes(x, acc[o + 3, b], acc[o + 4, b])
        for p in range(Wn):
            q = 4 + 2 * K + 5 * p
            _weigh(acc, filt, ri[q], ri[q + 1], ri[q + 2], ri[q + 3], ri[q + 4], B)
            if (j + 1) % sum_block == 0:
                r = ri[q + 4] + ri[q + 2] + 2 * ri[q + 3] + 1
                for b in range(B):
                    acc[r, b], acc[r + 1, b] = carry(acc[r, b], acc[r + 1, b])
                    acc[r + 2, b], acc[r + 3, b] = carry(acc[r + 2, b], acc[r + 3, b])


@numba.njit(cache=True, nogil=True, inline="always")
def _weigh(acc, filt, s, f, M, NS, r, B):
    """One sample of signal ``s`` through its pair's filter (numerator ``filt[f : f + M +
    1]``, then ``NS`` sections; its state from row ``r`` of ``acc``) into its sums, each
    operation over the lanes."""
    v, y = PER_SIGNAL * s, r + M + 2 * NS  # (the signal's row, the weighted sample's)
    c = filt[f]
    for b in range(B):
        acc[y, b] = tap(0.0, c, acc[v, b])
    for k in range(1, M + 1):
        c = filt[f + k]
        for b in range(B):
            acc[y, b] = tap(acc[y, b], c, acc[r + k - 1, b])
    for k in range(M - 1, 0, -1):
        for b in range(B):
            acc[r + k, b] = acc[r + k - 1, b]
    if M:
        for b in range(B):
            acc[r, b] = acc[v, b]
    for i in range(NS):
        o, z = f + M + 1 + 6 * i, r + M + 2 * i
        b0, b1, b2, a1, a2 = filt[o], filt[o + 1], filt[o + 2], filt[o + 4], filt[o + 5]
        for b in range(B):
            acc[y, b], acc[z, b], acc[z + 1, b] = section(
                acc[y, b], acc[z, b], acc[z + 1, b], b0, b1, b2, a1, a2
            )
    for b in range(B):
        acc[y + 1, b], acc[y + 3, b], acc[y + 5, b] = powers(
            acc[y, b], acc[y + 1, b], acc[y + 3, b], acc[y + 5, b]
        )


#: The generated function's C signature: ``accumulate(rec, acc, coef, filt, zs, j0, count)``,
#: the arrays as pointers to a block's buffer, accumulators and coefficients, the filters'
#: coefficients and the road inputs (one road).
ACCUMULATE = (
    "void(CPointer(float64), CPointer(float64), CPointer(float64), CPointer(float64), "
    "CPointer(float64), int64, int64)"
)


def _lines(ri: np.ndarray, rows: int, inputs: int, L: int) -> tuple[list[str], list[str]]:
    """The generated function's lines per lane (one sample) and at a block's end, for the
    indices ``ri``, a buffer of ``rows`` rows and ``inputs`` road inputs, ``L`` lanes."""
    i = [int(v) for v in ri]
    S, K, Wn = i[0], i[1], i[2]

    def a(row: int) -> str:
        return f"acc[{row * L} + b]"

    lines = [f"v{s} = coef[{(K + s) * L} + b]" for s in range(S)]
    for k in range(K):
        s, m = i[4 + 2 * k], i[5 + 2 * k]
        x = f"rec[base + {m * L} + b]" if m >= 0 else f"zs[j * {inputs} + {-m - 1}]"
        lines.append(f"v{s} = v{s} + coef[{k * L} + b] * {x}")
    for s in range(S):
        o = PER_SIGNAL * s
        lines += [
            f"{a(o + 1)}, {a(o + 2)} = welford(v{s}, w, {a(o + 1)}, {a(o + 2)})",
            f"{a(o + 3)}, {a(o + 4)} = extremes(v{s}, {a(o + 3)}, {a(o + 4)})",
        ]
    ends = []
    for p in range(Wn):
        s, f, M, NS, r = i[4 + 2 * K + 5 * p : 9 + 2 * K + 5 * p]
        y, top = f"y{p}", r + M + 2 * NS
        lines.append(f"{y} = tap(0.0, filt[{f}], v{s})")
        lines += [f"{y} = tap({y}, filt[{f + k}], {a(r + k - 1)})" for k in range(1, M + 1)]
        lines += [f"{a(r + k)} = {a(r + k - 1)}" for k in range(M - 1, 0, -1)]
        lines += [f"{a(r)} = v{s}"] if M else []
        for q in range(NS):
            o, z = f + M + 1 + 6 * q, r + M + 2 * q
            coefficients = ", ".join(f"filt[{o + c}]" for c in (0, 1, 2, 4, 5))
            lines.append(
                f"{y}, {a(z)}, {a(z + 1)} = section({y}, {a(z)}, {a(z + 1)}, {coefficients})"
            )
        lines.append(
            f"{a(top + 1)}, {a(top + 3)}, {a(top + 5)} = "
            f"powers({y}, {a(top + 1)}, {a(top + 3)}, {a(top + 5)})"
        )
        ends += [
            f"{a(top + 1)}, {a(top + 2)} = carry({a(top + 1)}, {a(top + 2)})",
            f"{a(top + 3)}, {a(top + 4)} = carry({a(top + 3)}, {a(top + 4)})",
        ]
    return lines, ends


def source(ri: np.ndarray, rows: int, inputs: int, L: int) -> str:
    """The module of the generated :func:`accumulate` (module docstring) for the indices
    ``ri``, a buffer of ``rows`` rows, ``inputs`` road inputs and ``L`` lanes."""
    lines, ends = _lines(ri, rows, inputs, L)
    body = [
        "    for t in range(count):",
        "        j = j0 + t",
        "        w = 1.0 / (j + 1)",
        f"        base = t * {rows * L}",
        f"        for b in range({L}):",
        *("            " + line for line in lines),
    ]
    if ends:
        body += [f"        if (j + 1) % {int(ri[3])} == 0:", f"            for b in range({L}):"]
        body += ["                " + line for line in ends]
    jit = f"@numba.cfunc({ACCUMULATE!r}, cache=True, nogil=True, error_model='numpy')"
    steps = "from suspopt.loops._compiled import carry, extremes, powers, section, tap, welford"
    head = ["import numba", "", steps, "", "", jit]
    head.append("def accumulate(rec, acc, coef, filt, zs, j0, count):")
    return "\n".join(head + body) + "\n"


#: The generated functions loaded in this process, by structure.
_LOADED: dict[bytes, object] = {}


def fused(ri: np.ndarray, rows: int, inputs: int, L: int):
    """The compiled generated :func:`accumulate` for these indices, or None when the
    generated module cannot be kept (:func:`._fused.load`)."""
    key = ri.tobytes() + f"|{rows}|{inputs}|{L}".encode()
    if key not in _LOADED:
        loaded = _fused.load(source(ri, rows, inputs, L), ("accumulate",))
        _LOADED[key] = None if loaded is None else loaded[0]
    return _LOADED[key]


def summed(state: tuple, B: int) -> tuple:
    """``(summing, summed)`` of the kernel's ``fused`` argument on the fused path: the
    function generated for the accumulators of the kernel's ``state`` (:func:`fused`), or
    the general loops when there are none or it cannot be kept."""
    ri, rec, zs = state[6], state[2], state[10]
    function = fused(ri, rec.shape[2], zs.shape[1], B) if ri[0] else None
    return (0, no_accumulate) if function is None else (1, function)


# The generated functions' stand-ins where the kernel walks the network or runs the general
# loops (never called: the kernel's ``fused`` argument, :data:`._kernel.NOT_FUSED`).
@numba.cfunc(ACCUMULATE, cache=True)
def no_accumulate(rec, acc, coef, filt, zs, j0, count):  # pragma: no cover
    """The stand-in of the generated reductions."""


@numba.cfunc(_fused.FIRST, cache=True)
def no_first(W, par, u, has, h):  # pragma: no cover
    """The stand-in of the fused first stage."""


@numba.cfunc(_fused.REGULAR, cache=True)
def no_regular(W, par, u, w, mid, end, dt):  # pragma: no cover
    """The stand-in of the fused regular step."""
