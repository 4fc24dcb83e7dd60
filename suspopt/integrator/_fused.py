"""The compiled engine's regular RK4 step fused for one network: generated, compiled, cached.

:mod:`._kernel` walks the packed network (:func:`.compiled._packed`) entry by entry, each
entry a loop over the block's lanes: general, but every stage stores and reloads its
deformations and forces, and a loop's set-up is paid per entry. For a run without a
controller sampled in the kernel and with one road for every design, the kernel can instead
call two functions written for this network's structure (its entries' rows and columns, its
laws and where each value sits in ``par``, all constants): one lane loop per call, the whole
stage (or the three remaining stages and the update of a regular step) in its body, in
registers. The compiler vectorises that loop over :data:`LANES` lanes (a block of that many
designs, its rows' offsets constants), and the arithmetic is :mod:`._kernel`'s, operation
for operation (sums started at zero in the same entry order, the stages scaled by their
step, the laws' closures), so a design gives the same bits on either path
(``tests/test_compiled.py``). A law's division by zero gives inf or NaN here (numpy's
rule, which the divergence check then reports) where :mod:`._kernel` would raise.

Only numbers from the packing reach the source: integers (rows, columns, offsets, law
codes) and the literals written here; the laws are the kernel's own function
(:func:`._kernel._law_value`), inlined. The source goes to a file named by its hash in the
user's cache (``$SUSPOPT_CACHE_DIR/fused``, else ``$XDG_CACHE_HOME/suspopt/fused`` or
``~/.cache/suspopt/fused``), written whole (a temporary file, then renamed), so that numba's
``cache=True`` keeps the compiled functions for later processes: about 2 s of compilation per
structure and machine on its first use. What runs is the text generated in this process,
compiled under that file's name, never the file read back. Where the cache cannot be
written, :func:`steps` returns None and the kernel walks the network. A source file there
that is damaged (not UTF-8) is written anew, and numba reads a damaged copy of its own as a
missing one (:mod:`suspopt._numba_cache`).
"""

from __future__ import annotations

import hashlib
import os
import sys
import threading
import types
from pathlib import Path

import numpy as np

#: Designs per block on the fused path: 16 took 4.0 ms per evaluation's integration of the
#: Ch. 5 problem at 200 designs, 32 4.8 ms, 64 5.3 ms and 8 10.7 ms (the step's other work,
#: samples and checks, per block), against 7.4 ms for the general kernel (2026-12-05).
LANES = 16
#: The fewest designs a run takes the fused path with (:func:`.compiled._fusable`). Once
#: compiled, the fused path was as fast or faster at every size (``Problem.evaluate`` of the
#: Ch. 5 problem, 2026-12-05: 3.3-3.6 against 3.8-4.0 ms at 1 design, 3.5-3.8 against
#: 4.5-4.6 ms at 8, 8.7-10.1 against 11.2-11.7 ms at 64); the bound spares a run of a few
#: designs, which takes milliseconds, the first compilation of its network (about 1.5 s).
MIN_DESIGNS = 64
#: The fused functions' C signatures: ``first(W, par, u, has_input, h)`` and
#: ``regular(W, par, u_mid, u_end, mid_has_input, end_has_input, dt)``, the arrays as
#: pointers to a block's ``W`` and ``par`` and to the inputs' row ``(2R,)``.
FIRST = "void(CPointer(float64), CPointer(float64), CPointer(float64), int64, float64)"
REGULAR = (
    "void(CPointer(float64), CPointer(float64), CPointer(float64), CPointer(float64), "
    "int64, int64, float64)"
)
#: The blocks of ``W`` the fused step touches (:data:`._kernel.Y`, :data:`._kernel.S1`).
_Y, _S1 = 0, 2


def _structure(idx: np.ndarray, lay: np.ndarray) -> dict:
    """The packed network's entries as (row, column, value row) lists, its laws as (code,
    element, first parameter row), the offsets of k, c and the inverse masses."""
    nD, nG, R, X, n = (int(v) for v in lay[:5])
    oD, oG, oK, oC, oL, oM = (int(v) for v in lay[5:11])
    i = [int(v) for v in idx]
    base = 2 * nD + 2 * nG
    return {
        "n": n,
        "R": R,
        "D": [(i[z], i[nD + z], oD + z) for z in range(nD)],
        "G": [(i[2 * nD + z], i[2 * nD + nG + z], oG + z) for z in range(nG)],
        "laws": [(i[base + x], i[base + X + x], oL + 5 * x) for x in range(X)],
        "oK": oK,
        "oC": oC,
        "oM": oM,
    }


