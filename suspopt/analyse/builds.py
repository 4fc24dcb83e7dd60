"""``suspopt analyse builds PARETO.h5 [--samples 100] [--tolerance 10] [--tolerance NAME=T]
[--seed S] [--distribution uniform|normal] [--pick NAMES] [--batch NAME,NAME]``: a front's
designs as many parts built to their tolerances at once.

``analyse tolerances`` moves one design variable at a time to the edge of its band; a built
suspension has every part off at once, by an amount nobody chose. This analysis builds each
design of the front ``--samples`` times: every design variable of every build is its
design's value times ``1 + u t/100``, ``u`` drawn from [-1, 1] independently for each
variable, design and build (``t`` the variable's tolerance [%], as ``analyse
tolerances`` takes it: :func:`!.tolerances.variable_tolerances`): uniformly, or with
``--distribution normal`` from a normal distribution of standard deviation 1/3 cut at ±1
(the band is ±3 σ: a process of capability 1, its parts outside the band rejected), by
the inverse of its distribution function. All builds of all designs are evaluated under
the stored config in one call (:func:`suspopt.choosing.selection.evaluate_pareto`).
It reports, per design, the spread of each objective's change over its builds (5th to 95th
percentile, ``100 (f_built - f_stored)/f_stored``) and the share of builds that meet every
constraint. The thesis has no such analysis; it is ours.

Parts of one batch: the design variables the stored config gives one
``design_variables[i].batch`` name, or ``--batch NAME,NAME`` names together (repeatable;
``--batch none``: every variable alone), are off alike in every build: they take the offset
``u`` drawn for the first of them, each within its own band (two dampers made in one
batch, off by the same fraction of their tolerance). The other variables' draws are those
of a run without batches, bit for bit. Which of the two a real process is lies between:
the two runs bound it.

Choices: a uniform draw by default, since a tolerance band says where a part may lie and
nothing of how often (the normal one narrows the spread, as a capable process does);
variables drawn independently unless they are of one batch. A
value the draw would take outside what its config field accepts is held at the field's
limit, and the report says how many (as ``analyse tolerances`` does). Each design's draws
come from a stream of its own, ``numpy.random.default_rng([seed, the 64 bits of each of its
values])`` (:func:`design_key`), ``seed`` = ``--seed``, by default the stored config's
``optimiser.seed``: the same seed gives a design the same builds bit for bit, whether the
whole front is built or only that design is (``--pick``), in any order and however the
batch is split, since they are drawn before any is evaluated. A failed simulation of a
build (NaN objectives) counts as not feasible and is left out of the percentiles.

``--pick knee,best_f1,...`` builds only those designs (names or row numbers, as ``simulate
--pick`` takes them, from an optimise, kesort or analyse file:
:func:`suspopt.choosing.picks.read_front`): the file's ``/pareto`` then holds the picked designs,
their picks by name and ``source_row``.

The file's layout is declared once, in :data:`suspopt.formats.BUILDS`. Its
``contribution`` is the share of an objective's variance over a design's builds that goes
with a variable: their squared correlation (the variables are drawn independently, so it is
the share a linear fit gives each).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, replace
from functools import cached_property
from pathlib import Path

import numpy as np

from ..choosing.builds_file import feasible_builds
from ..choosing.picks import read_front
from ..choosing.selection import DesignSet, ParetoSet, evaluate_pareto
from ..config.optimise import batches as config_batches
from ..design_ids import front_ids, id_marks
from ..errors import ConfigError
from ..formats import BUILDS
from ..io import atomic_h5, put
from ..params import MAX_SWEEP_DESIGNS
from .cells import (
    NOT_COMPUTED,
    NOT_COMPUTED_NOTE,
    failed_stored_note,
    percent,
    stored_cells,
    stored_failed,
    stored_reference,
)
from .pseudo import is_comfort, table_designs, write_stored_front
from .registry import KINDS, Analysis, Kind, Report, analysis, relative_change
from .tolerances import (
    Tolerances,
    bands,
    inside,
    known_variable,
    variable_limits,
    variable_tolerances,
)

__all__ = [
    "SAMPLES",
    "Builds",
    "variable_batches",
    "draw_builds",
    "builds",
    "write_builds",
    "run_builds",
    "feasible_builds",
]

#: The default number of builds of each design.
SAMPLES = 100
#: The percentiles the report and the file give [%].
PERCENTILES = (5.0, 50.0, 95.0)
#: How a build's variable is drawn within its band (module docstring), as the report says it.
DRAWS = {"uniform": "uniform draw", "normal": "normal draw (σ = t/3, cut at ±t)"}
DISTRIBUTIONS = tuple(DRAWS)
#: The fewest builds the report says what drives a spread from.
DRIVER_SAMPLES = 10


@dataclass(frozen=True)
class Builds:
    """The builds of a stored front: ``X (N, D, n)`` built designs, ``F (N, D, m + s)``
    their main then supplementary objectives (NaN where the simulation failed),
    ``feasible`` and ``failed (N, D)``, ``G (N, D, k)`` their constraints (``g <= 0`` is
    met; ``constraint_names``, ``constraint_units``); ``stored`` the front's designs under
    the stored config (``names``, ``units``), ``held (n,)`` how many values of each variable
    were held at its field's limit; ``tolerance (n,)`` [%], ``seed``, ``distribution`` and
    ``batches`` ((name, the indices of its variables), :func:`!variable_batches`) as drawn."""

    pareto: ParetoSet
    stored: DesignSet
    X: np.ndarray
    F: np.ndarray
    feasible: np.ndarray
    failed: np.ndarray
    held: np.ndarray
    tolerance: np.ndarray
    seed: int
    distribution: str
    G: np.ndarray
    constraint_names: tuple[str, ...]
    constraint_units: tuple[str, ...]
    batches: tuple[tuple[str, tuple[int, ...]], ...] = ()

    @property
    def m(self) -> int:
        return self.pareto.F.shape[1]

    @property
    def batch_of(self) -> list[str]:
        """(n,) the batch of each design variable (its name; "" for a variable drawn
        alone)."""
        out = [""] * self.X.shape[-1]
        for name, columns in self.batches:
            for j in columns:
                out[j] = name
        return out

    @property
    def reference(self) -> np.ndarray:
        """(D, m + s): the file's main objectives, then the re-simulated supplementary ones;
        NaN for a design that failed (:func:`.cells.stored_reference`)."""
        return stored_reference(self.pareto.F, self.stored)

    @property
    def stored_failed(self) -> np.ndarray:
        """(D,) the stored designs that failed: their changes cannot be computed."""
        return stored_failed(self.pareto.F, self.stored)

    @cached_property
    def change(self) -> np.ndarray:
        """(N, D, m + s) change of each objective of each build [%]."""
        return relative_change(self.F, self.reference)

    @cached_property
    def contributions(self) -> np.ndarray:
        """(D, n, m + s): for each design, the share of each objective's variance over its
        builds that goes with each design variable: their squared correlation over the
        builds that did not fail (the variables are drawn independently, so this is the
        share a linear fit gives each; what no variable explains alone, through a curved or
        joint effect, is left over). The variables of one batch are drawn as one, so each
        of them has the batch's share. NaN where a variable or an objective did not vary."""
        ok = ~self.failed[..., None]  # (N, D, 1)
        count = ok.sum(axis=0)  # (D, 1)
        with np.errstate(all="ignore"):  # (objectives of 1e160 and up: their square is inf)
            x = np.where(ok, self.X, 0.0)
            y = np.where(ok, self.F, 0.0)
            x = np.where(ok, x - x.sum(axis=0) / count, 0.0)  # (N, D, n), centred
            y = np.where(ok, y - y.sum(axis=0) / count, 0.0)  # (N, D, M)
            cov = np.einsum("kdi,kdj->dij", x, y)
            var_x, var_y = (x * x).sum(axis=0), (y * y).sum(axis=0)
            r2 = cov**2 / (var_x[:, :, None] * var_y[:, None, :])
        return np.where(np.isfinite(r2), r2, np.nan)

    def percentiles(self, values: np.ndarray) -> np.ndarray:
        """(3, D, ...) the :data:`PERCENTILES` of ``values (N, D, ...)`` over the builds (NaN
        for a design all of whose builds failed)."""
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # (all builds failed: NaN)
            return np.nanpercentile(values, PERCENTILES, axis=0)


