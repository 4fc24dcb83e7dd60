"""The compiled RK4 engine: the same integration as :mod:`.rk4`, its steps in numba.

The assembled network (:class:`suspopt.network.Assembled`) is packed, not re-described: the
deformation map ``D_q`` and the force map ``G = -D_qᵀ`` (masked where a one-way seat does not
push the body) become lists of their non-zero entries with one value per design (the maps are
shared or per design alike), the element coefficients ``k, c`` and the inverse masses rows
over the designs, and each non-linear part a law of :data:`LAWS` with its parameters. An
evaluation of the accelerations is then

    δ = D_q q + D_u u,   δ̇ = D_q q̇ + D_u u̇,   F = k δ + c δ̇ (+ F_x),   q̈ = M^-1 G F

as loops over those entries (432 floating-point operations per step for the Ch. 5 half car,
as ``benchmarks/bench_simulate.py`` counts them, where the numpy engine's dense products
take about 1,000).

Designs run in blocks of lanes (:func:`block_width`; the last design repeated to fill the
last block): every loop's innermost index is the lane, over contiguous rows, which the
compiler vectorises (a block of one design runs its stages lane by lane instead,
:func:`._kernel._stage_by_lane`: the same operations in the same order); the blocks are
spread over the cores (``numba.prange``). A lane's arithmetic never involves another lane,
so a design gives the same bits whatever its batch, its block or the number of threads.
Every step, sample, road edge (a split step's sub-steps and its exact impulse, planned by
:class:`.rk4.EdgePlan`) and the divergence rule are the numpy engine's; the regular step
uses its arithmetic (stages scaled by their step, ``y += (s1 + 2 s2 + s3)/3 + s4``). The
two agree to rounding: sums are taken in another order (and BLAS may fuse multiply-adds),
about 1e-15 relative per step (``tests/test_compiled.py`` checks 1e-12 on the bundled
configs).

A semi-active controller with a fixed threshold (or none) is sampled by the kernel itself
(:func:`._kernel._control`): every ``ΔT`` it maps the vehicle's velocities (and, for the
laws that need it, the accelerations with the coefficients in force) to each corner's
travel rate, body and wheel velocity, runs the corner's law (the controller's own rule of
:class:`suspopt.control.laws.Law`, compiled: one definition), compares it with the threshold
and puts the command into the damper's coefficient (with an actuator lag, into the
command's share, the kernel applying the lag at every step), keeping each sample's records;
the whole run is then one call of the kernel. The records the run keeps are chosen from them
as the numpy engine's hold keeps its own (:func:`_in_kernel`). An adaptive threshold (its
refits fit distributions to the whole history) is sampled by the kernel too between its
refits; at each refit the controller in :mod:`suspopt.control` takes the sample itself (the
fit) and hands the new threshold back. A law the kernel does not list (:data:`._kernel.
CONTROL_LAWS`) is sampled in numpy at every sample, between compiled stretches of steps
(:func:`_controlled`). Not covered (the numpy engine runs it, :func:`unsupported` says why): a
non-linear element without a compiled law.
A new law is a branch of ``_kernel._law`` and an entry of :data:`LAWS`, beside the numpy
closure that defines it (:attr:`suspopt.network.Elements.extra`).

A run of :data:`._fused.MIN_DESIGNS` designs or more without a controller and on one road
(:func:`_fusable`) takes its first stages and regular steps from functions generated and
compiled for its network (:mod:`._fused`), on blocks of :data:`._fused.LANES` designs: the
same arithmetic in one vectorised lane loop per call, the same bits.

The first call on a machine compiles the kernel (``cache=True`` keeps it in the package's
``__pycache__`` for later processes; ``benchmarks/bench_simulate.py`` reports the time).
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from ..network import Assembled
from .lanes import padded
from .reach import reached, reached_road, renumbered
from .rk4 import (
    _CHECK_EVERY,
    DIVERGENCE_LIMIT,
    Controller,
    EdgePlan,
    Edges,
    Run,
    Trajectory,
    _ControllerHold,
    _VehicleState,
)

#: The non-linear element laws the kernel knows: name -> (code, number of parameters).
#: ``poly3 (c1, c2, c3)``: ``F_x = ((c3 δ + c2) δ + c1) δ`` (a Duffing spring, Eq 2.31, as
#: ``(0, 0, k_nl)``; a seat's Taylor mechanism, Sec 8.2.2); ``cap (limit,)``: the element's
#: force ``k δ + c δ̇`` capped at ``limit`` (a tyre that cannot pull, capped at its static
#: load); ``link (a, b, ℓ², w0, F0)``: ``F_x = (a + b / sqrt(ℓ² - w²)) w + F0`` with ``w = w0 +
#: δ`` (the exact NSS2-NSS4 mechanisms, :func:`suspopt.seat.mechanisms._link_law`);
#: ``carrella (a, b, ℓ², w0, F0)``: ``F_x = (b / sqrt(w² + ℓ²) + a) w + F0`` (NSS1,
#: :func:`suspopt.seat.mechanisms.carrella_law`). Each is the numpy closure's arithmetic,
#: operation for operation.
LAWS = {"poly3": (0, 3), "cap": (1, 1), "link": (2, 5), "carrella": (3, 5)}
#: Parameters per law in the kernel's arrays (the most any law takes).
LAW_PARAMETERS = 5


def _damper_elements(asm: Assembled) -> np.ndarray:
    """The element rows of the semi-active dampers."""
    rows = asm.damper_rows
    assert rows is not None  # (a controlled network)
    return np.arange(rows.start - asm.R, rows.stop - asm.R)


def unsupported(asm: Assembled, controller: Controller | None) -> str | None:
    """Why the compiled engine cannot run this network, or None when it can (every
    ``controller`` is covered: it is asked at its samples)."""
    for g in asm.network.groups:
        if g.extra is not None and (g.extra_law is None or g.extra_law[0] not in LAWS):
            return f"the non-linear part of {g.name!r} has no compiled law"
    return None


def _entries(matrix: np.ndarray, P: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The non-zero entries of ``matrix`` (r, c) or (P0, r, c): rows, columns (nnz,) and
    values (nnz, P)."""
    mask = (matrix != 0).any(axis=0) if matrix.ndim == 3 else matrix != 0
    rows, cols = np.nonzero(mask)
    values = matrix[..., rows, cols]  # (nnz,) or (P0, nnz)
    values = values.T if matrix.ndim == 3 else values[:, None]
    return rows.astype(np.int64), cols.astype(np.int64), padded(values, P)


