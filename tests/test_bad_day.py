"""What a user sees on a bad day: a damaged input and a run that was killed.

A. No floating-point warning of numpy's reaches the terminal (the command line renders one as
``warning: overflow encountered ... (at x.py:N)``), and no table shows ``-inf %``: a value no
suspopt run writes is bad input (exit 2, one line naming the file and the dataset or line),
and a change that cannot be computed shows as ``n/a`` with a note. Library calls are checked
with ``RuntimeWarning`` as an error (``-W error::RuntimeWarning``); the command line, whose
own warning filter shows each warning once, by its stderr.

B. A lock or temporary file that a killed run left beside an output is removed by the next
run on that output, which says so in one ``note:`` line naming the file and the killed run's
command (:func:`suspopt.io.claim`); a lock file is untrusted input.
"""

from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
import sys
import time
import warnings
from pathlib import Path

import h5py
import numpy as np
import pytest
from conftest import CONFIGS, tiny

from suspopt._entry import main
from suspopt.templates import template_text

ROOT = Path(__file__).resolve().parents[1]
pytestmark = pytest.mark.cli


def cli(capsys, *args) -> tuple[int, str, str]:
    """Run the command in-process; (exit code, stdout, stderr)."""
    code = main([str(a) for a in args])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def assert_calm(out: str, err: str) -> None:
    """No floating-point warning on stderr, no table cell of an infinite or NaN change."""
    assert "RuntimeWarning" not in err and "Traceback" not in err, err
    assert not [line for line in err.splitlines() if line.startswith("warning:")], err
    for bad in ("inf %", "nan %", "(inf", "(-inf", "(+inf", "(nan"):
        assert bad not in out, out


def one_error(capsys, *args) -> str:
    """The single stderr line of a command that must exit 2 (no warning before it;
    ``validate``'s count of its errors after it: ``1 error in FILE``)."""
    code, out, err = cli(capsys, *args)
    assert code == 2, (out, err)
    lines = err.strip().splitlines()
    if args[0] == "validate":
        assert len(lines) == 2 and lines[1].startswith("1 error in "), err
        lines = lines[:1]
    assert len(lines) == 1 and lines[0].startswith("error: "), err
    return lines[0]


# --- A: a Pareto file's stored objectives --------------------------------------------------


@pytest.fixture(scope="module")
def front(tmp_path_factory) -> Path:
    """A tiny Pareto front of the PS seat (the spectral starter config), seven designs or so."""
    from suspopt import load_config
    from suspopt.optimisation import optimise

    folder = tmp_path_factory.mktemp("front")
    config = folder / "spectral.yaml"
    config.write_text(tiny(template_text("spectral"), 10.0, population=8, generations=2))
    out = folder / "front.h5"
    optimise(load_config(config), out)
    return out


def damaged(front: Path, folder: Path, name: str, value, column: int | None = None) -> Path:
    """A copy of ``front`` whose ``/pareto/F`` (one column, or all) holds ``value``."""
    path = folder / f"{name}.h5"
    shutil.copy(front, path)
    with h5py.File(path, "a") as h5:
        F = h5["pareto/F"][()]
        F[:, slice(None) if column is None else column] = value
        h5["pareto/F"][...] = F
    return path


ANALYSES = [
    ("analyse", "masses"),
    ("analyse", "roads", "--road", "B"),
    ("analyse", "tolerances"),
    ("analyse", "builds", "--samples", "3"),
]


@pytest.mark.parametrize("command", ANALYSES, ids=lambda c: c[1])
def test_stored_objectives_of_1e308_are_failed_designs_not_minus_inf_percent(
    tmp_path, capsys, front, command
):
    """1e308 is at or above the optimiser's penalty value: the file says the designs failed.
    Their stored values show as "failed", their changes as n/a, a note says why (an
    overflow warning and "-inf %" in every cell before)."""
    path = damaged(front, tmp_path, "big", 1e308)
    code, out, err = cli(capsys, *command[:2], path, *command[2:])
    assert code == 0, err
    assert_calm(out, err)
    assert "failed" in out and "n/a" in out and "1e+308" not in out
    assert re.search(r"(\d+) of \1 stored designs failed", out), out


