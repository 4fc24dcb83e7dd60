"""``optimise``: the run, its progress line and its optimum table (see :mod:`suspopt.cli`)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import typer

from ..errors import ConfigError
from . import base
from .base import app, err, out
from .notices import notices

if TYPE_CHECKING:
    from rich.table import Table


def _progress_line(p) -> str:
    """One generation's report: budget, evaluations, best or hypervolume, feasible share."""
    import numpy as np

    gen = f"gen {p.generation}" + (f"/{p.max_generations}" if p.max_generations else "")
    if not np.isfinite(p.best).any():
        score = "none feasible yet"
    else:
        score = f"HV {p.hypervolume:.4g}" if p.best.size > 1 else f"best {p.best[0]:.4g}"
    left = f", {p.time_left:.0f} s left" if p.time_left is not None else ""
    return (
        f"{p.phase} {gen}, {p.evaluations} evaluations, {score}, "
        f"{100 * p.feasible:.0f} % feasible{left}"
    )


def _baseline_line(result) -> str | None:
    """How the optimum stands against the config's own design (``result.baseline``): each
    objective's change for one optimum; the design's objectives and how many designs of a
    front dominate it (feasible, no objective worse, one better)."""

    from ..optimisation.problem import PENALTY

    own = result.baseline
    if own is None:
        return None
    if (own.F >= PENALTY).any():
        return "the config's own design failed to simulate (diverged or gave NaN)"
    if len(result.X) == 1:
        return base.against_baseline(result.obj_names, result.F[0], own.F[0], own.feasible[0])
    feasible = "feasible" if own.feasible[0] else "infeasible"
    ok = (result.G <= 0).all(axis=1)
    better = ok & (result.F <= own.F).all(axis=1) & (result.F < own.F).any(axis=1)
    values = ", ".join(
        f"{n} = {v:.4g} {u}" for n, v, u in zip(result.obj_names, own.F[0], result.obj_units)
    )
    return (
        f"the config's own design: {values} ({feasible}); {int(better.sum())} of the "
        f"{len(result.X)} designs dominate it (feasible, no objective worse, one better)"
    )


def _optimum_table(result, rows: int = 12) -> Table:
    """The best design (one column), or up to ``rows`` designs spread along the Pareto front
    (one row each; ``design``: its row in ``/pareto``, its id, :mod:`suspopt.design_ids`).
    The Pareto set is the optimiser's optimum: the non-dominated designs of the last
    generation's population (pymoo's ``opt``; the feasible ones where any is), which the
    title says, with the generation."""
    import numpy as np

    N = len(result.X)
    names = result.obj_names + result.var_names
    units = result.obj_units + result.var_units
    values = np.hstack([result.F, result.X])
    feasible = ["yes" if ok else "no" for ok in (result.G <= 0).all(axis=1)]
    suffix = "" if result.status == "finished" else " (interrupted)"
    if N == 1:
        table = base.new_table("best design" + suffix)
        table.add_column("quantity")
        table.add_column("unit")
        table.add_column("value", justify="right")
        own = result.baseline  # (the design the run started from, beside it)
        if own is not None:
            table.add_column("config's design", justify="right")
        for j, (name, unit, value) in enumerate(zip(names, units, values[0])):
            start = [] if own is None else [f"{np.hstack([own.F, own.X])[0, j]:.5g}"]
            table.add_row(name, unit, f"{value:.5g}", *start)
        start = [] if own is None else ["yes" if own.feasible[0] else "no"]
        table.add_row("feasible", "", feasible[0], *start)
        return table
    from ..plots.runs import evenly_spaced

    pick = evenly_spaced(N, rows)
    generations = result.history.get("generation", ())
    last = f"generation {int(generations[-1])}" if len(generations) else "the last generation"
    shown = (
        f", by {names[0]}"
        if len(pick) == N
        else (f"; {len(pick)} of them shown, evenly spaced by {names[0]}")
    )
    table = base.new_table(
        f"Pareto set: the {N} non-dominated designs of {last}'s population{shown}" + suffix
    )
    table.add_column("design", justify="right")
    for name, unit in zip(names, units):
        table.add_column(f"{name} [{unit}]", justify="right")
    table.add_column("feasible")
    for i in pick:
        table.add_row(str(i), *(f"{v:.4g}" for v in values[i]), feasible[i])
    return table


@app.command()
@base.run_options
def optimise(
    config: Path = typer.Argument(..., help="YAML config file"),
    output: Path | None = typer.Option(
        None,
        "-o",
        "--output",
        help="HDF5 file (default CONFIG's name with .h5 in "
        "the current folder), rewritten after the first generation and then at most every 2 s",
    ),
    resume: bool = typer.Option(False, "--resume", help="continue from the checkpoint in OUT.h5"),
    set_: list[str] = base.set_option(
        "; give the same with --resume, or a longer budget (optimiser.generations=50)"
    ),
    plot: Path | None = base.plot_option(
        "the front (or the best value) and the history per generation"
    ),
    *,
    run: base.RunOptions,
) -> None:
    """Optimise the config's design variables; write the optimum or Pareto set to HDF5.

    The progress line's HV is the hypervolume of every feasible non-dominated design found so
    far, objectives scaled by the first feasible generation's range (reference point 1.1):
    it never falls."""
    output = output if output is not None else Path(config.stem + ".h5")
    if resume and plot is None:  # (the figure of the run it continues, rewritten)
        from ..files import is_hdf5
        from ..replacing import stored_plot

        plot = stored_plot(output) if is_hdf5(output) else None
    if plot is not None:
        from ..plots import check_path

        try:
            check_path(plot)
        except ValueError as exc:
            base.fail(str(exc))
    inputs = [("the config", config)]
    with run.outputs(output, plot, execute=False, inputs=inputs, hold=False):
        _optimise(config, output, resume, plot, run, set_)


