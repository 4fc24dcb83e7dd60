"""Choose designs from Pareto sets: the run behind ``suspopt kesort`` (Sec 6.2.2, 7.2.2).

1. :func:`read_pareto` reads a ``suspopt optimise`` file (``/pareto/X`` physical values,
   ``/pareto/F``, ``/pareto/G`` with ``names`` and ``units``; root attribute ``config``, the
   YAML text: :data:`suspopt.formats.OPTIMISE`).
2. :func:`evaluate_pareto` gives every design its objectives, main then supplementary, under
   a config: the file's own, or another one with the same design variables (the same designs
   with a CDF controller: the thesis's "pseudo Pareto fronts", Sec 7.2.2, Fig. 7.4b). When
   that needs a simulation (supplementary objectives, another config) the designs are
   re-simulated in ONE batch through :meth:`suspopt.Problem.evaluate`, the optimiser's own
   objective code; otherwise the file's ``F`` and ``G`` are used as they are.
3. :func:`!select` pools the sets (Fig. 7.6), keeps the case each design came from, drops the
   designs whose simulation failed (and, unless asked, the infeasible ones), sorts the pool
   and each case alone by k-ε optimality (:func:`!suspopt.choosing.kepsilon.kesort`; Fig. 7.5: the
   optimum of each case, Fig. 7.6: the optimum among all; each sort normalises over its own
   designs, Eq 7.11-7.12) and takes the Pareto-theory picks (:func:`~suspopt.choosing.kepsilon.pareto_picks`).
4. :func:`write_selection` writes ``/kesort`` atomically (:func:`suspopt.io.atomic_h5`).

A *case* is a label: the sets of several files carry one label to form one case (Ch. 6 Part A
pools the optima of C1-C4).

The file's layout is declared once, in :data:`suspopt.formats.KESORT` (the docs' format
page is made from it).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from ..config import Config, ConfigError, load_config
from ..config.loader import load_config_text
from ..design_ids import picked_note, selection_ids
from ..errors import require
from ..files import listed
from ..formats import KESORT
from ..io import atomic_h5, put, write_attrs
from ..optimisation.problem import PENALTY, Problem
from .kepsilon import KEpsilonSort, kesort, pareto_picks

__all__ = [
    "ParetoSet",
    "DesignSet",
    "CaseSort",
    "Selection",
    "read_pareto",
    "evaluate_pareto",
    "load_design_sets",
    "select",
    "write_selection",
]

_FAILED = "simulation_failed"
_AGREE = 1e-6  # relative: re-simulated main objectives against the file's


@dataclass(frozen=True)
class ParetoSet:
    """A Pareto set as ``suspopt optimise`` wrote it: ``X (N, n)`` physical values,
    ``F (N, m)``, ``G (N, k)``, their names and units, and the config's YAML text.

    Designs picked from a file (:func:`suspopt.choosing.picks.read_front`) have ``picked``, each
    pick's name -> its row here, ``source_rows (N,)``, their rows in the file's table, and
    ``ids``, their ids (:func:`suspopt.design_ids.front_ids`); ``G`` is None where the file
    does not store their constraints (they are evaluated again)."""

    path: Path
    X: np.ndarray
    var_names: list[str]
    var_units: list[str]
    F: np.ndarray
    obj_names: list[str]
    G: np.ndarray | None
    constraint_names: list[str]
    config_text: str
    picked: dict[str, int] | None = None
    source_rows: np.ndarray | None = None
    obj_units: list[str] | None = None
    ids: tuple[str, ...] | None = None

    def config(self) -> Config:
        """The config the set was optimised with; errors point into the file
        (``PARETO.h5:config:LINE``), and relative paths resolve from the file's folder."""
        return load_config_text(self.config_text, self.path.with_name(self.path.name + ":config"))

    def plot(self, picks: dict[str, int] | None = None):
        """The front as ``suspopt optimise --plot`` draws it
        (:func:`!suspopt.plots.pareto_set_figure`), with the file's ``/history`` where it
        has one; ``picks`` (name -> row here) starred and named, default :meth:`marks`.
        Returns a matplotlib Figure."""
        from ..plots import pareto_set_figure

        return pareto_set_figure(self, self.marks() if picks is None else picks)

    def marks(self) -> dict[str, int]:
        """The designs a report names: the picks given (``--pick``; a row number names
        none), or the edges and knee of the front (:func:`suspopt.choosing.kepsilon.pareto_picks`)."""
        if self.picked is not None:
            return dict(self.picked)
        return pareto_picks(self.F, self.obj_names)

    def marks_by_row(self) -> dict[int, list[str]]:
        """:meth:`marks` by design: row -> the names it is marked by, in their order."""
        named: dict[int, list[str]] = {}
        for name, row in self.marks().items():
            named.setdefault(row, []).append(name)
        return named

    def picked_note(self) -> list[str]:
        """The report's note of the designs picked from the file, by id (none for a whole
        front): :func:`suspopt.design_ids.picked_note`."""
        return picked_note(self)


