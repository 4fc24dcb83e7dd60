"""Hostile input: bounded YAML, strict values, what validate checks, memory, outputs,
data-only checkpoints, broken HDF5 inputs and the command's messages."""

from __future__ import annotations

import errno
import os
import pickle
import platform
import re
import shlex
import signal
import subprocess
import sys
import time
import tracemalloc
from pathlib import Path

import h5py
import numpy as np
import pytest
from conftest import CONFIGS, optimised_front, run

import suspopt
import suspopt.cli  # noqa: F401  (imported before any timing)
from suspopt._entry import main
from suspopt.config.loader import load_config_text

GOOD = (CONFIGS / "quickstart.yaml").read_text()
ROOT = Path(__file__).resolve().parents[1]


def cli(capsys, *args) -> tuple[int, str, str]:
    """Run the command in-process; (exit code, stdout, stderr)."""
    code = main([str(a) for a in args])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def one_error(capsys, *args) -> str:
    """The single error line of a command that must exit 2 (``validate``'s count of its
    errors after it: ``1 error in FILE``)."""
    code, out, err = cli(capsys, *args)
    assert code == 2, (out, err)
    lines = err.strip().splitlines()
    if args[0] == "validate":
        assert len(lines) == 2 and lines[1].startswith("1 error in "), err
        lines = lines[:1]
    assert len(lines) == 1 and "Traceback" not in err, err
    return lines[0]


def write(folder: Path, text: str | bytes, name: str = "case.yaml") -> Path:
    path = folder / name
    path.write_bytes(text if isinstance(text, bytes) else text.encode())
    return path


def edited(old: str, new: str, text: str = GOOD) -> str:
    assert old in text, old
    return text.replace(old, new)


# --- bounded YAML ---------------------------------------------------------------------------

BOMB = "a: &a [x, x, x, x, x, x, x, x, x]\n" + "".join(
    f"{b}: &{b} [{', '.join([f'*{a}'] * 9)}]\n" for a, b in zip("abcdefgh", "bcdefghi")
)


@pytest.mark.parametrize(
    "text, needle",
    [
        (BOMB, "expands to more than 100,000 nodes"),
        ("[" * 5000 + "]" * 5000, "nested more than 64 levels deep"),
        ("a: &a [*a]\n", "refers to the node that contains it"),
        (
            GOOD + "simulation: {duration: 1.0}\n",
            "key 'simulation' appears twice in one mapping (first on line 24)",
        ),
        # Python reads no integer of more than 4300 digits: said without its line before
        (
            "a: 1\nb: " + "9" * 5000 + "\n",
            ":2: malformed YAML: a value that cannot be read as int '99999999999999999999' "
            "(5000 characters)",
        ),
        (
            "c: !!timestamp 2020-13-45\n",
            ":1: malformed YAML: a value that cannot be read as timestamp '2020-13-45'",
        ),
    ],
    ids=["alias_bomb", "deep_nesting", "recursive_alias", "duplicate_key", "huge_int", "tag"],
)
def test_hostile_yaml_is_refused_fast_and_small(tmp_path, capsys, text, needle):
    path = write(tmp_path, text)
    tracemalloc.start()
    start = time.perf_counter()
    message = one_error(capsys, "validate", path)
    elapsed = time.perf_counter() - start
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert needle in message and message.startswith(f"error: {path}:")
    assert elapsed < 1.0 and peak < 100e6, (elapsed, peak)


@pytest.mark.parametrize(
    "make, needle",
    [
        (lambda d: os.symlink("/dev/zero", d / "zero.yaml") or d / "zero.yaml", "is a device"),
        (lambda d: os.mkfifo(d / "fifo.yaml") or d / "fifo.yaml", "is a FIFO"),
        (lambda d: d, "is a directory"),
        (lambda d: write(d, b"vehicle: \x00\x01\x02"), "holds NUL bytes"),
        (lambda d: write(d, b"vehicle: \xff\xfe"), "is not UTF-8 text"),
        (
            lambda d: write(d, "# " + "x" * (1 << 20) + "\n"),
            "is larger than 1 MB, not a config file",
        ),
        # a regular file whose reading fails (EIO): a traceback before
        (
            lambda d: os.symlink("/proc/self/mem", d / "mem.yaml") or d / "mem.yaml",
            "cannot read it (Input/output error)",
        ),
    ],
)
@pytest.mark.parametrize(
    "command",
    [
        ("validate", "{}"),
        ("simulate", "{}", "-o", "{out}"),
        ("optimise", "{}", "-o", "{out}"),
        ("analyse", "transmissibility", "{}"),
        ("analyse", "models", "{}", str(CONFIGS / "quickstart.yaml")),
    ],
    ids=["validate", "simulate", "optimise", "transmissibility", "models"],
)
def test_config_files_that_are_no_config_are_refused(tmp_path, capsys, make, needle, command):
    """Every command whose source may be a config says so in the same words (``simulate``
    and ``analyse transmissibility`` first look for a result file's signature: reading
    ``/proc/self/mem`` for it was a traceback)."""
    source, out = make(tmp_path), tmp_path / "out.h5"
    message = one_error(capsys, *[a.format(source, out=out) for a in command])
    assert needle in message
    assert not out.exists()


@pytest.mark.parametrize("command", ["validate", "optimise", "models"])
def test_a_result_file_where_a_config_belongs_is_named_so(tmp_path, capsys, command):
    """``validate front.h5`` said "holds NUL bytes: a binary file", and a larger result
    "is larger than 1 MB"; the commands that take only configs say what the file is."""
    front, out = tmp_path / "front.h5", tmp_path / "out.h5"
    with h5py.File(front, "w") as h5:
        h5.attrs["suspopt_version"] = suspopt.__version__
    args = {
        "validate": ["validate", front],
        "optimise": ["optimise", front, "-o", out],
        "models": ["analyse", "models", front, CONFIGS / "quickstart.yaml"],
    }[command]
    message = one_error(capsys, *args)
    assert message == f"error: {front}: is an HDF5 file, not a YAML config", message
    assert not out.exists()


@pytest.mark.parametrize(
    "old, new, needle, line",
    [
        ("mass: 2210", "mass: true", "vehicle.body.mass: expected a number (got true)", 6),
        (
            "mass: 2210",
            "mass: '2210'",
            "vehicle.body.mass: expected a number (got the text '2210': write numbers without "
            "quotes)",
            6,
        ),
        ("mass: 2210", "mass: .inf", "vehicle.body.mass: must be a finite number (got .inf)", 6),
        (
            "mass: 2210",
            "mass: 1.0e308",
            "vehicle.body.mass: must be at most 1000000 kg (got 1e+308)",
            6,
        ),
        ("stiffness: 4.0e5}", "stiffness: -4.0e5}", "must be at least 0.001 N/m (got -400000)", 10),
        (
            "preset: half_pitch",
            "preset: yes",
            "vehicle.preset: unknown preset 'yes'; expected one of quarter, half_roll, half_pitch, "
            "full",
            5,
        ),
    ],
)
def test_values_are_strict_finite_and_in_range(tmp_path, capsys, old, new, needle, line):
    message = one_error(capsys, "validate", write(tmp_path, edited(old, new)))
    assert needle in message and f"case.yaml:{line}:" in message, message


