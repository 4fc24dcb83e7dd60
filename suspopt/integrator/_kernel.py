"""The numba kernel of :mod:`.compiled` (imported only when that engine runs: it needs numba).

A block of ``B`` designs (:func:`.compiled.block_width`) keeps everything in a few arrays
indexed by constants and offsets, so the hot loop creates no array views and passes no tuples
(each would cost atomic reference counts): ``W (11, 2n, B)`` holds the state ``y``, the stage
state ``ys``, the slopes ``s1..s4`` of a regular step, those of a split step ``k1..k4`` and a
scratch block; ``F (3, R, B)`` the deformations ``δ, δ̇`` and the element forces;
``par (rows, B)`` every per-design number, ``idx`` every index and ``lay`` where each part
starts (:func:`.compiled._packed`):

- ``lay = (nD, nG, R, X, n, oD, oG, oK, oC, oL, oM, Nl, oE, oU)``: the entries of D_q and
  of G, the elements, the non-linear laws, the DOFs; the first row in ``par`` of the values
  of D_q's entries, of G's, of ``k``, of ``c``, of the laws' parameters (5 per law) and of the
  inverse masses times 1, dt/2, dt and dt/6 (n rows each); the lagged dampers, the first row
  of their decay per step ``e`` and of their command's share ``c_cmd (1 - e)``;
- ``idx``: D_q's rows and columns, G's rows (DOFs) and columns (elements), the laws' codes
  (:data:`.compiled.LAWS`) and element rows, the lagged dampers' element rows.

A fixed-threshold controller's samples are taken in the kernel (:func:`_control`, with
``ctl = (cp, ci, records)``: its values per block, its indices and each sample's records;
empty when the kernel takes none).

The lane is every loop's innermost index (a loop the compiler vectorises, with a run-time
check that its arrays do not overlap).
"""

from __future__ import annotations

from typing import Any

import numba
import numpy as np
from numba import types
from numba.extending import intrinsic

from .. import _numba_cache
from ..control.laws import LAWS
from ._accumulate import accumulate, no_accumulate, no_first, no_regular

_numba_cache.prepare()  # (cached for the machine, damaged files compiled again: suspopt._numba_cache)
_jit = numba.njit(cache=True, nogil=True)
#: A helper compiled into its one caller (no call, no reference counts).
_inline = numba.njit(cache=True, nogil=True, inline="always")


def _address_of(typingctx, array):
    """The address of ``array``'s first element, for a fused step (:mod:`._fused`)."""

    def codegen(context, builder, signature, args):
        return context.make_array(array)(context, builder, args[0]).data

    return types.CPointer(array.dtype)(array), codegen


_address: Any = intrinsic(_address_of)


#: The kernel's ``fused`` argument where it walks the network (:func:`run`).
NOT_FUSED = (0, no_first, no_regular, 0, no_accumulate)
#: Samples a block buffers before writing them to the records.
SAMPLES = 32
#: The blocks of W.
Y, YS, S1, S2, S3, S4, K1, K2, K3, K4, TMP = range(11)


@_inline
def _law_value(code, d, f, a, b, c, w0, f0):
    """The force ``f`` at ``δ = d`` with the non-linear part of law ``code``
    (:data:`.compiled.LAWS`) added, its parameters ``a, b, c, w0, f0`` (as many as it takes;
    the numpy closures' arithmetic). The walked kernel (:func:`_law_force`) and the fused
    step (:mod:`._fused`, the code a literal) both call it."""
    if code == 0:  # poly3 (c1, c2, c3): ((c3 δ + c2) δ + c1) δ
        return f + ((c * d + b) * d + a) * d
    if code == 1:  # cap (limit,): the force no larger than the limit (NaN stays NaN)
        return a if f > a else f
    w = w0 + d
    if code == 2:  # link: (a + b / sqrt(l^2 - w^2)) w + F0, w = w0 + δ
        x = (a + b / np.sqrt(c - w * w)) * w
    else:  # carrella: (b / sqrt(w^2 + l^2) + a) w + F0
        x = (b / np.sqrt(w * w + c) + a) * w
    return (f + x) + f0


