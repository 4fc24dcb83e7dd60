"""Write the reproduction report of the thesis from the files examples/reproduce_thesis.sh wrote.

    python examples/report.py OUT REPORT [--wall SECONDS]

OUT holds the HDF5 files and figures of the CLI runs (``OUT/ch3`` ... ``OUT/ch8``, the step
times in ``OUT/run.tsv``); REPORT receives ``README.md`` (header, budgets, headlines),
``ch3.md`` ... ``ch8.md`` and ``figures/``. Every table is computed from those files and set
beside the thesis's printed numbers of examples/thesis_values.yaml, with the difference
``(ours - thesis)/thesis`` (suspopt.analyse.relative_change). Where a table needs metrics the
optimiser does not store (Tables 5.5-5.13, 6.4: maximum travel, tyre force, wheel travel), the
stored optimum is simulated again from its file's config and design (one batch per file,
``simulate`` with the config's ``metrics:``, Table 2.x definitions below). Nothing here is a
thesis number: those are read from the YAML file, and the library holds none.
"""

from __future__ import annotations

import argparse
import datetime as dt
import platform
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from report_ch3 import CH3_FILES, chapter3
from report_ch4 import chapter4
from report_ch5 import bounds_text, chapter5, late_gain_sentence, reproduced
from report_ch6 import chapter6
from report_ch7 import chapter7
from report_ch8 import chapter8
from report_common import (
    CHAPTERS,
    CONVERGED,
    Doc,
    dt_sentence,
    grid_sentence,
    narrowed,
    placed,
    read_steps,
    seed_sentence,
    share_sentence,
    side,
    spread,
)

import suspopt
from suspopt.errors import ConfigError

#: What the tests and other scripts read from here (the parts live in report_*.py).
__all__ = [
    "main",
    "Doc",
    "CH3_FILES",
    "CONVERGED",
    "dt_sentence",
    "side",
    "placed",
    "chapter3",
    "chapter4",
    "chapter5",
    "chapter6",
    "chapter7",
    "chapter8",
    "bounds_text",
    "late_gain_sentence",
    "reproduced",
    "grid_sentence",
    "narrowed",
    "seed_sentence",
    "share_sentence",
    "spread",
]


# --- the report ----------------------------------------------------------------------------


def git(*args: str) -> str:
    try:
        return subprocess.run(
            ["git", *args],
            cwd=Path(__file__).resolve().parent,
            capture_output=True,
            text=True,
            check=True,
        ).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


CHAPTER_BUILDERS = {3: chapter3, 4: chapter4, 5: chapter5, 6: chapter6, 7: chapter7, 8: chapter8}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path, help="the output folder of reproduce_thesis.sh")
    parser.add_argument("report", type=Path, help="where to write the report")
    parser.add_argument(
        "--wall",
        type=float,
        default=None,
        help="total wall time of the runs [s] (reproduce_thesis.sh passes it)",
    )
    args = parser.parse_args()
    args.report.mkdir(parents=True, exist_ok=True)
    if (args.report / "figures").is_dir():
        shutil.rmtree(args.report / "figures")
    headlines, missing = _chapters(args)
    doc = Doc(args.report)
    steps = _header(args, doc)
    _budgets(args, doc, steps)
    doc("## Headlines", "")
    for number in CHAPTER_BUILDERS:
        doc(*[f"- {h}" for h in headlines[number]])
    doc("")
    doc("## Chapters", "")
    for number, title in CHAPTERS.items():
        doc(f"- [Chapter {number}: {title}](ch{number}.md)")
    doc("")
    (args.report / "README.md").write_text(doc.text())
    print(f"wrote {args.report / 'README.md'} and ch3.md ... ch8.md")
    for number, why in missing.items():
        print(f"not built: chapter {number}: {why}", file=sys.stderr)


