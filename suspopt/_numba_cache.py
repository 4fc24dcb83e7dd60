"""numba's cache, whose damaged files numba reads as an error instead of a miss.

numba (0.68 at least) raises ``EOFError`` or an unpickling error when a file of its cache is
truncated or overwritten (a disk that filled up, a copy cut short, a stray write), where a
missing file makes it compile again; every later run of the compiled engine then fails, in
every process, until someone deletes the file. :func:`heal` makes numba treat such a file as
missing, as a change pending in numba does: the function compiles again and its cache is
written anew. It wraps the two methods of ``numba.core.caching.IndexDataCacheFile`` that read
the index and the data, once per process, and only where numba has them; nothing else of
numba's changes. It holds for every cached numba function of the process, suspopt's or not
(a damaged file is then compiled again where numba would have raised). The modules that compile with ``cache=True`` call it before their first
function (``suspopt.integrator._kernel``, ``._accumulate``, ``suspopt.loops._compiled``, and
``suspopt.integrator._fused`` before a generated module).

**Where the cache lives** (:func:`prepare`): numba keys its cache on the folder of the
source file, so every install of suspopt (each virtual environment, a wheel, a checkout)
compiled the kernel again, a minute or more each time. :class:`MachineCacheLocator` keeps
the compiled functions of suspopt's own modules in ``cache_root() / "numba"``
(``$SUSPOPT_CACHE_DIR/numba``, else ``$XDG_CACHE_HOME/suspopt/numba`` or
``~/.cache/suspopt/numba``), in a folder named by a digest of the sources numba compiles
(``suspopt/integrator``, ``suspopt/control`` and ``suspopt/loops``) and the version: every install of the same
code on a machine shares one compile, and a change to any of those files (numba's own cache
does not see a change in a file that a cached function calls into) compiles anew. numba
still checks each file's own content and the machine's CPU before it uses an entry. Where
that folder cannot be written, or where ``NUMBA_CACHE_DIR`` is set (numba's own choice),
numba's locators apply as before.

**Compiles are said** (:func:`prepare`, :func:`compiling`): a compile of suspopt's numba
code is told to :mod:`suspopt._notices` (``compile-start``, ``compile-end`` with its wall
time), which the command line shows as a live indicator on stderr; without a listener it is
logged on the ``suspopt`` logger.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import logging
import os
import pickle
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from . import _notices

__all__ = [
    "heal",
    "prepare",
    "cache_root",
    "kernel_cache",
    "compiling",
    "compiled_available",
    "INSTALL_FAST",
]

#: What to install for the compiled engine and the compiled loops of the metrics.
INSTALL_FAST = "pip install numba (a dependency of suspopt; this platform may lack its wheels)"


@functools.cache
def compiled_available() -> bool:
    """Whether numba can be imported (the compiled engine's and the compiled metric loops'
    one dependency), without importing it; looked up once per process."""
    import importlib.util

    return importlib.util.find_spec("numba") is not None


#: What unpickling a damaged file raises (the bytes decide which).
_DAMAGED = (
    EOFError,
    pickle.UnpicklingError,
    ValueError,
    TypeError,
    AttributeError,
    ImportError,
    IndexError,
    KeyError,
    MemoryError,
)


def heal() -> None:
    """Make numba read a damaged file of its cache as a missing one (module docstring)."""
    from numba.core import caching

    files: Any = getattr(caching, "IndexDataCacheFile", None)
    load_index = getattr(files, "_load_index", None)
    load_data = getattr(files, "_load_data", None)
    if load_index is None or load_data is None or getattr(files, "_suspopt_heals", False):
        return

    def _load_index(self):
        try:
            return load_index(self)
        except _DAMAGED:
            return {}  # (no entry: compiled again, and the index written anew)

    def _load_data(self, name):
        try:
            return load_data(self, name)
        except _DAMAGED:
            # numba's load() takes an OSError for a data file gone: a miss, compiled again
            raise OSError(f"numba's cache file {name} is damaged") from None

    files._load_index = _load_index
    files._load_data = _load_data
    files._suspopt_heals = True


def cache_root() -> Path:
    """suspopt's cache folder: ``$SUSPOPT_CACHE_DIR``, else ``$XDG_CACHE_HOME/suspopt`` or
    ``~/.cache/suspopt`` (RuntimeError where no home directory can be found). A ``~`` that no
    shell expanded (an environment file) is expanded here."""
    if os.environ.get("SUSPOPT_CACHE_DIR"):
        return Path(os.environ["SUSPOPT_CACHE_DIR"]).expanduser()
    xdg = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(xdg) / "suspopt"


#: The package folders whose modules numba compiles (their digest names the cache folder).
_COMPILED_PACKAGES = ("integrator", "control", "loops")
_PACKAGE = Path(__file__).resolve().parent


@functools.cache
def _digest() -> str:
    """A digest of suspopt's version and the sources numba compiles, read once a process."""
    from ._version import __version__

    h = hashlib.sha256(__version__.encode())
    for folder in _COMPILED_PACKAGES:
        for path in sorted((_PACKAGE / folder).glob("*.py")):
            h.update(path.name.encode() + b"\0" + path.read_bytes() + b"\0")
    return h.hexdigest()[:16]


