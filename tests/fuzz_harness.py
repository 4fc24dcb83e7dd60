"""Fuzzing harness of the command line: broken configs and broken Pareto files.

Shared by ``tests/test_fuzz.py`` (configs), ``tests/test_fuzz_h5.py`` (Pareto files) and
``benchmarks/fuzz_configs.py`` (long runs). It never touches the library's code: it writes
inputs, runs the commands and judges what they did.

The contract every case is held to (docs/guide/errors.md): exit 0, or exit 2 with exactly one
line on stderr that names the input file (and, for a Pareto file, the dataset at fault) and no
``Traceback`` (``validate``: a line per problem, each naming the file, then their count:
:func:`report_problems`); never another exit code; never longer than :data:`LIMIT` seconds per command;
and a config that ``validate`` accepts must ``simulate -o OUT.h5`` (exit 0, the file written).

**How cases run.** The commands run in-process through ``typer.testing.CliRunner`` inside
worker processes (``python tests/fuzz_harness.py --worker``), never in the pytest process:

- each worker caps its address space at :data:`MEMORY` bytes (``RLIMIT_AS``), so a case that
  would allocate tens of GB fails there (``MemoryError``: exit 1, reported) instead of taking
  the machine down;
- each command gets ``SIGALRM`` after :data:`LIMIT` s (in the worker's main thread), which
  raises :class:`CaseTimeout` (a ``BaseException``: the library's ``except Exception`` does not
  swallow it) where the command was, so a time-out reports the place it hung;
- a worker that does not answer within the hard limit (stuck in C code that never returns to
  Python) is killed by its process id and restarted; a worker that dies (a crash) likewise.

Workers talk JSON lines over a pipe: one case in, one result out. Cases are described by data
(the file's text or bytes, or a special file to create: a directory, a FIFO, a symlink to
/dev/zero), so the worker creates the file and the harness itself never reads it.

**Cases are reproducible.** Mutation ``i`` of a run with seed ``s`` draws from
``numpy.random.default_rng([s, i])`` and mutates config ``i mod 117``: raising the number of
cases keeps the first ones as they were.
"""

from __future__ import annotations

import base64
import contextlib
import copy
import functools
import json
import math
import os
import queue
import re
import select
import signal
import subprocess
import sys
import tempfile
import threading
import time
import traceback
from dataclasses import asdict, dataclass, replace
from pathlib import Path

import numpy as np
import yaml

ROOT = Path(__file__).resolve().parents[1]
CONFIGS = ROOT / "configs"
HARNESS = Path(__file__).resolve()

#: The fixed seed of CI's cases.
SEED = 20260611
#: Per-command time limit [s] (SIGALRM in the worker). Every seed and every passing case
#: runs in under 0.7 s on the 2-core development machine.
LIMIT = 3.0
#: Grace before a silent worker is killed [s], on top of LIMIT per command.
HARD_GRACE = 8.0
#: Address-space cap of a worker [bytes] (``SUSPOPT_FUZZ_MEMORY_GB``, default 2); a worker with
#: everything imported maps ~0.4 GB. A MemoryError under the cap is a failure (exit 1).
MEMORY = int(float(os.environ.get("SUSPOPT_FUZZ_MEMORY_GB", "2")) * 2**30)
#: The base transformations of every seed: a short run and a tiny optimiser budget.
DURATION = 0.3
BUMP_START = 0.1
BUDGET = {"population": 8, "generations": 2, "max_evaluations": 16}


# --- cases ---------------------------------------------------------------------------------


@dataclass
class Case:
    """One input and the commands run on it.

    ``setup``: how the worker makes the input at ``{path}``: ``{"kind": "text", "text": ...}``,
    ``{"kind": "bytes", "b64": ...}``, ``{"kind": "dir"}``, ``{"kind": "fifo"}``,
    ``{"kind": "symlink", "target": ...}``, ``{"kind": "missing"}``, ``{"kind":
    "existing", "path": ...}`` (a file the parent made, e.g. a broken Pareto file) or
    ``{"kind": "folder", "path": ...}`` (a copy of a folder the parent made, for option cases;
    a refused command must leave it as it was).
    ``runs``: argv lists with ``{path}`` and ``{out}`` (an output file in the case's folder).
    ``dataset``: for Pareto cases, the dataset or attribute an exit-2 message must name.
    """

    id: str
    family: str  # "config", "h5" or "options"
    label: str
    setup: dict
    runs: list[list[str]]
    source: str = ""  # the bundled config (or front) it was made from
    name: str = "config.yaml"  # file name of the input
    dataset: str | None = None

    def to_json(self) -> str:
        return json.dumps(asdict(self))


CONFIG_RUNS = [["validate", "{path}"], ["simulate", "{path}", "-o", "{out}"]]
#: ``benchmarks/fuzz_configs.py --optimise``: the optimisation configs through ``optimise``
OPTIMISE_RUNS = [["validate", "{path}"], ["optimise", "{path}", "-o", "{out}"]]
#: The commands that write ``{out}`` from a config, and their exit codes that are not a
#: rejection of a config ``validate`` accepted (``optimise``'s 3: every design failed, a
#: result of the search, not of the config; it writes the file all the same)
WRITERS = {"simulate": (0,), "optimise": (0, 3)}
#: What ``optimise`` may refuse of a config ``validate`` accepts: a config with no optimiser
#: or no design variables (a mutation deleted them) is a valid config of the other commands,
#: not one to optimise
NOT_FOR = {
    "optimise": (": optimiser: required key is missing", ": design_variables: required key is")
}


def bundled_configs() -> list[Path]:
    return sorted(CONFIGS.rglob("*.yaml"))


def rel_name(path: Path) -> str:
    return path.relative_to(CONFIGS).with_suffix("").as_posix()


def seed_data(path: Path) -> dict:
    """A fresh copy of :func:`_seed_data` (cached: YAML is slow to parse)."""
    return copy.deepcopy(_seed_data(path))


@functools.cache
def _seed_data(path: Path) -> dict:
    """The bundled config with the base transformations: ``simulation.duration`` cut to
    :data:`DURATION` (a bump's ``start`` moved to :data:`BUMP_START` so the cut run still
    meets it) and the optimiser's budget cut to :data:`BUDGET`."""
    data = yaml.load(path.read_text(), Loader=LOADER)
    sim = data["simulation"]
    sim["duration"] = min(float(sim["duration"]), DURATION)
    road = data.get("road", {})
    if road.get("kind", "").startswith("bump") and road.get("start", 0) > BUMP_START:
        road["start"] = BUMP_START
    opt = data.get("optimiser")
    if isinstance(opt, dict):
        for key, most in BUDGET.items():
            if key in opt:
                opt[key] = min(int(opt[key]), most)
        if isinstance(opt.get("hybrid"), dict):
            opt["hybrid"]["ga_generations"] = 1
        balance = (opt.get("weighted_sum") or {}).get("balance")
        if isinstance(balance, dict):
            balance["samples"] = min(int(balance.get("samples", 100)), 8)
    return data


#: libyaml's dumper and loader where PyYAML has them (the same text and data as the pure
#: Python ones, four times faster: the cases are made at collection, in every pytest worker).
DUMPER = getattr(yaml, "CSafeDumper", yaml.SafeDumper)
LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


def dump(data) -> str:
    return yaml.dump(data, Dumper=DUMPER, sort_keys=False, allow_unicode=True, width=100)


def flow(value) -> str:
    """``value`` as one line of flow-style YAML."""
    return (
        yaml.safe_dump(value, default_flow_style=True, width=float("inf"))
        .strip()
        .removesuffix("\n...")
        .strip()
    )


# --- the tree of a config ------------------------------------------------------------------


def walk(node, prefix=()):
    """Every (path, value) below ``node`` (not the root), depth first."""
    items = (
        node.items()
        if isinstance(node, dict)
        else enumerate(node)
        if isinstance(node, list)
        else ()
    )
    for key, value in items:
        path = prefix + (key,)
        yield path, value
        yield from walk(value, path)


def get_at(data, path):
    for key in path:
        data = data[key]
    return data


def set_at(data, path, value) -> None:
    get_at(data, path[:-1])[path[-1]] = value


def delete_at(data, path) -> None:
    del get_at(data, path[:-1])[path[-1]]


def dotted(path) -> str:
    return (
        "".join(
            f"[{p}]" if isinstance(p, int) else (f".{p}" if i else str(p))
            for i, p in enumerate(path)
        )
        or "(root)"
    )


def is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def short(value, n: int = 40) -> str:
    text = (
        value
        if isinstance(value, str)
        else flow(value)
        if not isinstance(value, float)
        else repr(value)
    )
    text = text.replace("\n", "\\n")
    return text if len(text) <= n else text[: n - 3] + "..."


# --- mutation values -----------------------------------------------------------------------

#: Sizes are either cheap or absurd (>= 1e8 steps or waves, tens of GB): never a legal run
#: that merely takes longer than LIMIT (a 1000 s run, dt = 1e-7, 10^6 waves), whose time-out
#: would say nothing about robustness.
EXTREMES = [
    math.inf,
    -math.inf,
    math.nan,
    1e308,
    -1e308,
    0,
    0.0,
    -1,
    -1.0,
    1e-300,
    -1e-300,
    5e-324,
    2**70,
    -(2**70),
    2**63,
    2**64 + 1,
    10**9,
    10**12,
    1e9,
    1e12,
    1e15,
    1e-9,
]
#: numbers YAML reads as strings that pydantic may still turn into floats
NUMBER_STRINGS = [
    "1e309",
    "-1e309",
    "1e400",
    "nan",
    "inf",
    "-inf",
    "Infinity",
    "1_0",
    "0x10",
    " 1",
    "2e0",
    "",
    "NaN",
]
WRONG_TYPES = [
    "abc",
    "",
    [1, 2],
    [],
    {"a": 1},
    {},
    True,
    False,
    None,
    "true",
    [[]],
    {"kind": "x"},
    "0.0.0",
    "\u00e9\u00e8\u2603",
    "x" * 10_000,
]
#: sizes of a run: (path, values). Paths that a config lacks are added (unknown keys there).
SIZES = {
    ("simulation", "duration"): [
        math.inf,
        math.nan,
        1e6,
        1e7,
        1e9,
        1e12,
        1e308,
        2**70,
        1e-300,
        5e-324,
        0,
        -1,
        1.0,
        2.0,
        1e-3,
    ],
    ("simulation", "dt"): [
        1e-300,
        5e-324,
        1e-12,
        1e-9,
        math.inf,
        math.nan,
        0,
        -1e-3,
        0.3,
        0.29,
        0.1,
    ],
    ("simulation", "output_dt"): [1e-300, 1e308, math.inf, math.nan, 0, 0.3, 1e-3, 3e-3, 0.2],
    ("road", "n_waves"): [10**8, 10**9, 10**12, 2**70, 1e9, 1e12, 0, -1, 1, 2, 3, math.inf, 2.5],
    ("road", "n_max"): [1e8, 1e12, 1e308, math.inf, 2**70, 1e-300, 0.0111],
    ("road", "n_min"): [1e-300, 5e-324, 0, 2.8, 1e-12],
    ("road", "speed"): [1e-300, 1e308, math.inf, 1e9, 1e-9],
    ("road", "length"): [1e-300, 1e308, 1e12, 1e-12],
    ("road", "start"): [1e6, 1e308, 0.29, 0.3, 0.31, 10.0],
    ("road", "seed"): [2**70, 2**64, 2**63 - 1, -1, 1e12],
    ("road", "waviness"): [1e308, 1e-300, 100, 1e3],
    ("road", "level"): [1e308, 1e-300, 1e6],
    ("optimiser", "population"): [10**6, 10**9, 10**12, 2**70, 0, 1, 2, 1e6],
    ("optimiser", "generations"): [10**12, 2**70, 0, 1e9],
    ("optimiser", "max_evaluations"): [10**12, 2**70, 0, 1],
    ("optimiser", "stall_generations"): [10**12, 2**70, 0],
    ("optimiser", "seed"): [2**70, -1, 2**64, 1e12],
    ("optimiser", "tolerance"): [1e-300, 1e308, math.inf, math.nan],
    ("optimiser", "options"): [
        {"n_offsprings": 10**12},
        {"pop_size": 10**9},
        {"bogus": 1},
        {"eliminate_duplicates": "x"},
        {"sampling": 5},
        "abc",
    ],
    ("control", "sample_time"): [1e-300, 1e-12, 1e308, math.inf],
    ("control", "lag"): [1e-300, 1e308, math.inf],
    ("seat", "mass"): [1e308, 1e-300, math.inf, 0, 1e12],
    ("vehicle", "body", "mass"): [1e308, 1e-300, math.inf, 0, 1e12, -285],
}


