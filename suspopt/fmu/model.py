"""A design's element network as the FMU's C code takes it: :func:`describe`.

The description is the network the simulator integrates (:func:`suspopt.checks.full_network`
of :func:`suspopt.simulation.prepare`'s model and attachments), unpacked into

- ``structure``: every integer and flag - counts, the rows and columns of the non-zero
  entries of the deformation map ``D_q`` (with whether the DOF feels the element's force, the
  mask of a one-way seat) and of the input map ``D_u``, the non-linear laws' codes and rows
  (:data:`suspopt.integrator.compiled.LAWS`), the controller's laws and indices, the road's
  split steps;
- ``entries``: every number, in named float arrays - the DOFs' masses, the maps' values, each
  element's ``k`` and ``c``, the laws' parameters, gravity, the controller's rates map,
  ``C_min``, ``C_max``, threshold and law parameters, the seat's mount on the body, and with
  ``road="embedded"`` the road on the integrator's half-step grid, its split steps and jumps.

The C runtime evaluates ``q'' = M^-1 G F`` with ``δ = D_q q + D_u u``, ``F = k δ + c δ̇ (+
F_x)`` and ``G = -D_qᵀ`` (masked) from exactly these, so no physics is written twice: what is
derived at run time is network algebra only - ``M^-1``, the static compression of each tyre
(the linear statics ``K q0 = -M g`` of the vehicle's own groups, as
:func:`suspopt.vehicle.build_vehicle` solves them: the cap of a tyre that may lift off and the
``tyre_force`` signal) and the actuator's decay ``exp(-dt/τ)``. Which entries follow which
config field is found by :mod:`suspopt.fmu.params`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..config import Config, ConfigError
from ..integrator import EdgePlan, Edges
from ..integrator.compiled import LAWS as ELEMENT_LAWS
from ..road import road_edges, road_inputs
from ..simulation import prepare
from .description import Description
from .outputs import add_outputs

__all__ = ["Description", "describe", "ROAD_MODES"]

#: ``--road``: the road from the FMU's inputs, or built into it.
ROAD_MODES = ("input", "embedded")


def describe(cfg: Config, road: str = "input") -> Description:
    """The description of ``cfg``'s one design (its config values) with the road taken from
    inputs or embedded (:data:`ROAD_MODES`); ConfigError naming what cannot be exported."""
    if road not in ROAD_MODES:
        raise ConfigError(f"--road {road}: use {' or '.join(ROAD_MODES)}")
    prepared = prepare(cfg)
    model, controller, attachments = prepared.model, prepared.controller, prepared.attachments
    from ..checks import full_network

    network = full_network(model, attachments)
    d = Description()
    sim = cfg.simulation
    d.structure.update(
        n=network.n,
        n_vehicle=model.n_dof,
        nu=len(model.corners),
        dt_steps=sim.n_steps,
        output_every=sim.output_every,
        road=road,
    )
    d.put("dt", sim.dt)
    d.info.update(
        dof_names=network.dof_names,
        corners=model.corners,
        preset=model.preset,
        duration=sim.duration,
        dt=sim.dt,
        output_dt=sim.dt * sim.output_every,
    )
    _network(d, network, model, cfg)
    _statics(d, model, cfg)
    _controller(d, controller, network, cfg)
    _inputs(d, model, road)
    if road == "embedded":
        _embedded_road(d, cfg, model, network)
    add_outputs(d, prepared, network)
    return d


def _map_entries(matrix: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rows, columns and values of the non-zero entries of ``matrix`` (m, c), row by row."""
    rows, cols = np.nonzero(matrix)
    return rows, cols, matrix[rows, cols]


