"""Shared helpers: configs built from YAML text in a temporary folder."""

from __future__ import annotations

import re
from pathlib import Path

import h5py
import pytest
import yaml

import suspopt
from suspopt.config.loader import load_config_text

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
    from suspopt.optimise import optimise

    path = folder / f"{name.replace('/', '_')}.yaml"
    path.write_text(tiny((CONFIGS / f"{name}.yaml").read_text(), duration, **budget))
    out = folder / f"{path.stem}.h5"
    optimise(suspopt.load_config(path), out)
    with h5py.File(out) as h5:
        assert len(h5["pareto/X"]) >= 2
    return path, out
