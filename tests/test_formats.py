"""The file formats declared once (:mod:`suspopt.formats`): a file of every kind holds what its
format declares and nothing else; every reader of a kind, given a copy with one declared
dataset missing or replaced by a text, exits 0 or 2 with one located line, never a
traceback; and every analysis computes without writing, then writes a file of its format."""

from __future__ import annotations

import shutil
import sys

import h5py
import numpy as np
import pytest
import yaml
from conftest import CONFIGS, tiny
from typer.testing import CliRunner

from suspopt.cli import app
from suspopt.formats import FORMATS, LayoutError, format_of

runner = CliRunner()


def _cli(*args) -> None:
    res = runner.invoke(app, [str(a) for a in args])
    assert res.exit_code == 0, (args, res.output)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """One file of every kind, each written by its command: name -> path."""
    sys.path.insert(0, str(CONFIGS.parent / "tests"))
    from test_control import SENSITIVITY

    from suspopt.templates import template_text

    d = tmp_path_factory.mktemp("formats")
    (d / "ps.yaml").write_text(tiny((CONFIGS / "ch8/pareto_ps_class_a.yaml").read_text(), 2.0))
    robust = template_text("robust").replace("population: 30 ", "population: 8 ")
    (d / "robust.yaml").write_text(robust.replace("generations: 15 ", "generations: 2 "))
    (d / "cdf.yaml").write_text(yaml.safe_dump(SENSITIVITY, sort_keys=False))
    quick = (CONFIGS / "quickstart.yaml").read_text().replace("duration: 3.0", "duration: 1.0")
    (d / "q.yaml").write_text(quick)
    out = {k: d / f"{k}.h5" for k in (
        "sim", "front", "robust", "ke", "picksim", "roads", "masses", "tol", "builds",
        "picked", "stht", "sthtcfg", "models", "cdf", "scen",
    )}  # fmt: skip
    sweep = "vehicle.corners.F1.spring.linear=4e4:6e4:2"
    _cli("simulate", d / "q.yaml", "-o", out["sim"], "--sweep", sweep)
    _cli("optimise", d / "ps.yaml", "-o", out["front"])
    _cli("optimise", d / "robust.yaml", "-o", out["robust"])
    _cli("kesort", out["front"], out["front"], "-o", out["ke"])
    _cli("simulate", out["front"], "--pick", "knee", "-o", out["picksim"])
    _cli("analyse", "roads", out["front"], "--road", "B", "-o", out["roads"])
    _cli("analyse", "masses", out["front"], "-o", out["masses"])
    _cli("analyse", "tolerances", out["front"], "-o", out["tol"])
    _cli("analyse", "builds", out["front"], "--samples", 4, "-o", out["builds"])
    _cli("analyse", "builds", out["ke"], "--pick", "knee", "--samples", 3, "-o", out["picked"])
    _cli("analyse", "transmissibility", out["front"], "-o", out["stht"])
    _cli("analyse", "transmissibility", d / "ps.yaml", "-o", out["sthtcfg"])
    bump = [CONFIGS / "ch3/part1a_qc_bump.yaml", CONFIGS / "ch3/part1a_hc1_bump.yaml"]
    _cli("analyse", "models", *bump, "-o", out["models"])
    _cli("analyse", "cdf-sensitivity", d / "cdf.yaml", "-o", out["cdf"])
    _cli("analyse", "scenarios", out["robust"], "-o", out["scen"])
    return out


def _datasets(h5) -> list[str]:
    held: list[str] = []
    h5.visititems(lambda n, o: held.append(n) if isinstance(o, h5py.Dataset) else None)
    return held


def test_every_file_holds_what_its_format_declares(files):
    """Each file is of the format its command declares, holds nothing that format does not
    declare (groups, datasets, dimensions, fixed units, root attributes), and holds every
    dataset the format writes unconditionally; every format is met."""
    seen = set()
    for name, path in files.items():
        with h5py.File(path) as h5:
            fmt = format_of(h5)
            assert fmt is not None, name
            seen.add(fmt.kind)
            assert fmt.problems(h5) == [], (name, fmt.problems(h5))
            held = _datasets(h5)
            for entry in fmt.datasets:
                if not entry.when and "<" not in entry.path:
                    assert entry.path in held, (name, entry.path)
    assert seen == set(FORMATS)


def test_the_check_finds_what_the_format_does_not_declare(files, tmp_path):
    """``problems`` is not blind: an undeclared dataset, a wrong unit and wrong dimensions."""
    path = tmp_path / "sim.h5"
    shutil.copy(files["sim"], path)
    with h5py.File(path, "a") as h5:
        h5["modal/frequency"].attrs["units"] = "kHz"
        h5.create_dataset("metrics/extra/x", data=[1.0])
        h5.attrs["mine"] = 1
        found = format_of(h5).problems(h5)
    assert "/modal/frequency: units 'kHz', declared 'Hz'" in found
    assert "/metrics/extra/x: undeclared dataset" in found
    assert "/: root attributes ['mine'] undeclared" in found


