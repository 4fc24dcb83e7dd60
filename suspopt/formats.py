"""The layout of every kind of HDF5 file suspopt writes, declared once.

A :class:`FileFormat` lists every group and dataset a kind of file may hold: its path (a
``<name>`` part stands for a name of the run: a signal, a metric, a pick, a model), its
dimensions, its unit (``None``: one per column or per name, from the run: the objectives',
the design variables'), what it holds and when it is written. Everything else reads it from
here:

- the writers make their datasets with :meth:`FileFormat.table` (and
  :func:`suspopt.io.put`), which take the dimensions and the fixed units from the declaration
  and refuse a dataset it does not declare, a unit that contradicts it or one missing;
- the xarray view in memory (:func:`suspopt.layout.as_dataset`) is made of the same tables;
- :meth:`FileFormat.problems` checks a whole file against it (the tests run it on a file of
  every kind, and make damaged copies of each declared dataset to feed every reader);
- the docs' format page is generated from :data:`FORMATS` when the docs are built.

The root attributes every file has are :data:`ROOT_ATTRIBUTES`; each kind adds its own.
A dimension's scale (``design``, ``objective`` ...) is the dataset of that name in the group
or a group above it, made by the writer when the group has none (row numbers, or the
column names).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

__all__ = [
    "Table",
    "Data",
    "Group",
    "FileFormat",
    "LayoutError",
    "FORMATS",
    "ROOT_ATTRIBUTES",
    "format_of",
]


@dataclass(frozen=True)
class Table:
    """One dataset of a group: ``data`` with its ``units`` (one, or one per column), the
    names of its axes ``dims`` (``(name,)``: it is that dimension's scale), ``coords`` (a
    dimension's values where the group makes its scale), ``names`` (the columns' names:
    the attribute ``names`` and the last dimension's coordinate) and other ``attrs``
    (:func:`suspopt.io.write_dataset`)."""

    name: str
    data: Any
    units: str | Sequence[str]
    dims: tuple[str, ...]
    coords: Mapping[str, Sequence] | None = None
    names: Sequence[str] | None = None
    attrs: Mapping[str, Any] = field(default_factory=dict)


class LayoutError(RuntimeError):
    """A writer made a dataset its file's :class:`FileFormat` does not declare, or with other
    dimensions or units: a fault of suspopt, not of its input."""


@dataclass(frozen=True)
class Data:
    """A dataset: ``path`` in the file, ``dims`` its dimensions (space-separated, ``""`` a
    scalar), ``units`` (``None``: given per column or per name by the run), ``doc`` what it
    holds, ``when`` the condition it is written under (``""``: always), ``attrs`` its own
    attributes (name -> what it holds)."""

    path: str
    dims: str
    units: str | None
    doc: str
    when: str = ""
    attrs: Mapping[str, str] = field(default_factory=dict)

    @property
    def axes(self) -> tuple[str, ...]:
        return tuple(self.dims.split())


@dataclass(frozen=True)
class Group:
    """A group: ``path``, ``doc``, ``when`` and its ``attrs`` (as :class:`Data`)."""

    path: str
    doc: str
    when: str = ""
    attrs: Mapping[str, str] = field(default_factory=dict)


def _parts(path: str) -> list[str]:
    return [p for p in path.split("/") if p]


def _matches(pattern: str, path: str) -> bool:
    """Whether ``path`` is one of ``pattern``'s (a ``<name>`` part matches any one part)."""
    want, got = _parts(pattern), _parts(path)
    return len(want) == len(got) and all(
        w == g or (w.startswith("<") and w.endswith(">")) for w, g in zip(want, got)
    )


def _literal(pattern: str) -> int:
    """How many parts of ``pattern`` are literal (the more, the closer the match)."""
    return sum(not p.startswith("<") for p in _parts(pattern))


@dataclass(frozen=True)
class FileFormat:
    """A kind of file: ``kind`` (its name), ``written_by`` (the command line that writes it),
    ``doc``, ``attrs`` (root attributes besides :data:`ROOT_ATTRIBUTES`), ``nodes`` (its
    groups and datasets) and ``read_by`` (the commands that read it, ``FILE`` standing for
    it: what the damaged-file tests run)."""

    kind: str
    written_by: str
    doc: str
    attrs: Mapping[str, str]
    nodes: tuple[Data | Group, ...]
    read_by: tuple[str, ...] = ()

    @property
    def datasets(self) -> list[Data]:
        return [n for n in self.nodes if isinstance(n, Data)]

    @property
    def groups(self) -> list[Group]:
        return [n for n in self.nodes if isinstance(n, Group)]

    def data(self, path: str) -> Data:
        """The declared dataset ``path`` is (the most literal match); :class:`LayoutError`
        when there is none."""
        found = [d for d in self.datasets if _matches(d.path, path)]
        if not found:
            raise LayoutError(f"the {self.kind} file format declares no dataset {path!r}")
        return max(found, key=lambda d: _literal(d.path))

    def group(self, path: str) -> Group | None:
        """The declared group ``path`` is, or None."""
        found = [g for g in self.groups if _matches(g.path, path)]
        return max(found, key=lambda g: _literal(g.path)) if found else None

    def table(
        self,
        group: str,
        name: str,
        data,
        units: str | Sequence[str] | None = None,
        names: Sequence[str] | None = None,
        coords: Mapping[str, Sequence] | None = None,
        attrs: Mapping[str, Any] | None = None,
    ) -> Table:
        """The :class:`Table` of the dataset ``name`` of ``group`` (a path, ``""`` the root)
        holding ``data``: its dimensions and (fixed) unit as declared, ``units`` where the
        declaration leaves them to the run. :class:`LayoutError` for an undeclared dataset,
        units given where the declaration fixes other ones, or none where it fixes none."""
        path = "/".join(_parts(group) + [name])
        entry = self.data(path)
        if entry.units is None:
            if units is None:
                raise LayoutError(f"{self.kind} file: {path} takes its units from the run")
        elif (
            units is not None and units != entry.units and list(units) != [entry.units] * len(units)
        ):
            raise LayoutError(f"{self.kind} file: {path} is in {entry.units}, not {units}")
        held: str | Sequence[str] = entry.units if units is None else units  # type: ignore[assignment]
        extra = dict(attrs or {})
        unknown = set(extra) - set(entry.attrs)
        if unknown:
            raise LayoutError(f"{self.kind} file: {path} declares no attribute {sorted(unknown)}")
        return Table(name, data, held, entry.axes, coords=coords, names=names, attrs=extra)

    def problems(self, h5) -> list[str]:
        """What in the open h5py file ``h5`` this format does not declare: a group, a dataset,
        or a dataset of other dimensions or units (``[]`` for a file of this format)."""
        found: list[str] = []
        undeclared_roots = set(h5.attrs) - set(ROOT_ATTRIBUTES) - set(self.attrs)
        if undeclared_roots:
            found.append(f"/: root attributes {sorted(undeclared_roots)} undeclared")

        def visit(name: str, obj) -> None:
            if not hasattr(obj, "shape"):
                if self.group(name) is None and not any(
                    _matches("/".join(_parts(d.path)[: len(_parts(name))]), name)
                    for d in self.datasets
                ):
                    found.append(f"/{name}: undeclared group")
                return
            try:
                entry = self.data(name)
            except LayoutError:
                found.append(f"/{name}: undeclared dataset")
                return
            dims = (
                (_parts(name)[-1],)
                if obj.is_scale
                else tuple(d[0].name.rsplit("/", 1)[-1] if len(d) else "" for d in obj.dims)
            )
            if dims != entry.axes:
                found.append(f"/{name}: dimensions {dims}, declared {entry.axes}")
            units = obj.attrs.get("units")
            held = (
                {units}
                if isinstance(units, str)
                else {str(u) for u in ([] if units is None else units)}
            )
            if entry.units is not None and held != {entry.units}:
                found.append(f"/{name}: units {units!r}, declared {entry.units!r}")

        h5.visititems(visit)
        return found


#: The root attributes of every file suspopt writes (:func:`suspopt.io.root_attrs`).
ROOT_ATTRIBUTES: dict[str, str] = {
    "suspopt_version": "the version that wrote it (suspopt knows its own outputs by it)",
    "created": "when, ISO 8601 in UTC",
    "command": "the command line",
    "config": "the config's YAML text (after ``--set`` edits, the edited config)",
    "seed": "the road's seed (-1 for a road without one); in a builds file, the builds' seed",
    "request": "what the command was asked for, as JSON: the command and the options that "
    "change the result (not the files' names, nor how the run was executed)",
    "plot": "written with ``--plot``: the figure, as a path from the file's folder",
}


def _scales(group: str, *dims: str, when: str = "") -> tuple[Data, ...]:
    """The dimension scales ``dims`` of ``group`` (row numbers, or the columns' names),
    written ``when`` (a dimension ``name:condition`` only under that condition too)."""
    prefix = f"{group}/" if group else ""
    out = []
    for d in dims:
        name, _, alone = d.partition(":")
        out.append(
            Data(prefix + name, name, "1", f"the scale of dimension ``{name}``", alone or when)
        )
    return tuple(out)


def _sort(group: str, design: str, tie: str, when: str = "") -> tuple[Data | Group, ...]:
    """One k-ε sort's datasets in ``group`` (:func:`suspopt.choosing.selection.write_selection`)."""
    sort_attrs = {
        "epsilon": "ε per objective (SI)",
        "P": "the P used (NaN: automatic)",
        "P_auto": "whether P was chosen automatically",
        "normalisation": "how the objectives were normalised",
        "unique": "whether the optimum is unique",
    }
    return (
        Group(group, "a k-ε sort", when, sort_attrs),
        Data(f"{group}/k_eps", design, "1", "each design's k-ε level", when),
        Data(f"{group}/k", design, "1", "each design's k level", when),
        Data(f"{group}/chosen", "", "1", "the optimum's row", when),
        Data(f"{group}/ties", tie, "1", "the rows tied with the optimum", when),
        Group(f"{group}/picks", "the Pareto picks", when),
        Data(f"{group}/picks/<pick>", "", "1", "the row of each pick (best_<f>, knee)", when),
    )


_DESIGN_XFG = (
    Data("pareto/X", "design variable", None, "the designs' variables (physical values)"),
    Data(
        "pareto/F",
        "design objective",
        None,
        "the main objectives",
        attrs={"over_scenarios": "robust run: each column's rule over the scenarios"},
    ),
    Data(
        "pareto/G",
        "design constraint",
        None,
        "the constraint margins (g <= 0 is met)",
        attrs={"over_scenarios": "robust run: each column's rule over the scenarios"},
    ),
)

SIMULATE = FileFormat(
    "simulate",
    "suspopt simulate CONFIG -o OUT.h5",
    "A simulation of P designs over T samples: every signal asked for, the config's "
    "metrics and the modes.",
    {},
    (
        Data("time", "time", "s", "the sample times"),
        Data("design", "design", "1", "the designs' row numbers"),
        Data("diverged_at", "design", "s", "when each design diverged; NaN where it is fine"),
        Group("signals", "every signal of ``output.signals``"),
        Data(
            "signals/<signal>",
            "design time",
            None,
            "a signal (float32 with ``output.float32: true``)",
        ),
        Group("metrics", "the config's ``metrics:``"),
        Data("metrics/<metric>", "design", None, "a metric's value per design"),
        Group(
            "designs",
            "the designs' parameters",
            "a batch of designs (``--sweep``, ``--pick``, ``params``)",
            attrs={"source": "``--pick``: the file the designs were picked from"},
        ),
        Data(
            "designs/X",
            "design variable",
            None,
            "the parameters, by dotted path",
            "a batch of designs",
        ),
        *_scales("designs", "variable", when="a batch of designs"),
        Data("designs/pick", "design", "1", "each design's pick name", "``--pick``"),
        Data("designs/id", "design", "1", "each design's id", "``--pick``"),
        Data("designs/row", "design", "1", "each design's row in the source", "``--pick``"),
        Group("objectives", "the picks' objectives", "``--pick``"),
        Data(
            "objectives/F",
            "design objective",
            None,
            "main and supplementary objectives, re-simulated",
            "``--pick``",
        ),
        Data(
            "objectives/stored_F",
            "design stored_objective",
            None,
            "the values the source stored",
            "``--pick``",
        ),
        *_scales("objectives", "objective", "stored_objective", when="``--pick``"),
        Group("modal", "the undamped modes (``suspopt.modal_analysis``)"),
        Data(
            "modal/frequency",
            "design mode",
            "Hz",
            "undamped natural frequencies",
            attrs={"dominant": "the DOF of most energy in each mode"},
        ),
        Data("modal/label", "design mode", "1", "what each mode is (``wheel.F1 + wheel.F2``)"),
        Data(
            "modal/energy_share",
            "design mode dof",
            "1",
            "each DOF's share of each mode's kinetic energy",
            attrs={"dofs": "the DOFs"},
        ),
        *_scales("modal", "mode", "dof"),
    ),
    ("export FILE --csv OUT", "report FILE -o OUT.html"),
)

OPTIMISE = FileFormat(
    "optimise",
    "suspopt optimise CONFIG -o OUT.h5",
    "An optimisation: its optimum or Pareto set, its history and the checkpoint ``--resume`` "
    "continues from.",
    {
        "status": "``running``, ``finished``, ``interrupted`` or ``failed``",
        "algorithm": "the optimiser",
        "optimiser_seed": "the optimiser's seed",
        "generations": "generations run",
        "evaluations": "designs evaluated",
    },
    (
        Group(
            "pareto",
            "the optimum or the Pareto set",
            attrs={"weights": "weighted sum: the weights"},
        ),
        *_DESIGN_XFG,
        *_scales("pareto", "design", "variable", "objective", "constraint"),
        Group("pareto/scenarios", "robust run: every scenario's values", "robust run"),
        Data("pareto/scenarios/scenario", "scenario", "1", "the scenarios' names", "robust run"),
        Data("pareto/scenarios/weight", "scenario", "1", "each scenario's weight", "robust run"),
        Data(
            "pareto/scenarios/F",
            "design scenario objective",
            None,
            "each scenario's objectives (NaN where it failed)",
            "robust run",
        ),
        Data(
            "pareto/scenarios/G",
            "design scenario constraint",
            None,
            "each scenario's constraint margins",
            "robust run",
        ),
        Group("history", "one row per generation"),
        Data("history/generation", "generation", "1", "the generation"),
        Data("history/best", "generation objective", None, "the best objectives (or weighted sum)"),
        Data("history/hypervolume", "generation", "1", "the hypervolume"),
        Data("history/evaluations", "generation", "1", "designs evaluated so far"),
        Data("history/time", "generation", "s", "wall time so far"),
        Data("history/feasible", "generation", "1", "the feasible share"),
        *_scales("history", "objective"),
        Group(
            "baseline",
            "the config's own design, evaluated once when the run ends",
            "a run not interrupted",
        ),
        Data("baseline/X", "design variable", None, "its variables", "a run not interrupted"),
        Data("baseline/F", "design objective", None, "its objectives", "a run not interrupted"),
        Data("baseline/G", "design constraint", None, "its margins", "a run not interrupted"),
        *_scales(
            "baseline",
            "design",
            "variable",
            "objective",
            "constraint",
            when="a run not interrupted",
        ),
        Group(
            "checkpoint",
            "every evaluated batch, as data, for ``--resume``",
            attrs={"format": "the checkpoint's format", "generations": "generations stored"},
        ),
        Data("checkpoint/X", "evaluation variable", None, "search coordinates"),
        Data("checkpoint/F", "evaluation objective", None, "objectives"),
        Data("checkpoint/G", "evaluation constraint", None, "constraint margins"),
        Data("checkpoint/batches", "batch", "1", "the size of each evaluated batch"),
        *_scales("checkpoint", "evaluation", "variable", "objective", "constraint", "batch"),
    ),
    (
        "kesort FILE -o OUT.h5",
        "simulate FILE --pick knee -o OUT.h5",
        "report FILE -o OUT.html",
        "export FILE --pick knee -o OUT.yaml",
    ),
)

KESORT = FileFormat(
    "kesort",
    "suspopt kesort PARETO.h5 ... -o OUT.h5",
    "A k-ε selection of one or more pooled fronts.",
    {},
    (
        Group(
            "kesort",
            "the pooled designs and their sort",
            attrs={
                "cases": "the cases' labels",
                "epsilon": "ε per objective (SI)",
                "P": "the P used (NaN: automatic)",
                "P_auto": "whether P was chosen automatically",
                "normalisation": "how the objectives were normalised",
                "unique": "whether the optimum is unique",
            },
        ),
        Data("kesort/F", "design objective", None, "main and supplementary objectives"),
        Data(
            "kesort/F_as_built",
            "design objective",
            None,
            "the values sorted on",
            "``--as-built Q``",
            {"percentile": "Q [%]"},
        ),
        Data(
            "kesort/X", "design variable", None, "the design variables (NaN where a case lacks one)"
        ),
        Data("kesort/case", "design", "1", "each design's case"),
        Data("kesort/source", "design", "1", "each design's input file (index)"),
        Data("kesort/row", "design", "1", "each design's row in its file's ``/pareto``"),
        Data("kesort/id", "design", "1", "each design's id (``13``, or ``C1:13`` pooled)"),
        Data("kesort/feasible", "design", "1", "whether it meets every constraint"),
        *_sort("kesort", "design", "tie")[1:],
        *_scales("kesort", "design", "objective", "variable", "tie"),
        Group("kesort/sets", "the input files"),
        Data("kesort/sets/file", "set", "1", "each input file"),
        Data("kesort/sets/label", "set", "1", "its label"),
        Data("kesort/sets/config", "set", "1", "its config"),
        *_scales("kesort/sets", "set"),
        Group("kesort/cases", "each case's own sort", "several cases"),
        *_sort("kesort/cases/<case>", "rows", "case_tie", "several cases"),
        Data(
            "kesort/cases/<case>/rows", "rows", "1", "the case's rows in the pool", "several cases"
        ),
        *_scales("kesort/cases/<case>", "case_tie", when="several cases"),
    ),
    (
        "simulate FILE --pick chosen -o OUT.h5",
        "report FILE -o OUT.html",
        "export FILE --pick chosen -o OUT.yaml",
    ),
)

#: ``/pareto`` of an analysis of a front (:func:`suspopt.analyse.pseudo.write_stored_front`).
_STORED_FRONT: tuple[Data | Group, ...] = (
    Group("pareto", "the front analysed, as stored"),
    Data("pareto/X", "design variable", None, "its designs' variables"),
    Data("pareto/F", "design objective", None, "its main objectives, as stored"),
    Data(
        "pareto/S",
        "design supplementary",
        None,
        "its supplementary objectives, re-simulated",
        "a config with some",
    ),
    Data("pareto/feasible", "design", "1", "whether each design meets its constraints"),
    Data("pareto/id", "design", "1", "each design's id"),
    Data("pareto/source_row", "design", "1", "each design's row in the source", "``--pick``"),
    Group("pareto/picks", "the front's picks (edges, knee; the picks of ``--pick``)"),
    Data("pareto/picks/<pick>", "", "1", "a pick's row"),
    *_scales("pareto", "design", "variable", "objective", "supplementary:a config with some"),
)

_ANALYSIS = {
    "analysis": "the kind of analysis",
    "source": "the input file",
}

PSEUDO = FileFormat(
    "analyse roads, masses, controllers, tolerances",
    "suspopt analyse roads|masses|controllers|tolerances PARETO.h5 -o OUT.h5",
    "A front re-simulated under changed configs: one pseudo-front per change.",
    _ANALYSIS,
    (
        *_STORED_FRONT,
        Group("pseudo", "the pseudo-fronts", attrs={"labels": "their labels"}),
        Group(
            "pseudo/<label>",
            "one pseudo-front",
            attrs={
                "label": "its label",
                "config": "the changed config's YAML",
                "road_class": "roads: the ISO 8608 class",
                "road_source": "roads: the config whose road was taken",
                "load_mass": "masses: the load on the seat [kg]",
                "mass_change": "masses: the change of the load [kg]",
                "controller_source": "controllers: the file of the controller",
                "variable": "tolerances: the variable changed",
                "tolerance": "tolerances: its signed change [%]",
                "held_at_limit": "tolerances: designs held at a field's limit",
            },
        ),
        Data("pseudo/<label>/F", "design objective", None, "the main objectives"),
        Data("pseudo/<label>/change", "design objective", "%", "their change"),
        Data(
            "pseudo/<label>/S",
            "design supplementary",
            None,
            "the supplementary objectives",
            "a config with some",
        ),
        Data(
            "pseudo/<label>/S_change",
            "design supplementary",
            "%",
            "their change",
            "a config with some",
        ),
        Data(
            "pseudo/<label>/X",
            "design variable",
            None,
            "the changed designs",
            "a change of the designs' own values",
        ),
        Data("pseudo/<label>/feasible", "design", "1", "whether each design meets its constraints"),
        Data("pseudo/<label>/failed", "design", "1", "whether its simulation failed"),
        *_scales(
            "pseudo/<label>",
            "design",
            "objective",
            "supplementary:a config with some",
            "variable:a change of the designs' own values",
        ),
    ),
    ("simulate FILE --pick knee -o OUT.h5", "report FILE -o OUT.html", "export FILE --csv OUT"),
)

_B = "sample design"

BUILDS = FileFormat(
    "analyse builds",
    "suspopt analyse builds PARETO.h5 -o OUT.h5",
    "A front's designs built many times, every design variable off at once.",
    _ANALYSIS,
    (
        *_STORED_FRONT,
        Group(
            "builds",
            "the builds",
            attrs={"samples": "builds per design", "distribution": "``uniform`` or ``normal``"},
        ),
        Data("builds/X", f"{_B} variable", None, "the built designs"),
        Data("builds/F", f"{_B} objective", None, "their main objectives"),
        Data(
            "builds/S",
            f"{_B} supplementary",
            None,
            "their supplementary objectives",
            "a config with some",
        ),
        Data("builds/change", f"{_B} objective", "%", "the change from the stored values"),
        Data(
            "builds/G", f"{_B} constraint", None, "constraint margins", "a config with constraints"
        ),
        Data("builds/feasible", _B, "1", "whether each build meets its constraints"),
        Data("builds/failed", _B, "1", "whether its simulation failed"),
        Data("builds/F_p05", "design objective", None, "5th percentile over the builds"),
        Data("builds/F_median", "design objective", None, "median over the builds"),
        Data("builds/F_p95", "design objective", None, "95th percentile over the builds"),
        Data("builds/feasible_share", "design", "1", "the share of feasible builds"),
        Data(
            "builds/contribution",
            "design variable objective",
            "1",
            "the squared correlation of each variable with each objective",
        ),
        Data("builds/tolerance", "variable", "%", "each variable's tolerance"),
        Data("builds/batch", "variable", "1", "each variable's batch (empty: drawn alone)"),
        *_scales(
            "builds",
            "sample",
            "design",
            "variable",
            "objective",
            "supplementary:a config with some",
            "constraint:a config with constraints",
        ),
    ),
    ("simulate FILE --pick knee -o OUT.h5", "report FILE -o OUT.html", "export FILE --csv OUT"),
)

TRANSMISSIBILITY = FileFormat(
    "analyse transmissibility",
    "suspopt analyse transmissibility CONFIG|PARETO.h5 -o OUT.h5",
    "Seat and seat-to-head transmissibility, linearised and simulated (Eq 2.86).",
    {"seat_kind": "the seat's kind"},
    (
        Data("design", "design", "1", "the designs' row numbers"),
        Group("linear", "the linearised transmissibility"),
        Data("linear/frequency", "frequency", "Hz", "its frequencies"),
        Data("linear/<dof>", "design frequency", "-", "|H| of a DOF"),
        Group("simulated", "the H1 estimate from the simulation"),
        Data("simulated/frequency", "frequency", "Hz", "its frequencies"),
        Data("simulated/<dof>", "design frequency", "-", "|H1| of a DOF"),
        Group("simulated/coherence", "the estimate's coherence"),
        Data("simulated/coherence/<dof>", "design frequency", "-", "coherence of a DOF"),
        Group("statics", "the static state"),
        Data("statics/static_deflection", "design", "m", "the seat's static deflection"),
        Group("modal", "the modes"),
        Data(
            "modal/frequency",
            "design mode",
            "Hz",
            "natural frequencies",
            attrs={"dof_names": "the DOFs"},
        ),
        *_scales("modal", "mode"),
        Group("constraints", "the seat's constraints"),
        Data("constraints/<constraint>", "design", None, "a constraint's value"),
        Group("weighted_rms", "ISO 2631-1 weighted r.m.s. accelerations"),
        Data("weighted_rms/<signal>", "design", "m/s^2", "a signal's weighted r.m.s."),
        Group(
            "designs",
            "the designs of a front",
            "a Pareto or result file",
            {"picks": "each design's picks"},
        ),
        Data("designs/row", "design", "1", "each design's row", "a Pareto or result file"),
        Data("designs/id", "design", "1", "each design's id", "a Pareto or result file"),
        Data("designs/X", "design variable", None, "its variables", "a Pareto or result file"),
        Data(
            "designs/F",
            "design objective",
            None,
            "its stored objectives",
            "a Pareto or result file",
        ),
        *_scales("designs", "variable", "objective", when="a Pareto or result file"),
    ),
    ("simulate FILE --pick 0 -o OUT.h5", "report FILE -o OUT.html", "export FILE --csv OUT"),
)

MODELS = FileFormat(
    "analyse models",
    "suspopt analyse models A.yaml B.yaml ... -o OUT.h5",
    "Configs side by side (Ch. 3).",
    {"analysis": "``models``", "models": "the models' labels", "reference": "the reference"},
    (
        Group("models", "one group per config"),
        Group(
            "models/<model>",
            "a config's run",
            attrs={
                "source": "the file",
                "config": "its YAML",
                "preset": "the vehicle preset",
                "road": "the road's kind",
            },
        ),
        Data("models/<model>/time", "time", "s", "the sample times"),
        Group("models/<model>/signals", "the signals compared"),
        Data("models/<model>/signals/<signal>", "time", None, "a signal"),
        Group("models/<model>/psd", "power spectral densities"),
        Data("models/<model>/psd/frequency", "frequency", "Hz", "their frequencies"),
        Data("models/<model>/psd/<signal>", "frequency", None, "a signal's PSD"),
        Group("models/<model>/modal", "the modes"),
        Data(
            "models/<model>/modal/frequency",
            "mode",
            "Hz",
            "natural frequencies",
            attrs={"dominant": "each mode's DOF of most energy", "label": "what each mode is"},
        ),
        *_scales("models/<model>/modal", "mode"),
        Group("comparison", "one value per model and metric"),
        Data("comparison/model", "model", "1", "the models, in order"),
        Group("comparison/value", "the metrics' values"),
        Data(
            "comparison/value/<metric>",
            "model",
            None,
            "a metric per model",
            attrs={"models": "the models"},
        ),
        Group("comparison/difference", "their change from the reference"),
        Data(
            "comparison/difference/<metric>",
            "model",
            "%",
            "a metric's change",
            attrs={"models": "the models"},
        ),
    ),
    ("report FILE -o OUT.html", "export FILE --csv OUT"),
)

CDF_SENSITIVITY = FileFormat(
    "analyse cdf-sensitivity",
    "suspopt analyse cdf-sensitivity CONFIG -o OUT.h5",
    "The CDF threshold's C_max share swept against the base law (Figs. 4.7, 4.10).",
    {},
    (
        Group(
            "cdf_sensitivity",
            "the sweep",
            attrs={
                "laws": "the laws",
                "corners": "the semi-active corners",
                "distribution": "the fitted distribution",
            },
        ),
        Data("cdf_sensitivity/c_max_share", "c_max_share", "1", "the shares asked for"),
        Data("cdf_sensitivity/achieved_share", "c_max_share", "1", "the shares achieved"),
        Data("cdf_sensitivity/base_share", "", "1", "the base law's share"),
        Data(
            "cdf_sensitivity/final_threshold",
            "c_max_share corner",
            None,
            "each corner's final threshold (the law's condition unit)",
        ),
        *_scales("cdf_sensitivity", "corner"),
        Group("cdf_sensitivity/base", "the base law's metrics"),
        Data("cdf_sensitivity/base/<metric>", "", None, "SW, RC, ST, TD, DE of the base law"),
        Group("cdf_sensitivity/cdf", "the metrics with the CDF threshold"),
        Data("cdf_sensitivity/cdf/<metric>", "c_max_share", None, "a metric per share"),
        Group("cdf_sensitivity/reduction", "(X_base - X_CDF) / X_base"),
        Data("cdf_sensitivity/reduction/<metric>", "c_max_share", "%", "a metric's reduction"),
    ),
    ("report FILE -o OUT.html", "export FILE --csv OUT"),
)

SCENARIOS = FileFormat(
    "analyse scenarios",
    "suspopt analyse scenarios ROBUST.h5 -o OUT.h5",
    "A robust front's picks under each of its scenarios.",
    _ANALYSIS,
    (
        Group("scenarios", "the picks under each scenario"),
        Data("scenarios/scenario", "scenario", "1", "the scenarios"),
        Data("scenarios/pick", "pick", "1", "the picks"),
        Data("scenarios/row", "pick", "1", "each pick's row in the front"),
        Data(
            "scenarios/F",
            "pick scenario objective",
            None,
            "the objectives",
            attrs={"over_scenarios": "each objective's rule over the scenarios"},
        ),
        Data("scenarios/holds", "pick scenario", "1", "whether every constraint holds"),
        *_scales("scenarios", "objective"),
    ),
    ("report FILE -o OUT.html", "export FILE --csv OUT"),
)

#: Every file format, by kind.
FORMATS: dict[str, FileFormat] = {
    f.kind: f
    for f in (
        SIMULATE,
        OPTIMISE,
        KESORT,
        PSEUDO,
        BUILDS,
        TRANSMISSIBILITY,
        MODELS,
        CDF_SENSITIVITY,
        SCENARIOS,
    )
}


def format_of(h5) -> FileFormat | None:
    """The format of the open h5py file ``h5``, told by its groups and root attributes."""
    analysis = h5.attrs.get("analysis")
    if analysis == "builds":
        return BUILDS
    if analysis in ("roads", "masses", "controllers", "tolerances"):
        return PSEUDO
    for fmt, group in (
        (MODELS, "comparison"),
        (SCENARIOS, "scenarios"),
        (CDF_SENSITIVITY, "cdf_sensitivity"),
        (KESORT, "kesort"),
        (OPTIMISE, "checkpoint"),
        (TRANSMISSIBILITY, "linear"),
        (SIMULATE, "signals"),
    ):
        if group in h5:
            return fmt
    return None
