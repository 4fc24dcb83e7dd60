"""The batched fixed-step integrator: classical RK4 of an assembled element network.

:class:`Assembled` packs the equations of motion of the vehicle with its attachments
(:mod:`suspopt.network`) for fast evaluation of the accelerations; :func:`integrate` advances
all P designs together, states ``(2n, P, 1)`` - DOF by DOF, each a contiguous row over the
designs - each stage two small matrix products and the element forces on whole rows, in
preallocated buffers, with no Python loop over designs. Its parts are separate: the steps
(:class:`_RK4`, and :class:`_Splitter` for the steps that meet a road edge), the samples
(:class:`_Recorder`), the controller's samples, hold and actuator lag
(:class:`_ControllerHold`, for a :class:`Controller`) and the divergence check
(:class:`_Divergence`). The road is sampled on the half-step grid the stages need.

Road edges (``edges``; the bumps' jumps in z or its rate, Eq 2.101-2.104) are seen at their
instants. A step whose interior holds edges is split at them into RK4 sub-steps; each sub-step's
last stage takes the road's left limit at its end and the next one's first stage the right limit,
so a step ending on an edge uses the left limit in its last stage and one starting on it (the grid)
the right limit. Where the inputs jump by ``Δu`` their rate holds a Dirac ``Δu δ(t - t_e)``,
integrated exactly: an impulse ``c D_u Δu`` [N s] of the viscous elements that see the road (the
tyre damping c_T, Eq 2.29), so the velocities jump by ``M^-1 (-D_qᵀ) (c D_u Δu)`` at the edge (the
elastic forces stay bounded and give no impulse). A tyre that may lift off cannot pull (its force
capped at the static load): its impulse at an edge where it would pull is not applied. A split step
still makes one output sample (the accelerations of its first stage), its controller sample (at its
start) and one actuator-lag update. Only the few split steps allocate and call the road again.

A sample at ``t_k`` holds the state, the accelerations ``f(y_k)`` - the first stage of
step k, so they cost nothing more - and the controller's coefficients and records in force
over step k (from ``t_k`` on); the last sample, where no step begins, asks the controller
once more and evaluates the accelerations. :func:`windows` hands the samples over in
windows of time, for a run that keeps no whole record (:mod:`suspopt.streaming`).

A single design is integrated as two identical columns: BLAS multiplies one column by a
matrix-vector kernel whose rounding differs from the matrix-matrix kernel's. Beyond that,
OpenBLAS chooses its kernels by the shapes, batch width included, and some choices round
some rows differently (by an ulp): a design re-simulated in a batch of another width agrees
with its first run to rounding, while the same batch repeats bit for bit.

A design whose state becomes non-finite or exceeds :data:`DIVERGENCE_LIMIT` gets its time in
``Trajectory.diverged_at`` and NaN samples from then on: it never passes for a valid one.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator, Mapping
from dataclasses import dataclass
from typing import NamedTuple, Protocol

import numpy as np

from ..network import Assembled, widen

__all__ = [
    "Controller",
    "Held",
    "HeldRecords",
    "Trajectory",
    "Edges",
    "Run",
    "integrate",
    "windows",
    "DIVERGENCE_LIMIT",
]

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

    @property
    def sample_every(self) -> int: ...

    @property
    def lag_decay(self) -> np.ndarray | None: ...

    def start(self, P: int) -> np.ndarray: ...

    def sample(self, k: int, t: float, state: _VehicleState) -> np.ndarray: ...

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


class Held:
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


class HeldRecords(Mapping):
    """The controller's records by name, each a :class:`Held` of one index: published (see
    the ``Controller`` protocol) from the values kept at each sample when one is first read."""

    def __init__(
        self, names: Iterable[str], publish: Callable[[], dict[str, np.ndarray]], index: np.ndarray
    ):
        self._names, self._index = tuple(names), index
        self._publish: Callable[[], dict[str, np.ndarray]] | None = publish
        self._held: dict[str, Held] | None = None

    def __getitem__(self, name: str) -> Held:
        if name not in self._names:
            raise KeyError(name)
        if self._held is None:
            assert self._publish is not None  # (published once, then dropped)
            self._held = {n: Held(v, self._index) for n, v in self._publish().items()}
            self._publish = None
        return self._held[name]

    def __contains__(self, name: object) -> bool:
        return name in self._names

    def __iter__(self) -> Iterator[str]:
        return iter(self._names)

    def __len__(self) -> int:
        return len(self._names)


@dataclass
class Trajectory:
    """What one integration produced: states (2n, P, T), accelerations (n, P, T), the damping
    coefficients (held between changes, or (N, P, T) when a lagged actuator changes them
    every step) and controller records (or None / empty without a controller) and the
    divergence times (P,)."""

    states: np.ndarray
    accelerations: np.ndarray
    damping: Held | np.ndarray | None
    records: Mapping[str, Held]
    diverged_at: np.ndarray
    engine: str = "numpy"  #: the integrator that ran (:mod:`suspopt.integrator`)


def _stacked(arrays: list[np.ndarray]) -> np.ndarray:
    """``np.stack(arrays)`` of equal-shaped arrays (of at least one dimension) by one
    concatenation: for thousands of small arrays np.stack takes about three times as long."""
    return np.concatenate(arrays).reshape((len(arrays),) + arrays[0].shape)


class Edges(NamedTuple):
    """The road's edges (:func:`suspopt.road.road_edges`) as :func:`integrate` takes them."""

    times: np.ndarray  #: (E,) ascending [s]
    jumps: np.ndarray  #: (E, n_u) the step in the inputs u at each edge [m] ((E, G, n_u): G roads)
    #: ``inputs(t, left)``: the inputs' part (T, 2R, G, 1) at ``t`` (T,), left limits if ``left``
    inputs: Callable[[np.ndarray, bool], np.ndarray]
    #: (R,) element rows that cannot pull (a tyre that may lift off), or None
    no_pull: np.ndarray | None