@pytest.mark.parametrize("value", [1e-308, 0.0], ids=["1e-308", "0"])
@pytest.mark.parametrize("command", ANALYSES[:3], ids=lambda c: c[1])
def test_a_change_from_0_or_1e308_times_over_is_n_a_with_a_note(
    tmp_path, capsys, front, command, value
):
    path = damaged(front, tmp_path, "small", value, column=0)
    code, out, err = cli(capsys, *command[:2], path, *command[2:])
    assert code == 0, err
    assert_calm(out, err)
    assert "(n/a)" in out and "n/a: a change that cannot be computed" in out
    assert not re.search(r"\d{20}", out)  # (a change of 1e307 % printed with 300 digits)


@pytest.mark.parametrize(
    "value", [np.array([1e308, -1e308]), -1e308, -1e10], ids=["span", "negative", "minus_penalty"]
)
@pytest.mark.parametrize(
    "command",
    [
        ("analyse", "masses", "{}"),
        ("analyse", "transmissibility", "{}"),
        ("kesort", "{}"),
        ("report", "{}", "-o", "{out}.html"),
        ("export", "{}", "--pick", "knee", "-o", "{out}.yaml"),
        ("simulate", "{}", "--pick", "knee", "-o", "{out}.h5"),
    ],
    ids=["masses", "transmissibility", "kesort", "report", "export", "simulate"],
)
def test_stored_objectives_beyond_the_range_are_bad_input(tmp_path, capsys, front, value, command):
    """A column spanning -1e308 to 1e308 (the knee's normalisation overflowed: a traceback
    from report and export) or holding -1e308 (the figures' axes overflowed) is a file
    suspopt did not write."""
    path = tmp_path / "odd.h5"
    shutil.copy(front, path)
    with h5py.File(path, "a") as h5:
        F = h5["pareto/F"][()]
        F[:, 0] = np.resize(value, len(F))
        h5["pareto/F"][...] = F
    args = [a.format(path, out=tmp_path / "out") for a in command]
    message = one_error(capsys, *args)
    lowest = float(np.min(value))
    assert message == (
        f"error: {path}: /pareto/F: RC_se holds {lowest:g}, at or below -1e+10 (not values "
        "suspopt wrote)"
    )


def test_the_lowest_objective_a_file_may_hold_is_minus_the_penalty():
    from suspopt.h5read import LOWEST_OBJECTIVE
    from suspopt.optimisation.problem import PENALTY

    assert LOWEST_OBJECTIVE == -PENALTY


def test_a_baseline_of_1e_308_or_0_gives_no_warning(tmp_path, capsys, front):
    for value in (1e-308, 0.0, 1e308, -1e308):
        path = tmp_path / "baseline.h5"
        shutil.copy(front, path)
        with h5py.File(path, "a") as h5:
            h5["baseline/F"][...] = value
        code, out, err = cli(capsys, "kesort", path)
        assert code == 0, err
        assert_calm(out, err)
        assert "against the config's own design" in out or "failed to simulate" in out


@pytest.mark.slow
def test_a_failed_stored_front_is_drawn_without_its_penalty_values(tmp_path, capsys, front):
    """The stored designs' 1e308 went to the figure's axes: an overflow in matplotlib's
    ticker and ``error: arange: cannot compute length``."""
    path = damaged(front, tmp_path, "big", 1e308)
    for kind, options in [("masses", []), ("builds", ["--samples", 3])]:
        figure = tmp_path / f"{kind}.png"
        code, out, err = cli(capsys, "analyse", kind, path, "--plot", figure, *options)
        assert code == 0, err
        assert_calm(out, err)
        assert figure.stat().st_size > 0


def test_the_analyses_as_a_library_raise_no_runtime_warning(tmp_path, front):
    from suspopt.analyse import analysis_kinds

    kinds = analysis_kinds()
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        for value in (1e308, 1e-308, 0.0):
            path = damaged(front, tmp_path, "lib", value)
            for kind, options in [("masses", {}), ("tolerances", {}), ("builds", {"samples": 3})]:
                report = kinds[kind].run(path, **options).report()
                cells = [c for row in report.rows for c in row] + report.notes
                assert not [c for c in cells if "inf" in c or "nan %" in c], cells


