"""Batched fixed-step simulation of P designs at once and the ``Result`` it returns.

The equations of motion are the vehicle's :class:`~suspopt.network.Network` with the seat (if
any) mounted on it, packed by :class:`_Assembled`. The integrator is the classical 4th-order
Runge-Kutta method with a fixed step ``dt``; the road is sampled on the half-step grid the
stages need, and a step that meets a bump's edge is split there, the step bump's Dirac in the
road's rate entering as an exact impulse (:func:`_integrate`), so every edge is seen at its
instant. All P designs advance together: states are ``(2n, P, 1)`` - DOF by DOF, each a
contiguous row over the designs - and each stage is two small matrix products and the element
forces on whole rows, in preallocated buffers. There is no Python loop over designs.

A design whose state becomes non-finite or exceeds ``DIVERGENCE_LIMIT`` is marked in
``Result.diverged`` (with the time in ``Result.diverged_at``); its samples from then on are NaN,
so a diverged design can never pass for a valid one.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, NamedTuple, Protocol

import difflib

import numpy as np

from . import memory
from .checks import check_steps, full_network
from .config import Config
from .control.controller import build_controller
from .network import Network, widen
from .params import ParamView
from .specs import evaluate_spec, spec_signals
from .road import road_edges, road_inputs, road_memory
from .seat import SIGNAL_HEADS as _SEAT_HEADS, build_attachments
from .seat import signal_units as _seat_signal_units
from .vehicle import VehicleModel, build_vehicle

__all__ = ["simulate", "prepare", "signal_names", "signal_units", "Result", "SignalMap",
           "Controller", "Attachment", "DIVERGENCE_LIMIT"]

#: |state| above this (m, rad, m/s, rad/s) counts as divergence.
DIVERGENCE_LIMIT = 1.0e6
_CHECK_EVERY = 25
#: Input offsets are stored per design column when that takes at most this many floats.
_WIDE_OFFSETS = 4_000_000
#: Output samples moved to the (2n, P, T) states at a time.
_BLOCK = 64


class Controller(Protocol):
    """A semi-active damper controller (built by :mod:`suspopt.control`).

    The integrator calls ``start(P)`` once for the command at rest ``(P, 1, N)`` [N s/m], then
    ``sample(k, t, state)`` at every ``sample_every``-th step (from step 0) for the command
    held until the next sample (zero-order hold). ``state.velocity()`` gives the vehicle
    velocities ``(n, P)`` at that instant, ``state.acceleration()`` the accelerations
    (computed only when called, with the coefficients in force before the sample). With
    ``lag_decay`` (P, 1, 1) the dampers follow the command as a first-order actuator,
    ``c <- c_cmd - (c_cmd - c) lag_decay`` every integration step. ``record`` returns what
    the latest sample decided ``{name: (P, N)}`` (it changes only when ``samples``, the number
    of samples taken, does); ``published`` turns those of the whole run, stacked ``(S, P,
    N)``, into the records that become the signals ``<name>.<corner>`` with units
    ``units[name]``, the records' names being the keys of ``units``; a run publishes them
    when one is first read. The integrator keeps the arrays that ``start``, ``sample`` and
    ``record`` return without copying them: the controller must not write them afterwards.
    """

    units: dict[str, str]
    samples: int
    sample_every: int
    lag_decay: np.ndarray | None

    def start(self, P: int) -> np.ndarray: ...

    def sample(self, k: int, t: float, state: "_VehicleState") -> np.ndarray: ...

    def record(self) -> dict[str, np.ndarray]: ...

    def published(self, raw: dict[str, np.ndarray]) -> dict[str, np.ndarray]: ...


class _VehicleState:
    """The vehicle's motion at the current step, as the controller reads it: one row per
    vehicle DOF, one column per design."""

    __slots__ = ("_velocity", "_acceleration")

    def __init__(self, velocity: np.ndarray, acceleration: Callable[[], np.ndarray]):
        self._velocity, self._acceleration = velocity, acceleration

    def velocity(self) -> np.ndarray:
        """(n_vehicle, P) [m/s, rad/s] (a view of the integrator's state)."""
        return self._velocity

    def acceleration(self) -> np.ndarray:
        """(n_vehicle, P) [m/s^2, rad/s^2]."""
        return self._acceleration()


class Attachment(Protocol):
    """Extra bodies mounted at a point of the vehicle body (a seat, a seated passenger).

    ``dof_names`` name its vertical DOFs (appended after the vehicle's); ``network`` its
    :class:`~suspopt.network.Network` with the floor under it as the one input;
    ``point = (x, y)`` is where it sits on the body [m] (x + forward, y + right), the floor's
    motion being the body's vertical motion there; ``coupled`` puts the floor's reaction on
    the body (two-way); the thesis drives seats one way. ``signal(name, ...)`` computes its
    named signals ``(P, T)`` from its states ``(m, P, T)`` and the floor's ``(P, T)``.
    """

    dof_names: tuple[str, ...]
    network: Network
    point: tuple[float, float]
    coupled: bool

    def signal_names(self) -> list[str]: ...

    def signal(self, name: str, q: np.ndarray, v: np.ndarray, acc: np.ndarray,
               base: np.ndarray, base_vel: np.ndarray, base_acc: np.ndarray) -> np.ndarray: ...


def _product(matrix: np.ndarray, x: np.ndarray, out: np.ndarray) -> None:
    """``out = matrix @ x`` for a (P, r, c) matrix per design and columns ``x (c, P)``."""
    np.einsum("prc,cp->rp", matrix, x, out=out)


class _Assembled:
    """A network packed for fast evaluation of ``q'' = M^-1 Σ -D_qᵀ F`` (suspopt.network).

    All groups' deformation rows are stacked: ``e = D2 @ [q; v] + offset`` gives the
    displacements (rows ``:R``) and rates (rows ``R:``) of every element, ``F = coef * e`` their
    elastic and viscous forces (``coef = [k; c]``), the groups' non-linear parts are added to
    the elastic rows, and ``q'' = M^-1 G2 @ F`` with ``G2 = [G, G]`` (``G = -D_qᵀ``, masked
    where a one-way seat does not push the body). ``offset`` holds the inputs' part
    ``[D_u u; D_u u']``. A semi-active damper's coefficients are the rows ``damper_rows`` of
    ``coef``. The deformation and force maps are shared by all designs unless a group's map
    differs between them (``(P, ...)`` arrays, multiplied per design by :func:`_product`).
    """

    def __init__(self, network: Network, P: int, controlled: str | None = None):
        self.network = network
        n, groups = network.n, network.groups
        R = sum(g.size for g in groups)
        self.n, self.R, self.P = n, R, P
        per_design = any(g.dof_map.ndim == 3 for g in groups)
        dq = [np.broadcast_to(g.dof_map, (P, g.size, n)) if per_design else g.dof_map
              for g in groups]
        Dq = np.concatenate(dq, axis=-2)
        D2 = np.zeros(Dq.shape[:-2] + (2 * R, 2 * n))
        D2[..., :R, :n] = Dq
        D2[..., R:, n:] = Dq
        self.input_map = np.concatenate([g.input_map for g in groups])       # (R, n_u)
        G = np.concatenate([np.broadcast_to(g.force_map, (P, n, g.size)) if per_design
                            else g.force_map for g in groups], axis=-1)
        # the non-linear parts are forces of their own rows of F, acting like their elements
        extra_rows = np.concatenate([np.arange(start, start + g.size) for start, g
                                     in zip(np.cumsum([0] + [g.size for g in groups]), groups)
                                     if g.extra is not None] or [np.arange(0)])
        G2 = np.concatenate([G, G, G[..., extra_rows]], axis=-1)
        # M^-1 multiplies the accelerations even where it could be folded into G2: folding
        # rounds differently, and a design must give the same bits whatever else varies in
        # its batch
        self.inverse_mass = np.ascontiguousarray(1.0 / np.broadcast_to(network.mass,
                                                                       (n, P, 1)))
        self.D2, self.G2 = np.ascontiguousarray(D2), np.ascontiguousarray(G2)
        self.coef = np.ascontiguousarray(np.concatenate(
            [np.broadcast_to(g.stiffness, (g.size, P, 1)) for g in groups]
            + [np.broadcast_to(g.damping, (g.size, P, 1)) for g in groups]))
        self.extras, self.damper_rows, start, out = [], None, 0, 2 * R
        for g in groups:
            rows = slice(start, start + g.size)
            rates = slice(R + start, R + start + g.size)
            if g.extra is not None:
                self.extras.append((rows, rates, slice(out, out + g.size), g.extra,
                                    g.extra_uses_force))
                out += g.size
            if g.name == controlled:
                self.damper_rows = rates
            start += g.size
        self.F_rows = out

    def offsets(self, u: np.ndarray, u_dot: np.ndarray) -> np.ndarray:
        """``[D_u u; D_u u']`` at each sample of the inputs ``u, u_dot (n_u, T)``: (T, 2R,
        1, 1), contiguous per sample."""
        off = np.concatenate([self.input_map @ u, self.input_map @ u_dot])
        return np.ascontiguousarray(off.T)[:, :, None, None]

    def evaluator(self, width: int | None = None
                  ) -> Callable[[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray,
                                 np.ndarray], None]:
        """A function ``(y2, offset, coef, inverse_mass, acc2, acc) -> None`` that writes
        ``q''`` of ``width`` design columns (default P) into ``acc``.

        ``y2 = [q; v]`` (2n, width); ``offset`` (2R, 1|width, 1), or None where the inputs
        are zero; ``coef`` (2R, width, 1);
        ``inverse_mass`` (n, width, 1), scaled when the caller wants a multiple of q'';
        ``acc2``/``acc`` the (n, width) and (n, width, 1) views of the output. Its buffers for
        the deformations and forces are allocated once, with the non-linear parts' views into
        them, so that the integrator's stages allocate nothing.
        """
        R, width = self.R, width or self.P
        e, F = np.empty((2 * R, width, 1)), np.empty((self.F_rows, width, 1))
        e2, F2, linear = e.reshape(2 * R, -1), F.reshape(self.F_rows, -1), F[:2 * R]
        extras = [(F[rows], F[rates], e[rows], e[rates], F[out], make(width), uses)
                  for rows, rates, out, make, uses in self.extras]
        product = np.dot if self.D2.ndim == 2 else _product
        D2, G2, multiply, add = self.D2, self.G2, np.multiply, np.add

        def evaluate(y2, offset, coef, inverse_mass, acc2, acc) -> None:
            product(D2, y2, out=e2)
            if offset is not None:
                e.__iadd__(offset)
            multiply(coef, e, out=linear)
            for elastic, viscous, disp, rate, out, fn, uses_force in extras:
                fn(disp, rate, add(elastic, viscous) if uses_force else None, out)
            product(G2, F2, out=acc2)
            acc.__imul__(inverse_mass)
        return evaluate


class _Held:
    """A controller quantity held between changes: the distinct values ``(S, P, N)`` and, for
    each output sample, which of them held ``(T,)``. Expanded to ``(N, P, T)`` on demand, so a
    coefficient that changes only every ΔT is stored once per change, not per sample. The
    values may be given as a function that makes them: they are then made on first use (a run
    whose metrics never read them does not pay for them)."""

    def __init__(self, values: np.ndarray | Callable[[], np.ndarray], index: np.ndarray):
        self._values, self.index = values, index

    @property
    def values(self) -> np.ndarray:
        """``(S, P, N)``."""
        if callable(self._values):
            self._values = self._values()
        return self._values

    def corner(self, c: int) -> np.ndarray:
        """(P, T) series of corner ``c``."""
        return self.values[self.index, :, c].T

    def full(self) -> np.ndarray:
        """(N, P, T) series of every corner."""
        return np.transpose(self.values[self.index], (2, 1, 0))


class _HeldRecords(Mapping):
    """The controller's records by name, each a :class:`_Held` of one index: published (see
    the ``Controller`` protocol) from the values kept at each sample when one is first read."""

    def __init__(self, names: Sequence[str], publish: Callable[[], dict[str, np.ndarray]],
                 index: np.ndarray):
        self._names, self._publish, self._index = tuple(names), publish, index
        self._held: dict[str, _Held] | None = None

    def __getitem__(self, name: str) -> _Held:
        if name not in self._names:
            raise KeyError(name)
        if self._held is None:
            self._held = {n: _Held(v, self._index) for n, v in self._publish().items()}
            self._publish = None
        return self._held[name]

    def __contains__(self, name: object) -> bool:
        return name in self._names

    def __iter__(self) -> Iterator[str]:
        return iter(self._names)

    def __len__(self) -> int:
        return len(self._names)


@dataclass
class _Trajectory:
    """What one integration produced: states (2n, P, T), accelerations (n, P, T), the damping
    coefficients (held between changes, or (N, P, T) when a lagged actuator changes them
    every step) and controller records (or None / empty without a controller) and the
    divergence times (P,)."""

    states: np.ndarray
    accelerations: np.ndarray
    damping: _Held | np.ndarray | None
    records: Mapping[str, _Held]
    diverged_at: np.ndarray


def _stacked(arrays: list[np.ndarray]) -> np.ndarray:
    """``np.stack(arrays)`` of equal-shaped arrays (of at least one dimension) by one
    concatenation: for thousands of small arrays np.stack takes about three times as long."""
    return np.concatenate(arrays).reshape((len(arrays),) + arrays[0].shape)


class _Edges(NamedTuple):
    """The road's edges (:func:`suspopt.road.road_edges`) as :func:`_integrate` takes them."""

    times: np.ndarray      #: (E,) ascending [s]
    jumps: np.ndarray      #: (E, n_u) the step in the inputs u at each edge [m]
    #: ``inputs(t, left)``: the inputs' part of the deformations (T, 2R, 1, 1) at times ``t``
    #: (T,), their left limits if ``left``, else the right ones
    inputs: Callable[[np.ndarray, bool], np.ndarray]
    #: (R,) element rows that cannot pull (a tyre that may lift off), or None
    no_pull: np.ndarray | None


def _integrate(asm: _Assembled, n_vehicle: int, offsets: np.ndarray, dt: float, n_steps: int,
               every: int, controller: Controller | None = None,
               edges: _Edges | None = None) -> _Trajectory:
    """Classical RK4 over ``n_steps``; ``offsets`` (2 n_steps + 1, 2R, 1, 1) are the inputs'
    part of the deformations on the half-step grid ``t = j dt/2`` (their right limits at a
    road edge). Samples are kept every ``every``-th step.

    Road edges (``edges``; the bumps' jumps in z or its rate, Eq 2.101-2.104) are seen at their
    instants. A step whose interior holds edges is split at them into RK4 sub-steps; each
    sub-step's last stage takes the road's left limit at its end and the next one's first stage
    the right limit, so a step ending on an edge uses the left limit in its last stage and one
    starting on it (the grid) the right limit. Where the inputs jump by ``Δu`` their rate
    holds a Dirac ``Δu δ(t - t_e)``, integrated exactly: an impulse ``c D_u Δu`` [N s] of the
    viscous elements that see the road (the tyre damping c_T, Eq 2.29), so the velocities
    jump by ``M^-1 (-D_qᵀ) (c D_u Δu)`` at the edge (the elastic forces stay bounded and give
    no impulse). A tyre that may lift off cannot pull: its force is capped at the static load,
    so its impulse at an edge where it would pull (the road dropping away) is not applied; one
    that pushes is. A split step still makes one output sample, its controller sample (at the
    step's start) and one actuator-lag update; the sample's accelerations are the first stage
    of the step, as for any step. Only the few split steps allocate and call the road again;
    the others pay one dictionary look-up.

    Every array lives in preallocated buffers (states ``(2n, P, 1)``) and each stage is a few
    whole-population operations: two small matrix products and the element forces. A sample
    at ``t_k`` holds the state, the accelerations ``f(y_k)`` - the first stage of step k, so
    they cost nothing more - and the controller's coefficients and records in force over
    step k (from ``t_k`` on); the last sample, where no step begins, asks the controller once
    more and evaluates the accelerations.

    A single design is integrated as two identical columns: BLAS multiplies one column by a
    matrix-vector kernel whose rounding differs from the matrix-matrix kernel's. Beyond that,
    OpenBLAS chooses its kernels by the shapes, batch width included, and some choices round
    some rows differently (by an ulp): a design re-simulated in a batch of another width agrees
    with its first run to rounding, while the same batch repeats bit for bit.
    """
    n, P = asm.n, asm.P
    n2, width = 2 * n, max(P, 2)
    evaluate = asm.evaluator(width=width)
    y, ys = np.zeros((n2, width, 1)), np.empty((n2, width, 1))
    s1, s2, s3, s4 = (np.empty((n2, width, 1)) for _ in range(4))
    coef = np.broadcast_to(asm.coef, asm.coef.shape[:1] + (width, 1)).copy()
    half = 0.5 * dt
    active = offsets.any(axis=(1, 2, 3))
    if offsets.size * width <= _WIDE_OFFSETS:          # small batches: no broadcasting
        offsets = widen(offsets, width)
    # the inputs' part of each half-step, None where it is zero (a bump's road before and after)
    offsets = [o if a else None for o, a in zip(offsets, active)]
    # Each stage's slope is scaled by the step it is used with, so that a stage state is one
    # addition: s1 = dt/2 k1, s2 = dt/2 k2, s3 = dt k3, s4 = dt/6 k4, and
    # y += dt/6 (k1 + 2 k2 + 2 k3 + k4) = (s1 + 2 s2 + s3)/3 + s4. The first stage is
    # evaluated unscaled (it is the sample's acceleration) and scaled after.
    # A stage: (state, half-steps after t_k, M^-1 scaled, slope and its views, scale, target)
    flat = {id(a): a.reshape(n2, width) for a in (y, ys)}

    def plan(state, shift, slope, h, target):
        return (flat[id(state)], shift, widen(asm.inverse_mass * h, width),
                slope[n:].reshape(n, width), slope[n:], slope[:n], state[n:], h, slope, target)
    first = plan(y, 0, s1, 1.0, ys)
    stages = (plan(ys, 1, s2, half, ys), plan(ys, 1, s3, dt, ys), plan(ys, 2, s4, dt / 6.0, None))
    n_out = n_steps // every + 1
    # samples go to a time-major block (one contiguous write each), and each full block is
    # moved to the (rows, P, T) records as a transposed copy: cache-friendly, unlike moving
    # the whole time-major record at the end (ten times slower for 1000 designs)
    states, accelerations = np.empty((n2, P, n_out)), np.empty((n, P, n_out))
    y2, _, unscaled_mass, acc2, acc = first[:5]
    recorded = [(y, states), (acc, accelerations)]        # (buffer, its record)
    # controller quantities are stored when they change, at the controller's samples (a lagged
    # damper's coefficients apart: they change every step and are recorded like a state)
    held_damping: list[np.ndarray] = []     # (P, N) views of the commands
    held_records: list[dict[str, np.ndarray]] = []
    changes: list[int] = []                 # the output samples at which they were stored
    last_samples = [-1]
    diverged_at = np.full(P, np.nan)
    step_index = [0]
    third, multiply, add = 1.0 / 3.0, np.multiply, np.add

    def vehicle_acceleration() -> np.ndarray:
        evaluate(y2, offsets[step_index[0]], coef, unscaled_mass, acc2, acc)
        return acc[:n_vehicle, :P, 0].copy()
    vehicle = _VehicleState(y[n:n + n_vehicle, :P, 0], vehicle_acceleration)
    if controller is not None:
        damping = coef[asm.damper_rows]                   # (N, width, 1), a view
        command = [controller.start(P)]                   # the latest command (P, 1, N)
        damping[...] = command[0].transpose(2, 0, 1)
        sample_every, decay = controller.sample_every, controller.lag_decay
        if decay is not None:
            decay = widen(decay.transpose(2, 0, 1), width)
            rise, pulled = 1.0 - decay, np.empty_like(damping)
            lagged = np.empty((damping.shape[0], P, n_out))    # a new value every step
            recorded.append((damping, lagged))

    def control(k: int) -> None:
        """The controller's sample at step k (when due) and the actuator's response."""
        if k % sample_every == 0:
            step_index[0] = 2 * k
            command[0] = controller.sample(k, k * dt, vehicle)
            new = command[0].transpose(2, 0, 1)
            if decay is None:
                damping[...] = new
            else:
                multiply(new, rise, out=pulled)
        if decay is not None:   # c <- c_cmd - (c_cmd - c) exp(-dt/τ) = c e + c_cmd (1 - e)
            multiply(damping, decay, out=damping)
            add(damping, pulled, out=damping)

    blocks = []                             # (buffer, time-major block and its 2-D view, record)
    for buffer, record in recorded:
        block = np.empty((_BLOCK,) + record.shape[:2])
        blocks.append((buffer, block, block.reshape(_BLOCK, -1), record.reshape(-1, n_out)))

    def keep(j: int) -> None:
        """Sample j: the state, the accelerations just evaluated into s1 (and a lagged
        damper's coefficients)."""
        row = j % _BLOCK
        for buffer, block, _, _ in blocks:
            block[row] = buffer[:, :P, 0]
        if row == _BLOCK - 1 or j == n_out - 1:
            for _, _, by_sample, by_time in blocks:
                by_time[:, j - row:j + 1] = by_sample[:row + 1].T
        if controller is not None and controller.samples != last_samples[0]:
            held_records.append(controller.record())      # they change with samples only
            if decay is None:
                held_damping.append(command[0][:, 0])     # the damping is the command
            changes.append(j)
            last_samples[0] = controller.samples

    # the steps k with road edges in (t_k, t_k+1] (the grid as _run's, t_k = 2k dt/2), by step
    split: dict[int, list[int]] = {}
    if edges is not None:
        bounds = np.arange(2 * n_steps + 1)[::2] * half
        for e, k in enumerate(np.searchsorted(bounds, edges.times) - 1):
            if edges.times[e] >= 0.0 and k < n_steps:
                split.setdefault(int(k), []).append(e)
        R = asm.R
        rate_forces = asm.G2[..., R:2 * R]      # q'' per unit viscous force, times M

    def derivative(state: np.ndarray, offset: np.ndarray | None) -> np.ndarray:
        """[q'; q''] at ``state`` (2n, width, 1), in a new array (split steps only)."""
        out = np.empty_like(state)
        out[:n] = state[n:]
        evaluate(state.reshape(n2, width), offset, coef, unscaled_mass,
                 out[n:].reshape(n, width), out[n:])
        return out

    def impulse(e: int) -> None:
        """The velocity jump M^-1 G (c D_u Δu) of the inputs' jump Δu at edge e."""
        force = coef[R:2 * R] * (asm.input_map @ edges.jumps[e])[:, None, None]   # [N s]
        if edges.no_pull is not None:   # a tyre that cannot pull takes no pulling impulse
            force[edges.no_pull] = np.minimum(force[edges.no_pull], 0.0)
        force2 = force.reshape(R, width)
        jump = rate_forces @ force2 if rate_forces.ndim == 2 \
            else np.einsum("prc,cp->rp", rate_forces, force2)
        y[n:] += jump[:, :, None] * unscaled_mass

    def split_step(k: int, found: list[int]) -> None:
        """Step k in RK4 sub-steps between the edges ``found`` inside it, each edge's impulse
        applied at its instant (the first stage, at t_k, is the step's as always)."""
        times, end = edges.times[found], bounds[k + 1]
        ends = np.append(times[times < end], end)
        starts = np.insert(ends[:-1], 0, bounds[k])
        h = ends - starts
        rights, middles = edges.inputs(starts, False), edges.inputs(starts + 0.5 * h, False)
        lefts = edges.inputs(ends, True)
        for j, step in enumerate(h):
            k1 = derivative(y, offsets[2 * k] if j == 0 else rights[j])
            k2 = derivative(y + 0.5 * step * k1, middles[j])
            k3 = derivative(y + 0.5 * step * k2, middles[j])
            k4 = derivative(y + step * k3, lefts[j])
            y[...] += step / 6.0 * (k1 + 2.0 * (k2 + k3) + k4)
            if j < len(found) and edges.jumps[found[j]].any():
                impulse(found[j])

    q_rate1, v1 = first[5], first[6]
    with np.errstate(over="ignore", invalid="ignore"):
        for e in split.pop(-1, []):                     # edges at t = 0: before the first sample
            if edges.jumps[e].any():
                impulse(e)
        for k in range(n_steps):
            i = 2 * k
            if controller is not None and (decay is not None or k % sample_every == 0):
                control(k)
            evaluate(y2, offsets[i], coef, unscaled_mass, acc2, acc)
            if k % every == 0:
                keep(k // every)
            if k in split:
                split_step(k, split[k])
            else:
                acc *= half
                multiply(v1, half, out=q_rate1)
                add(y, s1, out=ys)
                for state2, shift, inverse_mass, out2, out, q_rate, v, h, slope, target in stages:
                    evaluate(state2, offsets[i + shift], coef, inverse_mass, out2, out)
                    multiply(v, h, out=q_rate)
                    if target is not None:
                        add(y, slope, out=target)
                s1 += s3
                s2 *= 2.0
                s1 += s2
                s1 *= third
                s1 += s4
                y += s1
            if (k + 1) % _CHECK_EVERY == 0 or k + 1 == n_steps:
                bad = ~(np.abs(flat[id(y)][:, :P]) < DIVERGENCE_LIMIT).all(axis=0)
                new_bad = bad & np.isnan(diverged_at)
                if new_bad.any():
                    diverged_at[new_bad] = (k + 1) * dt
                    y[:, :P][:, bad] = np.nan
        if n_steps % every == 0:                         # the final instant is a sample
            if controller is not None:
                control(n_steps)
            evaluate(y2, offsets[2 * n_steps], coef, unscaled_mass, acc2, acc)
            keep(n_out - 1)

    damping_held, records_held = None, {}
    if controller is not None:
        held_at = np.searchsorted(changes, np.arange(n_out), side="right") - 1  # which holds
        damping_held = lagged if decay is not None \
            else _Held(lambda: _stacked(held_damping), held_at)

        def publish() -> dict[str, np.ndarray]:
            return controller.published({name: _stacked([h[name] for h in held_records])
                                         for name in held_records[0]})
        records_held = _HeldRecords(controller.units, publish, held_at)
    return _Trajectory(states=states, accelerations=accelerations, damping=damping_held,
                       records=records_held, diverged_at=diverged_at)


def prepare(cfg: Config, params: Mapping[str, Any] | None = None):
    """Designs, model, controller and attachments of a run, after the checks that need no
    integration (so that bad input fails before any): the time grid and the road against
    ``dt`` (:func:`suspopt.checks.check_steps`), and the metric specs and ``output.signals``
    against the signals the run will have."""
    check_steps(cfg)
    pv = ParamView(cfg, params)
    model = build_vehicle(cfg, pv)
    controller: Controller | None = build_controller(cfg, pv, model)
    attachments: list[Attachment] = build_attachments(cfg, pv)
    available = signal_names(model, getattr(controller, "units", {}), attachments)
    for i, spec in enumerate(cfg.metrics):
        try:
            spec_signals(spec, available, model.corners)
        except ValueError as exc:
            raise cfg.error(("metrics", i, "signal"), str(exc)) from None
    if cfg.output.signals != "all":
        for i, name in enumerate(cfg.output.signals):
            if name not in available:
                close = difflib.get_close_matches(name, available, n=3)
                raise cfg.error(("output", "signals", i), f"unknown signal {name!r}" + (
                    f"; did you mean {', '.join(close)}?" if close else ""))
    return pv, model, controller, attachments


def simulate(cfg: Config, params: Mapping[str, Any] | None = None) -> "Result":
    """Simulate ``cfg`` for one design, or for P designs given as dotted-path arrays.

    ``params`` maps dotted config paths (e.g. ``"vehicle.corners.F1.damper.c"``) to arrays of
    shape (P,). Returns a :class:`Result` whose signals are (P, T) and whose ``metrics`` hold
    the config's ``metrics:`` specs as (P,) arrays.
    """
    pv, model, controller, attachments = prepare(cfg, params)
    check_memory(cfg, model, attachments, pv.P, signals=len(cfg.metrics))
    result = _run(cfg, pv, model, controller, attachments)
    for spec in cfg.metrics:
        for name, values, unit in evaluate_spec(spec, result, result.signal_unit):
            result.metrics[name] = values
            result.metric_units[name] = unit
    return result


def run_memory(cfg: Config, model: VehicleModel, attachments: Sequence[Attachment], P: int,
               signals: int = 0) -> tuple[float, float]:
    """Peak bytes of a run of P designs, ``(shared, per_design)``: what does not grow with P
    (the road's inputs on the half-step grid, their part of the element deformations) and
    what each design adds (its states and accelerations at every output sample, the
    controller's records, the caches behind its signals, ``signals`` signals computed from
    them, the ISO 2631 weighting's transforms). An estimate from the arrays the integrator and
    :class:`Result` allocate, rounded up."""
    sim, road = cfg.simulation, cfg.road
    n = model.n_dof + sum(len(att.dof_names) for att in attachments)
    rows = sum(g.size for g in model.network.groups) + sum(
        g.size for att in attachments for g in att.network.groups)
    corners = len(model.corners)
    half_steps = 2 * sim.n_steps + 1
    samples = sim.n_steps // sim.output_every + 1
    span = road.speed * sim.duration + float(np.max(model.offsets, initial=0.0))
    shared = road_memory(road, corners, half_steps, span) + 8.0 * half_steps * 2 * rows
    # states, accelerations, deformation and force caches, held records, signals, transforms
    per_design = 8.0 * samples * (3 * n + 8 * corners + 4 * corners + signals + 6)
    return shared, per_design


def check_memory(cfg: Config, model: VehicleModel, attachments: Sequence[Attachment], P: int,
                 signals: int = 0) -> None:
    """ConfigError when a run of P designs (:func:`run_memory`) needs more memory than the
    limit (:func:`suspopt.memory.check`)."""
    shared, per_design = run_memory(cfg, model, attachments, P, signals)
    memory.check(shared + P * per_design, f"simulating {P} design{'s' if P > 1 else ''} for "
                 f"{cfg.simulation.duration:g} s at dt = {cfg.simulation.dt:g} s",
                 ("simulate fewer designs at once, " if P > 1 else "")
                 + "shorten simulation.duration, raise simulation.dt or output_dt, store fewer "
                 "output.signals" + (", lower road.n_max or set road.n_waves"
                                     if cfg.road.kind == "iso8608" else ""))


def _run(cfg: Config, pv: ParamView, model: VehicleModel, controller: Controller | None,
         attachments: Sequence[Attachment]) -> "Result":
    sim = cfg.simulation
    n_steps, every = sim.n_steps, sim.output_every
    t_grid = np.arange(2 * n_steps + 1) * (0.5 * sim.dt)
    z, zd = road_inputs(cfg.road, model.offsets, model.sides, t_grid, base_dir=cfg.base_dir)
    network = full_network(model, attachments)
    asm = _Assembled(network, pv.P, controlled="suspension" if controller else None)
    times, jumps = road_edges(cfg.road, model.offsets, model.sides)
    edges = None
    if times.size:
        def inputs(t: np.ndarray, left: bool) -> np.ndarray:
            return asm.offsets(*road_inputs(cfg.road, model.offsets, model.sides, t,
                                            base_dir=cfg.base_dir, left=left))
        no_pull = np.concatenate([np.full(g.size, g.name == "tyre") for g in network.groups]) \
            if cfg.vehicle.tyre_lift_off else None
        edges = _Edges(times, jumps.T, inputs, no_pull)
    traj = _integrate(asm, model.n_dof, asm.offsets(z, zd), sim.dt, n_steps, every, controller,
                      edges)
    out_idx = np.arange(0, 2 * n_steps + 1, 2 * every)
    return Result(config=cfg, model=model, time=t_grid[out_idx], states=traj.states,
                  accelerations=traj.accelerations, road=z[:, None, out_idx],
                  road_vel=zd[:, None, out_idx],
                  diverged_at=traj.diverged_at, designs=dict(pv.params), _assembled=asm,
                  attachments=tuple(attachments), held_damping=traj.damping,
                  controller_records=traj.records,
                  controller_units=dict(getattr(controller, "units", {})))


_BODY_UNITS = {"heave": "m", "roll": "rad", "pitch": "rad"}


def signal_units(name: str) -> str:
    """SI unit of a signal name."""
    head = name.split(".")[0]
    if head in _SEAT_HEADS:
        return _seat_signal_units(name)
    if head == "body":
        dof, _, deriv = name.split(".")[1].partition("_")
        base = _BODY_UNITS[dof]
        return {"": base, "vel": base + "/s", "acc": base + "/s^2"}[deriv]
    if head == "wheel":
        return {"heave": "m", "heave_vel": "m/s", "heave_acc": "m/s^2"}[name.split(".")[2]]
    return {"travel": "m", "travel_vel": "m/s", "tyre_deflection": "m", "tyre_force": "N",
            "spring_force": "N", "damper_force": "N", "damping": "N s/m", "road": "m",
            "road_vel": "m/s"}[head]


def signal_names(model: VehicleModel, controller_units: Mapping[str, str] = {},
                 attachments: Sequence[Attachment] = ()) -> list[str]:
    """Every signal a simulation of this model (controller, attachments) provides."""
    names = []
    for dof in model.body_dofs:
        names += [f"body.{dof}", f"body.{dof}_vel", f"body.{dof}_acc"]
    for c in model.corners:
        names += [f"wheel.{c}.heave", f"wheel.{c}.heave_vel", f"wheel.{c}.heave_acc"]
    for head in ("travel", "travel_vel", "tyre_deflection", "tyre_force", "spring_force",
                 "damper_force", "damping", "road", "road_vel", *controller_units):
        names += [f"{head}.{c}" for c in model.corners]
    for att in attachments:
        names += att.signal_names()
    return names


class SignalMap(Mapping):
    """Lazy, cached mapping of signal name -> (P, T) array, computed from the states."""

    def __init__(self, result: "Result"):
        # the result keeps the cache, not this map: a cycle result <-> map would keep the
        # (large) arrays alive until the cyclic garbage collector happens to run
        self._result = result
        self._cache = result._signal_cache
        self._names = result._signal_names
        self._attachment_of = {name: j for j, att in enumerate(result.attachments)
                               for name in att.signal_names()}

    def __iter__(self) -> Iterator[str]:
        return iter(self._names)

    def __len__(self) -> int:
        return len(self._names)

    def __contains__(self, name: object) -> bool:
        return name in self._names

    def __getitem__(self, name: str) -> np.ndarray:
        if name not in self._cache:
            if name not in self._names:
                close = difflib.get_close_matches(name, self._names, n=3)
                raise KeyError(f"unknown signal {name!r}" +
                               (f"; did you mean {', '.join(close)}?" if close else ""))
            self._cache[name] = self._compute(name)
        return self._cache[name]

    def _compute(self, name: str) -> np.ndarray:
        r = self._result
        m = r.model
        if name in self._attachment_of:
            return r.attachment_signal(self._attachment_of[name], name)
        parts = name.split(".")
        head = parts[0]
        if head == "body":
            dof, _, deriv = parts[1].partition("_")
            return r.channel(deriv, m.body_dofs.index(dof))
        c = m.corners.index(parts[1])
        if head in r.controller_records:
            return r.controller_records[head].corner(c)
        if head == "wheel":
            return r.channel(parts[2].partition("_")[2], m.n_body + c)
        if head in ("road", "road_vel"):
            src = r.road if head == "road" else r.road_vel
            return np.broadcast_to(src[c], (m.P, r.time.size)).copy()
        if head == "travel":
            return r.deformation("suspension")[c]
        if head == "travel_vel":
            return r.deformation("suspension", rate=True)[c]
        if head == "tyre_deflection":
            return r.deformation("tyre")[c]
        if head == "spring_force":
            return r.element_forces("suspension")[0][c]
        if head == "damper_force":
            return r.element_forces("suspension")[1][c]
        if head == "damping":
            return np.broadcast_to(r.damping_coefficient()[c], (m.P, r.time.size)).copy()
        if head == "tyre_force":
            # the normal load, compression +: static load less the tyre element's force
            elastic, viscous = r.element_forces("tyre")
            static = m.static_tyre_load[:, 0, c, None]
            force = elastic[c] + viscous[c]
            if r.config.vehicle.tyre_lift_off:
                # a lifted tyre carries exactly 0: the force is capped at the static load, and
                # adding the capped parts back up can round past the cap by an ulp
                force = np.minimum(force, static)
            return static - force
        raise KeyError(name)


@dataclass
class Result:
    """Output of :func:`simulate`.

    ``time (T,)`` [s]; ``signals[name] (P, T)`` (lazy); ``metrics[name] (P,)``;
    ``diverged (P,)`` and ``diverged_at (P,)`` [s, NaN when fine]; ``designs`` the (P,) arrays of
    the design parameters by dotted path; ``states (2n, P, T)`` the raw [q, q'] samples, DOF
    by DOF (vehicle, then attachments), and ``accelerations (n, P, T)`` their q''. A sample
    at ``t`` holds what is in force from ``t`` on: a semi-active damper's coefficient (and so
    its force and the accelerations) is the one set at ``t`` when ``t`` is a sample instant
    of its controller.
    """

    config: Config
    model: VehicleModel
    time: np.ndarray
    states: np.ndarray
    accelerations: np.ndarray
    road: np.ndarray            # (N, 1, T) road height under each wheel [m]
    road_vel: np.ndarray        # (N, 1, T) [m/s]
    diverged_at: np.ndarray
    designs: dict[str, np.ndarray]
    _assembled: _Assembled
    attachments: tuple[Attachment, ...] = ()
    held_damping: _Held | np.ndarray | None = None
    controller_records: Mapping[str, _Held] = field(default_factory=dict)
    controller_units: dict[str, str] = field(default_factory=dict)
    metrics: dict[str, np.ndarray] = field(default_factory=dict)
    metric_units: dict[str, str] = field(default_factory=dict)

    def __post_init__(self):
        self._signal_cache: dict[str, np.ndarray] = {}
        self._signal_names = signal_names(self.model, self.controller_units, self.attachments)
        self._deformation: dict[tuple[str, bool], np.ndarray] = {}
        self._forces: dict[str, tuple[np.ndarray, np.ndarray]] = {}
        self._damping_full: np.ndarray | None = None

    @property
    def signals(self) -> SignalMap:
        """Signal name -> (P, T) array, computed on first use and cached."""
        return SignalMap(self)

    def signal_unit(self, name: str) -> str:
        """SI unit of a signal of this result."""
        head = name.split(".")[0]
        if head in self.controller_units:
            return self.controller_units[head]
        return signal_units(name)

    @property
    def P(self) -> int:
        return self.states.shape[1]

    @property
    def n(self) -> int:
        """Number of DOFs (vehicle and attachments)."""
        return self._assembled.n

    @property
    def diverged(self) -> np.ndarray:
        """(P,) True where the design's simulation diverged."""
        return ~np.isnan(self.diverged_at)

    @property
    def q(self) -> np.ndarray:
        """Displacements of every DOF (vehicle, then attachments), (P, T, n) (a view)."""
        return np.moveaxis(self.states[:self.n], 0, -1)

    @property
    def v(self) -> np.ndarray:
        """Velocities of every DOF, (P, T, n) (a view)."""
        return np.moveaxis(self.states[self.n:], 0, -1)

    def damping_coefficient(self) -> np.ndarray:
        """Damper coefficient of every corner, (N, P, T) or (N, P, 1) when passive [N s/m]."""
        if self.damping_history is None:
            return self.model.network.group("suspension").damping
        return self.damping_history

    @property
    def damping_history(self) -> np.ndarray | None:
        """(N, P, T) damping coefficients of a controlled run [N s/m], None when passive."""
        if self.held_damping is None or isinstance(self.held_damping, np.ndarray):
            return self.held_damping
        if self._damping_full is None:
            self._damping_full = self.held_damping.full()
        return self._damping_full

    def deformation(self, group: str, rate: bool = False) -> np.ndarray:
        """Deformations (or their rates) of a vehicle element group, (m, P, T): ``suspension``
        the travel ST [m], ``tyre`` the tyre deflection TD [m], ``anti_roll_bar`` the twist."""
        key = (group, rate)
        if key not in self._deformation:
            g = self.model.network.group(group)
            nv = self.model.n_dof
            x = self.states[self.n:self.n + nv] if rate else self.states[:nv]
            self._deformation[key] = g.deformation(x, self.road_vel if rate else self.road)
        return self._deformation[key]

    def element_forces(self, group: str) -> tuple[np.ndarray, np.ndarray]:
        """The elastic and viscous forces (m, P, T) [N] of a vehicle element group (the
        suspension's spring force F_K and damper force F_C, Eq 2.30-2.32; the tyre's
        F_T parts, Eq 2.28-2.29), with the controller's damping where it has one."""
        if group not in self._forces:
            damping = self.damping_history if group == "suspension" else None
            self._forces[group] = self.model.network.group(group).parts_at(
                self.deformation(group), self.deformation(group, rate=True), damping)
        return self._forces[group]

    def acceleration(self) -> np.ndarray:
        """Accelerations of every DOF, (n, P, T): the equations of motion at each sample, as
        the integrator evaluated them."""
        return self.accelerations

    def base(self, j: int, x: np.ndarray) -> np.ndarray:
        """Body displacement (velocity, acceleration) at attachment ``j``'s point, (P, T),
        from the vehicle rows of ``x (n_vehicle, P, T)``."""
        row = self.model.point_map(*self.attachments[j].point)
        return np.tensordot(row, x[:self.model.n_dof], axes=1)

    def attachment_signal(self, j: int, name: str) -> np.ndarray:
        nv = self.model.n_dof
        start = nv + sum(len(a.dof_names) for a in self.attachments[:j])
        sl = slice(start, start + len(self.attachments[j].dof_names))
        n = self.n
        q, v, acc = self.states[:n], self.states[n:], self.acceleration()
        return self.attachments[j].signal(name, q[sl], v[sl], acc[sl], self.base(j, q),
                                          self.base(j, v), self.base(j, acc))

    def channel(self, deriv: str, j: int) -> np.ndarray:
        """DOF ``j`` displacement (''), velocity ('vel') or acceleration ('acc'), (P, T)."""
        if deriv == "":
            return self.states[j]
        if deriv == "vel":
            return self.states[self.n + j]
        return self.acceleration()[j]
