"""``suspopt report FILE.h5 ... -o study.html``: the interactive Pareto explorer
(:mod:`suspopt.report`)."""

from __future__ import annotations

from contextlib import ExitStack
from pathlib import Path

import typer

from ..errors import ConfigError
from . import base
from .base import app, out


@app.command()
def report(
    sources: list[Path] = typer.Argument(
        ...,
        help="result files of optimise, kesort or analyse"
        " roads|masses|controllers|tolerances|builds|transmissibility",
    ),
    output: Path = typer.Option(..., "-o", "--output", help="the HTML file to write"),
    with_signals: list[str] = typer.Option(
        [],
        "--with-signals",
        help="designs (design ids or pick names) whose signals to show besides the picks'; "
        "repeatable, or separated by commas",
    ),
    title: str | None = typer.Option(None, "--title", help="the page's title"),
    force: bool = base.force_option(),
) -> None:
    """Write one self-contained HTML page to explore the fronts of result files.

    The page holds the front and parallel coordinates, each design's row on click, the picks'
    signals, the history and the provenance; it opens offline in any browser."""
    from ..report import build_report

    rows = [r.strip() for item in with_signals for r in item.split(",") if r.strip()]
    with ExitStack() as stack:
        base.claim_output(stack, output, force, inputs=[("the input", s) for s in sources])
        base.check_suffix(output, "html")
        try:
            path, size, notes = build_report(sources, output, rows, title)
        except ConfigError as exc:
            base.fail(str(exc))
    for note in notes:
        out.print(note)
    out.print(f"wrote {path} ({size / 1e6:.1f} MB)")
