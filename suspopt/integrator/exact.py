"""The exact stepper of a linear network: ``simulation.method: exact``.

A network without a non-linear part and without a controller is linear in its state
``y = [q; q']`` and the road's part of its deformations ``o = [D_u u; D_u u']``
(:class:`suspopt.network.Assembled`): ``y' = A y + B o`` with ``q'' = M^-1 G2 (coef (D2 y +
o))``. The road's inputs ``w = [u; u']`` are taken as linear between the integration steps
(a first-order hold of their values at the steps, as ``scipy.signal.lsim(..., interp=True)``
takes them), which makes the step exact: for each design, the matrix exponential of the
augmented matrix ``[[A dt, B_w dt, 0], [0, 0, I], [0, 0, 0]]`` (``B_w = B E``, ``o = E w``)
gives the transition ``Φ`` and the input matrices ``Γ0, Γ1`` of

    y_{k+1} = Φ y_k + Γ0 w_k + Γ1 w_{k+1},

one matrix-vector product per step at any ``dt`` (no stability limit). The exponentials of
all designs are one batched ``scipy.linalg.expm``; the steps run compiled, designs spread
over the cores. Deviation from RK4: on a road that is not linear between the steps (a smooth
bump), this is the exact response to the road's first-order hold, and RK4 the fourth-order
approximation to the response to the road itself; both converge to it as ``dt`` shrinks.

The samples, the output grid and the divergence rule are those of :mod:`.rk4` (the state is
checked after every step here); the accelerations of a sample are ``A y + B_w w`` at it.
"""

from __future__ import annotations

from collections.abc import Iterator

import numba
import numpy as np

from .. import _numba_cache
from .rk4 import DIVERGENCE_LIMIT, Run, Trajectory

_numba_cache.prepare()

__all__ = ["unsupported", "discretised", "windows"]


def unsupported(run: Run) -> str | None:
    """Why ``run`` has no exact stepper (a phrase), or None."""
    if run.controller is not None:
        return "a semi-active controller switches the damping"
    if run.asm.extras:
        return "a non-linear element (a Duffing spring, a tyre that lifts off, a seat mechanism)"
    if run.edges is not None:
        return "the road has steps (edges) between the integration steps"
    return None


def _matrices(run: Run) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``A (P, N, N)``, ``B_w (P, N, m)`` and ``E⁺ (m, 2R)`` (the inputs ``w`` of the
    offsets: ``w = E⁺ o``), ``N = 2n``, ``m = 2 n_u``."""
    asm = run.asm
    n, R, P = asm.n, asm.R, asm.P
    D2 = np.broadcast_to(asm.D2, (P, 2 * R, 2 * n))
    G2 = np.broadcast_to(asm.G2[..., : 2 * R], (P, n, 2 * R))
    coef = asm.coef[:, :, 0].T  # (P, 2R)
    jacobian = asm.inverse_mass[:, :, 0].T[:, :, None] * G2 * coef[:, None, :]  # (P, n, 2R)
    A = np.zeros((P, 2 * n, 2 * n))
    A[:, :n, n:] = np.eye(n)
    A[:, n:] = jacobian @ D2
    nu = asm.input_map.shape[1]
    E = np.zeros((2 * R, 2 * nu))
    E[:R, :nu] = asm.input_map
    E[R:, nu:] = asm.input_map
    B = np.zeros((P, 2 * n, 2 * nu))
    B[:, n:] = jacobian @ E
    return A, B, np.linalg.pinv(E)


def discretised(run: Run, matrices: tuple | None = None) -> tuple[np.ndarray, ...]:
    """``(Φ, Γ0, Γ1, A_acc, B_acc)`` of every design (module docstring): ``(P, N, N)``,
    ``(P, N, m)`` twice, and the acceleration rows of ``A`` and ``B_w``; ``matrices`` the
    run's :func:`_matrices` when the caller has them."""
    from scipy.linalg import expm

    A, B, _ = _matrices(run) if matrices is None else matrices
    P, N, m = B.shape
    dt = run.dt
    M = np.zeros((P, N + 2 * m, N + 2 * m))
    M[:, :N, :N] = A * dt
    M[:, :N, N : N + m] = B * dt
    M[:, N : N + m, N + m :] = np.eye(m)
    E = expm(M)
    phi = np.ascontiguousarray(E[:, :N, :N])
    gamma1 = np.ascontiguousarray(E[:, :N, N + m :])
    gamma0 = np.ascontiguousarray(E[:, :N, N : N + m] - gamma1)
    n = N // 2
    return phi, gamma0, gamma1, np.ascontiguousarray(A[:, n:]), np.ascontiguousarray(B[:, n:])