@pytest.mark.parametrize(
    "vehicle, needle",
    [  # found by fuzzing: the corner defaults were applied before the types were checked
        (
            "{preset: quarter, body: {mass: 300}, corner_defaults: {unsprung_mass: 40}, corners: true}",
            "corners",
        ),
        ("{preset: quarter, body: {mass: 300}, corners: [F1]}", "corners"),
        (
            "{preset: {a: 1}, body: {mass: 300}, corner_defaults: {unsprung_mass: 40}, corners: {}}",
            "preset",
        ),
    ],
)
def test_corner_defaults_meet_wrong_types_as_bad_input(vehicle, needle):
    text = edited(GOOD.split("vehicle:")[1].split("\nroad:")[0], " " + vehicle)
    with pytest.raises(suspopt.ConfigError, match=rf"<config>:\d+: vehicle\.{needle}: "):
        load_config_text(text)


def test_yaml_1_2_numbers():
    cfg = load_config_text(edited("stiffness: 4.0e5}", "stiffness: 4e5}"))
    assert cfg.vehicle.corners["F1"].tyre.stiffness == 4e5
    with pytest.raises(
        suspopt.ConfigError,
        match=r"road.seed: must be at most 9223372036854775807 "
        r"\(got 1180591620717411303424\)",
    ):
        load_config_text(
            (CONFIGS / "ch8/ps_class_a.yaml").read_text().replace("seed: 1", f"seed: {2**70}")
        )


# --- validate finds what a run would reject ------------------------------------------------


@pytest.mark.parametrize(
    "old, new, needle, line",
    [
        (
            "simulation: {duration: 3.0, dt: 1.0e-3}",
            "simulation: {duration: 3.0005, dt: 1.0e-3}",
            "simulation.duration: 3.0005 s is not a whole number of steps",
            24,
        ),
        (
            "start: 0.5 ",
            "start: 3.5 ",
            "road.start: the bump starts at 3.5 s, after the run ends",
            23,
        ),
        (
            "simulation: {duration: 3.0, dt: 1.0e-3}",
            "simulation: {duration: 3.0, dt: 0.02}",
            "simulation.dt: 0.02 s steps over the bump: a wheel crosses it in 0.09 s",
            24,
        ),
        (
            "tyre: {stiffness: 4.0e5}",
            "tyre: {stiffness: 4.0e9}",
            "simulation.dt: 0.001 s exceeds classical RK4's stability limit 0.000",
            24,
        ),
        (
            "simulation: {duration: 3.0, dt: 1.0e-3}",
            "simulation: {duration: 3.0, dt: 1.0e-3, output_dt: 2.0e-2}\nmetrics:\n  - {metric: "
            "rms_weighted, signal: body.heave_acc, weighting: Wk}",
            "metrics[0].metric: rms_weighted needs signals sampled at 100 Hz or more",
            26,
        ),
        (
            "simulation: {duration: 3.0, dt: 1.0e-3}",
            "simulation: {duration: 3.0, dt: 1.0e-3}\noutput: {signals: [body.heave, body.hiev]}",
            "output.signals[1]: unknown signal 'body.hiev'; did you mean body.heave",
            25,
        ),
        (
            "simulation: {duration: 3.0, dt: 1.0e-3}",
            "simulation: {duration: 3.0, dt: 1.0e-3}\ncontrol: {sample_time: .inf}",
            "control.sample_time: must be a finite number (got .inf)",
            25,
        ),
        (
            "simulation: {duration: 3.0, dt: 1.0e-3}",
            "simulation: {duration: 0.001, dt: 1.0e-3, output_dt: 2.0e-3}",
            "simulation: output_dt (0.002) must not exceed duration (0.001)",
            24,
        ),
        (
            "simulation: {duration: 3.0, dt: 1.0e-3}",
            "simulation: {duration: 3.0, dt: 1.0e-3}\nmetrics:\n  - {metric: null, signal: body.heave}",
            "metrics[0].metric: expected text (got an empty value)",
            26,
        ),
        # a flat "bump": optimise with balanced weights found every objective's median 0
        # (benchmarks/fuzz_configs.py --optimise --seed 23), after validate had accepted it
        ("height: 0.05 ", "height: 0.0 ", "road.height: a bump of height 0 m is a flat road", 20),
        ("height: 0.05 ", "height: -1.0e-300 ", "height -1e-300 m is a flat road", 20),
    ],
)
def test_validate_rejects_what_simulate_would(tmp_path, capsys, old, new, needle, line):
    path = write(tmp_path, edited(old, new))
    message = one_error(capsys, "validate", path)
    assert needle in message and f"case.yaml:{line}:" in message, message
    assert one_error(capsys, "simulate", path, "-o", tmp_path / "out.h5") == message
    assert not (tmp_path / "out.h5").exists()


def test_the_stability_limit_is_rk4s():
    """The limit is where RK4 stops being stable: just below it a stiff design stays
    bounded, just above it it diverges (a quarter car with a very stiff tyre)."""
    from suspopt.checks import check_stability
    from suspopt.simulation import prepare

    cfg = load_config_text((CONFIGS / "ch3/part1a_qc_bump.yaml").read_text())
    cfg.vehicle.corners["F1"].tyre.stiffness = 1.0e9
    pv, model, _, attachments = prepare(cfg)
    with pytest.raises(suspopt.ConfigError, match="stability limit") as error:
        cfg.simulation.dt = 1e-3
        check_stability(cfg, pv, model, attachments)
    limit = float(str(error.value).split("stability limit ")[1].split(" s")[0])
    for factor, diverges in ((0.97, False), (1.03, True)):
        cfg.simulation.dt = limit * factor
        cfg.simulation.duration = round(0.5 / cfg.simulation.dt) * cfg.simulation.dt
        cfg.road.length, cfg.road.start = 2.0, 0.1
        assert bool(suspopt.simulate(cfg).diverged[0]) == diverges


@pytest.mark.parametrize(
    "options, needle",
    [
        (
            "{eliminate_duplicates: 'yes'}",
            "option 'eliminate_duplicates' takes true or false, got 'yes'",
        ),
        (
            "{sampling: lhs}",
            "NSGA2's option 'sampling' takes a pymoo object, which a config cannot give",
        ),
        ("{n_offsprings: 0}", "option 'n_offsprings' takes a whole number from 1 to 1000000"),
    ],
)
def test_optimiser_options_are_checked_data(tmp_path, capsys, options, needle):
    text = (CONFIGS / "ch8/pareto_ps_class_a.yaml").read_text()
    path = write(tmp_path, text.rstrip() + f"\n  options: {options}\n")
    message = one_error(capsys, "validate", path)
    assert needle in message and "optimiser.options" in message, message


def test_an_optimiser_seed_must_be_a_seed(tmp_path, capsys):
    text = (CONFIGS / "ch8/pareto_ps_class_a.yaml").read_text()
    head, optimiser = text.split("\noptimiser:")
    text = head + "\noptimiser:" + optimiser.replace("seed: 1", "seed: -1")
    message = one_error(capsys, "validate", write(tmp_path, text))
    assert "optimiser.seed: must be at least 0 (got -1)" in message


# --- road files -----------------------------------------------------------------------------

SECRET = "root:x:0:0:root:/root:/bin/bash"