def typo(rng, text: str) -> str:
    """A misspelling of ``text``."""
    if not text:
        return "x"
    i = int(rng.integers(len(text)))
    ops = [
        lambda: text[:i] + text[i + 1 :],  # drop
        lambda: text[:i] + text[i] * 2 + text[i + 1 :],  # double
        lambda: text[:i] + text[i + 1 : i + 2] + text[i : i + 1] + text[i + 2 :],  # swap
        lambda: text.upper() if text.upper() != text else text.lower(),
        lambda: text + " ",
        lambda: text + "_",
        lambda: text.replace("_", "-") if "_" in text else text + "s",
        lambda: text[:i] + "\u0430" + text[i + 1 :],
    ]  # a Cyrillic 'а'
    out = ops[int(rng.integers(len(ops)))]()
    return out if out != text else text + "x"


# --- YAML fragments ------------------------------------------------------------------------


def alias_bomb(levels: int = 9, width: int = 9) -> tuple[str, str]:
    """(anchors, alias): top-level keys ``_a``-``_i`` of a 'billion laughs' and the alias of
    the last level (``width ** levels`` leaves, about 400 bytes of text)."""
    names = "abcdefghijklmnopqrstuvwxyz"[:levels]
    lines = [f"_{names[0]}: &{names[0]} [" + ", ".join(['"x"'] * width) + "]"]
    for prev, name in zip(names, names[1:]):
        lines.append(f"_{name}: &{name} [" + ", ".join([f"*{prev}"] * width) + "]")
    return "\n".join(lines) + "\n", f"*{names[-1]}"


def deep_nesting(depth: int, style: str = "[") -> str:
    if style == "[":
        return "[" * depth + "]" * depth
    if style == "[unclosed":
        return "[" * depth
    if style == "{":
        return "{a: " * depth + "1" + "}" * depth
    raise ValueError(style)


def block_nesting(depth: int) -> str:
    """``depth`` levels of block mappings (about depth**2 bytes; keep depth ~1000)."""
    return (
        "\n"
        + "".join(" " * (2 * i + 2) + "a:\n" for i in range(depth))
        + " " * (2 * depth + 2)
        + "1"
    )


RAW = "__FUZZ_RAW_{}__"


def with_raw(data: dict, path, raw: str, header: str = "") -> str:
    """The YAML text of ``data`` with the value at ``path`` replaced by the raw YAML ``raw``
    (an alias, an anchor, deep brackets ...) and ``header`` put first."""
    data = copy.deepcopy(data)
    token = RAW.format(0)
    set_at(data, path, token)
    text = dump(data)
    assert token in text
    return header + text.replace(token, raw, 1)


# --- mutations -----------------------------------------------------------------------------


def _leaves(data, want=None):
    out = []
    for path, value in walk(data):
        if isinstance(value, (dict, list)):
            continue
        if want is None or want(value):
            out.append(path)
    return out


def _pick(rng, items):
    return items[int(rng.integers(len(items)))]


def _mappings(data):
    return [()] * 3 + [p for p, v in walk(data) if isinstance(v, dict) and v]


def mutate_delete(rng, data):
    path = _pick(rng, [p for p, _ in walk(data)])
    delete_at(data, path)
    return f"delete {dotted(path)}", None


def mutate_type(rng, data):
    paths = [p for p, _ in walk(data)]
    path = _pick(rng, paths)
    value = copy.deepcopy(_pick(rng, WRONG_TYPES))
    set_at(data, path, value)
    return f"{dotted(path)} = {short(value)}", None


def mutate_number(rng, data):
    paths = _leaves(data, is_number) or [p for p, _ in walk(data)]
    path = _pick(rng, paths)
    value = _pick(rng, EXTREMES + NUMBER_STRINGS if rng.random() < 0.3 else EXTREMES)
    set_at(data, path, value)
    return f"{dotted(path)} = {short(value)}", None


def mutate_size(rng, data):
    keys = [k for k in SIZES if k[0] in data]
    key = _pick(rng, keys)
    value = copy.deepcopy(_pick(rng, SIZES[key]))
    parent = (
        get_at(data, key[:-1])
        if all(isinstance(get_at(data, key[:i]), dict) for i in range(1, len(key)))
        else None
    )
    if not isinstance(parent, dict):
        return mutate_number(rng, data)
    parent[key[-1]] = value
    return f"{dotted(key)} = {short(value)}", None


def mutate_enum(rng, data):
    paths = _leaves(data, lambda v: isinstance(v, str) and v)
    if not paths:
        return mutate_type(rng, data)
    path = _pick(rng, paths)
    value = typo(rng, get_at(data, path))
    set_at(data, path, value)
    return f"{dotted(path)} = {short(value)}", None


def mutate_key(rng, data):
    path = _pick(rng, _mappings(data))
    mapping = get_at(data, path)
    if rng.random() < 0.5 and mapping:
        key = _pick(rng, list(mapping))
        new = typo(rng, str(key))
        mapping[new] = mapping.pop(key)
        return f"rename {dotted(path + (key,))} -> {short(new)}", None
    new = _pick(rng, ["bogus", "n_waves", "duration", "kind", "seed", "path", 1, True, None])
    mapping[new] = _pick(rng, [1, "x", math.inf, [1], {"a": 1}])
    return f"add {dotted(path)}[{short(new)}]", None


def mutate_list(rng, data):
    lists = [p for p, v in walk(data) if isinstance(v, list) and v]
    if not lists:
        return mutate_delete(rng, data)
    path = _pick(rng, lists)
    items = get_at(data, path)
    how = int(rng.integers(3))
    if how == 0:
        set_at(data, path, [])
        return f"{dotted(path)} = []", None
    k = int(_pick(rng, [2, 3, 20, 50]))
    set_at(data, path, [copy.deepcopy(items[0]) for _ in range(k)] + items[1:])
    return f"{dotted(path)}[0] repeated {k} times", None


def mutate_section(rng, data):
    key = _pick(rng, list(data))
    value = copy.deepcopy(_pick(rng, WRONG_TYPES[:12]))
    data[key] = value
    return f"section {key} = {short(value)}", None


def mutate_combo(rng, data):
    labels = []
    for _ in range(int(rng.integers(2, 4))):
        op = _pick(
            rng, [mutate_delete, mutate_type, mutate_number, mutate_size, mutate_enum, mutate_key]
        )
        try:
            label, _ = op(rng, data)
        except (KeyError, IndexError, TypeError):
            continue
        labels.append(label)
    return " & ".join(labels) or "combo (nothing)", None


# text-level mutations: return (label, text)


def _any_path(rng, data):
    return _pick(rng, [p for p, _ in walk(data)])


SYNTAX_BREAKS = [
    ("unclosed [", lambda line: line + " ["),
    ("unclosed {", lambda line: line + " {"),
    (
        "unterminated quote",
        lambda line: line.replace(": ", ': "', 1) if ": " in line else line + ' "',
    ),
    ("tab indentation", lambda line: "\t" + line),
    ("one more space", lambda line: " " + line),
    ("one less space", lambda line: line[1:] if line.startswith(" ") else "  " + line),
    ("missing colon", lambda line: line.replace(": ", " ", 1).replace(":", " ", 1)),
    ("value: value: value", lambda line: line + ": x: y"),
    ("stray dash", lambda line: line + "\n- x"),
    ("stray ]", lambda line: line + " ]"),
    ("stray }", lambda line: line + " }"),
    ("stray quote", lambda line: '"' + line),
    ("directive midway", lambda line: line + "\n%YAML 1.1"),
    ("second document", lambda line: line + "\n---\n" + line.strip()),
    ("python tag", lambda line: line + "\nzz: !!python/object/apply:os.system ['true']"),
    ("unknown tag", lambda line: line.replace(": ", ": !custom ", 1)),
    ("bad !!float", lambda line: line.replace(": ", ": !!float ", 1)),
    ("bad !!binary", lambda line: line.replace(": ", ": !!binary ", 1)),
    ("bad !!timestamp", lambda line: line.replace(": ", ": !!timestamp ", 1)),
    (
        "undefined alias",
        lambda line: line.split(":")[0] + ": *nowhere" if ":" in line else "*nowhere",
    ),
    ("anchor only", lambda line: line + " &"),
    ("complex key", lambda line: "? [a, b]\n: 1\n" + line),
    ("control character", lambda line: line + " \x07"),
    ("NUL", lambda line: line + "\x00"),
]


def mutate_syntax(rng, data):
    lines = dump(data).splitlines()
    i = int(rng.integers(len(lines)))
    if rng.random() < 0.1:
        cut = int(rng.integers(1, max(2, len("\n".join(lines)))))
        return f"text cut at {cut}", "\n".join(lines)[:cut]
    name, edit = _pick(rng, SYNTAX_BREAKS)
    lines[i] = edit(lines[i])
    return f"{name} at line {i + 1}", "\n".join(lines) + "\n"


