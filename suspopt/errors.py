"""The error every part of suspopt raises for bad input (a light module: the command line
catches it before anything heavy is imported).

A :class:`ConfigError` holds one :class:`Problem` or several (``exc.problems``): ``suspopt
validate`` lists them all, one line each; every other command prints ``str(exc)``, the first
problem and how many more there are. A :class:`Problems` collects them, from the checks of a
config that can run independently of each other. Problems of severity ``warning`` (a value
that looks like a unit slip, :mod:`suspopt.config.plausible`) never reject anything: they
are ``exc.warnings`` or ``cfg.warnings`` and ``validate`` prints them.
"""

from __future__ import annotations

import difflib
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, replace
from typing import Any

__all__ = [
    "require_like",
    "InputError",
    "ConfigError",
    "Problem",
    "Problems",
    "check_known",
    "require",
    "suggest",
    "type_name",
]


@dataclass(frozen=True)
class Problem:
    """One located problem of an input: ``where`` the file (or another name of the input),
    ``line`` its 1-based line (None when the key and every key above it are absent),
    ``key`` the dotted YAML key path (empty when the problem is the file's), ``message`` in
    the user's terms and ``severity`` ``error`` or ``warning``. A problem made from a
    message alone (``where`` empty) is that message."""

    where: str
    line: int | None
    key: str
    message: str
    severity: str = "error"

    def __str__(self) -> str:
        if not self.where:
            return self.message
        at = f"{self.where}:{self.line}" if self.line else self.where
        return f"{at}: {self.key}: {self.message}" if self.key else f"{at}: {self.message}"


class InputError(ValueError):
    """Bad input, whatever it is: a config, an argument, a file given to read (a missing,
    foreign or damaged result file included) or an output that cannot be written. The
    command line makes it exit code 2 with its one line. ``ConfigError`` is the same class
    (its name before it covered more than configs).

    ``str(exc)`` is one line naming the file, line and key path (or the file
    and the dataset) of its first problem, followed by ``(+K more: HINT)`` when it holds
    ``K`` more (``HINT`` says how to see them, e.g. ``run suspopt validate case.yaml``).

    ``ConfigError(message)`` holds one problem, the message; ``ConfigError(problems=...)``
    holds those problems (the errors; ``warnings`` holds the warnings found with them)."""

    def __init__(
        self,
        message: str | None = None,
        problems: Sequence[Problem] = (),
        warnings: Sequence[Problem] = (),
        hint: str | None = None,
    ):
        if not problems:
            problems = (Problem("", None, "", str(message)),)
        self.problems: tuple[Problem, ...] = tuple(problems)
        self.warnings: tuple[Problem, ...] = tuple(warnings)
        self.hint = hint
        if message is None:
            message = str(self.problems[0])
            more = len(self.problems) - 1
            if more:
                message += f" (+{more} more" + (f": {hint})" if hint else ")")
        super().__init__(message)

    def __reduce__(self):  # (pickled between processes: keep the problems)
        return (_rebuild, (str(self), self.problems, self.warnings, self.hint))


#: The name :class:`InputError` had while it stood for a config's errors only; the same class.
ConfigError = InputError


def _rebuild(message, problems, warnings, hint) -> InputError:
    return InputError(message, problems, warnings, hint)


