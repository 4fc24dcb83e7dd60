"""Sphinx extension of suspopt's docs: the configuration reference, generated from the
config's JSON Schema (``suspopt.config_schema()``, what ``suspopt schema`` prints) when the
docs are built, so that it cannot drift from the code.

``.. suspopt-config-reference::`` writes one section per top-level key of a config, each a
table of every key below it: its dotted path, type and allowed range, default, SI unit,
meaning and the thesis equation, table or section it cites. A section used at several
places (a corner's keys under ``corner_defaults`` and under each corner) is listed once and
referred to elsewhere; each variant of a key with kinds (``road.kind``, ``seat.kind``, a
damper's ``kind``, an optimiser's algorithm options) has its own table.

:func:`rows` is what the directive renders; ``tests/test_docs_site.py`` checks with it that
every key of the schema is listed.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any

#: A unit in a description: ``[N s/m]`` (not a list such as ``[kg, m]`` of names).
UNIT = re.compile(r"\[([^\]]{1,24})\]")
#: A thesis citation in a description: ``Eq 2.31``, ``Eqs 6.10-6.12``, ``Table 5.2``, ...
CITATION = re.compile(r"\b(?:Eqs?|Tables?|Sec|Figs?\.?)\s?\d+(?:\.\d+)*(?:-\d+(?:\.\d+)*)?")


@dataclass
class Row:
    """One key of the reference."""

    path: str  # dotted, with <name> for a key of the user's choosing
    definition: str  # the schema definition (section) it belongs to, or "" at the root
    key: str
    kind: str  # type and range
    default: str
    unit: str
    meaning: str
    thesis: str


@dataclass
class Table:
    """The keys of one section at one place (or of one variant of it)."""

    title: str
    path: str
    definition: str
    rows: list[Row]
    label: str = ""  # the id of its section in the page (:func:`reference_rst`)


def github_slug(heading: str) -> str:
    """GitHub's anchor of a heading: punctuation dropped (letters, digits, ``_``, ``-`` and
    spaces kept), lower case, each space a hyphen; MyST's anchors of the site's headings, so
    that a page's links work on GitHub and in the site alike."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def _ref(node: dict) -> str | None:
    ref = node.get("$ref")
    return ref.rsplit("/", 1)[-1] if ref else None


def _branches(node: dict) -> list[dict]:
    """The alternatives of a node (``anyOf``/``oneOf``), the node itself when it has none."""
    for key in ("anyOf", "oneOf"):
        if key in node:
            return [b for sub in node[key] for b in _branches(sub)]
    return [node]


def _range(node: dict) -> str:
    parts = []
    for key, sign in (("minimum", ">="), ("exclusiveMinimum", ">")):
        if key in node:
            parts.append(f"{sign} {node[key]:g}")
    for key, sign in (("maximum", "<="), ("exclusiveMaximum", "<")):
        if key in node:
            parts.append(f"{sign} {node[key]:g}")
    for key, what in (("minItems", "at least"), ("maxItems", "at most")):
        if key in node:
            parts.append(f"{what} {node[key]} items")
    if "maxLength" in node:
        parts.append(f"at most {node['maxLength']} characters")
    return ", ".join(parts)


def _type(node: dict) -> str:
    """A node's type in words, its range included."""
    words = []
    for branch in _branches(node):
        name = _ref(branch)
        if name is not None:
            words.append(f"section {name}")
        elif "enum" in branch:
            words.append(" | ".join(f"``{v}``" for v in branch["enum"]))
        elif "const" in branch:
            words.append(f"``{branch['const']}``")
        elif branch.get("type") == "array":
            items = branch.get("items", {})
            words.append(f"list of {_type(items)}" if items else "list")
        elif branch.get("type") == "object":
            extra = branch.get("additionalProperties")
            if isinstance(extra, dict):
                words.append(f"mapping of name to {_type(extra)}")
            else:
                words.append("mapping")
        elif branch.get("type") == "null":
            words.append("null")
        elif "type" in branch:
            words.append(str(branch["type"]))
        else:
            words.append("any")
        span = _range(branch)
        if span:
            words[-1] += f" ({span})"
    seen: list[str] = []
    for w in words:
        if w not in seen:
            seen.append(w)
    return " or ".join(seen)


def _default(node: dict) -> str:
    if "default" not in node:
        return "required" if node.get("_required") else ""
    value = node["default"]
    if value is None:
        return "absent"
    if isinstance(value, bool):
        return f"``{str(value).lower()}``"
    if isinstance(value, (list, dict)) and not value:
        return "empty"
    return f"``{value}``"


def _meaning(node: dict, definitions: dict) -> str:
    text = node.get("description", "")
    if not text:
        for branch in _branches(node):
            name = _ref(branch)
            if name is not None and definitions[name].get("description"):
                text = definitions[name]["description"]
                break
    return " ".join(text.split())


def _unit(text: str) -> str:
    found = [u for u in UNIT.findall(text) if not any(c in u for c in ",|")]
    return found[-1] if found else ""


