"""A config changed in Python records what runs: ``Config.text`` is the YAML as written
while the values are those it was loaded with, and the values as they are once one was
changed (an optimisation of an edited template recorded the unedited template, and every
command reading that file back then worked on a config that had not run)."""

from __future__ import annotations

import pytest

import suspopt
from suspopt.config.loader import load_config_text
from suspopt.templates import template_names


@pytest.mark.parametrize("kind", template_names())
def test_an_edited_config_records_its_values_and_reads_back_the_same(kind):
    cfg = suspopt.load_template(kind)
    written = cfg.text
    assert "#" in written.splitlines()[0]  # (the template's comments kept while unedited)
    cfg.simulation.duration = cfg.simulation.duration * 2
    edited = cfg.text
    assert edited != written and edited.startswith(f"# {kind}.yaml as edited in Python")
    again = load_config_text(edited)
    assert again.model_dump(mode="json") == cfg.model_dump(mode="json")
    assert again.text == edited  # (read back: its own text, unedited)


def test_an_optimisation_of_an_edited_config_stores_the_edited_config(tmp_path):
    from suspopt.choosing.picks import read_front
    from suspopt.optimisation import optimise

    cfg = suspopt.load_template("kesort")
    cfg.optimiser.population, cfg.optimiser.generations = 8, 2
    cfg.design_variables[0].tolerance = 2.5
    optimise(cfg, tmp_path / "front.h5")
    stored = read_front(tmp_path / "front.h5").config()
    assert stored.optimiser.population == 8
    assert stored.design_variables[0].tolerance == 2.5
