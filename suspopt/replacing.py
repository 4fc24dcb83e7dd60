"""Replacing a result: when a command may write over an existing result file, the suffix an
output must have, and a result's figure replaced together with it.

**Another result** (:func:`refusal`): an HDF5 result records the config it was made from
(root attribute ``config``, the YAML text after any ``--set``) and, when a command wrote it,
the request that made it (root attribute ``request``, JSON: the command, and its options
that change the result, such as ``analyse builds --samples``; :func:`request_of`). A command
that would write onto a result of another config or another request is refused unless it is
given ``--force`` (``optimise`` also takes ``--resume``, which continues the stored run),
in one line naming the file and the first differences::

    front.h5 holds a front of another config (optimiser.generations 40, not 10); give
    --force to replace it or --resume to continue it

A result of the same config and request is replaced without a word: it is the same result
again (the runs are seeded), so running a command twice gives what running it once does.
The old file is never touched when the command is refused: the check reads it before
anything is written (the request when the output is claimed, before any work; the config
before the run or at the first write, once it is known), and the new file is written aside
and renamed over it.

**Suffixes** (:func:`check_suffix`): an output's suffix must name what is written into it;
``-o out.csv`` for an HDF5 writer is refused (:data:`SUFFIXES`).

**Figures** (:func:`together`): ``--plot FIG`` is written with its result as one: both are
written aside and renamed at the end of the command, so that a failed run leaves both old
files; a run whose result must land as it goes (``optimise``'s checkpoints) renames its result
at once, and its old figure, no longer of that result, is removed when the run ends without
a new one. A result records its figure (root attribute ``plot``, the path from the result's
folder), which ``optimise --resume`` rewrites without being given ``--plot`` again.
"""

from __future__ import annotations

import contextlib
import json
import os
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

from .errors import ConfigError

__all__ = [
    "SUFFIXES",
    "Guard",
    "admit",
    "check_suffix",
    "remove_figure",
    "is_suspopt_output",
    "OUTPUT_MARKER",
    "refusal",
    "request_of",
    "stored_plot",
    "together",
]

#: The suffixes each kind of output may have (lower case).
SUFFIXES = {
    "hdf5": (".h5", ".hdf5", ".he5", ".nc"),
    "html": (".html", ".htm"),
    "yaml": (".yaml", ".yml"),
    "figure": (".png", ".svg"),
    "fmu": (".fmu",),
}
_FORMAT_NAMES = {
    "hdf5": "HDF5",
    "html": "HTML",
    "yaml": "YAML",
    "figure": "a figure",
    "fmu": "an FMU (FMI 2.0)",
}
#: What a result of each command holds, for :func:`refusal`'s line.
_HOLDS = {
    "optimise": "a front",
    "kesort": "a k-ε selection",
    "simulate": "a simulation",
    "analyse": "an analysis",
}
#: The most differences :func:`refusal` names.
_SHOWN = 2


def check_suffix(path: str | Path, kind: str, option: str = "-o") -> None:
    """ConfigError when ``path``'s suffix is not one of ``kind``'s (:data:`SUFFIXES`):
    ``-o out.csv`` for an HDF5 writer wrote HDF5 into a ``.csv``."""
    allowed = SUFFIXES[kind]
    suffix = Path(path).suffix.lower()
    if suffix not in allowed:
        given = f"ends in {Path(path).suffix}" if suffix else "has no suffix"
        raise ConfigError(
            f"{option} {path}: {given}, but this writes {_FORMAT_NAMES[kind]}; "
            f"give a name ending in {', '.join(allowed)}"
        )


@dataclass
class Guard:
    """What a claimed output may replace (:func:`suspopt.io.claim`): ``request`` the JSON-able
    request of the command writing it (:func:`request_of`), ``force`` and ``resume`` as given;
    ``plot`` the figure written with it (or None); ``checked`` once the first write of the
    run was let replace what the file held; ``stale`` the figure of the result it replaces,
    of another config or request, which no figure of this run replaces (removed with it)."""

    request: dict
    force: bool = False
    resume: bool = False
    plot: Path | None = None
    checked: bool = False
    stale: Path | None = None


def request_of(command: str, parameters: list, given: dict, skip: set[str]) -> dict:
    """The request of ``command`` (module docstring) given the values ``given`` of its
    ``parameters`` (``inspect.Parameter``, their defaults typer's options): each option by
    its longest flag (``{"command": "analyse", "kind": "builds", "--samples": 200}``), paths
    and lists as text. Left out: the names in ``skip`` (outputs, how the run is executed),
    the input files (arguments of paths: what they hold is in the result's config) and
    options at None, False or an empty list."""
    request: dict = {"command": command}
    for p in parameters:
        value = given.get(p.name)
        kind = type(p.default).__name__
        decls = getattr(p.default, "param_decls", None) or ()
        if p.name in skip or (kind == "ArgumentInfo" and "Path" in str(p.annotation)):
            continue
        if value is None or value == [] or value is False:
            continue
        if isinstance(value, (list, tuple)):
            value = [os.path.normpath(v) if isinstance(v, Path) else v for v in value]
        elif isinstance(value, Path):
            value = os.path.normpath(value)
        request[max(decls, key=len) if decls else p.name] = value
    return json.loads(json.dumps(request, default=str))


