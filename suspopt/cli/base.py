"""The command's shared parts: the typer app and its global options, the consoles, the tables that fold to the terminal, output claiming and config loading (see :mod:`suspopt.cli`)."""

from __future__ import annotations

import functools
import inspect
import shlex
import sys
from collections.abc import Callable, Iterator, Sequence
from contextlib import ExitStack, contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from ..errors import ConfigError
from .console import err, new_table, out

if TYPE_CHECKING:
    from rich.table import Table

app = typer.Typer(
    add_completion=True,
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    help="Simulate, optimise and select vehicle and seat suspensions from YAML.",
)
#: Exit code of a run that finished but whose every design failed to simulate.
EXIT_ALL_FAILED = 3

FORCE_HELP = (
    "replace an existing output that suspopt did not write, or a result of another config "
    "or other options"
)
MEMORY_HELP = (
    "most memory a run may take, e.g. 4G (default: what the machine has free); "
    "evaluations of many designs run in batches of at most half of it"
)


def force_option():
    """``--force``: replace an existing output that suspopt did not write, or a result of
    another config or request (:mod:`suspopt.replacing`)."""
    return typer.Option(False, "--force", help=FORCE_HELP)


def plot_option(what: str):
    """``--plot FIG``: a figure of ``what``, PNG or SVG by the suffix."""
    return typer.Option(None, "--plot", help=f"figure of {what} (.png or .svg)")


def set_option(then: str = ""):
    """``--set PATH=VALUE``: a numeric field of the config changed before it is checked
    (:func:`suspopt.params.apply_sets`); ``then``: what else the command says of it."""
    return typer.Option(
        [],
        "--set",
        help="PATH=VALUE: override a numeric field of the config (road.speed=25); repeatable"
        + then,
    )


def max_memory_option():
    """``--max-memory SIZE``: the most memory a run may take."""
    return typer.Option(None, "--max-memory", help=MEMORY_HELP)


EXECUTOR_HELP = (
    "where designs are simulated: local (this process), processes (a local pool) or dask "
    "(pip install 'suspopt[dask]'); wins over the config's execution: section"
)


def executor_option():
    """``--executor``: where designs are simulated (:mod:`suspopt.execution`)."""
    return typer.Option(None, "--executor", help=EXECUTOR_HELP)


def scheduler_option():
    """``--scheduler``: the address of a running Dask scheduler."""
    return typer.Option(
        None, "--scheduler", help="address of a running Dask scheduler, e.g. tcp://host:8786"
    )


def workers_option():
    """``--workers``: the worker processes an executor starts."""
    return typer.Option(
        None,
        "--workers",
        help="worker processes that processes, or dask without --scheduler, starts "
        "(default: the machine's cores)",
    )


@dataclass(frozen=True)
class RunOptions:
    """The options of every command that runs a study (``simulate``, ``optimise``, ``kesort``,
    ``analyse``): ``--force``, ``--max-memory``, ``--executor``, ``--scheduler`` and
    ``--workers``, declared once (:func:`run_options`)."""

    force: bool = False
    max_memory: str | None = None
    executor: str | None = None
    scheduler: str | None = None
    workers: int | None = None
    #: What the command is asked for (:func:`suspopt.replacing.request_of`) and ``--resume``.
    request: dict = field(default_factory=dict)
    resume: bool = False

    def executing(self, progress=None, lost_hint: str = ""):
        """:func:`executing` with the command's ``--executor``, ``--scheduler``, ``--workers``."""
        return executing(self.executor, self.scheduler, self.workers, progress, lost_hint)

    @contextmanager
    def outputs(
        self,
        output: Path | None,
        plot: Path | None,
        execute: bool = True,
        inputs: Sequence[tuple[str, Path]] = (),
        hold: bool = True,
    ) -> Iterator[None]:
        """``--max-memory`` applied; then, for the block, the executor options in force (unless
        ``execute`` is False: the command puts them in force itself) and ``output`` and
        ``plot`` claimed (:func:`claim_output`, ``--force``), neither of them one of the
        command's ``inputs`` nor the other. ``output`` must end in an HDF5 suffix, and may
        replace only a result of the same config and request (:mod:`suspopt.replacing`);
        ``plot`` is written with it as one (``hold``: both renamed at the block's end; else
        ``output`` lands as it is written, :func:`suspopt.replacing.together`)."""
        from ..replacing import Guard, refusal

        set_memory_limit(self.max_memory)
        with ExitStack() as stack:
            if execute:
                stack.enter_context(self.executing())
            guard = Guard(dict(self.request), self.force, self.resume, plot)
            claim_output(stack, output, self.force, inputs=inputs, guard=guard)
            others = [*inputs, ("-o", output)] if output is not None else inputs
            claim_output(stack, plot, self.force, "--plot", others)
            check_suffix(output, "hdf5")  # (after the names' own checks: an empty name)
            if output is not None and not (self.force or self.resume):
                why = refusal(output, None, guard)  # (the request now; the config on writing)
                if why is not None:
                    fail(why)
            if output is not None and plot is not None:
                from .. import io
                from ..replacing import together

                keys = [io._key(output), io._key(plot)]
                stack.enter_context(together(keys, hold, io.commit))
            yield