def _checked_samples(samples: int | None, designs: int) -> int:
    """``--samples`` as a whole number from 1 on, at most :data:`MAX_SWEEP_DESIGNS` builds
    in all."""
    N = SAMPLES if samples is None else samples
    if isinstance(N, bool) or not isinstance(N, (int, np.integer)) or N < 1:
        raise ConfigError(f"--samples {N!r}: give a whole number of builds from 1 on")
    if int(N) * designs > MAX_SWEEP_DESIGNS:
        raise ConfigError(
            f"--samples {N}: {int(N) * designs} builds of {designs} designs, more than "
            f"{MAX_SWEEP_DESIGNS}; give fewer samples"
        )
    return int(N)


def _checked_seed(seed: int | None, pareto: ParetoSet) -> int:
    """``--seed``, by default the stored config's ``optimiser.seed``."""
    if seed is None:
        optimiser = pareto.config().optimiser
        if optimiser is None:
            raise ConfigError(
                f"{pareto.path}: the stored config has no optimiser.seed: give --seed"
            )
        return int(optimiser.seed)
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)):
        raise ConfigError(f"--seed {seed!r}: give a whole number from 0 to 2**63 - 1")
    if not 0 <= seed <= 2**63 - 1:
        raise ConfigError(f"--seed {seed}: give a whole number from 0 to 2**63 - 1")
    return int(seed)