def mutate_alias(rng, data):
    path = _any_path(rng, data)
    how = int(rng.integers(6))
    if how == 0:
        levels = int(_pick(rng, [3, 5, 7, 8, 9]))
        header, alias = alias_bomb(levels)
        return f"alias bomb ({levels} levels) at {dotted(path)}", with_raw(
            data, path, alias, header
        )
    if how == 1:
        return f"self-referencing list at {dotted(path)}", with_raw(data, path, "&r [*r]")
    if how == 2:
        return f"self-referencing map at {dotted(path)}", with_raw(data, path, "&r {a: *r}")
    if how == 3:
        maps = [p for p, v in walk(data) if isinstance(v, dict)] or [path]
        target = _pick(rng, maps)
        value = get_at(data, target)
        raw = "&m {<<: *m}" if rng.random() < 0.5 else "{<<: [1, 2]}"
        if isinstance(value, dict) and value and raw.startswith("{"):
            raw = "{<<: 5, " + flow(value)[1:]
        return f"bad merge key at {dotted(target)}: {raw[:20]}", with_raw(data, target, raw)
    if how == 4:
        # a good merge: the mapping given once under an anchor and merged back where it was
        maps = [p for p, v in walk(data) if isinstance(v, dict) and v]
        target = _pick(rng, maps)
        header = f"_defaults: &d {flow(get_at(data, target))}\n"
        return f"merge key (with unknown _defaults) at {dotted(target)}", with_raw(
            data, target, "{<<: *d}", header
        )
    # a merge inside the document that keeps it valid: the first corner merged into the second
    corners = data.get("vehicle", {}).get("corners")
    if isinstance(corners, dict) and len(corners) >= 2:
        first, second = list(corners)[:2]
        rest = {k: v for k, v in corners[second].items() if k != "tyre"}
        merged = copy.deepcopy(data)
        merged["vehicle"]["corners"][first] = RAW.format(1)
        merged["vehicle"]["corners"][second] = RAW.format(2)
        text = (
            dump(merged)
            .replace(RAW.format(1), "&c0 " + flow(corners[first]))
            .replace(RAW.format(2), "{<<: *c0" + (", " + flow(rest)[1:-1] if rest else "") + "}")
        )
        return f"corner {second} merges corner {first}'s tyre", text
    return f"undefined alias at {dotted(path)}", with_raw(data, path, "*nowhere")


def mutate_nesting(rng, data):
    path = _any_path(rng, data)
    style = _pick(rng, ["[", "[unclosed", "{", "block"])
    depth = int(_pick(rng, [50, 500, 990, 1100, 5000, 20_000]))
    if style == "block":  # block maps need a top-level key's indentation
        depth, path = min(depth, 1100), path[:1]
        return f"{depth} nested block maps at {dotted(path)}", with_raw(
            data, path, block_nesting(depth)
        )
    return (
        f"{depth} nested {style} at {dotted(path)}",
        with_raw(data, path, deep_nesting(depth, style)),
    )


def mutate_duplicate(rng, data):
    maps = [p for p, v in walk(data) if isinstance(v, dict) and v]
    if rng.random() < 0.3 or not maps:
        key = _pick(rng, list(data))
        extra = _pick(rng, [data[key], "x", {"duration": math.inf, "dt": 1e-3}, None])
        return f"top-level key {key} twice", dump(data) + f"{key}: {flow(extra)}\n"
    target = _pick(rng, maps)
    value = get_at(data, target)
    key = _pick(rng, list(value))
    extreme = _pick(rng, [math.inf, -1, "x", None, [1], value[key]])
    body = flow(value)[1:-1]
    raw = "{" + body + f", {flow(key)}: {flow(extreme)}" + "}"
    return f"duplicate key {dotted(target + (key,))} = {short(extreme)}", with_raw(
        data, target, raw
    )


def mutate_bytes(rng, data):
    """Not UTF-8, or not text at all: (label, bytes)."""
    text = dump(data).encode()
    how = int(rng.integers(7))
    if how == 0:
        n = int(_pick(rng, [1, 16, 4096]))
        return f"{n} random bytes", rng.bytes(n)
    if how == 1:
        i = int(rng.integers(len(text)))
        bad = _pick(rng, [b"\xff", b"\xfe\xff", b"\x80", b"\xc3", b"\xed\xa0\x80", b"\xf4\x90"])
        return f"byte {bad!r} at {i}", text[:i] + bad + text[i:]
    if how == 2:
        return "UTF-16 text", dump(data).encode("utf-16")
    if how == 3:
        return "UTF-8 BOM", b"\xef\xbb\xbf" + text
    if how == 4:
        return "latin-1 comment", b"# r\xe9sum\xe9\n" + text
    if how == 5:
        i = int(rng.integers(len(text)))
        return f"NUL byte at {i}", text[:i] + b"\x00" + text[i:]
    return "random bytes after the text", text + rng.bytes(64)


DATA_MUTATIONS = [
    (mutate_delete, 3),
    (mutate_type, 3),
    (mutate_number, 4),
    (mutate_size, 4),
    (mutate_enum, 2),
    (mutate_key, 2),
    (mutate_list, 1),
    (mutate_section, 1),
    (mutate_combo, 2),
]
TEXT_MUTATIONS = [
    (mutate_syntax, 2),
    (mutate_alias, 2),
    (mutate_nesting, 1),
    (mutate_duplicate, 1),
    (mutate_bytes, 1),
]


def _choose(rng, table):
    weights = np.array([w for _, w in table], dtype=float)
    return table[int(rng.choice(len(table), p=weights / weights.sum()))][0]


def _file_name(source: str) -> str:
    return source.replace("/", "_") + ".yaml"


def mutated_case(i: int, seed: int = SEED, configs: list[Path] | None = None) -> Case:
    """Mutation ``i`` of the run with ``seed`` (reproducible, see the module docstring)."""
    configs = configs or bundled_configs()
    path = configs[i % len(configs)]
    source = rel_name(path)
    rng = np.random.default_rng([seed, i])
    data = seed_data(path)
    op = _choose(rng, DATA_MUTATIONS + TEXT_MUTATIONS)
    label, out = op(rng, data)
    if out is None:
        setup = {"kind": "text", "text": dump(data)}
    elif isinstance(out, bytes):
        setup = {"kind": "bytes", "b64": base64.b64encode(out).decode()}
    else:
        setup = {"kind": "text", "text": out}
    kind = op.__name__.removeprefix("mutate_")
    return Case(
        id=_case_id(f"{i:04d}", source, f"{kind}:{label}"),
        family="config",
        label=f"{kind}: {label}",
        setup=setup,
        runs=CONFIG_RUNS,
        source=source,
        name=_file_name(source),
    )


def _case_id(*parts: str) -> str:
    text = "-".join(parts)
    text = re.sub(r"[^A-Za-z0-9_.:+\[\]-]+", "_", text)  # what pytest -k can match
    return text[:110]


def seed_cases(configs: list[Path] | None = None) -> list[Case]:
    """Every bundled config after the base transformations, unmutated: each must pass."""
    out = []
    for path in configs or bundled_configs():
        source = rel_name(path)
        out.append(
            Case(
                id=_case_id("seed", source),
                family="config",
                label="seed",
                setup={"kind": "text", "text": dump(seed_data(path))},
                runs=CONFIG_RUNS,
                source=source,
                name=_file_name(source),
            )
        )
    return out


def special_cases() -> list[Case]:
    """The inputs the brief names, each once: special files, alias bombs, deep nesting,
    duplicate keys, YAML breakage, non-UTF-8 text."""
    qs = CONFIGS / "quickstart.yaml"
    rnd = CONFIGS / "ch8" / "ps_class_a.yaml"
    base = seed_data(qs)
    seat = seed_data(rnd)
    good = dump(base)
    cases: list[tuple[str, dict, str]] = []

    def text(label, t, source="quickstart"):
        cases.append((label, {"kind": "text", "text": t}, source))

    def sub(t, old, new):
        assert old in t, old
        return t.replace(old, new, 1)

    def raw(label, b, source="quickstart"):
        cases.append((label, {"kind": "bytes", "b64": base64.b64encode(b).decode()}, source))

    cases.append(("config is a directory", {"kind": "dir"}, "quickstart"))
    cases.append(("config is a FIFO (nobody writes)", {"kind": "fifo"}, "quickstart"))
    cases.append(
        (
            "config is a symlink to /dev/zero",
            {"kind": "symlink", "target": "/dev/zero"},
            "quickstart",
        )
    )
    cases.append(("config is a symlink loop", {"kind": "symlink", "target": "self"}, "quickstart"))
    cases.append(
        (
            "config is a dangling symlink",
            {"kind": "symlink", "target": "/nonexistent/x.yaml"},
            "quickstart",
        )
    )
    cases.append(("config does not exist", {"kind": "missing"}, "quickstart"))
    text("empty file", "")
    text("only a comment", "# nothing\n")
    text("null document", "null\n")
    text("a list", "- 1\n- 2\n")
    text("a number", "42\n")
    text("a string", "hello\n")
    header, alias = alias_bomb(9)
    text(
        "alias bomb, 9 levels, at vehicle.body.mass",
        with_raw(base, ("vehicle", "body", "mass"), alias, header),
    )
    text("alias bomb, 9 levels, as metrics", header + good + f"metrics: {alias}\n")
    text("alias bomb, 9 levels, unused (unknown top-level keys)", header + good)
    text("self-referencing anchor: metrics: &m [*m]", good + "metrics: &m [*m]\n")
    text(
        "self-referencing anchor: vehicle.body: &b {mass: *b}",
        with_raw(base, ("vehicle", "body"), "&b {mass: *b}"),
    )
    text("merge key merging itself", with_raw(base, ("vehicle", "body"), "&b {<<: *b}"))
    text("merge key of a scalar", with_raw(base, ("vehicle", "body"), "{<<: 5, mass: 2210}"))
    corners = base["vehicle"]["corners"]
    merged = copy.deepcopy(base)
    merged["vehicle"]["corners"]["F1"] = RAW.format(1)
    merged["vehicle"]["corners"]["R1"] = RAW.format(2)
    rear = {k: v for k, v in corners["R1"].items() if k != "tyre"}
    text(
        "merge key: R1 merges F1's tyre (valid)",
        dump(merged)
        .replace(RAW.format(1), "&f1 " + flow(corners["F1"]))
        .replace(RAW.format(2), "{<<: *f1, " + flow(rear)[1:]),
    )
    text(
        "5000 [ at simulation.duration (closed)",
        with_raw(base, ("simulation", "duration"), deep_nesting(5000)),
    )
    text(
        "5000 [ at simulation.duration (unclosed)",
        with_raw(base, ("simulation", "duration"), deep_nesting(5000, "[unclosed")),
    )
    text("5000 { at vehicle.body", with_raw(base, ("vehicle", "body"), deep_nesting(5000, "{")))
    text("1100 nested block maps at road", with_raw(base, ("road",), block_nesting(1100)))
    text(
        "duplicate top-level key simulation (second: duration .inf)",
        good + "simulation: {duration: .inf, dt: 1.0e-3}\n",
    )
    text(
        "duplicate key simulation.duration (.inf last)",
        with_raw(base, ("simulation",), "{duration: 0.3, dt: 1.0e-3, duration: .inf}"),
    )
    text(
        "duplicate key vehicle.body.mass (equal)",
        with_raw(
            base, ("vehicle", "body"), "{" + flow(base["vehicle"]["body"])[1:-1] + ", mass: 2210}"
        ),
    )
    lines = good.splitlines()
    text("unclosed bracket", sub(good, "body:", "body: ["))
    text("bad indentation", "\n".join(lines[:3] + [" " + lines[3]] + lines[4:]) + "\n")
    text("tabs for indentation", good.replace("\n  ", "\n\t"))
    text("unterminated quote", sub(good, "kind: ", 'kind: "'))
    text("python object tag", good + "zz: !!python/object/apply:os.system ['true']\n")
    raw("non-UTF-8 byte in a value", good.replace("bump_half_sine", "bump_\xe9").encode("latin-1"))
    raw("UTF-16 text", good.encode("utf-16"))
    raw("4 KB of random bytes", np.random.default_rng([SEED, 1]).bytes(4096))
    raw("NUL bytes", good.encode().replace(b"\n", b"\n\x00", 3))
    text("enum typo road.kind", sub(good, "bump_half_sine", "bump_half_sin"))
    text("enum typo vehicle.preset", sub(good, "half_pitch", "Half_pitch"))
    for key, values in (
        ("duration", [".inf", ".nan", "1e308", "1.0e+12", "2e6", str(2**70)]),
        ("dt", ["1.0e-300", "5.0e-324"]),
    ):
        for v in values:
            text(
                f"simulation.{key} = {v}",
                sub(good, f"  {key}: {base['simulation'][key]}\n", f"  {key}: {v}\n"),
            )
    seat_text = dump(seat)
    for v in ["1000000000000", "1.0e+9", str(2**70), "100000000"]:
        text(
            f"road.n_waves = {v}",
            sub(seat_text, "  seed: 1\n", f"  seed: 1\n  n_waves: {v}\n"),
            "ch8/ps_class_a",
        )
    for v in ["1.0e+12", ".inf"]:
        text(
            f"road.n_max = {v}",
            sub(seat_text, "  seed: 1\n", f"  seed: 1\n  n_max: {v}\n"),
            "ch8/ps_class_a",
        )
    opt = seed_data(CONFIGS / "ch8" / "pareto_ps_class_a.yaml")
    for v in [10**12, 10**9, 2**70]:
        o = copy.deepcopy(opt)
        o["optimiser"]["population"] = v
        text(f"optimiser.population = {v}", dump(o), "ch8/pareto_ps_class_a")
    for label, mass in (
        ("vehicle.body.mass = .inf", math.inf),
        ("vehicle.body.mass = 1e308", 1e308),
    ):
        b = copy.deepcopy(base)
        b["vehicle"]["body"]["mass"] = mass
        text(label, dump(b))
    out = []
    for n, (label, setup, source) in enumerate(cases):
        out.append(
            Case(
                id=_case_id("special", f"{n:02d}", label),
                family="config",
                label=label,
                setup=setup,
                runs=CONFIG_RUNS,
                source=source,
                name=_file_name(source),
            )
        )
    return out


