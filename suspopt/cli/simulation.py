"""``simulate``: a config, a batch from the command line, or picks of a result file (see :mod:`suspopt.cli`)."""

from __future__ import annotations

import time
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from ..errors import ConfigError
from . import base
from .base import app, err, out

if TYPE_CHECKING:
    from rich.table import Table


#: The most designs the tables of ``simulate`` show, evenly spaced over a larger batch.
TABLE_DESIGNS = 5


def _columns(result, picked, title: str) -> tuple[Table, list[int]]:
    """A table titled ``title`` with a column per design shown (each pick's name, ``design
    i`` in a batch, ``value`` alone; at most :data:`TABLE_DESIGNS`, evenly spaced by index,
    which the title says), and the designs' indices."""
    from ..plots.runs import evenly_spaced

    shown = evenly_spaced(result.P, TABLE_DESIGNS)
    if len(shown) < result.P:
        title += f" ({len(shown)} of {result.P} designs, evenly spaced by index)"
    table = base.new_table(title)
    table.add_column("quantity")
    table.add_column("unit")
    for p in shown:
        head = (
            picked.names[p] if picked is not None else "value" if result.P == 1 else f"design {p}"
        )
        table.add_column(head, justify="right")
    return table, shown


def _design_rows(table, result, picked, shown: list[int]) -> None:
    """The designs' own values, above their results: every design variable of the picks, or
    the parameters that differ between the designs of a batch (``--sweep``)."""
    from ..params import field_unit
    from ..plots.runs import varying_parameters

    if picked is not None:
        paths, names, units = picked.paths, picked.var_names, picked.var_units
    else:  # (by their paths as given to --sweep)
        paths = names = varying_parameters(result.designs, result.P)
        units = [field_unit(result.config, path) for path in paths]
    for path, name, unit in zip(paths, names, units):
        table.add_row(name, unit, *(f"{result.designs[path][p]:.4g}" for p in shown))
    if paths:
        table.add_section()


def _summary_table(result, picked=None) -> Table:
    """The designs' own values (:func:`_design_rows`), then peak and RMS body acceleration,
    max travel and tyre deflection per corner."""
    import numpy as np

    from ..metrics.stats import max_abs, maximum, rms

    table, shown = _columns(result, picked, f"{result.model.preset} - key results")
    _design_rows(table, result, picked, shown)
    sig = result.signals

    def row(label, unit, values):
        table.add_row(label, unit, *(f"{values[p]:.4g}" for p in shown))

    heave, acc = sig["body.heave"], sig["body.heave_acc"]
    row("peak body heave", "mm", 1e3 * maximum(heave))
    row("time of peak body heave", "s", result.time[np.argmax(heave, axis=-1)])
    row("peak |body heave acc|", "m/s^2", max_abs(acc))
    row("time of peak |body heave acc|", "s", result.time[np.argmax(np.abs(acc), axis=-1)])
    row("RMS body heave acc", "m/s^2", rms(acc))
    for c in result.model.corners:
        row(f"max |travel| {c}", "mm", 1e3 * max_abs(sig[f"travel.{c}"]))
    for c in result.model.corners:
        row(f"max |tyre deflection| {c}", "mm", 1e3 * max_abs(sig[f"tyre_deflection.{c}"]))
    return table


def _metrics_table(result, picked=None) -> Table:
    """The config's metrics (``metrics:`` section), one row each, for the designs of
    :func:`_summary_table`."""
    table, shown = _columns(result, picked, "metrics")
    for name, values in result.metrics.items():
        table.add_row(name, result.metric_units[name], *(f"{values[p]:.4g}" for p in shown))
    return table


_PICK_HELP = (
    "designs of a result file to simulate: knee, best_<objective>, chosen (the k-ε "
    "optimum of a kesort file) or a design id (its row in the front it came from, NAME:ROW "
    "when kesort pooled fronts); repeatable, or separated by commas"
)


@app.command()
@base.run_options
def simulate(
    source: Path = typer.Argument(
        ...,
        help="YAML config, or with --pick a result file of optimise, kesort or analyse"
        " roads|masses|controllers|tolerances|builds|transmissibility",
    ),
    output: Path | None = typer.Option(None, "-o", "--output", help="HDF5 file to write"),
    pick: list[str] = typer.Option([], "--pick", help=_PICK_HELP),
    set_: list[str] = base.set_option(),
    sweep_: list[str] = typer.Option(
        [],
        "--sweep",
        help="PATH=START:STOP:N: N "
        "designs from START to STOP; several sweeps "
        "make a grid (all combinations) or, with "
        "--zip, go side by side",
    ),
    zipped: bool = typer.Option(
        False, "--zip", help="pair the --sweep values instead of taking every combination"
    ),
    scenario: str | None = typer.Option(
        None,
        "--scenario",
        help="NAME: simulate under this scenario of the config's scenarios: section "
        "(robust design) instead of the config as written",
    ),
    plot: Path | None = base.plot_option(
        "the signals over time, their PSD and the ISO 2631 comfort levels"
    ),
    full: bool = base.full_option(),
    *,
    run: base.RunOptions,
) -> None:
    """Simulate a config (or designs picked from a result file) and write signals to HDF5."""
    with run.outputs(output, plot, inputs=[("the input", source)]):
        try:
            _simulate(source, output, pick, set_, sweep_, zipped, plot, scenario, full)
        except (ConfigError, ValueError) as exc:
            base.fail(str(exc))