def _chapters(args) -> tuple[dict, dict]:
    """Write ch3.md ... ch8.md; each chapter's headlines, and why a chapter was not built."""
    headlines = {}
    missing = {}
    for number, build in CHAPTER_BUILDERS.items():
        doc = Doc(args.report)
        try:
            headlines[number] = build(args.out, doc)
        except (ConfigError, OSError) as exc:  # a partial output: say what is missing
            missing[number] = str(exc)
            headlines[number] = [f"Ch. {number}: not built - {exc}"]
            doc = Doc(args.report)
            doc(
                f"# Chapter {number}: {CHAPTERS[number]}",
                "",
                f"Not built: the outputs of this chapter's runs are incomplete ({exc}). "
                f"Run `examples/reproduce_thesis.sh` (or this chapter's script) to make them.",
            )
        (args.report / f"ch{number}.md").write_text(doc.text())
    return headlines, missing


def _header(args, doc: Doc) -> dict:
    """The report's header: version, commit, machine, wall time; the steps' wall times."""
    steps = read_steps(args.out)
    wall = args.wall if args.wall is not None else sum(steps.values())
    tsv = args.out / "run.tsv"
    finished = (
        dt.datetime.fromtimestamp(tsv.stat().st_mtime).astimezone().isoformat(timespec="seconds")
        if tsv.is_file()
        else "unknown"
    )
    dirty = git("status", "--porcelain", "--untracked-files=no")
    doc(
        "# suspopt: reproduction report of the thesis",
        "",
        "*Optimization of vehicle dynamic behavior* (NTUA), Chapters 3-8, reproduced through",
        "the suspopt CLI by `examples/reproduce_thesis.sh`. Each chapter file sets the thesis's",
        "tables beside ours (computed from the HDF5 files of the runs; the thesis's numbers",
        "from `examples/thesis_values.yaml`) with the difference and its reason.",
        "",
    )
    doc.table(
        ["", ""],
        [
            ["suspopt version", suspopt.__version__],
            ["git commit", git("rev-parse", "HEAD") + (" (uncommitted changes)" if dirty else "")],
            ["runs finished", finished],
            ["report written", dt.datetime.now().astimezone().isoformat(timespec="seconds")],
            [
                "machine",
                f"{platform.platform()}, {platform.machine()}, Python "
                f"{platform.python_version()}, numpy {np.__version__}",
            ],
            ["total wall time of the runs", f"{wall:.0f} s ({wall / 60:.1f} min)"],
            ["outputs", f"`{args.out}`"],
        ],
    )
    return steps


def _budgets(args, doc: Doc, steps: dict) -> None:
    """The mode and every step's budget and wall time."""
    doc("## Budgets and wall times", "")
    mode = (args.out / "mode").read_text().split() if (args.out / "mode").is_file() else []
    if mode[:1] == ["quick"]:
        budget = {k: "SUSPOPT_QUICK=1: population 8, 2 generations, 3 s runs" for k in steps}
    else:
        cap = int(mode[1]) if len(mode) > 1 else None
        budget = {
            "ch3": "the configs as they are (full runs)",
            "ch3_checks": "11 extra runs: dt halved, seeds 1-5, double length",
            "ch4": "full runs",
            "ch5": f"at most {cap:,} evaluations per run" if cap else "the configs'",
            "ch6": "population 100, 100 generations",
            "ch7": "population 100, 100 generations",
            "ch8": "population 100, 100 generations (10 fronts)",
        }
    doc.para(
        "**Mode:** "
        + (
            "SUSPOPT_QUICK=1 (tiny budgets: the report's structure only; its numbers mean nothing)"
            if mode[:1] == ["quick"]
            else "full (the budgets below)"
        )
        + "."
    )
    doc.table(
        ["step", "budget", "wall [s]"],
        [[name, budget.get(name, "-"), f"{seconds:.0f}"] for name, seconds in steps.items()],
    )
    doc.para(
        "Each chapter's file gives the generations, evaluations and wall time of every",
        "optimisation next to its tables.",
    )


if __name__ == "__main__":
    main()