@_inline
def _law_force(code, d, f, par, p, b):
    """Lane ``b``'s :func:`_law_value`, its parameters in rows ``p .. p + 4`` of ``par``."""
    a, b_, c, w0, f0 = par[p, b], par[p + 1, b], par[p + 2, b], par[p + 3, b], par[p + 4, b]
    return _law_value(code, d, f, a, b_, c, w0, f0)


@_jit
def _law(code, r, p, F, par):
    """Element ``r``'s non-linear part (:func:`_law_force`) added to its force ``F[2, r]`` at
    ``δ = F[0, r]``, the law chosen once, outside the lane loops."""
    B = F.shape[2]
    if code == 0:
        for b in range(B):
            F[2, r, b] = _law_force(0, F[0, r, b], F[2, r, b], par, p, b)
    elif code == 1:
        for b in range(B):
            F[2, r, b] = _law_force(1, F[0, r, b], F[2, r, b], par, p, b)
    elif code == 2:
        for b in range(B):
            F[2, r, b] = _law_force(2, F[0, r, b], F[2, r, b], par, p, b)
    else:
        for b in range(B):
            F[2, r, b] = _law_force(3, F[0, r, b], F[2, r, b], par, p, b)


@_inline
def _deformations(W, F, par, idx, nD, n, oD, src):
    """``δ = D_q q`` and ``δ̇ = D_q q̇`` at ``W[src]`` into ``F[0], F[1]``: the entries of a
    row in pairs (one lane loop does two entries' work, the same operations in the same
    order as one at a time), a row's first entry starting its sum at zero."""
    B = W.shape[2]
    z = 0
    while z < nD:
        r, j = idx[z], idx[nD + z]
        first = z == 0 or idx[z - 1] != r
        p = oD + z
        if z + 1 < nD and idx[z + 1] == r:
            k = idx[nD + z + 1]
            if first:
                for b in range(B):
                    F[0, r, b] = (0.0 + par[p, b] * W[src, j, b]) + par[p + 1, b] * W[src, k, b]
                    d = 0.0 + par[p, b] * W[src, n + j, b]
                    F[1, r, b] = d + par[p + 1, b] * W[src, n + k, b]
            else:
                for b in range(B):
                    d = F[0, r, b] + par[p, b] * W[src, j, b]
                    F[0, r, b] = d + par[p + 1, b] * W[src, k, b]
                    d = F[1, r, b] + par[p, b] * W[src, n + j, b]
                    F[1, r, b] = d + par[p + 1, b] * W[src, n + k, b]
            z += 2
        else:
            if first:
                for b in range(B):
                    F[0, r, b] = 0.0 + par[p, b] * W[src, j, b]
                    F[1, r, b] = 0.0 + par[p, b] * W[src, n + j, b]
            else:
                for b in range(B):
                    F[0, r, b] += par[p, b] * W[src, j, b]
                    F[1, r, b] += par[p, b] * W[src, n + j, b]
            z += 1


