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

import ctypes
import ctypes.util

__all__ = ["reuse_memory"]

#: mallopt parameters of glibc's malloc.h.
_M_TRIM_THRESHOLD, _M_MMAP_MAX = -1, -4
#: Free memory at the top of the heap kept rather than returned to the kernel [bytes]: the
#: largest value mallopt takes (an int).
_KEEP = 2 ** 31 - 1


def reuse_memory() -> bool:
    """Make glibc's allocator keep freed memory for reuse (``mallopt``: no ``mmap`` for large
    blocks, no trimming of the heap). Returns True when it took effect, False (changing
    nothing) where the C library is not glibc."""
    name = ctypes.util.find_library("c")
    if name is None:
        return False
    try:
        libc = ctypes.CDLL(name)
        libc.gnu_get_libc_version          # glibc only
        mallopt = libc.mallopt
    except (OSError, AttributeError):
        return False
    mallopt.argtypes, mallopt.restype = (ctypes.c_int, ctypes.c_int), ctypes.c_int
    return bool(mallopt(_M_MMAP_MAX, 0)) and bool(mallopt(_M_TRIM_THRESHOLD, _KEEP))