def _inputs(source: Path, pick, sets, sweeps, zipped):
    """(config, design parameters or None, the picks or None) of ``simulate``'s arguments."""
    from ..files import is_hdf5
    from ..params import apply_sets, sweep

    if is_hdf5(source):
        from ..choosing.picks import read_picks, split_picks

        if not pick:
            base.fail(
                f"{source} is a result file: name the designs to simulate with --pick "
                f"(knee, best_<objective>, chosen or a design id)"
            )
        if sweeps:
            base.fail("--sweep takes a config; with --pick the designs are the picked ones")
        picked = read_picks(source, split_picks(pick))
        cfg = apply_sets(picked.config, sets)
        params: dict | None = picked.params()
    else:
        picked = None
        if pick:
            base.fail(
                f"--pick takes a result file (optimise, kesort, analyse); {source} is a config"
            )
        cfg = apply_sets(base.read_config(source), sets)
        params = sweep(cfg, sweeps, zipped) or None
    return cfg, params, picked


def _under_scenario(cfg, params, picked, name: str):
    """The config and designs of ``simulate --scenario NAME``: the scenario's road and time
    grid, its per-design values over the designs' own; the picks' stored objectives become
    that scenario's (:func:`suspopt.choosing.picks.stored_scenario_values`), or NaN where there are
    none."""
    import dataclasses
    import difflib

    from ..optimisation.scenarios import Group, ScenarioSet

    scenarios = ScenarioSet.from_config(cfg)
    where = cfg.source if cfg.source is not None else "the config"
    if scenarios is None:
        raise ConfigError(f"--scenario {name}: {where} has no scenarios: section")
    if "," in name and all(part.strip() in scenarios.names for part in name.split(",")):
        raise ConfigError(f"--scenario {name}: one scenario per run; simulate each on its own")
    if name not in scenarios.names:
        close = difflib.get_close_matches(name, scenarios.names, n=3)
        raise ConfigError(
            f"--scenario {name}: no such scenario; "
            + (
                f"did you mean {', '.join(close)}?"
                if close
                else f"it has {', '.join(scenarios.names)}"
            )
        )
    s = scenarios.names.index(name)
    group = next(g for g in scenarios.groups if s in g.members)
    k = group.members.index(s)
    member_cfg = group.configs[k]
    alone = Group(member_cfg, [s], [group.values[k]], [group.scales[k]], [member_cfg])
    P = len(next(iter(params.values()))) if params else 1
    params = scenarios.columns(alone, dict(params or {}), P) or None
    if picked is not None:
        from ..choosing.picks import stored_scenario_values

        stored, note = stored_scenario_values(picked, s, scenarios.names)
        if note:
            err.print(f"note: {note}")
        picked = dataclasses.replace(picked, F=stored)
    return member_cfg, params, picked


def _picks_writer(picked, objectives):
    """Writes the picks' names, rows, ids (:mod:`suspopt.design_ids`) and objectives (new and
    stored) beside the signals."""
    from ..formats import SIMULATE
    from ..io import put

    def extra(h5) -> None:
        F, names, units = objectives
        designs = h5.require_group("designs")
        designs.attrs["source"] = str(picked.source)
        put(SIMULATE, designs, "pick", list(picked.names))
        put(SIMULATE, designs, "row", picked.rows)
        put(SIMULATE, designs, "id", list(picked.ids))
        group = h5.create_group("objectives")
        put(SIMULATE, group, "F", F, units, names=names)
        put(SIMULATE, group, "stored_F", picked.F, picked.obj_units, names=picked.obj_names)

    return extra