@pytest.mark.parametrize(
    "content, needle",
    [
        (b"distance,height\n0,0\n", "needs at least two rows of 'distance,height', found 1"),
        (b"0,0\n1,nan\n2,0\n", "road.csv:2: values must be finite"),
        (f"0,0\n{SECRET}\n".encode(), "road.csv:2: expected two numbers 'distance,height'"),
        (b"0,0\n1,0\n\xff\xfe\x00", "not UTF-8 text"),
        (b"0,0\n2,0\n1,0\n", "road.csv:3: distances must increase strictly"),
        ("/proc/self/mem", "road.csv: cannot read it (Input/output error)"),
        ("/dev/zero", "road.csv: is a device"),
        ("fifo", "road.csv: is a FIFO"),
        ("folder", "road.csv: is a directory"),
    ],
)
def test_road_files_are_checked_on_load_and_never_echoed(tmp_path, capsys, content, needle):
    if content == "fifo":
        os.mkfifo(tmp_path / "road.csv")
    elif content == "folder":
        (tmp_path / "road.csv").mkdir()
    elif isinstance(content, str):
        os.symlink(content, tmp_path / "road.csv")
    else:
        (tmp_path / "road.csv").write_bytes(content)
    text = GOOD.split("road:")[0] + (
        "road: {kind: file, path: road.csv, speed: 10}\nsimulation: {duration: 1.0}\n"
    )
    message = one_error(capsys, "validate", write(tmp_path, text))
    assert needle in message and "road.path" in message and "case.yaml:18:" in message
    assert SECRET not in message and "/bin/bash" not in message


# --- memory -----------------------------------------------------------------------------------

ISO_ROAD = "road: {kind: iso8608, road_class: A, convention: iso8608, n_max: 100.0, speed: 70.0}\n"


@pytest.mark.parametrize(
    "text, needle",
    [
        (
            edited(
                "simulation: {duration: 3.0, dt: 1.0e-3}",
                "simulation: {duration: 9.0e4, dt: 1.0e-5}",
            ),
            "simulating 1 design for 90000 s at dt = 1e-05 s needs about",
        ),
        (
            GOOD.split("road:")[0] + ISO_ROAD + "simulation: {duration: 9.0e4, dt: 1.0e-5}\n",
            "lower road.n_max or set road.n_waves",
        ),  # waves down to 1 cm over 6,300 km (70 m/s: a faster road warns of km/h)
    ],
)
def test_a_run_larger_than_memory_is_refused_before_allocating(tmp_path, capsys, text, needle):
    tracemalloc.start()
    message = one_error(capsys, "validate", write(tmp_path, text))
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert needle in message and "more than the memory this machine has available" in message
    assert message.startswith("error: ") and "case.yaml:" in message  # (the file: none before)
    assert ": simulation: simulating 1 design" in message
    assert peak < 200e6


def test_an_address_space_limit_counts_what_the_process_maps_already(monkeypatch):
    """Under ``ulimit -v``, what is left is the limit less what the process maps (numpy,
    scipy and numba: several hundred MB), but not what the allocator keeps free for reuse.
    The whole limit was taken as free, so a run the estimate let through met a MemoryError
    traceback (found under the fuzz workers' 2 GB)."""
    import resource

    from suspopt import memory

    memory.reuse_memory()  # (as every command does: freed arrays stay mapped for reuse)
    before = memory._mapped()
    block = np.ones(200 << 17)  # 200 MB
    assert memory._mapped() - before > 150 << 20
    del block  # kept by the allocator, but free for the next arrays: not counted as held
    mapped = memory._mapped()
    assert mapped - before < 50 << 20 and mapped > 50 << 20  # (numpy, h5py, suspopt)
    monkeypatch.setattr(resource, "getrlimit", lambda which: (mapped + (300 << 20), -1))
    left = memory.available()
    assert 250 << 20 < left <= 300 << 20
    cap, source = memory.limit()
    assert abs(cap - left) < 16 << 20  # (what the process holds moves a little between calls)
    assert source == "what this process's address-space limit (ulimit -v) leaves"


def test_max_memory_caps_a_run(tmp_path, capsys):
    message = one_error(capsys, "simulate", CONFIGS / "quickstart.yaml", "--max-memory", "1M")
    assert "simulating 1 design for 3 s" in message and "the --max-memory limit (1 MB)" in message
    assert "--max-memory: '4Q' is not a size" in one_error(
        capsys, "simulate", CONFIGS / "quickstart.yaml", "--max-memory", "4Q"
    )
    code, _, _ = cli(capsys, "simulate", CONFIGS / "quickstart.yaml", "--max-memory", "2G")
    assert code == 0


def test_a_population_whose_pairs_exceed_memory_is_refused_before_allocating(tmp_path, capsys):
    """The optimiser compares every pair of designs (pymoo's duplicate elimination): a
    population of a million asked for 7 TB in its first generation, a MemoryError traceback
    after the whole first generation was simulated."""
    text = (CONFIGS / "ch6" / "part_a_c2.yaml").read_text()
    text = re.sub(r"(?m)^(  population:) \d+", r"\1 1000000", text)
    path = write(tmp_path, text)
    line = text[: text.index("population: 1000000")].count("\n") + 1
    tracemalloc.start()
    for command in ("validate", "optimise"):
        args = [path] if command == "validate" else [path, "-o", tmp_path / "out.h5"]
        message = one_error(capsys, command, *args)
        assert f"case.yaml:{line}: optimiser.population: a population of 1,000,000" in message
    assert tracemalloc.get_traced_memory()[1] < 200e6
    tracemalloc.stop()
    assert not (tmp_path / "out.h5").exists()
    text = re.sub(r"(?m)^(  population:) \d+", r"\1 2000", text)
    message = one_error(capsys, "validate", write(tmp_path, text), "--max-memory", "50M")
    assert "a population of 2,000" in message and "the --max-memory limit (50 MB)" in message


def test_large_evaluations_run_in_batches_of_bounded_memory(monkeypatch):
    from suspopt.optimisation import problem as problem_module

    cfg = suspopt.load_config(CONFIGS / "ch5/case1_s1.yaml")
    cfg.simulation.duration = 0.6
    problem = suspopt.Problem.from_config(cfg)
    X = problem.xl + np.random.default_rng(0).random((9, problem.n_var)) * (problem.xu - problem.xl)
    whole = problem.evaluate(X, return_values_of=["F", "G"])
    batched = suspopt.Problem.from_config(cfg)
    monkeypatch.setattr(problem_module, "MAX_BATCH", 10**9)  # (the memory bound alone)
    width = batched.batch_width()
    monkeypatch.setattr(problem_module, "BATCH_BYTES", problem_module.BATCH_BYTES * 4 / width)
    batched._width = None
    assert batched.batch_width() == 4
    calls = []
    real = problem_module.streaming.reduce
    monkeypatch.setattr(
        problem_module.streaming,
        "reduce",
        lambda cfg, params, requests: (
            calls.append(len(next(iter(params.values())))) or real(cfg, params, requests)
        ),
    )
    parts = batched.evaluate(X, return_values_of=["F", "G"])
    assert calls == [4, 4, 1]
    for a, b in zip(whole, parts):
        np.testing.assert_allclose(a, b, rtol=1e-12)


# --- outputs ----------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "make, needle",
    [
        (
            lambda d: os.mkfifo(d / "out.h5") or d / "out.h5",
            "is a FIFO; an output must be a regular file or a new name",
        ),
        (lambda d: d, "is a directory"),
        (
            lambda d: os.symlink(d / "elsewhere.h5", d / "out.h5") or d / "out.h5",
            "is a symbolic link",
        ),
        (lambda d: d / "no" / "out.h5", "does not exist"),
        (lambda d: write(d, "x\n", "notes.txt") / "out.h5", "notes.txt is not a folder"),
        (lambda d: d / ("x" * 300) / "out.h5", "cannot inspect it (File name too long)"),
        (lambda d: "", "-o .: names a folder, not a file"),  # (typer makes '' a '.')
        (
            lambda d: write(d, "my notes\n", "out.h5"),
            "exists and was not written by suspopt; give --force",
        ),
    ],
    ids=["fifo", "directory", "symlink", "no-folder", "file-as-folder", "long", "empty", "foreign"],
)
def test_outputs_must_be_regular_files_or_new_names(tmp_path, capsys, make, needle):
    target = make(tmp_path)
    before = sorted(p.name for p in tmp_path.iterdir())
    message = one_error(capsys, "simulate", CONFIGS / "quickstart.yaml", "-o", target)
    assert needle in message, message
    assert sorted(p.name for p in tmp_path.iterdir()) == before  # nothing written