class _Recorder:
    """The output samples: each buffer's rows of the first P columns go to a time-major block
    (one contiguous write each), and each full block moves to its ``(rows, P, T)`` record as a
    transposed copy, cache-friendly, unlike moving a whole time-major record at the end (ten
    times slower for 1000 designs)."""

    def __init__(self, buffers: list[tuple[np.ndarray, np.ndarray]], P: int, n_out: int):
        self.P, self.n_out = P, n_out
        self.blocks = []
        for buffer, record in buffers:
            block = np.empty((_BLOCK,) + record.shape[:2])
            self.blocks.append(
                (buffer, block, block.reshape(_BLOCK, -1), record.reshape(-1, n_out))
            )

    def keep(self, j: int) -> None:
        """Sample ``j`` of every buffer."""
        row, P = j % _BLOCK, self.P
        for buffer, block, _, _ in self.blocks:
            block[row] = buffer[:, :P, 0]
        if row == _BLOCK - 1 or j == self.n_out - 1:
            for _, _, by_sample, by_time in self.blocks:
                by_time[:, j - row : j + 1] = by_sample[: row + 1].T


class _ControllerHold:
    """The controller's side of the integration: its samples every ``sample_every`` steps
    (zero-order hold of the command in the damper rows of ``coef``), the actuator's lag once
    per step, and the values to publish, stored when they change (at the controller's
    samples; a lagged coefficient changes every step and is recorded like a state)."""

    def __init__(
        self,
        controller: Controller,
        coef: np.ndarray,
        rows: slice,
        P: int,
        n_out: int,
        dt: float,
        vehicle: _VehicleState,
    ):
        self.controller, self.dt, self.vehicle = controller, dt, vehicle
        self.damping = coef[rows]  # (N, width, 1), a view
        self.command = controller.start(P)  # the latest command (P, 1, N)
        self.damping[...] = self.command.transpose(2, 0, 1)
        self.every, decay = controller.sample_every, controller.lag_decay
        self.sample_index = 0  # the half step of the latest sample
        self.decay = (
            None if decay is None else widen(decay.transpose(2, 0, 1), self.damping.shape[1])
        )
        self.lagged: np.ndarray | None = None
        if self.decay is not None:
            self.rise, self.pulled = 1.0 - self.decay, np.empty_like(self.damping)
            self.lagged = np.empty((self.damping.shape[0], P, n_out))
        self.held_damping: list[np.ndarray] = []  # (P, N) views of the commands
        self.held_records: list[dict[str, np.ndarray]] = []
        self.changes: list[int] = []  # the output samples where they changed
        self.last_samples = -1

    def due(self, k: int) -> bool:
        """Whether step ``k`` needs the controller (a sample, or the lag)."""
        return self.decay is not None or k % self.every == 0

    def control(self, k: int) -> None:
        """The controller's sample at step ``k`` (when due) and the actuator's response."""
        if k % self.every == 0:
            self.sample_index = 2 * k
            self.command = self.controller.sample(k, k * self.dt, self.vehicle)
            new = self.command.transpose(2, 0, 1)
            if self.decay is None:
                self.damping[...] = new
            else:
                np.multiply(new, self.rise, out=self.pulled)
        if self.decay is not None:  # c <- c_cmd - (c_cmd - c) exp(-dt/τ) = c e + c_cmd (1 - e)
            np.multiply(self.damping, self.decay, out=self.damping)
            np.add(self.damping, self.pulled, out=self.damping)

    def kept(self, j: int) -> None:
        """Output sample ``j`` was taken: store what changed since the last one."""
        controller = self.controller
        if controller.samples != self.last_samples:
            self.held_records.append(controller.record())  # they change with samples only
            if self.decay is None:
                self.held_damping.append(self.command[:, 0])  # the damping is the command
            self.changes.append(j)
            self.last_samples = controller.samples

    def held(self, n_out: int) -> tuple[Held | np.ndarray, HeldRecords]:
        """The damping (held, or the lagged record) and the records of the whole run."""
        held_at = np.searchsorted(self.changes, np.arange(n_out), side="right") - 1
        held_damping, held_records = self.held_damping, self.held_records
        damping: Held | np.ndarray = (
            self.lagged
            if self.lagged is not None
            else Held(lambda: _stacked(held_damping), held_at)
        )

        def publish() -> dict[str, np.ndarray]:
            return self.controller.published(
                {name: _stacked([h[name] for h in held_records]) for name in held_records[0]}
            )

        return damping, HeldRecords(self.controller.units, publish, held_at)


