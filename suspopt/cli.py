"""The ``suspopt`` command: a thin layer that reads arguments, calls the library and renders.

Exit codes: 0 success; 2 bad input (config, file, arguments) with one line naming the YAML key
and line; 1 unexpected failure.
"""

from __future__ import annotations

import json
import shlex
import sys
from pathlib import Path
from typing import Optional

import numpy as np
import typer
from rich.console import Console
from rich.table import Table

from .config import ConfigError, config_schema, load_config

app = typer.Typer(add_completion=False, no_args_is_help=True, pretty_exceptions_enable=False,
                  help="Simulate, optimise and select vehicle and seat suspensions from YAML.")
out = Console()
err = Console(stderr=True)


def _fail(message: str) -> None:
    """Report bad input in one line and exit with code 2."""
    err.print(f"error: {message}", markup=False, highlight=False, soft_wrap=True)
    raise typer.Exit(code=2)


def _load(path: Path):
    try:
        return load_config(path)
    except ConfigError as exc:
        _fail(str(exc))


def _command() -> str:
    return "suspopt " + " ".join(shlex.quote(a) for a in sys.argv[1:])


@app.command()
def validate(config: Path = typer.Argument(..., help="YAML config file")) -> None:
    """Check a config file and report the first problem with its line."""
    cfg = _load(config)
    out.print(f"{config}: valid ({cfg.vehicle.preset}, road {cfg.road.kind})")


@app.command()
def schema() -> None:
    """Print the JSON Schema of the config (for editor completion)."""
    sys.stdout.write(json.dumps(config_schema(), indent=2) + "\n")


def _summary_table(result) -> Table:
    """Peak and RMS body acceleration, max travel and tyre deflection per corner."""
    P = min(result.P, 5)
    table = Table(title=f"{result.model.preset} - key results"
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


@app.command()
def simulate(config: Path = typer.Argument(..., help="YAML config file"),
             output: Optional[Path] = typer.Option(None, "-o", "--output",
                                                   help="HDF5 file to write")) -> None:
    """Simulate the configured vehicle over its road; write signals to HDF5."""
    from .io import write_simulation
    from .simulate import simulate as run

    cfg = _load(config)
    if output is not None and not output.parent.exists():
        _fail(f"-o {output}: folder {output.parent} does not exist")
    try:
        result = run(cfg)
    except (ConfigError, FileNotFoundError, ValueError) as exc:
        _fail(str(exc))
    if result.diverged.any():
        err.print(f"warning: design(s) {np.flatnonzero(result.diverged).tolist()} diverged "
                  f"(at t = {np.nanmin(result.diverged_at):.4g} s); their samples are NaN; "
                  f"try a smaller simulation.dt", markup=False)
    out.print(_summary_table(result))
    if output is not None:
        signals = None if cfg.output.signals == "all" else cfg.output.signals
        try:
            write_simulation(output, result, signals=signals, float32=cfg.output.float32,
                             command=_command())
        except KeyError as exc:
            _fail(f"output.signals: {exc.args[0]}")
        out.print(f"wrote {output}")


@app.command()
def analyse(kind: str = typer.Argument(..., help="analysis kind"),
            source: Path = typer.Argument(..., help="YAML config or result HDF5 file"),
            output: Optional[Path] = typer.Option(None, "-o", "--output",
                                                  help="HDF5 file for the numbers"),
            plot: Optional[Path] = typer.Option(None, "--plot",
                                                help="figure file (.png or .svg)")) -> None:
    """Run an analysis (see the README for the kinds) and print its table."""
    from .analyse import analysis_kinds

    kinds = analysis_kinds()
    if kind not in kinds:
        _fail(f"analyse: unknown kind {kind!r}; available: {', '.join(sorted(kinds))}")
    if not source.exists():
        _fail(f"{source}: no such file")
    for path in (output, plot):
        if path is not None and not path.parent.exists():
            _fail(f"{path}: folder {path.parent} does not exist")
    try:
        report = kinds[kind](source, output, plot)
    except (ConfigError, FileNotFoundError, ValueError) as exc:
        _fail(str(exc))
    table = Table(title=report.title)
    for col in report.columns:
        table.add_column(col)
    for row in report.rows:
        table.add_row(*row)
    out.print(table)
    for note in report.notes:
        out.print(note)
    for path in (output, plot):
        if path is not None:
            out.print(f"wrote {path}")