@dataclass(frozen=True)
class DesignSet:
    """The designs of one Pareto set with every objective evaluated under ``config``:
    ``F (N, m)`` main then supplementary objectives (``names``, ``units``); ``feasible (N,)``
    (every constraint ``g <= 0``); ``failed (N,)`` (the simulation diverged or gave NaN);
    ``resimulated``: whether the designs were simulated again; ``notes`` for the report;
    ``G (N, k)`` the constraints (``g <= 0`` is met; ``constraint_names``,
    ``constraint_units``); ``F_as_built (N, m)``, when given, the values :func:`!select`
    sorts on instead of ``F``: each objective's ``as_built`` percentile [%] over the
    design's builds (``kesort --as-built``)."""

    label: str
    source: Path
    config: Config
    X: np.ndarray
    var_names: list[str]
    var_units: list[str]
    F: np.ndarray
    names: list[str]
    units: list[str]
    feasible: np.ndarray
    failed: np.ndarray
    resimulated: bool
    notes: tuple[str, ...] = ()
    G: np.ndarray | None = None
    constraint_names: tuple[str, ...] = ()
    constraint_units: tuple[str, ...] = ()
    F_as_built: np.ndarray | None = None
    as_built: float | None = None


@dataclass(frozen=True)
class CaseSort:
    """The sort of one case alone: ``rows`` (its designs in the pool), ``sort`` over those
    rows, ``picks`` (indices in the pool)."""

    label: str
    rows: np.ndarray
    sort: KEpsilonSort
    picks: dict[str, int]

    @property
    def chosen(self) -> int:
        """The case's optimum, as an index in the pool."""
        return int(self.rows[self.sort.chosen])

    @property
    def ties(self) -> np.ndarray:
        return self.rows[self.sort.ties]


@dataclass(frozen=True)
class Selection:
    """The pooled designs (``N`` rows) and their sorts; see the module docstring for the
    meaning of each field (they are the ``/kesort`` datasets)."""

    F: np.ndarray
    names: list[str]
    units: list[str]
    X: np.ndarray
    var_names: list[str]
    var_units: list[str]
    case: np.ndarray
    cases: list[str]
    source: np.ndarray
    row: np.ndarray
    feasible: np.ndarray
    sets: list[DesignSet]
    sort: KEpsilonSort
    picks: dict[str, int]
    case_sorts: dict[str, CaseSort] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    F_as_built: np.ndarray | None = None
    as_built: float | None = None

    @property
    def F_sorted(self) -> np.ndarray:
        """The values the designs were sorted and picked on: ``F_as_built`` when given,
        else ``F``."""
        return self.F if self.F_as_built is None else self.F_as_built

    @property
    def chosen(self) -> int:
        return self.sort.chosen

    def level_in_case(self, i: int) -> float:
        """The k-ε level of design ``i`` (an index in the pool) in the sort of its case alone
        (its pooled level when there is one case)."""
        cs = self.case_sorts.get(self.case[i])
        if cs is None:
            return float(self.sort.k_eps[i])
        return float(cs.sort.k_eps[np.flatnonzero(cs.rows == i)[0]])