@_inline
def _accelerations(W, F, par, idx, nD, nG, n, oG, oM, src, out, h):
    """``q'' = M^-1 G F`` into ``W[out, n:]`` (the inverse masses' rows from ``oM``) and
    ``h q'`` into ``W[out, :n]``: the entries of a DOF in pairs, as :func:`_deformations`
    does, a DOF's last entry scaling its sum."""
    B = W.shape[2]
    z = 0
    while z < nG:
        i, r = idx[2 * nD + z], idx[2 * nD + nG + z]
        g, m = oG + z, oM + i
        first = z == 0 or idx[2 * nD + z - 1] != i
        e = z + 2 if z + 1 < nG and idx[2 * nD + z + 1] == i else z + 1  # the next entry
        last = e == nG or idx[2 * nD + e] != i
        s = idx[2 * nD + nG + z + 1] if e == z + 2 else r
        if e == z + 1 and first and last:
            for b in range(B):
                W[out, n + i, b] = (0.0 + par[g, b] * F[2, r, b]) * par[m, b]
                W[out, i, b] = W[src, n + i, b] * h
        elif e == z + 1 and first:
            for b in range(B):
                W[out, n + i, b] = 0.0 + par[g, b] * F[2, r, b]
        elif e == z + 1 and last:
            for b in range(B):
                W[out, n + i, b] = (W[out, n + i, b] + par[g, b] * F[2, r, b]) * par[m, b]
                W[out, i, b] = W[src, n + i, b] * h
        elif e == z + 1:
            for b in range(B):
                W[out, n + i, b] += par[g, b] * F[2, r, b]
        elif first and last:
            for b in range(B):
                a = (0.0 + par[g, b] * F[2, r, b]) + par[g + 1, b] * F[2, s, b]
                W[out, n + i, b] = a * par[m, b]
                W[out, i, b] = W[src, n + i, b] * h
        elif first:
            for b in range(B):
                a = 0.0 + par[g, b] * F[2, r, b]
                W[out, n + i, b] = a + par[g + 1, b] * F[2, s, b]
        elif last:
            for b in range(B):
                a = W[out, n + i, b] + par[g, b] * F[2, r, b]
                W[out, n + i, b] = (a + par[g + 1, b] * F[2, s, b]) * par[m, b]
                W[out, i, b] = W[src, n + i, b] * h
        else:
            for b in range(B):
                a = W[out, n + i, b] + par[g, b] * F[2, r, b]
                W[out, n + i, b] = a + par[g + 1, b] * F[2, s, b]
        z = e


@_inline
def _stage_by_lane(W, F, par, idx, lay, src, o, oi, lr, has_input, scale, out, h):
    """:func:`_stage` lane by lane, for a block of one design: each lane's operations in the
    same order as the lane loops do them, without a loop per entry (whose set-up, for one
    lane, costs more than the entry: a run of the Ch. 8 seat takes about a fifth less time
    this way; with two lanes or more the lane loops are as fast or faster)."""
    nD, nG, R, X, n = lay[0], lay[1], lay[2], lay[3], lay[4]
    oD, oG, oK, oC, oL, oM = lay[5], lay[6], lay[7], lay[8], lay[9], lay[10]
    for b in range(W.shape[2]):
        g = lr[b] if o.shape[1] > 1 else 0
        for z in range(nD):
            r, j = idx[z], idx[nD + z]
            d = 0.0 if z == 0 or idx[z - 1] != r else F[0, r, b]
            v = 0.0 if z == 0 or idx[z - 1] != r else F[1, r, b]
            F[0, r, b] = d + par[oD + z, b] * W[src, j, b]
            F[1, r, b] = v + par[oD + z, b] * W[src, n + j, b]
        for r in range(R):
            d, v = F[0, r, b], F[1, r, b]
            if has_input:
                d = d + o[oi, g, r]
                v = v + o[oi, g, R + r]
                F[0, r, b] = d
            F[2, r, b] = par[oK + r, b] * d + par[oC + r, b] * v
        for x in range(X):
            r = idx[2 * nD + 2 * nG + X + x]
            code, p = idx[2 * nD + 2 * nG + x], oL + 5 * x
            F[2, r, b] = _law_force(code, F[0, r, b], F[2, r, b], par, p, b)
        for z in range(nG):
            i, r = idx[2 * nD + z], idx[2 * nD + nG + z]
            a = 0.0 if z == 0 or idx[2 * nD + z - 1] != i else W[out, n + i, b]
            a = a + par[oG + z, b] * F[2, r, b]
            if z == nG - 1 or idx[2 * nD + z + 1] != i:  # the DOF's last entry
                a = a * par[oM + scale * n + i, b]
                W[out, i, b] = W[src, n + i, b] * h
            W[out, n + i, b] = a


