"""The lock of an output that one writer holds (:func:`suspopt.io.claim`), and what a killed
writer left.

A writer holds an exclusive ``flock`` on ``.NAME.suspopt-lock`` beside the output ``NAME``
for as long as it writes. The lock file holds three lines of text: the writer's process id,
when it took the lock (UTC ISO 8601) and its command line (cut to :data:`LOCK_COMMAND_CHARS`
characters, control characters replaced); it is removed when the writer ends. A second writer
fails at once with the first one's process id.

A lock file that holds something when its ``flock`` is taken was left by a run that was killed
(its lock died with its process); so were the temporary files ``.NAME.*.suspopt-tmp`` that
the new writer finds. It removes them and says so in one line, kept for :func:`take_notes`
(the command line prints it as ``note: ...`` on stderr; the library prints nothing)::

    front.h5: removed a lock and 1 temporary file left by a run that was killed (process
    1234, started 2026-05-01T09:12:44+00:00: suspopt optimise study.yaml -o front.h5)

A lock file is read as untrusted input: at most :data:`LOCK_READ_BYTES` of it, each line
checked (a process id of digits, a time that parses, printable text); one with garbage,
binary or huge content is cleared all the same, its note saying that it does not tell which
run it was. An empty one is reused without a word (a writer makes it just before it locks
it). A lock name that is not a regular file (a directory, a FIFO, a symbolic link) is not
suspopt's: the writer refuses it, naming it.
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import os
import stat
import sys
from datetime import UTC, datetime
from pathlib import Path

from .errors import ConfigError
from .files import link_kind

__all__ = [
    "LOCK_SUFFIX",
    "LOCK_COMMAND_CHARS",
    "LOCK_READ_BYTES",
    "take_lock",
    "take_notes",
    "this_command",
]

#: The ending of a lock file's name: ``.NAME.suspopt-lock``.
LOCK_SUFFIX = ".suspopt-lock"
#: The longest command line a lock file keeps [characters].
LOCK_COMMAND_CHARS = 500
#: The most of a lock file read back [bytes] (its three lines take at most about 600).
LOCK_READ_BYTES = 4096
#: What :func:`claim` cleared of killed runs, for :func:`take_notes`.
_notes: list[str] = []
#: Control characters a lock file's command line does not keep (all of C0 and DEL, C1).
_CONTROL = dict.fromkeys([*range(32), 127, *range(128, 160)], "?")


def take_notes() -> list[str]:
    """The lines saying what :func:`claim` removed that killed runs had left (module
    docstring), oldest first, since the last call; they are forgotten once taken. The library
    prints nothing: the command line prints them as ``note: ...``."""
    taken = list(_notes)
    _notes.clear()
    return taken


def this_command() -> str:
    """This process's command line as its user typed it (``suspopt optimise study.yaml -o
    front.h5``, for ``python -m suspopt`` too), for a lock file."""
    import shlex

    args = [str(a) for a in sys.argv] or ["python"]
    program = Path(args[0]).name
    if program in ("suspopt", "__main__.py"):
        return shlex.join(["suspopt", *args[1:]])
    return shlex.join(args)


def _lock_text(command: str | None) -> bytes:
    """The lock file's three lines: process id, start (UTC), command line (bounded)."""
    command = (this_command() if command is None else command).translate(_CONTROL)
    if len(command) > LOCK_COMMAND_CHARS:
        command = command[: LOCK_COMMAND_CHARS - 3] + "..."
    started = datetime.now(UTC).isoformat(timespec="seconds")
    return f"{os.getpid()}\n{started}\n{command}\n".encode("utf-8", "replace")


def _lock_owner(head: bytes) -> str:
    """Which run a lock file's first bytes ``head`` say took it: ``process 1234, started
    TIME: COMMAND`` (each part only when it reads well), or that they do not say."""
    lines = head.decode("utf-8", "replace").split("\n")
    pid = lines[0].strip()
    if not (pid.isdigit() and pid.isascii() and len(pid) <= 10):
        return "its lock file does not say which run it was"
    said = f"process {int(pid)}"
    started = lines[1].strip() if len(lines) > 1 else ""
    if started and len(started) <= 40:
        with contextlib.suppress(ValueError):  # (a time that does not parse is left out)
            said += f", started {datetime.fromisoformat(started).isoformat()}"
    command = " ".join(lines[2].translate(_CONTROL).split()) if len(lines) > 2 else ""
    if command:
        cut = command[:LOCK_COMMAND_CHARS]
        said += f": {cut}" + ("..." if len(command) > LOCK_COMMAND_CHARS else "")
    return said