class _Divergence:
    """Designs whose state left ``|x| < DIVERGENCE_LIMIT`` (or became non-finite), checked
    every ``_CHECK_EVERY`` steps: their time ``diverged_at (P,)`` [s] and NaN states from
    then on."""

    def __init__(self, y2: np.ndarray, P: int, dt: float):
        self.y2, self.P, self.dt, self.at = y2, P, dt, np.full(P, np.nan)

    def check(self, k: int, y: np.ndarray, n_steps: int) -> None:
        """After step ``k``."""
        if (k + 1) % _CHECK_EVERY == 0 or k + 1 == n_steps:
            bad = ~(np.abs(self.y2[:, : self.P]) < DIVERGENCE_LIMIT).all(axis=0)
            new_bad = bad & np.isnan(self.at)
            if new_bad.any():
                self.at[new_bad] = (k + 1) * self.dt
                y[:, : self.P][:, bad] = np.nan


class _RK4:
    """Classical RK4 steps of the assembled network, every array in buffers allocated once
    (states ``(2n, width, 1)``; a step is a few whole-population operations: two small matrix
    products and the element forces per stage).

    Each stage's slope is scaled by the step it is used with, so that a stage state is one
    addition: ``s1 = dt/2 k1``, ``s2 = dt/2 k2``, ``s3 = dt k3``, ``s4 = dt/6 k4``, and
    ``y += dt/6 (k1 + 2 k2 + 2 k3 + k4) = (s1 + 2 s2 + s3)/3 + s4``. The first stage is
    evaluated unscaled (:meth:`first`: it is the sample's acceleration, ``acc``) and scaled
    by :meth:`rest`, which takes the step from there.
    """

    def __init__(self, asm: Assembled, width: int, dt: float, offsets: list):
        n = asm.n
        n2 = 2 * n
        self.n, self.n2, self.width, self.dt, self.offsets = n, n2, width, dt, offsets
        self.evaluate = asm.evaluator(width=width)
        self.y, ys = np.zeros((n2, width, 1)), np.empty((n2, width, 1))
        s1, s2, s3, s4 = (np.empty((n2, width, 1)) for _ in range(4))
        self.coef = np.broadcast_to(asm.coef, asm.coef.shape[:1] + (width, 1)).copy()
        self.y2, ys2 = self.y.reshape(n2, width), ys.reshape(n2, width)
        self.unscaled_mass = widen(asm.inverse_mass, width)
        self.acc2, self.acc = s1[n:].reshape(n, width), s1[n:]
        half = 0.5 * dt

        def stage(state2, state, shift, slope, h, target):
            # (state, half-steps after t_k, M^-1 scaled, slope and its views, scale, target)
            return (
                state2,
                shift,
                widen(asm.inverse_mass * h, width),
                slope[n:].reshape(n, width),
                slope[n:],
                slope[:n],
                state[n:],
                h,
                slope,
                target,
            )

        self.rest = self._make_rest(
            s1,
            s2,
            s3,
            s4,
            ys,
            (
                stage(ys2, ys, 1, s2, half, ys),
                stage(ys2, ys, 1, s3, dt, ys),
                stage(ys2, ys, 2, s4, dt / 6.0, None),
            ),
        )

    def first(self, i: int) -> None:
        """The accelerations at the state, with the inputs of half step ``i``, into ``acc``."""
        self.evaluate(self.y2, self.offsets[i], self.coef, self.unscaled_mass, self.acc2, self.acc)

    def _make_rest(self, s1, s2, s3, s4, ys, stages):
        """The rest of a step after :meth:`first` (a closure: its names are local, the
        integrator's hot loop)."""
        y, n, evaluate, offsets, coef = self.y, self.n, self.evaluate, self.offsets, self.coef
        acc, half, third = self.acc, 0.5 * self.dt, 1.0 / 3.0
        q_rate1, v1 = s1[:n], y[n:]
        multiply, add = np.multiply, np.add

        def rest(i: int) -> None:
            acc.__imul__(half)
            multiply(v1, half, out=q_rate1)
            add(y, s1, out=ys)
            for state2, shift, inverse_mass, out2, out, q_rate, v, h, slope, target in stages:
                evaluate(state2, offsets[i + shift], coef, inverse_mass, out2, out)
                multiply(v, h, out=q_rate)
                if target is not None:
                    add(y, slope, out=target)
            s1.__iadd__(s3)
            s2.__imul__(2.0)
            s1.__iadd__(s2)
            s1.__imul__(third)
            s1.__iadd__(s4)
            y.__iadd__(s1)

        return rest

    def derivative(self, state: np.ndarray, offset: np.ndarray | None) -> np.ndarray:
        """[q'; q''] at ``state`` (2n, width, 1), in a new array (split steps only)."""
        n = self.n
        out = np.empty_like(state)
        out[:n] = state[n:]
        self.evaluate(
            state.reshape(self.n2, self.width),
            offset,
            self.coef,
            self.unscaled_mass,
            out[n:].reshape(n, self.width),
            out[n:],
        )
        return out