def _stored(path: Path) -> tuple[str | None, dict | None]:
    """The config text and the request a result file records (None where it has none)."""
    from .h5read import H5Reader

    with H5Reader(path) as h5:
        text = h5.text_attr("config") if h5.has_attr("config") else None
        request = None
        if h5.has_attr("request"):
            with contextlib.suppress(ValueError):
                loaded = json.loads(h5.text_attr("request"))
                request = loaded if isinstance(loaded, dict) else None
    return text, request


def _flat(value, prefix: str = "") -> dict:
    """A config's dump as ``{"optimiser.generations": 40, ...}``."""
    if isinstance(value, dict):
        found: dict = {}
        for key, item in value.items():
            found.update(_flat(item, f"{prefix}.{key}" if prefix else str(key)))
        return found
    if isinstance(value, list) and any(isinstance(v, (dict, list)) for v in value):
        found = {}
        for i, item in enumerate(value):
            found.update(_flat(item, f"{prefix}[{i}]"))
        return found
    return {prefix: value}


def _differences(old: dict, new: dict) -> list[str]:
    """``key old, not new`` for each key whose value differs (in ``old``'s order)."""
    keys = list(old) + [k for k in new if k not in old]
    return [
        f"{key} {_said(old, key)}, not {_said(new, key)}"
        for key in keys
        if old.get(key) != new.get(key)
    ]


def _said(values: dict, key: str) -> str:
    """The value of ``key`` as a command line gives it (a list as its items), or unset."""
    if key not in values:
        return "unset"
    value = values[key]
    if isinstance(value, list):
        return " ".join(str(v) for v in value)
    return str(value)


def _config_differences(stored: str, text: str, source) -> list[str]:
    """How the config text ``text`` differs from ``stored`` (none: the same config; one
    that cannot be read back is another config without saying how)."""
    from .config.loader import load_config_text

    if stored == text:
        return []
    try:
        old = load_config_text(stored, source).model_dump(mode="json")
        new = load_config_text(text, source).model_dump(mode="json")
    except ConfigError:
        return ["its text differs"]
    return _differences(_flat(old), _flat(new))


def _described(differences: list[str]) -> str:
    more = len(differences) - _SHOWN
    return "; ".join(differences[:_SHOWN]) + (f"; {more} more" if more > 0 else "")


def refusal(path: Path, text: str | None, guard: Guard, source=None) -> str | None:
    """Why the existing result ``path`` may not be replaced by a result of the config text
    ``text`` (None: not known yet) and ``guard``'s request (module docstring) without
    ``--force``, or None when it may: it does not exist, is no result of suspopt, or is of
    the same config and request."""
    from .files import is_hdf5, status

    if status(path) is None or not is_hdf5(path):
        return None
    try:
        stored_text, stored_request = _stored(path)
    except ConfigError:
        return None  # (not a result: check_target has judged whether it may be replaced)
    if stored_text is None and stored_request is None:
        return None
    asked = guard.request.get("command")
    command = (stored_request or {}).get("command", asked)
    holds = _HOLDS.get(str(command), "a result")
    changed = (
        _config_differences(stored_text, text, source)
        if stored_text is not None and text is not None
        else []
    )
    if command != asked:
        why = f"another command (suspopt {command}, not {asked})"
    elif changed:
        why = f"another config ({_described(changed)})"
    elif stored_request is not None and stored_request != guard.request:
        why = f"other options ({_described(_differences(stored_request, guard.request))})"
    else:
        return None
    resume = " or --resume to continue it" if asked == "optimise" else ""
    return f"{path} holds {holds} of {why}; give --force to replace it{resume}"


def admit(path: Path, text: str, guard: Guard, source=None) -> None:
    """Let the result of the config text ``text`` replace what ``path`` holds (once: the
    guard is then ``checked``), or ConfigError saying why not (:func:`refusal`; ``--resume``
    continues the stored run, which its reader checks, and ``--force`` replaces anything).
    The figure the old result records stays recorded when this run writes none and the
    result is the same; of another result, it is removed with it (``guard.stale``)."""
    from .files import is_hdf5, status

    if guard.checked:
        return
    why = None if guard.resume else refusal(path, text, guard, source)
    if why is not None and not guard.force:
        raise ConfigError(why)
    old = stored_plot(path) if status(path) is not None and is_hdf5(path) else None
    if guard.plot is None and old is not None:
        if why is None:
            guard.plot = old
        else:
            guard.stale = old
    guard.checked = True


