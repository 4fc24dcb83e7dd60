"""The top-level ``Config`` and YAML loading.

Every error names the YAML key path and its line: ``case.yaml:12: vehicle.body.mass: ...``.
Values built into the config by merging (``corner_defaults``) are reported at the line of the
key they came from; a key absent from the file at the line of the nearest key above it that
is there, or with no line when none is (``case.yaml: road: required key is missing``).

One load reports every problem it finds (``ConfigError.problems``): all of pydantic's errors,
said in the user's terms (``suspopt.config.messages``), and the values the table of
``suspopt.config.plausible`` finds absurd for a road vehicle; its warnings (a value that
looks like a unit slip) are ``cfg.warnings``, or ``exc.warnings`` with the errors.
"""

from __future__ import annotations

import os
import shlex
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

import yaml
from pydantic import Field, PrivateAttr, ValidationError

from ..errors import ConfigError, Problem, Problems, require, type_name
from .base import Section
from .control import Control
from .messages import plain_errors
from .metrics import MetricSpec
from .optimise import Constraint, DesignVariable, Objectives, Optimiser
from .plausible import check_plausible
from .road import RoadConfig
from .scenarios import Scenarios
from .seat import SeatConfig
from .simulation import Execution, Output, Simulation
from .vehicle import Vehicle, corner_defaults_schema
from .yamlio import YamlError, parse_yaml, read_text

__all__ = [
    "Config",
    "ConfigError",
    "load_config",
    "load_config_text",
    "require_config",
    "config_schema",
    "edit_config",
    "set_path",
    "line_of",
    "SCHEMA_DIALECT",
    "SCHEMA_ID",
]

#: The JSON Schema dialect of :func:`config_schema` (pydantic writes draft 2020-12).
SCHEMA_DIALECT = "https://json-schema.org/draft/2020-12/schema"
#: The schema's ``$id``: a name, not an address (``suspopt schema`` prints the schema and no
#: server holds it), so a URN, which no tool tries to download.
SCHEMA_ID = "urn:suspopt:schema:config"


class Config(Section):
    """A whole suspopt study."""

    vehicle: Vehicle = Field(description="the vehicle: preset, body, corners, anti-roll bars")
    road: RoadConfig = Field(description="the road under the wheels: a bump, ISO 8608 or a file")
    simulation: Simulation = Field(description="time step, duration and output sampling [s]")
    output: Output = Field(
        default_factory=Output, description="which signals simulate writes, and their precision"
    )
    metrics: list[MetricSpec] = Field(
        default_factory=list, description="metrics computed and stored by simulate"
    )
    control: Control | None = Field(
        None,
        description="digital controller of the semi-active "
        "dampers (sample time, actuator lag, CDF threshold)",
    )
    seat: SeatConfig | None = Field(
        None,
        description="seat isolator (PS, NSS1-NSS4) on the "
        "body, with its optional passenger (Sec 2.2-2.3)",
    )
    design_variables: list[DesignVariable] = Field(
        default_factory=list, description="config fields the optimiser varies, with bounds"
    )
    objectives: Objectives | None = Field(
        None, description="main and supplementary objectives of suspopt optimise (minimised)"
    )
    constraints: list[Constraint] = Field(
        default_factory=list, description="constraints g <= 0 of suspopt optimise"
    )
    optimiser: Optimiser | None = Field(
        None, description="algorithm, budget and seed of suspopt optimise"
    )
    scenarios: Scenarios | None = Field(
        None,
        description="conditions (roads, speeds, loads) every design of suspopt optimise is "
        "evaluated under; each objective and constraint combines its values over them",
    )
    execution: Execution = Field(
        default_factory=Execution,
        description="where populations are simulated: this process, local processes or Dask",
    )

    _source: Path | None = PrivateAttr(None)
    _text: str = PrivateAttr("")
    _lines: dict = PrivateAttr(default_factory=dict)
    _loaded: dict | None = PrivateAttr(None)  # the values as loaded from _text
    _warnings: tuple = PrivateAttr(())  # Problems of severity warning found on loading
    _hint: str | None = PrivateAttr(None)  # how to see every problem (ConfigError.hint)

    def problems(self) -> Problems:
        """A collector of problems found after validation, located like load errors (each
        at its key's line); ``raise_if_any()`` raises them as one ConfigError."""
        name = str(self._source) if self._source is not None else "<config>"
        lines = self._lines
        return Problems(name, lambda loc: _line_of(loc, lines) if lines else None, self._hint)

    def error(self, loc: tuple, message: str) -> ConfigError:
        """A ConfigError for a problem found after validation, located like a load error."""
        return ConfigError(problems=[self.problems().problem(loc, message)], hint=self._hint)

    @property
    def warnings(self) -> tuple[Problem, ...]:
        """What loading found plausible only as a unit slip (``suspopt.config.plausible``):
        problems of severity ``warning``, which reject nothing; ``suspopt validate`` prints
        them."""
        return self._warnings

    @property
    def source(self) -> Path | None:
        """The YAML file this config came from (None when built in Python)."""
        return self._source

    @property
    def text(self) -> str:
        """The YAML text of this config, recorded in every output file: as written (its
        comments kept) while the values are those it was loaded with; once a value was
        changed in Python (``cfg.simulation.duration = 10``), or for a config built in
        Python, the values as they are now, so that a file records the config that ran."""
        values = self.model_dump(mode="json")
        if self._text and (self._loaded is None or values == self._loaded):
            return self._text
        where = f"{self._source} as edited in Python" if self._text else "built in Python"
        return f"# {where}\n" + yaml.safe_dump(values, sort_keys=False)

    @property
    def base_dir(self) -> Path:
        """Directory that relative paths in the config are resolved against."""
        return self._source.parent if self._source is not None else Path.cwd()