def kernel_cache() -> Path | None:
    """The folder that keeps the compiled kernel of this code on this machine, or None where
    numba's own locators apply (``NUMBA_CACHE_DIR`` set, or no home directory)."""
    if os.environ.get("NUMBA_CACHE_DIR"):
        return None
    try:
        return cache_root() / "numba" / _digest()
    except (RuntimeError, OSError):
        return None


def _locator_class() -> Any:
    """:class:`MachineCacheLocator`, made once numba is imported (it subclasses numba's)."""
    from numba.core import caching

    class MachineCacheLocator(caching._SourceFileBackedLocatorMixin, caching._CacheLocator):
        """Keeps suspopt's compiled functions in :func:`kernel_cache` (module docstring);
        declines every other file, and where that folder cannot be written."""

        def __init__(self, py_func, py_file):
            self._py_file = py_file
            self._lineno = py_func.__code__.co_firstlineno
            relative = Path(py_file).resolve().parent.relative_to(_PACKAGE)
            folder = kernel_cache()
            assert folder is not None
            self._cache_path = str(folder / "_".join(relative.parts or ("suspopt",)))

        def get_cache_path(self):
            return self._cache_path

        @classmethod
        def from_function(cls, py_func, py_file):
            try:
                inside = Path(py_file).resolve().is_relative_to(_PACKAGE)
            except (OSError, ValueError):
                return None
            if not inside or kernel_cache() is None:
                return None
            return super().from_function(py_func, py_file)

    return MachineCacheLocator


def _listener() -> Any:
    """A listener of numba's ``numba:compile`` events that tells the compiles of suspopt's
    functions as :func:`compiling` does: the outermost one opens the stretch and its end
    closes it (numba compiles what a function calls inside its own compile)."""
    from numba.core import event

    class CompileListener(event.Listener):
        depth = 0
        opened: Any = None

        def on_start(self, ev) -> None:
            self.depth += 1
            if self.depth == 1:
                dispatcher = (ev.data or {}).get("dispatcher")
                module = getattr(getattr(dispatcher, "py_func", None), "__module__", "") or ""
                if module.startswith("suspopt"):
                    self.opened = compiling("the simulation kernel")
                    self.opened.__enter__()

        def on_end(self, ev) -> None:
            self.depth -= 1
            if self.depth == 0 and self.opened is not None:
                opened, self.opened = self.opened, None
                opened.__exit__(None, None, None)

    return CompileListener()


_prepared = threading.Lock()
_done: list[bool] = []


def prepare() -> None:
    """Before a module's first cached numba function: damaged cache files read as misses
    (:func:`heal`), suspopt's functions cached for the machine (``MachineCacheLocator``)
    and their compiles told (:func:`compiling`); once per process."""
    with _prepared:
        if _done:
            return
        try:  # (numba cannot compile in a folder that is gone: it raised from deep inside)
            os.getcwd()
        except FileNotFoundError:
            from .errors import InputError

            raise InputError("the current folder no longer exists; cd to one that does") from None
        heal()
        from numba.core import caching, event

        impl: Any = getattr(caching, "CacheImpl", None) or getattr(caching, "_CacheImpl", None)
        locators = list(getattr(impl, "_locator_classes", None) or [])
        if locators and not any(c.__name__ == "MachineCacheLocator" for c in locators):
            impl._locator_classes = [_locator_class(), *locators]
        event.register("numba:compile", _listener())
        _done.append(True)


_log = logging.getLogger("suspopt")
#: The shortest stretch logged when nobody listens [s] (a cache's load takes less).
LOGGED_SECONDS = 1.0
_depth = threading.local()


@contextlib.contextmanager
def compiling(what: str, cache: Path | None = None) -> Iterator[None]:
    """A stretch of code that may compile ``what`` (or load it from the cache): told as
    ``compile-start`` and ``compile-end`` (:mod:`suspopt._notices`) with its wall time and
    the folder that keeps it (``cache``, default :func:`kernel_cache`); an inner stretch
    inside an outer one is part of it."""
    depth = getattr(_depth, "value", 0)
    _depth.value = depth + 1
    start = time.perf_counter()
    try:
        if depth == 0:
            _notices.tell("compile-start", what=what)
        yield
    finally:
        _depth.value = depth
        if depth == 0:
            seconds = time.perf_counter() - start
            cache = cache if cache is not None else kernel_cache()
            told = _notices.tell("compile-end", what=what, seconds=seconds, cache=cache)
            if not told and seconds >= LOGGED_SECONDS:
                _log.info("compiled %s in %.1f s (kept in %s)", what, seconds, cache)