def read_pareto(path: str | Path) -> ParetoSet:
    """Read a ``suspopt optimise`` output; ConfigError naming the file and the dataset or
    attribute if it is not one (:class:`suspopt.h5read.H5Reader`)."""
    from ..h5read import H5Reader

    path = Path(path)
    data = {}
    with H5Reader(path) as h5:
        for key in ("X", "F", "G"):
            name = f"pareto/{key}"
            values = h5.array(name, ndim=2)
            data[key] = (
                values,
                h5.labels(name, "names", values.shape[1]),
                h5.labels(name, "units", values.shape[1]),
            )
        rows = {key: value[0].shape[0] for key, value in data.items()}
        if len(set(rows.values())) != 1:
            raise ConfigError(
                f"{path}: /pareto: X, F and G have {rows['X']}, {rows['F']} and {rows['G']} rows"
            )
        if rows["X"] == 0:
            raise ConfigError(f"{path}: /pareto/X: the set is empty")
        for key in ("X", "F", "G"):
            if not np.isfinite(data[key][0]).all():
                raise ConfigError(
                    f"{path}: /pareto/{key}: values must be finite (a failed "
                    f"design has the penalty values, never NaN)"
                )
        h5.objectives("pareto/F", data["F"][0], data["F"][1])
        if not h5.has_attr("config"):
            raise ConfigError(
                f"{path}: attribute 'config' (the YAML text) is missing; give --config"
            )
        text = h5.text_attr("config")
    (X, var_names, var_units), (F, obj_names, obj_units), (G, constraint_names, _) = (
        data["X"],
        data["F"],
        data["G"],
    )
    return ParetoSet(
        path,
        X,
        var_names,
        var_units,
        F,
        obj_names,
        G,
        constraint_names,
        text,
        None,
        None,
        obj_units,
    )


def evaluate_pareto(
    pareto: ParetoSet, cfg: Config | None = None, label: str | None = None
) -> DesignSet:
    """The designs of ``pareto`` with their main and supplementary objectives under ``cfg``
    (default: the file's own config), in one batch; see the module docstring."""
    own = cfg is None
    if cfg is None:
        cfg = pareto.config()
    problem = Problem.from_config(cfg)
    where = cfg.source if cfg.source is not None else "the config"
    if sorted(pareto.var_names) != sorted(problem.var_names):
        raise ConfigError(
            f"{pareto.path}: /pareto/X holds {', '.join(pareto.var_names)}; "
            f"{where} varies {', '.join(problem.var_names)}: the designs do not "
            f"fit its design_variables"
        )
    X = pareto.X[:, [pareto.var_names.index(n) for n in problem.var_names]]
    names = problem.obj_names + problem.supplementary_names
    units = problem.obj_units + problem.supplementary_units
    notes = []
    if own and pareto.obj_names != problem.obj_names:
        raise ConfigError(
            f"{pareto.path}: /pareto/F holds {', '.join(pareto.obj_names)} but "
            f"its config's main objectives are {', '.join(problem.obj_names)}"
        )
    resimulate = not own or bool(problem.supplementary_names) or pareto.G is None
    if resimulate:
        try:
            F, G, S = problem.evaluate(problem.to_search(X), return_values_of=["F", "G", "S"])
        except ConfigError as exc:  # a stored value the config's field cannot take
            raise ConfigError(f"{pareto.path}: /pareto/X: {exc}") from None
        if own:
            gap = _relative_gap(F, pareto.F)
            if gap > _AGREE:
                notes.append(
                    f"{pareto.path}: the re-simulated main objectives differ from the "
                    f"file's by up to {gap:.2g} (relative): the file was written by "
                    f"another version of the model"
                )
        F = np.hstack([F, S])
        constraint_names = problem.constraint_names
    else:
        assert pareto.G is not None  # (a set without stored constraints is evaluated again)
        F, G, constraint_names = pareto.F, pareto.G, pareto.constraint_names
    failed = ~np.isfinite(F).all(axis=1) | (F >= PENALTY).any(axis=1)
    same = list(constraint_names) == problem.constraint_names
    constraint_units = problem.constraint_units if same else [""] * len(constraint_names)
    if constraint_names and constraint_names[-1] == _FAILED:
        failed |= G[:, -1] > 0
        G, constraint_names, constraint_units = (
            G[:, :-1],
            constraint_names[:-1],
            constraint_units[:-1],
        )
    feasible = (G <= 0).all(axis=1) & ~failed
    default = cfg.source.stem if not own and cfg.source is not None else pareto.path.stem
    return DesignSet(
        label or default,
        pareto.path,
        cfg,
        X,
        problem.var_names,
        problem.var_units,
        F,
        names,
        units,
        feasible,
        failed,
        resimulate,
        tuple(notes),
        G,
        tuple(constraint_names),
        tuple(constraint_units),
    )


