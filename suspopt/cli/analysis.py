"""``analyse``: the analyses of Ch. 3, 7 and 8 (see :mod:`suspopt.cli`)."""

from __future__ import annotations

from pathlib import Path

import typer

from ..errors import ConfigError
from . import base
from .base import app, out
from .kinds import AnalyseCommand

_ANALYSE_OPTIONS = {
    "reference": "--reference",
    "road": "--road",
    "with_": "--with",
    "mass_change": "--mass-change",
    "tolerance": "--tolerance",
    "samples": "--samples",
    "seed": "--seed",
    "distribution": "--distribution",
    "pick": "--pick",
    "batch": "--batch",
}


_TOLERANCE_HELP = (
    "tolerances, builds: how far a design variable may be off, in % of its value: T for "
    "every variable, NAME=T for one (repeatable); without them each variable's tolerance "
    "in the config, else 10"
)


_PICK_HELP = (
    "roads, masses, controllers, tolerances, builds, transmissibility: analyse only these "
    "designs of the file (knee, best_<objective>, chosen of a kesort file, or design ids; "
    "comma-separated or repeated), from any file simulate --pick reads; scenarios: these "
    "designs of its robust front"
)


_BATCH_HELP = (
    "builds: design variables made in one batch, off alike in every build: NAME,NAME "
    "(repeatable, one batch each); none: every variable alone; without it the config's "
    "design_variables[i].batch"
)


def _analysis_help() -> str:
    from ..analyse import SUMMARIES

    return "analysis kind: " + "; ".join(f"{k}: {v}" for k, v in SUMMARIES.items())


def _analysis_kinds(incomplete: str) -> list[str]:
    from ..analyse import SUMMARIES

    return [k for k in SUMMARIES if k.startswith(incomplete)]


def _checked(kind: str, sources: list[Path], given: dict):
    """The analysis of ``kind`` and the options given to it, checked as bad input."""
    from ..analyse import analysis_kinds
    from ..files import Unreadable, status

    kinds = analysis_kinds()
    if kind not in kinds:
        base.fail(f"analyse: unknown kind {kind!r}; available: {', '.join(sorted(kinds))}")
    spec = kinds[kind]
    if len(sources) > 1 and not spec.many:
        base.fail(f"analyse {kind} takes one SOURCE, got {len(sources)}")
    for source in sources:
        try:
            if status(source) is None:
                base.fail(f"{source}: no such file")
        except Unreadable as exc:
            base.fail(f"{source}: {exc}")
    options = {key: value for key, value in given.items() if value is not None}
    wrong = [_ANALYSE_OPTIONS[key] for key in options if key not in spec.options]
    if wrong:
        base.fail(f"analyse {kind} does not take {', '.join(wrong)}")
    return spec, options


@app.command(cls=AnalyseCommand)
@base.run_options
def analyse(
    kind: str = typer.Argument(..., help=_analysis_help(), autocompletion=_analysis_kinds),
    sources: list[Path] = typer.Argument(
        ..., help="YAML config, or Pareto HDF5 file; models takes several configs"
    ),
    output: Path | None = typer.Option(None, "-o", "--output", help="HDF5 file for the numbers"),
    plot: Path | None = typer.Option(None, "--plot", help="figure file (.png or .svg)"),
    reference: Path | None = typer.Option(
        None,
        "--reference",
        help="models: the config the others are compared with (default the first)",
    ),
    road: list[str] | None = typer.Option(
        None,
        "--road",
        help="roads: an ISO 8608 class (A-E), or a config whose road "
        "and simulation sections replace the stored ones; repeatable",
    ),
    with_: list[Path] | None = typer.Option(
        None,
        "--with",
        help="controllers: YAML whose control: section and dampers "
        "replace the stored ones, repeatable; transmissibility of a front: YAML whose "
        "seat.mass and seat.passenger replace the stored ones",
    ),
    mass_change: list[float] | None = typer.Option(
        None,
        "--mass-change",
        help="masses: change of the load on the seat, in kg; repeatable (default -20 and +20)",
    ),
    tolerance: list[str] | None = typer.Option(None, "--tolerance", help=_TOLERANCE_HELP),
    samples: int | None = typer.Option(
        None, "--samples", help="builds: how many builds of each design (default 100)"
    ),
    seed: int | None = typer.Option(
        None, "--seed", help="builds: the seed of the draws (default the config's optimiser.seed)"
    ),
    distribution: str | None = typer.Option(
        None, "--distribution", help="builds: uniform (default) or normal (σ = t/3, cut at ±t)"
    ),
    pick: list[str] | None = typer.Option(None, "--pick", help=_PICK_HELP),
    batch: list[str] | None = typer.Option(None, "--batch", help=_BATCH_HELP),
    full: bool = base.full_option(),
    *,
    run: base.RunOptions,
) -> None:
    """Run an analysis of configs or of a Pareto file and print its table.

    The kinds: models, roads, masses, controllers, tolerances, builds, transmissibility,
    scenarios and cdf-sensitivity (see KIND below); suspopt analyse KIND --help shows a
    kind's own options and an example."""
    from ..plots import check_path

    given = {
        "reference": reference,
        "road": road or None,
        "with_": with_ or None,
        "mass_change": mass_change or None,
        "tolerance": tolerance or None,
        "samples": samples,
        "seed": seed,
        "distribution": distribution,
        "pick": pick or None,
        "batch": batch or None,
    }
    spec, options = _checked(kind, sources, given)
    try:
        if plot is not None:
            check_path(plot)
    except ValueError as exc:
        base.fail(str(exc))
    inputs = [("the input", s) for s in sources]
    inputs += [("--reference", reference)] if reference is not None else []
    inputs += [("--road", Path(r)) for r in road or []] + [("--with", w) for w in with_ or []]
    with run.outputs(output, plot, inputs=inputs):
        try:
            done = spec.run(sources if spec.many else sources[0], **options)
            if output is not None:
                done.write(output)
            if plot is not None:
                done.plot(plot)
            report = done.report()
        except (ConfigError, FileNotFoundError, ValueError) as exc:
            base.fail(str(exc))
    _show(report, output, plot, full)


def _show(report, output: Path | None, plot: Path | None, full: bool = True) -> None:
    """An analysis's table (a long one summarised unless ``full``) and notes, and the files
    it wrote."""
    table = base.new_table(report.title)
    for col in report.columns:
        table.add_column(col)
    for row in report.rows:
        table.add_row(*row)
    keys = 2 if report.columns[:2] == ["metric", "unit"] else 1
    base.show_table(table, keys, full, output)
    from .summary import notes_that_fit

    for note in report.notes if full else notes_that_fit(report.notes):
        out.print(note)
    for path in (output, plot):
        if path is not None:
            out.print(f"wrote {path}")