def _par(p: int) -> str:
    return f"par[{p * LANES} + b]"


def _law(code: int, d: str, f: str, p: int) -> str:
    """The force ``f`` with law ``code``'s part at ``δ = d``: the kernel's own
    :func:`._kernel._law_value`, its parameters the law's five rows of ``par``."""
    return f"_law_value({code}, {d}, {f}, " + ", ".join(_par(p + k) for k in range(5)) + ")"


def _stage(s: dict, q: list[str], v: list[str], inputs: tuple[str, str], scale: int, h: str,
           tag: str) -> list[str]:  # fmt: skip
    """Lines of one stage at the state ``q, v`` (expressions per DOF): ``δ, δ̇`` row by row
    from zero, the inputs' row ``u`` added when ``has``, ``F = k δ + c δ̇`` and the laws,
    ``q'' = M^-1 G F`` (inverse masses' row set ``scale``) into ``sv{i}{tag}`` and ``h q'``
    into ``sq{i}{tag}`` (:func:`._kernel._stage`'s order)."""
    u, has = inputs
    n, R, lines, started = s["n"], s["R"], [], set()
    for r, j, p in s["D"]:
        d0, v0 = ("0.0", "0.0") if r not in started else (f"d{r}{tag}", f"v{r}{tag}")
        started.add(r)
        lines += [
            f"d{r}{tag} = {d0} + {_par(p)} * {q[j]}",
            f"v{r}{tag} = {v0} + {_par(p)} * {v[j]}",
        ]
    for r in range(R):
        lines += [
            f"d{r}{tag} = d{r}{tag} + {u}{r} if {has} else d{r}{tag}",
            f"v{r}{tag} = v{r}{tag} + {u}{R + r} if {has} else v{r}{tag}",
            f"f{r}{tag} = {_par(s['oK'] + r)} * d{r}{tag} + {_par(s['oC'] + r)} * v{r}{tag}",
        ]
    for code, r, p in s["laws"]:
        lines.append(f"f{r}{tag} = " + _law(code, f"d{r}{tag}", f"f{r}{tag}", p))
    G = s["G"]
    for z, (i, r, p) in enumerate(G):
        first = z == 0 or G[z - 1][0] != i
        lines.append(f"a{i}{tag} = {'0.0' if first else f'a{i}{tag}'} + {_par(p)} * f{r}{tag}")
        if z == len(G) - 1 or G[z + 1][0] != i:  # the DOF's last entry
            lines.append(f"sv{i}{tag} = a{i}{tag} * {_par(s['oM'] + scale * n + i)}")
            lines.append(f"sq{i}{tag} = {v[i]} * {h}")
    return lines


def _w(block: int, row: int, n: int) -> str:
    return f"W[{(block * 2 * n + row) * LANES} + b]"