def test_relative_change_and_its_cells_raise_no_runtime_warning():
    from suspopt.analyse import relative_change
    from suspopt.analyse.cells import change_span, percent
    from suspopt.cli.base import against_baseline

    value = np.array([0.15, -1e308, 1e308, 0.1, np.nan, 5.0])
    reference = np.array([1e308, 1e308, -1e308, 0.0, 1.0, 1e-308])
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        change = relative_change(value, reference)
        cells = [percent(c) for c in change]
        span = change_span("f1", change)
        line = against_baseline(["a", "b", "c"], [0.15, -1e308, 1.0], [1e-308, 1e308, 0.0], True)
    assert change[0] == pytest.approx(-100.0)
    assert np.isnan(change[1:]).all()
    assert cells == ["-100.0 %"] + ["n/a"] * 5
    assert span == "f1 -100.0 to -100.0 % (median -100.0 %), n/a for 5"
    assert "inf" not in line and "nan" not in line
    assert percent(1.5e307) == "+1.5e+307 %" and percent(-12.345, ".0f") == "-12 %"


# --- A: a road profile --------------------------------------------------------------------

SEAT_ON_A_FILE = re.sub(
    r"(?ms)^road:.*?(?=^simulation:)",
    "road: {kind: file, path: road.csv, speed: 20}\n",
    template_text("seat"),
).replace("duration: 10.0", "duration: 0.5")


@pytest.mark.parametrize(
    "rows, needle",
    [
        ([(i * 0.5, 1e308 * (-1) ** i) for i in range(20)], "road.csv:1: heights must be within"),
        ([(0, 0), (1, 0), (1 + 1e-12, 0.5), (2, 0)], "road.csv:3: the height changes by more"),
        ([(0, 0), (1e300, 0.1)], "road.csv:2: distances must be within ±1e+09 m"),
        ([(0, 0), (5e-324, 1.0)], "road.csv:2: the height changes by more"),
    ],
    ids=["heights_1e308", "steep", "distance_1e300", "subnormal_step"],
)
@pytest.mark.parametrize("command", ["validate", "simulate"])
def test_a_road_profile_beyond_what_a_road_is_is_bad_input(tmp_path, capsys, rows, needle, command):
    """Heights of 1e308 overflowed in the slope (np.diff) and then in the model's matrices:
    two numpy warnings and a NaN run before."""
    (tmp_path / "road.csv").write_text("".join(f"{d!r},{h!r}\n" for d, h in rows))
    config = tmp_path / "case.yaml"
    config.write_text(SEAT_ON_A_FILE.replace("simulation:\n", "simulation:\n  engine: numpy\n"))
    args = [command, config] + (["-o", tmp_path / "out.h5"] if command == "simulate" else [])
    message = one_error(capsys, *args)
    assert message.startswith(f"error: {config}:") and needle in message
    from suspopt.config.road import read_profile

    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        with pytest.raises(ValueError, match=re.escape(needle)):
            read_profile(tmp_path / "road.csv")


def test_the_largest_road_a_profile_may_hold_diverges_without_a_numpy_warning(tmp_path, capsys):
    """The profile's bounds at their limits under road.scale 1000 at 200 m/s, on a seat and
    a cubic spring: the design diverges, which suspopt says itself (``tensordot`` of the
    seat's floor and the spring usage's square warned before)."""
    rows = [(2.0 * i, 1e6 * (-1) ** i) for i in range(100)]
    (tmp_path / "road.csv").write_text("".join(f"{d!r},{h!r}\n" for d, h in rows))
    text = SEAT_ON_A_FILE.replace("speed: 20}", "speed: 200, scale: 1000}")
    text = text.replace("spring: {linear: 3.0e4}", "spring: {linear: 3.0e4, cubic: 1.0e7}")
    text = text.replace("simulation:\n", "simulation:\n  engine: numpy\n")
    assert "cubic: 1.0e7" in text
    config = tmp_path / "case.yaml"
    config.write_text(text)
    code, out, err = cli(capsys, "simulate", config, "-o", tmp_path / "out.h5")
    assert code == 0, err
    warned = [line for line in err.splitlines() if line.startswith("warning:")]
    assert len(warned) == 1 and "diverged" in warned[0], err
    from suspopt import load_config
    from suspopt.simulation import simulate

    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        result = simulate(load_config(config))
        dict(result.metrics), [result.signals[name] for name in list(result.signals)]
    assert result.diverged.all()


