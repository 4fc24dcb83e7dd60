"""From a chosen design onward: picks re-simulated and exported, batches from the command
line, starter configs, the command's conventions (version, help, 80 columns, quiet)."""

from __future__ import annotations

import os
import re

import h5py
import numpy as np
import pytest
from conftest import CONFIGS, optimised_front

import suspopt
from suspopt._entry import main

pytestmark = pytest.mark.cli


def cli(capsys, *args) -> tuple[int, str, str]:
    code = main([str(a) for a in args])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def printed_table(stdout: str, title: str) -> tuple[list[str], dict[str, list[str]]]:
    """The columns (after quantity and unit) and {quantity: [unit, *values]} of the table
    whose title holds ``title``, as printed, its parts (a table wider than the terminal)
    joined."""
    heads: list[str] = []
    rows: dict[str, list[str]] = {}
    part = None
    for line in stdout.splitlines():
        if title in line and not line.startswith(("┃", "│")):
            part = []
        elif part is not None and line.startswith(("┃", "│")):
            cells = [c.strip() for c in line.strip("┃│").split("┃" if "┃" in line else "│")]
            if line.startswith("┃"):
                part = cells[2:]
                heads += part
            else:
                rows.setdefault(cells[0], [cells[1]]).extend(cells[2:])
        elif part is not None and line.startswith("└"):
            part = None
    return heads, rows


@pytest.fixture(scope="module")
def kesort_file(tmp_path_factory):
    """A kesort file of a tiny Ch. 7 SH-2 front (main f1-f2, supplementary f3-f6)."""
    from suspopt.choosing.selection import load_design_sets, select, write_selection

    folder = tmp_path_factory.mktemp("loop")
    _, front = optimised_front(folder, "ch7/sh_2", 1.0, population=10, generations=3)
    out = folder / "ke.h5"
    write_selection(out, select(load_design_sets([front]), P="auto"))
    return front, out


@pytest.mark.slow
def test_a_kesort_knee_re_simulated_gives_its_stored_objectives(kesort_file, tmp_path, capsys):
    _, ke = kesort_file
    out, figure = tmp_path / "knee.h5", tmp_path / "knee.svg"
    code, stdout, err = cli(
        capsys, "simulate", ke, "--pick", "knee,chosen", "-o", out, "--plot", figure
    )
    assert code == 0, err
    legend = figure.read_text()  # (the picks name the curves)
    named = r"\b{} \(design \d+\) F1\.[\w.]+="  # (each pick with its design id)
    assert re.search(named.format("knee"), legend) and re.search(named.format("chosen"), legend)
    with h5py.File(ke) as h5:
        rows = [int(h5["kesort/picks/knee"][()]), int(h5["kesort/chosen"][()])]
        stored = h5["kesort/F"][rows]
        names = list(h5["kesort/F"].attrs["names"])
    with h5py.File(out) as h5:
        assert [p.decode() for p in h5["designs/pick"][()]] == ["knee", "chosen"]
        assert h5["designs/row"][()].tolist() == rows
        assert h5["designs"].attrs["source"] == str(ke)
        F = h5["objectives/F"]
        assert list(F.attrs["names"]) == names  # main then supplementary
        np.testing.assert_allclose(F[()], stored, rtol=1e-9)
        assert h5["designs/X"].shape == (2, 6) and (F[()] < 1e10).all()
        X = h5["designs/X"]
        units = list(X.attrs["units"].astype(str))
        X, paths = X[()], list(X.attrs["names"].astype(str))
    with h5py.File(ke) as h5:
        variables = list(h5["kesort/X"].attrs["names"].astype(str))
        assert list(h5["kesort/X"].attrs["units"].astype(str)) == units  # (from the config)
    heads, rows = printed_table(stdout, " - key results")
    assert heads == ["knee", "chosen"]  # each column is the pick it shows
    for j, (name, unit) in enumerate(zip(variables, units)):  # each pick's variables on top
        assert rows[name] == [unit, *(f"{x:.4g}" for x in X[:, j])], (name, paths[j])
    assert list(rows)[: len(variables)] == variables and "peak body heave" in rows