def design_key(seed: int, x: np.ndarray) -> list[int]:
    """The entropy of the stream a design's builds are drawn from: ``seed`` and the 64 bits
    of each of its variables' values ``x (n,)`` (physical, as the file stores them)."""
    return [int(seed), *np.ascontiguousarray(x, dtype=np.float64).view(np.uint64).tolist()]


def variable_batches(
    pareto: ParetoSet, batch: Sequence[str] | str | None = None
) -> tuple[tuple[str, tuple[int, ...]], ...]:
    """The batches of the design variables of ``pareto``: (name, the columns of its
    variables) each. ``batch`` None: the stored config's ``design_variables[i].batch``;
    else ``--batch`` as given, one ``"NAME,NAME[,...]"`` per batch (named by its variables
    joined with ``+``), or ``"none"``: every variable drawn alone. ConfigError naming the
    option (or the file) for a name that is no design variable, a variable in two batches
    or a batch of one."""
    if batch is None:
        where = f"{pareto.path}: the stored config's design_variables"
        variables = pareto.config().design_variables
        groups = [
            (name, [variables[i].label for i in members], where)
            for name, members in config_batches(variables).items()
        ]
    else:
        given = [batch] if isinstance(batch, str) else list(batch)
        if [str(g).strip() for g in given] == ["none"]:
            return ()
        groups = []
        for text in given:
            names = [part.strip() for part in str(text).split(",")]
            if "none" in names or "" in names:
                raise ConfigError(
                    f"--batch {text!r}: give the names of two design variables or more, "
                    f"comma-separated (or none alone: every variable drawn alone)"
                )
            groups.append(("+".join(names), names, f"--batch {text}"))
    out: list[tuple[str, tuple[int, ...]]] = []
    seen: dict[str, str] = {}
    for name, members, where in groups:
        columns = tuple(known_variable(pareto, label, where) for label in members)
        for label in members:
            if label in seen:
                raise ConfigError(f"{where}: {label} is in two batches ({seen[label]}, {name})")
            seen[label] = name
        if len(members) < 2:
            raise ConfigError(
                f"{where}: batch {name!r} has one design variable: a batch is two or more"
            )
        out.append((name, columns))
    return tuple(out)