def source(idx: np.ndarray, lay: np.ndarray) -> str:
    """The module of the two fused functions for the network packed as ``idx, lay``."""
    s = _structure(idx, lay)
    n, R = s["n"], s["R"]
    head = ["import numba", "", "from suspopt.integrator._kernel import _law_value", ""]
    loads = [f"    {name}{r} = {name}[{r}]" for name in ("u", "w") for r in range(2 * R)]
    first = _stage(s, [_w(_Y, j, n) for j in range(n)], [_w(_Y, n + j, n) for j in range(n)],
                   ("u", "has"), 0, "h", "")  # fmt: skip
    first += [f"{_w(_S1, i, n)} = sq{i}" for i in range(n)]
    first += [f"{_w(_S1, n + i, n)} = sv{i}" for i in range(n)]
    body = [f"y{i} = {_w(_Y, i, n)}" for i in range(2 * n)]
    body += [f"sq{i}_0 = {_w(_S1, i, n)}" for i in range(n)]
    body += [f"sv{i}_0 = {_w(_S1, n + i, n)} * half" for i in range(n)]
    for k, (inputs, h) in enumerate(((("u", "mid"), "half"), (("u", "mid"), "dt"),
                                     (("w", "end"), "sixth")), start=1):  # fmt: skip
        body += [f"x{j}_{k} = y{j} + 1.0 * sq{j}_{k - 1}" for j in range(n)]
        body += [f"x{n + j}_{k} = y{n + j} + 1.0 * sv{j}_{k - 1}" for j in range(n)]
        q, v = [f"x{j}_{k}" for j in range(n)], [f"x{n + j}_{k}" for j in range(n)]
        body += _stage(s, q, v, inputs, k, h, f"_{k}")

    def slope(k: int, i: int) -> str:
        return f"sq{i}_{k}" if i < n else f"sv{i - n}_{k}"

    body += [
        f"{_w(_Y, i, n)} = y{i} + ((((({slope(0, i)} + {slope(2, i)}) + {slope(1, i)} * 2.0)"
        f" * third) + {slope(3, i)}))"
        for i in range(2 * n)
    ]
    jit = "@numba.cfunc({!r}, cache=True, nogil=True, error_model='numpy')"
    return (
        "\n".join(
            head
            + [jit.format(FIRST), "def first(W, par, u, has, h):"]
            + loads[: 2 * R]
            + [f"    for b in range({LANES}):"]
            + ["        " + line for line in first]
            + ["", "", jit.format(REGULAR), "def regular(W, par, u, w, mid, end, dt):"]
            + ["    half = 0.5 * dt", "    sixth = dt / 6.0", "    third = 1.0 / 3.0"]
            + loads
            + [f"    for b in range({LANES}):"]
            + ["        " + line for line in body]
        )
        + "\n"
    )


def cache_dir() -> Path:
    """Where the generated modules (and numba's compiled copies) are kept: ``fused`` in
    suspopt's cache folder (:func:`suspopt._numba_cache.cache_root`)."""
    from .._numba_cache import cache_root

    return cache_root() / "fused"


#: The functions loaded in this process, by packed structure.
_LOADED: dict[bytes, tuple | None] = {}


def steps(idx: np.ndarray, lay: np.ndarray) -> tuple | None:
    """The compiled ``(first, regular)`` of the network packed as ``idx, lay``, or None
    when the generated module cannot be kept (the cache not writable)."""
    key = b"steps|" + idx.tobytes() + b"|" + lay.tobytes()
    if key not in _LOADED:
        _LOADED[key] = load(source(idx, lay), ("first", "regular"))
    return _LOADED[key]


def load(text: str, names: tuple[str, ...]) -> tuple | None:
    """The functions ``names`` of the generated module ``text``, compiled (module
    docstring: the file kept under its hash, the text of this process run), or None when the
    cache cannot be written."""
    digest = hashlib.sha256(text.encode()).hexdigest()[:24]
    try:
        folder = cache_dir()
    except RuntimeError:  # (no home directory to be found)
        return None
    path = folder / f"fused_{digest}.py"
    try:
        kept = path.read_text(encoding="utf-8") if path.is_file() else None
    except (OSError, UnicodeDecodeError):  # (a damaged file is written anew)
        kept = None
    try:
        if kept != text:
            folder.mkdir(parents=True, exist_ok=True)
            temporary = folder / f".{path.name}.{os.getpid()}.{threading.get_ident()}.tmp"
            temporary.write_text(text)
            os.replace(temporary, path)
    except OSError:
        return None
    # the text generated here runs, never the file's (which numba's cache keys on)
    module = types.ModuleType(f"suspopt_fused_{digest}")
    module.__file__ = str(path)
    sys.modules[module.__name__] = module  # (numba's cache finds the module by its name)
    from .. import _numba_cache

    _numba_cache.prepare()  # (numba's damaged copy of the module: compiled again)
    what = "the kernel's reductions" if "accumulate" in names else "the fused step"
    with _numba_cache.compiling(f"{what} of this network", folder):
        exec(compile(text, str(path), "exec"), module.__dict__)
    return tuple(getattr(module, name) for name in names)