def _variants(node: dict, definitions: dict) -> list[tuple[str, str]]:
    """``(label, definition)`` of each section a node may be (its kinds, where it has
    several): ``("kind: iso8608", "Iso8608Road")``."""
    found = []
    for branch in _branches(node):
        name = _ref(branch)
        if name is None:
            continue
        kind = definitions[name].get("properties", {}).get("kind", {})
        values = kind.get("enum") or ([kind["const"]] if "const" in kind else [])
        label = f"kind: {', '.join(map(str, values))}" if values else name
        found.append((label, name))
    return found


def tables(schema: dict) -> list[Table]:
    """Every table of the reference, in the order of the config's keys (module docstring)."""
    definitions = schema.get("$defs", {})
    out: list[Table] = []
    placed: dict[str, str] = {}  # definition -> the path whose table lists it

    def walk(title: str, path: str, definition: str, node: dict) -> None:
        required = set(node.get("required", []))
        rows: list[Row] = []
        later: list[tuple[str, str, str, dict]] = []
        for key, child in node.get("properties", {}).items():
            child = {**child, "_required": key in required}
            sub = f"{path}.{key}" if path else key
            meaning = _meaning(child, definitions)
            kind = _type(child)
            variants = _variants(child, definitions)
            inline = [
                b for b in _branches(child) if b.get("type") == "object" and "properties" in b
            ]
            items = child.get("items", {}) if child.get("type") == "array" else {}
            extra = child.get("additionalProperties")
            if items and _variants(items, definitions):
                variants, sub_path = _variants(items, definitions), f"{sub}[i]"
            elif isinstance(extra, dict) and _variants(extra, definitions):
                variants, sub_path = _variants(extra, definitions), f"{sub}.<name>"
            else:
                sub_path = sub
            refers = []
            for label, name in variants:
                if name in placed:
                    refers.append(f"``{placed[name]}``")
                else:
                    placed[name] = sub_path
                    heading = f"{sub_path} ({label})" if len(variants) > 1 else sub_path
                    later.append((heading, sub_path, name, definitions[name]))
            for branch in inline:
                later.append((sub, sub, definition, branch))
            if refers:
                meaning += f" (its keys: as under {', '.join(refers)})"
            rows.append(
                Row(
                    path=sub,
                    definition=definition,
                    key=key,
                    kind=kind,
                    default=_default(child),
                    unit=_unit(meaning),
                    meaning=meaning,
                    thesis=", ".join(dict.fromkeys(CITATION.findall(meaning))),
                )
            )
        if rows:
            out.append(Table(title, path, definition, rows))
        for heading, sub, name, child in later:
            walk(heading, sub, name, child)

    walk("Top level", "", "", schema)
    return out


def rows(schema: dict) -> list[Row]:
    """Every row of every table of :func:`tables`."""
    return [row for table in tables(schema) for row in table.rows]


def _escaped(text: str) -> str:
    """A description as reStructuredText: its ``literals`` kept, the characters that would
    start other markup (emphasis, substitutions, a reference's trailing ``_``) escaped."""
    text = re.sub(r":\w+:`[!~]?([^`]+)`", r"``\1``", text)  # (roles of the code's names)
    text = re.sub(r"([*|])", r"\\\1", text)
    return re.sub(r"(\w)_(?=\W|$)", r"\1\\_", text) or " "


def _label(title: str) -> str:
    """The id docutils gives the section of a table titled ``title``."""
    from docutils.nodes import make_id

    return make_id(title)


def _linked(kind: str, where: dict[str, str]) -> str:
    """``section Name`` in a type as a link to Name's table."""

    def link(match: re.Match) -> str:
        name = match.group(1)
        return f"`{name} <#{where[name]}>`__" if name in where else name

    return re.sub(r"section (\w+)", link, kind)


def reference_rst(schema: dict) -> str:
    """The reference as reStructuredText: a section and a list-table per :class:`Table`."""
    lines: list[str] = []
    found = tables(schema)
    where: dict[str, str] = {}
    labels: set[str] = set()
    for table in found:
        label = _label(table.title if table.path else "Top-level keys")
        table.label = label
        labels.add(label)
        if table.definition and table.definition not in where:
            where[table.definition] = label
    for table in found:
        title = table.title if table.path else "Top-level keys"
        lines += [_escaped(title), "~" * (2 * len(title) + 4), ""]
        if table.definition:
            description = schema["$defs"][table.definition].get("description", "")
            if description:
                lines += [_escaped(" ".join(description.split())), ""]
        lines += [
            ".. list-table::",
            "   :header-rows: 1",
            "   :widths: 22 20 9 8 31 10",
            "",
            "   * - key",
            "     - type (range)",
            "     - default",
            "     - unit",
            "     - meaning",
            "     - thesis",
        ]
        for row in table.rows:
            lines += [
                f"   * - ``{row.path}``",
                f"     - {_linked(row.kind, where) or ' '}",
                f"     - {row.default or ' '}",
                f"     - {_escaped(row.unit)}",
                f"     - {_escaped(row.meaning)}",
                f"     - {_escaped(row.thesis)}",
            ]
        lines.append("")
    return "\n".join(lines)


