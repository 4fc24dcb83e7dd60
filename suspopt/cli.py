"""The ``suspopt`` command: a thin layer that reads arguments, calls the library and renders.

Exit codes: 0 success; 2 bad input (config, file, arguments) with one line naming the YAML key
and line (or the file and dataset); 3 a run whose every optimum design failed to simulate;
130 interrupted (suspopt._entry); 1 an unexpected failure (a bug).
"""

from __future__ import annotations

import shlex
import sys
import time
from contextlib import ExitStack
from pathlib import Path
from typing import Optional

import typer
from rich.console import Console
from rich.table import Table

from .errors import ConfigError

app = typer.Typer(add_completion=True, no_args_is_help=True, pretty_exceptions_enable=False,
                  help="Simulate, optimise and select vehicle and seat suspensions from YAML.")
# text from files and arguments is printed as it is: no rich markup, no emoji codes
# (":x:" in a file name), no highlighting
out = Console(markup=False, emoji=False, highlight=False, soft_wrap=True)
err = Console(stderr=True, markup=False, emoji=False, highlight=False, soft_wrap=True)

#: Exit code of a run that finished but whose every design failed to simulate.
EXIT_ALL_FAILED = 3

_FORCE_HELP = "replace an existing output that suspopt did not write"
_MEMORY_HELP = ("most memory a run may take, e.g. 4G (default: what the machine has free); "
                "evaluations of many designs run in batches of at most half of it")


#: ``-v``: what each step did and how long it took, on stderr.
_verbose = [False]


def _info(message: str) -> None:
    if _verbose[0]:
        err.print(f"info: {message}", soft_wrap=True)


def _show_version(value: bool) -> None:
    if value:
        from . import __version__
        out.print(f"suspopt {__version__}")
        raise typer.Exit()


@app.callback()
def _main(version: bool = typer.Option(False, "--version", callback=_show_version,
                                       is_eager=True, help="print the version and exit"),
          quiet: bool = typer.Option(False, "-q", "--quiet", help="print nothing but warnings "
                                     "and errors (no tables, no progress)"),
          verbose: bool = typer.Option(False, "-v", "--verbose", help="also print, on stderr, "
                                       "what each step did and how long it took")) -> None:
    """Simulate, optimise and select vehicle and seat suspensions from YAML."""
    from .memory import reuse_memory

    out.quiet = quiet
    _verbose[0] = verbose and not quiet
    reuse_memory()          # a command's repeated batches reuse their memory (suspopt.memory)


class _FoldingTable(Table):
    """A table whose cells fold onto further lines when the terminal is narrow (a CI log's
    80 columns) instead of being cut to "…"."""

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self.cells: list[tuple[str, ...]] = []      # the rows as given, for _show

    def add_column(self, *args, **kwargs) -> None:
        kwargs.setdefault("overflow", "fold")
        super().add_column(*args, **kwargs)

    def add_row(self, *cells, **kwargs) -> None:
        self.cells.append(tuple(str(c) for c in cells))
        super().add_row(*cells, **kwargs)


def _table(title: str | None = None) -> Table:
    return _FoldingTable(title=title)


def _show(table: _FoldingTable, keys: int = 1) -> None:
    """Print ``table``; when it is wider than the terminal (a CI log's 80 columns), as several
    tables of the columns that fit, each with the first ``keys`` columns again, so that no
    number is cut or broken across lines."""
    def needs(j: int) -> int:             # column j's widest cell and the border and padding
        return max(len(str(c)) for c in [table.columns[j].header,
                                          *(row[j] for row in table.cells)]) + 3

    width, count = out.width, len(table.columns)
    if 1 + sum(needs(j) for j in range(count)) <= width or count <= keys + 1:
        out.print(table)
        return
    key, rest = list(range(keys)), list(range(keys, count))
    base = 1 + sum(needs(c) for c in key)
    groups, current, used = [], [], base
    for column in rest:
        if current and used + needs(column) > width:
            groups.append(current)
            current, used = [], base
        current.append(column)
        used += needs(column)
    groups.append(current)
    title = str(table.title or "")
    for i, group in enumerate(groups, start=1):
        part = _table(f"{title} ({i} of {len(groups)})" if title else None)
        for j in key + group:
            part.add_column(table.columns[j].header, justify=table.columns[j].justify)
        for row in table.cells:
            part.add_row(*(row[j] for j in key + group))
        out.print(part)