@_jit
def _stage(W, F, par, idx, lay, src, o, oi, lr, has_input, scale, out, h):
    """The accelerations at the state ``W[src] = [q; q']`` with the inputs' part ``o[oi]``
    (when ``has_input``; ``o (.., G, 2R)``, lane ``b`` on road ``lr[b]`` when G > 1), times
    the inverse masses' row set ``scale`` (0: 1, 1: dt/2, 2: dt, 3: dt/6), into
    ``W[out, n:]``, and the displacement rates ``h q'`` into ``W[out, :n]``: ``δ = D_q q + D_u
    u``, ``F = k δ + c δ̇`` plus the laws, ``q'' = M^-1 G F``. The entries of D_q (of G) come
    row by row, every row at least once (:func:`.compiled._packed`): a row's first entry
    starts its sum (``0 + x``, the arithmetic of a sum started at zero) and its last one
    scales it; a lane loop does two entries' work where a row has two or more
    (:func:`_deformations`, :func:`_accelerations`: the loops' set-up is much of a stage's
    time at 50 lanes), and a block of one design runs lane by lane
    (:func:`_stage_by_lane`)."""
    nD, nG, R, X, n = lay[0], lay[1], lay[2], lay[3], lay[4]
    oD, oG, oK, oC, oL, oM = lay[5], lay[6], lay[7], lay[8], lay[9], lay[10]
    B = W.shape[2]
    if B == 1:  # (two or three lanes are faster in lane loops)
        _stage_by_lane(W, F, par, idx, lay, src, o, oi, lr, has_input, scale, out, h)
        return
    _deformations(W, F, par, idx, nD, n, oD, src)
    if has_input and o.shape[1] == 1:
        for r in range(R):
            for b in range(B):
                d = F[0, r, b] + o[oi, 0, r]
                F[0, r, b] = d
                F[2, r, b] = par[oK + r, b] * d + par[oC + r, b] * (F[1, r, b] + o[oi, 0, R + r])
    elif has_input:  # a road per lane
        for r in range(R):
            for b in range(B):
                d = F[0, r, b] + o[oi, lr[b], r]
                F[0, r, b] = d
                v = F[1, r, b] + o[oi, lr[b], R + r]
                F[2, r, b] = par[oK + r, b] * d + par[oC + r, b] * v
    else:
        for r in range(R):
            for b in range(B):
                F[2, r, b] = par[oK + r, b] * F[0, r, b] + par[oC + r, b] * F[1, r, b]
    for x in range(X):
        _law(idx[2 * nD + 2 * nG + x], idx[2 * nD + 2 * nG + X + x], oL + 5 * x, F, par)
    _accelerations(W, F, par, idx, nD, nG, n, oG, oM + scale * n, src, out, h)


@_jit
def _plus(W, a, s, w, out, n):
    """``W[out] = W[a] + w W[s]``."""
    for i in range(2 * n):
        for b in range(W.shape[2]):
            W[out, i, b] = W[a, i, b] + w * W[s, i, b]


@_jit
def _regular_step(h0, dt, W, F, par, idx, lay, off, lr, active):
    """One RK4 step from half step ``h0`` with the numpy engine's arithmetic: ``s1`` holds
    the first stage's accelerations (unscaled) in its lower rows; each stage is scaled by its
    step, ``y += (s1 + 2 s2 + s3)/3 + s4``."""
    n, half = lay[4], 0.5 * dt
    for i in range(n):
        for b in range(W.shape[2]):
            W[S1, n + i, b] *= half
    for stage in range(3):  # s2, s3, s4
        h = half if stage == 0 else (dt if stage == 1 else dt / 6.0)
        hi = h0 + 1 if stage < 2 else h0 + 2
        _plus(W, Y, S1 + stage, 1.0, YS, n)
        _stage(W, F, par, idx, lay, YS, off, hi, lr, active[hi], stage + 1, S2 + stage, h)
    third = 1.0 / 3.0
    for i in range(2 * n):
        for b in range(W.shape[2]):
            W[Y, i, b] += (((W[S1, i, b] + W[S3, i, b]) + W[S2, i, b] * 2.0) * third) + W[S4, i, b]