LONG = "x" * 300  # (a name longer than the system takes: os.stat raises ENAMETOOLONG)


@pytest.fixture(scope="module")
def tiny_front(tmp_path_factory):
    """A real tiny Pareto file (a Ch. 8 seat, 0.3 s runs)."""
    return optimised_front(tmp_path_factory.mktemp("front"), "ch8/pareto_ps_class_a", 0.3)[1]


@pytest.mark.slow  # (the tiny front: 1.5 s)
@pytest.mark.parametrize(
    "args, needle",
    [
        (
            ("analyse", "models", LONG, "{config}"),
            f"{LONG}: cannot inspect it (File name too long)",
        ),
        (("analyse", "transmissibility", LONG), "cannot inspect it (File name too long)"),
        (
            ("analyse", "roads", "{front}", "--road", LONG),
            f"--road {LONG}: cannot inspect it (File name too long)",
        ),
        (("export", "{front}", "--csv", LONG), f"--csv {LONG}: cannot inspect it (File name"),
        (("export", "{front}", "--csv", "{config}"), "is not a folder"),
    ],
    ids=["models", "transmissibility", "road", "csv-long", "csv-file"],
)
def test_a_path_the_system_cannot_look_up_is_bad_input(tiny_front, capsys, args, needle):
    """A name longer than the system takes, given where a command looks a path up before it
    reads it (``analyse``'s sources and ``--road``, ``export --csv``'s folder): Path.exists
    raised OSError there, a traceback."""
    argv = [a.format(front=tiny_front, config=CONFIGS / "quickstart.yaml") for a in args]
    before = sorted(p.name for p in tiny_front.parent.iterdir())
    message = one_error(capsys, *argv)
    assert needle in message, message
    assert sorted(p.name for p in tiny_front.parent.iterdir()) == before  # nothing written


def test_the_librarys_writers_refuse_a_folder_the_system_cannot_look_up(tmp_path):
    """``atomic_file`` (every writer's) looked its folder up with ``Path.is_dir`` before
    ``check_target``: a name too long was an OSError there (the command line checks its
    outputs first, so only the library met it)."""
    from suspopt.io import atomic_file

    with pytest.raises(suspopt.ConfigError, match=r"cannot inspect it \(File name too long\)"):
        with atomic_file(tmp_path / LONG / "out.h5") as stream:
            stream.write(b"never")
    from suspopt.optimisation.output import read_checkpoint  # (optimise(..., resume=True))

    with pytest.raises(suspopt.ConfigError, match=r"--resume: .*: cannot inspect it \(File name"):
        read_checkpoint(tmp_path / LONG, None, None)
    assert list(tmp_path.iterdir()) == []


def test_a_relative_output_in_a_deleted_working_folder_is_bad_input(tmp_path, capsys, monkeypatch):
    """``cd build && rm -r ../build && suspopt simulate ... -o out.h5``: '.' still answers
    as a folder, so the output's lock looked up its full path and got a traceback."""
    gone = tmp_path / "gone"
    gone.mkdir()
    monkeypatch.chdir(gone)
    gone.rmdir()
    message = one_error(capsys, "simulate", CONFIGS / "quickstart.yaml", "-o", "out.h5")
    assert message == "error: -o out.h5: folder . does not exist"


def test_force_replaces_a_foreign_file_and_suspopt_replaces_its_own(tmp_path, capsys):
    target = write(tmp_path, "my notes\n", "out.h5")
    code, _, err = cli(capsys, "simulate", CONFIGS / "quickstart.yaml", "-o", target, "--force")
    assert code == 0, err
    assert cli(capsys, "simulate", CONFIGS / "quickstart.yaml", "-o", target)[0] == 0
    with h5py.File(target) as h5:
        assert "suspopt_version" in h5.attrs
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.h5"]
    assert oct(target.stat().st_mode & 0o777) != oct(0o600)


def test_a_config_suspopt_wrote_is_the_users_once_edited(tmp_path, capsys, front):
    """``init`` and ``export -o`` sign the configs they write (the last line: the SHA-256 of
    the lines above). Run again, they replace their own unedited config, but not one the
    user has edited since (they did: an hour's edits gone at a rerun from the shell's
    history), nor a YAML file without a signature that merely mentions suspopt."""
    from suspopt.io import is_suspopt_output

    config = tmp_path / "car.yaml"
    for _ in range(2):
        assert cli(capsys, "init", "quarter", "-o", config)[0] == 0
    signature = config.read_text().splitlines()[-1]
    assert signature.startswith("# suspopt ") and " sha256 " in signature
    assert is_suspopt_output(config)
    for edit in (
        lambda text: text.replace("dt:", "dt: ", 1),  # a line changed
        lambda text: text + "# my note\n",  # a line added after the signature
        lambda text: text.replace(signature, signature.replace("sha256 ", "sha256 0", 1)[:-1]),
    ):
        original = config.read_text()
        config.write_text(edit(original))
        edited = config.read_bytes()
        message = one_error(capsys, "init", "quarter", "-o", config)
        assert (
            message
            == f"error: -o {config}: was edited since suspopt wrote it; give --force to replace it"
        )
        assert config.read_bytes() == edited and not is_suspopt_output(config)
        assert cli(capsys, "init", "quarter", "-o", config, "--force")[0] == 0
        assert config.read_text() == original
    mine = write(tmp_path, "# my suspopt study\nvehicle: {preset: quarter}\n", "mine.yaml")
    assert "not written by suspopt" in one_error(capsys, "init", "quarter", "-o", mine)
    # a design exported from a front of an exported design: one signature, the last line
    _, pareto = front
    design = tmp_path / "design.yaml"
    for _ in range(2):
        assert cli(capsys, "export", pareto, "--pick", "knee", "-o", design)[0] == 0
    again = tmp_path / "again.h5"
    assert cli(capsys, "optimise", design, "-o", again)[0] == 0
    assert cli(capsys, "export", again, "--pick", "knee", "-o", tmp_path / "d2.yaml")[0] == 0
    lines = (tmp_path / "d2.yaml").read_text().splitlines()
    assert [i for i, line in enumerate(lines) if " sha256 " in line] == [len(lines) - 1]
    assert is_suspopt_output(tmp_path / "d2.yaml")


def test_a_killed_writers_temporary_files_are_removed(tmp_path, capsys):
    stale = [
        write(tmp_path, b"half a file", f".out.h5.{tag}.suspopt-tmp") for tag in ("a1b2c3", "zz")
    ]
    other = write(tmp_path, b"not ours", ".other.h5.x.suspopt-tmp")
    assert cli(capsys, "simulate", CONFIGS / "quickstart.yaml", "-o", tmp_path / "out.h5")[0] == 0
    assert not any(p.exists() for p in stale) and other.exists()


def test_a_second_writer_is_refused(tmp_path):
    from suspopt.io import claim

    target = tmp_path / "out.h5"
    with claim(target):
        proc = subprocess.run(
            [
                sys.executable,
                "-m",
                "suspopt",
                "simulate",
                str(CONFIGS / "quickstart.yaml"),
                "-o",
                str(target),
            ],
            capture_output=True,
            text=True,
            timeout=120,
            cwd=ROOT,
        )
    assert proc.returncode == 2
    assert f"another suspopt run (process {os.getpid()}) is writing it" in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1 and not target.exists()
    assert list(tmp_path.iterdir()) == []  # the lock went with its holder