def draw_builds(
    pareto: ParetoSet,
    samples: int,
    tolerance: float | np.ndarray,
    seed: int,
    distribution: str = "uniform",
    batches: Sequence[tuple[str, Sequence[int]]] = (),
) -> tuple[np.ndarray, np.ndarray]:
    """``samples`` builds of every design of ``pareto`` (module docstring), each variable
    within ``tolerance`` [%] (one for all, or ``(n,)`` one each): ``X (N, D, n)`` and how
    many values of each variable were held at its field's limit ``(n,)``. Each
    design's offsets come from ``default_rng(design_key(seed, x))``, ``(N, n)`` in one call:
    the first N of a longer run are those of a run of N. The variables of one of
    ``batches`` ((name, columns), :func:`!variable_batches`) take the offset drawn for the
    first of them, as a fraction of each one's own band; the other variables' draws are
    those of a run without batches, bit for bit."""
    shape = (samples, pareto.X.shape[1])
    # one stream per design, keyed by its values: its builds are the same whichever front,
    # pick or order it is built in (a loop over random streams, not over simulations)
    streams = [np.random.default_rng(design_key(seed, x)) for x in pareto.X]
    if distribution == "uniform":
        u = np.stack([rng.uniform(-1.0, 1.0, shape) for rng in streams], axis=1)
    else:  # normal, sigma 1/3, cut at ±1: the inverse of its distribution function
        from scipy.special import ndtr, ndtri

        low = ndtr(-3.0)
        drawn = np.stack([rng.random(shape) for rng in streams], axis=1)
        u = ndtri(low + drawn * (1.0 - 2.0 * low)) / 3.0
    for _, columns in batches:  # (made together: off alike)
        u[..., list(columns[1:])] = u[..., [columns[0]]]
    wanted = pareto.X * (1.0 + u * tolerance / 100.0)
    X = np.empty_like(wanted)
    for j, limits in enumerate(variable_limits(pareto)):  # (per variable: its field's range)
        X[..., j] = inside(wanted[..., j], limits)
    return X, (wanted != X).sum(axis=(0, 1))


def builds(
    pareto: ParetoSet,
    samples=SAMPLES,
    *,
    tolerance: Tolerances = None,
    seed=None,
    distribution=None,
    batch: Sequence[str] | str | None = None,
) -> Builds:
    """Draw and evaluate ``samples`` builds (int) of every design of ``pareto``, each design
    variable within its tolerance [%] (``tolerance`` as
    ``tolerances.variable_tolerances`` takes it), from the streams of ``seed`` (int;
    None: the stored config's ``optimiser.seed``), ``distribution`` ``"uniform"`` (None) or
    ``"normal"`` (module docstring), the variables of one batch off alike (``batch`` as
    :func:`!variable_batches` takes it)."""
    distribution = "uniform" if distribution is None else distribution
    if distribution not in DISTRIBUTIONS:
        raise ConfigError(
            f"--distribution {distribution!r}: give one of {', '.join(DISTRIBUTIONS)}"
        )
    t = variable_tolerances(pareto, tolerance)
    N = _checked_samples(samples, len(pareto.X))
    s = _checked_seed(seed, pareto)
    together = variable_batches(pareto, batch)
    X, held = draw_builds(pareto, N, t, s, distribution, together)
    stored = evaluate_pareto(pareto)
    flat = replace(pareto, X=X.reshape(-1, X.shape[-1]))
    built = evaluate_pareto(flat, pareto.config(), "builds")  # (one batch of N D designs)
    if built.names != stored.names:
        raise ConfigError(f"{pareto.path}: the builds' objectives are {', '.join(built.names)}")
    shape = X.shape[:2]
    F = np.where(built.failed[:, None], np.nan, built.F).reshape(shape + (-1,))
    return Builds(
        pareto=pareto,
        stored=stored,
        X=X,
        F=F,
        feasible=built.feasible.reshape(shape),
        failed=built.failed.reshape(shape),
        held=held,
        tolerance=t,
        seed=s,
        distribution=distribution,
        G=(np.zeros((len(F), 0)) if built.G is None else built.G).reshape(shape + (-1,)),
        constraint_names=built.constraint_names,
        constraint_units=built.constraint_units,
        batches=together,
    )


def write_builds(path: str | Path, b: Builds, command: str | None = None) -> Path:
    """Write ``b`` with the layout of the module docstring (atomically)."""
    p, m = b.pareto, b.m
    names, units = b.stored.names, b.stored.units
    with atomic_h5(path, p.config(), command, inputs=[("the input", p.path)]) as h5:
        write_stored_front(h5, BUILDS, "builds", p, b.stored)
        h5.attrs["seed"] = b.seed
        g = h5.create_group("builds")
        g.attrs["samples"] = len(b.X)
        g.attrs["distribution"] = b.distribution
        put(BUILDS, g, "X", b.X, list(p.var_units), names=p.var_names)
        put(BUILDS, g, "tolerance", b.tolerance)
        put(BUILDS, g, "batch", b.batch_of)
        put(BUILDS, g, "F", b.F[..., :m], units[:m], names=names[:m])
        if len(names) > m:
            put(BUILDS, g, "S", b.F[..., m:], units[m:], names=names[m:])
        put(BUILDS, g, "change", b.change[..., :m], ["%"] * m, names=names[:m])
        if b.constraint_names:
            k = list(b.constraint_names)
            put(BUILDS, g, "G", b.G, list(b.constraint_units), names=k)
        put(BUILDS, g, "feasible", b.feasible.astype(np.int8))
        put(BUILDS, g, "failed", b.failed.astype(np.int8))
        for key, values in zip(("F_p05", "F_median", "F_p95"), b.percentiles(b.F[..., :m])):
            put(BUILDS, g, key, values, units[:m], names=names[:m])
        put(BUILDS, g, "feasible_share", b.feasible.mean(axis=0))
        put(BUILDS, g, "contribution", b.contributions[..., :m], names=names[:m])
    return Path(path)


