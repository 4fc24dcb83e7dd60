"""Bounded, safe YAML: what suspopt reads from a config file or from a config stored in HDF5.

Nothing read from a file runs as code, and no input can make the reader hang or allocate
without bound:

- **Regular files only**, at most :data:`MAX_CONFIG_BYTES`: a directory, a FIFO, a device (a
  symlink to ``/dev/zero``) or a larger file is refused before more than the limit is read.
- **Text**: UTF-8 without NUL bytes.
- **Safe tags only** (PyYAML's safe constructor: no Python objects).
- **Structure**: at most :data:`MAX_DEPTH` levels of nesting (5,000 nested ``[`` would
  otherwise overflow the recursion), at most :data:`MAX_NODES` nodes once aliases are
  expanded (a 9-line "billion laughs" alias bomb expands to 10^9 nodes), no alias that
  refers to itself, and no key twice in one mapping (YAML says keys are unique; PyYAML keeps
  the last one silently).
- **Scalars as YAML 1.2 reads them** (the core schema): ``4.0e5`` and ``1e5`` are numbers,
  ``yes``/``no``/``on``/``off`` are text, not booleans, ``010`` is ten, and ``1:30`` is text.
  PyYAML implements YAML 1.1, where ``4.0e5`` is a string and ``no`` is false.

Errors are :class:`YamlError` with the line (1-based) where known.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import yaml
from yaml.composer import Composer
from yaml.constructor import SafeConstructor
from yaml.nodes import MappingNode, Node, ScalarNode, SequenceNode
from yaml.parser import Parser
from yaml.reader import Reader
from yaml.resolver import BaseResolver
from yaml.scanner import Scanner

from ..files import Unreadable, is_hdf5, read_bounded
from ..memory import describe

__all__ = ["YamlError", "MAX_CONFIG_BYTES", "MAX_DEPTH", "MAX_NODES", "read_text", "parse_yaml"]

#: Largest config file read [bytes]: a config is a few kB; the largest bundled one is 5 kB.
MAX_CONFIG_BYTES = 1 << 20
#: Deepest nesting of mappings and sequences (the deepest bundled config has 6 levels).
MAX_DEPTH = 64
#: Most nodes of a document with its aliases expanded.
MAX_NODES = 100_000


class YamlError(ValueError):
    """Unreadable or unsafe YAML; ``line`` is 1-based, or None."""

    def __init__(self, message: str, line: int | None = None):
        super().__init__(message)
        self.line = line


def read_text(path: str | Path, limit: int = MAX_CONFIG_BYTES, what: str = "config") -> str:
    """The UTF-8 text of the regular file ``path``, read without following it into a device
    or FIFO and without reading more than ``limit`` bytes (:func:`suspopt.files.read_bounded`);
    YamlError otherwise (the message says why; FileNotFoundError for a missing file)."""
    path = Path(path)
    if str(path) == "":
        raise YamlError(f"an empty file name is not a {what} file")
    if is_hdf5(path):  # (a result where a config belongs: "holds NUL bytes" said less)
        raise YamlError(f"is an HDF5 file, not a YAML {what}")
    try:
        data = read_bounded(path, limit)
    except Unreadable as exc:  # ("is a FIFO, not a config file"; "cannot read it (...)")
        reason = str(exc)
        message = f"{reason}, not a {what} file" if reason.startswith("is ") else reason
        raise YamlError(message) from None
    if b"\0" in data:
        raise YamlError(f"holds NUL bytes: a binary file, not a YAML {what}")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise YamlError(f"is not UTF-8 text (byte {exc.start})", line) from None


class _CoreResolver(BaseResolver):
    """Implicit tags of the YAML 1.2 core schema (null, bool, int, float)."""


_CORE = [
    ("tag:yaml.org,2002:null", r"^(?:~|null|Null|NULL|)$", list("~nN") + [""]),
    ("tag:yaml.org,2002:bool", r"^(?:true|True|TRUE|false|False|FALSE)$", list("tTfF")),
    ("tag:yaml.org,2002:int", r"^(?:[-+]?[0-9]+|0o[0-7]+|0x[0-9a-fA-F]+)$", list("-+0123456789")),
    (
        "tag:yaml.org,2002:float",
        r"^(?:[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?"
        r"|[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN))$",
        list("-+.0123456789"),
    ),
]
for _tag, _pattern, _first in _CORE:
    _CoreResolver.add_implicit_resolver(_tag, re.compile(_pattern), _first)
_CoreResolver.add_implicit_resolver("tag:yaml.org,2002:merge", re.compile(r"^(?:<<)$"), ["<"])


class _Constructor(SafeConstructor):
    """The safe constructor with YAML 1.2 integers (``010`` is ten) and floats."""

    def construct_yaml_int(self, node):
        text = self.construct_scalar(node)
        if text.startswith(("0o", "0x")):
            return int(text[2:], 8 if text[1] == "o" else 16)
        return int(text)

    def construct_yaml_float(self, node):
        text = self.construct_scalar(node).lower()
        if text.lstrip("+-") == ".inf":
            return float("-inf") if text.startswith("-") else float("inf")
        if text == ".nan":
            return float("nan")
        return float(text)

    def construct_object(self, node, deep=False):
        """The constructor's object of ``node``; YamlError with the node's line and an
        excerpt of its text for a value its constructor cannot read (a number Python cannot
        hold, like an integer of more than 4300 digits; an explicit tag such as
        ``!!timestamp`` on text that is not one)."""
        try:
            return super().construct_object(node, deep)
        except YamlError:
            raise
        except (ValueError, OverflowError, TypeError, AttributeError):
            value = node.value if isinstance(node, ScalarNode) else ""
            shown = f" {value[:20]!r}" + (f" ({len(value)} characters)" if len(value) > 20 else "")
            kind = node.tag.rsplit(":", 1)[-1]
            raise YamlError(
                f"malformed YAML: a value that cannot be read as {kind}{shown if value else ''}",
                node.start_mark.line + 1,
            ) from None


_Constructor.add_constructor("tag:yaml.org,2002:int", _Constructor.construct_yaml_int)
_Constructor.add_constructor("tag:yaml.org,2002:float", _Constructor.construct_yaml_float)


class _Bounded(Composer):
    """PyYAML's composer with at most :data:`MAX_DEPTH` levels and no key twice in a
    mapping."""

    _depth = 0

    def compose_node(self, parent, index):
        self._depth += 1
        try:
            if self._depth > MAX_DEPTH:
                mark = self.peek_event().start_mark
                raise YamlError(f"nested more than {MAX_DEPTH} levels deep", mark.line + 1)
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1

    def compose_mapping_node(self, anchor):
        node = super().compose_mapping_node(anchor)
        seen: dict[Any, int] = {}
        for key, _ in node.value:
            if not isinstance(key, ScalarNode) or key.tag == "tag:yaml.org,2002:merge":
                continue
            value = (key.tag, key.value)
            if value in seen:
                raise YamlError(
                    f"key {key.value[:60]!r} appears twice in one mapping (first "
                    f"on line {seen[value]})",
                    key.start_mark.line + 1,
                )
            seen[value] = key.start_mark.line + 1
        return node


class _Loader(Reader, Scanner, Parser, _Bounded, _Constructor, _CoreResolver):
    """PyYAML's safe loader with the core schema and bounded composition (all in Python)."""

    def __init__(self, stream):
        Reader.__init__(self, stream)
        Scanner.__init__(self)
        Parser.__init__(self)
        _Bounded.__init__(self)
        _Constructor.__init__(self)
        _CoreResolver.__init__(self)

    def fetch_flow_collection_start(self, TokenClass):
        # the scanner's cost grows with the square of the flow nesting: stop it early
        if self.flow_level >= MAX_DEPTH:
            raise YamlError(f"nested more than {MAX_DEPTH} levels deep", self.get_mark().line + 1)
        super().fetch_flow_collection_start(TokenClass)


