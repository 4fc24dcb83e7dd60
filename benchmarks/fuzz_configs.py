"""Long fuzz runs of the command line: broken configs and broken Pareto files, with counts.

The cases of ``tests/test_fuzz.py`` and ``tests/test_fuzz_h5.py`` (the harness is
``tests/fuzz_harness.py``), in any number: ``--cases N`` random config mutations with
``--seed S`` (mutation ``i`` is the same in every run with that seed), besides the bundled
seeds and the fixed special inputs; ``--h5-cases M`` random byte flips of the tiny front,
besides the fixed broken Pareto files. Every command runs in-process in worker processes
capped at ``--memory`` GB of address space, with ``--limit`` s per command (SIGALRM). Run:

    python benchmarks/fuzz_configs.py --cases 2000 --seed 1
    python benchmarks/fuzz_configs.py --cases 0 --no-fixed --h5-only --h5-cases 500
    python benchmarks/fuzz_configs.py --configs-only --optimise --cases 1000 --limit 10

``--options`` runs, instead, every command's every option that takes a value, and every
positional argument, with each of a list of hostile values (``fuzz_harness.OPTION_VALUES``:
numbers out of range, names the system cannot look up, special files, the command's own
inputs) on a folder of valid inputs made first (a tiny front, its k-ε choice, a robust
front); a command that refuses must also leave that folder as it was:

    python benchmarks/fuzz_configs.py --options --limit 20

``--optimise`` mutates the optimisation configs only and runs ``validate`` and ``optimise``
(tiny budgets) on each, instead of ``validate`` and ``simulate``. ``--bounds`` sets every
number of every bundled config, one at a time, to each bound its schema allows (and 0),
instead of random mutations (with ``--optimise``: the optimisation configs, optimised):

    python benchmarks/fuzz_configs.py --configs-only --bounds
    python benchmarks/fuzz_configs.py --configs-only --bounds --optimise --limit 20

Prints, for configs and Pareto files apart, a table of counts (cases, exit 0, exit 2, other
exits, tracebacks, multi-line messages, time-outs, validate-accepts-but-simulate-rejects
(or optimise)),
the causes (category, exception, where it was raised) with an example each, and the slowest
cases. ``--json FILE`` keeps every case and result. Asserts nothing; exit code 0.
"""

from __future__ import annotations

import argparse
import collections
import json
import platform
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import fuzz_harness as fh  # noqa: E402


def tally(cases, results) -> dict:
    """Counts over cases and over command runs."""
    c = collections.Counter()
    for case in cases:
        result = results[case.id]
        found = fh.problems(case, result)
        c["cases"] += 1
        c["cases failing"] += bool(found)
        if "fatal" in result:
            c["worker crashes / kills / harness errors"] += 1
            continue
        for run in result["runs"]:
            if run.get("skipped"):
                c["commands skipped after a time-out"] += 1
                continue
            c["command runs"] += 1
            if run["timeout"]:
                c["time-outs"] += 1
            elif run["exit"] == 0:
                c["exit 0"] += 1
            elif run["exit"] == 2:
                c["exit 2"] += 1
                if run["stderr_lines"] != 1 and run["command"] != "validate":
                    c["multi-line (or empty) messages"] += 1
            else:
                c["other exits"] += 1
            if run.get("exc") and not run["timeout"]:
                c["tracebacks"] += 1
            if "Traceback" in run["stderr"] + run["stdout"]:
                c["'Traceback' printed"] += 1
        for p in found:
            if p["category"].startswith("message does not name"):
                c["messages not naming the file / dataset"] += 1
            if p["category"].startswith("validate accepts"):
                c["validate accepts, simulate/optimise rejects"] += 1
            if " exit 0 but" in p["category"]:
                c["simulate/optimise exit 0, no file"] += 1
    return c


ORDER = [
    "cases",
    "cases failing",
    "command runs",
    "exit 0",
    "exit 2",
    "other exits",
    "tracebacks",
    "'Traceback' printed",
    "multi-line (or empty) messages",
    "messages not naming the file / dataset",
    "time-outs",
    "validate accepts, simulate/optimise rejects",
    "simulate/optimise exit 0, no file",
    "commands skipped after a time-out",
    "worker crashes / kills / harness errors",
]


def report(title: str, cases, results, slowest: int, causes: int) -> None:
    c = tally(cases, results)
    print(f"\n## {title}\n")
    print("| count | value |\n|---|---|")
    for key in ORDER:
        if key in c or key in (
            "cases",
            "exit 0",
            "exit 2",
            "other exits",
            "tracebacks",
            "multi-line (or empty) messages",
            "time-outs",
        ):
            print(f"| {key} | {c.get(key, 0)} |")
    groups: dict[tuple, list] = collections.defaultdict(list)
    for case in cases:
        for p in fh.problems(case, results[case.id]):
            key = (p["command"],) + fh.signature(p)
            groups[key].append((case, p))
    if groups:
        print(
            f"\n### causes ({len(groups)}; command, category, exception, where) - "
            f"{'all' if causes <= 0 else f'top {causes}'}\n"
        )
        print("| n | command | category | exception | where | example case | message |")
        print("|---|---|---|---|---|---|---|")
        ranked = sorted(groups.items(), key=lambda kv: -len(kv[1]))
        for key, items in ranked[: causes if causes > 0 else None]:
            case, p = items[0]
            msg = (p.get("message") or p.get("stderr") or "")[:90].replace("|", "/")
            print(
                f"| {len(items)} | {key[0]} | {key[1]} | {key[2]} | {key[3]} | "
                f"`{case.id[:60]}` | {msg} |"
            )
    timed = []
    for case in cases:
        result = results[case.id]
        if "fatal" in result:
            timed.append((result.get("seconds", 0.0), case, "(worker: " + result["fatal"] + ")"))
            continue
        for run in result["runs"]:
            if not run.get("skipped"):
                timed.append((run["seconds"], case, run["command"]))
    timed.sort(key=lambda t: -t[0])
    print(f"\n### slowest {slowest} command runs\n")
    print("| s | command | case |\n|---|---|---|")
    for seconds, case, cmd in timed[:slowest]:
        print(f"| {seconds:.2f} | {cmd} | `{case.id}` |")