def _leftovers_note(path: Path, head: bytes, temporary: int) -> str | None:
    """The line saying what was removed beside ``path`` (module docstring): a lock that held
    ``head``, and ``temporary`` files; None when nothing was."""
    parts = ["a lock"] if head else []
    if temporary:
        parts.append(f"{temporary} temporary file{'s' if temporary != 1 else ''}")
    if not parts:
        return None
    owner = f" ({_lock_owner(head)})" if head else ""
    return f"{path}: removed {' and '.join(parts)} left by a run that was killed{owner}"


def take_lock(path: Path, option: str, command: str | None, temporary: str) -> tuple[Path, int]:
    """Take the lock of the output ``path`` (module docstring): its lock file's name and its
    descriptor, holding the ``flock`` and this run's lines; what a killed run left (its lock
    and its temporary files, ``.NAME.*`` ending in ``temporary``) removed and noted.
    ConfigError when another process holds it, or it cannot be written (naming ``option``)."""
    lock = path.with_name(f".{path.name}{LOCK_SUFFIX}")
    while True:
        _check_lock_kind(path, lock)
        try:
            fd = os.open(
                lock,
                os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_CLOEXEC | os.O_NONBLOCK,
                0o644,
            )
        except OSError as exc:
            raise ConfigError(f"{path}: cannot write in {path.parent} ({exc.strerror})") from None
        if not stat.S_ISREG(os.fstat(fd).st_mode):  # (made in the moment since the check)
            os.close(fd)
            continue
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as exc:
            first = os.pread(fd, 32, 0).decode(errors="replace").split("\n")[0].strip()
            owner = first if first.isdigit() else "?"
            os.close(fd)
            if exc.errno in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                raise ConfigError(
                    f"{path}: another suspopt run (process {owner}) is writing "
                    f"it; wait for it to finish or choose another output"
                ) from None
            raise
        try:  # the lock file may have been removed and made anew
            same = os.stat(lock, follow_symlinks=False).st_ino == os.fstat(fd).st_ino
        except FileNotFoundError:
            same = False
        if same:
            break
        os.close(fd)
    try:
        head = os.pread(fd, LOCK_READ_BYTES, 0)  # (a killed run's; empty for a new lock)
        os.ftruncate(fd, 0)
        os.pwrite(fd, _lock_text(command), 0)
    except OSError as exc:  # (a full disk: even the lock's few bytes do not fit)
        lock.unlink(missing_ok=True)
        os.close(fd)
        raise ConfigError(
            f"{option} {path}: cannot write in {path.parent} ({exc.strerror})"
        ) from None
    _clear_leftovers(path, head, temporary)
    return lock, fd


def _clear_leftovers(path: Path, head: bytes, temporary: str) -> None:
    """Remove the temporary files a killed writer left beside ``path`` and note them with
    the lock it left, which held ``head`` (:func:`take_notes`)."""
    removed = 0
    for stale in path.parent.glob(f".{_glob_escape(path.name)}.*{temporary}"):
        with contextlib.suppress(OSError):  # (gone meanwhile, or a folder: not suspopt's)
            stale.unlink()
            removed += 1
    note = _leftovers_note(path, head, removed)
    if note is not None:
        _notes.append(note)


def _glob_escape(name: str) -> str:
    return "".join(f"[{c}]" if c in "*?[" else c for c in name)


def _check_lock_kind(path: Path, lock: Path) -> None:
    """ConfigError when the lock's name is taken by something that is not a regular file
    (a directory, a FIFO, a symbolic link): not suspopt's lock, and not to be opened."""
    try:
        _, kind = link_kind(lock)
    except OSError as exc:
        raise ConfigError(f"{path}: cannot inspect {lock} ({exc.strerror})") from None
    if kind is not None:
        raise ConfigError(
            f"{path}: {lock} is {kind}, not suspopt's lock file; remove it or choose another output"
        )