def test_an_exported_design_validates_and_gives_its_objectives(kesort_file, tmp_path, capsys):
    front, _ = kesort_file
    design = tmp_path / "design.yaml"
    code, _, err = cli(capsys, "export", front, "--pick", "best_f2", "-o", design)
    assert code == 0, err
    text = design.read_text()
    assert text.startswith("# Design 'best_f2' (row ") and str(front) in text.splitlines()[0]
    assert cli(capsys, "validate", design)[0] == 0
    cfg = suspopt.load_config(design)
    problem = suspopt.Problem.from_config(cfg)
    with h5py.File(front) as h5:
        row = suspopt.pareto_picks(h5["pareto/F"][()], ["f1", "f2"])["best_f2"]
        stored = h5["pareto/F"][row]
    # the config holds the design itself: its own values are the picked design's
    values = [[_value(cfg, v.path) for v in cfg.design_variables]]
    F = problem.evaluate(problem.to_search(values), return_values_of=["F"])
    np.testing.assert_allclose(F[0], stored, rtol=1e-9)
    message = cli(capsys, "export", front, "--pick", "knee,best_f1", "-o", tmp_path / "x.yaml")
    assert message[0] == 2 and "-o writes one design; got 2" in message[2]


def _value(cfg, path):
    node = cfg
    for part in path.split("."):
        node = node[part] if isinstance(node, dict) else getattr(node, part)
    return node


def test_unknown_picks_list_the_choices(kesort_file, capsys):
    front, ke = kesort_file
    code, _, err = cli(capsys, "simulate", ke, "--pick", "kneee")
    assert code == 2 and "has no such pick; it has chosen, best_f1" in err
    code, _, err = cli(capsys, "simulate", front, "--pick", "99")
    assert code == 2 and "/pareto has rows 0 to" in err
    code, _, err = cli(capsys, "simulate", front)
    assert code == 2 and "name the designs to simulate with --pick" in err


@pytest.mark.slow
def test_the_library_takes_picks_as_the_command_line_does(kesort_file):
    """``read_picks`` takes one string as ``--pick`` does (it was read letter by letter:
    "no such pick k"), and no pick is a ConfigError (an IndexError before);
    ``design_config`` names the designs it holds for an index it lacks."""
    from suspopt.choosing.picks import design_config, read_picks

    _, ke = kesort_file
    assert read_picks(ke, "chosen,knee").names == ["chosen", "knee"]
    assert read_picks(ke, [0, "knee"]).names == ["0", "knee"]
    with pytest.raises(suspopt.ConfigError, match="name a design"):
        read_picks(ke, [])
    picked = read_picks(ke, "knee")
    with pytest.raises(IndexError, match=r"design 1: picked holds 1 design\(s\), 0..0"):
        design_config(picked, 1)
    for i in (0.5, None, "0"):  # (no row number: a TypeError, as a list's index gives)
        with pytest.raises(TypeError, match="i must be a design's row number in picked"):
            design_config(picked, i)
    assert design_config(picked, -1)[1] == design_config(picked, 0)[1]


def test_the_selection_functions_name_the_object_they_want(tmp_path):
    """``select`` of file names, ``write_selection`` of no selection and ``design_config`` of
    no picks were AttributeErrors from inside ("'str' object has no attribute 'names'")."""
    from suspopt.choosing.picks import design_config
    from suspopt.choosing.selection import select, write_selection

    with pytest.raises(TypeError, match=r"sets\[0\] must be a DesignSet \(from load_design_sets"):
        select("front.h5")
    with pytest.raises(TypeError, match=r"selection must be a Selection \(from select\(sets\)\)"):
        write_selection(tmp_path / "new.h5", None)
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(TypeError, match=r"picked must be a Picked \(from read_picks"):
        design_config("choice.h5")


@pytest.mark.slow
def test_sets_sweeps_and_names_given_as_one_string_are_one_item(kesort_file):
    """``apply_sets(cfg, "PATH=VALUE")`` and ``sweep`` said "--set 'v': expected
    PATH=VALUE" (the first letter), ``report.collect(path, "knee")`` "no such pick k", and
    ``kesort(F, names="RC")`` took R and C as two objectives' names."""
    from suspopt.params import apply_sets, sweep
    from suspopt.report import collect

    cfg = suspopt.load_config(CONFIGS / "quickstart.yaml")
    assert apply_sets(cfg, "vehicle.body.mass=300").vehicle.body.mass == 300
    assert sweep(cfg, "vehicle.body.mass=300:400:3")["vehicle.body.mass"].tolist() == [
        300.0,
        350.0,
        400.0,
    ]
    front, _ = kesort_file
    assert collect(front, "knee").data == collect(front, ["knee"]).data
    with pytest.raises(ValueError, match="1 names for 2 objectives"):
        suspopt.kesort(np.eye(2) + 1.0, names="RC")