@_jit
def _impulse(jumps, u, no_pull, W, F, par, idx, lay, lr):
    """The velocity jump ``M^-1 G (c D_u Δu)`` of an inputs' jump with ``D_u Δu = jumps[u]
    (G, R)`` (lane ``b`` on road ``lr[b]``); a row that cannot pull takes no pulling
    impulse."""
    nD, nG, R, n, oG, oC, oM = lay[0], lay[1], lay[2], lay[4], lay[6], lay[8], lay[10]
    for r in range(R):
        for b in range(W.shape[2]):
            force = par[oC + r, b] * jumps[u, lr[b], r]
            if no_pull[r] and force > 0.0:
                force = 0.0
            F[2, r, b] = force
    for i in range(n):
        for b in range(W.shape[2]):
            W[TMP, i, b] = 0.0
    for z in range(nG):
        i, r = idx[2 * nD + z], idx[2 * nD + nG + z]
        for b in range(W.shape[2]):
            W[TMP, i, b] += par[oG + z, b] * F[2, r, b]
    for i in range(n):
        for b in range(W.shape[2]):
            W[Y, n + i, b] += W[TMP, i, b] * par[oM + i, b]


@_jit
def _split_step(s, W, F, par, idx, lay, road, lr):
    """Split step ``s``: RK4 sub-steps between its edges (``k = f(y + w k_prev)`` unscaled),
    each edge's impulse at its end."""
    sub_first, sub_h, sub_right, sub_middle, sub_left = road[3], road[4], road[5], road[6], road[7]
    sub_jump, sub_kick, no_pull = road[8], road[9], road[11]
    n = lay[4]
    for u in range(sub_first[s], sub_first[s + 1]):
        hu = sub_h[u]
        for stage in range(4):
            w = 0.0 if stage == 0 else (hu if stage == 3 else 0.5 * hu)
            inputs = sub_right if stage == 0 else (sub_left if stage == 3 else sub_middle)
            _plus(W, Y, Y if stage == 0 else K1 + stage - 1, w, TMP, n)
            _stage(W, F, par, idx, lay, TMP, inputs, u, lr, True, 0, K1 + stage, 1.0)
        for i in range(2 * n):
            for b in range(W.shape[2]):
                W[Y, i, b] += (
                    hu / 6.0 * (W[K1, i, b] + 2.0 * (W[K2, i, b] + W[K3, i, b]) + W[K4, i, b])
                )
        if sub_kick[u]:
            _impulse(sub_jump, u, no_pull, W, F, par, idx, lay, lr)


@_jit
def _check(W, at, limit, time):
    """Lanes whose state left ``|x| < limit`` (or is not finite): their time and NaN."""
    for b in range(W.shape[2]):
        bad = False
        for i in range(W.shape[1]):
            if not (abs(W[Y, i, b]) < limit):
                bad = True
        if bad:
            if np.isnan(at[b]):
                at[b] = time
            for i in range(W.shape[1]):
                W[Y, i, b] = np.nan


@_jit
def _keep(W, rec, t, n, pb, idx, lay, kept):
    """Sample into row ``t`` of the time-major buffer ``rec``: the rows ``kept`` of the
    record (the state ``0 .. 2n``, the accelerations ``2n .. 3n``, the lagged damping
    coefficients from ``3n`` on), in that order."""
    base = 2 * lay[0] + 2 * lay[1] + 2 * lay[3]
    for m in range(kept.shape[0]):
        i = kept[m]
        if i < 2 * n:
            for b in range(W.shape[2]):
                rec[t, m, b] = W[Y, i, b]
        elif i < 3 * n:
            for b in range(W.shape[2]):
                rec[t, m, b] = W[S1, i - n, b]
        else:
            for b in range(W.shape[2]):
                rec[t, m, b] = pb[lay[8] + idx[base + i - 3 * n], b]


