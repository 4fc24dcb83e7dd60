"""The starter configs of ``suspopt init`` (suspopt.templates): each is a commented config
that validates, runs (the optimisations at their own budget) and is physically sensible."""

from __future__ import annotations

import re
from importlib import resources

import numpy as np
import pytest

import suspopt
from suspopt.config.loader import load_config_text
from suspopt.optimisation import optimise
from suspopt.templates import template_description, template_names, template_text
from suspopt.validation import check_config

NAMES = template_names()


def test_every_template_file_is_registered_and_described():
    files = {
        p.name[:-5]
        for p in resources.files("suspopt.templates").iterdir()
        if p.name.endswith(".yaml")
    }
    assert set(NAMES) == files
    assert {
        "quarter",
        "half_roll",
        "half_pitch",
        "full",
        "seat",
        "semi_active",
        "optimise",
        "kesort",
    } <= set(NAMES)
    for name in NAMES:
        description = template_description(name)
        assert description and "\n" not in description and len(description) <= 90, name


def test_an_unknown_template_is_refused_with_the_closest_names():
    with pytest.raises(ValueError, match="unknown template 'quater'; did you mean quarter"):
        template_text("quater")
    with pytest.raises(ValueError, match="unknown template"):
        template_description("hovercraft")


@pytest.mark.parametrize("name", NAMES)
def test_template_says_what_every_value_is_and_where_it_comes_from(name):
    text = template_text(name)
    lines = text.splitlines()
    header = "\n".join(
        line
        for line in lines[: next(i for i, line in enumerate(lines) if not line.startswith("#"))]
    )
    assert re.search(r"\b(Table|Eq) \d", header) and "SI units" in header, name
    depth, previous = 0, ""
    for number, line in enumerate(lines, start=1):
        code = line.split("#", 1)[0]
        continued = depth > 0  # inside a flow mapping begun above
        depth += code.count("{") + code.count("[") - code.count("}") - code.count("]")
        holds_value = re.match(r"\s*(- )?\{|\s*[\w.]+:\s*\S", code) is not None
        if holds_value and not continued:
            assert "#" in line or previous.lstrip().startswith("#"), f"{name}.yaml:{number}"
        previous = line
    assert max(len(line) for line in lines) <= 99, name


@pytest.mark.slow
@pytest.mark.parametrize("name", NAMES)
def test_template_validates_runs_and_is_physically_sensible(name, tmp_path):
    cfg = load_config_text(template_text(name))
    check_config(cfg)  # what suspopt validate checks
    assert cfg.warnings == ()  # (no value that looks like a slip of units)
    if name in ("quarter", "half_roll", "half_pitch", "full"):
        assert cfg.vehicle.preset == name
    assert cfg.simulation.duration <= 20.0  # cheap in CI; comments say how long
    result = suspopt.simulate(cfg)
    assert not result.diverged.any()
    assert result.metrics or cfg.objectives is not None, name
    assert all(np.isfinite(v).all() for v in result.metrics.values())
    modes = suspopt.modal_analysis(suspopt.build_vehicle(cfg))
    for label, frequency in zip(modes.label[0], modes.frequency[0]):
        band = (0.5, 3.0) if label.startswith("body.") else (8.0, 20.0)  # ride, wheel hop
        assert band[0] <= frequency <= band[1], (name, label, frequency)
    if cfg.optimiser is None:
        return
    run = optimise(cfg, tmp_path / "out.h5")
    opt = cfg.optimiser
    assert run.status == "finished"
    assert run.history["evaluations"][-1] <= opt.population * opt.generations
    feasible = (run.G <= 0).all(axis=1)
    assert feasible.any(), name
    assert np.isfinite(run.F[feasible]).all()