def _within(b: Builds) -> str:
    band = bands(b.pareto.var_names, b.tolerance)
    return f"{band} of its value" if band.startswith("±") else f"its tolerance ({band})"


def _alike(b: Builds) -> str:
    """What the report says of the batches: which variables are off alike."""
    if not b.batches:
        return ""
    each = "; ".join(
        " and ".join(b.pareto.var_names[j] for j in columns) for _, columns in b.batches
    )
    return f", the parts of one batch off alike ({each})"


def _designs(n: int) -> str:
    return f"{n} design" + ("" if n == 1 else "s")


def _spread(low: float, high: float, failed: bool) -> str:
    """A cell of the 5-95 % spread: "failed" where every build failed, :data:`NOT_COMPUTED`
    where the change cannot be computed."""
    if failed:
        return "failed"
    if math.isnan(low) or math.isnan(high):
        return NOT_COMPUTED
    return f"{percent(low, suffix='')} to {percent(high)}"


def _broken(b: Builds) -> str:
    """Which constraints the builds break, how often, and the design that breaks each most
    often."""
    broken = (b.G > 0) & ~b.failed[..., None]  # (N, D, k)
    parts = []
    for j, name in enumerate(b.constraint_names):
        if broken[..., j].any():
            share = broken[..., j].mean(axis=0)
            k = int(np.argmax(share))
            parts.append(
                f"{name} in {100 * broken[..., j].mean():.0f} % of all builds "
                f"(design {front_ids(b.pareto)[k]}: {100 * share[k]:.0f} %)"
            )
    return "constraints the builds break: " + ("; ".join(parts) if parts else "none")


def _drivers(b: Builds) -> str:
    """What drives each objective's spread: each variable's median share over the designs
    (:attr:`Builds.contributions`), largest first; from :data:`DRIVER_SAMPLES` builds on
    (the squared correlation of two unrelated quantities over N builds is about 1/(N - 1):
    1 over two builds)."""
    if len(b.X) < DRIVER_SAMPLES:
        return f"what drives each objective's spread: give {DRIVER_SAMPLES} builds or more to see"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # (nothing varied: NaN)
        share = np.nanmedian(b.contributions, axis=0)  # (n, M)
    label = list(b.pareto.var_names)
    for batch, columns in b.batches:  # (drawn as one: the batch is one driver)
        label[columns[0]] = batch
        share[list(columns[1:])] = np.nan
    parts = []
    for j, name in enumerate(b.stored.names):
        order = [i for i in np.argsort(-np.nan_to_num(share[:, j], nan=-1.0)) if share[i, j] >= 0]
        if order:
            each = ", ".join(f"{label[i]} {share[i, j]:.2f}" for i in order)
            parts.append(f"{name}: {each}")
    return (
        "what drives each objective's spread (squared correlation with each variable over "
        "the builds, median over the designs): " + ("; ".join(parts) if parts else "nothing varied")
    )


