"""The compiled engine's share of this machine's floating-point peak, per thread and on all.

In one run it measures:

1. **The machine's FP64 peak**: a compiled loop of 32 independent fused multiply-adds
   (``a = a * b + c``). LLVM's SLP vectorizer keeps them in registers and issues them as
   vector FMAs. It runs on one thread and on every thread numba has, in a process of its own
   with the vectorizer on, and is counted at 2 flops per FMA. The best of five runs of each.
2. **The useful flops of one design-step** of the compiled kernel on the Chapter 5 HC2
   problem (``configs/ch5/case1_s1.yaml``: the half car, Duffing springs, the half-sine bump,
   dt = 2 ms, 1,500 steps). They are counted from the packed network
   (``bench_simulate.flops_per_design_step``), the model's non-zero products only. Per RK4
   stage: 4 flops per entry of D_q (the deformation and its rate), 2 per entry of G (the
   forces onto the DOFs), 5 per element (inputs, k δ + c δ̇), 6 per non-linear law and 1 per
   DOF (the inverse mass). Four stages, plus 12 per state row for the stage states and the
   update. The ISO weighting, the metric sums and the constraints are not counted: they are
   work the kernel does beyond the model.
3. **The engine's rate** for that problem's objectives and constraints
   (``Problem._evaluate``: what an optimisation generation calls), at P = 100, 1000 and
   10000 designs drawn inside the design variables' bounds. It gives designs/s, GFLOP/s
   (designs/s x steps x flops per design-step) and the share of the peak measured on the same
   number of threads, on one thread and on all. Each is the best of three calls on fresh
   draws (the first call of a size is run once before, untimed). The time per design at
   P = 10000 is also set against P = 1000.

    python benchmarks/bench_kernel.py [--sizes 100,1000,10000]

It prints tables and asserts nothing. docs/performance.md ("Share of the machine's peak")
keeps its figures with the date and the CPU.
"""

from __future__ import annotations

import argparse
import platform
import sys
import time
from pathlib import Path

import numba
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

from bench_simulate import flops_per_design_step  # noqa: E402

import suspopt  # noqa: E402
from suspopt.optimisation import Problem  # noqa: E402

CONFIG = ROOT / "configs" / "ch5" / "case1_s1.yaml"
#: Independent FMA chains of the peak loop: 8 vectors of 4 doubles (AVX2 registers), enough
#: to cover the FMA units' latency without spilling.
LANES = 32


def _fma_source() -> str:
    """The peak loop: :data:`LANES` scalars ``a_k = a_k * b + c``, written out so that
    LLVM's SLP vectorizer packs them into vector FMAs held in registers."""
    names = [f"a{k}" for k in range(LANES)]
    lines = ["def fma_loop(n, c, b):"]
    lines += [f"    {name} = c + {k} * 1e-9" for k, name in enumerate(names)]
    lines += ["    for _ in range(n):"] + [f"        {name} = {name} * b + c" for name in names]
    return "\n".join(lines + ["    return " + " + ".join(names)]) + "\n"


def _measure_peak(threads: int, n: int = 20_000_000) -> float:
    """The FP64 peak on ``threads`` threads [flop/s], in this process (which must have
    numba's SLP vectorizer on): the best of five timed loops, each thread running its own."""
    namespace: dict = {}
    exec(_fma_source(), namespace)  # (the script's own loop, made above)
    loop = numba.njit(fastmath=True, cache=False)(namespace["fma_loop"])

    @numba.njit(parallel=True, cache=False)
    def on_threads(n, c, b, threads):
        out = np.empty(threads)
        for t in numba.prange(threads):
            out[t] = loop(n, c + t, b)
        return out.sum()

    numba.set_num_threads(threads)
    on_threads(1000, 1.0, 0.999999, threads)  # (compiled)
    best = np.inf
    for _ in range(5):
        start = time.perf_counter()
        on_threads(n, 1.0, 0.999999, threads)
        best = min(best, time.perf_counter() - start)
    return 2.0 * LANES * n * threads / best


def peak(threads: int) -> float:
    """:func:`_measure_peak` in a process of its own, with numba's SLP vectorizer on there
    only (``NUMBA_SLP_VECTORIZE``, off by default): the kernel measured here is compiled, or
    loaded from its cache, as suspopt compiles it."""
    import os
    import subprocess

    done = subprocess.run(
        [sys.executable, __file__, "--peak-of", str(threads)],
        capture_output=True,
        text=True,
        check=True,
        env={**os.environ, "NUMBA_SLP_VECTORIZE": "1"},
    )
    return float(done.stdout.split()[-1])


def rate(problem: Problem, P: int, threads: int, rng: np.random.Generator) -> float:
    """Designs per second of ``problem``'s objectives and constraints at ``P`` designs on
    ``threads`` threads: the best of three calls on fresh draws."""
    numba.set_num_threads(threads)

    def draw() -> np.ndarray:
        return problem.xl + rng.random((P, problem.n_var)) * (problem.xu - problem.xl)

    problem._evaluate(draw(), {})  # (a first call of the size: memory, compiles)
    best = np.inf
    for _ in range(3):
        X = draw()
        start = time.perf_counter()
        problem._evaluate(X, {})
        best = min(best, time.perf_counter() - start)
    return P / best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="100,1000,10000", help="numbers of designs")
    parser.add_argument("--peak-of", type=int, help=argparse.SUPPRESS)  # (see peak)
    args = parser.parse_args()
    if args.peak_of:
        print(_measure_peak(args.peak_of))
        return
    sizes = [int(s) for s in args.sizes.split(",")]
    every = numba.config.NUMBA_NUM_THREADS
    cfg = suspopt.load_config(CONFIG)
    cfg.simulation.engine = "compiled"
    problem = Problem.from_config(cfg)
    flops = flops_per_design_step(cfg)
    steps = cfg.simulation.n_steps
    print(
        f"suspopt {suspopt.__version__}, {platform.processor() or platform.machine()}, "
        f"numba {numba.__version__}, {every} threads; {CONFIG.relative_to(ROOT)}: {steps} "
        f"steps, {flops} useful flops per design-step"
    )
    peaks = {1: peak(1), every: peak(every)}
    print(
        f"FP64 peak (FMA loop): {peaks[1] / 1e9:.1f} GFLOP/s on 1 thread, "
        f"{peaks[every] / 1e9:.1f} GFLOP/s on {every}"
    )
    print(
        f"{'threads':>7} {'P':>6} {'designs/s':>10} {'us/design':>10} {'GFLOP/s':>8} {'% peak':>7}"
    )
    rng = np.random.default_rng(2026)
    per_design: dict[tuple[int, int], float] = {}
    for threads in dict.fromkeys((1, every)):
        for P in sizes:
            r = rate(problem, P, threads, rng)
            per_design[threads, P] = 1e6 / r
            achieved = r * steps * flops
            print(
                f"{threads:>7} {P:>6} {r:>10.0f} {1e6 / r:>10.2f} {achieved / 1e9:>8.2f} "
                f"{100 * achieved / peaks[threads]:>6.1f}%"
            )
    for threads in dict.fromkeys((1, every)):
        if (threads, 1000) in per_design and (threads, 10000) in per_design:
            ratio = per_design[threads, 10000] / per_design[threads, 1000]
            print(f"{threads} thread(s): time per design at P = 10000 is {ratio:.2f}x P = 1000's")


if __name__ == "__main__":
    main()