#: The :class:`RunOptions` as the command line declares them: (name, type, option).
_RUN_OPTIONS = (
    ("force", bool, force_option),
    ("max_memory", str | None, max_memory_option),
    ("executor", str | None, executor_option),
    ("scheduler", str | None, scheduler_option),
    ("workers", int | None, workers_option),
)


def run_options(command: Callable[..., None]) -> Callable[..., None]:
    """``command``, whose last parameter is the keyword-only ``run: RunOptions``, as a typer
    command that takes the :class:`RunOptions` after its own options and hands them over as
    that one ``run``, with the command's request (:func:`suspopt.replacing.request_of`); a
    ConfigError that leaves ``command`` is bad input (:func:`fail`)."""
    from ..replacing import request_of

    own = [p for p in inspect.signature(command).parameters.values() if p.name != "run"]
    shared = [
        inspect.Parameter(name, inspect.Parameter.KEYWORD_ONLY, default=option(), annotation=kind)
        for name, kind, option in _RUN_OPTIONS
    ]

    @functools.wraps(command)
    def wrapper(**kwargs: Any) -> None:
        run = RunOptions(
            **{p.name: kwargs.pop(p.name) for p in shared},
            request=request_of(command.__name__, own, kwargs, _NOT_REQUESTED),
            resume=bool(kwargs.get("resume", False)),
        )
        try:
            command(**kwargs, run=run)
        except ConfigError as exc:  # bad input wherever it is found (a full disk on writing)
            fail(str(exc))

    wrapper.__signature__ = inspect.Signature(own + shared)  # type: ignore[attr-defined]
    wrapper.__annotations__ = {p.name: p.annotation for p in own + shared}
    return wrapper


#: The parameters that do not change what a command writes: its outputs, how it is run, and
#: ``--set`` (which the result's config records).
_NOT_REQUESTED = {"output", "plot", "resume", "set_", "full"}


@contextmanager
def executing(
    executor: str | None,
    scheduler: str | None,
    workers: int | None,
    progress=None,
    lost_hint: str = "",
) -> Iterator[None]:
    """The command's ``--executor``, ``--scheduler`` and ``--workers`` in force (checked as
    bad input first) for the block; the executors it opens are stopped at its end. A lost
    executor is an error (exit 1) that names it, followed by ``lost_hint``; so is a scheduler
    that never answered (what ``validate`` accepts stays accepted: an address is checked, not
    whether a server listens there)."""
    from .. import execution

    try:
        execution.check_settings(executor, scheduler, workers, dashes="--")
    except ValueError as exc:
        fail(str(exc))
    executor = "dask" if scheduler is not None and executor is None else executor
    with execution.use(executor, scheduler, workers, progress=progress):
        try:
            yield
        except execution.SchedulerUnreachable as exc:  # the machine's state, not the input's
            err.print(f"error: {exc}", soft_wrap=True)
            raise typer.Exit(code=1) from None
        except execution.ExecutionLost as exc:
            err.print(f"error: {exc}{lost_hint}", soft_wrap=True)
            raise typer.Exit(code=1) from None


