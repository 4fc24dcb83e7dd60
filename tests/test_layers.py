"""The house's shape (docs/architecture.md#layers): the layers hold, and a command builds its
model once."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from conftest import CONFIGS
from typer.testing import CliRunner

ROOT = Path(__file__).resolve().parents[1]


def test_no_import_cycle_and_no_import_against_the_layers():
    """``.ci/import-layers`` counts, from the code, the cycles and the imports that run up the
    layers of pyproject.toml's contract (those inside functions too): none of either."""
    done = subprocess.run(
        [sys.executable, str(ROOT / ".ci" / "import-layers")], capture_output=True, text=True
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "0 cycles, 0 imports against the layer order, 0 modules in no layer" in done.stdout


def test_the_layer_script_finds_a_cycle_and_an_import_up_the_layers(tmp_path, monkeypatch):
    """The counting itself: a module of the base layer that imports the command line is an
    import against the layers, and two modules that import each other a cycle."""
    import importlib.machinery
    import importlib.util

    loader = importlib.machinery.SourceFileLoader("import_layers", str(ROOT / ".ci/import-layers"))
    spec = importlib.util.spec_from_loader("import_layers", loader)
    script = importlib.util.module_from_spec(spec)
    loader.exec_module(script)
    package = tmp_path / "suspopt"
    (package / "cli").mkdir(parents=True)
    (package / "__init__.py").write_text("")
    (package / "cli" / "__init__.py").write_text("")
    (package / "errors.py").write_text("def f():\n    from .cli import base\n")
    (package / "cli" / "base.py").write_text("from . import console\n")
    (package / "cli" / "console.py").write_text("from .base import x\n")
    monkeypatch.setattr(script, "ROOT", tmp_path)
    known = script.modules()
    edges = script.graph(known)
    assert script.cycles(known, edges) == [["suspopt.cli.base", "suspopt.cli.console"]]
    order = [["suspopt.errors"], ["suspopt.cli"]]
    assert script.layer_of("suspopt.errors", order) < script.layer_of("suspopt.cli.base", order)
    assert "suspopt.cli.base" in edges["suspopt.errors"]  # (imported inside a function)


def test_simulate_builds_its_model_once(tmp_path, monkeypatch):
    """``suspopt simulate CONFIG`` checks the config's design and simulates it on the one
    model it built (before, the command built it, then ``simulate()`` again)."""
    import importlib

    from suspopt.cli import app

    simulation = importlib.import_module("suspopt.simulation")

    built = []
    build = simulation.build_vehicle

    def counted(cfg, pv):
        built.append(pv.P)
        return build(cfg, pv)

    monkeypatch.setattr(simulation, "build_vehicle", counted)
    out = tmp_path / "out.h5"
    done = CliRunner().invoke(app, ["simulate", str(CONFIGS / "quickstart.yaml"), "-o", str(out)])
    assert done.exit_code == 0, done.output
    assert built == [1] and out.exists()
