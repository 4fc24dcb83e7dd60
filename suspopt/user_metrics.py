"""User-defined metrics: a function of one signal, registered under a name that a config then
uses wherever a built-in metric goes (``metrics:``, ``objectives:``, ``constraints:``).

Two ways to register one (docs/guide/custom-metrics.md):

- from Python, with the :func:`metric` decorator (or :func:`register`), before the config
  is loaded::

      @suspopt.metric(name="peak_jerk", unit=lambda u: f"{u}/s")
      def peak_jerk(x, t):
          return np.abs(np.gradient(x, t, axis=-1)).max(axis=-1)

- from an installed package, with an entry point of the group :data:`GROUP`
  (``suspopt.metrics``), ``peak_jerk = mypackage.metrics:peak_jerk``: loaded the first time a
  config names a metric that is not built in, so that nothing is imported otherwise. The
  object it names is a function decorated as above, or a plain function (then the metric has
  its signal's unit and its docstring's first line as description).

The function takes the signal's samples ``(P, T)`` (SI units, read-only) and the output
times ``(T,)`` [s], and returns one value per design, ``(P,)``, in SI units: batch first, no
loop over the designs. A value that is not finite marks its design failed, as a diverged
run does. The metric is a :class:`suspopt.specs.MetricDef` of kind ``user`` and stream mode
``keep``: on either engine, in a streamed evaluation (:mod:`suspopt.streaming`) its signal is
kept whole and the function runs once on it, exactly as on a whole :class:`Result`. What it
returns is checked: a value of the wrong shape, or an exception in the function, is a
:class:`~suspopt.errors.ConfigError` (one line naming the metric and its function, exit 2 on
the command line), not a traceback from deep inside numpy.

A name may not be a built-in metric's. Registering a name again replaces the user metric (a
notebook cell run twice).

Workers of the ``processes`` and ``dask`` executors (:mod:`suspopt.execution`) need the
metric too: a config's spec carries where its metric came from (:class:`Source`), and
unpickling it in a worker imports that module, or loads that entry point, first. A metric
registered in a script's ``__main__`` therefore reaches only ``processes`` workers (which
run the script's module again, ``spawn``); for Dask put it in a module the workers can
import, or in an entry point.
"""

from __future__ import annotations

import importlib
import re
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from .errors import ConfigError, check_known
from .specs import METRICS, MetricDef

__all__ = ["GROUP", "BUILT_IN", "Source", "metric", "register", "unregister", "check_metric"]

#: The entry point group of installed packages' metrics.
GROUP = "suspopt.metrics"
#: The names of suspopt's own metrics, which a user metric may not take.
BUILT_IN = frozenset(METRICS)
#: What a metric's name may be: a letter or ``_``, then letters, digits and ``_``.
NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
#: The attribute :func:`metric` sets on the function it registers: the metric's name.
MARK = "__suspopt_metric__"


@dataclass(frozen=True)
class Source:
    """Where the user metric ``name`` was registered: in ``module`` (by :func:`register`),
    or by the entry point ``name`` of :data:`GROUP` (``entry_point``). Unpickled (in a
    worker), it registers the metric again first if that process does not have it."""

    name: str
    module: str
    entry_point: bool = False

    def __reduce__(self):
        return (_restore, (self.name, self.module, self.entry_point))


_SOURCES: dict[str, Source] = {}


def metric(
    name: str | None = None,
    *,
    unit: str | Callable[[str], str] | None = None,
    description: str | None = None,
) -> Callable[[Callable], Callable]:
    """Register the decorated function as a metric that configs name like a built-in one.

    The function takes a signal's samples ``x`` ``(P, T)`` (SI units, read-only) and the
    output times ``t`` ``(T,)`` [s] and returns one value per design ``(P,)``, in SI units,
    without a loop over the designs; a value that is not finite marks its design failed.
    Registration must happen before a config that names the metric is loaded
    (docs/guide/custom-metrics.md).

    Parameters
    ----------
    name : str, optional
        The metric's name in YAML (``metric: NAME``): letters, digits and ``_``, not a
        built-in metric's. Default the function's name; registering a name again replaces
        the user metric.
    unit : str or callable, optional
        The metric's SI unit: a fixed unit (``"m/s^3"``), a function of the signal's unit
        (``lambda u: f"({u})/s"``), or None (default) for the signal's own unit.
    description : str, optional
        One line on what it measures (default the docstring's first line).

    Returns
    -------
    callable
        A decorator that registers the function and returns it unchanged.

    Examples
    --------
    >>> import numpy as np, suspopt
    >>> @suspopt.metric(name="peak_jerk", unit=lambda u: f"({u})/s")
    ... def peak_jerk(x, t):
    ...     return np.abs(np.diff(x, axis=-1)).max(axis=-1) / (t[1] - t[0])
    """

    def decorate(function: Callable) -> Callable:
        register(function, name or function.__name__, unit=unit, description=description)
        return function

    return decorate