def _fail(message: str) -> None:
    """Report bad input in one line and exit with code 2."""
    err.print("error: " + " ".join(str(message).split()), soft_wrap=True)
    raise typer.Exit(code=2)


def _memory(max_memory: str | None) -> None:
    """Apply ``--max-memory``."""
    from .memory import parse_size, set_limit

    try:
        set_limit(None if max_memory is None else parse_size(max_memory))
    except ValueError as exc:
        _fail(f"--max-memory: {exc}")


def _claim(stack: ExitStack, path: Path | None, force: bool, option: str = "-o") -> None:
    """Check an output and hold its writer's lock for the rest of the command
    (:func:`suspopt.io.claim`)."""
    from .io import claim

    if path is None:
        return
    try:
        stack.enter_context(claim(path, force, option))
    except ConfigError as exc:
        _fail(str(exc))


def _load(path: Path):
    from .config import load_config

    try:
        return load_config(path)
    except ConfigError as exc:
        _fail(str(exc))


def _command() -> str:
    return "suspopt " + " ".join(shlex.quote(a) for a in sys.argv[1:])


@app.command()
def validate(config: Path = typer.Argument(..., help="YAML config file"),
             max_memory: Optional[str] = typer.Option(None, "--max-memory",
                                                      help=_MEMORY_HELP)) -> None:
    """Check a config and report its first problem with its line (what any command would
    reject about it)."""
    from .checks import check_config

    _memory(max_memory)
    started = time.perf_counter()
    cfg = _load(config)
    _info(f"{config}: read and typed in {time.perf_counter() - started:.3g} s")
    try:
        check_config(cfg)
    except ConfigError as exc:
        _fail(str(exc))
    _info(f"checked the run (steps, road, RK4 stability, memory"
          f"{', the optimisation' if cfg.design_variables else ''}) in "
          f"{time.perf_counter() - started:.3g} s")
    out.print(f"{config}: valid ({cfg.vehicle.preset}, road {cfg.road.kind})")


@app.command()
def schema() -> None:
    """Print the JSON Schema of the config (for editor completion)."""
    from importlib import resources

    # the schema as suspopt.config.config_schema() makes it, stored with the package so that
    # printing it needs no model (tests/test_schema.py checks the two are the same)
    sys.stdout.write(resources.files("suspopt").joinpath("schema.json").read_text())


def _template_help() -> str:
    from .templates import TEMPLATES

    return "the kind of study: " + "; ".join(f"{k}: {v}" for k, v in TEMPLATES.items())


def _template_kinds(incomplete: str) -> list[str]:
    from .templates import template_names

    return [k for k in template_names() if k.startswith(incomplete)]


@app.command()
def init(kind: str = typer.Argument(..., help=_template_help(),
                                    autocompletion=_template_kinds),
         output: Path = typer.Option(..., "-o", "--output", help="the new config (YAML)"),
         force: bool = typer.Option(False, "--force", help=_FORCE_HELP)) -> None:
    """Write a commented starter config of one kind of study, ready to validate and run."""
    from .io import atomic_file
    from .templates import template_text

    with ExitStack() as stack:
        try:
            text = template_text(kind)
        except ValueError as exc:
            _fail(f"init: {exc}")
        _claim(stack, output, force)
        with atomic_file(output) as stream:
            stream.write(text.encode())
    command = "optimise" if kind in ("optimise", "kesort") else "simulate"
    out.print(f"wrote {output}; next: suspopt validate {output}, then suspopt {command} "
              f"{output} -o {Path(output).with_suffix('.h5')}")


@app.command()
def export(source: Path = typer.Argument(..., help="result file of optimise, kesort or "
                                         "analyse"),
           pick: list[str] = typer.Option([], "--pick", help="the design to write as a config: "
                                          "knee, best_<objective>, chosen or a row number"),
           output: Optional[Path] = typer.Option(None, "-o", "--output",
                                                 help="YAML file for the picked design"),
           csv: Optional[Path] = typer.Option(None, "--csv", help="folder for the file's "
                                              "tables as CSV, units in the headers"),
           force: bool = typer.Option(False, "--force", help=_FORCE_HELP)) -> None:
    """Write a picked design as a standalone config (-o design.yaml), or a result file's
    tables as CSV (--csv DIR)."""
    if (output is None) == (csv is None):
        _fail("export: give -o FILE.yaml (with --pick) or --csv DIR")
    with ExitStack() as stack:
        try:
            if csv is not None:
                from .export import write_csv
                if pick:
                    _fail("--csv writes every table of the file; --pick is for -o")
                for path in write_csv(source, csv, force=force):
                    out.print(f"wrote {path}")
                return
            from .io import atomic_file
            from .picks import design_config, read_picks, split_picks

            _claim(stack, output, force)
            names = split_picks(pick)
            if len(names) != 1:
                _fail(f"--pick: -o writes one design; got {len(names)} ({', '.join(names)})")
            picked = read_picks(source, names)
            _, text = design_config(picked)
            with atomic_file(output) as stream:
                stream.write(text.encode())
        except ConfigError as exc:
            _fail(str(exc))
    out.print(f"wrote {output} (design {names[0]!r}, row {int(picked.rows[0])} of "
              f"{source})")