def config_cases(n: int, seed: int = SEED) -> list[Case]:
    """CI's config cases: the seeds, the special inputs and ``n`` random mutations."""
    configs = bundled_configs()
    return (
        seed_cases(configs) + special_cases() + [mutated_case(i, seed, configs) for i in range(n)]
    )


def optimisation_cases(n: int, seed: int = SEED, fixed: bool = True) -> list[Case]:
    """The bundled optimisation configs (those with an ``optimiser:`` section, on the tiny
    budget of :data:`BUDGET`) and ``n`` random mutations of them, each run through
    ``validate`` and ``optimise`` (:data:`OPTIMISE_RUNS`)."""
    configs = [p for p in bundled_configs() if isinstance(_seed_data(p).get("optimiser"), dict)]
    cases = seed_cases(configs) if fixed else []
    cases += [mutated_case(i, seed, configs) for i in range(n)]
    return [replace(c, id=f"opt-{c.id}"[:110], runs=OPTIMISE_RUNS) for c in cases]


#: pydantic's message for a number out of range: which side and the bound
_BOUND = re.compile(r"(less|greater) than or equal to (-?[0-9.eE+-]+)")


def bound_cases(optimise: bool = False) -> list[Case]:
    """Every number of every bundled config (the optimisation configs only, run through
    ``optimise``, with ``optimise``) set to each closed bound its schema allows, and to 0
    where that is allowed: the values most likely to pass ``validate`` and still break a
    run. The bounds are found by loading the config with the number at ±1e308 and reading
    the range from the error."""
    from suspopt.config import ConfigError
    from suspopt.config.loader import load_config_text

    out, seen = [], set()
    for path in bundled_configs():
        data = seed_data(path)
        if optimise and not isinstance(data.get("optimiser"), dict):
            continue
        source = rel_name(path)
        for leaf in _leaves(data, lambda v: is_number(v) and not isinstance(v, bool)):
            value = get_at(data, leaf)
            for probe in (1e308, -1e308, 0.0):
                probed = copy.deepcopy(data)
                set_at(probed, leaf, probe)
                try:
                    load_config_text(dump(probed), path)
                    bound: float | None = probe if probe == 0.0 else None
                except ConfigError as exc:
                    found = _BOUND.search(str(exc))
                    bound = float(found.group(2)) if found and probe != 0.0 else None
                if bound is None:
                    continue
                if isinstance(value, int) and bound.is_integer():
                    bound = int(bound)
                case_id = _case_id("bound", source, dotted(leaf), str(bound))
                if case_id in seen:
                    continue
                seen.add(case_id)
                bounded = copy.deepcopy(data)
                set_at(bounded, leaf, bound)
                out.append(
                    Case(
                        id=case_id,
                        family="config",
                        label=f"bound: {dotted(leaf)} = {bound}",
                        setup={"kind": "text", "text": dump(bounded)},
                        runs=OPTIMISE_RUNS if optimise else CONFIG_RUNS,
                        source=source,
                        name=_file_name(source),
                    )
                )
    return out


def case_count(default: int) -> int:
    """The number of random mutations: ``SUSPOPT_FUZZ_CASES`` (env), else ``default``."""
    value = os.environ.get("SUSPOPT_FUZZ_CASES")
    return int(value) if value else default


# --- Pareto files ----------------------------------------------------------------------------

H5_RUNS = [
    ["kesort", "{path}", "-o", "{out}"],
    ["analyse", "roads", "{path}", "--road", "B", "-o", "{out}"],
    ["analyse", "masses", "{path}", "-o", "{out}"],
    ["analyse", "transmissibility", "{path}", "-o", "{out}"],
    ["simulate", "{path}", "--pick", "knee,0", "-o", "{out}"],
    ["export", "{path}", "--pick", "knee", "-o", "{out}.yaml"],
    ["export", "{path}", "--csv", "{out}.csv"],
    ["export", "{path}", "--mat", "{out}.mat"],
    ["export", "{path}", "--pick", "knee", "--fmu", "{out}.fmu"],
]
#: the bundled config of the tiny front, and its run length [s]
FRONT = "ch8/pareto_ps_class_a"
FRONT_DURATION = 0.3
HUGE_ROWS = 10**12