def commands_rst() -> str:
    """Every command of ``suspopt`` (the typer app's click commands): its usage, its help
    text and a table of its arguments and options, as ``suspopt COMMAND --help`` has them."""
    import typer

    from suspopt.cli import app

    group = typer.main.get_command(app)
    lines: list[str] = []

    def section(command: Any, name: str, parent: Any) -> None:
        ctx = command.context_class(command, info_name=name, parent=parent)
        title = ctx.command_path if parent is not None else "suspopt and its global options"
        lines.extend([title, "~" * (len(title) + 2), ""])
        usage = " ".join(command.collect_usage_pieces(ctx))
        lines.extend(["::", "", f"    {ctx.command_path} {usage}", ""])
        for paragraph in (command.help or "").split("\n\n"):
            text = " ".join(paragraph.split())
            if text:
                lines.extend([_escaped(text), ""])
        params = [p for p in command.params if not getattr(p, "hidden", False)]
        if params:
            lines.extend(
                [
                    ".. list-table::",
                    "   :header-rows: 1",
                    "   :widths: 28 14 58",
                    "",
                    "   * - argument or option",
                    "     - default",
                    "     - meaning",
                ]
            )
            for param in params:
                names = ", ".join(f"``{o}``" for o in [*param.opts, *param.secondary_opts])
                if param.param_type_name == "argument":
                    names = f"``{param.name.upper()}``"
                default = param.default
                shown = (
                    " "
                    if default in (None, (), [], False) or callable(default)
                    else f"``{default}``"
                )
                meaning = " ".join((getattr(param, "help", None) or "").split())
                lines.extend([f"   * - {names}", f"     - {shown}", f"     - {_escaped(meaning)}"])
            lines.append("")
        if hasattr(command, "commands"):
            for sub_name, sub in command.commands.items():
                section(sub, sub_name, ctx)

    section(group, "suspopt", None)
    return "\n".join(lines)


def formats_rst() -> str:
    """Every file format of :data:`suspopt.formats.FORMATS` as reStructuredText: per kind, what
    writes it, its root attributes and a table of its groups and datasets."""
    from suspopt.formats import FORMATS, ROOT_ATTRIBUTES, Data

    lines = ["Root attributes of every file", "~" * 31, ""]
    lines += [".. list-table::", "   :header-rows: 1", "   :widths: 20 80", ""]
    lines += ["   * - attribute", "     - what it holds"]
    for key, doc in ROOT_ATTRIBUTES.items():
        lines += [f"   * - ``{key}``", f"     - {_escaped(doc)}"]
    lines.append("")
    for fmt in FORMATS.values():
        title = f"{fmt.kind} files"
        lines += [_escaped(title), "~" * (2 * len(title) + 4), ""]
        lines += [f"Written by ``{fmt.written_by}``. {_escaped(fmt.doc)}", ""]
        if fmt.attrs:
            attrs = "; ".join(f"``{k}``: {v}" for k, v in fmt.attrs.items())
            lines += [f"Root attributes besides those of every file: {attrs}.", ""]
        if fmt.read_by:
            reads = ", ".join(f"``suspopt {c.split(' FILE')[0]}``" for c in fmt.read_by)
            lines += [f"Read by {reads}.", ""]
        lines += [
            ".. list-table::",
            "   :header-rows: 1",
            "   :widths: 30 22 10 38",
            "",
            "   * - path",
            "     - dimensions",
            "     - unit",
            "     - what it holds",
        ]
        for node in fmt.nodes:
            is_data = isinstance(node, Data)
            doc = node.doc + (f" (when: {node.when})" if node.when else "")
            if node.attrs:
                doc += "; attributes " + "; ".join(f"``{k}``: {v}" for k, v in node.attrs.items())
            unit = (node.units if node.units is not None else "from the run") if is_data else " "
            dims = f"({', '.join(node.axes)})" if is_data else "group"
            lines += [
                f"   * - ``/{node.path}``",
                f"     - {dims}",
                f"     - {_escaped(unit)}",
                f"     - {_escaped(doc)}",
            ]
        lines.append("")
    return "\n".join(lines)


def _config_reference_rst() -> str:
    from suspopt.config import config_schema

    return reference_rst(config_schema())


def setup(app: Any) -> dict:
    from docutils import nodes
    from docutils.parsers.rst import Directive
    from docutils.statemachine import StringList
    from sphinx.util.nodes import nested_parse_with_titles

    def directive(make_text):
        """A directive without content that parses the reStructuredText ``make_text()``
        gives, its sections included."""

        class Generated(Directive):
            has_content = False

            def run(self):
                holder = nodes.section()
                holder.document = self.state.document
                lines = StringList(make_text().splitlines())
                nested_parse_with_titles(self.state, lines, holder)
                return holder.children

        return Generated

    app.add_directive("suspopt-formats", directive(formats_rst))
    app.add_directive("suspopt-config-reference", directive(_config_reference_rst))
    app.add_directive("suspopt-commands", directive(commands_rst))
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
