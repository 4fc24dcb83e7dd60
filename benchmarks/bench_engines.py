"""End to end: the numpy engine against the compiled one, as a user runs them (a whole
``suspopt`` process, the compiled kernel already in its cache), for the rule of
``simulation.engine: auto`` (:func:`suspopt.integrator.auto_engine`).

The model is ``suspopt init half_pitch`` (the Ch. 5 half car, Duffing springs, the half-sine
bump; dt = 1 ms): one design over runs of several lengths, a batch of designs (``--sweep``)
over 3 s, and the NSGA-II run of ``suspopt init kesort`` (population 40, 10 generations).
Each cell is the best of ``--runs`` wall times, both engines in the same run; the last
column says which engine ``auto`` picks there. It asserts nothing.

    python benchmarks/bench_engines.py [--runs 3]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def wall(args: list[str], folder: str) -> float:
    """Wall time [s] of one ``python -m suspopt -q ARGS`` process."""
    start = time.perf_counter()
    subprocess.run(
        [sys.executable, "-m", "suspopt", "-q", *args],
        check=True,
        cwd=folder,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    return time.perf_counter() - start


def config(folder: str, kind: str, engine: str) -> str:
    """The template ``kind`` with ``simulation.engine: engine``, written to ``folder``."""
    from suspopt.templates import template_text

    text = template_text(kind)
    lines = [line for line in text.splitlines() if not line.startswith("# suspopt ")]
    out = []
    for line in lines:
        out.append(line)
        if line.startswith("simulation:"):
            out.append(f"  engine: {engine}")
    path = os.path.join(folder, f"{kind}_{engine}.yaml")
    Path(path).write_text("\n".join(out) + "\n")
    return path


def main() -> None:
    from suspopt.integrator import auto_engine, compiled_available

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    runs = parser.parse_args().runs
    if not compiled_available():
        raise SystemExit("needs numba")
    with tempfile.TemporaryDirectory() as folder:
        cases = []
        for duration in (3.0, 10.0, 15.0, 30.0):
            sets = ["--set", f"simulation.duration={duration}"]
            cases.append((f"1 design, {duration:g} s", "half_pitch", "simulate", sets, 1))
        for P in (100, 1000, 3000):
            sweep = ["--sweep", f"vehicle.corners.F1.damper.c=2000:4000:{P}"]
            cases.append((f"{P} designs, 3 s", "half_pitch", "simulate", sweep, P))
        cases.append(("init kesort: NSGA-II 40 x 10", "kesort", "optimise", [], None))
        configs = {
            (kind, engine): config(folder, kind, engine)
            for kind in ("half_pitch", "kesort")
            for engine in ("numpy", "compiled")
        }
        # the kernel into the cache first (a fresh machine compiles it here, once)
        wall(["simulate", configs["half_pitch", "compiled"], "-o", "warm.h5", "--force"], folder)
        print("| run | numpy [s] | compiled [s] | numpy / compiled | auto picks |")
        print("|---|---|---|---|---|")
        for label, kind, command, extra, P in cases:
            best = {}
            for engine in ("numpy", "compiled"):
                args = [command, configs[kind, engine], "-o", "out.h5", "--force", *extra]
                best[engine] = min(wall(args, folder) for _ in range(runs))
            if P is None:
                picked = auto_engine(3000, 40, evaluation=True)
            else:
                steps = int(float(extra[1].split("=")[1]) * 1000) if "--set" in extra else 3000
                picked = auto_engine(steps, P, evaluation=False)
            ratio = best["numpy"] / best["compiled"]
            print(
                f"| {label} | {best['numpy']:.2f} | {best['compiled']:.2f} | {ratio:.2f} "
                f"| {picked} |"
            )


if __name__ == "__main__":
    main()
