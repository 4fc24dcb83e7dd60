"""CPU time of the command line's start-up: ``suspopt --help``, ``validate``, ``schema`` and
the quickstart ``simulate`` (with ``-o``), best of 5 runs each, as a table.

CPU time (user + system, of the process and its children) rather than wall time, so that a
busy machine moves the figures less; it asserts nothing.

    python benchmarks/bench_startup.py [--runs 5]
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
QUICKSTART = ROOT / "configs" / "quickstart.yaml"


def cpu_seconds(args: list[str]) -> float:
    """CPU time [s] of one ``python -m suspopt ARGS`` run (its process alone)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(
        [sys.executable, "-m", "suspopt", *args],
        check=True,
        cwd=ROOT,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=5)
    runs = parser.parse_args().runs
    with tempfile.TemporaryDirectory() as folder:
        out = os.path.join(folder, "quickstart.h5")
        commands = {
            "suspopt --help": ["--help"],
            "suspopt validate configs/quickstart.yaml": ["validate", str(QUICKSTART)],
            "suspopt schema": ["schema"],
            "suspopt simulate configs/quickstart.yaml -o OUT.h5": [
                "simulate",
                str(QUICKSTART),
                "-o",
                out,
            ],
            "python -c pass (the interpreter alone)": None,
        }
        rows = []
        for label, args in commands.items():
            if args is None:
                times = []
                for _ in range(runs):
                    before = resource.getrusage(resource.RUSAGE_CHILDREN)
                    subprocess.run([sys.executable, "-c", "pass"], check=True)
                    after = resource.getrusage(resource.RUSAGE_CHILDREN)
                    times.append(
                        after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime
                    )
            else:
                times = [cpu_seconds(args) for _ in range(runs)]
            rows.append((label, min(times), sorted(times)[len(times) // 2]))
    print(f"CPU time, best and median of {runs} runs (Python {sys.version.split()[0]})\n")
    print("| command | best [s] | median [s] |")
    print("|---|---|---|")
    for label, best, median in rows:
        print(f"| `{label}` | {best:.2f} | {median:.2f} |")


if __name__ == "__main__":
    main()
