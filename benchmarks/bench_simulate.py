"""Designs simulated per second for the Chapter 5 HC2 problem, at P = 1, 100, 1000 and 10000,
on the numpy engine and (when numba is installed) the compiled engine, in the same run, with
the peak memory of each call (tracemalloc: numpy's arrays included) and the agreement of the
two engines' body accelerations; then the same sizes for objectives and constraints only
(``Problem.evaluate`` of configs/ch5/case1_s1.yaml, which keeps no (P, T) signal it does not
need: :mod:`suspopt.streaming`).

Table 5.1 half car with Duffing springs, half-sine bump 0.05 m (base 1 m) at 40 km/h, 3 s at
dt = 1 ms (configs/quickstart.yaml); designs drawn uniformly inside the Table 5.2 bounds (with
the k_nl range of docs/thesis-slips.md#table-52). Each size is timed as the best of three calls
(the first call of a size also pays the operating system for memory the process has not touched
before). Run:
``python benchmarks/bench_simulate.py [--sizes 1,100,1000,10000]``. Prints a table; asserts
nothing. The compiled engine's first call (compiling, or loading numba's cache) and its first
call of 64 designs (this network's fused step, :mod:`suspopt.integrator._fused`) are printed
first; last, the kernel's share of the machine's peak, from whole ``simulate`` calls and from
the kernel's own calls at P = 1000 (:func:`kernel_rate`).
Like the command line, it first makes the allocator reuse freed memory
(:func:`suspopt.reuse_memory`); ``--default-allocator`` leaves it as it is.
"""

from __future__ import annotations

import platform
import sys
import time
from pathlib import Path

import numpy as np

import suspopt

CONFIG = Path(__file__).resolve().parents[1] / "configs" / "quickstart.yaml"
BOUNDS = {  # Table 5.2 (k_nl range: slip: docs/thesis-slips.md#table-52)
    "vehicle.corners.F1.spring.linear": (3.2e4, 1.5e5),
    "vehicle.corners.R1.spring.linear": (3.2e4, 1.5e5),
    "vehicle.corners.F1.damper.c": (2.0e3, 1.0e4),
    "vehicle.corners.R1.damper.c": (2.0e3, 1.0e4),
    "vehicle.corners.F1.spring.cubic": (5.0e5, 3.0e7),
    "vehicle.corners.R1.spring.cubic": (5.0e5, 3.0e7),
}


def designs(P: int, rng: np.random.Generator) -> dict[str, np.ndarray]:
    return {k: rng.uniform(lo, hi, P) for k, (lo, hi) in BOUNDS.items()}


def timed(cfg, params, engine: str):
    """Best wall time of three calls [s], the peak memory of one [B], the result."""
    import tracemalloc

    c = cfg.model_copy(deep=True)
    c.simulation.engine = engine
    wall = np.inf
    for _ in range(3):
        start = time.perf_counter()
        res = suspopt.simulate(c, params=params)
        wall = min(wall, time.perf_counter() - start)
    tracemalloc.start()
    suspopt.simulate(c, params=params)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return wall, peak, res


def main() -> None:
    sizes = (1, 100, 1000, 10000)
    if "--sizes" in sys.argv:
        sizes = tuple(int(p) for p in sys.argv[sys.argv.index("--sizes") + 1].split(","))
    memory = (
        "reused"
        if "--default-allocator" not in sys.argv[1:] and suspopt.reuse_memory()
        else "default"
    )
    cfg = suspopt.load_config(CONFIG)
    rng = np.random.default_rng(2026)
    suspopt.simulate(cfg, params=designs(2, rng))  # warm-up (imports, caches)
    from suspopt.integrator import compiled_available

    engines = ["numpy"] + (["compiled"] if compiled_available() else [])
    print(
        f"suspopt {suspopt.__version__} | Python {platform.python_version()} | "
        f"numpy {np.__version__} | {platform.machine()} | freed memory {memory}"
    )
    if "compiled" in engines:
        import numba

        c = cfg.model_copy(deep=True)
        c.simulation.engine = "compiled"
        start = time.perf_counter()
        suspopt.simulate(c, params=designs(2, rng))
        first = time.perf_counter() - start
        from suspopt.integrator import _fused

        start = time.perf_counter()
        suspopt.simulate(c, params=designs(_fused.MIN_DESIGNS, rng))
        print(
            f"numba {numba.__version__}, {numba.get_num_threads()} threads: first compiled call "
            f"{first:.1f} s, first call of {_fused.MIN_DESIGNS} designs (this network's fused "
            f"step) {time.perf_counter() - start:.1f} s (compiling, or loading the caches)"
        )
    print(
        f"HC2 Ch. 5 problem: {cfg.simulation.duration} s at dt = {cfg.simulation.dt} s "
        f"({cfg.simulation.n_steps} RK4 steps)"
    )
    print(
        f"{'P':>6} {'engine':>9} {'wall [s]':>9} {'designs/s':>10} {'x numpy':>8} "
        f"{'peak [MB]':>10} {'MB/design':>10} {'body acc RMS':>13} {'max rel diff':>13}"
    )
    best_rate = 0.0
    for P in sizes:
        params = designs(P, rng)
        base = None
        for engine in engines:
            wall, peak, res = timed(cfg, params, engine)
            acc = res.signals["body.heave_acc"]
            rms = np.sqrt(np.mean(acc**2, axis=-1))
            if base is None:
                base, ref = wall, acc
                diff = "-"
            else:
                scale = np.max(np.abs(ref), axis=-1, keepdims=True)
                diff = f"{np.max(np.abs(acc - ref) / scale):.1e}"
            print(
                f"{P:>6} {res.engine:>9} {wall:>9.3f} {P / wall:>10.1f} {base / wall:>8.2f} "
                f"{peak / 1e6:>10.1f} {peak / 1e6 / P:>10.3f} {rms.mean():>13.4f} {diff:>13}"
            )
            if engine == "compiled":
                best_rate = max(best_rate, P / wall)
    objectives_only(sizes, engines, rng)
    if "compiled" in engines:
        flops, machine = flops_per_design_step(cfg), peak_flops()
        kernel = kernel_rate(cfg, designs(1000, rng))
        for what, rate in (("whole simulate calls", best_rate), ("the kernel alone", kernel)):
            achieved = rate * cfg.simulation.n_steps * flops
            print(
                f"compiled kernel: {flops} flops per design and step (counted from the packed "
                f"network); at {rate:.0f} designs/s ({what}) that is {achieved / 1e9:.2f} "
                f"Gflop/s, {100 * achieved / machine[0]:.1f} % of the peak ({machine[1]} "
                f"flops/cycle = {machine[0] / 1e9:.0f} Gflop/s)"
            )