def _summary_table(result) -> Table:
    """Peak and RMS body acceleration, max travel and tyre deflection per corner."""
    import numpy as np

    P = min(result.P, 5)
    table = _table(f"{result.model.preset} - key results"
                  + (f" (first {P} of {result.P} designs)" if result.P > P else ""))
    table.add_column("quantity")
    table.add_column("unit")
    for p in range(P):
        table.add_column(f"design {p}" if result.P > 1 else "value", justify="right")
    sig = result.signals

    def row(label, unit, values):
        table.add_row(label, unit, *(f"{v:.4g}" for v in values[:P]))

    heave, acc = sig["body.heave"], sig["body.heave_acc"]
    row("peak body heave", "mm", 1e3 * np.max(heave, axis=-1))
    row("time of peak body heave", "s", result.time[np.argmax(heave, axis=-1)])
    row("peak |body heave acc|", "m/s^2", np.max(np.abs(acc), axis=-1))
    row("time of peak |body heave acc|", "s", result.time[np.argmax(np.abs(acc), axis=-1)])
    row("RMS body heave acc", "m/s^2", np.sqrt(np.mean(acc ** 2, axis=-1)))
    for c in result.model.corners:
        row(f"max |travel| {c}", "mm", 1e3 * np.max(np.abs(sig[f"travel.{c}"]), axis=-1))
    for c in result.model.corners:
        row(f"max |tyre deflection| {c}", "mm",
            1e3 * np.max(np.abs(sig[f"tyre_deflection.{c}"]), axis=-1))
    return table


def _metrics_table(result) -> Table:
    """The config's metrics (``metrics:`` section), one row each."""
    P = min(result.P, 5)
    table = _table("metrics")
    table.add_column("metric")
    table.add_column("unit")
    for p in range(P):
        table.add_column(f"design {p}" if result.P > 1 else "value", justify="right")
    for name, values in result.metrics.items():
        table.add_row(name, result.metric_units[name], *(f"{v:.4g}" for v in values[:P]))
    return table


def _is_hdf5(path: Path) -> bool:
    """Whether ``path`` is an HDF5 file (by its signature), not a YAML config."""
    import os
    import stat

    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    except OSError:
        return False
    try:                                 # (a FIFO or a device is no HDF5 file: never read it)
        return stat.S_ISREG(os.fstat(fd).st_mode) and os.read(fd, 8) == b"\x89HDF\r\n\x1a\n"
    finally:
        os.close(fd)


_PICK_HELP = ("designs of a result file to simulate: knee, best_<objective>, chosen (the k-ε "
              "optimum of a kesort file) or a row number; repeatable, or separated by commas")


@app.command()
def simulate(source: Path = typer.Argument(..., help="YAML config, or a result file of "
                                           "optimise, kesort or analyse with --pick"),
             output: Optional[Path] = typer.Option(None, "-o", "--output",
                                                   help="HDF5 file to write"),
             pick: list[str] = typer.Option([], "--pick", help=_PICK_HELP),
             set_: list[str] = typer.Option([], "--set", help="PATH=VALUE: override a "
                                            "numeric field of the config; repeatable"),
             sweep_: list[str] = typer.Option([], "--sweep", help="PATH=START:STOP:N: N "
                                              "designs from START to STOP; several sweeps "
                                              "make a grid (all combinations) or, with "
                                              "--zip, go side by side"),
             zipped: bool = typer.Option(False, "--zip", help="pair the --sweep values "
                                         "instead of taking every combination"),
             plot: Optional[Path] = typer.Option(None, "--plot", help="figure of the signals "
                                                 "over time, their PSD and the ISO 2631 "
                                                 "comfort levels (.png or .svg)"),
             force: bool = typer.Option(False, "--force", help=_FORCE_HELP),
             max_memory: Optional[str] = typer.Option(None, "--max-memory",
                                                      help=_MEMORY_HELP)) -> None:
    """Simulate a config (or designs picked from a result file) and write signals to HDF5."""
    _memory(max_memory)
    with ExitStack() as stack:
        _claim(stack, output, force)
        _claim(stack, plot, force, "--plot")
        try:
            _simulate(source, output, pick, set_, sweep_, zipped, plot)
        except (ConfigError, ValueError) as exc:
            _fail(str(exc))


