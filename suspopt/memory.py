"""Reusing freed memory between simulations of the same size.

A batched simulation allocates a few large arrays (the states of 1000 designs over 3000 samples
take 190 MB) and frees them when its result is dropped; an optimiser does this once per
generation. glibc's allocator serves such arrays by ``mmap`` and gives them back to the kernel
on ``free``, so every generation the kernel hands out fresh pages and zeroes them on first
touch - on the 2-core development machine (a virtual machine) that costs a fifth of a
population's evaluation. :func:`reuse_memory` asks the allocator to serve large arrays from its
heap and to keep what is freed, so that the next generation finds the pages already mapped.

The command line calls it for every command; scripts that evaluate many populations can call it
once at the start. The process then keeps its peak memory until it exits.
"""

from __future__ import annotations

import contextlib
import ctypes

__all__ = [
    "reuse_memory",
    "parse_size",
    "set_limit",
    "explicit_limit",
    "available",
    "limit",
    "describe",
    "check",
]

#: mallopt parameters of glibc's malloc.h.
_M_TRIM_THRESHOLD, _M_MMAP_MAX = -1, -4
#: Free memory at the top of the heap kept rather than returned to the kernel [bytes]: the
#: largest value mallopt takes (an int).
_KEEP = 2**31 - 1


def reuse_memory() -> bool:
    """Make glibc's allocator keep freed memory for reuse (``mallopt``: no ``mmap`` for large
    blocks, no trimming of the heap). Returns True when it took effect, False (changing
    nothing) where the C library is not glibc.

    Returns
    -------
    bool
        Whether the setting took effect.
    """
    try:
        # the process's own symbols, the C library's among them (``find_library`` would run
        # ``ldconfig``, or a compiler where that is missing, at every command)
        libc = ctypes.CDLL(None)
        _ = libc.gnu_get_libc_version  # glibc only
        mallopt = libc.mallopt
    except (OSError, AttributeError, TypeError):  # (TypeError: Windows takes no None)
        return False
    mallopt.argtypes, mallopt.restype = (ctypes.c_int, ctypes.c_int), ctypes.c_int
    return bool(mallopt(_M_MMAP_MAX, 0)) and bool(mallopt(_M_TRIM_THRESHOLD, _KEEP))


# --- how much a run may allocate ---------------------------------------------------------------

#: The limit set by ``--max-memory`` (bytes), or None for the memory the machine has free.
_limit: int | None = None
_UNITS = {"": 1, "k": 1 << 10, "m": 1 << 20, "g": 1 << 30, "t": 1 << 40}


def parse_size(text: str) -> int:
    """Bytes of a size such as ``4G``, ``512M``, ``2.5g`` or ``1000000`` (binary units);
    ValueError for anything else."""
    import re

    match = re.fullmatch(r"\s*([0-9]+(?:\.[0-9]*)?)\s*([kKmMgGtT]?)[bB]?\s*", text)
    if match is None:
        raise ValueError(f"{text!r} is not a size (give e.g. 4G, 512M)")
    size = float(match.group(1)) * _UNITS[match.group(2).lower()]
    if not 1 <= size < 1 << 60:
        raise ValueError(f"{text!r} is not a size of memory")
    return int(size)


def set_limit(size: int | None) -> None:
    """Cap what a run may allocate (``--max-memory``); None: the machine's free memory."""
    global _limit
    _limit = size


def explicit_limit() -> int | None:
    """The ``--max-memory`` limit [bytes], or None when none was set."""
    return _limit


def available() -> int:
    """Memory this process may still allocate [bytes]: the kernel's ``MemAvailable``, cut by
    what an address-space limit (``ulimit -v``) leaves beyond what the process holds
    already (:func:`_mapped`), if one is set."""
    return _available()[0]