#: The text by which suspopt knows a file other than HDF5 as its own (in its first
#: :data:`_HEAD` bytes: a figure's metadata, a CSV's first line).
OUTPUT_MARKER = "suspopt"
_HEAD = 4096


def is_suspopt_output(path: Path) -> bool:
    """Whether the regular file ``path`` was written by suspopt (:mod:`suspopt.io`'s docstring). A config
    (a file ending in a config signature, or any ``.yaml``/``.yml`` file) is suspopt's only
    while its signature matches its lines: once edited it is the user's, and ``init`` or
    ``export`` run again replace it only with ``--force``."""
    return _not_ours(path) is None


def _not_ours(path: Path) -> str | None:
    """Why suspopt may not replace the regular file ``path`` without ``--force``, or None
    (:func:`is_suspopt_output`)."""
    from .signature import CONFIG_SUFFIXES, signature_state  # (not at start-up)

    foreign = "exists and was not written by suspopt"
    with open(path, "rb") as stream:
        head = stream.read(_HEAD)
        size = os.fstat(stream.fileno()).st_size
    if head.startswith(b"\x89HDF\r\n\x1a\n"):
        from .h5read import H5Reader

        try:  # (a damaged file, one that crashes or hangs the HDF5 library included, is
            with H5Reader(path) as reader:  # not known to be suspopt's)
                return None if reader.has_attr("suspopt_version") else foreign
        except ConfigError:
            return foreign
    signed = signature_state(path, size)
    if signed is False:
        return "was edited since suspopt wrote it"
    if signed is None and path.suffix.lower() in CONFIG_SUFFIXES:
        return foreign
    return None if signed or OUTPUT_MARKER.encode() in head else foreign


def remove_figure(path: Path) -> None:
    """Remove the figure ``path`` if it is a regular file that suspopt wrote."""

    if path.is_file() and not path.is_symlink():
        with contextlib.suppress(OSError):
            if is_suspopt_output(path):
                path.unlink()


def stored_plot(path: Path) -> Path | None:
    """The figure the result ``path`` records (root attribute ``plot``), where it exists."""
    from .h5read import H5Reader

    try:
        with H5Reader(path) as h5:
            if not h5.has_attr("plot"):
                return None
            figure = path.parent / h5.text_attr("plot")
    except ConfigError:
        return None
    return figure if figure.suffix.lower() in SUFFIXES["figure"] else None


@dataclass
class _Group:
    """Outputs written as one (:func:`together`): ``members`` their keys, result first;
    ``hold`` whether renames wait for the end; ``pending`` key -> temporary file written;
    ``landed`` the keys renamed into place."""

    members: list[Path]
    hold: bool
    pending: dict[Path, Path] = field(default_factory=dict)
    landed: set[Path] = field(default_factory=set)


#: The groups of outputs open now (:func:`together`).
_groups: list[_Group] = []


def _group_of(key: Path) -> _Group | None:
    return next((g for g in _groups if key in g.members), None)


def deferred(key: Path, tmp: Path) -> bool:
    """Whether the temporary file ``tmp``, written for the output ``key`` (its resolved
    folder and name), waits for its group's end instead of being renamed now (it is then
    kept in the group; an earlier one for ``key`` is removed). False for an output of no
    group, or of a group that does not hold, or a figure whose result has landed."""
    group = _group_of(key)
    if group is None:
        return False
    if not group.hold or (key != group.members[0] and group.members[0] in group.landed):
        group.landed.add(key)
        return False
    old = group.pending.pop(key, None)
    if old is not None:
        old.unlink(missing_ok=True)
    group.pending[key] = tmp
    return True


@contextmanager
def together(paths: list[Path], hold: bool, commit) -> Iterator[None]:
    """The outputs ``paths`` (keys as :func:`suspopt.io.claim` makes them; the result first,
    its figure after) written as one for the block (module docstring). ``hold``: the renames
    wait for the block's end, where ``commit(tmp, key)`` renames each, result first; on an
    exception they are removed. Without ``hold`` each lands when written, and a figure that
    did not land when its result did is removed at the end (it is of the old result)."""
    group = _Group(list(paths), hold)
    _groups.append(group)
    ok = False
    try:
        yield
        ok = True
    finally:
        _groups.remove(group)
        pending = [(k, group.pending[k]) for k in group.members if k in group.pending]
        for key, tmp in pending:
            if ok:
                commit(tmp, key)
                group.landed.add(key)
            else:
                tmp.unlink(missing_ok=True)
        _remove_stale(group)


def _remove_stale(group: _Group) -> None:
    """Remove the old figure of a result that landed without its new figure (if suspopt
    wrote it)."""
    if group.members[0] not in group.landed:
        return
    for key in group.members[1:]:
        if key not in group.landed:
            remove_figure(key)
