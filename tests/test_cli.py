"""The command line: exit codes, one-line errors naming key and line, atomic HDF5 output."""

from __future__ import annotations

import json

import h5py
import numpy as np
import pytest
from conftest import CONFIGS, run, write

pytestmark = pytest.mark.cli

GOOD = (CONFIGS / "quickstart.yaml").read_text()


BAD_INPUTS = {
    "malformed_yaml": (
        GOOD.replace("  preset: half_pitch", "  preset: [half_pitch"),
        "malformed YAML",
        6,
    ),
    "unknown_key": (
        GOOD.replace("unsprung_mass: 50", "unsprung_mas: 50"),
        "vehicle.corners.F1.unsprung_mas: unknown key; did you mean unsprung_mass",
        9,
    ),
    "negative_mass": (GOOD.replace("mass: 2210", "mass: -2210"), "vehicle.body.mass", 6),
    "zero_mass": (
        GOOD.replace("unsprung_mass: 100", "unsprung_mass: 0"),
        "vehicle.corners.R1.unsprung_mass",
        14,
    ),
    "missing_section": (GOOD.split("simulation:")[0], "simulation: required key is missing", None),
    "wrong_type": (GOOD.replace("height: 0.05", "height: high"), "road.height", 20),
    "no_road_file": (
        GOOD.split("road:")[0] + "road: {kind: file, path: nowhere.csv, "
        "speed: 10}\nsimulation: {duration: 1.0}\n",
        "road.path",
        18,
    ),
}


@pytest.mark.parametrize("case", sorted(BAD_INPUTS))
def test_bad_input_exits_2_with_one_line(tmp_path, case):
    text, needle, line = BAD_INPUTS[case]
    cfg = write(tmp_path, text)
    out = tmp_path / "out.h5"
    proc = run("simulate", cfg, "-o", out)
    assert proc.returncode == 2, proc.stderr
    message = proc.stderr.strip()
    assert len(message.splitlines()) == 1, message
    assert "Traceback" not in proc.stderr + proc.stdout
    assert needle in message
    if line is not None:
        assert f"case.yaml:{line}:" in message
    else:  # (a key absent with every key above it: the file alone, "case.yaml:?:" before)
        assert message.startswith(f"error: {cfg}: "), message
    assert not out.exists()
    assert list(tmp_path.glob("*.tmp")) == [] and list(tmp_path.glob(".*tmp")) == []


def test_missing_config_file_exits_2(tmp_path):
    proc = run("validate", tmp_path / "absent.yaml")
    assert proc.returncode == 2 and "no such config file" in proc.stderr


def test_help_prints_each_text_as_written():
    """Every command's docstring paragraphs and every argument's help appear in ``--help``
    as written: each paragraph on one line of a wide terminal (typer's markup kept the
    docstring's line breaks) and nothing in brackets dropped (``pip install
    'suspopt[dask]'`` came out as ``'suspopt'``)."""
    import inspect
    import re

    from typer.testing import CliRunner

    from suspopt.cli import app

    runner = CliRunner()
    listing = runner.invoke(app, ["--help"], env={"COLUMNS": "400"}).output
    for command in app.registered_commands:
        name = command.name or command.callback.__name__
        output = runner.invoke(app, [name, "--help"], env={"COLUMNS": "400"}).output
        paragraphs = inspect.cleandoc(command.callback.__doc__).split("\n\n")
        flowed = [" ".join(p.split()) for p in paragraphs]
        assert flowed[0] in listing, name
        for paragraph in flowed:
            assert paragraph in output, (name, paragraph)
        helps = [
            p.default.help
            for p in inspect.signature(command.callback).parameters.values()
            if isinstance(getattr(p.default, "help", None), str)
        ]
        for text in [*flowed, *helps]:
            for token in re.findall(r"\S*\[[^\]]*\]\S*", text.replace("\\[", "[")):
                assert token in output, (name, token)
    assert "suspopt[dask]" in runner.invoke(app, ["optimise", "--help"]).output


@pytest.mark.slow
def test_validate_and_schema():
    proc = run("validate", CONFIGS / "quickstart.yaml")
    assert proc.returncode == 0 and "valid" in proc.stdout
    proc = run("schema")
    schema = json.loads(proc.stdout)
    assert {"vehicle", "road", "simulation"} <= set(schema["properties"])


@pytest.mark.slow
def test_simulate_writes_the_design_md_layout(tmp_path):
    out = tmp_path / "run.h5"
    proc = run("simulate", CONFIGS / "quickstart.yaml", "-o", out)
    assert proc.returncode == 0, proc.stderr
    assert "peak |body heave acc|" in proc.stdout
    with h5py.File(out) as h5:
        for key in ("suspopt_version", "created", "command", "config", "seed"):
            assert key in h5.attrs
        assert h5.attrs["config"] == GOOD
        T = h5["time"].shape[0]
        assert T == 3001 and h5["time"].attrs["units"] == "s"
        acc = h5["signals/body.heave_acc"]
        assert acc.shape == (1, T) and acc.attrs["units"] == "m/s^2"
        assert h5["signals/travel.F1"].attrs["units"] == "m"
        assert h5["signals/tyre_force.R1"].attrs["units"] == "N"
        assert np.isnan(h5["diverged_at"][()]).all()
        assert h5["modal/frequency"].attrs["units"] == "Hz"


def test_validate_takes_several_configs_and_gives_each_its_lines(tmp_path):
    """Each config gets its lines in the order given, valid (stdout) or every problem and
    their count (stderr); a bad one does not stop the rest, and the exit code is 2 if any
    is bad."""
    from typer.testing import CliRunner

    from suspopt.cli import app

    good = CONFIGS / "quickstart.yaml"
    bad = write(tmp_path, BAD_INPUTS["unknown_key"][0], "bad.yaml")
    missing = tmp_path / "none.yaml"
    res = CliRunner().invoke(app, ["validate", str(good), str(bad), str(missing), str(good)])
    assert res.exit_code == 2, res.output
    assert res.stdout.splitlines() == [f"{good}: valid (half_pitch, road bump_half_sine)"] * 2
    assert res.stderr.splitlines() == [
        f"error: {bad}:8: vehicle.corners.F1.unsprung_mass: required key is missing",
        f"error: {bad}:9: vehicle.corners.F1.unsprung_mas: unknown key; did you mean "
        "unsprung_mass?",
        f"2 errors in {bad}",
        f"error: {missing}: no such config file",
        f"1 error in {missing}",
    ]
    res = CliRunner().invoke(app, ["validate", str(good), str(good)])
    assert res.exit_code == 0 and res.stderr == ""


@pytest.mark.slow
def test_every_bundled_config_validates():
    # in-process (typer's runner): a subprocess per config costs seconds of imports each,
    # and the command's own process behaviour is covered by test_validate_and_schema
    from typer.testing import CliRunner

    from suspopt.cli import app

    configs = sorted(CONFIGS.rglob("*.yaml"))
    assert len(configs) >= 47
    runner = CliRunner()
    for cfg in configs:
        res = runner.invoke(app, ["validate", str(cfg)])
        assert res.exit_code == 0, f"{cfg}: {res.output}"
        assert res.stderr == "", f"{cfg}: {res.stderr}"  # (not even a warning)