def _every_row(
    entries: tuple[np.ndarray, np.ndarray, np.ndarray], count: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``entries`` (rows, columns, values) with a zero entry in column 0 for each of the
    ``count`` rows that has none, in row order: the kernel starts a row's sum at its first
    entry and scales it at its last (:func:`._kernel._stage`), so every row needs one."""
    rows, cols, vals = entries
    missing = np.setdiff1d(np.arange(count), rows)
    if not missing.size:
        return rows, cols, vals
    rows = np.concatenate([rows, missing])
    cols = np.concatenate([cols, np.zeros_like(missing)])
    vals = np.concatenate([vals, np.zeros((missing.size, vals.shape[1]))])
    order = np.argsort(rows, kind="stable")
    return rows[order], cols[order], np.ascontiguousarray(vals[order])


def _laws(asm: Assembled, P: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The non-linear parts element by element: law codes and element rows (X,), parameters
    (:data:`LAW_PARAMETERS`, X, P)."""
    codes, rows, params, start = [], [], [], 0
    for g in asm.network.groups:
        if g.extra is not None:
            assert g.extra_law is not None  # (unsupported() said so)
            name, values = g.extra_law
            code, count = LAWS[name]
            for i in range(g.size):
                codes.append(code)
                rows.append(start + i)
                row = np.zeros((LAW_PARAMETERS, P))
                for j in range(count):
                    row[j] = padded(values[j][i, :, 0], P)
                params.append(row)
        start += g.size
    stacked = np.stack(params, axis=1) if params else np.zeros((LAW_PARAMETERS, 0, P))
    return np.array(codes, np.int64), np.array(rows, np.int64), np.ascontiguousarray(stacked)


def _jump(asm: Assembled, jumps: np.ndarray) -> np.ndarray:
    """``D_u Δu`` of an edge's jumps ``(n_u,)`` or ``(G, n_u)``, as (G, R)."""
    return np.atleast_2d(jumps) @ asm.input_map.T


def _edge_arrays(asm: Assembled, edges: Edges | None, dt: float, n_steps: int, offsets):
    """The road's edges as arrays for the kernel: for each step the index of its split plan
    or -1 (n_steps,); per split step its first sub-step (S + 1,); per sub-step its length,
    the inputs' part at its start, middle and end (U, G, 2R), the inputs' jump at its end
    (U, G, R: the impulse's ``D_u Δu``) and whether there is one; the jumps at t = 0
    (Q, G, R); the rows that cannot pull (R,). ``offsets (T, G, 2R)``: G roads."""
    R, G = asm.R, offsets.shape[1]
    split_of = np.full(n_steps, -1, np.int64)
    first, h_all, rights, middles, lefts, jumps, kicks = [0], [], [], [], [], [], []
    start_jumps = np.zeros((0, G, R))
    no_pull = np.zeros(R, np.bool_)
    if edges is not None:
        plan = EdgePlan(edges, dt, n_steps)
        if edges.no_pull is not None:
            no_pull[:] = edges.no_pull
        start_jumps = np.array([_jump(asm, edges.jumps[e]) for e in plan.at_start])
        start_jumps = start_jumps.reshape(-1, G, R)
        for s, k in enumerate(sorted(plan.steps)):
            split_of[k] = s
            found = plan.steps[k]
            h, right, middle, left = plan.sub_steps(k)
            right = right[..., 0].transpose(0, 2, 1).copy()  # (J, G, 2R)
            right[0] = offsets[2 * k]  # the step's first stage, as every step's
            for j in range(len(h)):
                h_all.append(h[j])
                rights.append(right[j])
                middles.append(middle[j][..., 0].T)
                lefts.append(left[j][..., 0].T)
                kick = j < len(found) and bool(edges.jumps[found[j]].any())
                kicks.append(kick)
                jumps.append(_jump(asm, edges.jumps[found[j]]) if kick else np.zeros((G, R)))
            first.append(len(h_all))

    def rows(a, *width):
        return np.ascontiguousarray(np.array(a, float).reshape(-1, *width))

    return (
        split_of,
        np.array(first, np.int64),
        np.array(h_all, float),
        rows(rights, G, 2 * R),
        rows(middles, G, 2 * R),
        rows(lefts, G, 2 * R),
        rows(jumps, G, R),
        np.array(kicks, np.bool_),
        rows(start_jumps, G, R),
        no_pull,
    )


def _packed(
    asm: Assembled,
    dt: float,
    P: int,
    lagged: np.ndarray | None = None,
    decay=None,
    reach: tuple[np.ndarray, np.ndarray] | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The network for the kernel (:mod:`._kernel`): every per-design number ``par (rows,
    P)``, every index ``idx`` and where each part starts, ``lay``; ``lagged`` the element rows
    of dampers with an actuator lag, ``decay (1, P0)`` its decay per step; ``reach`` (the
    DOFs, the elements: :func:`.reach.reached`) keeps only those, renumbered in their order (each
    kept row's entries are the same, in the same order: the same arithmetic)."""
    lagged = np.zeros(0, np.int64) if lagged is None else lagged
    n, R = asm.n, asm.R
    D, G, im = asm.D2[..., :R, :n], asm.G2[..., :R], asm.inverse_mass[:, :, 0]
    k, c = asm.coef[:R, :, 0], asm.coef[R : 2 * R, :, 0]
    law_code, law_row, law_par = _laws(asm, P)
    if reach is not None:
        dofs, elements = reach
        D, G = D[..., elements, :][..., dofs], G[..., dofs, :][..., elements]
        im, k, c = im[dofs], k[elements], c[elements]
        mine = np.isin(law_row, elements)
        law_code, law_par = law_code[mine], np.ascontiguousarray(law_par[:, mine])
        law_row = np.searchsorted(elements, law_row[mine]).astype(np.int64)
        n, R = dofs.size, elements.size
    d_row, d_col, d_val = _every_row(_entries(D, P), R)
    g_row, g_col, g_val = _every_row(_entries(G, P), n)
    im = padded(im, P)
    parts = [
        d_val,
        g_val,
        padded(k, P),
        padded(c, P),
        law_par.transpose(1, 0, 2).reshape(-1, P),  # (5 X, P): the laws' parameters in turn
        im,
        im * (0.5 * dt),
        im * dt,
        im * (dt / 6.0),
        padded(np.broadcast_to(decay, (lagged.size, decay.shape[-1])), P)
        if lagged.size
        else np.zeros((0, P)),
        np.zeros((lagged.size, P)),  # the command's share, set at each controller sample
    ]
    starts = np.cumsum([0] + [p.shape[0] for p in parts])
    lay = [d_row.size, g_row.size, R, law_code.size, n, *starts[[0, 1, 2, 3, 4, 5]]]
    lay += [lagged.size, starts[9], starts[10]]
    idx = np.concatenate([d_row, d_col, g_row, g_col, law_code, law_row, lagged])
    idx = idx.astype(np.int64)
    return np.ascontiguousarray(np.concatenate(parts)), idx, np.array(lay, np.int64)


#: The most lanes of a block: enough to amortise each lane loop's set-up, few enough for the
#: block's buffers to stay in the second-level cache (about 160 KB for the Ch. 5 half car):
#: 128 took 10-30 % less kernel time than 64 at 200 and 1000 designs here, 256 about as long.
MAX_LANES = 128


def block_width(P: int, threads: int) -> int:
    """Designs per block: the fewest blocks, a multiple of the threads, of at most
    :data:`MAX_LANES` each, shared out evenly (300 designs on 2 threads: 4 blocks of 75, not
    4 of 128 with 212 lanes of padding; 150 designs: 2 blocks of 75). A design's arithmetic
    does not depend on it."""
    threads = max(threads, 1)
    blocks = threads * -(-P // (threads * MAX_LANES))
    return max(1, -(-P // blocks))


def integrate(run: Run) -> Trajectory:
    """The compiled engine's :func:`suspopt.integrator.integrate` (what it covers:
    :func:`unsupported`); a road's offsets are shared by its designs. A controller is asked
    at its samples between compiled stretches of steps (:func:`_controlled`)."""
    return next(windows(run))[1]


def windows(
    run: Run, width: int | None = None, recorded: np.ndarray | None = None, accumulators=None
) -> Iterator[tuple[int, Trajectory]]:
    """The compiled engine's :func:`.rk4.windows`: the run in windows of ``width`` output
    samples (a multiple of :data:`._kernel.SAMPLES`; all of them when None), a controlled run
    whole. ``recorded (3n,)`` says which rows of the states ``[q; q']`` and then of the
    accelerations the samples keep (all when None); the others are not written (the caller
    reads none of them: :func:`suspopt.streaming.recorded_rows`; writing every row is a third
    of the kernel's time, filling the rest with NaN would cost about as much). ``accumulators``
    (:class:`.accumulators.Accumulators`, with ``recorded``, no controller): signals the
    kernel forms and reduces itself, their rows read but not recorded. Without a controller,
    only the DOFs and elements those rows depend on are integrated (:func:`.reach.reached`):
    the same arithmetic for them, and a part that no row read depends on neither costs time
    nor, by diverging, fails a design."""
    asm, n_vehicle, offsets, dt, n_steps, every, controller, edges = run
    import numba

    from . import _accumulate, _fused, _kernel

    n, P0 = asm.n, asm.P
    n_out, width = run.window(width)
    if width < n_out and width % _kernel.SAMPLES:
        raise ValueError(f"a window is a multiple of {_kernel.SAMPLES} samples")
    lagged = decay = None
    if controller is not None and controller.lag_decay is not None:
        lagged = _damper_elements(asm)
        decay = controller.lag_decay.reshape(1, -1)
    reach = None
    if recorded is not None and controller is None:
        reach = reached(asm, recorded if accumulators is None else recorded | accumulators.rows(n))
    fusable = _fusable(offsets, controller, P0)
    B = _fused.LANES if fusable else block_width(P0, numba.get_num_threads())
    blocks = -(-P0 // B)
    P = blocks * B  # whole blocks: the last design repeated
    flat, idx, lay = _packed(asm, dt, P, lagged, decay, reach)
    steps = _fused.steps(idx, lay) if fusable else None
    Nl = int(lay[11])
    par = np.ascontiguousarray(flat.reshape(flat.shape[0], blocks, B).transpose(1, 0, 2))
    road = _road_arrays(run, reach, (blocks, B))
    state = _kernel_state(blocks, B, lay, n, (recorded, accumulators), reach)
    fused = _kernel.NOT_FUSED if steps is None else (1, *steps, *_accumulate.summed(state, B))
    diverged_at = np.full(P, np.nan)
    rows = 0 if getattr(accumulators, "alone", False) else n  # (every signal in the kernel)
    for j0 in range(0, n_out, width):
        T = min(width, n_out - j0)
        # zeros, not np.empty: the kernel writes only the rows and samples that are read,
        # and the signals are formed over whole windows (recycled memory there made numpy
        # warn of overflows in values nobody reads)
        states, accelerations = np.zeros((2 * rows, P, T)), np.zeros((rows, P, T))
        out = (states, accelerations, diverged_at, np.zeros((Nl, P, T)))

        def advance(k0: int, k1: int, ctl=_no_control(blocks, B), out=out, j0=j0) -> None:
            if k1 <= k0:  # (no step: a call from step 0 would apply the start's impulses)
                return
            _kernel.run(k0, k1, j0, dt, n_steps, every, DIVERGENCE_LIMIT, _CHECK_EVERY, par,
                        idx, lay, road, state, out, ctl, fused)  # fmt: skip

        damping, records = None, {}
        if controller is None:
            advance(j0 * every, (j0 + T) * every if j0 + T < n_out else n_steps + 1)
        else:
            lanes = _Lanes(par, idx, state, lay, road, P0, n_vehicle)
            damping, records = _controlled(controller, asm, lanes, advance, dt, n_steps, every)
            if Nl:
                damping = out[3][:, :P0]  # a lagged coefficient changes every step
        yield (
            j0,
            Trajectory(
                states=states[:, :P0],
                accelerations=accelerations[:, :P0],
                damping=damping,
                records=records,
                diverged_at=diverged_at[:P0].copy(),
                engine="compiled",
            ),
        )


def _road_arrays(run: Run, reach, lanes: tuple[int, int]) -> tuple:
    """The kernel's ``road``: the inputs' part ``(T, G, 2R)`` of G roads (each under P0/G
    consecutive designs) and whether each half step has one, the edges' arrays
    (:func:`_edge_arrays`), of the ``reach`` elements alone, and the road of each lane of
    ``lanes = (blocks, B)`` (the padding's the last design's)."""
    asm, offsets, P0 = run.asm, run.offsets, run.asm.P
    off = np.ascontiguousarray(offsets[:, :, :, 0].transpose(0, 2, 1))
    G, (blocks, B) = off.shape[1], lanes
    lane_road = np.minimum(np.arange(blocks * B) // (P0 // G), G - 1).reshape(blocks, B)
    road = (off, off.any(axis=(1, 2))) + _edge_arrays(asm, run.edges, run.dt, run.n_steps, off)
    return (road if reach is None else reached_road(road, reach[1], asm.R)) + (lane_road,)


def _fusable(offsets: np.ndarray, controller, P: int) -> bool:
    """Whether a run's regular steps take the network's fused functions (:mod:`._fused`):
    no controller, one road for every design (``offsets (T, 2R, G, 1)``) and at least
    :data:`._fused.MIN_DESIGNS` designs (a run of a few designs would pay more for the
    first compilation of its network than it saves). With a controller, whose samples the
    kernel takes block by block, it showed no gain (Ch. 7 SH-2, ``Problem.evaluate`` of 200
    designs: 114-119 ms against 107-134 ms walked), and a road per design is not generated."""
    from . import _fused

    return controller is None and offsets.shape[2] == 1 and P >= _fused.MIN_DESIGNS


def _kernel_state(blocks: int, B: int, lay: np.ndarray, n: int, kept, reach) -> tuple:
    """The kernel's ``state = (W, F, rec, at, kept, dest, *red)`` (:func:`._kernel.run`) of
    a network of ``n`` DOFs packed as ``lay`` (its ``reach`` of them, :func:`.reach.reached`),
    ``kept = (recorded, accumulators)``: its samples recording the rows ``recorded (3n,)``
    (all when None) and the lagged coefficients, and buffering the rows the
    ``accumulators`` read (or None) for the kernel's own reductions."""
    from . import _kernel
    from .accumulators import no_accumulators

    Nl, n_kernel, R = int(lay[11]), int(lay[4]), int(lay[2])  # (the reached DOFs, elements)
    recorded, accumulators = kept
    recorded = np.ones(3 * n, np.bool_) if recorded is None else recorded
    reads = recorded if accumulators is None else recorded | accumulators.rows(n)
    wanted = np.flatnonzero(reads)  # rows of the buffer, and where the kernel has them
    rows = wanted if reach is None else renumbered(wanted, n, reach[0])
    red = no_accumulators(blocks, B) if accumulators is None else accumulators.arrays(
        blocks, B, wanted)  # fmt: skip
    return (
        np.zeros((blocks, 11, 2 * n_kernel, B)),
        np.empty((blocks, 3, R, B)),
        np.empty((blocks, _kernel.SAMPLES, rows.size + Nl, B)),
        np.full((blocks, B), np.nan),
        np.concatenate([rows, 3 * n_kernel + np.arange(Nl)]).astype(np.int64),
        np.concatenate([np.where(recorded[wanted], wanted, -1), 3 * n + np.arange(Nl)]).astype(
            np.int64
        ),
        *red,
    )


class _Lanes:
    """The controller's view of the compiled blocks: the vehicle's velocities and
    accelerations as ``(n_vehicle, P)`` rows, and the damper coefficients written into the
    blocks' parameters."""

    def __init__(self, par, idx, state, lay, road, P: int, n_vehicle: int):
        self.par, self.idx, self.state, self.lay, self.road, self.P = par, idx, state, lay, road, P
        self.n, self.n_vehicle = int(lay[4]), n_vehicle
        self.velocity = np.zeros((n_vehicle, P))

    def rows(self, a: np.ndarray) -> np.ndarray:
        """``(blocks, rows, B)`` as ``(rows, P)`` (the real designs only)."""
        return a.transpose(1, 0, 2).reshape(a.shape[1], -1)[:, : self.P]

    def read_velocity(self) -> None:
        n = self.n
        self.velocity[...] = self.rows(self.state[0][:, 0, n : n + self.n_vehicle])

    def acceleration(self, h: int) -> np.ndarray:
        from . import _kernel

        blocks, _, B = self.par.shape
        acc = np.empty((blocks, self.n, B))
        _kernel.accelerations_now(h, self.par, self.idx, self.lay, self.road, self.state, acc)
        return self.rows(acc)[: self.n_vehicle].copy()

    def set_rows(self, rows: slice, values: np.ndarray) -> None:
        """Rows ``rows`` of the blocks' parameters to ``values (rows, P)``, the last design
        repeated over the padding (at every controller sample: no allocation)."""
        blocks, _, B = self.par.shape
        target = self.par[:, rows, :]  # (blocks, rows, B), a view
        whole, P = self.P // B, self.P
        target[:whole] = values[:, : whole * B].reshape(-1, whole, B).transpose(1, 0, 2)
        if whole < blocks:  # the last, padded block
            target[whole, :, : P - whole * B] = values[:, whole * B :]
            target[whole, :, P - whole * B :] = values[:, -1:]


def _no_control(blocks: int, B: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The kernel's controller arrays of a run whose kernel takes no controller sample."""
    return np.zeros((blocks, 0, B)), np.array([0, 0, 1, 0, 0, 0], np.int64), np.zeros((4, 0, B, 0))


def _sample_rules(controller):
    """The controller's :class:`~suspopt.controller.SampleRules` when the kernel can
    take its samples (laws of :data:`._kernel.CONTROL_LAWS`; an adaptive threshold's refits
    are the controller's own samples), else None (every sample in numpy, between compiled
    stretches)."""
    from . import _kernel

    rules = getattr(controller, "sample_rules", lambda: None)()
    if rules is None or any(law not in _kernel.CONTROL_LAWS for law in rules.laws if law):
        return None
    return rules


def _control_arrays(
    asm: Assembled, rules, par: np.ndarray, every_c: int, final: bool, lagged: bool
) -> tuple[np.ndarray, np.ndarray]:
    """The kernel's controller values ``cp (blocks, rows, B)`` and indices ``ci``
    (:func:`._kernel._control`) for samples every ``every_c`` steps (the run's final instant
    one of them when ``final``), the command into the lag's share when ``lagged``."""
    from . import _kernel

    blocks, _, B = par.shape
    P = blocks * B
    r_row, r_col, r_val = _entries(rules.rates, P)
    values = [rules.c_min, rules.c_max, rules.threshold, *rules.parameters]
    cp = np.concatenate([r_val] + [padded(np.asarray(v, float).T, P) for v in values])
    codes = [_kernel.CONTROL_LAWS.index(law) if law else -1 for law in rules.laws]
    ci = [len(rules.laws), r_row.size, every_c, int(final), int(rules.needs_acceleration)]
    ci += [int(lagged)] + codes + [int(b) for b in rules.below] + list(_damper_elements(asm))
    ci += list(r_row) + list(r_col)
    cp = np.ascontiguousarray(cp.reshape(cp.shape[0], blocks, B).transpose(1, 0, 2))
    return cp, np.array(ci, np.int64)


def _controlled(controller, asm: Assembled, lanes: _Lanes, advance, dt, n_steps, every):
    """The run with ``controller``, each sample taken as the numpy engine's
    :class:`.rk4._ControllerHold` takes it (zero-order hold, the records kept at the first
    output sample after each change): by the kernel itself when it can
    (:func:`_sample_rules`), else in compiled stretches of steps between the samples."""
    n_out, lay = n_steps // every + 1, lanes.lay
    elements = _damper_elements(asm)  # contiguous: their rows of c among the parameters
    dampers = slice(int(lay[8]) + elements[0], int(lay[8]) + elements[-1] + 1)
    coef = np.array(asm.coef)  # the hold's coefficients (its damper rows)
    vehicle = _VehicleState(lanes.velocity, lambda: lanes.acceleration(hold.sample_index))
    rows = asm.damper_rows
    assert rows is not None
    hold = _ControllerHold(controller, coef, rows, asm.P, n_out, dt, vehicle)
    lanes.set_rows(dampers, hold.damping[:, :, 0])
    every_c = controller.sample_every
    samples = list(range(0, n_steps, every_c))
    if n_steps % every == 0 and n_steps % every_c == 0:
        samples.append(n_steps)  # the final instant is an output sample
    # where a sample's command goes: the damper rows, or with a lag the command's share
    command_rows = (
        slice(int(lay[13]), int(lay[13]) + int(lay[11])) if hold.decay is not None else dampers
    )
    rules = _sample_rules(controller)
    if rules is not None:
        return _in_kernel(
            hold, rules, (asm, lanes, command_rows), advance, samples, (n_steps, every)
        )
    k0, pending = 0, None
    for k in samples:
        advance(k0, k)
        first_output = -(-k // every)
        if pending is not None and pending != first_output:
            hold.kept(pending)  # the previous sample's records, at its first output sample
        _take_sample(hold, k, lanes, command_rows)
        pending, k0 = (first_output if first_output < n_out else None), k
    advance(k0, n_steps + 1)
    if pending is not None:
        hold.kept(pending)
    return hold.held(n_out)


def _take_sample(hold, k: int, lanes: _Lanes, rows: slice) -> None:
    """The controller's own sample at step ``k`` from the blocks' velocities, its command
    into the blocks' ``rows`` (the damper coefficients, or with a lag the command's share:
    the kernel applies the lag at every step)."""
    lanes.read_velocity()
    hold.control(k)
    lanes.set_rows(rows, (hold.pulled if hold.decay is not None else hold.damping)[:, :, 0])


def _in_kernel(hold, rules, blocks_of, advance, samples, grid):
    """The run in calls of the kernel, which takes the controller's samples, but for an
    adaptive threshold's refits (:func:`_take_sample`, :func:`_refitted`); then the records the hold keeps (those of
    the last sample before each output sample), as the hold would have kept them."""
    n_steps, every = grid
    asm, lanes, command_rows = blocks_of  # (command_rows: :func:`_take_sample`)
    n_out, P = n_steps // every + 1, asm.P
    final = bool(samples) and samples[-1] == n_steps
    cp, ci = _control_arrays(asm, rules, lanes.par, hold.every, final, hold.decay is not None)
    blocks, _, B = lanes.par.shape
    records = np.empty((4, len(samples), blocks * B, len(rules.laws)))  # (every one written)
    controller, k0 = hold.controller, 0
    refit = controller.refit_step(0)
    while refit is not None and samples and refit <= samples[-1]:
        advance(k0, refit, (cp, ci, records))
        controller.taken(records[1, -(-k0 // hold.every) : refit // hold.every, :P])
        _take_sample(hold, refit, lanes, command_rows)
        _refitted(controller, rules, ci, cp, records[:, refit // hold.every, :P])
        advance(refit, refit + 1)  # (the step of the sample the controller took)
        k0, refit = refit + 1, controller.refit_step(refit + 1)
    advance(k0, n_steps + 1, (cp, ci, records))
    records = records[:, :, :P]
    first = -(-np.array(samples) // every)  # each sample's first output sample
    last = np.append(first[1:] != first[:-1], True) & (first < n_out)
    kept = np.flatnonzero(last)
    names = ["command", "condition", "threshold"] + (["stiff"] if rules.stiff_records else [])
    columns = [list(records[0, kept]), list(records[1, kept]), list(records[2, kept])]
    columns += [list(records[3, kept] > 0.5)] if rules.stiff_records else []
    hold.held_records.extend(dict(zip(names, values)) for values in zip(*columns))
    if hold.decay is None:
        hold.held_damping.extend(columns[0])
    hold.changes.extend(first[kept].tolist())
    return hold.held(n_out)


def _refitted(controller, rules, ci: np.ndarray, cp: np.ndarray, record: np.ndarray) -> None:
    """After the controller's own sample (a refit of its adaptive threshold): its records
    into ``record (4, P, N)`` as the kernel writes them, and its new threshold into the
    kernel's controller values ``cp``, whose rows are the rates map's ``ci[1]`` entries, then
    ``C_min``, ``C_max`` and the threshold (:func:`_control_arrays`)."""
    values, N = controller.record(), len(rules.laws)
    record[0], record[1], record[2] = values["command"], values["condition"], values["threshold"]
    if rules.stiff_records:
        record[3] = values["stiff"]
    blocks, _, B = cp.shape
    o = int(ci[1]) + 2 * N
    threshold = np.broadcast_to(values["threshold"], rules.c_min.shape).T  # (N, P)
    cp[:, o : o + N] = padded(threshold, blocks * B).reshape(N, blocks, B).transpose(1, 0, 2)