def make_front(folder: Path) -> tuple[Path, Path]:
    """A real tiny Pareto file (``tests/conftest.py: optimised_front``)."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from conftest import optimised_front

    return optimised_front(folder, FRONT, FRONT_DURATION)


def _copy_edit(edit):
    """A variant that copies the good file and edits it with h5py (``edit(h5)``)."""

    def build(good: Path, dst: Path) -> None:
        import shutil

        import h5py

        shutil.copyfile(good, dst)
        with h5py.File(dst, "r+") as h5:
            edit(h5)

    return build


def _bytes_of(transform):
    """A variant whose bytes are ``transform(bytes of the good file)``."""

    def build(good: Path, dst: Path) -> None:
        dst.write_bytes(transform(good.read_bytes()))

    return build


def _replace(key: str, make):
    """``/pareto/<key>`` replaced by ``make(h5, old values, old attrs)``, which creates it."""

    def edit(h5):
        ds = h5[f"pareto/{key}"]
        values, attrs = ds[()], dict(ds.attrs)
        del h5[f"pareto/{key}"]
        make(h5, f"pareto/{key}", values, attrs)

    return _copy_edit(edit)


def _data(fn, keep_attrs: bool = True):
    def make(h5, name, values, attrs):
        ds = h5.create_dataset(name, data=fn(values))
        if keep_attrs:
            for k, v in attrs.items():
                ds.attrs[k] = v

    return make


def _huge(h5, name, values, attrs):
    ds = h5.create_dataset(
        name,
        shape=(HUGE_ROWS, values.shape[1]),
        dtype="f8",
        chunks=(1024, values.shape[1]),
        maxshape=(None, values.shape[1]),
    )
    for k, v in attrs.items():
        ds.attrs[k] = v


def _attr(key: str, attr: str, value):
    def edit(h5):
        ds = h5[f"pareto/{key}"]
        if value is _DELETE:
            del ds.attrs[attr]
        else:
            ds.attrs[attr] = value(ds) if callable(value) else value

    return _copy_edit(edit)


_DELETE = object()


def _root_config(value):
    def edit(h5):
        if value is _DELETE:
            del h5.attrs["config"]
        else:
            h5.attrs["config"] = value(h5.attrs["config"]) if callable(value) else value

    return _copy_edit(edit)


def _names(ds, n_more=0):
    names = [n.encode() if isinstance(n, str) else bytes(n) for n in ds.attrs["names"]]
    return np.array(
        names[: len(names) + n_more] if n_more < 0 else names + [b"extra"] * n_more, dtype="S"
    )


def _config_of(rel: str) -> str:
    return (CONFIGS / f"{rel}.yaml").read_text()


def _edit_config(edit):
    def change(text):
        text = text.decode() if isinstance(text, bytes) else str(text)
        data = yaml.safe_load(text)
        edit(data)
        return dump(data)

    return change


def _set_config(path, value):
    def edit(data):
        set_at(data, path, value)

    return _edit_config(edit)


def _special_file(kind: str):
    def build(good: Path, dst: Path) -> None:
        if kind == "dir":
            dst.mkdir()
        elif kind == "fifo":
            os.mkfifo(dst)
        elif kind == "zero":
            os.symlink("/dev/zero", dst)

    return build


def h5_variants() -> list[tuple[str, object, str | None]]:
    """(name, build(good, dst), the dataset an exit-2 message must name) of every broken
    Pareto file."""
    header, alias = alias_bomb(9)
    out: list[tuple[str, object, str | None]] = [
        ("intact", _bytes_of(lambda b: b), None),
        ("empty_file", _bytes_of(lambda b: b""), None),
        ("truncated_half", _bytes_of(lambda b: b[: len(b) // 2]), None),
        ("truncated_2048_bytes", _bytes_of(lambda b: b[:2048]), None),
        ("truncated_last_byte", _bytes_of(lambda b: b[:-1]), None),
        ("random_4KB", _bytes_of(lambda b: np.random.default_rng([SEED, 2]).bytes(4096)), None),
        (
            "hdf5_signature_then_random",
            _bytes_of(lambda b: b[:8] + np.random.default_rng([SEED, 3]).bytes(len(b) - 8)),
            None,
        ),
        ("text_file", _bytes_of(lambda b: b"vehicle: {}\n"), None),
        ("directory", _special_file("dir"), None),
        ("fifo", _special_file("fifo"), None),
        ("symlink_dev_zero", _special_file("zero"), None),
        ("no_pareto_group", _copy_edit(lambda h5: h5.__delitem__("pareto")), "/pareto"),
        (
            "pareto_empty_group",
            _copy_edit(lambda h5: [h5["pareto"].__delitem__(k) for k in list(h5["pareto"])]),
            "/pareto",
        ),
        (
            "pareto_is_a_dataset",
            _copy_edit(
                lambda h5: (h5.__delitem__("pareto"), h5.create_dataset("pareto", data=1.0))
            ),
            "/pareto",
        ),
    ]
    for key in ("X", "F", "G"):
        ds = f"/pareto/{key}"
        out += [
            (f"{key}_deleted", _copy_edit(lambda h5, k=key: h5["pareto"].__delitem__(k)), ds),
            (f"{key}_text_scalar", _replace(key, _data(lambda v: "abc")), ds),
            (
                f"{key}_text_array",
                _replace(key, _data(lambda v: np.full(v.shape, b"abc", dtype="S3"))),
                ds,
            ),
            (
                f"{key}_vlen_text",
                _replace(
                    key,
                    _data(
                        lambda v: np.array([["x"] * v.shape[1]] * v.shape[0], dtype=object).astype(
                            "O"
                        )
                    ),
                ),
                ds,
            ),
            (f"{key}_1d", _replace(key, _data(lambda v: v[:, 0])), ds),
            (f"{key}_3d", _replace(key, _data(lambda v: v[:, :, None])), ds),
            (f"{key}_zero_rows", _replace(key, _data(lambda v: v[:0])), ds),
            (f"{key}_zero_columns", _replace(key, _data(lambda v: v[:, :0])), ds),
            (f"{key}_one_row_fewer", _replace(key, _data(lambda v: v[:-1])), ds),
            (f"{key}_scalar", _replace(key, _data(lambda v: 1.0)), ds),
            (f"{key}_nan", _replace(key, _data(lambda v: np.full(v.shape, np.nan))), ds),
            (f"{key}_inf", _replace(key, _data(lambda v: np.full(v.shape, np.inf))), ds),
            (f"{key}_minus_inf", _replace(key, _data(lambda v: np.full(v.shape, -np.inf))), ds),
            (
                f"{key}_one_row_nan",
                _replace(key, _data(lambda v: np.vstack([np.full(v.shape[1], np.nan), v[1:]]))),
                ds,
            ),
            (f"{key}_1e308", _replace(key, _data(lambda v: np.full(v.shape, 1e308))), ds),
            (f"{key}_negative", _replace(key, _data(lambda v: -np.abs(v) - 1.0)), ds),
            (f"{key}_int", _replace(key, _data(lambda v: v.astype(np.int64))), ds),
            (f"{key}_bool", _replace(key, _data(lambda v: v > np.median(v))), ds),
            (f"{key}_complex", _replace(key, _data(lambda v: v + 1j)), ds),
            (
                f"{key}_compound",
                _replace(
                    key, _data(lambda v: np.zeros(v.shape[0], dtype=[("a", "f8"), ("b", "S3")]))
                ),
                ds,
            ),
            (f"{key}_a_group", _replace(key, lambda h5, name, v, a: h5.create_group(name)), ds),
            (f"{key}_huge_declared_shape", _replace(key, _huge), ds),
            (f"{key}_names_missing", _attr(key, "names", _DELETE), ds),
            (f"{key}_units_missing", _attr(key, "units", _DELETE), ds),
            (f"{key}_names_one_more", _attr(key, "names", lambda d: _names(d, 1)), ds),
            (
                f"{key}_units_one_fewer",
                _attr(key, "units", lambda d: np.array(list(d.attrs["units"])[:-1], dtype="S")),
                ds,
            ),
            (f"{key}_names_empty", _attr(key, "names", np.array([], dtype="S1")), ds),
            (
                f"{key}_names_ints",
                _attr(key, "names", lambda d: np.arange(len(d.attrs["names"]))),
                ds,
            ),
            (f"{key}_names_scalar_string", _attr(key, "names", "RC_se"), ds),
            (
                f"{key}_names_not_utf8",
                _attr(
                    key,
                    "names",
                    lambda d: np.array([b"\xff\xfe"] * len(d.attrs["names"]), dtype="S2"),
                ),
                ds,
            ),
            (
                f"{key}_names_2d",
                _attr(key, "names", lambda d: np.array([list(d.attrs["names"])], dtype="S")),
                ds,
            ),
        ]
    # values of the right type whose content is odd but possible (failed or infeasible
    # designs): the commands may reject them, without a dataset being at fault
    plausible = {
        "F_nan",
        "F_inf",
        "F_minus_inf",
        "F_one_row_nan",
        "F_1e308",
        "F_negative",
        "F_int",
        "F_bool",
        "G_nan",
        "G_inf",
        "G_minus_inf",
        "G_one_row_nan",
        "G_1e308",
        "G_negative",
        "G_int",
        "G_bool",
        "X_1e308",
        "X_negative",
        "X_int",
        "X_bool",
    }
    out = [(name, build, None if name in plausible else ds) for name, build, ds in out]
    out += [
        ("X_names_not_in_config", _attr("X", "names", np.array([b"foo", b"bar"])), "/pareto/X"),
        (
            "X_names_duplicated",
            _attr(
                "X",
                "names",
                lambda d: np.array([d.attrs["names"][0]] * len(d.attrs["names"]), dtype="S"),
            ),
            "/pareto/X",
        ),
        (
            "X_names_swapped",
            _attr("X", "names", lambda d: np.array(list(d.attrs["names"])[::-1], dtype="S")),
            None,
        ),
        ("F_names_not_in_config", _attr("F", "names", np.array([b"a", b"b"])), "/pareto/F"),
        ("X_outside_bounds", _replace("X", _data(lambda v: v * 1e6)), None),
        ("X_zero", _replace("X", _data(lambda v: np.zeros_like(v))), None),
        ("config_missing", _root_config(_DELETE), "config"),
        ("config_not_utf8", _root_config(np.bytes_(b"vehicle: \xff\xfe\n")), "config"),
        ("config_yaml_error", _root_config("vehicle: [\n"), "config"),
        (
            "config_alias_bomb",
            _root_config(lambda t: header + str(t) + f"metrics: {alias}\n"),
            "config",
        ),
        ("config_self_reference", _root_config(lambda t: str(t) + "metrics: &m [*m]\n"), "config"),
        (
            "config_deep_nesting",
            _root_config(
                lambda t: str(t).replace("road:", "zz: " + "[" * 5000 + "]" * 5000 + "\nroad:", 1)
            ),
            "config",
        ),
        ("config_empty", _root_config(""), "config"),
        ("config_an_int", _root_config(42), "config"),
        ("config_a_list", _root_config(np.array([b"vehicle:", b"road:"])), "config"),
        ("config_other_without_design_variables", _root_config(_config_of("quickstart")), "config"),
        ("config_other_seat", _root_config(_config_of("ch8/pareto_nss1_class_a")), "config"),
        (
            "config_other_objectives",
            _root_config(_edit_config(lambda d: d["objectives"]["main"].reverse())),
            "config",
        ),
        (
            "config_supplementary_objective",
            _root_config(
                _edit_config(
                    lambda d: (
                        d["objectives"]
                        .setdefault("supplementary", [])
                        .append({"name": "travel", "metric": "max_abs", "signal": "seat.travel"})
                    )
                )
            ),
            None,
        ),
        (
            "config_bump_road",
            _root_config(
                _set_config(
                    ("road",),
                    {
                        "kind": "bump_step",
                        "height": 0.05,
                        "length": 1.0,
                        "speed": 10.0,
                        "start": 0.1,
                    },
                )
            ),
            "config",
        ),
        (
            "config_body_mass_inf",
            _root_config(_set_config(("vehicle", "body", "mass"), math.inf)),
            "config",
        ),
        ("config_seat_mass_1e308", _root_config(_set_config(("seat", "mass"), 1e308)), "config"),
        (
            "config_duration_1e12",
            _root_config(_set_config(("simulation", "duration"), 1e12)),
            "config",
        ),
        ("config_dt_1e-300", _root_config(_set_config(("simulation", "dt"), 1e-300)), "config"),
        ("config_n_waves_1e12", _root_config(_set_config(("road", "n_waves"), 10**12)), "config"),
        ("config_no_seat", _root_config(_edit_config(lambda d: d.pop("seat"))), "config"),
        # the config's own design (/baseline), which kesort and report read
        (
            "baseline_F_text",
            _copy_edit(
                lambda h5: (
                    h5["baseline"].__delitem__("F"),
                    h5["baseline"].create_dataset("F", data=b"abc"),
                )
            ),
            "/baseline/F",
        ),
        (
            "baseline_F_3d",
            _copy_edit(
                lambda h5: (
                    h5["baseline"].__delitem__("F"),
                    h5["baseline"].create_dataset("F", data=np.zeros((1, 1, 1))),
                )
            ),
            "/baseline/F",
        ),
        (
            "baseline_names_missing",
            _copy_edit(lambda h5: h5["baseline/F"].attrs.__delitem__("names")),
            "/baseline/F",
        ),
        (
            "baseline_G_missing",
            _copy_edit(lambda h5: h5["baseline"].__delitem__("G")),
            "/baseline/G",
        ),
        (
            "baseline_F_nan",
            _copy_edit(lambda h5: h5["baseline/F"].__setitem__((0, 0), np.nan)),
            None,
        ),
        (
            "baseline_a_dataset",
            _copy_edit(
                lambda h5: (h5.__delitem__("baseline"), h5.create_dataset("baseline", data=1.0))
            ),
            None,
        ),
    ]
    return out


def normalised_front(good: Path, dst: Path) -> Path:
    """The front's root attributes and ``/pareto`` (no ``/history``, no ``/checkpoint``) in a
    new file, with ``created`` and ``command`` fixed: the same bytes in every run (the
    optimiser is reproducible), so that random byte flips are reproducible too."""
    import h5py

    with h5py.File(good, "r") as src, h5py.File(dst, "w") as out:
        for key, value in src.attrs.items():
            out.attrs[key] = {
                "created": "2000-01-01T00:00:00+00:00",
                "command": f"suspopt optimise {FRONT}",
            }.get(key, value)
        src.copy("pareto", out)
    return dst


RANDOM_PREFIX = "random_bytes_"


def _flipped(seed: int, i: int):
    """The builder of random variant ``i`` of ``seed``: 1-8 bytes overwritten at random."""

    def flip(b):
        rng = np.random.default_rng([seed, 10_000 + i])
        b = bytearray(b)
        for _ in range(int(rng.integers(1, 9))):
            at = int(rng.integers(len(b)))
            b[at] = int(rng.integers(256))
        return bytes(b)

    return _bytes_of(flip)


def h5_random_variants(n: int, seed: int = SEED) -> list[tuple[str, object, str | None]]:
    """``n`` copies of the normalised front (:func:`normalised_front`) with 1-8 bytes
    overwritten at random offsets, and the flips of other seeds that once found a fault
    (:data:`FOUND_FLIPS`)."""
    out = [(f"{RANDOM_PREFIX}{i:04d}", _flipped(seed, i), None) for i in range(n)]
    for found_seed, i, _ in FOUND_FLIPS:
        out.append((f"{RANDOM_PREFIX}seed{found_seed}_{i:04d}", _flipped(found_seed, i), None))
    return out


#: Random flips of other seeds (``benchmarks/fuzz_configs.py --h5-only --seed S``) that found a
#: fault: (seed, variant, what it did). They hold only while the front's bytes stay the same.
FOUND_FLIPS = [
    (777, 145, "a text attribute's stored length of 1 GB, allocated before the read failed"),
    (2024, 292, "a name that is not UTF-8, failing only when written out again"),
    (2024, 426, "an attribute crashing HDF5, behind a root whose attributes fail to list"),
    (99, 515, "a damaged reference to a dimension scale, crashing HDF5 when export opened it"),
    (31337, 855, "an objective of -7e306, whose normalisation overflowed: a warning line"),
    (606, 402, "a dataset that cannot be opened, ending the probe's walk before a crash"),
    (4242, 9, "a damaged datatype, a traceback when an output's owner was looked up"),
    (4242, 159, "an object of no known type, a traceback when an output's owner was looked up"),
]
#: Run on the found flips only (last: it replaces the file where suspopt wrote it): the file
#: as an existing output, whose owner is looked up before anything is written.
FOUND_FLIP_RUNS = [["simulate", "configs/quickstart.yaml", "-o", "{path}"]]


def h5_cases(variants) -> list[Case]:
    return [
        Case(
            id=_case_id("h5", name),
            family="h5",
            label=name,
            setup={"kind": "h5", "variant": name},
            runs=H5_RUNS + (FOUND_FLIP_RUNS if name.startswith(f"{RANDOM_PREFIX}seed") else []),
            source=FRONT,
            name=f"{name}.h5",
            dataset=dataset,
        )
        for name, _, dataset in variants
    ]


def build_h5_cases(cases: list[Case], variants, folder: Path) -> list[Case]:
    """Make the file of every case in ``folder`` (a tiny front, then its broken copies);
    the cases with ``setup`` pointing at their files."""
    folder.mkdir(parents=True, exist_ok=True)
    _, good = make_front(folder)
    normalised = normalised_front(good, folder / "normalised.h5")
    builders = {name: build for name, build, _ in variants}
    out = []
    for case in cases:
        dst = folder / "variants" / case.name
        dst.parent.mkdir(exist_ok=True)
        base = normalised if case.label.startswith(RANDOM_PREFIX) else good
        builders[case.label](base, dst)
        out.append(Case(**{**asdict(case), "setup": {"kind": "existing", "path": str(dst)}}))
    return out


# --- command-line options ------------------------------------------------------------------

#: Hostile values for every option that takes one and every positional argument
#: (``benchmarks/fuzz_configs.py --options``): numbers out of every range, non-finite and
#: unparsable ones, names the system cannot look up, special files, and names of the case's
#: own inputs (``{path}`` is the case's copy of :func:`option_fixtures`).
OPTION_VALUES = [
    "nan", "inf", "-inf", "-1", "0", "1e309", "1e-320", "99999999999999999999999", "0x10",
    "3.5", "1,2", ",", "", "-", "..", "~", "ü/ß", "x" * 300, "x/" * 200, "/", "/dev/zero",
    "/dev/stdin", "/proc/self/mem", "/proc/self/status", "{path}", "{path}/fifo",
    "{path}/study.yaml", "{path}/front.h5", "{path}/nofile/x.h5", "{path}/study.yaml/x",
    "4G", "1e30G", "-2G", "0.5K", "--force", "--help", "A", "knee,chosen,0,-1,99",
]  # fmt: skip
#: One valid run of every command on :func:`option_fixtures` (``{path}``: the case's copy of
#: the folder; ``{out}``: an output beside it); the options of each are fuzzed on it
OPTION_BASES = [
    ["validate", "{path}/study.yaml"],
    ["init", "quarter", "-o", "{out}.yaml"],
    ["simulate", "{path}/study.yaml", "-o", "{out}"],
    ["optimise", "{path}/study.yaml", "-o", "{out}"],
    ["kesort", "{path}/front.h5", "-o", "{out}"],
    ["export", "{path}/choice.h5", "--pick", "chosen", "-o", "{out}.yaml"],
    ["export", "{path}/builds.h5", "--mat", "{out}.mat"],
    ["export", "{path}/choice.h5", "--pick", "chosen", "--fmu", "{out}.fmu"],
    ["report", "{path}/front.h5", "-o", "{out}.html"],
    ["analyse", "roads", "{path}/front.h5", "--road", "{path}/road.yaml", "-o", "{out}"],
    ["analyse", "masses", "{path}/front.h5", "-o", "{out}"],
    ["analyse", "builds", "{path}/front.h5", "--samples", "3", "-o", "{out}"],
    ["analyse", "builds", "{path}/choice.h5", "--pick", "chosen", "--samples", "3", "-o", "{out}"],
    [
        "analyse",
        "builds",
        "{path}/front.h5",
        "--samples",
        "3",
        "--batch",
        "C_F1,C_R1",
        "-o",
        "{out}",
    ],
    [
        "kesort",
        "{path}/front.h5",
        "--builds",
        "{path}/builds.h5",
        "--as-built",
        "95",
        "-o",
        "{out}",
    ],
    ["analyse", "models", "{path}/study.yaml", "{path}/study2.yaml"],
    ["analyse", "transmissibility", "{path}/front.h5"],
    ["analyse", "scenarios", "{path}/robust.h5"],
]


def option_fixtures(folder: Path) -> Path:
    """The inputs of :data:`OPTION_BASES` in ``folder``: the ``kesort`` starter config with a
    tiny budget, its front, the front's k-ε choice and builds, a robust front, a second
    config, a road config and a FIFO (made by ``python -m suspopt``, as a user would)."""
    folder.mkdir(parents=True, exist_ok=True)

    def suspopt(*args: str) -> None:
        done = subprocess.run(
            [sys.executable, "-m", "suspopt", "-q", *args],
            cwd=folder,
            capture_output=True,
            text=True,
            env=worker_env(),
        )
        if done.returncode != 0:
            raise RuntimeError(f"suspopt {' '.join(args)}: {done.stderr[-500:]}")

    budget = {"population": 8, "generations": 2}
    for kind, config, front in (("kesort", "study", "front"), ("robust", "robust", "robust")):
        suspopt("init", kind, "-o", f"{config}.yaml")
        text = (folder / f"{config}.yaml").read_text()
        for key, value in budget.items():
            text = re.sub(rf"(?m)^(\s+{key}:) \d+", rf"\1 {value}", text)
        (folder / f"{config}.yaml").write_text(text)
        suspopt("optimise", f"{config}.yaml", "-o", f"{front}.h5")
    suspopt("kesort", "front.h5", "-o", "choice.h5")
    suspopt("analyse", "builds", "front.h5", "--samples", "4", "-o", "builds.h5")
    (folder / "study2.yaml").write_text((folder / "study.yaml").read_text())
    (folder / "road.yaml").write_text((CONFIGS / "quickstart.yaml").read_text())
    os.mkfifo(folder / "fifo")
    return folder


def _value_slots(base: list[str]) -> list[tuple[str, int | None]]:
    """(label, index) of each positional argument of ``base`` that may be replaced."""
    start = 2 if base[0] == "analyse" else 1
    return [
        (f"argument {i}", i)
        for i in range(start, len(base))
        if not base[i].startswith("-") and not base[i - 1].startswith("-")
    ]


def option_cases(fixtures: Path, values: list[str] | None = None) -> list[Case]:
    """Every option that takes a value, of every command of :data:`OPTION_BASES`, and every
    positional argument, given each of ``values`` (default :data:`OPTION_VALUES`), one case
    each. The options are read from the command tree, so a new option is fuzzed as it comes."""
    import typer.main

    from suspopt.cli import app

    tree = typer.main.get_command(app)
    cases = []
    for b, base in enumerate(OPTION_BASES):
        command = tree.commands[base[0]]
        slots = [
            (param.opts[0], None)
            for param in command.params
            if param.param_type_name == "option" and not param.is_flag and not param.count
        ] + _value_slots(base)
        for slot, index in slots:
            for k, value in enumerate(OPTION_VALUES if values is None else values):
                argv = list(base)
                if index is None:
                    argv += [slot, value]
                else:
                    argv[index] = value
                cases.append(
                    Case(
                        # (the base's number: two bases may run one command)
                        id=_case_id("opt", f"{b:02d}", _command_name(base), slot, f"{k:02d}"),
                        family="options",
                        label=f"{' '.join(base[:2])} {slot} {short(value, 30)!r}",
                        setup={"kind": "folder", "path": str(fixtures)},
                        runs=[argv],
                        source=" ".join(base),
                        name="",  # (a message names the option or the file it is about)
                        dataset=None,
                    )
                )
    return cases


def _copy_folder(src: Path, dst: Path) -> None:
    """``src``'s files into the new folder ``dst``, a FIFO made anew (never read)."""
    dst.mkdir()
    for item in src.iterdir():
        if item.is_fifo():
            os.mkfifo(dst / item.name)
        else:
            (dst / item.name).write_bytes(item.read_bytes())