@_jit
def _flush(rec, j0, count, p0, out, dest):
    """The buffer's first ``count`` samples to samples ``j0 ..`` of the records (its row
    ``m`` is record row ``dest[m]`` of the whole network's ``n`` DOFs: the states ``0 ..
    2n``, the accelerations ``2n .. 3n``, the lagged coefficients from ``3n`` on; -1 for a
    row only the kernel's own reductions read): a
    transposed copy that writes each design's row as a contiguous run (writing every sample
    straight to the ``(rows, P, T)`` records touches a new cache line per value and took two
    thirds of the run)."""
    states, accelerations, lagged = out[0], out[1], out[3]
    n = states.shape[0] // 2
    for m in range(dest.shape[0]):
        i = dest[m]
        for b in range(rec.shape[2] if i >= 0 else 0):
            for t in range(count):
                if i < 2 * n:
                    states[i, p0 + b, j0 + t] = rec[t, m, b]
                elif i < 3 * n:
                    accelerations[i - 2 * n, p0 + b, j0 + t] = rec[t, m, b]
                else:
                    lagged[i - 3 * n, p0 + b, j0 + t] = rec[t, m, b]


@_jit
def _lag(pb, idx, lay):
    """The actuators' first-order lag, once per step: ``c <- c e + c_cmd (1 - e)`` (the
    command's share ``c_cmd (1 - e)`` set at each controller sample), as the numpy engine's
    hold does it."""
    base, oC, oDecay, oPulled = 2 * lay[0] + 2 * lay[1] + 2 * lay[3], lay[8], lay[12], lay[13]
    for m in range(lay[11]):
        r = idx[base + m]
        for b in range(pb.shape[1]):
            pb[oC + r, b] = pb[oC + r, b] * pb[oDecay + m, b]
            pb[oC + r, b] = pb[oC + r, b] + pb[oPulled + m, b]


#: The control laws the kernel takes samples of, by code (their index here); their rules are
#: the controller's own functions (:class:`suspopt.control.laws.Law`), compiled.
CONTROL_LAWS = ("sh_2", "sh_l", "add", "sh_add_1", "sh_add_2", "groundhook", "hybrid")
_x0, _x1, _x2, _x3, _x4, _x5, _x6 = (_jit(LAWS[name].rule) for name in CONTROL_LAWS)


def _stiff_rule(name: str):
    rule = LAWS[name].stiff_rule
    assert rule is not None  # (a continuous law)
    return _jit(rule)


#: The continuous laws' codes and stiff coefficients (the other laws' is C_max).
_SH_L, _HYBRID = CONTROL_LAWS.index("sh_l"), CONTROL_LAWS.index("hybrid")
_stiff_sh_l, _stiff_hybrid = _stiff_rule("sh_l"), _stiff_rule("hybrid")


@_jit
def _condition(code, st, zs, zu, za, lw, cf, sw):
    """X of law ``code`` (:data:`CONTROL_LAWS`; -1, a passive corner: 0)."""
    a = (st, zs, zu, za, lw, cf, sw)
    if code < 0:
        return np.zeros_like(st)
    if code < 4:
        return (
            _x0(*a)
            if code == 0
            else (_x1(*a) if code == 1 else (_x2(*a) if code == 2 else _x3(*a)))
        )
    return _x4(*a) if code == 4 else (_x5(*a) if code == 5 else _x6(*a))


@_jit
def _stiff(code, c_min, c_max, st, zs, x, lw, cf, sw):
    """The stiff coefficient of law ``code`` (``C_max`` for an on-off law)."""
    if code == _SH_L:
        return _stiff_sh_l(c_min, c_max, st, zs, x, lw, cf, sw)
    if code == _HYBRID:
        return _stiff_hybrid(c_min, c_max, st, zs, x, lw, cf, sw)
    return c_max.copy()


