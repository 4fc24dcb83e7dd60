"""Shared helpers: configs built from YAML text in a temporary folder."""

from __future__ import annotations

from pathlib import Path

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
    return {"unsprung_mass": m_u, "tyre": {"stiffness": k_t, "damping": c_t},
            "spring": {"linear": k, "cubic": k_nl}, "damper": {"c": c}}


@pytest.fixture
def load():
    """Load a bundled config by path relative to configs/."""
    return lambda rel: suspopt.load_config(CONFIGS / rel)
