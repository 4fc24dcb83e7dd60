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
function (``._kernel``, ``._accumulate``, ``._reductions``, and ``._fused`` before a
generated module).
"""

from __future__ import annotations

import pickle
from typing import Any

__all__ = ["heal"]

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