def _line_map(node: yaml.Node, prefix: tuple = (), out: dict | None = None) -> dict:
    """Map every key path of a composed YAML tree to its 1-based line."""
    out = {} if out is None else out
    if isinstance(node, yaml.MappingNode):
        for key_node, value_node in node.value:
            path = prefix + (str(key_node.value),)
            out[path] = key_node.start_mark.line + 1
            _line_map(value_node, path, out)
    elif isinstance(node, yaml.SequenceNode):
        for i, item in enumerate(node.value):
            path = prefix + (i,)
            out[path] = item.start_mark.line + 1
            _line_map(item, path, out)
    return out


def line_of(node: yaml.Node | None, keys: tuple) -> int | None:
    """The 1-based line of the key path ``keys`` in the composed YAML ``node`` (that of the
    nearest enclosing key when it is not there), or None."""
    return _line_of(tuple(keys), _line_map(node)) if node is not None else None


def _line_of(loc: tuple, lines: dict) -> int | None:
    """Line of a pydantic error location: the key itself, else where a merged value came
    from (``corner_defaults``), else the nearest enclosing key."""
    loc = tuple(p for p in loc if not (isinstance(p, str) and p.startswith("function-")))
    candidates = [loc]
    if len(loc) >= 3 and loc[:2] == ("vehicle", "corners"):
        candidates.append(("vehicle", "corner_defaults") + loc[3:])
    for cand in candidates:
        if cand in lines:
            return lines[cand]
    for n in range(len(loc) - 1, 0, -1):
        if loc[:n] in lines:
            return lines[loc[:n]]
    return None


def _sections(text: str, name: str):
    """The data and node tree of a config's YAML text, a mapping of sections; ConfigError
    naming ``name`` and the line otherwise."""
    try:
        data, node = parse_yaml(text)
    except YamlError as exc:
        raise ConfigError(f"{name}{f':{exc.line}' if exc.line else ''}: {exc}") from None
    if not isinstance(data, dict):
        raise ConfigError(
            f"{name}:1: the config must be a mapping of sections (vehicle, road, simulation, ...)"
        )
    return data, node


def load_config_text(text: str, source: Path | None = None) -> Config:
    """Parse and validate YAML text; raise ConfigError with file, line and key path.

    The YAML is read by :func:`suspopt.config.yamlio.parse_yaml`: safe tags, the YAML 1.2
    core schema, bounded depth and size, no duplicate keys. ``source`` (a str or Path) names
    the file in messages, and relative paths inside the config are read from its folder.
    The ConfigError holds every problem of the config's values (module docstring)."""
    return _load_text(text, source)