def _c_loader():
    """The same loader with libyaml's scanner and parser (about 6x faster on a config: 2 ms
    instead of 13 ms for configs/ch6/part_b.yaml), when PyYAML was built with it; the
    composer, the bounds and the constructor are the Python ones above, so that the same
    events give the same data and errors. Deep flow nesting costs libyaml's scanner linear
    time (measured: 100,000 nested ``[`` refused in 3 ms); libyaml 0.2.6 also stops at 1000
    levels, which is reported as the composer's :data:`MAX_DEPTH` is."""
    if not getattr(yaml, "__with_libyaml__", False):
        return _Loader
    from yaml._yaml import CParser

    class _CLoader(_Bounded, CParser, _Constructor, _CoreResolver):
        def __init__(self, stream):
            CParser.__init__(self, stream)
            _Bounded.__init__(self)
            _Constructor.__init__(self)
            _CoreResolver.__init__(self)

    return _CLoader


_LOADER = _c_loader()


def _expanded_size(root: Node) -> int:
    """Nodes of ``root`` with aliases expanded, counted without expanding them (each shared
    node once, its count reused); YamlError for an alias that contains itself or a document
    over :data:`MAX_NODES`."""
    sizes: dict[int, int] = {}
    open_: set[int] = set()

    def size(node: Node) -> int:
        key = id(node)
        if key in sizes:
            return sizes[key]
        if key in open_:
            raise YamlError(
                "an alias refers to the node that contains it (a recursive structure)",
                node.start_mark.line + 1,
            )
        open_.add(key)
        total = 1
        if isinstance(node, SequenceNode):
            total += sum(size(item) for item in node.value)
        elif isinstance(node, MappingNode):
            total += sum(size(k) + size(v) for k, v in node.value)
        open_.discard(key)
        if total > MAX_NODES:
            raise YamlError(
                f"expands to more than {MAX_NODES:,} nodes (aliases of aliases?)",
                node.start_mark.line + 1,
            )
        sizes[key] = total
        return total

    return size(root)