def _inputs(run: Run, pinv: np.ndarray) -> np.ndarray:
    """The road's inputs ``w (n_steps + 1, m, G)`` at the steps (the offsets' whole steps,
    mapped back by ``pinv = E⁺``)."""
    offsets = run.offsets[::2, :, :, 0]  # (n_steps + 1, 2R, G)
    return np.ascontiguousarray(np.einsum("mr,krg->kmg", pinv, offsets))


#: Designs per block of the stepper: their values side by side, so that each product runs
#: over the lanes (the compiler vectorises it).
LANES = 64


@numba.njit(cache=True, nogil=True, parallel=True)
def _advance(phi, g0, g1, a_acc, b_acc, w, road, y, k0, k1, every, j0, states, accs, at, dt):
    """Steps ``k0 .. k1 - 1`` of every block of :data:`LANES` designs from its state
    ``y (blocks, N, L)`` (in place), the samples ``k % every == 0`` (and ``k1`` when it is
    one) into ``states (blocks, T, N, L)`` and ``accs (blocks, T, n, L)`` from sample ``j0``
    (each sample's values side by side: written whole); the matrices
    ``(blocks, rows, columns, L)``, ``w (steps + 1, m, G)`` the inputs of each road,
    ``road (blocks, L)`` each lane's; ``at (blocks, L)`` the divergence times."""
    blocks, N = y.shape[0], y.shape[1]
    n, m = N // 2, w.shape[1]
    for blk in numba.prange(blocks):
        x = y[blk].copy()
        nxt = np.empty((N, LANES))
        u0, u1 = np.empty((m, LANES)), np.empty((m, LANES))
        s = np.empty(LANES)
        for c in range(m):
            for lane in range(LANES):
                u1[c, lane] = w[k0, c, road[blk, lane]]
        for k in range(k0, k1 + 1):
            u0[:] = u1
            if k % every == 0:
                j = k // every - j0
                if 0 <= j < states.shape[1]:
                    _sample(blk, x, u0, a_acc, b_acc, states[blk, j], accs[blk, j], s, n, m)
            if k == k1:
                break
            for c in range(m):
                for lane in range(LANES):
                    u1[c, lane] = w[k + 1, c, road[blk, lane]]
            for i in range(N):
                for lane in range(LANES):
                    nxt[i, lane] = 0.0
                for c in range(N):
                    for lane in range(LANES):
                        nxt[i, lane] += phi[blk, i, c, lane] * x[c, lane]
                for c in range(m):
                    for lane in range(LANES):
                        nxt[i, lane] += g0[blk, i, c, lane] * u0[c, lane]
                        nxt[i, lane] += g1[blk, i, c, lane] * u1[c, lane]
            worst = 0.0
            for i in range(N):
                for lane in range(LANES):
                    x[i, lane] = nxt[i, lane]
                    worst = max(worst, abs(nxt[i, lane]))
            if not worst < DIVERGENCE_LIMIT:  # (rare: a lane's own check only then)
                _diverged(blk, x, at, (k + 1) * dt)
        y[blk] = x


@numba.njit(cache=True, nogil=True, inline="always")
def _sample(blk, x, u, a_acc, b_acc, states, accs, s, n, m):
    """One output sample of block ``blk``: its states ``(N, L)`` and accelerations ``A y +
    B w`` ``(n, L)``."""
    N = x.shape[0]
    for i in range(N):
        for lane in range(LANES):
            states[i, lane] = x[i, lane]
    for i in range(n):
        for lane in range(LANES):
            s[lane] = 0.0
        for c in range(N):
            for lane in range(LANES):
                s[lane] += a_acc[blk, i, c, lane] * x[c, lane]
        for c in range(m):
            for lane in range(LANES):
                s[lane] += b_acc[blk, i, c, lane] * u[c, lane]
        for lane in range(LANES):
            accs[i, lane] = s[lane]


