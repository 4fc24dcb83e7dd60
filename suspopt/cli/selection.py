"""``kesort``: k-ε selection over Pareto files (see :mod:`suspopt.cli`)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import typer

from ..errors import ConfigError
from . import base
from .base import app, out

if TYPE_CHECKING:
    from rich.table import Table


def _floats(option: str, text: str) -> list[float]:
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        base.fail(f"{option} {text}: expected numbers separated by commas")
    return values


def _kesort_tables(sel) -> list[Table]:
    """The optimum of each case and of the pool (the form of Tables 6.2-6.3, 7.5-7.6), then
    the Pareto picks of the pool; each design named by its id (its row in the front it came
    from, ``NAME:ROW`` when pooled: :mod:`suspopt.design_ids`), which ``--pick`` takes."""
    import numpy as np

    from ..design_ids import selection_ids

    ids = selection_ids(sel)

    columns = [(f"{label} optimum", cs.chosen) for label, cs in sel.case_sorts.items()]
    columns.append(("optimum among all" if sel.case_sorts else "k-ε optimum", sel.chosen))
    columns += [(f"tie {n}", int(i)) for n, i in enumerate(sel.sort.ties[1:], start=2)]
    table = base.new_table(
        "k-ε optimum" + (" of each case and among all" if sel.case_sorts else "")
    )
    table.add_column("quantity")
    table.add_column("unit")
    rows = [i for _, i in columns]
    for title, _ in columns:
        table.add_column(title, justify="right")
    table.add_row("design", "", *(ids[i] for i in rows))
    table.add_row("case", "", *(str(sel.case[i]) for i in rows))
    if sel.case_sorts:
        table.add_row("k-ε level in its case", "1", *(f"{sel.level_in_case(i):.3f}" for i in rows))
    table.add_row(
        "k-ε level among all" if sel.case_sorts else "k-ε level",
        "1",
        *(f"{sel.sort.k_eps[i]:.3f}" for i in rows),
    )
    table.add_row(
        "k level among all" if sel.case_sorts else "k level",
        "1",
        *(f"{sel.sort.k[i]:.0f}" for i in rows),
    )
    for j, (name, unit) in enumerate(zip(sel.names, sel.units)):
        table.add_row(name, unit, *(f"{sel.F[i, j]:.4g}" for i in rows))
        if sel.F_as_built is not None:  # (what the sort ranked)
            built = f"{name}, as built (p{sel.as_built:g})"
            table.add_row(built, unit, *(f"{sel.F_as_built[i, j]:.4g}" for i in rows))
    for j, (name, unit) in enumerate(zip(sel.var_names, sel.var_units)):
        table.add_row(
            name, unit, *("-" if np.isnan(sel.X[i, j]) else f"{sel.X[i, j]:.5g}" for i in rows)
        )
    table.add_row("feasible", "", *("yes" if sel.feasible[i] else "no" for i in rows))
    title = "Pareto picks among all (Fig. 8.21: edges and knee)"
    if sel.F_as_built is not None:
        title += f", as built: the {sel.as_built:g}th percentiles they were picked on"
    picks = base.new_table(title)
    for col in ("pick", "design", "case", "k-ε level"):
        picks.add_column(col, justify="left" if col in ("pick", "case") else "right")
    for name, unit in zip(sel.names, sel.units):
        picks.add_column(f"{name} [{unit}]", justify="right")
    for key, i in sel.picks.items():
        picks.add_row(
            key,
            ids[i],
            str(sel.case[i]),
            f"{sel.sort.k_eps[i]:.3f}",
            *(f"{v:.4g}" for v in sel.F_sorted[i]),
        )
    return [table, picks]


def _optimum_bounds_note(sel) -> str | None:
    """Which design variables of the k-ε optimum lie at a bound of its own set's config
    (:func:`suspopt.optimisation.bounds.bounds_note`), or None (none does, or the config's
    design variables are not the set's)."""
    from ..optimisation.bounds import bounds_note

    design_set = sel.sets[int(sel.source[sel.chosen])]
    variables = design_set.config.design_variables
    if [v.label for v in variables] != list(design_set.var_names):
        return None
    row = int(sel.row[sel.chosen])
    return bounds_note(design_set.var_names, variables, design_set.X[[row]])


def _optimum_against_baseline(sel) -> str | None:
    """The k-ε optimum against the config's own design of its set (``/baseline`` of an
    optimise file), or None: the file has none, or the set was evaluated under another
    config (``--config``), to which the file's baseline does not belong."""
    from ..h5read import H5Reader

    design_set = sel.sets[int(sel.source[sel.chosen])]
    with H5Reader(design_set.source) as h5:
        if h5._node("baseline/F") is None or h5.text_attr("config") != design_set.config.text:
            return None
        F = h5.array("baseline/F", ndim=2)
        G = h5.array("baseline/G", ndim=2)
        names = h5.labels("baseline/F", "names", F.shape[1])
        X = h5.array("baseline/X", ndim=2)
        variables = h5.labels("baseline/X", "names", X.shape[1])
    if len(F) != 1 or len(G) != 1 or len(X) != 1:
        return None
    if any(name not in names for name in sel.names):  # (supplementary: not in the file)
        F, names = _with_supplementary(design_set.config, X, variables, F, names)
    mine = [j for j, name in enumerate(sel.names) if name in names]
    return base.against_baseline(
        [sel.names[j] for j in mine],
        sel.F[sel.chosen, mine],
        [F[0, names.index(sel.names[j])] for j in mine],
        bool((G <= 0).all()),
    )


def _with_supplementary(cfg, X, variables: list[str], F, names: list[str]):
    """The config's design ``X (1, n)`` (columns ``variables``) with its supplementary
    objectives evaluated under ``cfg`` beside its main ones ``F (1, m)``: (F, names)."""
    import numpy as np

    from ..optimisation.problem import Problem

    problem = Problem.from_config(cfg)
    if sorted(variables) != sorted(problem.var_names):
        return F, names
    ordered = X[:, [variables.index(name) for name in problem.var_names]]
    S = problem.evaluate(problem.to_search(ordered), return_values_of=["S"])
    return np.hstack([F, S]), names + problem.supplementary_names


def _builds_options(
    pareto: list[Path],
    builds: list[Path],
    least: float | None,
    as_built: float | None = None,
    config: list[Path] | None = None,
) -> float:
    """``--min-feasible-builds`` [%] (None: :data:`MIN_FEASIBLE_BUILDS`), checked with
    ``--builds`` (one per Pareto file) and ``--as-built`` (a percentile, with ``--builds``
    and without ``--config``: the builds were evaluated under each file's own config) before
    any design is evaluated."""
    import math

    if as_built is not None:
        if not builds:
            raise ConfigError("--as-built: give --builds too (the builds it takes a percentile of)")
        if not (math.isfinite(as_built) and 0 <= as_built <= 100):
            raise ConfigError(f"--as-built {as_built:g}: give a percentile from 0 to 100")
        if config:
            raise ConfigError(
                "--as-built: the builds were evaluated under each Pareto file's own config; "
                "--config evaluates the designs under another: give one or the other"
            )
    if not builds and least is not None:
        raise ConfigError("--min-feasible-builds: give --builds too (the builds it counts)")
    least = MIN_FEASIBLE_BUILDS if least is None else least
    if not (math.isfinite(least) and 0 <= least <= 100):
        raise ConfigError(f"--min-feasible-builds {least:g}: give a share from 0 to 100 %")
    if builds and len(builds) != len(pareto):
        raise ConfigError(
            f"--builds: give one per Pareto file, in their order ({len(pareto)}), not {len(builds)}"
        )
    return least


def _as_built(
    sets, pareto: list[Path], builds: list[Path], least: float, percentile: float | None = None
):
    """``sets`` with a design counted infeasible where fewer than ``least`` % of its builds
    (the ``analyse builds`` file of its Pareto file, ``builds[i]`` of ``pareto[i]``) are
    feasible and, with ``percentile``, sorted on that percentile of each objective over its
    builds (a design all of whose builds failed counted failed), and the notes that say so;
    ``sets`` and no note without ``builds``."""
    from dataclasses import replace

    import numpy as np

    from ..choosing.builds_file import as_built_objectives, feasible_builds

    if not builds:
        return sets, []
    shorts = [feasible_builds(b, p) < least / 100 for b, p in zip(builds, pareto)]
    notes = [
        f"{int(short.sum())} of {len(short)} designs have fewer than {least:g} % of their "
        f"builds feasible ({b}): counted infeasible"
        for short, b in zip(shorts, builds)
    ]
    sets = [replace(s, feasible=s.feasible & ~short) for s, short in zip(sets, shorts)]
    if percentile is None:
        return sets, notes
    for i, (b, p) in enumerate(zip(builds, pareto)):
        values = as_built_objectives(b, p, sets[i].names, percentile)
        lost = np.isnan(values).any(axis=1)
        sets[i] = replace(
            sets[i], F_as_built=values, as_built=percentile, failed=sets[i].failed | lost
        )
        if lost.any():
            notes.append(
                f"{int(lost.sum())} design(s) of {p} with no build that simulated ({b}): left out"
            )
    notes.append(
        f"sorted as built: each objective's {percentile:g}th percentile over each design's "
        f"builds ({', '.join(map(str, builds))}), kept in /kesort/F_as_built; /kesort/F "
        f"holds the nominal values, the ones simulate --pick reproduces"
    )
    return sets, notes


def _threshold_line(sort, label: str) -> str:
    if sort.P is None:
        how = "absolute ε"
    else:
        how = f"ε = P·max NF with P = {sort.P:.4g}" + (" (auto)" if sort.P_auto else "")
    tied = "" if sort.unique else f"; {len(sort.ties)} designs share the top level"
    return f"{label}: {how}, normalised by {sort.normalisation}{tied}"


#: The share of a design's builds that must be feasible [%] (``kesort --builds``): a design
#: that meets its constraints in 19 builds of 20.
MIN_FEASIBLE_BUILDS = 95.0

_BUILDS_HELP = (
    "the analyse builds file of each Pareto file, in their order (repeatable): a design with "
    "fewer feasible builds than --min-feasible-builds counts as infeasible"
)
_MIN_FEASIBLE_BUILDS_HELP = (
    "with --builds: the share of a design's builds that must be feasible, in % (default 95)"
)
_AS_BUILT_HELP = (
    "with --builds: sort and pick the designs on this percentile of each objective over "
    "their builds (95: how the worst 5 % of builds perform), not on their nominal values"
)
_EPS_HELP = (
    "absolute thresholds in the objectives' SI units: one value, or one per objective "
    "separated by commas"
)


@app.command()
@base.run_options
def kesort(
    pareto: list[Path] = typer.Argument(
        ..., help="Pareto HDF5 file(s) written by suspopt optimise"
    ),
    config: list[Path] = typer.Option(
        [],
        "--config",
        "-c",
        help="config whose objectives are evaluated (default: "
        "each file's own): once for every file, or once per file",
    ),
    label: list[str] = typer.Option(
        [],
        "--label",
        "-l",
        help="case label, once per file; files with the same "
        "label form one case (default: the config's or the file's name)",
    ),
    eps: str | None = typer.Option(None, "--eps", help=_EPS_HELP),
    P: str | None = typer.Option(
        None,
        "--P",
        "-P",
        help="ε = P·max NF (Eq 6.19, 7.13), or 'auto' (default): "
        "the smallest P on the --P-range grid that leaves one best design",
    ),
    P_range: str = typer.Option("0.01,1.0", "--P-range", help="LOW,HIGH of P for auto"),
    P_step: float = typer.Option(0.01, "--P-step", help="grid step of P for auto"),
    normalise: str = typer.Option("max", "--normalise", help="max (Eq 7.12) or minmax"),
    keep_infeasible: bool = typer.Option(
        False, "--keep-infeasible", help="sort infeasible designs too"
    ),
    builds: list[Path] = typer.Option([], "--builds", help=_BUILDS_HELP),
    min_feasible_builds: float | None = typer.Option(
        None, "--min-feasible-builds", help=_MIN_FEASIBLE_BUILDS_HELP
    ),
    as_built: float | None = typer.Option(None, "--as-built", help=_AS_BUILT_HELP),
    output: Path | None = typer.Option(None, "-o", "--output", help="HDF5 file for /kesort"),
    plot: Path | None = typer.Option(
        None, "--plot", help="figure of the k-ε levels over the front (.png or .svg)"
    ),
    full: bool = base.full_option(),
    *,
    run: base.RunOptions,
) -> None:
    """Choose the optimum of Pareto sets by k-ε optimality (Eq 6.10-6.12).

    Supplementary objectives are re-simulated in one batch."""
    inputs = [("the input", p) for p in pareto] + [("--config", c) for c in config]
    inputs += [("--builds", b) for b in builds]
    with run.outputs(output, plot, inputs=inputs):
        _kesort(
            pareto, config, label, eps, P, P_range, P_step, normalise, keep_infeasible, output,
            plot, (builds, min_feasible_builds, as_built), full,
        )  # fmt: skip


def _kesort(
    pareto, config, label, eps, P, P_range, P_step, normalise, keep_infeasible, output, plot,
    by_builds, full=True,
) -> None:  # fmt: skip
    import importlib.util

    from ..choosing.kepsilon import check_options
    from ..choosing.selection import load_design_sets, select, write_selection

    if plot is not None:
        if plot.suffix.lower() not in (".png", ".svg"):
            base.fail(f"--plot {plot}: give a .png or .svg file")
        if importlib.util.find_spec("matplotlib") is None:
            base.fail("--plot needs matplotlib, a dependency of suspopt: pip install matplotlib")
    if P is not None and P != "auto":
        P = _floats("--P", P)[0]
    P_lo_hi = _floats("--P-range", P_range)
    if len(P_lo_hi) != 2:
        base.fail(f"--P-range {P_range}: expected LOW,HIGH")
    eps_values = None if eps is None else _floats("--eps", eps)
    options = dict(P=P, normalise=normalise, P_range=tuple(P_lo_hi), P_step=P_step)
    try:
        check_options(eps_values, **options)
    except ValueError as exc:  # (named as the options are on this command line)
        message = str(exc).replace("P_range", "--P-range").replace("P_step", "--P-step")
        base.fail(f"kesort options: {message}")
    try:
        builds, least, percentile = by_builds
        least = _builds_options(pareto, builds, least, percentile, config)
        sets = load_design_sets(pareto, config, label)
        sets, built = _as_built(sets, pareto, builds, least, percentile)
        selection = select(sets, eps_values, feasible_only=not keep_infeasible, **options)
    except ConfigError as exc:
        base.fail(str(exc))
    if output is not None:
        write_selection(output, selection, command=base.command_line())
    if plot is not None:
        from ..plots import plot_kesort

        plot_kesort(selection, plot)
    for table, keys in zip(_kesort_tables(selection), (2, 3)):
        base.show_table(table, keys, full, output)
    for label_, cs in selection.case_sorts.items():
        out.print(_threshold_line(cs.sort, label_))
    out.print(
        _threshold_line(selection.sort, "all" if selection.case_sorts else selection.cases[0])
    )
    for note in [*built, *selection.notes]:
        out.print(f"note: {note}")
    against = _optimum_against_baseline(selection)
    if against is not None:
        nominal = "" if selection.as_built is None else " (its nominal values)"
        out.print(f"the k-ε optimum{nominal} {against}")
    bounds = _optimum_bounds_note(selection)
    if bounds is not None:
        out.print(f"note: the k-ε optimum is {bounds}")
    for path in (output, plot):
        if path is not None:
            out.print(f"wrote {path}")
