"""The documentation site's generated references (docs/_ext/suspopt_docs.py): the
configuration reference lists every key of ``suspopt schema``, and the commands reference
every command and option of the command line. The site itself is built by ``.ci/run``
(``sphinx-build -W -n``), which fails on any warning."""

from __future__ import annotations

import json
import sys
from importlib import resources
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "docs" / "_ext"))

import suspopt_docs  # noqa: E402


def _schema() -> dict:
    return json.loads(resources.files("suspopt").joinpath("schema.json").read_text())


def _keys(node: dict, definitions: dict, seen: set[str]) -> set[tuple[str, str]]:
    """(definition, key) of every key reachable from ``node``, through every ``$ref``,
    alternative, list item, mapping value and conditional (``if``/``then``/``else``)."""
    found: set[tuple[str, str]] = set()

    def visit(n, owner: str) -> None:
        if isinstance(n, list):
            for item in n:
                visit(item, owner)
            return
        if not isinstance(n, dict):
            return
        ref = n.get("$ref")
        if ref:
            name = ref.rsplit("/", 1)[-1]
            if name not in seen:
                seen.add(name)
                visit(definitions[name], name)
        for key, child in n.get("properties", {}).items():
            found.add((owner, key))
            visit(child, owner)
        for word in ("anyOf", "oneOf", "allOf", "items", "additionalProperties"):
            visit(n.get(word), owner)
        for word in ("if", "then", "else"):
            visit(n.get(word), owner)

    visit(node, "")
    return found


def test_the_config_reference_lists_every_key_of_the_schema():
    schema = _schema()
    listed = {(row.definition, row.key) for row in suspopt_docs.rows(schema)}
    keys = _keys(schema, schema["$defs"], set())
    # a complete corner (no corner_defaults) has a partial corner's keys: listed once
    partial = {(d + "Partial", k) for d, k in keys}
    missing = {(d, k) for d, k in keys if (d, k) not in listed and (d + "Partial", k) not in listed}
    missing -= {(d, k) for d, k in keys if (d, k) in partial}
    conditional = {(d, k) for d, k in keys if d == ""}  # (root-level conditions' keys)
    missing -= {(d, k) for d, k in conditional if ("", k) in listed}
    assert not missing, sorted(missing)
    assert len(listed) > 200


def test_the_config_reference_gives_units_and_thesis_citations_where_the_schema_does():
    rows = {row.path: row for row in suspopt_docs.rows(_schema())}
    assert rows["simulation.dt"].unit == "s" and rows["simulation.dt"].default == "``0.001``"
    assert rows["vehicle.gravity"].unit == "m/s^2"
    assert rows["vehicle.body"].default == "required"
    assert rows["seat"].thesis == "Sec 2.2-2.3"
    text = suspopt_docs.reference_rst(_schema())
    assert "``road.road_class``" in text and "``seat.passenger.pelvis``" in text


def test_the_commands_reference_lists_every_command_and_option():
    import typer

    from suspopt.cli import app

    text = suspopt_docs.commands_rst()
    group = typer.main.get_command(app)
    for name, command in group.commands.items():
        assert f"suspopt {name}\n" in text
        for param in command.params:
            for option in param.opts:
                if option.startswith("-"):
                    assert f"``{option}``" in text, (name, option)