def _report(b: Builds, title: str) -> Report:
    p, m = b.pareto, b.m
    names, units = b.stored.names, b.stored.units
    low, _, high = b.percentiles(b.change)  # (D, m + s) each
    share = b.feasible.mean(axis=0)
    columns = ["design", "pick"] + [f"{n} [{u}]" for n, u in zip(names[:m], units[:m])]
    columns += [f"{n}: 5-95 % (change)" for n in names] + ["feasible builds"]
    picks, ids = table_designs(len(p.X), p.marks_by_row()), front_ids(p)
    lost, every = b.stored_failed, np.asarray(b.failed.all(axis=0), dtype=bool)  # (D,) each
    rows = [
        [ids[k], picked]
        + stored_cells(p.F[k], lost[k])
        + [_spread(lo, hi, every[k]) for lo, hi in zip(low[k], high[k])]
        + [f"{100 * share[k]:.0f} %"]
        for k, picked in picks
    ]
    shown = {cell for row in rows for cell in row}
    notes = [
        f"{len(b.X)} builds of each of {_designs(len(p.X))} of {p.path.name}: every design "
        f"variable off at once by a {DRAWS[b.distribution]} within {_within(b)} "
        f"(seed {b.seed}){_alike(b)}; change = (f_built - f_stored)/f_stored, its 5th to "
        f"95th percentile over the builds",
        *p.picked_note(),
        *b.stored.notes,
    ]
    if lost.any():
        notes.append(failed_stored_note(lost, ids))
    if NOT_COMPUTED in shown:
        notes.append(NOT_COMPUTED_NOTE)
    worst = [
        f"{name} {percent(high[k, j], '.3g')} (design {ids[k]})"
        for j, name in enumerate(names)
        if np.isfinite(high[:, j]).any()
        for k in [int(np.nanargmax(high[:, j]))]
    ]
    if worst:
        notes.append("largest 95th percentile of each objective's change: " + "; ".join(worst))
    k = int(np.argmin(share))
    notes.append(
        f"feasible builds: {100 * share[k]:.0f} % at the least (design {ids[k]}); "
        f"every build feasible in {int((share == 1).sum())} of {_designs(len(p.X))}"
    )
    notes.append(_broken(b))
    notes.append(_drivers(b))
    if b.failed.any():
        notes.append(f"{int(b.failed.sum())} of {b.failed.size} builds failed to simulate")
    notes += [
        f"{name}: {int(n)} value(s) held at the field's limit"
        for name, n in zip(p.var_names, b.held)
        if n
    ]
    return Report(title=title, columns=columns, rows=rows, notes=notes)


def plot_builds(b: Builds, path: str | Path, title: str) -> Path:
    """The stored front with each objective's 5th and 95th percentile over the builds, every
    build that did not fail as a faint dot beneath, and the design variables along it
    (:func:`suspopt.plots.pareto_fronts`)."""
    from .. import plots

    p, m = b.pareto, b.m
    low, _, high = b.percentiles(b.F[..., :m])
    stored = np.where(b.stored_failed[:, None], np.nan, p.F)  # (not the penalty values)
    curves = [(f"optimised ({p.path.name})", stored), ("builds: 5th percentile", low)]
    curves.append(("builds: 95th percentile", high))
    variables = [(n, u, p.X[:, j]) for j, (n, u) in enumerate(zip(p.var_names, p.var_units))]
    objectives = list(zip(b.stored.names[:m], b.stored.units[:m]))
    marks, comfort = id_marks(p, p.marks()), is_comfort(p.config())
    built = b.F[..., :m][~b.failed]  # (builds that did not fail, m)
    return plots.pareto_fronts(
        path, title, objectives, curves, variables, marks=marks, comfort=comfort,
        cloud=(f"builds ({len(built)})", built),
    )  # fmt: skip


def run_builds(
    source: Path,
    tolerance: Tolerances = None,
    samples: int | None = SAMPLES,
    seed: int | None = None,
    distribution: str | None = None,
    pick: Sequence[str] | None = None,
    batch: Sequence[str] | None = None,
) -> Analysis:
    """``suspopt analyse builds PARETO.h5 [--samples 100] [--tolerance 10] [--tolerance
    NAME=T] [--seed S] [--distribution uniform|normal] [--pick NAMES] [--batch NAME,NAME]``
    (module docstring); nothing written."""
    pareto = read_front(Path(source), pick)
    b = builds(
        pareto, samples, tolerance=tolerance, seed=seed, distribution=distribution, batch=batch
    )
    title = f"builds: {pareto.path.name} as built to {bands(pareto.var_names, b.tolerance)}"
    return analysis(
        "builds",
        title,
        b,
        pareto.config(),
        [pareto.path],
        lambda path, command: write_builds(path, b, command),
        lambda path: plot_builds(b, path, title),
        lambda: _report(b, title),
    )


KINDS["builds"] = Kind(
    run_builds, options=("tolerance", "samples", "seed", "distribution", "pick", "batch")
)