def _simulate(source: Path, output, pick, sets, sweeps, zipped, plot) -> None:
    import numpy as np

    from .checks import check_config, check_stability
    from .io import write_dataset, write_simulation
    from .params import apply_sets, sweep
    from .simulate import check_memory, prepare, signal_names
    from .simulate import simulate as run

    if plot is not None:
        from .plots import check_path
        check_path(plot)
    picked = None
    if _is_hdf5(source):
        from .picks import read_picks, split_picks
        if not pick:
            _fail(f"{source} is a result file: name the designs to simulate with --pick "
                  f"(knee, best_<objective>, chosen or a row number)")
        if sweeps:
            _fail("--sweep takes a config; with --pick the designs are the picked ones")
        picked = read_picks(source, split_picks(pick))
        cfg = apply_sets(picked.config, sets)
        params = picked.params()
    else:
        if pick:
            _fail(f"--pick takes a result file (optimise, kesort, analyse); {source} is a "
                  f"config")
        cfg = apply_sets(_load(source), sets)
        params = sweep(cfg, sweeps, zipped) or None
    check_config(cfg, optimisation=False)
    pv, model, controller, attachments = prepare(cfg, params)
    if params:
        check_stability(cfg, pv, model, attachments,
                        what=" for a picked design" if picked else " for a swept design")
    written = cfg.output.signals if cfg.output.signals != "all" else signal_names(
        model, getattr(controller, "units", {}), attachments)
    check_memory(cfg, model, attachments, pv.P, signals=len(written) + len(cfg.metrics))
    if _verbose[0]:
        from .memory import describe
        from .simulate import run_memory
        shared, per_design = run_memory(cfg, model, attachments, pv.P,
                                        len(written) + len(cfg.metrics))
        _info(f"{cfg.source}: checked; {pv.P} design{'s' if pv.P > 1 else ''}, "
              f"{cfg.simulation.n_steps} steps of {cfg.simulation.dt:g} s, about "
              f"{describe(shared + pv.P * per_design)} of memory")
    started = time.perf_counter()
    result = run(cfg, params)
    _info(f"simulated in {time.perf_counter() - started:.3g} s")
    if result.diverged.any():
        err.print(f"warning: design(s) {np.flatnonzero(result.diverged).tolist()} diverged "
                  f"(at t = {np.nanmin(result.diverged_at):.4g} s); their samples are NaN; "
                  f"try a smaller simulation.dt")
    _show(_summary_table(result), keys=2)
    if result.metrics:
        _show(_metrics_table(result), keys=2)
    extra = None
    if picked is not None:
        objectives = _pick_objectives(picked, cfg, result)
        _show(_picks_table(picked, *objectives), keys=3)

        def extra(h5) -> None:
            F, names, units = objectives
            designs = h5.require_group("designs")
            designs.attrs["source"] = str(picked.source)
            write_dataset(designs, "pick", list(picked.names), "1", dims=("design",))
            write_dataset(designs, "row", picked.rows, "1", dims=("design",))
            group = h5.create_group("objectives")
            write_dataset(group, "F", F, units, dims=("design", "objective"), names=names)
            write_dataset(group, "stored_F", picked.F, picked.obj_units,
                          dims=("design", "stored_objective"), names=picked.obj_names)
    if output is not None:
        started = time.perf_counter()
        write_simulation(output, result, signals=None if cfg.output.signals == "all"
                         else cfg.output.signals, float32=cfg.output.float32,
                         command=_command(), extra=extra)
        _info(f"wrote {len(written)} signals in {time.perf_counter() - started:.3g} s")
        out.print(f"wrote {output}")
    if plot is not None:
        from .plots import plot_simulation
        plot_simulation(result, plot)
        out.print(f"wrote {plot}")


