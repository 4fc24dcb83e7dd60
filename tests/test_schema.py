"""The JSON schema of ``suspopt schema`` (suspopt.config.config_schema), checked with the
jsonschema package on configs read as YAML 1.2 (PyYAML's 1.1 reads 2.0e5 as a string)."""

from __future__ import annotations

from pathlib import Path

import jsonschema
import pytest

from suspopt.config import ConfigError, config_schema
from suspopt.config.loader import SCHEMA_ID, load_config_text
from suspopt.config.yamlio import parse_yaml
from suspopt.templates import template_names, template_text

CONFIGS = Path(__file__).resolve().parents[1] / "configs"
BUNDLED = sorted(CONFIGS.rglob("*.yaml"))
QUICKSTART = (CONFIGS / "quickstart.yaml").read_text()
CH7 = (CONFIGS / "ch7" / "sh_2.yaml").read_text()  # corners given by corner_defaults


@pytest.fixture(scope="module")
def validator():
    schema = config_schema()
    assert schema["$schema"] == "https://json-schema.org/draft/2020-12/schema"
    assert schema["$id"] == SCHEMA_ID
    cls = jsonschema.validators.validator_for(schema)
    assert cls is jsonschema.Draft202012Validator
    cls.check_schema(schema)  # a valid draft 2020-12 schema
    return cls(schema)


def _errors(validator, text: str) -> list[str]:
    return [
        f"{'.'.join(map(str, e.absolute_path))}: {e.message}"
        for e in validator.iter_errors(parse_yaml(text)[0])
    ]


def test_the_bundled_configs_are_all_there():
    assert len(BUNDLED) > 100 and len(list((CONFIGS / "ch7").glob("*.yaml"))) == 5


@pytest.mark.parametrize("path", BUNDLED, ids=lambda p: str(p.relative_to(CONFIGS)))
def test_every_bundled_config_matches_the_schema(validator, path):
    assert _errors(validator, path.read_text()) == []


@pytest.mark.parametrize("name", template_names())
def test_every_template_matches_the_schema(validator, name):
    assert _errors(validator, template_text(name)) == []


WRONG = {
    "unknown key": QUICKSTART + "outptu: {float32: true}\n",
    "a string for a number": QUICKSTART.replace("damper: {c: 3000}", 'damper: {c: "3000"}'),
    "a negative mass": QUICKSTART.replace("mass: 2210", "mass: -2210"),
    "a corner without its mass and no corner_defaults": QUICKSTART.replace(
        "      unsprung_mass: 100\n", ""
    ),
    "an unknown corner": QUICKSTART.replace("    R1:\n", "    RR:\n"),
    "a misspelt key in corner_defaults": CH7.replace(
        "tyre: {stiffness: 2.0e5}", "tyre: {stifness: 2.0e5}"
    ),
    "a misspelt key in a corner over corner_defaults": CH7.replace(
        "corners: {F1: {}, R1: {}}", "corners: {F1: {unsprung_mas: 30}, R1: {}}"
    ),
}
# (the schema cannot see the kind a part of a damper takes from corner_defaults, so it lets
# a passive key over a semi-active default pass, which the loader refuses)
RIGHT = {
    "corners left empty": CH7.replace("corners: {F1: {}, R1: {}}", "corners: {F1: , R1: }"),
    "no corners at all": CH7.replace("  corners: {F1: {}, R1: {}}\n", ""),
    # without kind a part of a damper is of the default's kind
    "a semi-active key without kind over corner_defaults": CH7.replace(
        "corners: {F1: {}, R1: {}}", "corners: {F1: {damper: {c_max: 4000}}, R1: {}}"
    ),
    "a corner overriding part of corner_defaults": CH7.replace(
        "corners: {F1: {}, R1: {}}",
        "corners: {F1: {damper: {kind: semi_active, "
        "c_max: 4000}, spring: {cubic: 1.0e6}}, R1: {unsprung_mass: 30}}",
    ),
}


@pytest.mark.parametrize("case", WRONG)
def test_the_schema_refuses_what_the_loader_refuses(validator, case):
    text = WRONG[case]
    assert text not in (QUICKSTART, CH7)  # the edit took
    assert _errors(validator, text)
    with pytest.raises(ConfigError):
        load_config_text(text)


@pytest.mark.parametrize("case", RIGHT)
def test_the_schema_accepts_what_the_loader_accepts(validator, case):
    text = RIGHT[case]
    assert text != CH7
    assert _errors(validator, text) == []
    load_config_text(text)


def test_the_stored_schema_is_the_models_schema():
    """``suspopt schema`` prints suspopt/schema.json (no model to build at start-up); it must
    be what the models give. After changing a config section:
    ``python -c "import json, suspopt; print(json.dumps(suspopt.config_schema(), indent=2))"
    > suspopt/schema.json``."""
    import json
    from importlib import resources

    from suspopt.config import config_schema

    stored = json.loads(resources.files("suspopt").joinpath("schema.json").read_text())
    assert stored == config_schema()