def _load_text(text: str, source: Path | None, hint: str | None = None) -> Config:
    """:func:`load_config_text`; ``hint`` says how to see every problem (``ConfigError``)."""
    if not isinstance(text, str):
        raise TypeError(f"text must be the YAML as a str; got {type_name(text)}")
    source = Path(source) if source is not None else None
    name = str(source) if source is not None else "<config>"
    data, node = _sections(text, name)
    lines = _line_map(node) if node is not None else {}
    found = Problems(name, lambda loc: _line_of(loc, lines), hint)
    refused: set[tuple] = set()
    cfg = None
    try:
        base_dir = source.parent if source is not None else Path.cwd()
        cfg = Config.model_validate(data, context={"base_dir": base_dir})
    except ValidationError as exc:
        for loc, message in plain_errors(exc.errors(include_url=False), Config):
            found.add(loc, message)
            refused.add(loc)
    for loc, severity, message in check_plausible(data, refused):
        found.add(loc, message, severity)
    if found or cfg is None:
        # an unknown key usually explains a 'missing' one (a typo): the first said
        found.errors.sort(key=lambda p: (not p.message.startswith("unknown key"), p.line or 0))
        raise found.error()
    cfg._source = source
    cfg._text = text
    cfg._lines = lines
    cfg._loaded = cfg.model_dump(mode="json")
    cfg._warnings = tuple(found.warnings)
    cfg._hint = hint
    return cfg


def load_config(path: str | Path) -> Config:
    """Read and validate a YAML config file (a regular UTF-8 file of at most
    ``suspopt.config.yamlio.MAX_CONFIG_BYTES``, 1 MB).

    Parameters
    ----------
    path : str or Path
        The YAML file; relative paths inside it (a road CSV) are read from its folder.

    Returns
    -------
    Config
        The validated config, quantities in SI units (m, kg, s, N, rad).

    Raises
    ------
    ConfigError
        For anything wrong with the file, naming the file, the key and its line.
    TypeError
        When ``path`` is no path (None, a number, a loaded config).
    """
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"path must be a str or Path to a YAML config; got {type_name(path)}")
    path = Path(path)
    try:
        text = read_text(path)
    except FileNotFoundError:
        raise ConfigError(f"{path}: no such config file") from None
    except YamlError as exc:
        raise ConfigError(f"{path}{f':{exc.line}' if exc.line else ''}: {exc}") from None
    return _load_text(text, path, f"run suspopt validate {shlex.quote(str(path))}")


def require_config(cfg: object, argument: str = "cfg") -> Config:
    """``cfg`` when it is a :class:`Config`, else a TypeError that says how to make one: the
    library's entry points call it first, so that a path given where the loaded config
    belongs (the usual slip) is not an AttributeError from deep inside."""
    if isinstance(cfg, (str, os.PathLike)):
        how = f"load it first: suspopt.load_config({str(cfg)!r})"
    else:
        how = "from suspopt.load_config(path)"
    return require(cfg, Config, argument, how)


def set_path(data: dict, path: str, value: Any) -> None:
    """``data[a][b][c] = value`` for the dotted ``path`` ``a.b.c``, making missing levels (a
    corner given only by ``corner_defaults`` gets its own entry, which overrides them)."""
    *parents, key = path.split(".")
    for part in parents:
        if not isinstance(data.get(part), dict):
            data[part] = {}
        data = data[part]
    data[key] = value


def edit_config(
    text: str, edit: Callable[[dict], None], source: Path | None = None, what: str = "the change"
) -> Config:
    """The config of the YAML ``text`` with ``edit`` applied to its data (a dict, edited in
    place); the result's text is the edited YAML (comments are not kept) and its errors refer
    to the lines of that text under the name ``source``. ``what`` names the edit in messages.
    """
    data, _ = _sections(text, str(source) if source is not None else "<config>")
    edit(data)
    edited = yaml.safe_dump(data, sort_keys=False, allow_unicode=True)
    try:
        return load_config_text(edited, source)
    except ConfigError as exc:
        problems = [replace(p, message=f"{p.message} (with {what})") for p in exc.problems]
        raise ConfigError(problems=problems) from None


def config_schema() -> dict:
    """JSON Schema (draft 2020-12) of the config, for editors' completion and validation.

    It is pydantic's schema of :class:`Config` with one change, made here on the finished
    dict: the corners' keys that ``vehicle.corner_defaults`` may give are optional
    (:func:`!suspopt.config.vehicle.corner_defaults_schema`). The schema checks keys, types
    and ranges; rules between keys (``c_max >= c_min``, a preset's body fields, RK4
    stability, ...) are the loader's and ``suspopt validate``'s.

    Returns
    -------
    dict
        The schema as JSON-compatible data (the same as ``suspopt schema`` prints).
    """
    schema = Config.model_json_schema()
    corner_defaults_schema(schema["$defs"])
    return {"$schema": SCHEMA_DIALECT, "$id": SCHEMA_ID, **schema}