def _scenarios_line(cfg, output: Path) -> None:
    """How each objective combined over the config's scenarios, and where their values are."""
    from ..optimisation import Problem

    problem = Problem.from_config(cfg)
    assert problem.scenarios is not None
    rules = problem.aggregation()[0]
    out.print(
        f"over {len(problem.scenarios.names)} scenarios: "
        + ", ".join(f"{name} {rule}" for name, rule in zip(problem.obj_names, rules))
        + f"; every scenario's values in {output}:/pareto/scenarios"
    )


def _progress(cfg):
    """The run's progress bar (on a terminal; else a line per generation on stderr), its
    callback per generation and the executor's per chunk."""
    from rich.progress import BarColumn, Progress, TextColumn

    total = cfg.optimiser.generations if cfg.optimiser is not None else None
    bar = Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        console=err.console,
        disable=not err.is_terminal or out.quiet,
    )
    task = bar.add_task("starting", total=total)
    line = ["starting"]

    def report(p) -> None:
        line[0] = _progress_line(p)
        bar.update(task, completed=p.generation, description=line[0])
        if not err.is_terminal and not out.quiet:
            err.print(line[0])

    def chunk_done(done: int, total: int) -> None:  # chunks of an executor other than local
        bar.update(task, description=f"{line[0]} (chunks {done}/{total})")

    return bar, report, chunk_done


def _again(config: Path, output: Path, sets: list[str]) -> str:
    """The command that continues the run: its config, output and ``--set`` items."""
    import shlex

    edits = [word for item in sets for word in ("--set", item)]
    return shlex.join(["suspopt", "optimise", str(config), "-o", str(output), *edits, "--resume"])


def _resume_hint(config: Path, output: Path, kept: str, then: str, sets: list[str]) -> str:
    """What to do when a run stops early, its output holding what it ``kept``."""
    return f"; {output} keeps {kept}: {then} with {_again(config, output, sets)}"


def _optimise(
    config: Path,
    output: Path,
    resume: bool,
    plot: Path | None,
    options: base.RunOptions,
    sets: list[str],
) -> None:
    from ..io import WriteError, check_replace
    from ..optimisation import optimise as run
    from ..params import apply_sets
    from ..validation import check_config

    try:
        cfg = apply_sets(base.read_config(config), sets)
        check_config(cfg)
        check_replace(output, cfg)  # (before the run, not at its first checkpoint)
    except ConfigError as exc:
        base.fail(str(exc))
    bar, report, chunk_done = _progress(cfg)
    try:
        lost = _resume_hint(config, output, "the last generation's checkpoint", "continue", sets)
        executing = options.executing(progress=chunk_done, lost_hint=lost + " (on any executor)")
        with bar, executing, notices.beside(bar):  # (a compile's indicator: a line of the bar)
            result = run(cfg, output, resume=resume, callback=report, command=base.command_line())
    except WriteError as exc:  # (a full disk: the file holds the last generation it took)
        hint = "make room, then continue"
        kept = (
            _resume_hint(config, output, "an earlier checkpoint", hint, sets)
            if output.exists()
            else ""
        )
        base.fail(f"{exc}{kept}")
    except ConfigError as exc:
        base.fail(str(exc))
    except KeyboardInterrupt:
        err.print("the first generation had not completed: nothing written")
        raise typer.Exit(code=130) from None
    base.show_table(_optimum_table(result))
    line = _baseline_line(result)
    if line is not None:
        out.print(line)
    from ..optimisation.bounds import bounds_note

    note = bounds_note(result.var_names, cfg.design_variables, result.X)
    if note is not None:
        out.print(f"note: {note}")
    if result.weights is not None:
        out.print(
            "weighted sum (Eq 5.7): "
            + " + ".join(f"{w:.4g} {name}" for w, name in zip(result.weights, result.obj_names))
        )
    if cfg.scenarios is not None:
        _scenarios_line(cfg, output)
    if result.status == "interrupted":
        err.print(
            f"wrote the designs found so far to {output}; continue with "
            f"{_again(config, output, sets)}",
            soft_wrap=True,
        )
        raise typer.Exit(code=130)
    out.print(f"wrote {output}")
    if plot is not None:
        from ..plots import plot_optimisation

        try:
            plot_optimisation(result, plot)
        except ValueError as exc:
            base.fail(str(exc))
        out.print(f"wrote {plot}")
    if result.status == "failed":
        err.print(
            f"error: every design of the optimum failed to simulate (diverged or gave "
            f"NaN); {output} holds them with the penalty values and status 'failed'",
            soft_wrap=True,
        )
        raise typer.Exit(code=base.EXIT_ALL_FAILED)