def _network(d: Description, network, model, cfg: Config) -> None:
    """The elements, their maps and laws (module docstring)."""
    lists: list[list[Any]] = [[] for _ in range(14)]
    dq_row, dq_col, dq_val, dq_react, du_row, du_col, du_val = lists[:7]
    k, c, law_code, law_row, law_par, groups, no_pull = lists[7:]
    start = 0
    for g in network.groups:
        dof_map = g.dof_map[0] if g.dof_map.ndim == 3 else g.dof_map
        if g.dof_map.ndim == 3 and not np.array_equal(g.dof_map, g.dof_map[:1]):
            raise ConfigError(f"the map of {g.name!r} differs between designs")  # (one design)
        rows, cols, vals = _map_entries(dof_map)
        react = np.ones(network.n, bool) if g.reacts is None else np.asarray(g.reacts, bool)
        dq_row += list(rows + start)
        dq_col += list(cols)
        dq_val += list(vals)
        dq_react += [int(react[j]) for j in cols]
        rows, cols, vals = _map_entries(g.input_map)
        du_row += list(rows + start)
        du_col += list(cols)
        du_val += list(vals)
        k += list(np.broadcast_to(g.stiffness[:, 0, 0], (g.size,)))
        c += list(np.broadcast_to(g.damping[:, 0, 0], (g.size,)))
        if g.extra is not None:
            _law_rows(g, start, law_code, law_row, law_par)
        no_pull += [int(g.name == "tyre" and bool(cfg.vehicle.tyre_lift_off))] * g.size
        groups.append((g.name, start, g.size))
        start += g.size
    d.structure.update(
        R=start,
        dq_row=np.array(dq_row, dtype=np.int64),
        dq_col=np.array(dq_col, dtype=np.int64),
        dq_react=np.array(dq_react, dtype=np.int64),
        du_row=np.array(du_row, dtype=np.int64),
        du_col=np.array(du_col, dtype=np.int64),
        law_code=np.array(law_code, dtype=np.int64),
        law_row=np.array(law_row, dtype=np.int64),
        no_pull=np.array(no_pull, dtype=np.int64),
        groups=tuple(groups),
    )
    d.put("mass", network.mass[:, 0, 0])
    d.put("dq", dq_val)
    d.put("du", du_val)
    d.put("k", k)
    d.put("c", c)
    d.put("law", np.asarray(law_par, dtype=np.float64).reshape(-1))


def _law_rows(g, start: int, codes: list, rows: list, params: list) -> None:
    """The non-linear part of group ``g`` element by element: its law's code, row and five
    parameters (the cap of a tyre that may lift off is its static load, derived at run
    time: its parameter here is 0)."""
    if g.extra_law is None or g.extra_law[0] not in ELEMENT_LAWS:
        raise ConfigError(
            f"the non-linear part of {g.name!r} has no law the FMU's C code knows "
            f"(known: {', '.join(ELEMENT_LAWS)})"
        )
    name, values = g.extra_law
    code, count = ELEMENT_LAWS[name]
    for i in range(g.size):
        codes.append(code)
        rows.append(start + i)
        row = [0.0] * 5
        if name != "cap":
            for j in range(count):
                v = np.asarray(values[j], float)
                row[j] = float(np.broadcast_to(v, (g.size,) + v.shape[1:])[i].ravel()[0])
        params.append(row)


def _statics(d: Description, model, cfg: Config) -> None:
    """What the run-time statics need: the vehicle's groups (the first ones), the DOFs that
    carry their weight (heave and the wheels: :func:`suspopt.vehicle.build_vehicle`), the
    tyre rows, gravity."""
    groups = d.structure["groups"]
    vehicle_groups = len(model.network.groups)
    rows = groups[vehicle_groups - 1]
    d.structure.update(
        vehicle_rows=rows[1] + rows[2],
        weighted=np.array(
            [int(dof == "heave") for dof in model.body_dofs] + [1] * len(model.corners), int
        ),
        tyre_rows=np.array([start + i for n, start, m in groups if n == "tyre" for i in range(m)]),
    )
    d.put("gravity", cfg.vehicle.gravity)


def _inputs(d: Description, model, road: str) -> None:
    """The FMU's inputs in ``input`` mode: each wheel's road height, and its rate where the
    tyre damps (the rate enters only through c_T)."""
    damping = d.entries["c"]
    start = next(s for n, s, _ in d.structure["groups"] if n == "tyre")
    damped = [int(damping[start + i] != 0.0) for i in range(len(model.corners))]
    d.structure["rate_inputs"] = np.array(damped if road == "input" else [0] * len(damped), int)
    nu, inputs = len(model.corners), []  # (name, unit, description, slot of [z; zdot])
    if road == "input":
        for c, corner in enumerate(model.corners):
            inputs.append((f"input.road.{corner}", "m", f"road height under the wheel {corner}", c))
        for c, corner in enumerate(model.corners):
            if damped[c]:
                text = f"road height rate under the wheel {corner} (its tyre damps)"
                inputs.append((f"input.road_vel.{corner}", "m/s", text, nu + c))
    d.info["inputs"] = inputs