class EdgePlan:
    """Where the road's edges fall on the step grid of a run: ``steps`` maps each step k
    with edges in ``(t_k, t_k+1]`` to their indices (the grid as the run's, ``t_k = 2k dt/2``),
    ``at_start`` the edges at t = 0, and :meth:`sub_steps` a split step's sub-steps."""

    def __init__(self, edges: Edges, dt: float, n_steps: int):
        self.edges = edges
        self.bounds = np.arange(2 * n_steps + 1)[::2] * (0.5 * dt)
        self.steps: dict[int, list[int]] = {}
        for e, k in enumerate(np.searchsorted(self.bounds, edges.times) - 1):
            if edges.times[e] >= 0.0 and k < n_steps:
                self.steps.setdefault(int(k), []).append(e)
        self.at_start = [e for e in self.steps.pop(-1, []) if edges.jumps[e].any()]

    def sub_steps(self, k: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Step ``k``'s sub-steps between its edges: their lengths ``h`` (J,) [s] and the
        inputs' part of the deformations (J, 2R, 1, 1) at their starts (right limits), their
        middles and their ends (left limits). Sub-step j ends on the step's j-th edge."""
        edges = self.edges
        times, end = edges.times[self.steps[k]], self.bounds[k + 1]
        ends = np.append(times[times < end], end)
        starts = np.insert(ends[:-1], 0, self.bounds[k])
        h = ends - starts
        rights, middles = edges.inputs(starts, False), edges.inputs(starts + 0.5 * h, False)
        return h, rights, middles, edges.inputs(ends, True)


class _Splitter:
    """The steps that hold road edges (:class:`Edges`), split at them into RK4 sub-steps with
    each edge's impulse applied at its instant (see :func:`integrate`)."""

    def __init__(self, rk4: _RK4, asm: Assembled, edges: Edges, n_steps: int):
        self.rk4, self.asm, self.edges = rk4, asm, edges
        self.plan = EdgePlan(edges, rk4.dt, n_steps)
        self.steps = self.plan.steps
        R = asm.R
        self.rate_forces = asm.G2[..., R : 2 * R]  # q'' per unit viscous force, times M

    def at_start(self) -> None:
        """The impulses of edges at t = 0, before the first sample."""
        for e in self.plan.at_start:
            self.impulse(e)

    def impulse(self, e: int) -> None:
        """The velocity jump M^-1 G (c D_u Δu) of the inputs' jump Δu at edge ``e``."""
        rk4, R, edges = self.rk4, self.asm.R, self.edges
        du = self.asm.input_map @ np.atleast_2d(edges.jumps[e]).T  # (R, G): a road per block
        force = rk4.coef[R : 2 * R] * du.repeat(rk4.width // du.shape[1], axis=1)[..., None]
        if edges.no_pull is not None:  # a tyre that cannot pull takes no pulling impulse
            force[edges.no_pull] = np.minimum(force[edges.no_pull], 0.0)
        force2 = force.reshape(R, rk4.width)
        jump = (
            self.rate_forces @ force2
            if self.rate_forces.ndim == 2
            else np.einsum("prc,cp->rp", self.rate_forces, force2)
        )
        rk4.y[rk4.n :] += jump[:, :, None] * rk4.unscaled_mass

    def step(self, k: int) -> None:
        """Step ``k`` in RK4 sub-steps between its edges, each edge's impulse applied at its
        instant (the first stage, at t_k, is the step's as always)."""
        found, edges, rk4 = self.steps[k], self.edges, self.rk4
        y = rk4.y
        h, rights, middles, lefts = self.plan.sub_steps(k)
        for j, step in enumerate(h):
            k1 = rk4.derivative(y, rk4.offsets[2 * k] if j == 0 else rights[j])
            k2 = rk4.derivative(y + 0.5 * step * k1, middles[j])
            k3 = rk4.derivative(y + 0.5 * step * k2, middles[j])
            k4 = rk4.derivative(y + step * k3, lefts[j])
            y[...] += step / 6.0 * (k1 + 2.0 * (k2 + k3) + k4)
            if j < len(found) and edges.jumps[found[j]].any():
                self.impulse(found[j])


def _controller_hold(
    controller: Controller, rk4: _RK4, asm: Assembled, n_vehicle: int, n_out: int, dt: float
) -> _ControllerHold:
    """The controller's hold over the stepper ``rk4``: it reads the vehicle's states and, when
    a law needs them, the accelerations at its sample (the first stage of that step)."""
    n, P = asm.n, asm.P

    def vehicle_acceleration() -> np.ndarray:
        rk4.first(hold.sample_index)
        return rk4.acc[:n_vehicle, :P, 0].copy()

    vehicle = _VehicleState(rk4.y[n : n + n_vehicle, :P, 0], vehicle_acceleration)
    assert asm.damper_rows is not None  # (a controller: the network has semi-active rows)
    hold = _ControllerHold(controller, rk4.coef, asm.damper_rows, P, n_out, dt, vehicle)
    return hold


class Run(NamedTuple):
    """One integration, as every engine takes it: the assembled network (its first
    ``n_vehicle`` DOFs the vehicle's), the inputs' part of the deformations on the half-step
    grid ``t = j dt/2``, ``offsets`` (2 n_steps + 1, 2R, G, 1) (right limits at an edge; G
    roads, each under P/G consecutive designs, edges at shared instants), the step ``dt`` [s],
    the steps, the samples' spacing ``every``, the controller and the edges (or None)."""

    asm: Assembled
    n_vehicle: int
    offsets: np.ndarray
    dt: float
    n_steps: int
    every: int
    controller: Controller | None = None
    edges: Edges | None = None

    def window(self, width: int | None) -> tuple[int, int]:
        """``(output samples, window width)``: width None for all, a controlled run whole."""
        n_out = self.n_steps // self.every + 1
        if self.controller is not None and width is not None and width < n_out:
            raise ValueError("a controlled run is integrated whole (width >= its samples)")
        return n_out, n_out if width is None else width


def integrate(run: Run) -> Trajectory:
    """Classical RK4 of ``run`` (:class:`Run`) over its steps, samples kept every ``every``-th
    step. Road edges, the samples, the controller's hold and the batch width: see the module
    docstring."""
    return next(windows(run))[1]


def windows(run: Run, width: int | None = None) -> Iterator[tuple[int, Trajectory]]:
    """The integration of ``run`` as consecutive windows of at most ``width`` output samples
    (all when None): ``(j0, trajectory of samples j0 ..)``, the steps those of
    :func:`integrate` (the windows joined are its trajectory, bit for bit), ``diverged_at``
    as known at the window's end. A controlled run comes whole (:meth:`Run.window`)."""
    asm, n_vehicle, offsets, dt, n_steps, every, controller, edges = run
    n, P = asm.n, asm.P
    n_out, width = run.window(width)
    columns = max(P, 2)  # (a single design as two identical columns)
    active, roads = np.asarray(offsets.any(axis=(1, 2, 3))), offsets.shape[2]
    if offsets.size // roads * columns <= _WIDE_OFFSETS:  # small batches: no broadcasting
        offsets = widen(offsets, columns) if roads == 1 else offsets.repeat(P // roads, axis=2)
    # the inputs' part of each half-step, None where it is zero (a bump's road before and after)
    rk4 = _RK4(asm, columns, dt, [o if a else None for o, a in zip(offsets, active)])
    hold = None
    if controller is not None:
        hold = _controller_hold(controller, rk4, asm, n_vehicle, n_out, dt)
    divergence = _Divergence(rk4.y2, P, dt)
    splitter = _Splitter(rk4, asm, edges, n_steps) if edges is not None else None
    split = splitter.steps if splitter is not None else {}
    for j0 in range(0, n_out, width):
        j1 = min(j0 + width, n_out)
        states, accelerations = np.empty((2 * n, P, j1 - j0)), np.empty((n, P, j1 - j0))
        buffers = [(rk4.y, states), (rk4.acc, accelerations)]
        if hold is not None and hold.lagged is not None:
            buffers.append((hold.damping, hold.lagged))
        recorder = _Recorder(buffers, P, j1 - j0)
        with np.errstate(over="ignore", invalid="ignore"):
            if j0 == 0 and splitter is not None:
                splitter.at_start()
            for k in range(j0 * every, j1 * every if j1 < n_out else n_steps):
                if hold is not None and hold.due(k):
                    hold.control(k)
                rk4.first(2 * k)
                if k % every == 0:
                    recorder.keep(k // every - j0)
                    if hold is not None:
                        hold.kept(k // every)
                if splitter is not None and k in split:
                    splitter.step(k)
                else:
                    rk4.rest(2 * k)
                divergence.check(k, rk4.y, n_steps)
            if j1 == n_out and n_steps % every == 0:  # the final instant is a sample
                if hold is not None:
                    hold.control(n_steps)
                rk4.first(2 * n_steps)
                recorder.keep(j1 - 1 - j0)
                if hold is not None:
                    hold.kept(n_out - 1)
        damping, records = hold.held(n_out) if hold is not None else (None, {})
        yield j0, Trajectory(states, accelerations, damping, records, divergence.at.copy())