#: ``-v``: what each step did and how long it took, on stderr.
VERBOSE = [False]


def verbose_info(message: str) -> None:
    if VERBOSE[0]:
        err.print(f"info: {message}", soft_wrap=True)


def _show_version(value: bool) -> None:
    if value:
        from .._version import __version__

        out.print(f"suspopt {__version__}")
        raise typer.Exit()


@app.callback()
def _main(
    version: bool = typer.Option(
        False, "--version", callback=_show_version, is_eager=True, help="print the version and exit"
    ),
    quiet: bool = typer.Option(
        False,
        "-q",
        "--quiet",
        help="print nothing but warnings and errors (no tables, no progress)",
    ),
    verbose: bool = typer.Option(
        False,
        "-v",
        "--verbose",
        help="also print, on stderr, what each step did and how long it took",
    ),
) -> None:
    """Simulate, optimise and select vehicle and seat suspensions from YAML."""
    from .. import _notices
    from ..memory import reuse_memory
    from .notices import notices

    _notices.listen(notices)  # the compiled kernel's first compile, auto's fallback
    out.quiet = quiet
    VERBOSE[0] = verbose and not quiet
    reuse_memory()  # a command's repeated batches reuse their memory (suspopt.memory)


def against_baseline(names, values, baseline, feasible: bool) -> str:
    """``against the config's own design (feasible): f1 -13.4 %, ...``: each objective of
    ``names`` in ``values`` as a change from ``baseline`` (one that cannot be computed left
    out: a baseline of 0 or not finite, or a change beyond the floating-point range, as a
    damaged file's /baseline can give), the config's design ``feasible`` or not; a baseline
    of the optimiser's penalty values is a design that failed to simulate."""
    import math

    from ..optimisation.problem import PENALTY

    old_values = [float(old) for old in baseline]
    if any(old >= PENALTY for old in old_values):
        return "the config's own design failed to simulate (diverged or gave NaN)"
    changes = []
    for name, new, old in zip(names, values, old_values):
        if old == 0 or not math.isfinite(old):
            continue
        change = (float(new) - old) / abs(old) * 100.0  # (Python floats: inf, no warning)
        if math.isfinite(change):
            changes.append(f"{name} {change:+.3g} %")
    state = "feasible" if feasible else "infeasible"
    return f"against the config's own design ({state}): " + (
        ", ".join(changes) or "no change can be computed"
    )


def full_option():
    """``--full``: print long tables whole (:func:`show_table`)."""
    from .summary import LONG_TABLE, SUMMARY_LINES

    return typer.Option(
        False,
        "--full",
        help=f"print long tables whole (without it, a table of more than {LONG_TABLE} rows "
        f"or {SUMMARY_LINES} lines shows its first rows and columns and counts the rest; "
        "the whole table is in the output file)",
    )


def show_table(table: Table, keys: int = 1, full: bool = True, where: Path | None = None) -> None:
    """Print ``table``; when it is wider than the terminal (a CI log's 80 columns), as several
    tables of the columns that fit, each with the first ``keys`` columns again, so that no
    number is cut or broken across lines. Unless ``full``, a long table is summarised: its
    first rows and parts and a line counting the rest, saying that ``--full`` prints them
    and that the whole table is in ``where`` (:mod:`suspopt.cli.summary`)."""
    from . import summary

    shown = table if full else summary.top_rows(table)
    parts = _parts(shown, keys)
    kept = parts if full else summary.parts_that_fit(parts)
    for part in kept:
        out.print(part)
    if not full:
        line = summary.rest_line(table, shown, parts[len(kept) :], where, keys)
        if line is not None:
            out.print(line)


