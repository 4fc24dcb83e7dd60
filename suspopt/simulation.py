"""``simulate(cfg, params)``: P designs of a config simulated in one batch.

:func:`prepare` builds the designs (:class:`~suspopt.params.ParamView`), the vehicle
(:mod:`suspopt.vehicle`), its controller (:mod:`suspopt.control`) and attachments (the seat,
:mod:`suspopt.seat`) after the checks that need no integration; :func:`simulate` integrates
the assembled network (:mod:`suspopt.integrator`) over the road's inputs (:mod:`suspopt.road`)
and returns a :class:`~suspopt.result.Result` with the config's metrics;
:func:`run_memory` estimates what a run allocates, checked before it starts.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, NamedTuple

import numpy as np

from . import memory
from .checks import check_exact, check_steps, full_network, stepped_road
from .config import Config
from .config.loader import require_config
from .controller import build_controller
from .errors import suggest
from .integrator import DIVERGENCE_LIMIT, Controller, Edges, Held, Run, Trajectory, integrate
from .network import Assembled
from .params import ParamView
from .result import Attachment, Result, SignalMap, signal_names, signal_table
from .road import road_edges, road_inputs, road_memory
from .seat import build_attachments
from .specs import evaluate_spec, spec_signals
from .vehicle import VehicleModel, build_vehicle

__all__ = [
    "simulate",
    "prepare",
    "build_run",
    "assemble",
    "check_signals",
    "run_memory",
    "check_memory",
    "signal_names",
    "signal_table",
    "Result",
    "SignalMap",
    "Controller",
    "Attachment",
    "DIVERGENCE_LIMIT",
]


class Prepared(NamedTuple):
    """What :func:`prepare` makes of a config: the designs, the model, the controller (None
    for a passive run) and the attachments (seat, passenger)."""

    pv: ParamView
    model: VehicleModel
    controller: Controller | None
    attachments: list[Attachment]


def stepper(cfg: Config) -> str:
    """What integrates ``cfg``'s runs: ``exact`` for ``simulation.method: exact`` (the exact
    stepper of a linear network, :mod:`suspopt.integrator.exact`), else its
    ``simulation.engine``."""
    return "exact" if cfg.simulation.method == "exact" else cfg.simulation.engine


def prepare(cfg: Config, params: Mapping[str, Any] | None = None) -> Prepared:
    """Designs, model, controller and attachments of a run, after the checks that need no
    integration (so that bad input fails before any): the time grid and the road against
    ``dt`` (:func:`suspopt.checks.check_steps`), and the metric specs and ``output.signals``
    against the signals the run will have (:func:`build_run`). The ConfigError holds the
    problems of both."""
    found = require_config(cfg).problems()
    found.attempt(check_steps, cfg)
    prepared = found.attempt(build_run, cfg, params)
    found.raise_if_any()
    return prepared


def build_run(cfg: Config, params: Mapping[str, Any] | None = None) -> Prepared:
    """:func:`prepare` without the time grid's checks: the designs, the model, its controller
    and attachments (:func:`assemble`), and every metric spec and ``output.signals`` entry
    checked against the signals the run will have (:func:`check_signals`)."""
    prepared = assemble(cfg, params)
    check_signals(cfg, prepared)
    check_exact(cfg, prepared)
    return prepared


def assemble(cfg: Config, params: Mapping[str, Any] | None = None) -> Prepared:
    """The designs, the model, its controller and attachments of a run, unchecked."""
    pv = ParamView(require_config(cfg), params)
    model = build_vehicle(cfg, pv)
    controller: Controller | None = build_controller(cfg, pv, model)
    attachments: list[Attachment] = list(build_attachments(cfg, pv))
    return Prepared(pv, model, controller, attachments)


def check_signals(cfg: Config, prepared: Prepared) -> None:
    """Every metric spec and ``output.signals`` entry of ``cfg`` against the signals of the
    run ``prepared`` (ConfigError with the problems of all of them)."""
    _, model, controller, attachments = prepared
    available = signal_names(model, getattr(controller, "units", {}), attachments)
    found = cfg.problems()
    for i, spec in enumerate(cfg.metrics):
        try:
            spec_signals(spec, available, model.corners)
        except ValueError as exc:
            found.add(("metrics", i, "signal"), str(exc))
    if cfg.output.signals != "all":
        for i, name in enumerate(cfg.output.signals):
            if name not in available:
                close = suggest(name, available)
                found.add(
                    ("output", "signals", i),
                    f"unknown signal {name!r}"
                    + (f"; did you mean {', '.join(close)}?" if close else ""),
                )
    found.raise_if_any()


def simulate(
    cfg: Config, params: Mapping[str, Any] | None = None, prepared: Prepared | None = None
) -> Result:
    """Simulate ``cfg`` for one design, or for P designs given as dotted-path arrays.

    ``params`` maps dotted config paths (e.g. ``"vehicle.corners.F1.damper.c"``) to arrays of
    shape (P,). Returns a :class:`Result` whose signals are (P, T) and whose ``metrics`` hold
    the config's ``metrics:`` specs as (P,) arrays.

    Parameters
    ----------
    cfg : Config
        The study (vehicle, seat, road, control, simulation, metrics).
    params : mapping of str to array_like, optional
        Design parameters by dotted config path, each ``(P,)`` in the field's SI unit (the
        unit the schema gives that key: N/m, N s/m, kg, m, ...); all of one length P.
    prepared : Prepared, optional
        The run already built and checked from ``cfg`` and ``params``
        (``suspopt.simulation.prepare``, or ``suspopt.validation.check_config`` for the
        config's own design), so that a caller that checked it first does not build the
        model again.

    Returns
    -------
    Result
        Signals ``(P, T)`` with their SI units (``Result.signal_unit``), the metrics ``(P,)``
        and the time ``(T,)`` [s].
    """
    if prepared is None:
        prepared = prepare(cfg, params)
    pv, model, _, attachments = prepared
    check_memory(cfg, model, attachments, pv.P, signals=len(cfg.metrics))
    result = _run(with_engine(cfg, pv.P), prepared)
    for spec in cfg.metrics:
        for name, values, unit in evaluate_spec(spec, result, result.signal_unit):
            result.metrics[name] = values
            result.metric_units[name] = unit
    return result


def with_engine(cfg: Config, designs: int, evaluation: bool = False) -> Config:
    """``cfg`` with ``simulation.engine: auto`` resolved for a batch of ``designs``
    (:func:`suspopt.integrator.auto_engine`; an ``evaluation`` of objectives, or a config with
    an ``optimiser:`` section, runs compiled), as a copy; ``cfg`` itself for any other
    engine. Resolved once for the whole batch, before it is cut into chunks, so that every
    executor and chunk width runs the same engine."""
    sim = cfg.simulation
    if sim.engine != "auto":
        return cfg
    from .integrator import auto_engine

    engine = auto_engine(sim.n_steps, designs, evaluation or cfg.optimiser is not None)
    resolved = cfg.model_copy(update={"simulation": sim.model_copy(update={"engine": engine})})
    loaded = cfg._loaded
    if loaded is not None:  # (the engine resolved is no edit: the record stays the text)
        resolved._loaded = {**loaded, "simulation": {**loaded["simulation"], "engine": engine}}
    return resolved


def run_memory(
    cfg: Config,
    model: VehicleModel,
    attachments: Sequence[Attachment],
    P: int,
    signals: int = 0,
    window: int | None = None,
    kept: int = 0,
) -> tuple[float, float]:
    """Peak bytes of a run of P designs, ``(shared, per_design)``: what does not grow with P
    (the road's inputs on the half-step grid, their part of the element deformations) and
    what each design adds (its states and accelerations at every output sample, the
    controller's records, the caches behind its signals, ``signals`` signals computed from
    them, the ISO 2631 weighting's transforms). A run in windows of ``window`` samples
    (:mod:`suspopt.streaming`) holds those for one window only, and ``kept`` signals over
    the whole run. An estimate from the arrays the integrator and :class:`Result` allocate,
    rounded up."""
    sim, road = cfg.simulation, cfg.road
    n = model.n_dof + sum(len(att.dof_names) for att in attachments)
    rows = sum(g.size for g in model.network.groups) + sum(
        g.size for att in attachments for g in att.network.groups
    )
    corners = len(model.corners)
    half_steps = 2 * sim.n_steps + 1
    samples = sim.n_steps // sim.output_every + 1
    span = road.speed * sim.duration + float(np.max(model.offsets, initial=0.0))
    # the inputs' offsets, 2 rows each per half step, and as much again while they are made
    # (network.offsets: the products, then their transposed copy)
    shared = road_memory(road, corners, half_steps, span) + 8.0 * half_steps * 4 * rows
    # states, accelerations, deformation and force caches, held records, signals, transforms
    held = min(samples, window or samples)
    per_design = 8.0 * held * (3 * n + 8 * corners + 4 * corners + signals + 6)
    return shared, per_design + 8.0 * samples * kept


def check_memory(
    cfg: Config, model: VehicleModel, attachments: Sequence[Attachment], P: int, **sizes: Any
) -> None:
    """ConfigError when a run of P designs (:func:`run_memory`, with its ``signals``,
    ``window`` and ``kept``) needs more memory than the limit (:func:`suspopt.memory.check`)."""
    shared, per_design = run_memory(cfg, model, attachments, P, **sizes)
    memory.check(
        shared + P * per_design,
        f"simulating {P} design{'s' if P > 1 else ''} for "
        f"{cfg.simulation.duration:g} s at dt = {cfg.simulation.dt:g} s",
        ("simulate fewer designs at once, " if P > 1 else "")
        + "shorten simulation.duration, raise simulation.dt or output_dt, store fewer "
        "output.signals"
        + (", lower road.n_max or set road.n_waves" if cfg.road.kind == "iso8608" else ""),
        cfg,
        ("simulation",),
    )


def _run(cfg: Config, prepared: Prepared, roads: Sequence[Any] | None = None) -> Result:
    """The integration of a run (:func:`prepare`) and its :class:`Result` (``roads``:
    :func:`_setup`); a batch of several designs on one road goes to the executor in force
    (:mod:`suspopt.execution`) in chunks when that is not ``local``."""
    from . import execution

    pv, model, controller, attachments = prepared
    run, z, zd, t_grid = _setup(cfg, pv, model, controller, attachments, roads)
    chunked = pv.P > 1 and pv.params and not roads and not execution.is_local(cfg.execution)
    if chunked:
        rows = execution.chunks(pv.P, execution.chunk_width(cfg.execution))
        designs = [{k: np.asarray(v)[r] for k, v in pv.params.items()} for r in rows]
        traj = _joined(execution.map_chunks(_chunk_trajectory, cfg, designs, cfg.execution))
    else:
        traj = integrate(run, stepper(cfg))
    return _result(cfg, pv, model, controller, attachments, run, (z, zd, t_grid), traj)


def _result(
    cfg: Config,
    pv: ParamView,
    model: VehicleModel,
    controller: Controller | None,
    attachments: Sequence[Attachment],
    run: Run,
    grid: tuple[np.ndarray, np.ndarray, np.ndarray],
    traj: Trajectory,
    first: int = 0,
) -> Result:
    """The :class:`Result` of trajectory ``traj``, its samples from output sample ``first``
    on (a window of the run, :func:`suspopt.integrator.windows`); ``grid`` is the roads'
    inputs ``z, zd (n_u, G, 2 n_steps + 1)`` on the half-step grid and that grid [s]
    (:func:`_setup`)."""
    sim = cfg.simulation
    z, zd, t_grid = grid
    samples = traj.states.shape[-1]
    step = 2 * sim.output_every
    out_idx = np.arange(first * step, (first + samples) * step, step)
    per_road = pv.P // z.shape[1]  # (the designs under each road)
    return Result(
        config=cfg,
        model=model,
        time=t_grid[out_idx],
        states=traj.states,
        accelerations=traj.accelerations,
        road=z[:, :, out_idx].repeat(per_road, axis=1) if per_road < pv.P else z[:, :, out_idx],
        road_vel=(
            zd[:, :, out_idx].repeat(per_road, axis=1) if per_road < pv.P else zd[:, :, out_idx]
        ),
        diverged_at=traj.diverged_at,
        designs=dict(pv.params),
        _assembled=run.asm,
        attachments=tuple(attachments),
        held_damping=traj.damping,
        controller_records=traj.records,
        controller_units=dict(getattr(controller, "units", {})),
        engine=traj.engine,
    )


def _setup(
    cfg: Config,
    pv: ParamView,
    model: VehicleModel,
    controller: Controller | None,
    attachments: Sequence[Attachment],
    roads: Sequence[Any] | None = None,
) -> tuple[Run, np.ndarray, np.ndarray, np.ndarray]:
    """The integrator's :class:`~suspopt.integrator.Run` of the designs, the roads' inputs
    ``z, zd (n_u, G, 2 n_steps + 1)`` on the half-step grid and that grid [s]. ``roads``
    (G road sections, each checked against the time grid, their edges if any at the same
    instants) drive the designs in G equal blocks of consecutive columns; default: the
    config's road."""
    sim = cfg.simulation
    n_steps, every = sim.n_steps, sim.output_every
    t_grid = np.arange(2 * n_steps + 1) * (0.5 * sim.dt)
    network = full_network(model, attachments)
    asm = Assembled(network, pv.P, controlled="suspension" if controller else None)
    roads = list(roads) if roads else [cfg.road]
    for road in roads[1:] if len(roads) > 1 else ():  # (the first is the config's, checked)
        alone = cfg.model_copy(update={"road": road})
        check_steps(alone)
        check_memory(alone, model, attachments, pv.P)
    inputs = [
        road_inputs(road, model.offsets, model.sides, t_grid, base_dir=cfg.base_dir)
        for road in roads
    ]
    z, zd = np.stack([u for u, _ in inputs], axis=1), np.stack([v for _, v in inputs], axis=1)
    times, jumps = _edges(cfg, model, roads, asm.P)
    edges = None
    if times.size and sim.method == "exact":  # (a scenario's road: the config's is checked)
        raise stepped_road(cfg, roads[0].kind)
    if times.size:

        def at(t: np.ndarray, left: bool) -> np.ndarray:
            parts = [
                asm.offsets(
                    *road_inputs(
                        road, model.offsets, model.sides, t, base_dir=cfg.base_dir, left=left
                    )
                )
                for road in roads
            ]
            return parts[0] if len(parts) == 1 else np.concatenate(parts, axis=2)

        no_pull = (
            np.concatenate([np.full(g.size, g.name == "tyre") for g in network.groups])
            if cfg.vehicle.tyre_lift_off
            else None
        )
        edges = Edges(times, jumps, at, no_pull)
    offsets = (
        asm.offsets(*inputs[0])
        if len(roads) == 1
        else np.concatenate([asm.offsets(u, v) for u, v in inputs], axis=2)
    )
    run = Run(asm, model.n_dof, offsets, sim.dt, n_steps, every, controller, edges)
    return run, z, zd, t_grid


def _edges(cfg: Config, model: VehicleModel, roads: list, P: int):
    """The roads' edge times (E,) [s] and their jumps (E, n_u), or (E, G, n_u) for G > 1
    roads; ValueError unless G roads can drive P designs in G blocks: P divisible by G and
    their edges (if any) at the same instants."""
    found = [road_edges(road, model.offsets, model.sides) for road in roads]
    if len(roads) == 1:
        return found[0][0], found[0][1].T
    if P % len(roads):
        raise ValueError(f"{P} designs do not split evenly over {len(roads)} roads")
    for times, _ in found:
        if not np.array_equal(times, found[0][0]):
            raise ValueError("roads whose edges fall at other instants cannot share a batch")
    return found[0][0], np.stack([jumps.T for _, jumps in found], axis=1)


def _chunk_trajectory(cfg: Config, params: dict[str, np.ndarray]) -> Trajectory:
    """In a worker: the trajectory of one chunk of designs, every held quantity made (so that
    it travels as arrays)."""
    pv, model, controller, attachments = prepare(cfg, params)
    run, _, _, _ = _setup(cfg, pv, model, controller, attachments)
    traj = integrate(run, stepper(cfg))
    damping = traj.damping
    if isinstance(damping, Held):
        damping = Held(damping.values, damping.index)
    records = {name: Held(h.values, h.index) for name, h in traj.records.items()}
    return Trajectory(
        traj.states, traj.accelerations, damping, records, traj.diverged_at, traj.engine
    )


def _joined(parts: list[Trajectory]) -> Trajectory:
    """The chunks' trajectories as one, designs in order (a held quantity changes at the same
    samples in every design: the controller's instants)."""

    def held(pieces: list[Held]) -> Held:
        return Held(np.concatenate([h.values for h in pieces], axis=1), pieces[0].index)

    first = parts[0]
    damping: Held | np.ndarray | None = None
    if isinstance(first.damping, Held):
        damping = held([p.damping for p in parts])  # type: ignore[misc]
    elif first.damping is not None:
        damping = np.concatenate([p.damping for p in parts], axis=1)  # type: ignore[misc]
    return Trajectory(
        states=np.concatenate([p.states for p in parts], axis=1),
        accelerations=np.concatenate([p.accelerations for p in parts], axis=1),
        damping=damping,
        records={name: held([p.records[name] for p in parts]) for name in first.records},
        diverged_at=np.concatenate([p.diverged_at for p in parts]),
        engine=first.engine,
    )