# --- B: what a killed run left ------------------------------------------------------------

QUICKSTART = CONFIGS / "quickstart.yaml"
NOTE = re.compile(
    r"note: (?P<file>\S+): removed (?P<what>.+?) left by a run that was killed(?P<who>.*)"
)


def notes(err: str) -> list[str]:
    return [line for line in err.splitlines() if line.startswith("note: ")]


def test_a_killed_runs_lock_and_temporary_file_are_named_and_removed(tmp_path, capsys):
    out = tmp_path / "front.h5"
    lock = tmp_path / ".front.h5.suspopt-lock"
    lock.write_text("1234\n2026-05-01T09:12:44+00:00\nsuspopt optimise study.yaml -o front.h5\n")
    stale = tmp_path / ".front.h5.k3x9q1.suspopt-tmp"
    stale.write_bytes(b"half a file")
    code, _, err = cli(capsys, "simulate", QUICKSTART, "-o", out)
    assert code == 0, err
    assert notes(err) == [
        f"note: {out}: removed a lock and 1 temporary file left by a run that was killed "
        "(process 1234, started 2026-05-01T09:12:44+00:00: suspopt optimise study.yaml -o "
        "front.h5)"
    ]
    assert sorted(tmp_path.iterdir()) == [out]
    # the next run finds nothing to say
    code, _, err = cli(capsys, "simulate", QUICKSTART, "-o", out)
    assert code == 0 and notes(err) == [], err


def test_temporary_files_alone_are_named(tmp_path, capsys):
    out = tmp_path / "out.h5"
    for tag in ("a1", "b2"):
        (tmp_path / f".out.h5.{tag}.suspopt-tmp").write_bytes(b"")
    code, _, err = cli(capsys, "simulate", QUICKSTART, "-o", out)
    assert code == 0, err
    assert notes(err) == [f"note: {out}: removed 2 temporary files left by a run that was killed"]
    assert sorted(tmp_path.iterdir()) == [out]


@pytest.mark.parametrize(
    "content, who",
    [
        (b"4242\n", " (process 4242)"),
        (b"4242\nyesterday\n\x1b[31mrm -rf /\x07\n", " (process 4242: ?[31mrm -rf /?)"),
        (os.urandom(1 << 16), " (its lock file does not say which run it was)"),
        (b"\x00" * (4 << 20), " (its lock file does not say which run it was)"),
        (b"1\n2026-05-01T09:12:44\n" + b"x" * (1 << 20), None),
        (b"99999999999999999999\n", " (its lock file does not say which run it was)"),
    ],
    ids=["pid_alone", "control_characters", "binary", "huge_nul", "huge_command", "huge_pid"],
)
def test_a_lock_file_of_any_content_is_cleaned_with_a_sane_line(tmp_path, capsys, content, who):
    out = tmp_path / "out.h5"
    (tmp_path / ".out.h5.suspopt-lock").write_bytes(content)
    started = time.perf_counter()
    code, _, err = cli(capsys, "simulate", QUICKSTART, "-o", out)
    assert code == 0, err
    assert time.perf_counter() - started < 60
    (line,) = notes(err)
    found = NOTE.fullmatch(line)
    assert found and found["file"] == str(out) and found["what"] == "a lock", line
    assert line.isprintable() and len(line) < 800, line
    if who is not None:
        assert found["who"] == who
    else:  # (the command cut to its 500 characters)
        assert found["who"].startswith(" (process 1, started 2026-05-01T09:12:44: xxx")
        assert found["who"].endswith("x...)")
    assert sorted(tmp_path.iterdir()) == [out]


def test_an_empty_lock_file_is_reused_without_a_word(tmp_path, capsys):
    """An empty lock is what a run makes just before it locks it: not a killed run's."""
    out = tmp_path / "out.h5"
    (tmp_path / ".out.h5.suspopt-lock").write_bytes(b"")
    code, _, err = cli(capsys, "simulate", QUICKSTART, "-o", out)
    assert code == 0 and notes(err) == [], err
    assert sorted(tmp_path.iterdir()) == [out]