def test_a_failed_write_leaves_the_old_file(tmp_path, capsys, monkeypatch):
    from suspopt import io

    target = tmp_path / "out.h5"
    assert cli(capsys, "simulate", CONFIGS / "quickstart.yaml", "-o", target)[0] == 0
    before = target.read_bytes()

    def broken(*args, **kwargs):
        raise OSError("disk full")

    monkeypatch.setattr(io, "write_dataset", broken)
    with pytest.raises(OSError, match="disk full"):
        cli(capsys, "simulate", CONFIGS / "quickstart.yaml", "-o", target)
    assert target.read_bytes() == before and sorted(tmp_path.iterdir()) == [target]


def _no_space(*args, **kwargs):
    raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))


def test_a_full_disk_is_one_line_and_leaves_the_old_file(tmp_path, capsys, monkeypatch):
    """A full disk while the data are written, or already when the output's lock takes its
    few bytes: one line naming the file, exit 2, the old file as it was and no temporary
    file or lock left (tracebacks before; checked by hand on a 512 kB tmpfs too)."""
    from suspopt import io

    target = tmp_path / "out.h5"
    assert cli(capsys, "simulate", CONFIGS / "quickstart.yaml", "-o", target)[0] == 0
    before = target.read_bytes()
    with monkeypatch.context() as patch:
        patch.setattr(io, "write_dataset", _no_space)
        message = one_error(capsys, "simulate", CONFIGS / "quickstart.yaml", "-o", target)
    assert message == f"error: {target}: cannot write it (No space left on device)"
    assert target.read_bytes() == before and sorted(tmp_path.iterdir()) == [target]
    with monkeypatch.context() as patch:
        patch.setattr(io.os, "pwrite", _no_space)
        message = one_error(capsys, "init", "quarter", "-o", tmp_path / "new.yaml")
    assert (
        message
        == f"error: -o {tmp_path / 'new.yaml'}: cannot write in {tmp_path} (No space left on device)"
    )
    assert sorted(tmp_path.iterdir()) == [target]


def test_a_csv_export_that_fails_on_one_table_leaves_none(tmp_path, capsys, monkeypatch):
    """The tables of ``export --csv`` are renamed into place together, once all are written:
    a full disk at the second left the first behind before. A file given as the folder is
    named as such."""
    from suspopt import export

    source = tmp_path / "run.h5"
    assert cli(capsys, "simulate", CONFIGS / "quickstart.yaml", "-o", source)[0] == 0
    written = []
    real = export._write_table

    def second_fails(stream, *args):
        written.append(stream)
        if len(written) == 2:
            _no_space()
        real(stream, *args)

    monkeypatch.setattr(export, "_write_table", second_fails)
    message = one_error(capsys, "export", source, "--csv", tmp_path / "tables")
    assert "tables/run." in message and message.endswith(
        "cannot write it (No space left on device)"
    )
    assert sorted(tmp_path.iterdir()) == [source]  # (the folder it made, too, is gone)
    monkeypatch.setattr(export, "_write_table", real)
    code, out, _ = cli(capsys, "export", source, "--csv", tmp_path / "tables")
    assert code == 0 and len(list((tmp_path / "tables").iterdir())) > len(written) == 2
    # a file where the folder should be: said so (mkdir's "File exists" before)
    message = one_error(capsys, "export", source, "--csv", source)
    assert message == f"error: --csv {source}: is not a folder"


# --- checkpoints ------------------------------------------------------------------------------

TINY_RUN = """\
vehicle:
  preset: quarter
  body: {mass: 285}
  corners:
    F1: {unsprung_mass: 25, tyre: {stiffness: 2.0e5}, spring: {linear: 3.0e4}, damper: {c: 2500}}
road: {kind: bump_half_sine, height: 0.05, length: 1.0, speed: 11.111, start: 0.1}
simulation: {duration: 0.4, dt: 1.0e-3}
design_variables:
  - {name: k, path: vehicle.corners.F1.spring.linear, lower: 1.0e4, upper: 1.0e5}
  - {name: c, path: vehicle.corners.F1.damper.c, lower: 500, upper: 5000}
objectives:
  main:
    - {name: f1, metric: var, signal: body.heave_acc}
    - {name: f2, metric: var, signal: travel.F1}
optimiser: {algorithm: nsga2, population: 6, generations: 3, seed: 2}
"""


@pytest.fixture
def front(tmp_path, capsys) -> tuple[Path, Path]:
    config = write(tmp_path, TINY_RUN)
    out = tmp_path / "front.h5"
    code, _, err = cli(capsys, "optimise", config, "-o", out)
    assert code == 0, err
    return config, out


class _Payload:
    def __reduce__(self):
        return (os.system, (f"touch {_Payload.marker}",))


def test_a_crafted_checkpoint_runs_no_code(front, capsys, tmp_path):
    config, out = front
    _Payload.marker = tmp_path / "pwned"
    with h5py.File(out, "a") as h5:
        del h5["checkpoint"]
        h5.create_dataset("checkpoint/state", data=np.void(pickle.dumps(_Payload())))
    message = one_error(capsys, "optimise", config, "-o", out, "--resume")
    assert (
        "/checkpoint/state: an old checkpoint (a pickle), which suspopt no longer loads" in message
    )
    assert not _Payload.marker.exists()


@pytest.mark.parametrize(
    "damage, needle",
    [
        (lambda h5: h5.__delitem__("checkpoint/X"), "/checkpoint/X: missing"),
        (
            lambda h5: (
                h5.__delitem__("checkpoint/F"),
                h5.create_dataset("checkpoint/F", data=np.array([b"x"] * 18)),
            ),
            "/checkpoint/F: holds |S1 values, not numbers",
        ),
        (
            lambda h5: h5["checkpoint/batches"].__setitem__(0, 5),
            "/checkpoint: batches of 17 designs",
        ),
        (
            lambda h5: h5["checkpoint/F"].__setitem__((17, 0), 0.0),  # the last generation's
            "/history: replaying the checkpoint does not give the stored run",
        ),  # best changes
        (
            lambda h5: h5["checkpoint/F"].__setitem__((3, 0), 1.0),  # an earlier generation
            "/checkpoint/X: batch 2 holds other designs",
        ),  # changes the later ones
        (
            lambda h5: h5["checkpoint/X"].__setitem__((7, 1), 0.5),
            "/checkpoint/X: batch 1 holds other designs than the run asks for",
        ),
        (
            lambda h5: h5["checkpoint"].attrs.__setitem__("generations", -3),
            "attribute 'generations'",
        ),
    ],
)
@pytest.mark.slow
def test_a_damaged_checkpoint_is_a_clear_error(front, capsys, damage, needle):
    config, out = front
    with h5py.File(out, "a") as h5:
        damage(h5)
    message = one_error(capsys, "optimise", config, "-o", out, "--resume")
    assert needle in message and str(out) in message, message


