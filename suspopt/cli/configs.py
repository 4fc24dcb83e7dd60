"""``validate``, ``schema``, ``init`` and ``export``: configs in and out (see :mod:`suspopt.cli`)."""

from __future__ import annotations

import sys
import time
from contextlib import ExitStack
from pathlib import Path

import typer

from ..errors import ConfigError
from .base import (
    app,
    check_suffix,
    claim_output,
    err,
    fail,
    force_option,
    max_memory_option,
    out,
    say_io_notes,
    set_memory_limit,
    verbose_info,
)


@app.command()
def validate(
    configs: list[Path] = typer.Argument(..., help="YAML config files", metavar="CONFIG"),
    max_errors: int = typer.Option(
        20,
        "--max-errors",
        metavar="N",
        help="list at most N errors of each config (0: all of them)",
    ),
    max_memory: str | None = max_memory_option(),
) -> None:
    """Check configs and list every problem of each, with its line.

    What it reports is what any command would reject about a config. A valid config gets
    one line on stdout; one with errors a line per error on stderr (error: FILE:LINE:
    KEY: message, in the order of the file), then their count.

    A value that looks like a slip of units (1.2 for a body of 1200 kg) is an error where
    it is absurd for a road vehicle, else a warning, which rejects nothing.

    The exit code is 2 if any config is not valid."""
    set_memory_limit(max_memory)
    if max_errors < 0:
        fail(f"--max-errors {max_errors}: give how many errors to list, or 0 for all of them")
    problems = 0
    for config in configs:
        try:
            valid, warnings = _validate_one(config)
        except ConfigError as exc:
            problems += 1
            _report(config, exc.problems, exc.warnings, max_errors)
        else:
            _report(config, (), warnings, max_errors)
            out.print(valid)
    if problems:
        raise typer.Exit(code=2)


def _validate_one(config: Path) -> tuple[str, tuple]:
    """Check one config (ConfigError with its problems); the line that says it is valid and
    its warnings."""
    from ..config import load_config
    from ..validation import check_config

    started = time.perf_counter()
    cfg = load_config(config)
    verbose_info(f"{config}: read and typed in {time.perf_counter() - started:.3g} s")
    try:
        check_config(cfg)
    except ConfigError as exc:
        raise ConfigError(problems=exc.problems, warnings=cfg.warnings) from None
    verbose_info(
        f"checked the run (steps, road, RK4 stability, memory"
        f"{', the optimisation' if cfg.design_variables else ''}) in "
        f"{time.perf_counter() - started:.3g} s"
    )
    return f"{config}: valid ({cfg.vehicle.preset}, road {cfg.road.kind})", cfg.warnings


def _report(config: Path, errors, warnings, max_errors: int) -> None:
    """The lines of one config's ``errors`` (at most ``max_errors``, 0 for all) and
    ``warnings`` on stderr, in the order of the file, then the count of its errors."""
    shown = list(errors) if max_errors == 0 else list(errors)[:max_errors]
    lines = sorted(
        [("error", p) for p in shown] + [("warning", p) for p in warnings],
        key=lambda item: item[1].line or 0,
    )
    for severity, problem in lines:
        err.print(f"{severity}: " + " ".join(str(problem).split()), soft_wrap=True)
    if not errors:
        return
    count = f"{len(errors)} error{'s' if len(errors) != 1 else ''}"
    if warnings:
        count += f" and {len(warnings)} warning{'s' if len(warnings) != 1 else ''}"
    hidden = len(errors) - len(shown)
    more = f" ({hidden} not shown: --max-errors 0 lists all)" if hidden else ""
    err.print(f"{count} in {config}{more}", soft_wrap=True)


@app.command()
def schema() -> None:
    """Print the JSON Schema of the config (for editor completion)."""
    from importlib import resources

    # the schema as suspopt.config.config_schema() makes it, stored with the package so that
    # printing it needs no model (tests/test_schema.py checks the two are the same)
    sys.stdout.write(resources.files("suspopt").joinpath("schema.json").read_text())


def _template_help() -> str:
    from ..templates import TEMPLATES

    return "the kind of study: " + "; ".join(f"{k}: {v}" for k, v in TEMPLATES.items())


def _template_kinds(incomplete: str) -> list[str]:
    from ..templates import template_names

    return [k for k in template_names() if k.startswith(incomplete)]


@app.command()
def init(
    kind: str = typer.Argument(..., help=_template_help(), autocompletion=_template_kinds),
    output: Path = typer.Option(..., "-o", "--output", help="the new config (YAML)"),
    force: bool = force_option(),
) -> None:
    """Write a commented starter config of one kind of study, ready to validate and run."""
    from ..io import atomic_file
    from ..signature import signed_config
    from ..templates import template_text

    with ExitStack() as stack:
        try:
            text = template_text(kind)
        except ValueError as exc:
            fail(f"init: {exc}")
        claim_output(stack, output, force)
        check_suffix(output, "yaml")
        try:
            with atomic_file(output) as stream:
                stream.write(signed_config(text).encode())
        except ConfigError as exc:  # (a full disk)
            fail(str(exc))
    command = "optimise" if kind in ("optimise", "kesort", "spectral", "robust") else "simulate"
    out.print(
        f"wrote {output}; next: suspopt validate {output}, then suspopt {command} "
        f"{output} -o {Path(output).with_suffix('.h5')}"
    )