class Problems:
    """A collector of the problems of one input (``where``, its lines ``line_of(key path)``
    and the ``hint`` of :class:`ConfigError`): checks that do not depend on each other add
    theirs, :meth:`attempt` runs a check that raises and keeps its problems, and
    :meth:`raise_if_any` raises them all as one ConfigError."""

    def __init__(
        self,
        where: str = "",
        line_of: Callable[[tuple], int | None] | None = None,
        hint: str | None = None,
    ):
        self.where = where
        self.line_of = line_of or (lambda loc: None)
        self.hint = hint
        self.errors: list[Problem] = []
        self.warnings: list[Problem] = []

    def __bool__(self) -> bool:
        return bool(self.errors)

    def problem(self, loc: tuple, message: str, severity: str = "error") -> Problem:
        """The problem of ``message`` at the key path ``loc`` (a tuple of keys and indices)."""
        return Problem(self.where, self.line_of(tuple(loc)), dotted(loc), message, severity)

    def add(self, loc: tuple, message: str, severity: str = "error") -> None:
        """Add a problem at ``loc``; ``severity="warning"`` for one that rejects nothing."""
        found = self.problem(loc, message, severity)
        (self.warnings if severity == "warning" else self.errors).append(found)

    def extend(self, exc: ConfigError) -> None:
        """Add the problems of ``exc``."""
        self.errors.extend(exc.problems)
        self.warnings.extend(exc.warnings)

    def attempt(self, check: Callable[..., Any], *args: Any, **kwargs: Any) -> Any:
        """``check(*args, **kwargs)``, or :data:`FAILED` when it raised a ConfigError, whose
        problems are kept: the next independent check runs all the same."""
        try:
            return check(*args, **kwargs)
        except ConfigError as exc:
            self.extend(exc)
            return FAILED

    def error(self) -> ConfigError:
        """The ConfigError of the errors found (at least one), each once."""
        return ConfigError(
            problems=list(dict.fromkeys(self.errors)),
            warnings=list(dict.fromkeys(self.warnings)),
            hint=self.hint,
        )

    def raise_if_any(self) -> None:
        if self.errors:
            raise self.error()


#: What :meth:`Problems.attempt` returns for a check that failed.
FAILED: Any = type("Failed", (), {"__repr__": lambda self: "FAILED", "__bool__": lambda s: False})()


def dotted(loc: Iterable) -> str:
    """``("metrics", 0, "signal")`` -> ``metrics[0].signal``."""
    return "".join(
        f"[{p}]" if isinstance(p, int) else (f".{p}" if i else str(p)) for i, p in enumerate(loc)
    )


def with_message(problem: Problem, message: str) -> Problem:
    """``problem`` with another message."""
    return replace(problem, message=message)


def suggest(name: object, known: Iterable[str], n: int = 3, cutoff: float = 0.6) -> list[str]:
    """The (at most ``n``) entries of ``known`` closest to ``name``, each once, best first:
    the "did you mean" of a message."""
    return difflib.get_close_matches(str(name), list(dict.fromkeys(known)), n=n, cutoff=cutoff)


def type_name(value: object) -> str:
    """The type of ``value`` for a message, and the value itself when it is short."""
    shown = repr(value)
    return type(value).__name__ + (f" {shown}" if len(shown) <= 60 else "")


def require(value, kind: type, argument: str, how: str):
    """``value`` when it is a ``kind``, else a TypeError naming ``argument`` and ``how`` to make
    one: the library's entry points call it first, so that another object given (a path where
    the loaded file belongs) is not an AttributeError from deep inside."""
    if not isinstance(value, kind):
        raise TypeError(f"{argument} must be a {kind.__name__} ({how}); got {type_name(value)}")
    return value


def require_like(value, kind: str, attributes: Iterable[str], argument: str, how: str):
    """``value`` when it has every one of ``attributes``, else :func:`require`'s TypeError
    naming ``kind``: for the code of a layer below ``kind``'s (the figures of
    :mod:`suspopt.plots`), which knows it by what it holds, not by importing its class."""
    if not all(hasattr(value, name) for name in attributes):
        raise TypeError(f"{argument} must be a {kind} ({how}); got {type_name(value)}")
    return value


def check_known(what: str, name: str, known: Iterable[str]) -> str:
    """Return ``name`` if it is in ``known``, else raise ValueError with the closest matches."""
    known = list(dict.fromkeys(known))
    if name not in known:
        close = suggest(name, known)
        raise ValueError(
            f"unknown {what} {name!r}"
            + (f"; did you mean {', '.join(close)}?" if close else f"; known: {', '.join(known)}")
        )
    return name