def _relative_gap(a: np.ndarray, b: np.ndarray) -> float:
    sound = (np.abs(b) < PENALTY).all(axis=1) & (np.abs(a) < PENALTY).all(axis=1)
    if not sound.any():
        return 0.0
    a, b = a[sound], b[sound]
    return float(np.max(np.abs(a - b) / np.maximum(np.abs(b), np.finfo(float).tiny)))


def load_design_sets(
    files: Sequence[str | Path], configs: Sequence[str | Path] = (), labels: Sequence[str] = ()
) -> list[DesignSet]:
    """Read and evaluate Pareto files for :func:`suspopt.select`, as ``suspopt kesort``
    takes them.

    Parameters
    ----------
    files : sequence of str or Path
        The ``optimise`` files (their ``/pareto``).
    configs : sequence of str or Path
        None (each file's own config), one (for every file) or one per file.
    labels : sequence of str
        None, or one per file; files with the same label form one case. Default: the
        config's name when one is given, else the file's, made unique (``name#2``), so
        that only labels you give merge files.

    Returns
    -------
    list of DesignSet
        Each file's designs with their main and supplementary objectives (SI units).
    """
    files = [Path(f) for f in listed(files)]
    configs, labels = listed(configs), [str(label) for label in listed(labels)]
    if not files:
        raise ConfigError("give at least one Pareto file")
    if len(configs) not in (0, 1, len(files)):
        raise ConfigError(
            f"--config: give one config for every file, or one per file "
            f"({len(files)}); got {len(configs)}"
        )
    if len(labels) not in (0, len(files)):
        raise ConfigError(f"--label: give one label per file ({len(files)}); got {len(labels)}")
    for lab in labels:
        if not lab or "/" in lab:
            raise ConfigError(f"--label {lab!r}: a label must be non-empty and have no '/'")
    per_file = list(configs) * len(files) if len(configs) == 1 else list(configs)
    loaded: dict[Path, Config] = {}
    sets = []
    for i, path in enumerate(files):
        cfg = None
        if per_file:
            cfg_path = Path(per_file[i])
            if cfg_path not in loaded:
                loaded[cfg_path] = load_config(cfg_path)
            cfg = loaded[cfg_path]
        sets.append(evaluate_pareto(read_pareto(path), cfg, labels[i] if labels else None))
    if not labels:
        seen: dict[str, int] = {}
        for i, s in enumerate(sets):
            seen[s.label] = seen.get(s.label, 0) + 1
            if seen[s.label] > 1:
                sets[i] = replace(s, label=f"{s.label}#{seen[s.label]}")
    return sets


def _common_objectives(sets: list[DesignSet]) -> tuple[list[str], list[str]]:
    """The objectives' names and units that every set shares; ConfigError where they differ."""
    names, units = sets[0].names, sets[0].units
    for s in sets[1:]:
        if sorted(s.names) != sorted(names):
            raise ConfigError(
                f"{s.source} ({s.label}): objectives {', '.join(s.names)} differ "
                f"from {sets[0].source} ({sets[0].label}): "
                f"{', '.join(names)}; pooled sets need the same ones"
            )
        for name, unit in zip(s.names, s.units):
            if unit != units[names.index(name)]:
                raise ConfigError(
                    f"{s.source} ({s.label}): objective {name} is in {unit}, in "
                    f"{units[names.index(name)]} for {sets[0].source}"
                )
    return names, units


def _kept(sets: list[DesignSet], feasible_only: bool) -> tuple[list[np.ndarray], list[str]]:
    """Which designs of each set are sorted (not failed, feasible if asked) and the notes
    saying what was left out."""
    notes = [note for s in sets for note in s.notes]
    keep = [~s.failed & (s.feasible if feasible_only else True) for s in sets]
    for s, k in zip(sets, keep):
        dropped_failed, dropped = int(s.failed.sum()), int(len(k) - k.sum())
        if dropped:
            why = f"{dropped_failed} failed simulation" if dropped_failed else ""
            if dropped > dropped_failed:
                why += (", " if why else "") + f"{dropped - dropped_failed} infeasible"
            notes.append(f"{s.source} ({s.label}): left out {dropped} of {len(k)} designs ({why})")
    return keep, notes