def _simulate(
    source: Path, output, pick, sets, sweeps, zipped, plot, scenario=None, full=True
) -> None:
    import numpy as np

    from ..checks import check_stability
    from ..io import write_simulation
    from ..simulation import check_memory, prepare, signal_names
    from ..simulation import simulate as run
    from ..validation import check_config

    if plot is not None:
        from ..plots import check_path

        check_path(plot)
    cfg, params, picked = _inputs(source, pick, sets, sweeps, zipped)
    if scenario is not None:
        cfg, params, picked = _under_scenario(cfg, params, picked, scenario)
    checked = check_config(cfg, optimisation=False)  # (the config's own design, built)
    prepared = prepare(cfg, params) if params else checked
    pv, model, controller, attachments = prepared
    written = (
        cfg.output.signals
        if cfg.output.signals != "all"
        else signal_names(model, getattr(controller, "units", {}), attachments)
    )
    # the memory first: a batch too large to run is said so before its modes are computed
    check_memory(cfg, model, attachments, pv.P, signals=len(written) + len(cfg.metrics))
    if params:
        check_stability(
            cfg,
            pv,
            model,
            attachments,
            what=" for a picked design" if picked else " for a swept design",
        )
    if base.VERBOSE[0]:
        from ..memory import describe
        from ..simulation import run_memory

        shared, per_design = run_memory(
            cfg, model, attachments, pv.P, len(written) + len(cfg.metrics)
        )
        base.verbose_info(
            f"{cfg.source}: checked; {pv.P} design{'s' if pv.P > 1 else ''}, "
            f"{cfg.simulation.n_steps} steps of {cfg.simulation.dt:g} s, about "
            f"{describe(shared + pv.P * per_design)} of memory"
        )
    started = time.perf_counter()
    result = run(cfg, params, prepared=prepared)
    base.verbose_info(f"simulated in {time.perf_counter() - started:.3g} s")
    if result.diverged.any():
        err.print(
            f"warning: design(s) {np.flatnonzero(result.diverged).tolist()} diverged "
            f"(at t = {np.nanmin(result.diverged_at):.4g} s); their samples are NaN; "
            f"try a smaller simulation.dt"
        )
    base.show_table(_summary_table(result, picked), 2, full, output)
    if result.metrics:
        base.show_table(_metrics_table(result, picked), 2, full, output)
    extra = None
    if picked is not None:
        extra = _show_picks(picked, cfg, result, params, full, output)
    if output is not None:
        started = time.perf_counter()
        write_simulation(
            output,
            result,
            signals=None if cfg.output.signals == "all" else cfg.output.signals,
            float32=cfg.output.float32,
            command=base.command_line(),
            extra=extra,
        )
        base.verbose_info(f"wrote {len(written)} signals in {time.perf_counter() - started:.3g} s")
        out.print(f"wrote {output}")
    if plot is not None:
        from ..plots import plot_simulation

        plot_simulation(result, plot, design_names=None if picked is None else picked.labels())
        out.print(f"wrote {plot}")


def _show_picks(picked, cfg, result, params, full, output):
    """Show the picks' objectives, stored and simulated now (:func:`_picks_table`), with a
    note where the stored ones are the spectral method's; return the writer of them
    (:func:`_picks_writer`)."""
    objectives = _pick_objectives(picked, cfg, result, params)
    base.show_table(_picks_table(picked, *objectives), 3, full, output)
    if cfg.simulation.method == "spectral":  # (stored: stationary; here: in time)
        out.print(
            f"note: the stored values are the spectral method's (stationary); simulate "
            f"integrates {cfg.simulation.duration:g} s in time: they differ by the finite "
            f"road's error (docs/guide/spectral.md)"
        )
    return _picks_writer(picked, objectives)


def _pick_objectives(picked, cfg, result, params):
    """The picked designs' main and supplementary objectives from their new simulation of
    ``params``: ``(F (P, m + s), names, units)``."""
    import numpy as np

    from ..optimisation import Problem

    problem = Problem.from_config(cfg)
    F, _, S = problem.values(result, params, len(picked.rows), supplementary=True)
    return (
        np.hstack([F, S]),
        problem.obj_names + problem.supplementary_names,
        problem.obj_units + problem.supplementary_units,
    )


def _picks_table(picked, F, names, units) -> Table:
    """Each pick's objectives as the file stored them and as simulated now."""
    import numpy as np

    table = base.new_table(f"{picked.source.name}: the picked designs' objectives")
    for col in ("pick", "design", "objective", "stored", "simulated", "change"):
        table.add_column(col, justify="left" if col in ("pick", "objective") else "right")
    for i, name in enumerate(picked.names):
        for j, (objective, unit) in enumerate(zip(names, units)):
            stored = (
                picked.F[i, picked.obj_names.index(objective)]
                if objective in picked.obj_names
                else np.nan
            )
            with np.errstate(all="ignore"):  # (a damaged file's 1e-308: beyond the range)
                relative = (F[i, j] - stored) / abs(stored) if stored != 0 else np.nan
            change = f"{relative:+.1e}" if np.isfinite(relative) else ""
            table.add_row(
                name if j == 0 else "",
                picked.ids[i] if j == 0 else "",
                f"{objective} [{unit}]",
                "" if np.isnan(stored) else f"{stored:.6g}",
                f"{F[i, j]:.6g}",
                change,
            )
    return table


#: Options of ``analyse`` that only some kinds take: keyword -> flag.