@numba.njit(cache=True, nogil=True)
def _diverged(blk, x, at, t):
    """The lanes of block ``blk`` whose state left ``|x| < DIVERGENCE_LIMIT``: NaN from now,
    their time ``t`` the first time."""
    for lane in range(LANES):
        bad = False
        for i in range(x.shape[0]):
            if not abs(x[i, lane]) < DIVERGENCE_LIMIT:
                bad = True
        if bad:
            if at[blk, lane] != at[blk, lane]:
                at[blk, lane] = t
            for i in range(x.shape[0]):
                x[i, lane] = np.nan


def _designs_major(rec: np.ndarray, P: int, wanted: np.ndarray) -> np.ndarray:
    """``(blocks, T, rows, L)`` as the trajectories' ``(rows, P, T)``, the rows not
    ``wanted`` NaN."""
    blocks, T, rows, L = rec.shape
    out = np.full((rows, P, T), np.nan)
    for r in np.flatnonzero(wanted):
        out[r] = rec[:, :, r, :].transpose(0, 2, 1).reshape(blocks * L, T)[:P]
    return out


def _lanes(a: np.ndarray, blocks: int) -> np.ndarray:
    """``a (P, ...)`` as ``(blocks, ..., LANES)``, the last design repeated to fill."""
    from .lanes import padded

    P = a.shape[0]
    full = padded(a.reshape(P, -1).T, blocks * LANES).T.reshape((blocks * LANES,) + a.shape[1:])
    moved = np.moveaxis(full.reshape((blocks, LANES) + a.shape[1:]), 1, -1)
    return np.ascontiguousarray(moved)


def windows(
    run: Run, width: int | None = None, recorded: np.ndarray | None = None
) -> Iterator[tuple[int, Trajectory]]:
    """The run as consecutive windows of at most ``width`` output samples (all when None):
    ``(first sample, trajectory of the window)``, the samples those of :mod:`.rk4`.
    ``recorded (3n,)``: the rows of the states and then of the accelerations the caller
    reads; the others are left NaN (as the compiled engine may leave them)."""
    why = unsupported(run)
    if why is not None:
        raise ValueError(f"simulation.method exact needs a linear model: {why}")
    asm, n_steps, every = run.asm, run.n_steps, run.every
    n, P = asm.n, asm.P
    n_out, width = run.window(width)
    blocks = -(-P // LANES)
    matrices = _matrices(run)
    phi, g0, g1, a_acc, b_acc = (_lanes(a, blocks) for a in discretised(run, matrices))
    w = _inputs(run, matrices[2])
    G = w.shape[2]
    road = _lanes(np.repeat(np.arange(G), P // G).astype(np.int64), blocks)
    y = np.zeros((blocks, 2 * n, LANES))
    at = np.full((blocks, LANES), np.nan)
    k0 = 0
    for j0 in range(0, n_out, width):
        j1 = min(j0 + width, n_out)
        T = j1 - j0
        rec_s, rec_a = np.empty((blocks, T, 2 * n, LANES)), np.empty((blocks, T, n, LANES))
        k1 = (j1 - 1) * every if j1 < n_out else n_steps
        with np.errstate(over="ignore", invalid="ignore"):
            _advance(phi, g0, g1, a_acc, b_acc, w, road, y, k0, k1, every, j0, rec_s, rec_a,
                     at, run.dt)  # fmt: skip
        rows = np.ones(3 * n, np.bool_) if recorded is None else recorded
        states = _designs_major(rec_s, P, rows[: 2 * n])
        accs = _designs_major(rec_a, P, rows[2 * n :])
        k0 = k1  # (the next window goes on from its last sample's step)
        yield j0, Trajectory(states, accs, None, {}, at.reshape(-1)[:P].copy(), engine="exact")
