"""Reading road profile files (``road: {kind: file}``): wall time and peak memory of
``suspopt.config.road.read_profile`` on a well-formed profile (a header, then rows
``distance,height`` 1 mm apart) and on one whose second line is bad (rows ``1,1``), each of
about ``--mb`` MB, read by numpy's parser and fallen back to line by line, and read line by
line only (the reading before numpy's parser was tried first), in the same run.

Each reading runs in its own process; its peak memory is the process's peak resident set
(``ru_maxrss``) less that of the same process before reading. Prints a table; asserts
nothing.

    python benchmarks/bench_road_file.py [--mb 64]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

READ = """
import json, resource, sys, time
from pathlib import Path
import numpy
from suspopt.config import road
path, how = Path(sys.argv[1]), sys.argv[2]
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
start = time.perf_counter()
try:
    if how == "line by line":
        text = path.read_bytes().decode("utf-8")
        rows = road._rows_line_by_line(path, text, road._header(text))
    else:
        rows = road.read_profile(path)
    outcome = f"{len(rows[0])} rows"
except ValueError as exc:
    outcome = str(exc).rsplit(": ", 1)[-1]
wall = time.perf_counter() - start
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before
print(json.dumps({"wall": wall, "peak_mb": peak / 1024, "outcome": outcome}))
"""


def profiles(folder: Path, mb: int) -> dict[str, Path]:
    good, bad = folder / "good.csv", folder / "bad.csv"
    rows = (mb << 20) // 16
    with good.open("w") as out:
        out.write("distance,height\n")
        for start in range(0, rows, 100_000):
            out.write(
                "".join(f"{i * 1e-3:.3f},0.001\n" for i in range(start, min(rows, start + 100_000)))
            )
    bad.write_text("1,1\n" * ((mb << 20) // 4))
    return {"well-formed": good, "bad second line": bad}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--mb", type=int, default=64, help="size of each profile [MB]")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        files = profiles(Path(folder), args.mb)
        print(f"| profile ({args.mb} MB) | reading | wall [s] | peak [MB] | outcome |")
        print("|---|---|---|---|---|")
        for label, path in files.items():
            for how in ("read_profile", "line by line"):
                done = subprocess.run(
                    [sys.executable, "-c", READ, str(path), how],
                    capture_output=True,
                    text=True,
                    check=True,
                )
                row = json.loads(done.stdout)
                print(
                    f"| {label} | {how} | {row['wall']:.2f} | {row['peak_mb']:.0f} | "
                    f"{row['outcome']} |"
                )


if __name__ == "__main__":
    main()
