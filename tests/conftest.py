"""Shared helpers: configs built from YAML text in a temporary folder."""

from __future__ import annotations

import functools
import re
import subprocess
import sys
from pathlib import Path

import h5py
import pytest
import yaml

import suspopt
from suspopt.config.loader import load_config_text


def build_commands_once() -> None:
    """Make ``typer.testing.CliRunner`` build suspopt's click command tree once per process,
    not on every ``invoke`` (about 30 ms each: the in-process CLI tests and the fuzz workers
    invoke it thousands of times). A command tree holds no state between invocations."""
    import typer.testing

    build = getattr(typer.testing, "_get_command", None)
    if build is not None and not hasattr(build, "cache_info"):
        typer.testing._get_command = functools.cache(build)


build_commands_once()

ROOT = Path(__file__).resolve().parents[1]
CONFIGS = ROOT / "configs"


def make_config(data: dict):
    """Validate a config given as a Python dict (as if read from YAML)."""
    return load_config_text(yaml.safe_dump(data, sort_keys=False))


def corner(m_u=40.0, k_t=1.5e5, c_t=0.0, k=1.0e4, k_nl=0.0, c=800.0) -> dict:
    return {
        "unsprung_mass": m_u,
        "tyre": {"stiffness": k_t, "damping": c_t},
        "spring": {"linear": k, "cubic": k_nl},
        "damper": {"c": c},
    }


@pytest.fixture
def load():
    """Load a bundled config by path relative to configs/."""
    return lambda rel: suspopt.load_config(CONFIGS / rel)


def tiny(text: str, duration: float, population: int = 10, generations: int = 2) -> str:
    """A config's text with a tiny optimiser budget and a short run."""
    text = re.sub(r"(?m)^(  population:) \d+", rf"\1 {population}", text)
    text = re.sub(r"(?m)^(  generations:) \d+", rf"\1 {generations}", text)
    return re.sub(
        r"(?m)^simulation: \{duration: [0-9.]+", f"simulation: {{duration: {duration}", text
    )


def optimised_front(folder: Path, name: str, duration: float, **budget) -> tuple[Path, Path]:
    """Optimise a tiny version of the bundled config ``name`` (e.g. ``ch8/pareto_ps_class_a``)
    in ``folder``; return (config path, Pareto file). The front has two designs or more."""
    from suspopt.optimisation import optimise

    path = folder / f"{name.replace('/', '_')}.yaml"
    path.write_text(tiny((CONFIGS / f"{name}.yaml").read_text(), duration, **budget))
    out = folder / f"{path.stem}.h5"
    optimise(suspopt.load_config(path), out)
    with h5py.File(out) as h5:
        assert len(h5["pareto/X"]) >= 2
    return path, out


# --- shared by several test modules ----------------------------------------------------


def run(*args, cwd=None):
    """``python -m suspopt ARGS`` in a subprocess (for what needs a process of its own)."""
    return subprocess.run(
        [sys.executable, "-m", "suspopt", *map(str, args)],
        capture_output=True,
        text=True,
        cwd=cwd,
        timeout=120,
    )


def write(tmp_path: Path, text: str, name="case.yaml") -> Path:
    """``text`` written to ``tmp_path/name``; its path."""
    path = tmp_path / name
    path.write_text(text)
    return path


#: A half car with two design variables and a tiny optimiser budget.
TINY = """\
vehicle:
  preset: half_pitch
  body: {mass: 2210, pitch_inertia: 1142, a_front: 1.61, a_rear: 1.67}
  corners:
    F1:
      unsprung_mass: 50
      tyre: {stiffness: 4.0e5}
      spring: {linear: 5.0e4, cubic: 1.0e7}
      damper: {c: 3000}
    R1:
      unsprung_mass: 100
      tyre: {stiffness: 8.0e5}
      spring: {linear: 6.0e4, cubic: 1.0e7}
      damper: {c: 3500}
road: {kind: bump_half_sine, height: 0.05, length: 1.0, speed: 11.111, start: 0.1}
simulation: {duration: 0.5, dt: 1.0e-3}
design_variables:
  - {name: k_F1, path: vehicle.corners.F1.spring.linear, lower: 3.2e4, upper: 1.5e5}
  - {name: c_F1, path: vehicle.corners.F1.damper.c, lower: 2.0e3, upper: 1.0e4}
  - {name: knl_F1, path: vehicle.corners.F1.spring.cubic, lower: 5.0e5, upper: 3.0e7, scale: log}
objectives:
  main:
    - {name: f1, metric: var, signal: body.heave_acc}
    - {name: f3, metric: var, signal: tyre_deflection, reduce: mean}
  supplementary:
    - {name: f2, metric: var, signal: travel, reduce: mean}
constraints:
  - {name: RC, metric: rms_weighted, signal: body.heave_acc, weighting: Wk, max: 1.4}
  - {name: ratio, metric: spring_usage, min: 0.1, max: 0.3}
optimiser: {algorithm: nsga2, population: 8, generations: 4, seed: 1}
"""