def _changed(src: Path, dst: Path) -> list[str]:
    """What differs in ``dst`` from ``src`` (:func:`_copy_folder`): new, lost or changed."""
    have = {p.name for p in dst.iterdir()}
    want = {p.name for p in src.iterdir()}
    out = [f"new {n}" for n in sorted(have - want)] + [f"lost {n}" for n in sorted(want - have)]
    for name in sorted(have & want):
        a, b = src / name, dst / name
        if a.is_fifo() != b.is_fifo() or (not a.is_fifo() and a.read_bytes() != b.read_bytes()):
            out.append(f"changed {name}")
    return out


# --- judging -------------------------------------------------------------------------------


#: ``optimise``'s progress line per generation, which goes to stderr when it is no terminal
#: (``cli/optimisation._progress_line``): not part of a message
PROGRESS = re.compile(r"^\S+ gen \d+(?:/\d+)?, \d+ evaluations, ")


def stderr_lines(text: str) -> list[str]:
    """The lines of a command's stderr that are messages (not blank, not progress)."""
    return [line for line in text.splitlines() if line.strip() and not PROGRESS.match(line)]


#: ``validate``'s last line for a config it refused: ``3 errors in FILE``, ``1 error and 1
#: warning in FILE``, ``25 errors in FILE (5 not shown: --max-errors 0 lists all)``
COUNT_LINE = re.compile(
    r"^(?P<errors>\d+) errors? (?:and (?P<warnings>\d+) warnings? )?in (?P<file>.+?)"
    r"(?: \((?P<hidden>\d+) not shown: --max-errors 0 lists all\))?$"
)


def report_problems(lines: list[str], name: str) -> list[str]:
    """What is wrong with ``validate``'s stderr ``lines`` for a config ``name`` it refused
    (empty when nothing is): one line per problem, ``error: ...`` or ``warning: ...``, each
    naming the file, then :data:`COUNT_LINE` naming it, whose counts are those lines'."""
    if len(lines) < 2:
        return [f"{len(lines)} lines: no problem and count"]
    *listed, last = lines
    found = [
        f"not a problem line: {line[:200]}"
        for line in listed
        if not line.startswith(("error: ", "warning: "))
    ]
    found += [f"does not name the file: {line[:200]}" for line in listed if name not in line]
    count = COUNT_LINE.match(last)
    if count is None or name not in count["file"]:
        return found + [f"not a count naming the file: {last[:200]}"]
    errors = sum(line.startswith("error: ") for line in listed)
    warnings = sum(line.startswith("warning: ") for line in listed)
    if errors == 0 or int(count["errors"]) != errors + int(count["hidden"] or 0):
        found.append(f"{errors} error lines, counted as {last[:200]}")
    if int(count["warnings"] or 0) != warnings:
        found.append(f"{warnings} warning lines, counted as {last[:200]}")
    return found