def _controller(d: Description, controller, network, cfg: Config) -> None:
    """The semi-active controller's rules (:meth:`SemiActiveController.sample_rules`), its
    sample interval, actuator lag and adaptive threshold (or no controller)."""
    d.structure["controlled"] = controller is not None
    if controller is None:
        return
    from .laws import law_functions

    rules = controller.sample_rules()
    rates = rules.rates[0] if rules.rates.ndim == 3 else rules.rates
    rows, cols, vals = _map_entries(rates)
    names = sorted({law for law in rules.laws if law is not None})
    d.info["law_c"] = law_functions(names)
    suspension = next((s, m) for n, s, m in d.structure["groups"] if n == "suspension")
    spec = cfg.control.threshold if cfg.control is not None else None
    adaptive = spec is not None and spec.mode == "adaptive"
    distribution = spec.distribution if spec is not None else "empirical"
    if adaptive and distribution not in ("empirical", "normal"):
        raise ConfigError(
            f"control.threshold.distribution {distribution}: an adaptive threshold "
            "fitted by the Student-t distribution cannot be exported to an FMU (its fit is "
            "not in the C code); use empirical or normal"
        )
    d.structure.update(
        laws=np.array([-1 if law is None else names.index(law) for law in rules.laws], int),
        law_names=tuple(names),
        below=np.array(rules.below, int),
        needs_acc=int(rules.needs_acceleration),
        stiff_records=int(rules.stiff_records),
        rate_row=rows,
        rate_col=cols,
        damper_rows=np.arange(suspension[0], suspension[0] + suspension[1]),
        every=int(controller.sample_every),
        lagged=int(controller.lag_decay is not None),
        adaptive=int(adaptive),
        distribution=0 if not adaptive or distribution == "empirical" else 1,
    )
    d.put("rates", vals)
    d.put("c_min", rules.c_min[0])
    d.put("c_max", rules.c_max[0])
    d.put("threshold", rules.threshold[0])
    d.put("law_parameters", rules.parameters[:, 0, :])
    d.put("actuator_lag", controller_setting(cfg, "actuator_lag"))
    d.info["record_units"] = dict(controller.units)
    if adaptive:
        _adaptive(d, cfg, rules)


def controller_setting(cfg: Config, name: str) -> float:
    """``control.<name>`` of the config (0 without a control section, as the controller
    takes it)."""
    if cfg.control is None:
        return 0.0
    return float(getattr(cfg.control, name))


def _adaptive(d: Description, cfg: Config, rules) -> None:
    """The adaptive threshold's settings (:class:`SemiActiveController`): the quantile level
    per corner (the share for a law stiff below the threshold, else one less it), the first
    fit and the refit factor, and for the normal fit ``Φ⁻¹(level)``."""
    from scipy.special import ndtri

    spec = cfg.control.threshold if cfg.control is not None else None
    assert spec is not None and spec.c_max_share is not None  # (an adaptive threshold)
    share = float(spec.c_max_share)
    level = np.where(np.asarray(rules.below, bool), share, 1.0 - share)
    d.put("level", level)
    d.put("normal_z", ndtri(level))
    d.put("learn_time", spec.learn_time)
    d.put("refit_factor", spec.refit_factor)


def _embedded_road(d: Description, cfg: Config, model, network) -> None:
    """The config's road built in: its heights and rates under each wheel on the half-step
    grid (right limits at an edge), and for a bump its edges (times, jumps, left and right
    values) and the steps they split (:class:`suspopt.integrator.EdgePlan`), as the
    simulator takes them."""
    sim, road = cfg.simulation, cfg.road
    t_grid = np.arange(2 * sim.n_steps + 1) * (0.5 * sim.dt)

    def at(t, left=False) -> np.ndarray:  # (T, 2 nu): [z; zdot] at times t
        z, zd = road_inputs(road, model.offsets, model.sides, t, base_dir=cfg.base_dir, left=left)
        return np.concatenate([z, zd]).T

    d.put("road_table", at(t_grid))
    times, jumps = road_edges(road, model.offsets, model.sides)
    plan = EdgePlan(Edges(times, jumps.T, lambda t, left: at(t, left), None), sim.dt, sim.n_steps)
    steps = sorted(plan.steps)
    first, h, rights, middles, lefts, kicks = [0], [], [], [], [], []
    for k in steps:
        hk, r, m, left = plan.sub_steps(k)
        found = plan.steps[k]
        for j in range(hk.size):
            edge = found[j] if j < len(found) else -1
            kicks.append(edge if edge >= 0 and jumps[:, edge].any() else -1)
        h += list(hk)
        rights.append(r)
        middles.append(m)
        lefts.append(left)
        first.append(first[-1] + hk.size)
    d.structure.update(
        split_steps=np.array(steps, dtype=np.int64),
        split_first=np.array(first, dtype=np.int64),
        split_kick=np.array(kicks, dtype=np.int64),
        start_kicks=np.array(plan.at_start, int),
        edges=int(times.size),
    )
    stack = (lambda parts: np.concatenate(parts)) if steps else (lambda parts: np.zeros(0))
    d.put("split_h", h)
    d.put("split_right", stack(rights))
    d.put("split_middle", stack(middles))
    d.put("split_left", stack(lefts))
    d.put("edge_time", times)
    d.put("edge_jump", jumps.T)
    d.put("edge_left", at(times, True) if times.size else np.zeros(0))
    d.put("edge_right", at(times) if times.size else np.zeros(0))
    d.info["road_end"] = float(t_grid[-1])