def test_a_sweep_of_3_by_4_values_is_one_batch_of_12_named_designs(tmp_path, capsys, monkeypatch):
    import importlib

    simulate_module = importlib.import_module("suspopt.simulation")

    batches = []
    real = simulate_module._run
    monkeypatch.setattr(
        simulate_module,
        "_run",
        lambda cfg, prepared, *a: batches.append(prepared.pv.P) or real(cfg, prepared, *a),
    )
    out = tmp_path / "sweep.h5"
    code, stdout, err = cli(
        capsys,
        "simulate",
        CONFIGS / "quickstart.yaml",
        "-o",
        out,
        "--sweep",
        "vehicle.corners.F1.damper.c=1000:4000:3",
        "--sweep",
        "vehicle.corners.R1.spring.linear=4e4:7e4:4",
        "--set",
        "simulation.duration=1.0",
    )
    assert code == 0, err
    assert batches == [12]
    with h5py.File(out) as h5:
        X = h5["designs/X"]
        assert X.shape == (12, 2)
        assert list(X.attrs["names"]) == [
            "vehicle.corners.F1.damper.c",
            "vehicle.corners.R1.spring.linear",
        ]
        np.testing.assert_array_equal(X[:, 0], np.repeat([1000.0, 2500.0, 4000.0], 4))
        np.testing.assert_array_equal(X[:, 1], np.tile([4e4, 5e4, 6e4, 7e4], 3))
        assert list(X.attrs["units"].astype(str)) == ["N s/m", "N/m"]  # (not "SI")
        assert h5["signals/body.heave"].shape == (12, 1001)  # --set: 1 s
        peak = 1e3 * h5["signals/body.heave"][()].max(axis=1)
        X = X[()]
    heads, rows = printed_table(stdout, " - key results (5 of 12 designs, evenly spaced by index)")
    shown = [int(h.removeprefix("design ")) for h in heads]
    assert len(set(shown)) == 5 and shown == sorted(shown) and shown[0] == 0 and shown[-1] == 11
    for j, path in enumerate(["vehicle.corners.F1.damper.c", "vehicle.corners.R1.spring.linear"]):
        assert rows[path] == [["N s/m", "N/m"][j], *(f"{X[p, j]:.4g}" for p in shown)]
    assert rows["peak body heave"] == ["mm", *(f"{peak[p]:.4g}" for p in shown)]
    code, _, err = cli(
        capsys,
        "simulate",
        CONFIGS / "quickstart.yaml",
        "--zip",
        "--sweep",
        "vehicle.corners.F1.damper.c=1000:4000:3",
        "--sweep",
        "vehicle.corners.R1.damper.c=1000:2000:4",
    )
    assert code == 2 and "zipped sweeps need the same N" in err


@pytest.mark.parametrize(
    "args, needle",
    [
        (
            ("--set", "vehicle.body.mas=3"),
            "--set vehicle.body.mas: not a numeric field of this "
            "config; did you mean vehicle.body.mass",
        ),
        (("--set", "vehicle.body.mass=heavy"), "'heavy' is not a number"),
        (
            ("--set", "vehicle.body.mass=-3"),
            "vehicle.body.mass: must be at least 0.001 kg (got -3)",
        ),
        (
            ("--sweep", "road.speed=1:2:3"),
            "--sweep road.speed: cannot vary between the designs "
            "of one run: the road is one per run; use --set",
        ),
        (("--sweep", "vehicle.body.mass=1:2"), "expected PATH=START:STOP:N"),
    ],
)
def test_bad_sets_and_sweeps_are_one_line(capsys, args, needle):
    code, _, err = cli(capsys, "simulate", CONFIGS / "quickstart.yaml", *args)
    assert code == 2 and needle in err and len(err.strip().splitlines()) == 1, err


@pytest.mark.parametrize("kind", ["quarter", "optimise"])
def test_init_writes_a_config_that_validates(tmp_path, capsys, kind):
    path = tmp_path / "case.yaml"
    code, out, _ = cli(capsys, "init", kind, "-o", path)
    assert code == 0 and f"suspopt validate {path}" in out
    assert cli(capsys, "validate", path)[0] == 0
    assert cli(capsys, "init", kind, "-o", path)[0] == 0  # its own file: replaced
    code, _, err = cli(capsys, "init", "quater", "-o", tmp_path / "other.yaml")
    assert code == 2 and "did you mean quarter" in err