@_jit
def _control(step, W, F, pb, idx, lay, road, lr, cp, ci, records):
    """The controller's sample at ``step`` (:class:`suspopt.controller.
    SemiActiveController`'s arithmetic): the rates ``[ṠT; ż_s; ż_u]`` of the velocities (and
    ``z̈_s`` of the accelerations with the coefficients in force), each corner's condition,
    threshold and command, the command into the damper's coefficient (or its share of the
    lag) and the sample's records ``(command, condition, threshold, stiff)``. ``ci = (N,
    entries, steps per sample, whether the final instant is one, reads z̈_s, lagged, law
    codes (N), stiff below (N), damper elements (N), the rates map's rows and columns)``,
    ``cp``: the map's values, then ``C_min, C_max, T`` and the law parameters (N rows each)."""
    N, nnz, B, n = ci[0], ci[1], W.shape[2], lay[4]
    codes, below, elements, rows, cols = 6, 6 + N, 6 + 2 * N, 6 + 3 * N, 6 + 3 * N + nnz
    rates = np.zeros((3 * N, B))
    acc = np.zeros((N, B))
    for z in range(nnz):
        for b in range(B):
            rates[ci[rows + z], b] += cp[z, b] * W[Y, n + ci[cols + z], b]
    if ci[4]:
        _stage(W, F, pb, idx, lay, Y, road[0], 2 * step, lr, road[1][2 * step], 0, TMP, 0.0)
        for z in range(nnz):
            r = ci[rows + z]
            if N <= r < 2 * N:
                for b in range(B):
                    acc[r - N, b] += cp[z, b] * W[TMP, n + ci[cols + z], b]
    s, o = step // ci[2], nnz
    for c in range(N):
        st, zs, zu = rates[c], rates[N + c], rates[2 * N + c]
        lw, cf, sw = cp[o + 3 * N + c], cp[o + 4 * N + c], cp[o + 5 * N + c]
        c_min, c_max, threshold = cp[o + c], cp[o + N + c], cp[o + 2 * N + c]
        x = _condition(ci[codes + c], st, zs, zu, acc[c], lw, cf, sw)
        stiff = x < threshold if ci[below + c] else x > threshold
        command = np.where(stiff, _stiff(ci[codes + c], c_min, c_max, st, zs, x, lw, cf, sw), c_min)
        r = ci[elements + c]
        for b in range(B):
            if ci[5]:  # the command's share of the lag: c_cmd (1 - e)
                pb[lay[13] + c, b] = command[b] * (1.0 - pb[lay[12] + c, b])
            else:
                pb[lay[8] + r, b] = command[b]
            records[0, s, b, c] = command[b]
            records[1, s, b, c] = x[b]
            records[2, s, b, c] = threshold[b]
            records[3, s, b, c] = 1.0 if stiff[b] else 0.0