def test_an_output_that_is_an_input_is_bad_input_and_the_input_stays(front, capsys, tmp_path):
    """Every command wrote over its own input when told to (``kesort front.h5 -o front.h5``
    replaced the front; ``simulate cfg.yaml -o cfg.yaml`` the config, with HDF5; ``report``
    the front with HTML), and ``-o`` and ``--plot`` on one file kept only the figure. Each is
    now refused, whatever ``--force`` says, and nothing is written; another spelling of the
    path, a hard link and a symbolic link to the input count as the input."""
    import hashlib

    config, out = front
    (tmp_path / "link.h5").hardlink_to(out)
    (tmp_path / "symlink.h5").symlink_to(out)
    other = tmp_path / "sub" / ".." / out.name
    (tmp_path / "sub").mkdir()
    commands = [
        ["kesort", out, "-o", out],
        ["kesort", tmp_path / "symlink.h5", "-o", tmp_path / "link.h5"],
        ["kesort", out, "-c", config, "-o", config],
        ["simulate", out, "--pick", "knee", "-o", other],
        ["simulate", config, "-o", config, "--force"],
        ["simulate", config, "-o", tmp_path / "s.png", "--plot", tmp_path / "s.png"],
        ["optimise", config, "-o", config],
        ["export", out, "--pick", "knee", "-o", out],
        ["report", out, "-o", out],
        ["analyse", "roads", out, "--road", config, "-o", config],
        ["analyse", "controllers", out, "--with", config, "-o", config],
        ["analyse", "masses", out, "-o", out, "--force"],
        ["analyse", "models", config, "--reference", config, "-o", config],
    ]
    digests = {p: hashlib.sha256(p.read_bytes()).hexdigest() for p in (config, out)}
    for argv in commands:
        message = one_error(capsys, *argv)
        assert "is the same file as" in message and "choose another output" in message, argv
        assert not (tmp_path / "s.png").exists()
    assert {p: hashlib.sha256(p.read_bytes()).hexdigest() for p in (config, out)} == digests


def test_a_road_profile_that_is_the_output_is_bad_input_and_stays(tmp_path, capsys):
    """A config's road profile was no input of the output check: ``simulate cfg.yaml -o
    road.csv --force`` replaced the profile with HDF5. It is now refused for its suffix and,
    named as HDF5 (``road.h5``), at the key that names it; the profile stays as it was."""
    road = tmp_path / "road.csv"
    road.write_bytes(b"distance,height\n0,0\n10,0.01\n20,0\n30,0.02\n40,0\n")
    text = GOOD.split("road:")[0] + (
        "road: {kind: file, path: road.csv, speed: 10}\nsimulation: {duration: 1.0}\n"
    )
    config = write(tmp_path, text)
    message = one_error(capsys, "simulate", config, "-o", tmp_path / "." / "road.csv", "--force")
    assert "road.csv: ends in .csv, but this writes HDF5" in message  # (its suffix first)
    # a profile whose name has an HDF5 suffix (the reader takes any name)
    road = road.rename(tmp_path / "road.h5")
    config = write(tmp_path, text.replace("path: road.csv", "path: road.h5"))
    message = one_error(capsys, "simulate", config, "-o", tmp_path / "." / "road.h5", "--force")
    assert message.startswith(f"error: {config}:18: road.path: road profile") and (
        "is an output of this command, which writing would replace it" in message
    )
    assert road.read_bytes().startswith(b"distance,height")
    cli(capsys, "simulate", config, "-o", tmp_path / "out.h5")  # (the profile reads again)
    assert (tmp_path / "out.h5").exists()


def test_the_librarys_writers_refuse_their_own_inputs_too(front, tmp_path):
    """``optimise(cfg, "study.yaml")`` wrote the front over the config after its first
    generation, and ``write_selection`` and ``write_pseudo_fronts`` over the front they
    read; the command line refused each. Now the library does, before any simulation."""
    import hashlib

    from suspopt.analyse.pseudo import pseudo_fronts, road_variants, write_pseudo_fronts
    from suspopt.choosing.selection import load_design_sets, read_pareto, select, write_selection
    from suspopt.optimisation import optimise

    config, out = front
    digests = {p: hashlib.sha256(p.read_bytes()).hexdigest() for p in (config, out)}
    cfg = suspopt.load_config(config)
    pareto = read_pareto(out)
    heard: list = []
    writes = [
        lambda: optimise(cfg, tmp_path / ".." / tmp_path.name / config.name, callback=heard.append),
        lambda: write_selection(out, select(load_design_sets([out]))),
        lambda: write_pseudo_fronts(
            out, pseudo_fronts("roads", pareto, road_variants(pareto, config))
        ),
    ]
    for write in writes:
        with pytest.raises(suspopt.ConfigError, match="is the same file as the (config|input)"):
            write()
    assert {p: hashlib.sha256(p.read_bytes()).hexdigest() for p in (config, out)} == digests
    assert heard == []  # (optimise refused before its first generation)


def test_a_finished_run_resumes_to_itself(front, capsys):
    config, out = front
    with h5py.File(out) as h5:
        before = {k: h5[f"pareto/{k}"][()] for k in "XFG"}
    assert cli(capsys, "optimise", config, "-o", out, "--resume")[0] == 0
    with h5py.File(out) as h5:
        for k in "XFG":
            np.testing.assert_array_equal(h5[f"pareto/{k}"][()], before[k])


def test_a_run_whose_every_design_failed_says_so(tmp_path, capsys):
    text = (
        TINY_RUN.replace("body: {mass: 285}", "body: {mass: 285}\n  tyre_lift_off: false")
        .replace(
            "  - {name: c, path: vehicle.corners.F1.damper.c, lower: 500, upper: 5000}\n",
            "  - {name: c, path: vehicle.corners.F1.damper.c, lower: 500, upper: 5000}\n"
            "  - {name: b, path: seat.bar_length, lower: 0.001, upper: 0.005}\n",
        )
        .replace(
            "road:",
            "seat: {kind: nss2, mass: 95, damping: 1000, stiffness_ratio: 0.4, "
            "spring_free_length: 0.15, wall_distance: 0.16, bar_length: 0.06}\n"
            "road:",
        )
        .replace("signal: travel.F1}", "signal: seat.acc}")
    )
    out = tmp_path / "failed.h5"
    code, _, err = cli(capsys, "optimise", write(tmp_path, text), "-o", out)
    assert code == 3 and "error: every design of the optimum failed to simulate" in err
    with h5py.File(out) as h5:
        assert h5.attrs["status"] == "failed"


# --- broken HDF5 inputs -----------------------------------------------------------------------


@pytest.mark.parametrize(
    "damage, needle",
    [
        (
            lambda h5: h5.attrs.__setitem__("config", np.bytes_(b"vehicle: \xff\xfe")),
            "attribute 'config': not UTF-8 text",
        ),
        (
            lambda h5: h5.attrs.__setitem__("config", "vehicle: [unclosed"),
            "front.h5:config:1: malformed YAML",
        ),
        (lambda h5: h5.attrs.__setitem__("config", BOMB), "front.h5:config:"),
        (
            lambda h5: (h5.__delitem__("pareto/F"), h5.create_dataset("pareto/F", data=[[b"a"]])),
            "/pareto/F: holds object values, not numbers",
        ),
        (
            lambda h5: h5["pareto/X"].attrs.__setitem__("names", np.array([b"k", b"zz"])),
            "/pareto/X holds k, zz;",
        ),
        (
            lambda h5: (
                h5.create_dataset("pareto/huge", shape=(10**12, 3), chunks=(1000, 3), dtype="f8")
                and (h5.__delitem__("pareto/G"), h5.move("pareto/huge", "pareto/G"))
            ),
            "/pareto/G: shape (1000000000000, 3) is larger than 1024 MB",
        ),
        (lambda h5: h5.__delitem__("pareto"), "/pareto/X: missing"),
    ],
)
def test_broken_pareto_files_are_clear_errors(front, capsys, damage, needle):
    config, out = front
    with h5py.File(out, "a") as h5:
        damage(h5)
    for command in (("kesort", out), ("analyse", "roads", out, "--road", config)):
        start = time.perf_counter()
        message = one_error(capsys, *command)
        assert needle in message and str(out) in message, message
        assert time.perf_counter() - start < 5