def _pick_objectives(picked, cfg, result):
    """The picked designs' main and supplementary objectives from their new simulation:
    ``(F (P, m + s), names, units)``."""
    import numpy as np

    from .optimise import Problem

    problem = Problem.from_config(cfg)
    F, _, S = problem.values(result, picked.params(), len(picked.rows), supplementary=True)
    return (np.hstack([F, S]), problem.obj_names + problem.supplementary_names,
            problem.obj_units + problem.supplementary_units)


def _picks_table(picked, F, names, units) -> Table:
    """Each pick's objectives as the file stored them and as simulated now."""
    import numpy as np

    table = _table(f"{picked.source.name}: the picked designs' objectives")
    for col in ("pick", "row", "objective", "stored", "simulated", "change"):
        table.add_column(col, justify="left" if col in ("pick", "objective") else "right")
    for i, name in enumerate(picked.names):
        for j, (objective, unit) in enumerate(zip(names, units)):
            stored = picked.F[i, picked.obj_names.index(objective)] \
                if objective in picked.obj_names else np.nan
            change = "" if not np.isfinite(stored) or stored == 0 else \
                f"{(F[i, j] - stored) / abs(stored):+.1e}"
            table.add_row(name if j == 0 else "", str(int(picked.rows[i])) if j == 0 else "",
                          f"{objective} [{unit}]", "" if np.isnan(stored) else f"{stored:.6g}",
                          f"{F[i, j]:.6g}", change)
    return table


#: Options of ``analyse`` that only some kinds take: keyword -> flag.
_ANALYSE_OPTIONS = {"reference": "--reference", "road": "--road", "with_": "--with",
                    "mass_change": "--mass-change"}


def _analysis_help() -> str:
    from .analyse import SUMMARIES

    return "analysis kind: " + "; ".join(f"{k}: {v}" for k, v in SUMMARIES.items())


def _analysis_kinds(incomplete: str) -> list[str]:
    from .analyse import SUMMARIES

    return [k for k in SUMMARIES if k.startswith(incomplete)]


@app.command()
def analyse(kind: str = typer.Argument(..., help=_analysis_help(),
                                       autocompletion=_analysis_kinds),
            sources: list[Path] = typer.Argument(
                ..., help="YAML config, or Pareto HDF5 file; models takes several configs"),
            output: Optional[Path] = typer.Option(None, "-o", "--output",
                                                  help="HDF5 file for the numbers"),
            plot: Optional[Path] = typer.Option(None, "--plot",
                                                help="figure file (.png or .svg)"),
            reference: Optional[Path] = typer.Option(
                None, "--reference", help="models: the config the others are compared with "
                "(default the first)"),
            road: Optional[list[str]] = typer.Option(
                None, "--road", help="roads: an ISO 8608 class (A-E), or a config whose road "
                "and simulation sections replace the stored ones; repeatable"),
            with_: Optional[list[Path]] = typer.Option(
                None, "--with", help="controllers: YAML whose control: section and dampers "
                "replace the stored ones; repeatable"),
            mass_change: Optional[list[float]] = typer.Option(
                None, "--mass-change", help="masses: change of the load on the seat, in kg; "
                "repeatable (default -20 and +20)"),
            force: bool = typer.Option(False, "--force", help=_FORCE_HELP),
            max_memory: Optional[str] = typer.Option(None, "--max-memory",
                                                     help=_MEMORY_HELP)) -> None:
    """Run an analysis of configs or of a Pareto file and print its table: models, roads,
    masses, controllers, transmissibility or cdf-sensitivity (see KIND below)."""
    from .analyse import analysis_kinds
    from .plots import check_path

    kinds = analysis_kinds()
    if kind not in kinds:
        _fail(f"analyse: unknown kind {kind!r}; available: {', '.join(sorted(kinds))}")
    spec = kinds[kind]
    if len(sources) > 1 and not spec.many:
        _fail(f"analyse {kind} takes one SOURCE, got {len(sources)}")
    for source in sources:
        if not source.exists():
            _fail(f"{source}: no such file")
    given = {"reference": reference, "road": road or None, "with_": with_ or None,
             "mass_change": mass_change or None}
    options = {key: value for key, value in given.items() if value is not None}
    wrong = [_ANALYSE_OPTIONS[key] for key in options if key not in spec.options]
    if wrong:
        _fail(f"analyse {kind} does not take {', '.join(wrong)}")
    _memory(max_memory)
    with ExitStack() as stack:
        try:
            if plot is not None:
                check_path(plot)
        except ValueError as exc:
            _fail(str(exc))
        _claim(stack, output, force)
        _claim(stack, plot, force, "--plot")
        try:
            report = spec.run(sources if spec.many else sources[0], output, plot, **options)
        except (ConfigError, FileNotFoundError, ValueError) as exc:
            _fail(str(exc))
    table = _table(report.title)
    for col in report.columns:
        table.add_column(col)
    for row in report.rows:
        table.add_row(*row)
    _show(table, keys=2 if report.columns[:2] == ["metric", "unit"] else 1)
    for note in report.notes:
        out.print(note)
    for path in (output, plot):
        if path is not None:
            out.print(f"wrote {path}")