def _parts(table: Any, keys: int) -> list[Any]:  # (tables of new_table: with their cells)
    """``table``, or the tables of the columns that fit the terminal (:func:`show_table`)."""

    def needs(j: int) -> int:  # column j's widest cell and the border and padding
        return (
            max(len(str(c)) for c in [table.columns[j].header, *(row[j] for row in table.cells)])
            + 3
        )

    width, count = out.width, len(table.columns)
    if 1 + sum(needs(j) for j in range(count)) <= width or count <= keys + 1:
        return [table]
    key, rest = list(range(keys)), list(range(keys, count))
    base = 1 + sum(needs(c) for c in key)
    groups: list[list[int]] = []
    current: list[int] = []
    used = base
    for column in rest:
        if current and used + needs(column) > width:
            groups.append(current)
            current, used = [], base
        current.append(column)
        used += needs(column)
    groups.append(current)
    title = str(table.title or "")
    parts = []
    for i, group in enumerate(groups, start=1):
        part = new_table(f"{title} ({i} of {len(groups)})" if title else None)
        for j in key + group:
            part.add_column(table.columns[j].header, justify=table.columns[j].justify)
        for row, kept in zip(table.cells, table.rows):  # (and where a section ends)
            part.add_row(*(row[j] for j in key + group), end_section=kept.end_section)
        parts.append(part)
    return parts


def plain_helps(typer_app: typer.Typer) -> None:
    """Make the help texts of ``typer_app``'s commands print as written. Typer's help markup
    keeps a docstring's line breaks, which then break the terminal's own wrapping, and reads
    ``[...]`` as a style and drops it (``pip install 'suspopt[report]'`` came out without its
    extra). Each docstring paragraph becomes one line, and every ``[`` of a docstring or an
    argument's help is escaped."""
    import re

    escape = re.compile(r"(?<!\\)\[")  # (once: a second call changes nothing)
    for command in typer_app.registered_commands:
        if command.callback is None:
            continue
        if command.help is None:
            paragraphs = inspect.cleandoc(command.callback.__doc__ or "").split("\n\n")
            command.help = "\n\n".join(" ".join(p.split()) for p in paragraphs)
        command.help = escape.sub(r"\\[", command.help)
        for parameter in inspect.signature(command.callback).parameters.values():
            info = parameter.default
            if isinstance(getattr(info, "help", None), str):
                info.help = escape.sub(r"\\[", info.help)


def fail(message: str) -> None:
    """Report bad input in one line and exit with code 2."""
    err.print("error: " + " ".join(str(message).split()), soft_wrap=True)
    raise typer.Exit(code=2)


def set_memory_limit(max_memory: str | None) -> None:
    """Apply ``--max-memory``."""
    from ..memory import parse_size, set_limit

    try:
        set_limit(None if max_memory is None else parse_size(max_memory))
    except ValueError as exc:
        fail(f"--max-memory: {exc}")


def claim_output(
    stack: ExitStack,
    path: Path | None,
    force: bool,
    option: str = "-o",
    inputs: Sequence[tuple[str, Path]] = (),
    guard=None,
) -> None:
    """Check an output (not one of the command's ``inputs``: ``(option, path)`` pairs) and
    hold its writer's lock for the rest of the command (:func:`suspopt.io.claim`, with
    ``guard``: what it may replace); what a killed run had left beside it is said at once
    (:func:`say_io_notes`)."""
    from ..io import claim

    if path is None:
        return
    try:
        stack.enter_context(claim(path, force, option, inputs, command=command_line(), guard=guard))
    except ConfigError as exc:
        fail(str(exc))
    finally:
        say_io_notes()


def check_suffix(path: Path | None, kind: str, option: str = "-o") -> None:
    """Bad input when the output ``path`` does not end in a suffix of ``kind``
    (:func:`suspopt.replacing.check_suffix`: ``-o out.csv`` for an HDF5 writer)."""
    from ..replacing import check_suffix as check

    if path is None:
        return
    try:
        check(path, kind, option)
    except ConfigError as exc:
        fail(str(exc))


def say_io_notes() -> None:
    """Print, on stderr, a ``note: ...`` line for each lock and temporary files of a killed
    run that the outputs' writers removed (:func:`suspopt.locks.take_notes`)."""
    locks = sys.modules.get("suspopt.locks")  # (not imported: nothing was written or claimed)
    if locks is None:
        return
    for note in locks.take_notes():
        err.print(f"note: {note}", soft_wrap=True)


def read_config(path: Path):
    from ..config import load_config

    try:
        return load_config(path)
    except ConfigError as exc:
        fail(str(exc))


def command_line() -> str:
    return "suspopt " + " ".join(shlex.quote(a) for a in sys.argv[1:])