def select(
    sets: Sequence[DesignSet],
    eps=None,
    *,
    P=None,
    normalise: str = "max",
    feasible_only: bool = True,
    P_range=(0.01, 1.0),
    P_step: float = 0.01,
) -> Selection:
    """Pool ``sets`` and sort them by k-ε optimality (the module docstring): what ``suspopt
    kesort`` runs.

    Parameters
    ----------
    sets : sequence of DesignSet
        The design sets (:func:`suspopt.load_design_sets`); sets of one label form one
        case.
    eps : float or array_like, optional
        Absolute thresholds ``ε`` in the objectives' units (SI), one value or ``(m,)``.
    P : float or "auto", optional
        Threshold as a share [-] of each objective's largest normalised value (default
        ``auto``).
    normalise : {"max", "minmax"}
        Normalisation of the objectives before the thresholds.
    feasible_only : bool
        Leave out the infeasible designs (the failed ones are always left out).
    P_range : (float, float)
        The range [-] searched for ``P = "auto"``.
    P_step : float
        Step [-] of that search.

    Returns
    -------
    Selection
        The pooled designs, their sort, the sort of each case and the picks;
        :func:`suspopt.choosing.selection.write_selection` writes it.

    Raises
    ------
    suspopt.InputError
        When the sets have different objectives or no design is left to sort.
    """
    sets = [
        require(s, DesignSet, f"sets[{i}]", "from load_design_sets(paths)")
        for i, s in enumerate(listed(sets))
    ]
    if not sets:
        raise ConfigError("give at least one design set (load_design_sets)")
    names, units = _common_objectives(sets)
    _check_as_built(sets)
    var_names, var_units = [], []
    for s in sets:
        for n, u in zip(s.var_names, s.var_units):
            if n not in var_names:
                var_names.append(n)
                var_units.append(u)
    keep, notes = _kept(sets, feasible_only)
    cases = list(dict.fromkeys(s.label for s in sets))
    for label in cases:
        if not any(k.any() for s, k in zip(sets, keep) if s.label == label):
            files = ", ".join(str(s.source) for s in sets if s.label == label)
            hint = "" if not feasible_only else "; --keep-infeasible sorts infeasible ones too"
            raise ConfigError(
                f"{files}: no design of case {label} to sort (every one failed "
                f"or is infeasible){hint}"
            )
    pooled = _pooled(sets, keep, names, var_names)
    case = pooled["case"]
    F = pooled["F"] if pooled["F_as_built"] is None else pooled["F_as_built"]  # (what is sorted)
    options = dict(eps=eps, P=P, normalise=normalise, names=names, P_range=P_range, P_step=P_step)
    try:
        pool = kesort(F, **options)
        case_sorts = {}
        if len(cases) > 1:
            for label in cases:
                rows = np.flatnonzero(case == label)
                picks = {k: int(rows[v]) for k, v in pareto_picks(F[rows], names).items()}
                case_sorts[label] = CaseSort(label, rows, kesort(F[rows], **options), picks)
    except ValueError as exc:
        raise ConfigError(f"{', '.join(str(s.source) for s in sets)}: {exc}") from None
    return Selection(
        **pooled,
        names=names,
        units=units,
        var_names=var_names,
        var_units=var_units,
        sort=pool,
        picks=pareto_picks(F, names),
        cases=cases,
        case_sorts=case_sorts,
        sets=sets,
        notes=notes,
        as_built=sets[0].as_built,
    )


def _check_as_built(sets: list[DesignSet]) -> None:
    """Every set sorted as built at one percentile, with values of its ``F``'s shape, or
    none (ValueError naming the sets otherwise)."""
    if len({(s.F_as_built is None, s.as_built) for s in sets}) > 1:
        raise ConfigError(
            f"{', '.join(str(s.source) for s in sets)}: sorted as built (F_as_built) and "
            f"not, or at different percentiles: give every set the same"
        )
    for s in (s for s in sets if s.F_as_built is not None):
        shape, q = np.asarray(s.F_as_built).shape, s.as_built
        if shape != s.F.shape or q is None or not 0 <= q <= 100:
            raise ValueError(
                f"{s.source} ({s.label}): F_as_built of shape {shape} at percentile {q!r}: "
                f"give one value per design and objective ({s.F.shape}), at 0 to 100"
            )