def _progress_line(p) -> str:
    """One generation's report: budget, evaluations, best or hypervolume, feasible share."""
    import numpy as np

    gen = f"gen {p.generation}" + (f"/{p.max_generations}" if p.max_generations else "")
    if not np.isfinite(p.best).any():
        score = "none feasible yet"
    else:
        score = f"HV {p.hypervolume:.4g}" if p.best.size > 1 else f"best {p.best[0]:.4g}"
    left = f", {p.time_left:.0f} s left" if p.time_left is not None else ""
    return (f"{p.phase} {gen}, {p.evaluations} evaluations, {score}, "
            f"{100 * p.feasible:.0f} % feasible{left}")


def _optimum_table(result, rows: int = 12) -> Table:
    """The best design (one column), or up to ``rows`` designs spread along the Pareto front
    (one row each)."""
    import numpy as np

    N = len(result.X)
    names = result.obj_names + result.var_names
    units = result.obj_units + result.var_units
    values = np.hstack([result.F, result.X])
    feasible = ["yes" if ok else "no" for ok in (result.G <= 0).all(axis=1)]
    suffix = "" if result.status == "finished" else " (interrupted)"
    if N == 1:
        table = _table("best design" + suffix)
        for col in ("quantity", "unit", "value"):
            table.add_column(col, justify="right" if col == "value" else "left")
        for name, unit, value in zip(names, units, values[0]):
            table.add_row(name, unit, f"{value:.5g}")
        table.add_row("feasible", "", feasible[0])
        return table
    pick = np.unique(np.linspace(0, N - 1, min(rows, N)).round().astype(int))
    table = _table(f"Pareto set: {len(pick)} of {N} designs, by {names[0]}" + suffix)
    table.add_column("#", justify="right")
    for name, unit in zip(names, units):
        table.add_column(f"{name} [{unit}]", justify="right")
    table.add_column("feasible")
    for i in pick:
        table.add_row(str(i), *(f"{v:.4g}" for v in values[i]), feasible[i])
    return table


@app.command()
def optimise(config: Path = typer.Argument(..., help="YAML config file"),
             output: Optional[Path] = typer.Option(
                 None, "-o", "--output", help="HDF5 file (default CONFIG's name with .h5 in "
                 "the current folder), rewritten every generation"),
             resume: bool = typer.Option(False, "--resume",
                                         help="continue from the checkpoint in OUT.h5"),
             plot: Optional[Path] = typer.Option(None, "--plot", help="figure of the front "
                                                 "(or the best value) and the history per "
                                                 "generation (.png or .svg)"),
             force: bool = typer.Option(False, "--force", help=_FORCE_HELP),
             max_memory: Optional[str] = typer.Option(None, "--max-memory",
                                                      help=_MEMORY_HELP)) -> None:
    """Optimise the config's design variables; write the optimum or Pareto set to HDF5.

    The progress line's HV is the hypervolume of every feasible non-dominated design found so
    far, objectives scaled by the first feasible generation's range (reference point 1.1):
    it never falls."""
    with ExitStack() as stack:
        output = output if output is not None else Path(config.stem + ".h5")
        _memory(max_memory)
        if plot is not None:
            from .plots import check_path
            try:
                check_path(plot)
            except ValueError as exc:
                _fail(str(exc))
        _claim(stack, output, force)
        _claim(stack, plot, force, "--plot")
        _optimise(config, output, resume, plot)