def kernel_rate(cfg, params) -> float:
    """Designs per second of the compiled kernel's own calls (:func:`suspopt.integrator.
    _kernel.run`, timed around each) in the best of three ``simulate`` calls of ``params``:
    the integration and the writing of its samples, without the set-up and the signals
    computed from the samples."""
    from suspopt.integrator import _kernel

    c = cfg.model_copy(deep=True)
    c.simulation.engine = "compiled"
    run, spent = _kernel.run, [0.0]

    def timed_run(*args):
        start = time.perf_counter()
        run(*args)
        spent[0] += time.perf_counter() - start

    best = np.inf
    _kernel.run = timed_run
    try:
        for _ in range(3):
            spent[0] = 0.0
            suspopt.simulate(c, params=params)
            best = min(best, spent[0])
    finally:
        _kernel.run = run
    return len(next(iter(params.values()))) / best


def objectives_only(sizes, engines, rng) -> None:
    """The same sizes for what an optimisation asks: the objectives and constraints of the
    Ch. 5 Case 1 problem (configs/ch5/case1_s1.yaml, 3 s at dt = 2 ms) by
    ``Problem.evaluate``, which keeps no (P, T) signal but the one its Wk constraint weights
    (:mod:`suspopt.streaming`) and runs batches of at most ``MAX_BATCH`` designs; best of
    two calls, peak memory of a third."""
    import tracemalloc

    from suspopt.optimisation.problem import MAX_BATCH

    base = suspopt.load_config(CONFIG.parent / "ch5" / "case1_s1.yaml")
    print(
        f"objectives and constraints only: Problem.evaluate, Ch. 5 Case 1 (batches <= {MAX_BATCH})"
    )
    print(f"{'P':>6} {'engine':>9} {'wall [s]':>9} {'us/design':>10} {'peak [MB]':>10}")
    for P in sizes:
        for engine in engines:
            cfg = base.model_copy(deep=True)
            cfg.simulation.engine = engine
            problem = suspopt.Problem.from_config(cfg)
            X = rng.uniform(problem.xl, problem.xu, (P, problem.n_var))
            wall = np.inf
            for _ in range(2):
                start = time.perf_counter()
                problem.evaluate(X)
                wall = min(wall, time.perf_counter() - start)
            tracemalloc.start()
            problem.evaluate(X)
            peak = tracemalloc.get_traced_memory()[1]
            tracemalloc.stop()
            print(f"{P:>6} {engine:>9} {wall:>9.3f} {wall / P * 1e6:>10.1f} {peak / 1e6:>10.1f}")


def flops_per_design_step(cfg) -> int:
    """Floating-point operations of one RK4 step of one design in the compiled kernel,
    counted from the packed network: per stage 4 per entry of D_q (δ and δ̇), 2 per entry of
    G, 5 per element (inputs, k δ + c δ̇), 6 per non-linear law, 1 per DOF (the inverse mass);
    four stages; 12 per state row for the stage states and the update."""
    from suspopt.integrator.compiled import _packed
    from suspopt.network import Assembled
    from suspopt.simulation import full_network, prepare

    pv, model, _, attachments = prepare(cfg)
    asm = Assembled(full_network(model, attachments), pv.P)
    _, _, lay = _packed(asm, cfg.simulation.dt, 1)
    nD, nG, R, X, n = (int(v) for v in lay[:5])
    return 4 * (4 * nD + 2 * nG + 5 * R + 6 * X + n) + 12 * 2 * n


def peak_flops() -> tuple[float, str]:
    """The machine's double-precision peak [flop/s]: cores x clock x flops per cycle, from
    /proc/cpuinfo. Two FMA units of 4 doubles (AVX2) make 16 flops per cycle; 32 only where
    AVX-512 runs on 512-bit units: Intel's, and AMD's from family 26 (Zen 5). AMD's family 25
    (Zen 4) reports ``avx512f`` but runs each 512-bit operation as two 256-bit halves, so
    16. (An Intel part with one 512-bit FMA unit would be counted at twice its peak.)"""
    import os

    info = Path("/proc/cpuinfo").read_text() if Path("/proc/cpuinfo").exists() else ""
    mhz = [float(line.split(":")[1]) for line in info.splitlines() if line.startswith("cpu MHz")]
    family = [
        int(line.split(":")[1]) for line in info.splitlines() if line.startswith("cpu family")
    ]
    wide = "GenuineIntel" in info or (bool(family) and family[0] >= 26)
    per_cycle = 32 if "avx512f" in info and wide else 16
    cores = os.cpu_count() or 1
    clock = (mhz[0] if mhz else 2000.0) * 1e6
    return cores * clock * per_cycle, f"{cores} cores x {clock / 1e9:.2f} GHz x {per_cycle}"


if __name__ == "__main__":
    main()