def names_dataset(line: str, dataset: str) -> bool:
    """Whether an error line names ``dataset``: ``/pareto/F`` itself, or ``/pareto`` with
    the letter ``F`` (``/pareto: X, F and G have 8, 0 and 8 rows``)."""
    if dataset in line:
        return True
    group, _, leaf = dataset.rpartition("/")
    return bool(group) and group in line and re.search(rf"\b{re.escape(leaf)}\b", line)


def problems(case: Case, result: dict) -> list[dict]:
    """Every breach of the contract in ``result`` (the worker's answer to ``case``): dicts
    with ``category``, ``command`` and the details of the cause."""
    found = []
    if "fatal" in result:
        running = result.get("detail", "").split(" | ")[0]
        return [
            {
                "category": result["fatal"],
                "command": f"(worker) {running}",
                "exc": "",
                "where": "",
                "message": result.get("detail", ""),
                "seconds": result.get("seconds", 0.0),
            }
        ]
    for run in result["runs"]:
        cmd = run["command"]
        if run.get("skipped"):
            continue

        def add(category, cmd=cmd, run=run, **more):
            found.append(
                {
                    "category": category,
                    "command": cmd,
                    "exc": run.get("exc", ""),
                    "where": run.get("where", ""),
                    "message": run.get("exc_msg", ""),
                    "seconds": run["seconds"],
                    **more,
                }
            )

        if run["timeout"]:
            add("time-out")
            continue
        code = run["exit"]
        if code not in (0, 2) + WRITERS.get(cmd, ()):
            add(f"exit {code}" + (" (traceback)" if run.get("exc") else ""))
            continue
        if "Traceback" in run["stderr"] or "Traceback" in run["stdout"]:
            add("traceback in the output")
        if run.get("changed"):  # (an option case: a refused command changed its inputs)
            add("refused, but changed the inputs", stderr="; ".join(run["changed"])[:300])
        if code == 2 and cmd == "validate" and case.family == "config":
            for breach in report_problems(stderr_lines(run["stderr"]), case.name):
                add("validate's report: " + breach, stderr=run["stderr"][:600])
        elif code == 2:
            if run["stderr_lines"] != 1:
                add(
                    f"exit 2 with {run['stderr_lines']} lines on stderr", stderr=run["stderr"][:600]
                )
                continue
            line = stderr_lines(run["stderr"])[0]
            if case.name not in line:
                add("message does not name the file", stderr=line[:300])
            if case.dataset and not names_dataset(line, case.dataset):
                add(f"message does not name {case.dataset}", stderr=line[:300])
    runs = {r["command"]: r for r in result["runs"]}
    v = runs.get("validate")
    for command in WRITERS:
        s = runs.get(command)
        if not (v and s) or v["timeout"] or v["exit"] != 0 or s["timeout"] or s.get("skipped"):
            continue
        message = (stderr_lines(s["stderr"]) or [""])[0]
        if s["exit"] == 2 and any(text in message for text in NOT_FOR.get(command, ())):
            continue
        if s["exit"] not in WRITERS[command]:
            found.append(
                {
                    "category": f"validate accepts, {command} rejects",
                    "command": command,
                    "exc": s.get("exc", ""),
                    "where": s.get("where", ""),
                    "message": s.get("exc_msg") or message,
                    "seconds": s["seconds"],
                }
            )
        elif not s.get("written"):
            found.append(
                {
                    "category": f"{command} exit 0 but no HDF5 written",
                    "command": command,
                    "exc": "",
                    "where": "",
                    "message": "",
                    "seconds": s["seconds"],
                }
            )
    return found


def describe(case: Case, result: dict, found: list[dict]) -> str:
    """A failure report for pytest: the case, how to reproduce it, and each problem."""
    lines = [f"case {case.id}: {case.label} (from {case.source})"]
    setup = case.setup
    if setup["kind"] == "text":
        t = setup["text"]
        lines.append("input (YAML, first 600 chars): " + repr(t[:600]))
    elif setup["kind"] == "bytes":
        lines.append("input (bytes, first 200): " + repr(base64.b64decode(setup["b64"])[:200]))
    else:
        lines.append(f"input: {setup}")
    for p in found:
        lines.append(
            f"- {p['command']}: {p['category']}"
            + (f": {p['exc']}: {p['message'][:300]}" if p.get("exc") else "")
            + (f" at {p['where']}" if p.get("where") else "")
            + (f"; stderr: {p['stderr']!r}" if p.get("stderr") else "")
        )
    return "\n".join(lines)


def signature(p: dict) -> tuple:
    """What groups problems by cause: the category, the exception and where it was raised."""
    return (p["category"], p.get("exc", ""), p.get("where", ""))


# --- running cases: the pool (parent side) -------------------------------------------------


def worker_env() -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = str(ROOT) + (
        os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else ""
    )
    for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        env[var] = "1"
    env["COLUMNS"] = "80"
    env.pop("FORCE_COLOR", None)
    return env


class Worker:
    """One worker process (``python tests/fuzz_harness.py --worker``), restarted when it
    dies or is killed."""

    def __init__(self, folder: Path, index: int, memory: int, limit: float):
        self.folder, self.index, self.memory, self.limit = folder, index, memory, limit
        self.proc: subprocess.Popen | None = None
        self.buffer = b""
        self.starts = 0

    def start(self) -> None:
        work = self.folder / f"w{self.index}-{self.starts}"
        work.mkdir(parents=True, exist_ok=True)
        self.log = open(work / "stderr.log", "wb")  # noqa: SIM115  (closed with the worker)
        self.proc = subprocess.Popen(
            [
                sys.executable,
                str(HARNESS),
                "--worker",
                "--folder",
                str(work),
                "--memory",
                str(self.memory),
                "--limit",
                str(self.limit),
            ],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=self.log,
            cwd=ROOT,
            env=worker_env(),
        )
        self.buffer = b""
        self.starts += 1
        ready = self._read(300.0)  # (a cold kernel cache: the kernel compiles first)
        if ready is None or json.loads(ready).get("ready") is not True:
            raise RuntimeError(f"fuzz worker did not start: {self._log_tail()}")

    def _log_tail(self) -> str:
        try:
            self.log.flush()
            return Path(self.log.name).read_text(errors="replace")[-2000:]
        except OSError:
            return ""

    def _read(self, timeout: float) -> str | None:
        """One line from the worker, or None on time-out or end of file."""
        deadline = time.monotonic() + timeout
        fd = self.proc.stdout.fileno()
        while b"\n" not in self.buffer:
            left = deadline - time.monotonic()
            if left <= 0:
                return None
            ready, _, _ = select.select([fd], [], [], left)
            if not ready:
                continue
            chunk = os.read(fd, 1 << 20)
            if not chunk:
                return None
            self.buffer += chunk
        line, self.buffer = self.buffer.split(b"\n", 1)
        return line.decode()

    def stop(self) -> None:
        if self.proc is not None and self.proc.poll() is None:
            try:
                self.proc.stdin.close()
                self.proc.wait(timeout=10)
            except (OSError, subprocess.TimeoutExpired):
                self.proc.kill()
                self.proc.wait()
        if self.proc is not None:
            self.log.close()
        self.proc = None

    def kill(self) -> None:
        if self.proc is not None:
            if self.proc.poll() is None:
                os.kill(self.proc.pid, signal.SIGKILL)
            self.proc.wait()
            self.log.close()
        self.proc = None

    def run(self, case: Case) -> dict:
        if self.proc is None or self.proc.poll() is not None:
            self.start()
        started = time.monotonic()
        try:
            self.proc.stdin.write(case.to_json().encode() + b"\n")
            self.proc.stdin.flush()
        except BrokenPipeError:
            self.kill()
            return {"fatal": "worker died", "detail": "broken pipe", "seconds": 0.0}
        line = self._read(self.limit * len(case.runs) + HARD_GRACE)
        if line is None:
            alive = self.proc.poll() is None
            code = self.proc.returncode
            tail = _last_running(self._log_tail())
            self.kill()
            if alive:
                return {
                    "fatal": "killed after the hard time limit (stuck outside Python)",
                    "detail": tail,
                    "seconds": time.monotonic() - started,
                }
            how = (
                f"signal {signal.Signals(-code).name}"
                if code is not None and code < 0
                else f"exit {code}"
            )
            return {
                "fatal": f"worker crashed ({how})",
                "detail": tail,
                "seconds": time.monotonic() - started,
            }
        return json.loads(line)


def _last_running(log: str) -> str:
    """The command a worker was running (its log's last 'running' line) and the log's tail."""
    lines = [line for line in log.splitlines() if ": running " in line]
    return (lines[-1].split(": running ", 1)[1] if lines else "?") + " | log: " + log[-300:]


def selected_case_ids(request) -> set[str]:
    """The ids of the ``case`` parameters of the requesting module's collected tests (all of
    them unless ``-k`` deselected some), so that its module fixture runs only those."""
    return {
        item.callspec.params["case"].id
        for item in request.session.items
        if getattr(item, "callspec", None)
        and "case" in item.callspec.params
        and item.module is request.module
    }


def run_cases(
    cases: list[Case],
    workers: int | None = None,
    memory: int = MEMORY,
    limit: float = LIMIT,
    progress=None,
) -> dict[str, dict]:
    """Run ``cases`` on ``workers`` worker processes (default: the CPU count, at most 2 unless
    ``SUSPOPT_FUZZ_WORKERS`` says otherwise); {case id: result}."""
    if workers is None:
        workers = int(os.environ.get("SUSPOPT_FUZZ_WORKERS", min(2, os.cpu_count() or 1)))
    ids = [case.id for case in cases]
    if len(set(ids)) != len(ids):  # (results are kept by id: one would hide the other)
        twice = sorted({i for i in ids if ids.count(i) > 1})
        raise ValueError(f"{len(twice)} case ids given twice, e.g. {twice[:3]}")
    todo: queue.Queue = queue.Queue()
    for case in cases:
        todo.put(case)
    results: dict[str, dict] = {}
    lock = threading.Lock()
    errors: list[BaseException] = []
    with tempfile.TemporaryDirectory(prefix="suspopt-fuzz-") as folder:
        pool = [Worker(Path(folder), i, memory, limit) for i in range(max(1, workers))]

        def loop(worker: Worker) -> None:
            try:
                while True:
                    try:
                        case = todo.get_nowait()
                    except queue.Empty:
                        return
                    result = worker.run(case)
                    with lock:
                        results[case.id] = result
                        if progress is not None:
                            progress(case, result, len(results))
            except BaseException as exc:  # noqa: BLE001 - reported below
                errors.append(exc)
            finally:
                worker.stop()

        threads = [threading.Thread(target=loop, args=(w,), daemon=True) for w in pool]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
    if errors:
        raise errors[0]
    return results


# --- the worker ------------------------------------------------------------------------------