def _optimise(config: Path, output: Path, resume: bool, plot: Path | None) -> None:
    from rich.progress import BarColumn, Progress, TextColumn

    from .checks import check_config
    from .optimise import optimise as run

    cfg = _load(config)
    try:
        check_config(cfg)
    except ConfigError as exc:
        _fail(str(exc))
    total = cfg.optimiser.generations if cfg.optimiser is not None else None
    bar = Progress(TextColumn("{task.description}"), BarColumn(), console=err,
                   disable=not err.is_terminal or out.quiet)
    task = bar.add_task("starting", total=total)

    def report(p) -> None:
        bar.update(task, completed=p.generation, description=_progress_line(p))
        if not err.is_terminal and not out.quiet:
            err.print(_progress_line(p))

    try:
        with bar:
            result = run(cfg, output, resume=resume, callback=report, command=_command())
    except ConfigError as exc:
        _fail(str(exc))
    except KeyboardInterrupt:
        err.print("the first generation had not completed: nothing written")
        raise typer.Exit(code=130)
    _show(_optimum_table(result))
    if result.weights is not None:
        out.print("weighted sum (Eq 5.7): " + " + ".join(
            f"{w:.4g} {name}" for w, name in zip(result.weights, result.obj_names)))
    if result.status == "interrupted":
        err.print(f"wrote the designs found so far to {output}; continue with "
                  f"suspopt optimise {config} -o {output} --resume", soft_wrap=True)
        raise typer.Exit(code=130)
    out.print(f"wrote {output}")
    if plot is not None:
        from .plots import plot_optimisation
        try:
            plot_optimisation(result, plot)
        except ValueError as exc:
            _fail(str(exc))
        out.print(f"wrote {plot}")
    if result.status == "failed":
        err.print(f"error: every design of the optimum failed to simulate (diverged or gave "
                  f"NaN); {output} holds them with the penalty values and status 'failed'",
                  soft_wrap=True)
        raise typer.Exit(code=EXIT_ALL_FAILED)


def _floats(option: str, text: str) -> list[float]:
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        _fail(f"{option} {text}: expected numbers separated by commas")
    return values


def _kesort_tables(sel) -> list[Table]:
    """The optimum of each case and of the pool (the form of Tables 6.2-6.3, 7.5-7.6), then
    the Pareto picks of the pool."""
    import numpy as np

    columns = [(f"{label} optimum", cs.chosen) for label, cs in sel.case_sorts.items()]
    columns.append(("optimum among all" if sel.case_sorts else "k-ε optimum", sel.chosen))
    columns += [(f"tie {n}", int(i)) for n, i in enumerate(sel.sort.ties[1:], start=2)]
    table = _table("k-ε optimum" + (" of each case and among all" if sel.case_sorts
                                         else ""))
    table.add_column("quantity")
    table.add_column("unit")
    rows = [i for _, i in columns]
    for title, _ in columns:
        table.add_column(title, justify="right")
    table.add_row("design #", "", *(str(i) for i in rows))
    table.add_row("case", "", *(str(sel.case[i]) for i in rows))
    if sel.case_sorts:
        table.add_row("k-ε level in its case", "1",
                      *(f"{sel.level_in_case(i):.3f}" for i in rows))
    table.add_row("k-ε level among all" if sel.case_sorts else "k-ε level", "1",
                  *(f"{sel.sort.k_eps[i]:.3f}" for i in rows))
    table.add_row("k level among all" if sel.case_sorts else "k level", "1",
                  *(f"{sel.sort.k[i]:.0f}" for i in rows))
    for j, (name, unit) in enumerate(zip(sel.names, sel.units)):
        table.add_row(name, unit, *(f"{sel.F[i, j]:.4g}" for i in rows))
    for j, (name, unit) in enumerate(zip(sel.var_names, sel.var_units)):
        table.add_row(name, unit, *(
            "-" if np.isnan(sel.X[i, j]) else f"{sel.X[i, j]:.5g}" for i in rows))
    table.add_row("feasible", "", *("yes" if sel.feasible[i] else "no" for i in rows))
    picks = _table("Pareto picks among all (Fig. 8.21: edges and knee)")
    for col in ("pick", "design #", "case", "k-ε level"):
        picks.add_column(col, justify="left" if col in ("pick", "case") else "right")
    for name, unit in zip(sel.names, sel.units):
        picks.add_column(f"{name} [{unit}]", justify="right")
    for key, i in sel.picks.items():
        picks.add_row(key, str(i), str(sel.case[i]), f"{sel.sort.k_eps[i]:.3f}",
                      *(f"{v:.4g}" for v in sel.F[i]))
    return [table, picks]