def register(
    function: Callable,
    name: str,
    unit: str | Callable[[str], str] | None = None,
    description: str | None = None,
    _entry_point: bool = False,
) -> MetricDef:
    """Register ``function(x (P, T), t (T,)) -> (P,)`` as the metric ``name`` (module
    docstring) and return its :class:`~suspopt.specs.MetricDef`. Raises ValueError for a
    name that is a built-in metric's or not a plain identifier, TypeError for a function or
    unit that is not callable."""
    if not isinstance(name, str) or not NAME.match(name):
        raise ValueError(f"a metric's name is letters, digits and _ (not {name!r})")
    if name in BUILT_IN:
        raise ValueError(
            f"metric {name!r} is built into suspopt; give the user metric another name"
        )
    if not callable(function):
        raise TypeError(f"metric {name!r}: {function!r} is not a function")
    if isinstance(unit, str):
        fixed = unit
        unit = lambda _u: fixed  # noqa: E731
    elif unit is None:
        unit = _same
    elif not callable(unit):
        raise TypeError(f"metric {name!r}: unit must be a str or a function of the signal's unit")
    doc = (function.__doc__ or "").strip().splitlines()
    where = f"{function.__module__}.{getattr(function, '__qualname__', repr(function))}"
    definition = MetricDef(
        "user",
        unit,
        description or (doc[0] if doc else f"user metric ({where})"),
        _checked(name, where, function),
        stream="keep",
    )
    METRICS[name] = definition
    _SOURCES[name] = Source(name, function.__module__, _entry_point)
    setattr(function, MARK, name)
    return definition


def unregister(name: str) -> None:
    """Forget the user metric ``name`` (KeyError if there is none; a built-in stays)."""
    if name in BUILT_IN or name not in METRICS:
        raise KeyError(f"no user metric {name!r}")
    del METRICS[name]
    _SOURCES.pop(name, None)


def source(name: str | None) -> Source | None:
    """Where the metric ``name`` was registered, or None for a built-in (or none)."""
    return _SOURCES.get(name) if name is not None else None


def _same(u: str) -> str:
    return u


def _checked(name: str, where: str, function: Callable) -> Callable[[Any, Any, str], np.ndarray]:
    """A :class:`~suspopt.specs.MetricDef`'s ``compute`` that calls ``function`` on the
    signal and checks what it returns: real values of shape (P,)."""

    def compute(spec, result, signal: str) -> np.ndarray:
        x = np.asarray(result.signals[signal]).view()
        x.flags.writeable = False  # (the Result's cached signal)
        t = np.asarray(result.time).view()
        t.flags.writeable = False
        try:
            out = function(x, t)
        except Exception as exc:
            what = " ".join(f"{type(exc).__name__}: {exc}".split())
            raise ConfigError(f"metric {name!r} ({where}) failed on {signal}: {what}") from exc
        values = np.asarray(out)
        P = x.shape[0]
        if values.dtype.kind not in "biuf" or values.shape != (P,):
            got = f"{values.dtype} values" if values.dtype.kind not in "biuf" else "values"
            raise ConfigError(
                f"metric {name!r} ({where}) gave {got} of shape {values.shape} on {signal} "
                f"{x.shape}; it must give one real number per design, shape ({P},)"
            )
        return values.astype(float)

    return compute


def _entry_points() -> list:
    """The installed entry points of :data:`GROUP` (not loaded); ValueError for one that
    takes a built-in metric's name."""
    from importlib.metadata import entry_points

    found = list(entry_points(group=GROUP))
    for ep in found:
        if ep.name in BUILT_IN:
            raise ValueError(
                f"entry point {ep.name} = {ep.value} ({GROUP}"
                + (f", package {ep.dist.name}" if ep.dist is not None else "")
                + ") takes a built-in metric's name; rename it"
            )
    return found


def _load(name: str) -> bool:
    """Load the entry point ``name`` of :data:`GROUP`, if there is one, and register its
    metric; whether it did. Raises ValueError for one that fails to load or is not a
    metric's function."""
    found = [ep for ep in _entry_points() if ep.name == name]
    if not found:
        return False
    ep = found[0]
    try:
        loaded = ep.load()
    except Exception as exc:
        what = " ".join(f"{type(exc).__name__}: {exc}".split())
        raise ValueError(
            f"metric {name!r}: entry point {ep.value} ({GROUP}) fails: {what}"
        ) from exc
    marked = getattr(loaded, MARK, None)
    if marked is not None and marked != name:
        raise ValueError(
            f"entry point {name} = {ep.value} ({GROUP}) names a function registered as "
            f"metric {marked!r}; give both the same name"
        )
    if marked is None:
        register(loaded, name, _entry_point=True)
    else:
        _SOURCES[name] = Source(name, _SOURCES[name].module, True)
    return True


def check_metric(name: str) -> str:
    """``name`` if it is a built-in metric, a registered one or an installed entry point's
    (loaded now), else a ValueError that suggests the closest of all of them."""
    if name in METRICS or _load(name):
        return name
    installed = (ep.name for ep in _entry_points())
    return check_known("metric", name, dict.fromkeys([*METRICS, *installed]))


def _restore(name: str, module: str, entry_point: bool) -> Source:
    """A :class:`Source` unpickled: the metric registered in this process first. When the
    module does not register it here (a ``__main__`` the worker does not run), the metric
    is one whose evaluation is a ConfigError saying so, which the worker sends back."""
    if name not in METRICS:
        if entry_point:
            _load(name)
        else:
            importlib.import_module(module)
    if name not in METRICS:
        message = (
            f"metric {name!r} is registered by module {module!r}, which does not register it "
            "in a worker: define user metrics in a module the workers import, or in an "
            f"entry point ({GROUP}); docs/guide/custom-metrics.md"
        )

        def missing(spec, result, signal: str) -> np.ndarray:
            raise ConfigError(message)

        METRICS[name] = MetricDef("user", _same, message, missing, stream="keep")
    return _SOURCES.get(name, Source(name, module, entry_point))
