"""What a simulation returns: :class:`Result`, its signals and the one table of them.

:func:`signal_table` is every signal a run of a model has, name -> :class:`Signal` (its SI
unit and how it is computed from the result), in the order the HDF5 files list them: the
vehicle's (body, wheels, each corner's suspension, tyre and road), the controller's records
(per corner) and each attachment's (the seat and the passenger, :class:`!Attachment`, which
contribute their own entries). :class:`SignalMap` computes a signal the first time it is read
and keeps it.
"""

from __future__ import annotations

import difflib
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from .config import Config
from .integrator import Held
from .network import Assembled, Network
from .vehicle import VehicleModel

__all__ = ["Result", "SignalMap", "Signal", "Attachment", "signal_table", "signal_names"]


class Attachment(Protocol):
    """Extra bodies mounted at a point of the vehicle body (a seat, a seated passenger).

    ``dof_names`` name its vertical DOFs (appended after the vehicle's); ``network`` its
    :class:`~suspopt.network.Network` with the floor under it as the one input;
    ``point = (x, y)`` is where it sits on the body [m] (x + forward, y + right), the floor's
    motion being the body's vertical motion there; ``coupled`` puts the floor's reaction on
    the body (two-way); the thesis drives seats one way. ``signals()`` gives its entries of
    the signal table, name -> (SI unit, ``compute(q, v, acc, base, base_vel, base_acc)``): a
    signal (P, T) from its states (m, P, T) and the floor's motion (P, T).
    """

    dof_names: tuple[str, ...]
    network: Network
    point: tuple[float, float]
    coupled: bool

    def signals(self) -> dict[str, tuple[str, Callable[..., np.ndarray]]]: ...


@dataclass(frozen=True)
class Signal:
    """An entry of the signal table: its SI ``unit`` and ``compute(result) -> (P, T)``."""

    unit: str
    compute: Callable[..., np.ndarray]  # (result) -> (P, T)


_DOF_UNITS = {"heave": "m", "roll": "rad", "pitch": "rad"}
_DERIVATIVES = (("", ""), ("_vel", "/s"), ("_acc", "/s^2"))


def _tyre_force(r: Result, c: int) -> np.ndarray:
    """The normal load, compression +: static load less the tyre element's force."""
    elastic, viscous = r.element_forces("tyre")
    static = r.model.static_tyre_load[:, 0, c, None]
    force = elastic[c] + viscous[c]
    if r.config.vehicle.tyre_lift_off:
        # a lifted tyre carries exactly 0: the force is capped at the static load, and adding
        # the capped parts back up can round past the cap by an ulp
        force = np.minimum(force, static)
    return static - force


def _per_sample(values: Callable[[Result], np.ndarray]) -> Callable[[Result], np.ndarray]:
    """A signal held at one value per design over the run, or shared by the designs, as
    (P, T)."""
    return lambda r: np.broadcast_to(values(r), (r.P, r.time.size)).copy()


#: The vehicle's per-corner signals: head -> (unit, compute(result, corner index)).
_CORNER_SIGNALS: dict[str, tuple[str, Callable[[Result, int], np.ndarray]]] = {
    "travel": ("m", lambda r, c: r.deformation("suspension")[c]),
    "travel_vel": ("m/s", lambda r, c: r.deformation("suspension", rate=True)[c]),
    "tyre_deflection": ("m", lambda r, c: r.deformation("tyre")[c]),
    "tyre_force": ("N", _tyre_force),
    "spring_force": ("N", lambda r, c: r.element_forces("suspension")[0][c]),
    "damper_force": ("N", lambda r, c: r.element_forces("suspension")[1][c]),
    "damping": ("N s/m", lambda r, c: _per_sample(lambda r: r.damping_coefficient()[c])(r)),
    "road": ("m", lambda r, c: _per_sample(lambda r: r.road[c])(r)),
    "road_vel": ("m/s", lambda r, c: _per_sample(lambda r: r.road_vel[c])(r)),
}