def _pooled(
    sets: list[DesignSet], keep: list[np.ndarray], names: list[str], var_names: list[str]
) -> dict[str, Any]:
    """The kept designs of ``sets`` in one pool (:class:`Selection`'s ``F``, ``F_as_built``
    (None unless every set has it), ``X``, ``case``, ``source``, ``row`` and ``feasible``):
    the objectives ``names`` and the variables ``var_names`` in that order."""
    pairs = list(zip(sets, keep))
    as_built = None
    if all(s.F_as_built is not None for s in sets):
        as_built = np.vstack(
            [np.asarray(s.F_as_built)[k][:, [s.names.index(n) for n in names]] for s, k in pairs]
        )
    return {
        "F": np.vstack([s.F[k][:, [s.names.index(n) for n in names]] for s, k in pairs]),
        "F_as_built": as_built,
        "X": np.vstack([_columns(s.X[k], s.var_names, var_names) for s, k in pairs]),
        "case": np.concatenate([np.full(k.sum(), s.label, dtype=object) for s, k in pairs]),
        "source": np.concatenate([np.full(k.sum(), i) for i, k in enumerate(keep)]),
        "row": np.concatenate([np.flatnonzero(k) for k in keep]),
        "feasible": np.concatenate([s.feasible[k] for s, k in pairs]),
    }


def _columns(X: np.ndarray, have: list[str], want: list[str]) -> np.ndarray:
    """``X`` with columns ``want`` (NaN for a variable the set does not have)."""
    out = np.full((len(X), len(want)), np.nan)
    for j, name in enumerate(want):
        if name in have:
            out[:, j] = X[:, have.index(name)]
    return out


def _write_sort(group, sort: KEpsilonSort, rows: np.ndarray | None, picks: dict[str, int]) -> None:
    """k_eps, k, chosen, ties and picks of one sort; indices in the pool (``rows`` maps a
    case's own indices to the pool's and is the dimension of its k_eps and k)."""
    index = (lambda i: i) if rows is None else (lambda i: rows[i])
    if rows is not None:
        put(KESORT, group, "rows", rows)
    put(KESORT, group, "k_eps", sort.k_eps)
    put(KESORT, group, "k", sort.k)
    put(KESORT, group, "chosen", int(index(sort.chosen)))
    put(KESORT, group, "ties", np.asarray(index(sort.ties), dtype=int))
    grp = group.create_group("picks")
    for key, value in picks.items():
        put(KESORT, grp, key, int(value))
    write_attrs(
        group,
        epsilon=sort.epsilon,
        P=np.nan if sort.P is None else sort.P,
        P_auto=sort.P_auto,
        normalisation=sort.normalisation,
        unique=sort.unique,
    )


def write_selection(path: str | Path, selection: Selection, command: str | None = None) -> Path:
    """Write ``/kesort`` (its format: ``suspopt.formats.KESORT``) to a new HDF5 file,
    atomically."""
    s = require(selection, Selection, "selection", "from select(sets)")
    inputs = [("the input", d.source) for d in s.sets]  # (the fronts it sorted)
    with atomic_h5(path, s.sets[0].config, command, inputs=inputs) as h5:
        grp = h5.create_group("kesort")
        put(KESORT, grp, "F", s.F, s.units, names=s.names)
        if s.F_as_built is not None:
            put(KESORT, grp, "F_as_built", s.F_as_built, s.units, names=s.names,
                percentile=s.as_built)  # fmt: skip
        put(KESORT, grp, "X", s.X, s.var_units, names=s.var_names)
        put(KESORT, grp, "case", list(s.case))
        put(KESORT, grp, "source", s.source)
        put(KESORT, grp, "row", s.row)
        put(KESORT, grp, "id", list(selection_ids(s)))
        put(KESORT, grp, "feasible", s.feasible)
        _write_sort(grp, s.sort, None, s.picks)
        write_attrs(grp, cases=list(s.cases))
        sets = grp.create_group("sets")
        for key, values in (
            ("file", [str(d.source) for d in s.sets]),
            ("label", [d.label for d in s.sets]),
            ("config", [d.config.text for d in s.sets]),
        ):
            put(KESORT, sets, key, values)
        if s.case_sorts:
            cases = grp.create_group("cases")
            for label, cs in s.case_sorts.items():
                _write_sort(cases.create_group(label), cs.sort, cs.rows, cs.picks)
    return Path(path)