@app.command()
def export(
    source: Path = typer.Argument(
        ...,
        help="result file of optimise, kesort or analyse"
        " roads|masses|controllers|tolerances|builds|transmissibility",
    ),
    pick: list[str] = typer.Option(
        [],
        "--pick",
        help="the design to write as a config: knee, best_<objective>, chosen or a design id "
        "(its row in the front it came from)",
    ),
    output: Path | None = typer.Option(
        None, "-o", "--output", help="YAML file for the picked design"
    ),
    csv: Path | None = typer.Option(
        None, "--csv", help="folder for the file's tables as CSV, units in the headers"
    ),
    mat: Path | None = typer.Option(
        None, "--mat", help="MATLAB file (.mat) of every group of the file, as structs"
    ),
    fmu: Path | None = typer.Option(
        None,
        "--fmu",
        help="FMU (FMI 2.0, model exchange and co-simulation) of the pick, or of a config's "
        "own design; several picks: one FMU each, <stem>-<pick>.fmu",
    ),
    road: str = typer.Option(
        "input",
        "--road",
        help="with --fmu: input (the road under each wheel from the FMU's inputs) or "
        "embedded (the config's road built in: the FMU alone reproduces simulate)",
    ),
    force: bool = force_option(),
) -> None:
    """Write a picked design as a standalone config or an FMU, or a file's tables as CSV or MATLAB.

    With -o design.yaml it writes the config of one pick; with --fmu design.fmu, the pick (or a
    config's own design) as an FMU compiled for this platform when a C compiler is found
    (docs/guide/export-fmu.md); with --csv DIR, the tables; with --mat FILE.mat, every group as
    a MATLAB struct (docs/guide/export-mat.md)."""
    target = _one_output(output, csv, mat, fmu, road)
    if target is not None:
        return _export_fmu(source, pick, target, road, force)
    with ExitStack() as stack:
        try:
            if csv is not None or mat is not None:
                from ..export import write_csv
                from ..matfile import write_mat

                option, kind = ("--csv", "table") if csv is not None else ("--mat", "group")
                if pick:
                    fail(f"{option} writes every {kind} of the file; --pick is for -o")
                try:
                    if csv is not None:
                        written = write_csv(source, csv, force=force)
                    elif mat is not None:
                        written = [write_mat(source, mat, force=force)]
                finally:
                    say_io_notes()  # (a killed run's leftovers beside an output)
                for path in written:
                    out.print(f"wrote {path}")
                return
            from ..choosing.picks import design_config, read_picks, split_picks
            from ..io import atomic_file
            from ..signature import signed_config

            assert output is not None  # (one of the three is given: checked above)
            claim_output(stack, output, force, inputs=[("the input", source)])
            check_suffix(output, "yaml")
            names = split_picks(pick)
            if len(names) != 1:
                fail(f"--pick: -o writes one design; got {len(names)} ({', '.join(names)})")
            picked = read_picks(source, names)
            _, text = design_config(picked)
            with atomic_file(output) as stream:
                stream.write(signed_config(text).encode())
        except ConfigError as exc:
            fail(str(exc))
    out.print(f"wrote {output} (design {picked.ids[0]} of {source}, --pick {names[0]})")


def _one_output(output, csv, mat, fmu, road: str) -> Path | None:
    """Bad input unless ``export`` was given one output (and ``--road`` only with
    ``--fmu``); the FMU's path, or None for another output."""
    if [output, csv, mat, fmu].count(None) != 3:
        fail("export: give -o FILE.yaml (with --pick), --fmu FILE.fmu, --csv DIR or --mat FILE.mat")
    if fmu is None and road != "input":
        fail("--road is for --fmu")
    return fmu


def _export_fmu(source: Path, pick: list[str], fmu: Path, road: str, force: bool) -> None:
    """``export SOURCE --fmu FILE.fmu``: the picks of a result file, or a config's own design
    (:mod:`suspopt.fmu`); every target claimed and checked before any is written."""
    from ..choosing.picks import split_picks
    from ..fmu.export import check_pick_targets, export_fmu, export_picks
    from ..fmu.model import ROAD_MODES
    from ..signature import CONFIG_SUFFIXES

    if road not in ROAD_MODES:
        fail(f"--road {road}: use {' or '.join(ROAD_MODES)}")
    is_config = source.suffix.lower() in CONFIG_SUFFIXES
    with ExitStack() as stack:
        try:
            if is_config and pick:
                fail(
                    f"--pick: {source} is a config: it has one design, its own; pick from a "
                    "result file of optimise, kesort or analyse"
                )
            names = [] if is_config else split_picks(pick)
            targets = check_pick_targets(fmu, names)
            for target in targets:
                claim_output(stack, target, force, "--fmu", inputs=[("the input", source)])
                check_suffix(target, "fmu", "--fmu")
            if is_config:
                from ..config import load_config

                written = [export_fmu(load_config(source), fmu, road, source=str(source))]
            else:
                written = export_picks(source, names, fmu, road, force=force)
        except ConfigError as exc:
            fail(str(exc))
    for done in written:
        built = (
            f"compiled for {done.binary.split('/')[1]} with {done.note}"
            if done.binary
            else f"source-only ({done.note}; sources/ compiles with any C99 compiler)"
        )
        out.print(
            f"wrote {done.path} (FMI 2.0 model exchange and co-simulation, road {road}; "
            f"{built}; {done.inputs} inputs, {done.outputs} outputs, {done.tunable} tunable "
            f"parameters, {done.constants} constants)",
            soft_wrap=True,
        )