def _available() -> tuple[int, bool]:
    """:func:`available`, and whether the address-space limit is what bounds it."""
    import os
    import resource

    free = None
    with contextlib.suppress(OSError):  # no /proc: the sysconf figure below
        with open("/proc/meminfo") as info:
            for line in info:
                if line.startswith("MemAvailable:"):
                    free = int(line.split()[1]) * 1024
                    break
    if free is None:
        try:
            free = os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
        except (ValueError, OSError):
            free = 1 << 62
    soft, _ = resource.getrlimit(resource.RLIMIT_AS)
    if soft == resource.RLIM_INFINITY:
        return free, False
    left = max(soft - _mapped(), 0)
    return min(free, left), left <= free


def _mapped() -> int:
    """The address space this process holds now [bytes]: ``VmSize`` (0 where unknown) less
    what the allocator keeps free for reuse (:func:`reuse_memory` keeps freed arrays
    mapped; the next ones are served from them). What an address-space limit has left is
    the limit less this (numpy, scipy and numba alone map several hundred MB)."""
    import os

    try:
        with open("/proc/self/statm") as statm:
            size = int(statm.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return 0
    return max(size - _heap_free(), 0)


class _MallInfo2(ctypes.Structure):
    """glibc's ``struct mallinfo2`` (all ``size_t``)."""

    _fields_ = [
        (name, ctypes.c_size_t)
        for name in (
            "arena", "ordblks", "smblks", "hblks", "hblkhd",
            "usmblks", "fsmblks", "uordblks", "fordblks", "keepcost",
        )
    ]  # fmt: skip


def release_free() -> int:
    """Give the free memory at the top of the heap back to the kernel (glibc's
    ``malloc_trim``, which :func:`reuse_memory`'s setting does not stop) and return the free
    bytes the allocator still holds, in holes between blocks in use, which it serves again
    without mapping anything: an address-space limit set after this bounds only what is
    allocated beyond them [bytes]. Elsewhere than glibc nothing is released and 0 returned."""
    try:
        trim = ctypes.CDLL(None).malloc_trim
    except (OSError, AttributeError, TypeError):
        return 0
    trim.argtypes, trim.restype = (ctypes.c_size_t,), ctypes.c_int
    trim(0)
    return _heap_free()


def _heap_free() -> int:
    """Free bytes the allocator holds for reuse (glibc's ``mallinfo2().fordblks``; 0 where
    the C library has no ``mallinfo2``: glibc before 2.33, or another one)."""
    try:
        mallinfo2 = ctypes.CDLL(None).mallinfo2
    except (OSError, AttributeError, TypeError):
        return 0
    mallinfo2.argtypes, mallinfo2.restype = (), _MallInfo2
    return int(mallinfo2().fordblks)


def limit() -> tuple[int, str]:
    """The allocation limit [bytes] and where it comes from."""
    if _limit is not None:
        return _limit, "the --max-memory limit"
    free, by_rlimit = _available()
    if by_rlimit:
        return free, "what this process's address-space limit (ulimit -v) leaves"
    return free, "the memory this machine has available"


def describe(size: float) -> str:
    """``size`` bytes for a message: 512 MB, 3.2 GB, 44 TB."""
    for unit, scale in (("TB", 1 << 40), ("GB", 1 << 30), ("MB", 1 << 20)):
        if size >= scale:
            return f"{size / scale:.3g} {unit}"
    return f"{size / 1024:.3g} kB"


def check(need: float, what: str, advice: str, cfg=None, key: tuple = ()) -> None:
    """ConfigError when ``need`` bytes exceed the limit (:func:`limit`): the message gives
    the estimate, the limit and ``advice``, located at ``key`` of ``cfg`` (its file and
    line: ``Config.error``) when a config is given."""
    from .errors import ConfigError

    cap, source = limit()
    if need > cap:
        message = (
            f"{what} needs about {describe(need)}, more than {source} ({describe(cap)}); {advice}"
        )
        raise ConfigError(message) if cfg is None else cfg.error(key, message)
