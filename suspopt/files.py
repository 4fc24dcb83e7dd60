"""Reading a file a user names as input, within bounds.

An input path may name something that is not a file to read: a directory, a FIFO (reading
one waits for a writer that may never come), a device (``/dev/zero`` never ends) or a
regular file far larger than what it claims to be. :func:`read_bounded` opens the path
without blocking, reads only a regular file and never more than ``limit + 1`` bytes, so
none of these can hang suspopt or make it allocate without bound. The callers (the YAML
config reader, the road profile reader) word the reason into their own messages.
"""

from __future__ import annotations

import os
import stat
import sys
from pathlib import Path

from .memory import describe

__all__ = ["Unreadable", "kind_of", "read_bounded", "listed", "status", "is_hdf5"]


def listed(items) -> list:
    """``items`` as a list, one path, string or number being one item (a library call given
    ``"front.h5"`` where it takes several files read it letter by letter before)."""
    return [items] if isinstance(items, (str, os.PathLike, int, float)) else list(items)


class Unreadable(ValueError):
    """Why an input file was not read; ``str(exc)`` is a phrase that follows the file's name
    ("is a FIFO", "cannot read it (Input/output error)", "is larger than 1 MB")."""


def kind_of(mode: int) -> str | None:
    """What a file of ``st_mode`` ``mode`` is ("a directory", "a FIFO" ...), or None for a
    regular file."""
    if stat.S_ISREG(mode):
        return None
    if stat.S_ISDIR(mode):
        return "a directory"
    if stat.S_ISLNK(mode):
        return "a symbolic link"
    if stat.S_ISFIFO(mode):
        return "a FIFO"
    if stat.S_ISSOCK(mode):
        return "a socket"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    return "an unknown kind of file"


def link_kind(path) -> tuple[bool, str | None]:
    """``(exists, kind)`` of the name ``path`` itself, a link not followed: whether it exists
    and, where it is no regular file, what it is (:func:`kind_of`); an OSError other than a
    missing name passes."""
    try:
        mode = os.lstat(path).st_mode
    except FileNotFoundError:
        return False, None
    return True, kind_of(mode)


def _reason(exc: OSError) -> str:
    return exc.strerror or exc.__class__.__name__


def status(path: str | Path) -> os.stat_result | None:
    """``os.stat`` of what ``path`` names (a symlink followed), or None when it, or a folder on
    its way, is missing. :class:`Unreadable` when the system cannot tell: a name longer than
    the system takes, a folder that may not be searched, a symlink loop. (``Path.exists``
    raises OSError for the first two, which reached the user as a traceback.)"""
    try:
        return os.stat(path)
    except (FileNotFoundError, NotADirectoryError):
        return None
    except OSError as exc:
        raise Unreadable(f"cannot inspect it ({_reason(exc)})") from None
    except ValueError:  # (a NUL in the name, which no argument list can hold, but a call can)
        raise Unreadable("is no valid file name (it holds a NUL)") from None


def is_hdf5(path: str | Path) -> bool:
    """Whether ``path`` is an HDF5 file by its signature (a command's source may be a YAML
    config or a result file). False for anything that cannot be opened or read, which the
    YAML reader then words (:func:`read_bounded`: ``/proc/self/mem`` is a regular file that
    gives an I/O error), and for a FIFO or a device, which are never read."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except (OSError, ValueError):
        return False
    try:
        return stat.S_ISREG(os.fstat(fd).st_mode) and os.read(fd, 8) == b"\x89HDF\r\n\x1a\n"
    except OSError:
        return False
    finally:
        os.close(fd)


def read_bounded(path: str | Path, limit: int) -> bytes:
    """The bytes of the regular file ``path``, of at most ``limit`` bytes.

    Raises FileNotFoundError for a missing file and :class:`Unreadable` for anything else
    that is not read: not a regular file (a symlink is followed to what it names), a file
    that cannot be opened or read (a regular file may still fail to read: ``/proc/self/mem``
    gives an I/O error), one larger than ``limit``, or an output the running command has
    claimed (:func:`suspopt.io.is_output`: a road profile that ``-o`` names, which the
    command would replace, even with ``--force``).
    """
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except FileNotFoundError:
        raise
    except IsADirectoryError:
        raise Unreadable("is a directory") from None
    except OSError as exc:
        raise Unreadable(f"cannot open it ({_reason(exc)})") from None
    kind = kind_of(os.fstat(fd).st_mode)
    if kind is not None:
        os.close(fd)
        raise Unreadable(f"is {kind}")
    io = sys.modules.get(__package__ + ".io")  # (no output is claimed before it is imported)
    if io is not None and io.is_output(path):
        os.close(fd)
        raise Unreadable("is an output of this command, which writing would replace it")
    try:
        with os.fdopen(fd, "rb") as stream:
            data = stream.read(limit + 1)
    except OSError as exc:
        raise Unreadable(f"cannot read it ({_reason(exc)})") from None
    if len(data) > limit:
        raise Unreadable(f"is larger than {describe(limit)}")
    return data