class CaseTimeout(BaseException):
    """Raised by SIGALRM when a command runs past the time limit."""


def _alarm(signum, frame):
    raise CaseTimeout()


def _where(tb) -> str:
    """``file:function:line`` of the innermost frame in suspopt (and of the innermost frame
    overall when that is elsewhere, e.g. in yaml or numpy)."""
    frames = [
        f
        for f in traceback.extract_tb(tb)
        if "fuzz_harness" not in f.filename
        and "/click/" not in f.filename
        and "/typer/" not in f.filename
    ]
    if not frames:
        return ""

    def fmt(f):
        path = f.filename
        if f"{os.sep}suspopt{os.sep}" in path:
            path = "suspopt/" + path.rsplit(f"{os.sep}suspopt{os.sep}", 1)[1]
        elif "site-packages/" in path:
            path = path.split("site-packages/", 1)[1]
        else:
            path = re.sub(r"^.*/lib/python3\.\d+/", "", path)
        return f"{path}:{f.name}:{f.lineno}"

    own = [
        f
        for f in frames
        if f"{os.sep}suspopt{os.sep}" in f.filename and "fuzz_harness" not in f.filename
    ]
    last = frames[-1]
    if own and own[-1] is not last:
        return f"{fmt(own[-1])} -> {fmt(last)}"
    return fmt(last)


def _make_input(setup: dict, path: Path) -> None:
    kind = setup["kind"]
    if kind == "text":
        path.write_text(setup["text"], encoding="utf-8", errors="surrogatepass")
    elif kind == "bytes":
        path.write_bytes(base64.b64decode(setup["b64"]))
    elif kind == "dir":
        path.mkdir()
    elif kind == "fifo":
        os.mkfifo(path)
    elif kind == "symlink":
        os.symlink(path if setup["target"] == "self" else setup["target"], path)
    elif kind == "missing":
        pass
    elif kind == "folder":
        _copy_folder(Path(setup["path"]), path)
    else:
        raise ValueError(kind)


def _clear(folder: Path) -> None:
    for item in sorted(folder.rglob("*"), key=lambda p: -len(p.parts)):
        if item.is_dir() and not item.is_symlink():
            item.rmdir()
        else:
            item.unlink()
    folder.rmdir()


def worker_main(folder: Path, memory: int, limit: float, skip_after_timeout: bool = True) -> None:
    """Serve cases: one JSON case per line on stdin, one JSON result per line on stdout."""
    import resource

    proto = os.fdopen(os.dup(1), "w", buffering=1)
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)  # anything written to fd 1 by C code is dropped
    sys.setrecursionlimit(max(sys.getrecursionlimit(), 1000))
    # scipy.signal (the weightings' sosfilt) now: an import cut short by a case's alarm
    # would leave a half-made module behind for every later case
    import h5py
    import scipy.signal  # noqa: F401
    from conftest import build_commands_once
    from typer.testing import CliRunner

    import suspopt.analyse
    import suspopt.choosing.selection  # noqa: F401
    import suspopt.optimisation  # noqa: F401 - imported before the clock starts
    import suspopt.simulation  # noqa: F401
    from suspopt.cli import app

    suspopt.analyse.analysis_kinds()
    build_commands_once()
    _compile_the_kernel()

    if memory > 0:
        soft, hard = resource.getrlimit(resource.RLIMIT_AS)
        resource.setrlimit(resource.RLIMIT_AS, (memory, hard))
    signal.signal(signal.SIGALRM, _alarm)
    runner = CliRunner()
    proto.write(json.dumps({"ready": True, "pid": os.getpid()}) + "\n")
    n = 0
    for line in sys.stdin:
        if not line.strip():
            continue
        case = json.loads(line)
        n += 1
        work = folder / f"c{n}"
        work.mkdir()
        try:
            if case["setup"]["kind"] == "existing":
                path = Path(case["setup"]["path"])
            else:
                path = work / (case["name"] or "inputs")
                _make_input(case["setup"], path)
            out = work / "out.h5"
            runs = []
            for argv in case["runs"]:
                args = [a.replace("{path}", str(path)).replace("{out}", str(out)) for a in argv]
                if skip_after_timeout and any(r["timeout"] for r in runs):
                    # the case has failed already; spare the budget another time-out
                    runs.append(
                        {
                            "command": _command_name(args),
                            "argv": args,
                            "skipped": True,
                            "timeout": False,
                            "exit": None,
                            "seconds": 0.0,
                            "stdout": "",
                            "stderr": "",
                        }
                    )
                    continue
                # the log says which command was running if the worker has to be killed
                sys.stderr.write(f"case {case['id']}: running {_command_name(args)}\n")
                sys.stderr.flush()
                entry = case["family"] == "options"  # (usage errors: worded by the entry)
                home = os.getcwd()
                if entry:  # (a relative name given as a value lands in the case's folder)
                    os.chdir(path)
                try:
                    runs.append(_invoke(runner, app, args, limit, out, h5py, entry))
                finally:
                    os.chdir(home)
                done = runs[-1]  # (optimise's exit 3 writes its file all the same)
                if case["setup"]["kind"] == "folder" and done["exit"] not in (0, 3):
                    done["changed"] = _changed(Path(case["setup"]["path"]), path)
                if out.exists():
                    out.unlink()
            answer = {"id": case["id"], "runs": runs}
        except BaseException as exc:  # noqa: BLE001 - a harness error, reported
            signal.setitimer(signal.ITIMER_REAL, 0)
            answer = {
                "id": case["id"],
                "fatal": "harness error in the worker",
                "detail": "".join(traceback.format_exception(exc))[-1500:],
            }
        with contextlib.suppress(OSError):
            _clear(work)
        proto.write(json.dumps(answer) + "\n")


def _compile_the_kernel() -> None:
    """Run the compiled engine once before the clock starts (where numba is installed): its
    first call on a fresh checkout compiles the kernel (seconds), which a case's 3 s budget
    must not pay (a config with ``engine: auto`` or ``compiled`` would time out)."""
    import suspopt
    from suspopt.integrator import compiled_available

    if not compiled_available():
        return
    # passive over a bump, semi-active SH-2 over a bump, ADD (it reads accelerations) on a
    # random road (the kernel takes their samples), SH-ADD-2 with an adaptive threshold (the
    # controller takes them, between compiled stretches): every compiled function runs once
    names = ("quickstart.yaml", "ch3/part1b_qc_bump.yaml", "ch7/add.yaml", "ch7/sh_add_2_cdf.yaml")
    for name in names:
        cfg = suspopt.load_config(ROOT / "configs" / name)
        cfg.simulation.engine = "compiled"
        if cfg.road.kind.startswith("bump"):
            cfg.road.start = 0.01  # early in the short run
        cfg.simulation.duration = 0.1
        suspopt.simulate(cfg)
    # an optimisation's evaluation (streamed: the kernel's own reductions of the objectives);
    # a batch of one design takes the specialisations of any other batch
    cfg = suspopt.load_config(ROOT / "configs" / "ch5" / "case1_s1.yaml")
    cfg.road.start, cfg.simulation.duration = 0.01, 0.1
    problem = suspopt.Problem.from_config(cfg)
    problem.evaluate(((problem.xl + problem.xu) / 2)[None], return_values_of=["F", "G"])
    # the streamed reductions' loops (suspopt.loops._compiled), as an evaluation calls them
    from suspopt.metrics.iso2631 import power_state, weighting_filter
    from suspopt.metrics.stats import moments

    x = np.ones((2, 300))
    weighting_filter("Wk", 1000.0).apply(x)
    moments(x)
    power_state(x)


def _command_name(args: list[str]) -> str:
    if args[0] == "analyse":
        return f"analyse {args[1]}" + (" --road B" if "--road" in args else "")
    return args[0]


def _clip(text: str, head: int = 3000, tail: int = 1000) -> str:
    return text if len(text) <= head + tail else text[:head] + " [...] " + text[-tail:]


def _through_entry(runner, args):
    """``suspopt._entry.main(args)``, the command line's own entry point, in the runner's
    isolation: a :class:`typer.testing.Result`. The option cases run through it, since it
    words click's usage errors (a bad option value) as the one line a user sees, where
    ``runner.invoke`` would print click's box."""
    from typer.testing import Result

    from suspopt._entry import main

    exception, exc_info, code = None, None, 1
    with runner.isolation() as streams:
        try:
            code = main(list(args))
        except Exception as exc:  # noqa: BLE001 - a bug, reported as invoke reports it
            exception, exc_info = exc, sys.exc_info()
        finally:
            sys.stdout.flush()
            sys.stderr.flush()
            stdout, stderr, output = (stream.getvalue() for stream in streams)
    return Result(
        runner=runner,
        stdout_bytes=stdout,
        stderr_bytes=stderr,
        output_bytes=output,
        return_value=None,
        exit_code=code,
        exception=exception,
        exc_info=exc_info,
    )


def _invoke(runner, app, args, limit, out, h5py, entry: bool = False) -> dict:
    record = {
        "command": _command_name(args),
        "argv": args,
        "timeout": False,
        "exit": None,
        "stdout": "",
        "stderr": "",
        "exc": "",
        "exc_msg": "",
        "where": "",
    }
    started = time.perf_counter()
    signal.setitimer(signal.ITIMER_REAL, limit)
    try:
        if entry:
            result = _through_entry(runner, args)
        else:
            result = runner.invoke(app, args, catch_exceptions=True)
        signal.setitimer(signal.ITIMER_REAL, 0)
    except CaseTimeout as exc:
        record["timeout"] = True
        record["exc"] = "time-out"
        record["where"] = _where(exc.__traceback__)
    except MemoryError as exc:  # raised outside the runner's catch (in its isolation)
        signal.setitimer(signal.ITIMER_REAL, 0)
        record["exit"] = 1
        record["exc"] = "MemoryError"
        record["where"] = _where(exc.__traceback__)
    else:
        record["exit"] = result.exit_code
        record["stdout"] = _clip(result.stdout)
        record["stderr"] = _clip(result.stderr)
        record["stderr_lines"] = len(stderr_lines(result.stderr))
        exc = result.exception
        if exc is not None and not isinstance(exc, SystemExit):
            record["exc"] = type(exc).__name__
            record["exc_msg"] = str(exc)[:500].replace("\n", " ")
            tb = result.exc_info[2] if result.exc_info else None
            record["where"] = _where(tb)
            record["traceback"] = "".join(traceback.format_exception(exc))[-3000:]
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
    record["seconds"] = time.perf_counter() - started
    if record["command"] in WRITERS and record["exit"] in WRITERS[record["command"]]:
        try:
            record["written"] = out.is_file() and h5py.is_hdf5(out)
        except OSError:
            record["written"] = False
    return record


if __name__ == "__main__":
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--worker", action="store_true", required=True)
    parser.add_argument("--folder", type=Path, required=True)
    parser.add_argument("--memory", type=int, default=MEMORY)
    parser.add_argument("--limit", type=float, default=LIMIT)
    parser.add_argument(
        "--all-after-timeout",
        action="store_true",
        help="run a case's remaining commands after one timed out",
    )
    opts = parser.parse_args()
    worker_main(opts.folder, opts.memory, opts.limit, not opts.all_after_timeout)