@_jit
def _advance(
    blk, k0, k1, origin, dt, n_steps, every, limit, check_every, par, idx, lay, road, state, out,
    ctl, fused,
):  # fmt: skip
    """Block ``blk``'s steps ``k0 .. k1 - 1`` from its kept state (step ``n_steps`` is the
    final sample alone): the sample's first stage, the sample when one is due (sample ``j``
    written at ``j - origin`` of the records, ``origin`` a multiple of :data:`SAMPLES`), the
    step, the divergence check. ``fused = (on, first, regular, summing, summed)``: when ``on``, the first
    stage and the regular steps are the network's fused functions (:mod:`._fused`), and
    when ``summing`` the samples' reductions the generated ``summed``."""
    W_all, F_all, rec_all, at_all = state[0], state[1], state[2], state[3]
    states, diverged_at = out[0], out[2]
    W, F, rec, at, pb = W_all[blk], F_all[blk], rec_all[blk], at_all[blk], par[blk]
    n, B = lay[4], W.shape[2]
    off, active, split_of, start_jumps, no_pull = road[0], road[1], road[2], road[10], road[11]
    lr, kept, dest = road[12][blk], state[4], state[5]
    cp, ci, records = ctl[0][blk], ctl[1], ctl[2][:, :, blk * B : blk * B + B]
    on, first, regular, summing, summed = fused
    Wp, pp = _address(W), _address(pb)
    if k0 == 0:
        for u in range(start_jumps.shape[0]):
            _impulse(start_jumps, u, no_pull, W, F, pb, idx, lay, lr)
    for step in range(k0, k1):
        if ci[0] and step % ci[2] == 0 and (step < n_steps or ci[3]):
            _control(step, W, F, pb, idx, lay, road, lr, cp, ci, records)
        _lag(pb, idx, lay)
        h = 2 * step
        if on:
            first(Wp, pp, _address(off[h, 0]), 1 if active[h] else 0, 0.5 * dt)
        else:
            _stage(W, F, pb, idx, lay, Y, off, h, lr, active[h], 0, S1, 0.5 * dt)
        if step % every == 0:  # the sample: the state and the first stage's accelerations
            j = step // every
            _keep(W, rec, j % SAMPLES, n, pb, idx, lay, kept)
            if j % SAMPLES == SAMPLES - 1 or j - origin == states.shape[2] - 1:
                _flush(rec, j - j % SAMPLES - origin, j % SAMPLES + 1, blk * B, out, dest)
                if summing:  # (the generated reductions, :mod:`._accumulate`)
                    summed(_address(rec), _address(state[8][blk]), _address(state[7][blk]),
                           _address(state[9]), _address(state[10]), j - j % SAMPLES,
                           j % SAMPLES + 1)  # fmt: skip
                else:
                    accumulate(rec, j - j % SAMPLES, j % SAMPLES + 1, lr, blk, state)
        if step == n_steps:
            break
        if split_of[step] < 0 and on:
            mid, end = 1 if active[h + 1] else 0, 1 if active[h + 2] else 0
            regular(Wp, pp, _address(off[h + 1, 0]), _address(off[h + 2, 0]), mid, end, dt)
        elif split_of[step] < 0:
            _regular_step(h, dt, W, F, pb, idx, lay, off, lr, active)
        else:
            _split_step(split_of[step], W, F, pb, idx, lay, road, lr)
        if (step + 1) % check_every == 0 or step + 1 == n_steps:
            _check(W, at, limit, (step + 1) * dt)
    diverged_at[blk * B : blk * B + B] = at


@numba.njit(cache=True, parallel=True, nogil=True)
def run(
    k0, k1, origin, dt, n_steps, every, limit, check_every, par, idx, lay, road, state, out, ctl,
    fused,
):  # fmt: skip
    """Steps ``k0 .. k1 - 1`` of every block (in parallel over the cores) from the kept
    ``state = (W, F, rec, at, kept, dest, *red)`` of each (``kept``: the rows the samples
    keep, :func:`_keep`; ``dest``: the records' rows they go to, :func:`_flush`; ``red``: the
    signals the kernel reduces, :mod:`._accumulate`), ``par (blocks,
    rows, B)`` (the arrays: :func:`.compiled._packed`), samples from ``origin`` on in
    ``out``; ``fused``: :func:`_advance`, :data:`NOT_FUSED` to walk the network."""
    for blk in numba.prange(par.shape[0]):
        _advance(
            blk, k0, k1, origin, dt, n_steps, every, limit, check_every, par, idx, lay, road,
            state, out, ctl, fused,
        )  # fmt: skip


@numba.njit(cache=True, parallel=True, nogil=True)
def accelerations_now(h, par, idx, lay, road, state, out):
    """The accelerations ``out (blocks, n, B)`` at every block's current state with the
    inputs of half step ``h`` and the coefficients in ``par`` (what a controller's sample
    reads; scratch rows of ``W`` only)."""
    off, active = road[0], road[1]
    n = lay[4]
    for blk in numba.prange(par.shape[0]):
        W, F = state[0][blk], state[1][blk]
        _stage(W, F, par[blk], idx, lay, Y, off, h, road[12][blk], active[h], 0, TMP, 0.0)
        for i in range(n):
            for b in range(W.shape[2]):
                out[blk, i, b] = W[TMP, n + i, b]