def reported(title: str, cases, results, opts) -> list[dict]:
    """Print the tables of a family of cases (:func:`report`); its cases and results, for
    ``--json``."""
    report(title, cases, results, opts.slowest, opts.causes)
    return [{"case": fh.asdict(c), "result": results[c.id]} for c in cases]


def keep(cases, results, folder: Path) -> None:
    """Copy the inputs of the failing Pareto cases (regular files only) to ``folder``."""
    import shutil

    folder.mkdir(parents=True, exist_ok=True)
    for case in cases:
        src = Path(case.setup["path"])
        if fh.problems(case, results[case.id]) and src.is_file() and not src.is_symlink():
            shutil.copyfile(src, folder / src.name)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=1000, help="random config mutations")
    ap.add_argument("--seed", type=int, default=fh.SEED)
    ap.add_argument("--h5-cases", type=int, default=64, help="random byte flips of the front")
    ap.add_argument(
        "--no-fixed",
        action="store_true",
        help="leave out the seeds, the special inputs and the fixed Pareto files",
    )
    ap.add_argument("--configs-only", action="store_true")
    ap.add_argument(
        "--bounds",
        action="store_true",
        help="instead of random mutations, every number of every bundled config at each "
        "bound its schema allows (and 0), one at a time",
    )
    ap.add_argument(
        "--optimise",
        action="store_true",
        help="the config cases are the optimisation configs, run through validate and optimise "
        "(tiny budgets) instead of simulate",
    )
    ap.add_argument("--h5-only", action="store_true")
    ap.add_argument(
        "--options",
        action="store_true",
        help="only the command-line options and arguments, each given hostile values",
    )
    ap.add_argument("--workers", type=int, default=None)
    ap.add_argument("--limit", type=float, default=fh.LIMIT, help="seconds per command")
    ap.add_argument(
        "--memory", type=float, default=fh.MEMORY / 2**30, help="address-space cap of a worker [GB]"
    )
    ap.add_argument("--slowest", type=int, default=10)
    ap.add_argument("--causes", type=int, default=0, help="rows of the causes table (0: all)")
    ap.add_argument("--json", type=Path, help="write every case and result here")
    ap.add_argument(
        "--keep",
        type=Path,
        help="copy the Pareto file of every failing case "
        "into this folder (config cases are in --json)",
    )
    opts = ap.parse_args()

    import numpy

    import suspopt

    print(
        f"suspopt {suspopt.__version__} | Python {platform.python_version()} | numpy "
        f"{numpy.__version__} | seed {opts.seed} | limit {opts.limit:g} s per command | "
        f"memory cap {opts.memory:g} GB per worker"
    )
    run = dict(workers=opts.workers, memory=int(opts.memory * 2**30), limit=opts.limit)
    dumped = {}
    if opts.options:
        start = time.perf_counter()
        with tempfile.TemporaryDirectory(prefix="suspopt-fuzz-options-") as folder:
            cases = fh.option_cases(fh.option_fixtures(Path(folder) / "inputs"))
            made = time.perf_counter() - start
            results = fh.run_cases(cases, **run)
        wall = time.perf_counter() - start
        title = f"options and arguments: {len(cases)} cases (inputs made in {made:.1f} s"
        dumped["options"] = reported(f"{title}, wall {wall:.1f} s)", cases, results, opts)
    if not (opts.h5_only or opts.options):
        start = time.perf_counter()
        configs = fh.bundled_configs()
        if opts.bounds:
            cases = fh.bound_cases(opts.optimise)
        elif opts.optimise:
            cases = fh.optimisation_cases(opts.cases, opts.seed, fixed=not opts.no_fixed)
        else:
            cases = [] if opts.no_fixed else fh.seed_cases(configs) + fh.special_cases()
            cases += [fh.mutated_case(i, opts.seed, configs) for i in range(opts.cases)]
        made = time.perf_counter() - start
        results = fh.run_cases(cases, **run)
        wall = time.perf_counter() - start
        title = (
            f"{'optimisation ' if opts.optimise else ''}configs"
            f"{' at their bounds' if opts.bounds else ''}: {len(cases)} cases "
            f"({0 if opts.bounds else opts.cases} random; made in {made:.1f} s, wall {wall:.1f} s)"
        )
        dumped["configs"] = reported(title, cases, results, opts)
    if not (opts.configs_only or opts.options):
        start = time.perf_counter()
        variants = ([] if opts.no_fixed else fh.h5_variants()) + fh.h5_random_variants(
            opts.h5_cases, opts.seed
        )
        with tempfile.TemporaryDirectory(prefix="suspopt-fuzz-h5-") as folder:
            cases = fh.build_h5_cases(fh.h5_cases(variants), variants, Path(folder))
            results = fh.run_cases(cases, **run)
            if opts.keep:
                keep(cases, results, opts.keep)
        wall = time.perf_counter() - start
        title = f"Pareto files: {len(cases)} cases ({opts.h5_cases} random; wall {wall:.1f} s)"
        dumped["h5"] = reported(title, cases, results, opts)
    if opts.json:
        opts.json.write_text(json.dumps(dumped))
        print(f"\nwrote {opts.json}")


if __name__ == "__main__":
    main()