def test_a_writer_cannot_write_what_its_format_does_not_declare():
    fmt = FORMATS["simulate"]
    with pytest.raises(LayoutError, match="declares no dataset 'signals/x/y'"):
        fmt.table("signals/x", "y", np.zeros(2))
    with pytest.raises(LayoutError, match="is in Hz, not kHz"):
        fmt.table("modal", "frequency", np.zeros((1, 2)), "kHz")
    with pytest.raises(LayoutError, match="takes its units from the run"):
        fmt.table("signals", "body.heave", np.zeros((1, 2)))
    table = fmt.table("modal", "frequency", np.zeros((1, 2)))
    assert table.dims == ("design", "mode") and table.units == "Hz"


def _instances(path, fmt) -> list[str]:
    """One dataset of the file for each declared dataset it holds (the first ``<name>``)."""
    with h5py.File(path) as h5:
        held = _datasets(h5)
    first: dict[str, str] = {}
    for name in held:
        first.setdefault(fmt.data(name).path, name)
    return sorted(first.values())


def _damaged(source, tmp_path, dataset: str, how: str):
    path = tmp_path / f"{how}-{dataset.replace('/', '_')}.h5"
    shutil.copy(source, path)
    with h5py.File(path, "a") as h5:
        del h5[dataset]
        if how == "text":
            h5[dataset] = "damaged"
    return path


@pytest.mark.slow
@pytest.mark.parametrize("name", ["sim", "front", "ke", "builds", "stht", "models", "cdf", "scen"])
def test_every_reader_of_a_damaged_file_exits_2_with_one_line(files, tmp_path, name):
    """For each declared dataset of the file: a copy without it, and one with a text in its
    place, fed to every reader of its kind (the format's ``read_by``)."""
    with h5py.File(files[name]) as h5:
        fmt = format_of(h5)
    refused = 0
    for dataset in _instances(files[name], fmt):
        for how in ("missing", "text"):
            path = _damaged(files[name], tmp_path, dataset, how)
            for command in fmt.read_by:
                args = [str(path) if a == "FILE" else a for a in command.split()]
                args = [str(tmp_path / f"out{a[3:]}") if a.startswith("OUT") else a for a in args]
                res = runner.invoke(app, args)
                what = (name, dataset, how, command, res.output)
                assert res.exit_code in (0, 2), what
                assert "Traceback" not in res.output, what
                if res.exit_code == 2:
                    refused += 1
                    errors = [ln for ln in res.output.splitlines() if ln.startswith("error:")]
                    assert len(errors) == 1 and str(path) in errors[0], what
                for out in tmp_path.glob("out*"):
                    shutil.rmtree(out) if out.is_dir() else out.unlink()
    assert refused  # (a reader that reads nothing would pass the rest)


@pytest.mark.slow
def test_every_analysis_computes_without_writing_then_writes_its_format(files, tmp_path):
    """``run`` of each kind returns an :class:`suspopt.analyse.Analysis` and leaves every
    folder as it was; ``write`` then makes a file its format declares whole."""
    from suspopt.analyse import Analysis, analysis_kinds

    kinds = analysis_kinds()
    d = files["front"].parent
    sources = {
        "models": [CONFIGS / "ch3/part1a_qc_bump.yaml", CONFIGS / "ch3/part1a_hc1_bump.yaml"],
        "roads": files["front"],
        "masses": files["front"],
        "controllers": files["front"],
        "tolerances": files["front"],
        "builds": files["front"],
        "transmissibility": files["front"],
        "cdf-sensitivity": d / "cdf.yaml",
        "scenarios": files["robust"],
    }
    options = {
        "roads": {"road": ["B"]},
        "controllers": {"with_": [d / "same.yaml"]},
        "builds": {"samples": 3},
    }
    assert set(sources) == set(kinds)
    (d / "same.yaml").write_text("control: {sample_time: 0.004}\n")  # (the stored control)
    before = sorted(p.name for p in d.iterdir())
    for kind, source in sources.items():
        done = kinds[kind].run(source, **options.get(kind, {}))
        assert isinstance(done, Analysis) and done.kind == kind
        assert sorted(p.name for p in d.iterdir()) == before, kind
        assert done.report().rows
        path = done.write(tmp_path / f"{kind}.h5")
        with h5py.File(path) as h5:
            assert format_of(h5).problems(h5) == [], kind