def test_files_that_are_no_hdf5_are_clear_errors(tmp_path, capsys):
    for name, content in (
        ("empty.h5", b""),
        ("text.h5", b"hello"),
        ("truncated.h5", b"\x89HDF\r\n\x1a\n" + b"\0" * 100),
    ):
        path = write(tmp_path, content, name)
        assert f"{path}: not an HDF5 file" in one_error(capsys, "kesort", path)


# --- messages -----------------------------------------------------------------------------


def test_names_are_printed_as_they_are(tmp_path, capsys):
    message = one_error(capsys, "validate", tmp_path / "no:x:such[bold].yaml")
    assert message == f"error: {tmp_path}/no:x:such[bold].yaml: no such config file"


def test_usage_errors_are_one_line(capsys):
    assert (
        one_error(capsys, "simulate")
        == "error: Missing argument 'source'. (see suspopt simulate --help)"
    )
    assert "No such command 'simulat'" in one_error(capsys, "simulat")


@pytest.mark.cli
@pytest.mark.parametrize(
    "found, expected",
    [
        (signal.default_int_handler, (130, "interrupted\n")),
        (signal.SIG_IGN, (0, "")),  # nohup, or a background job of a script: ignored
    ],
    ids=["answered", "ignored"],
)
def test_an_interrupted_command_in_process_leaves_ctrl_c_as_it_found_it(
    capsys, monkeypatch, found, expected
):
    """``main`` called from Python (a notebook, these tests): after an interrupted command the
    process still answers Ctrl-C. (The command line's own process ignores a second one until
    it exits.) A process that ignores Ctrl-C (started by nohup, or in the background by a
    script, as CI may start these tests) goes on ignoring it, during the command too."""
    import suspopt.cli.configs

    def interrupt(_):  # Ctrl-C pressed as the command starts
        signal.raise_signal(signal.SIGINT)

    monkeypatch.setattr(suspopt.cli.configs, "set_memory_limit", interrupt)
    before = signal.signal(signal.SIGINT, found)
    try:
        code, _, err = cli(capsys, "validate", CONFIGS / "quickstart.yaml")
        assert (code, err) == expected
        assert signal.getsignal(signal.SIGINT) is found
    finally:
        signal.signal(signal.SIGINT, before)


@pytest.mark.cli
@pytest.mark.slow
@pytest.mark.parametrize(
    "delay, signum, code, said",
    [
        (0.0, signal.SIGINT, 130, "interrupted"),
        (1.5, signal.SIGINT, 130, "interrupted"),
        (1.5, signal.SIGTERM, 143, "terminated"),
    ],
)
def test_ctrl_c_at_any_moment_exits_130_without_a_traceback(tmp_path, delay, signum, code, said):
    """Interrupted during the start-up imports (as soon as numpy is being loaded, which
    suspopt's own code does) or during the run. (Before suspopt's first line runs, the
    interpreter's own start-up is Python's.) SIGTERM (a batch system's time limit) the same
    way, with its own code: before, Python's default ended the process at once, leaving the
    output's temporary file and lock behind."""
    # (long enough to be running 1.5 s after numpy is loaded: 3 million steps, which the
    # compiled engine takes seconds over, where 300,000 had finished in time)
    long = write(
        tmp_path,
        edited(
            "simulation: {duration: 3.0, dt: 1.0e-3}",
            "simulation: {duration: 3000.0, dt: 1.0e-3, output_dt: 5.0e-3}",
        ),
    )
    # the command starts with Ctrl-C at its default, as a shell's foreground job does,
    # whatever this test process does with it
    found = signal.signal(signal.SIGINT, signal.SIG_DFL)
    try:
        proc = subprocess.Popen(
            [sys.executable, "-m", "suspopt", "simulate", str(long), "-o", str(tmp_path / "o.h5")],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            cwd=ROOT,
        )
    finally:
        signal.signal(signal.SIGINT, found)
    maps = Path(f"/proc/{proc.pid}/maps")
    deadline = time.monotonic() + 30
    while "numpy" not in maps.read_text() and time.monotonic() < deadline:
        time.sleep(0.001)
    time.sleep(delay)
    proc.send_signal(signum)
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == code, (out, err)
    assert "Traceback" not in err and err.strip().splitlines()[-1] == said
    assert sorted(p.name for p in tmp_path.iterdir()) == ["case.yaml"]


@pytest.mark.cli
@pytest.mark.parametrize("encoding", ["ascii", "latin-1"])
def test_a_terminal_that_is_not_utf8_gets_question_marks_not_a_traceback(encoding):
    """``LANG=en_US.ISO-8859-1`` or ``PYTHONIOENCODING=ascii``: the help's Γ and ε, and
    kesort's, made a UnicodeEncodeError traceback (exit 1) before."""
    env = {**os.environ, "PYTHONIOENCODING": encoding}
    proc = subprocess.run(
        [sys.executable, "-m", "suspopt", "kesort", "--help"],
        capture_output=True,
        env=env,
        cwd=ROOT,
    )
    assert proc.returncode == 0 and proc.stderr == b"", proc.stderr[-500:]
    assert b"?" in proc.stdout and b"Eq 6.10" in proc.stdout


@pytest.mark.cli
@pytest.mark.slow
def test_a_reader_that_goes_away_is_not_an_error(tmp_path):
    """``suspopt simulate ... | head -1``: the file is written, nothing on stderr, exit 0 (the
    command's own code), not rich's SystemExit(1)."""
    out = tmp_path / "q.h5"
    proc = subprocess.run(
        f"{shlex.quote(sys.executable)} -m suspopt simulate configs/quickstart.yaml"
        f" -o {shlex.quote(str(out))} | head -c 1; exit ${{PIPESTATUS[0]}}",
        shell=True,
        executable="/bin/bash",
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=120,
    )
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr
    with h5py.File(out) as h5:
        assert "signals" in h5 and "metrics" in h5