@pytest.mark.parametrize(
    "make, kind",
    [
        (lambda p: p.mkdir(), "a directory"),
        (lambda p: os.mkfifo(p), "a FIFO"),
        (lambda p: p.symlink_to("/etc/passwd"), "a symbolic link"),
    ],
    ids=["directory", "fifo", "symlink"],
)
def test_a_lock_name_that_is_no_regular_file_is_refused(tmp_path, capsys, make, kind):
    out = tmp_path / "out.h5"
    lock = tmp_path / ".out.h5.suspopt-lock"
    make(lock)
    message = one_error(capsys, "simulate", QUICKSTART, "-o", out)
    assert message == (
        f"error: {out}: {lock} is {kind}, not suspopt's lock file; remove it or choose "
        "another output"
    )
    assert not out.exists()


def test_the_library_records_the_note_and_prints_nothing(tmp_path, capsys):
    from suspopt import io

    io.take_notes()
    out = tmp_path / "out.h5"
    (tmp_path / ".out.h5.suspopt-lock").write_text("77\n")
    with io.claim(out, command="my script"):
        lock = (tmp_path / ".out.h5.suspopt-lock").read_text().splitlines()
    captured = capsys.readouterr()
    assert captured.out == captured.err == ""
    assert io.take_notes() == [f"{out}: removed a lock left by a run that was killed (process 77)"]
    assert io.take_notes() == []
    assert lock[0] == str(os.getpid()) and lock[2] == "my script"
    assert re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\+00:00", lock[1])
    with io.claim(out, command="x" * 10_000 + "\n\x1b"):
        text = (tmp_path / ".out.h5.suspopt-lock").read_text()
    assert len(text) < 600 and text.count("\n") == 3 and text.endswith("x...\n")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow
def test_a_run_killed_mid_run_is_named_by_the_next_one(tmp_path, capsys):
    """``suspopt optimise`` killed (SIGKILL) while it runs; the next run on its output says
    which run it was and removes its lock; a live run's lock still refuses a second one at
    once, with its process id."""
    config = tmp_path / "study.yaml"
    config.write_text(tiny(template_text("spectral"), 10.0, population=40, generations=100000))
    out = tmp_path / "front.h5"
    lock = tmp_path / ".front.h5.suspopt-lock"
    args = ["optimise", "study.yaml", "-o", "front.h5"]
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    proc = subprocess.Popen(
        [sys.executable, "-m", "suspopt", *args],
        cwd=tmp_path,
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        deadline = time.monotonic() + 60
        while not (lock.exists() and lock.read_text().count("\n") == 3):
            assert proc.poll() is None and time.monotonic() < deadline
            time.sleep(0.05)
        second = one_error(capsys, "optimise", config, "-o", out)
        assert f"another suspopt run (process {proc.pid}) is writing it" in second
    finally:
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(timeout=30)
    assert lock.exists()  # (what the killed run left)
    config.write_text(tiny(template_text("spectral"), 10.0, population=6, generations=1))
    code, _, err = cli(capsys, "optimise", config, "-o", out)
    assert code == 0, err
    (line,) = notes(err)
    found = NOTE.fullmatch(line)
    assert found and found["file"] == str(out), line
    assert re.fullmatch(r"a lock( and \d+ temporary files?)?", found["what"]), line
    assert re.fullmatch(
        rf" \(process {proc.pid}, started \S+: suspopt optimise study\.yaml -o front\.h5\)",
        found["who"],
    ), line
    assert sorted(p.name for p in tmp_path.iterdir()) == ["front.h5", "study.yaml"]


def test_a_command_run_in_a_folder_that_is_gone_exits_2_with_one_line(tmp_path):
    """A shell left in a removed folder: one line, exit 2 (numba, compiling there, raised a
    FileNotFoundError from deep inside)."""
    gone = tmp_path / "gone"
    gone.mkdir()
    script = (
        "import os, sys\n"
        f"os.rmdir({str(gone)!r})\n"
        "from suspopt._entry import main\n"
        f"sys.exit(main(['simulate', {str(ROOT / 'configs' / 'quickstart.yaml')!r}]))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", script], cwd=gone, capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 2, done.stderr
    assert done.stderr == "error: the current folder no longer exists; cd to one that does\n"