def _threshold_line(sort, label: str) -> str:
    if sort.P is None:
        how = "absolute ε"
    else:
        how = f"ε = P·max NF with P = {sort.P:.4g}" + (" (auto)" if sort.P_auto else "")
    tied = "" if sort.unique else f"; {len(sort.ties)} designs share the top level"
    return f"{label}: {how}, normalised by {sort.normalisation}{tied}"


@app.command()
def kesort(pareto: list[Path] = typer.Argument(..., help="Pareto HDF5 file(s) written by "
                                               "suspopt optimise"),
           config: list[Path] = typer.Option(
               [], "--config", "-c", help="config whose objectives are evaluated (default: "
               "each file's own): once for every file, or once per file"),
           label: list[str] = typer.Option(
               [], "--label", "-l", help="case label, once per file; files with the same "
               "label form one case (default: the config's or the file's name)"),
           eps: Optional[str] = typer.Option(
               None, "--eps", help="absolute thresholds in the objectives' SI units: one "
               "value, or one per objective separated by commas"),
           P: Optional[str] = typer.Option(
               None, "--P", "-P", help="ε = P·max NF (Eq 6.19, 7.13), or 'auto' (default): "
               "the smallest P on the --P-range grid that leaves one best design"),
           P_range: str = typer.Option("0.01,1.0", "--P-range", help="LOW,HIGH of P for "
                                       "auto"),
           P_step: float = typer.Option(0.01, "--P-step", help="grid step of P for auto"),
           normalise: str = typer.Option("max", "--normalise", help="max (Eq 7.12) or "
                                         "minmax"),
           keep_infeasible: bool = typer.Option(False, "--keep-infeasible",
                                                help="sort infeasible designs too"),
           output: Optional[Path] = typer.Option(None, "-o", "--output",
                                                 help="HDF5 file for /kesort"),
           plot: Optional[Path] = typer.Option(None, "--plot", help="figure of the k-ε "
                                               "levels over the front (.png or .svg)"),
           force: bool = typer.Option(False, "--force", help=_FORCE_HELP),
           max_memory: Optional[str] = typer.Option(None, "--max-memory",
                                                    help=_MEMORY_HELP)) -> None:
    """Choose the optimum of Pareto sets by k-ε optimality (Eq 6.10-6.12); supplementary
    objectives are re-simulated in one batch."""
    _memory(max_memory)
    with ExitStack() as stack:
        _claim(stack, output, force)
        _claim(stack, plot, force, "--plot")
        _kesort(pareto, config, label, eps, P, P_range, P_step, normalise, keep_infeasible,
                output, plot)


def _kesort(pareto, config, label, eps, P, P_range, P_step, normalise, keep_infeasible, output,
            plot) -> None:
    import importlib.util

    from .kesort import check_options
    from .selection import load_design_sets, select, write_selection

    if plot is not None:
        if plot.suffix.lower() not in (".png", ".svg"):
            _fail(f"--plot {plot}: give a .png or .svg file")
        if importlib.util.find_spec("matplotlib") is None:
            _fail("--plot needs matplotlib: pip install 'suspopt[plot]'")
    if P is not None and P != "auto":
        P = _floats("--P", P)[0]
    P_lo_hi = _floats("--P-range", P_range)
    if len(P_lo_hi) != 2:
        _fail(f"--P-range {P_range}: expected LOW,HIGH")
    eps_values = None if eps is None else _floats("--eps", eps)
    options = dict(P=P, normalise=normalise, P_range=tuple(P_lo_hi), P_step=P_step)
    try:
        check_options(eps_values, **options)
    except ValueError as exc:
        _fail(f"kesort options: {exc}")
    try:
        sets = load_design_sets(pareto, config, label)
        selection = select(sets, eps_values, feasible_only=not keep_infeasible, **options)
    except ConfigError as exc:
        _fail(str(exc))
    if output is not None:
        write_selection(output, selection, command=_command())
    if plot is not None:
        from .plots import plot_kesort
        plot_kesort(selection, plot)
    for table, keys in zip(_kesort_tables(selection), (2, 3)):
        _show(table, keys=keys)
    for label_, cs in selection.case_sorts.items():
        out.print(_threshold_line(cs.sort, label_))
    out.print(_threshold_line(selection.sort, "all" if selection.case_sorts
                              else selection.cases[0]))
    for note in selection.notes:
        out.print(f"note: {note}")
    for path in (output, plot):
        if path is not None:
            out.print(f"wrote {path}")