@pytest.mark.cli
@pytest.mark.slow
def test_printed_lines_drop_control_characters(tmp_path):
    """A config whose name holds an escape sequence: the line that names it does not colour
    or move the terminal."""
    path = tmp_path / "q\x1b[31m\x07\r.yaml"
    path.write_text((ROOT / "configs" / "quickstart.yaml").read_text())
    proc = subprocess.run(
        [sys.executable, "-m", "suspopt", "validate", str(path)],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert proc.returncode == 0 and "valid" in proc.stdout, proc
    assert not set(proc.stdout) & {"\x1b", "\x07", "\r"}


@pytest.mark.cli
def test_the_command_sizes_blas_to_one_thread_unless_told():
    code = (
        "import os, sys\n"
        "import suspopt._entry as e\n"
        "e.main = lambda **_: print(os.environ.get('OPENBLAS_NUM_THREADS')) or 0\n"
        "e.run()\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_NUM_THREADS"}
    for given, seen in ((None, "1"), ("2", "2")):
        if given is not None:
            env["OPENBLAS_NUM_THREADS"] = given
        proc = subprocess.run(
            [sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=60
        )
        assert proc.returncode == 0 and proc.stdout.strip() == seen, proc


def test_numpy_warnings_are_one_line_each():
    code = (
        "import numpy as np, suspopt.cli.configs as cli\n"
        "from suspopt._entry import main\n"
        "def noisy(path):\n"
        "    for _ in range(3):\n"
        "        np.log(np.zeros(2))\n"
        "    raise SystemExit(0)\n"
        "cli._validate_one = noisy\n"
        "raise SystemExit(main(['validate', 'x.yaml']))\n"
    )
    proc = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=120
    )
    assert proc.returncode == 0 and proc.stderr.splitlines() == [
        "warning: divide by zero encountered in log (at <string>:5)"
    ], proc.stderr


# --- modes ------------------------------------------------------------------------------------


def test_mode_labels_say_what_a_mode_is(load):
    half = suspopt.modal_analysis(suspopt.build_vehicle(load("ch3/part1a_hc1_bump.yaml")))
    np.testing.assert_allclose(half.energy.sum(axis=1), 1.0)
    labels = sorted(half.label[0][2:])  # the two wheel hops: in and out of phase
    assert labels[0].startswith("wheel.F1 ") and labels[1].startswith("wheel.F2 ")
    assert {label.split()[1] for label in labels} == {"+", "-"}
    assert list(half.label[0][:2]) == ["body.roll", "body.heave"]
    quarter = suspopt.modal_analysis(suspopt.build_vehicle(load("ch3/part1a_qc_bump.yaml")))
    assert list(quarter.label[0]) == ["body.heave", "wheel.F1"]
    full = suspopt.modal_analysis(suspopt.build_vehicle(load("ch3/part1a_fc_bump.yaml")))
    wheel_modes = full.label[0][3:]
    assert all(
        sum(f"wheel.{c}" in label for c in ("F1", "F2", "R1", "R2")) >= 2 for label in wheel_modes
    ), wheel_modes


# --- a file that hangs or crashes the HDF5 library ----------------------------------------------


@pytest.mark.parametrize("failure", ["hang", "crash"])
def test_a_file_that_hangs_or_crashes_hdf5_is_bad_input(tmp_path, monkeypatch, failure):
    import os
    import signal
    import time

    from suspopt import h5read

    path = tmp_path / "front.h5"
    with h5py.File(path, "w") as h5:
        h5.attrs["x"] = 1

    def walk(_path):  # stands for a damaged global heap: an endless loop, or a crash, in C
        if failure == "hang":
            time.sleep(60)
        os.kill(os.getpid(), signal.SIGSEGV)

    monkeypatch.setattr(h5read, "_walk", walk)
    monkeypatch.setattr(h5read, "PROBE_SECONDS", 0.5)
    started = time.monotonic()
    with pytest.raises(suspopt.ConfigError, match="damaged: reading its metadata"):
        h5read.H5Reader(path)
    assert time.monotonic() - started < 5


@pytest.mark.parametrize("heap", ["fresh", "after a large run"])
def test_a_text_attribute_that_declares_a_gigabyte_is_bad_input_before_it_is_read(tmp_path, heap):
    """A byte flipped in a text attribute's stored length (found by fuzzing): the HDF5 library
    would allocate the length it says, about 1 GB for a 5 kB file, and then fail. The probe
    runs out of its own memory first, and this process never tries. That holds too when the
    process kept 1.2 GB of freed arrays for reuse (as the command line does), from which the
    probe's child could otherwise take the gigabyte without mapping anything (found by the
    fuzz suite, where a worker's earlier case had left such a heap)."""
    import struct

    from suspopt import h5read, memory

    if heap != "fresh":
        assert memory.reuse_memory()
        kept = np.empty(int(1.2e9), dtype=np.uint8)  # from the heap, never touched
        del kept

    path = tmp_path / "front.h5"
    with h5py.File(path, "w") as h5:
        h5.create_dataset("F", data=np.zeros((3, 2))).attrs["names"] = ["f1", "f2"]
    data = bytearray(path.read_bytes())
    # a variable-length string is stored as (length, global heap address, index)
    at = data.find(struct.pack("<IQ", 2, data.find(b"GCOL")))
    data[at + 3] = 0x3C  # the length's high byte: 2 + 0x3C << 24 bytes
    path.write_bytes(data)
    with pytest.raises(suspopt.ConfigError) as caught:
        h5read.H5Reader(path)
    assert str(caught.value) == (
        f"{path}: damaged: /F: attribute 'names' would take more than "
        f"{(h5read.PROBE_MEMORY + h5read.PROBE_MEMORY_PER_BYTE * len(data)) >> 20} MB to read"
    )
    memory.release_free()  # (this test process's heap back to its size)


def test_text_that_is_not_utf8_in_a_utf8_attribute_is_bad_input(tmp_path):
    """h5py hands such bytes over as lone surrogates, which failed only when written out
    again, after the run, in a message that named no file (found by fuzzing)."""
    from suspopt import h5read

    path = tmp_path / "front.h5"
    with h5py.File(path, "w") as h5:
        ds = h5.create_dataset("F", data=np.zeros((2, 1)))
        ds.attrs.create("names", np.array([b"\x80f1"], dtype=object), dtype=h5py.string_dtype())
    with h5read.H5Reader(path) as h5, pytest.raises(suspopt.ConfigError) as caught:
        h5.labels("F", "names", 1)
    assert str(caught.value) == f"{path}: /F: attribute 'names': not UTF-8 text"


def test_an_intact_file_passes_the_probe(tmp_path):
    from suspopt import h5read

    path = tmp_path / "front.h5"
    with h5py.File(path, "w") as h5:
        h5.attrs["config"] = "vehicle: {}"
        h5.create_dataset("names", data=["a", "b"])
    with h5read.H5Reader(path) as h5:
        assert h5.text_attr("config") == "vehicle: {}"


@pytest.mark.slow
@pytest.mark.cli
def test_a_million_swept_designs_is_bad_input_before_any_mode_is_computed(tmp_path):
    """The memory check comes before the stability check's eigenvalues (once 36 GB)."""
    out = tmp_path / "huge.h5"
    proc = run(
        "simulate",
        ROOT / "configs" / "quickstart.yaml",
        "--sweep",
        "vehicle.corners.F1.damper.c=500:3000:1000000",
        "-o",
        out,
        "--max-memory",
        "2G",
    )
    assert proc.returncode == 2 and "Traceback" not in proc.stderr, proc.stderr
    assert proc.stderr.count("\n") == 1 and "1000000 designs" in proc.stderr
    assert not out.exists()


def test_the_stability_radius_in_chunks_is_the_radius_in_one_pass(monkeypatch):
    import suspopt.checks as checks

    rng = np.random.default_rng(3)
    angle = rng.uniform(np.pi / 2, 3 * np.pi / 2, 1000)
    direction = np.exp(1j * angle)
    whole = checks._rk4_radius(direction)
    monkeypatch.setattr(checks, "_RADIUS_CHUNK", 64)
    np.testing.assert_array_equal(checks._rk4_radius(direction), whole)


@pytest.mark.skipif(
    not sys.platform.startswith("linux") or platform.libc_ver()[0] != "glibc",
    reason="glibc only",
)
def test_reuse_memory_keeps_freed_arrays_mapped():
    """After :func:`suspopt.reuse_memory` a freed 256 MB array stays in the process (the next
    one of that size finds its pages mapped); without it glibc gives it back at once."""
    script = """
import os
import sys
import numpy as np
import suspopt
if sys.argv[1] == "1":
    assert suspopt.reuse_memory() is True
def resident():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
before = resident()
a = np.ones(1 << 25)  # 256 MB, touched
del a
print(resident() - before)
"""
    kept = {}
    for flag in ("0", "1"):
        proc = subprocess.run([sys.executable, "-c", script, flag], capture_output=True, text=True)
        assert proc.returncode == 0, proc.stderr
        kept[flag] = int(proc.stdout)
    assert kept["1"] > 200e6 and kept["0"] < 50e6, kept