def test_the_command_follows_the_conventions(capsys):
    code, out, _ = cli(capsys, "--version")
    assert code == 0 and out.strip() == f"suspopt {suspopt.__version__}"
    code, out, _ = cli(capsys, "analyse", "--help")
    from suspopt.analyse import SUMMARIES, analysis_kinds

    assert set(SUMMARIES) == set(analysis_kinds())
    help_text = " ".join(out.split())
    assert all(f"{kind}:" in help_text for kind in SUMMARIES)
    code, out, err = cli(capsys, "-q", "simulate", CONFIGS / "quickstart.yaml")
    assert code == 0 and out == ""
    code, _, err = cli(capsys, "-v", "validate", CONFIGS / "quickstart.yaml")
    assert code == 0


@pytest.mark.slow
def test_tables_fit_80_columns_without_cutting_a_cell(kesort_file, monkeypatch, capsys):
    import sys

    from rich.console import Console

    narrow = Console(width=80, markup=False, emoji=False, highlight=False)
    for name, module in list(sys.modules.items()):  # every command module prints to it
        if name.startswith("suspopt.cli") and hasattr(module, "out"):
            monkeypatch.setattr(module, "out", narrow)
    front, ke = kesort_file
    for args in (
        ("simulate", CONFIGS / "ch3/part1a_fc_bump.yaml"),
        ("kesort", front),
        ("simulate", ke, "--pick", "knee,best_f1,best_f2,best_f3"),
        (
            "analyse",
            "models",
            CONFIGS / "ch3/part1a_qc_bump.yaml",
            CONFIGS / "ch3/part1a_fc_bump.yaml",
        ),
    ):
        code, out, err = cli(capsys, *args)
        assert code == 0, err
        lines = out.splitlines()
        assert lines and max(len(line) for line in lines) <= 80
        assert "…" not in out, args


def test_the_hypervolume_of_a_run_never_falls(tmp_path):
    _, front = optimised_front(tmp_path, "ch8/pareto_ps_class_a", 1.0, population=10, generations=6)
    with h5py.File(front) as h5:
        hv = h5["history/hypervolume"][()]
    hv = hv[np.isfinite(hv)]
    assert len(hv) >= 2 and (np.diff(hv) >= 0).all(), hv


def test_startup_does_not_import_the_heavy_modules():
    import subprocess
    import sys

    code = (
        "import sys, suspopt.cli\n"
        "heavy = [m for m in ('scipy', 'pymoo', 'matplotlib', 'h5py', 'numpy', 'pydantic')"
        " if m in sys.modules]\n"
        "print(heavy)\n"
    )
    proc = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        env={**os.environ, "PYTHONPATH": str(CONFIGS.parent)},
    )
    assert proc.stdout.strip() == "[]", proc.stdout + proc.stderr


@pytest.mark.slow
def test_simulate_of_a_config_writes_its_plot(tmp_path, capsys):
    fig = tmp_path / "run.png"
    code, out, err = cli(capsys, "simulate", CONFIGS / "quickstart.yaml", "--plot", fig)
    assert code == 0, err
    assert fig.stat().st_size > 10_000 and re.search(r"wrote .*run\.png", out)


@pytest.mark.parametrize(
    "groups, attrs, needle",
    [
        (["kesort"], {}, "the file holds a k-ε selection (suspopt kesort)"),
        (["signals", "metrics"], {}, "the file holds a simulation's signals (suspopt simulate)"),
        (
            ["pareto", "pseudo"],
            {"analysis": "masses"},
            "the file holds the results of suspopt analyse masses",
        ),
        ([], {}, "(is this a suspopt file of the right kind?)"),
    ],
    ids=["kesort", "simulate", "analyse", "unknown"],
)
def test_a_result_of_another_command_is_named_for_what_it_holds(
    tmp_path, capsys, groups, attrs, needle
):
    """``kesort chosen.h5`` (a simulation) said "/pareto/X: missing (is this a suspopt file
    of the right kind?)"; it now says what the file holds and which command writes that."""
    path = tmp_path / "other.h5"
    with h5py.File(path, "w") as h5:
        h5.attrs.update({"suspopt_version": suspopt.__version__, **attrs})
        for group in groups:
            h5.create_group(group)
    code, _, err = cli(capsys, "kesort", path)
    assert code == 2 and err.count("\n") == 1, err
    assert f"other.h5: /pareto/X: missing{'; ' if needle[0] != '(' else ' '}{needle}" in err, err