def parse_yaml(text: str) -> tuple[Any, Node | None]:
    """The data of one YAML document and its composed node tree (for line numbers);
    YamlError with the line for malformed, unsafe or oversized input."""
    if len(text) > MAX_CONFIG_BYTES:
        raise YamlError(f"is larger than {describe(MAX_CONFIG_BYTES)}: not a config")
    loader = None
    try:
        loader = _LOADER(text)
        node = loader.get_single_node()
        if node is None:
            return None, None
        _expanded_size(node)
        return loader.construct_document(node), node
    except YamlError:
        raise
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        line = mark.line + 1 if mark is not None else None
        if line is not None:  # (libyaml marks an unclosed last line's end on the next one)
            line = min(line, text.count("\n") + 1)
        if line is None and isinstance(exc, yaml.reader.ReaderError):
            line = text[: exc.position].count("\n") + 1
        problem = (
            getattr(exc, "problem", None)
            or getattr(exc, "reason", None)
            or str(exc).splitlines()[0]
        )
        if "maximum nesting depth" in str(problem):  # (libyaml 0.2.6 stops at 1000 levels)
            raise YamlError(f"nested more than {MAX_DEPTH} levels deep", line) from None
        raise YamlError(f"malformed YAML: {problem}", line) from None
    except (ValueError, OverflowError, TypeError, AttributeError) as exc:
        # a number Python cannot hold, an explicit tag (!!timestamp, !!binary) of a value
        # its constructor cannot read
        raise YamlError(
            f"malformed YAML: a value that cannot be read ({exc.__class__.__name__})"
        ) from None
    finally:
        if loader is not None:
            loader.dispose()