def signal_table(
    model: VehicleModel,
    controller_units: Mapping[str, str] = {},
    attachments: Sequence[Attachment] = (),
) -> dict[str, Signal]:
    """Every signal a simulation of this model (its controller's records, with their units,
    and its attachments) provides (module docstring)."""
    table: dict[str, Signal] = {}
    for j, dof in enumerate(model.body_dofs):
        for (suffix, per), deriv in zip(_DERIVATIVES, ("", "vel", "acc")):
            table[f"body.{dof}{suffix}"] = Signal(
                _DOF_UNITS[dof] + per, lambda r, j=j, d=deriv: r.channel(d, j)
            )
    for c, corner in enumerate(model.corners):
        for (suffix, per), deriv in zip(_DERIVATIVES, ("", "vel", "acc")):
            table[f"wheel.{corner}.heave{suffix}"] = Signal(
                "m" + per, lambda r, j=model.n_body + c, d=deriv: r.channel(d, j)
            )
    for head, (unit, compute) in _CORNER_SIGNALS.items():
        for c, corner in enumerate(model.corners):
            table[f"{head}.{corner}"] = Signal(unit, lambda r, c=c, f=compute: f(r, c))
    for head, unit in controller_units.items():
        for c, corner in enumerate(model.corners):
            table[f"{head}.{corner}"] = Signal(
                unit, lambda r, c=c, h=head: r.controller_records[h].corner(c)
            )
    for j, att in enumerate(attachments):
        for name, (unit, compute) in att.signals().items():
            table[name] = Signal(unit, lambda r, j=j, f=compute: r.attachment_signal(j, f))
    return table


def signal_names(
    model: VehicleModel,
    controller_units: Mapping[str, str] = {},
    attachments: Sequence[Attachment] = (),
) -> list[str]:
    """Every signal a simulation of this model (controller, attachments) provides."""
    return list(signal_table(model, controller_units, attachments))


class SignalMap(Mapping):
    """Lazy, cached mapping of signal name -> (P, T) array, computed from the states."""

    def __init__(self, result: Result):
        # the result keeps the cache, not this map: a cycle result <-> map would keep the
        # (large) arrays alive until the cyclic garbage collector happens to run
        self._result = result
        self._cache = result._signal_cache
        self._table = result._table

    def __iter__(self) -> Iterator[str]:
        return iter(self._table)

    def __len__(self) -> int:
        return len(self._table)

    def __contains__(self, name: object) -> bool:
        return name in self._table

    def __getitem__(self, name: str) -> np.ndarray:
        if name not in self._cache:
            self._cache[name] = _row(self._table, name).compute(self._result)
        return self._cache[name]


def _row(table: dict[str, Signal], name: str) -> Signal:
    """The table's row of signal ``name``, or a KeyError with the closest names."""
    if name not in table:
        close = difflib.get_close_matches(str(name), list(table), n=3)
        raise KeyError(
            f"unknown signal {name!r}" + (f"; did you mean {', '.join(close)}?" if close else "")
        )
    return table[name]


@dataclass
class Result:
    """Output of :func:`simulate`.

    A sample at ``t`` holds what is in force from ``t`` on: a semi-active damper's coefficient
    (and so its force and the accelerations) is the one set at ``t`` when ``t`` is a sample
    instant of its controller. Signals by name are :attr:`signals` (computed on first use),
    their units :meth:`signal_unit`.

    Attributes
    ----------
    config : Config
        The simulated study.
    model : VehicleModel
        The batched vehicle model (SI units: kg, N/m, N s/m).
    time : ndarray
        Sample times ``(T,)`` [s].
    states : ndarray
        The raw ``[q, q']`` samples ``(2n, P, T)``, DOF by DOF (vehicle, then attachments)
        [m, rad, m/s, rad/s].
    accelerations : ndarray
        Their ``q''`` ``(n, P, T)`` [m/s^2, rad/s^2].
    road : ndarray
        Road height under each wheel ``(N, 1, T)`` [m].
    road_vel : ndarray
        Its rate ``(N, 1, T)`` [m/s].
    diverged_at : ndarray
        Time a design diverged ``(P,)`` [s], NaN when it did not.
    designs : dict of str to ndarray
        The design parameters ``(P,)`` by dotted path, in the field's SI unit.
    attachments : tuple of Attachment
        The body attachments (a seat and its passenger).
    held_damping : Held or ndarray or None
        The semi-active dampers' coefficients [N s/m] (held between samples), or None.
    controller_records : mapping of str to Held
        What the controller decided at each sample, by record name (units in
        ``controller_units``).
    controller_units : dict of str to str
        SI unit of each controller record.
    metrics : dict of str to ndarray
        The config's metrics ``(P,)`` by name, units in ``metric_units``.
    metric_units : dict of str to str
        SI unit of each metric.
    engine : str
        The integrator that ran: ``numpy`` or ``compiled`` (:mod:`!suspopt.integrator`).
    """

    config: Config
    model: VehicleModel
    time: np.ndarray
    states: np.ndarray
    accelerations: np.ndarray
    road: np.ndarray  # (N, 1, T) road height under each wheel [m]
    road_vel: np.ndarray  # (N, 1, T) [m/s]
    diverged_at: np.ndarray
    designs: dict[str, np.ndarray]
    _assembled: Assembled
    attachments: tuple[Attachment, ...] = ()
    held_damping: Held | np.ndarray | None = None
    controller_records: Mapping[str, Held] = field(default_factory=dict)
    controller_units: dict[str, str] = field(default_factory=dict)
    metrics: dict[str, np.ndarray] = field(default_factory=dict)
    metric_units: dict[str, str] = field(default_factory=dict)
    engine: str = "numpy"

    def __post_init__(self):
        self._signal_cache: dict[str, np.ndarray] = {}
        self._table = signal_table(self.model, self.controller_units, self.attachments)
        self._deformation: dict[tuple[str, bool], np.ndarray] = {}
        self._bases: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
        self._forces: dict[str, tuple[np.ndarray, np.ndarray]] = {}
        self._damping_full: np.ndarray | None = None

    @property
    def signals(self) -> SignalMap:
        """Signal name -> (P, T) array, computed on first use and cached."""
        return SignalMap(self)

    def signal_unit(self, name: str) -> str:
        """SI unit of a signal of this result."""
        return _row(self._table, name).unit

    def to_xarray(
        self, group: str = "signals", signals: Sequence[str] | None = None, float32: bool = False
    ):
        """This result as an ``xarray.Dataset``, without a file (:mod:`!suspopt.layout`).

        It is the Dataset ``suspopt.io.open_dataset(path, group)`` reads from the file that
        ``suspopt.io.write_simulation(path, result, signals, float32)`` writes
        (docs/guide/results.md): the same variables, dimensions ``design`` and ``time``
        with their coordinates, ``units`` in each variable's attrs, and the provenance in
        the Dataset's attrs (``suspopt_version``, ``config``, ``seed``, ``command``, and
        ``created``: now).

        Parameters
        ----------
        group : str
            ``signals`` (each ``(design, time)`` in its SI unit), ``metrics`` (``(design,)``),
            ``designs`` (``X (design, variable)``, when design parameters were given),
            ``modal`` (``frequency`` [Hz], ``label``, ``energy_share``) or ``""`` (the root:
            ``diverged_at`` [s]).
        signals : list of str, optional
            The signals of ``signals`` (default every signal of the result).
        float32 : bool
            Signals as float32, as ``output.float32: true`` writes them.

        Returns
        -------
        xarray.Dataset
            KeyError for a group the result has not.
        """
        from .io import root_attrs
        from .layout import group_dataset, group_name, simulation_tables

        groups = simulation_tables(self, signals, float32, only={"", group_name(group)})
        return group_dataset(groups, group, {"": root_attrs(self.config)}, "this Result")

    def to_dataframe(self, group: str = "signals", signals: Sequence[str] | None = None):
        """:meth:`to_xarray` of ``group`` as a tidy pandas DataFrame
        (:func:`!suspopt.layout.frame`).

        Parameters
        ----------
        group : str
            ``signals``: long, one row per (design, time [s]), a column per signal;
            ``metrics``, ``designs`` (a column per parameter) and ``""`` (``diverged_at``):
            one row per design; ``modal``: one row per (design, mode, dof).
        signals : list of str, optional
            The signals (default every signal of the result).

        Returns
        -------
        pandas.DataFrame
            Each column's SI unit in ``df.attrs["units"]`` (column -> unit).
        """
        from .layout import frame

        return frame(self.to_xarray(group, signals))

    def plot(
        self,
        signals: Sequence[str] | None = None,
        designs: Sequence[int] | None = None,
        design_names: Sequence[str] | None = None,
    ):
        """The figure of ``suspopt simulate --plot`` (:func:`!suspopt.plots.result_figure`).

        One row per signal: its time history [s] (left), a line per design, and its Welch
        PSD (right); axes labelled ``name [unit]``, a legend naming the designs below; then
        the ISO 2631-1 weighted r.m.s. of the accelerations a person feels (Annex C.2.3).

        Parameters
        ----------
        signals : list of str, optional
            Signal names (default the body's heave acceleration, each corner's travel and
            tyre deflection, and the seat's and head's acceleration where there is a seat).
        designs : list of int, optional
            Design indices to draw (default every design, or 12 evenly spaced by index).
        design_names : list of str, optional
            One name per design of the result, in the legend instead of ``#i``.

        Returns
        -------
        matplotlib.figure.Figure
            ``fig.savefig("run.png")`` writes it. ValueError for an unknown signal or a
            design out of range.
        """
        from .plots import result_figure

        return result_figure(self, signals, designs, design_names)

    def metric(self, spec, name: str) -> np.ndarray:
        """The (P,) values of metric spec ``spec`` on signal ``name`` (:mod:`!suspopt.specs`)."""
        from .specs import METRICS

        return METRICS[spec.metric].compute(spec, self, name)

    @property
    def P(self) -> int:
        return self.states.shape[1]

    @property
    def n(self) -> int:
        """Number of DOFs (vehicle and attachments)."""
        return self._assembled.n

    @property
    def diverged(self) -> np.ndarray:
        """(P,) True where the design's simulation diverged."""
        return ~np.isnan(self.diverged_at)

    @property
    def q(self) -> np.ndarray:
        """Displacements of every DOF (vehicle, then attachments), (P, T, n) (a view)."""
        return np.moveaxis(self.states[: self.n], 0, -1)

    @property
    def v(self) -> np.ndarray:
        """Velocities of every DOF, (P, T, n) (a view)."""
        return np.moveaxis(self.states[self.n :], 0, -1)

    def damping_coefficient(self) -> np.ndarray:
        """Damper coefficient of every corner, (N, P, T) or (N, P, 1) when passive [N s/m]."""
        if self.damping_history is None:
            return self.model.network.group("suspension").damping
        return self.damping_history

    @property
    def damping_history(self) -> np.ndarray | None:
        """(N, P, T) damping coefficients of a controlled run [N s/m], None when passive."""
        if self.held_damping is None or isinstance(self.held_damping, np.ndarray):
            return self.held_damping
        if self._damping_full is None:
            self._damping_full = self.held_damping.full()
        return self._damping_full

    def deformation(self, group: str, rate: bool = False) -> np.ndarray:
        """Deformations (or their rates) of a vehicle element group, (m, P, T): ``suspension``
        the travel ST [m], ``tyre`` the tyre deflection TD [m], ``anti_roll_bar`` the twist."""
        key = (group, rate)
        if key not in self._deformation:
            g = self.model.network.group(group)
            nv = self.model.n_dof
            x = self.states[self.n : self.n + nv] if rate else self.states[:nv]
            self._deformation[key] = g.deformation(x, self.road_vel if rate else self.road)
        return self._deformation[key]

    def element_forces(self, group: str) -> tuple[np.ndarray, np.ndarray]:
        """The elastic and viscous forces (m, P, T) [N] of a vehicle element group (the
        suspension's spring force F_K and damper force F_C, Eq 2.30-2.32; the tyre's
        F_T parts, Eq 2.28-2.29), with the controller's damping where it has one."""
        if group not in self._forces:
            damping = self.damping_history if group == "suspension" else None
            with np.errstate(over="ignore", invalid="ignore"):  # (a diverging design: inf)
                self._forces[group] = self.model.network.group(group).parts_at(
                    self.deformation(group), self.deformation(group, rate=True), damping
                )
        return self._forces[group]

    def acceleration(self) -> np.ndarray:
        """Accelerations of every DOF, (n, P, T): the equations of motion at each sample, as
        the integrator evaluated them."""
        return self.accelerations

    def base(self, j: int, x: np.ndarray) -> np.ndarray:
        """Body displacement (velocity, acceleration) at attachment ``j``'s point, (P, T),
        from the vehicle rows of ``x (n_vehicle, P, T)``."""
        row = self.model.point_map(*self.attachments[j].point)
        with np.errstate(over="ignore", invalid="ignore"):  # (a diverging design: inf, NaN)
            return np.tensordot(row, x[: self.model.n_dof], axes=1)

    def attachment_signal(self, j: int, compute: Callable[..., np.ndarray]) -> np.ndarray:
        """A signal of attachment ``j`` (P, T) from its states and the floor's
        (``compute(q, v, acc, base, base_vel, base_acc)``, :class:`!Attachment`)."""
        nv = self.model.n_dof
        start = nv + sum(len(a.dof_names) for a in self.attachments[:j])
        sl = slice(start, start + len(self.attachments[j].dof_names))
        n = self.n
        q, v, acc = self.states[:n], self.states[n:], self.acceleration()
        if j not in self._bases:  # (computed once for every signal of the attachment)
            self._bases[j] = (self.base(j, q), self.base(j, v), self.base(j, acc))
        return compute(q[sl], v[sl], acc[sl], *self._bases[j])

    def channel(self, deriv: str, j: int) -> np.ndarray:
        """DOF ``j`` displacement (''), velocity ('vel') or acceleration ('acc'), (P, T)."""
        if deriv == "":
            return self.states[j]
        if deriv == "vel":
            return self.states[self.n + j]
        return self.acceleration()[j]
