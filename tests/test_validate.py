"""``suspopt validate`` lists every problem of a config, located and in the user's terms
(issue 59, item 3): pydantic's wording never reaches the user, "did you mean" names each
suggestion once, and a value that looks like a slip of units says so."""

from __future__ import annotations

import copy
import pickle
import re
import string
import tempfile
from pathlib import Path

import pytest
from conftest import CONFIGS, write
from fuzz_harness import report_problems, walk
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import suspopt
from suspopt._entry import main
from suspopt.config.loader import load_config_text
from suspopt.config.plausible import PLAUSIBLE, SAME_UNIT_METRICS, check_plausible
from suspopt.config.yamlio import parse_yaml
from suspopt.errors import ConfigError, Problem

QUICKSTART = (CONFIGS / "quickstart.yaml").read_text()
#: A line of validate's report: severity, file, line, key path, message (no line for a key
#: absent with every key above it: ``case.yaml: road: required key is missing``).
LINE = re.compile(
    r"^(?P<severity>error|warning): (?P<file>.+?\.yaml)(?::(?P<line>\d+))?: "
    r"(?P<key>[A-Za-z_][\w.]*(?:\[\d+\][\w.]*)*): (?P<message>\S.*)$"
)
#: pydantic's own wording, which must never reach the user.
PYDANTIC = (
    "Input should",
    "Field required",
    "Extra inputs",
    "type=",
    "For further information",
    "errors.pydantic.dev",
    "Value error,",
    "Input tag",
    "valid dictionary",
    "instance of",
    "String should",
    "literal[",
    "function-after",
    "pydantic",
)


def cli(capsys, *args) -> tuple[int, str, str]:
    code = main([str(a) for a in args])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def edited(*pairs: tuple[str, str], text: str = QUICKSTART) -> str:
    for old, new in pairs:
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    return text


def parsed(err: str) -> list[re.Match]:
    """The problem lines of validate's stderr, each matched (the count line left out)."""
    *lines, _ = err.strip().splitlines()
    matched = [LINE.match(line) for line in lines]
    assert all(matched), lines
    return matched


THREE = edited(
    ("body: {mass: 2210,", "body: {mass: 1.2,"),
    ("kind: bump_half_sine", "kind: bumpp"),
    ("dt: 1.0e-3}", "dt: fast}"),
)


def test_three_errors_are_three_located_lines_and_their_count(tmp_path, capsys):
    path = write(tmp_path, THREE)
    code, out, err = cli(capsys, "validate", path)
    assert code == 2 and out == "" and "Traceback" not in err
    found = parsed(err)
    assert [(m["line"], m["key"]) for m in found] == [
        ("6", "vehicle.body.mass"),
        ("19", "road.kind"),
        ("24", "simulation.dt"),
    ]
    assert {m["file"] for m in found} == {str(path)}
    assert err.strip().splitlines()[-1] == f"3 errors in {path}"
    assert "tonnes" in found[0]["message"] and "expected a number (got 'fast')" in err


def test_max_errors_shows_as_many_and_says_how_many_more(tmp_path, capsys):
    path = write(tmp_path, THREE)
    code, _, err = cli(capsys, "validate", "--max-errors", "1", path)
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 2, err
    assert lines[0].startswith(f"error: {path}:6: vehicle.body.mass: ")
    assert lines[1] == f"3 errors in {path} (2 not shown: --max-errors 0 lists all)"
    code, _, err = cli(capsys, "validate", "--max-errors", "0", path)
    assert len(err.strip().splitlines()) == 4
    code, _, err = cli(capsys, "validate", "--max-errors", "-1", path)
    assert code == 2 and err.strip().splitlines() == [
        "error: --max-errors -1: give how many errors to list, or 0 for all of them"
    ]


def test_other_commands_say_the_first_problem_and_how_many_more(tmp_path, capsys):
    path, out = write(tmp_path, THREE), tmp_path / "out.h5"
    code, _, err = cli(capsys, "simulate", path, "-o", out)
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1, err
    assert lines[0].startswith(f"error: {path}:6: vehicle.body.mass: 1.2 kg ")
    assert lines[0].endswith(f"(+2 more: run suspopt validate {path})")
    assert not out.exists()
    with pytest.raises(ConfigError) as caught:  # the library: every problem, one message
        suspopt.load_config(path)
    assert len(caught.value.problems) == 3 and "\n" not in str(caught.value)


def test_a_misspelt_road_kind_is_said_plainly_with_one_suggestion(tmp_path, capsys):
    path = write(tmp_path, edited(("kind: bump_half_sine", "kind: bumpp")))
    code, _, err = cli(capsys, "validate", path)
    assert code == 2
    assert err.splitlines()[0] == (
        f"error: {path}:19: road.kind: unknown road kind 'bumpp'; expected one of bump_step, "
        "bump_half_sine, iso8608, file (did you mean 'bump_step'?)"
    )
    code, _, err = cli(
        capsys, "validate", write(tmp_path, edited(("preset: half_pitch", "preset: halfpitch")))
    )
    assert (
        "unknown preset 'halfpitch'; expected one of quarter, half_roll, half_pitch, full " in err
    )
    assert "(did you mean 'half_pitch'?)" in err


def test_did_you_mean_names_each_suggestion_once(tmp_path, capsys):
    """A per-corner family was suggested once per corner (``travel, travel.R1, travel.R1``)."""
    text = (
        QUICKSTART
        + "metrics: [{metric: rms, signal: travl}, {metric: rms, signal: body.heave_ac}]\n"
    )
    code, _, err = cli(capsys, "validate", write(tmp_path, text))
    assert code == 2
    suggestions = re.findall(r"did you mean ([^?]+)\?", err)
    assert len(suggestions) == 2, err
    for said in suggestions:
        names = [n.strip() for n in said.split(",")]
        assert len(names) == len(set(names)), said


@pytest.mark.parametrize(
    "pairs, key, hint, severity",
    [
        (
            (("mass: 2210,", "mass: 1.2,"),),
            "vehicle.body.mass",
            "looks like tonnes (1.2 t = 1200 kg)?",
            "error",
        ),
        (
            (("mass: 2210,", "mass: 20,"),),
            "vehicle.body.mass",
            "looks like tonnes (20 t = 20000 kg)?",
            "warning",
        ),
        (
            (("unsprung_mass: 50", "unsprung_mass: 0.05"),),
            "vehicle.corners.F1.unsprung_mass",
            "looks like tonnes (0.05 t = 50 kg)?",
            "error",
        ),
        (
            (("a_front: 1.61", "a_front: 1610"),),
            "vehicle.body.a_front",
            "looks like mm (1610 mm = 1.61 m)?",
            "error",
        ),
        (
            (("height: 0.05 ", "height: 50 "),),
            "road.height",
            "looks like mm (50 mm = 0.05 m)?",
            "error",
        ),
        (
            (("length: 1.0 ", "length: 1000 "),),
            "road.length",
            "looks like mm (1000 mm = 1 m)?",
            "warning",
        ),
        (
            (("speed: 11.111", "speed: 72"),),
            "road.speed",
            "looks like km/h (72 km/h = 20 m/s)?",
            "warning",
        ),
        (
            (("speed: 11.111", "speed: 250"),),
            "road.speed",
            "looks like km/h (250 km/h = 69.4444 m/s)?",
            "error",
        ),
    ],
)
def test_a_value_in_another_unit_gets_its_hint(tmp_path, capsys, pairs, key, hint, severity):
    path = write(tmp_path, edited(*pairs))
    code, out, err = cli(capsys, "validate", path)
    lines = [m for m in map(LINE.match, err.strip().splitlines()) if m]
    assert [(m["severity"], m["key"]) for m in lines] == [(severity, key)], err
    assert lines[0]["message"].endswith(hint), err
    assert code == (2 if severity == "error" else 0)
    if severity == "warning":  # nothing refused: the config is valid, and runs
        assert out.strip() == f"{path}: valid (half_pitch, road bump_half_sine)"


def test_a_body_in_tonnes_is_said_so_not_as_a_time_step(tmp_path, capsys):
    """A body of 1.2 kg on its springs has a mode RK4's 1 ms step cannot follow: it was
    reported as ``simulation.dt`` exceeding the stability limit. The config's values are
    checked before the run's, and a value absurd for a road vehicle stops the checks that
    derive from it."""
    path = write(tmp_path, edited(("mass: 2210,", "mass: 1.2,")))
    for args in (("validate", path), ("simulate", path, "-o", tmp_path / "o.h5")):
        code, _, err = cli(capsys, *args)
        assert code == 2 and "simulation.dt" not in err and "stability" not in err, err
        assert f"{path}:6: vehicle.body.mass: 1.2 kg is less than any road vehicle's" in err


def test_a_warning_rejects_nothing_that_simulate_then_runs(tmp_path, capsys):
    path = write(
        tmp_path, edited(("speed: 11.111", "speed: 40"), ("duration: 3.0", "duration: 1.0"))
    )
    assert cli(capsys, "validate", path)[0] == 0  # (40 m/s: plausible, no warning)
    path = write(
        tmp_path, edited(("speed: 11.111", "speed: 72"), ("duration: 3.0", "duration: 1.0"))
    )
    code, out, err = cli(capsys, "validate", path)
    assert code == 0 and err.startswith("warning: ") and "valid" in out
    code, _, err = cli(capsys, "simulate", path, "-o", tmp_path / "o.h5")
    assert code == 0 and (tmp_path / "o.h5").is_file(), err
    assert suspopt.load_config(path).warnings[0].key == "road.speed"


def test_bounds_and_scenarios_are_judged_as_the_values_they_set():
    data, _ = parse_yaml(
        QUICKSTART
        + "design_variables: [{path: vehicle.body.mass, lower: 0.8, upper: 1.5}]\n"
        + "scenarios: {cases: [{name: fast, set: {road.speed: 90}}]}\n"
        + "constraints: [{metric: max_abs, signal: travel, max: 130}, {metric: var, signal: travel, max: 130}]\n"
    )
    found = {(".".join(map(str, loc)), severity) for loc, severity, _ in check_plausible(data)}
    assert found == {
        ("design_variables.0.lower", "error"),
        ("design_variables.0.upper", "error"),
        ("scenarios.cases.0.set.road.speed", "warning"),
        ("constraints.0.max", "warning"),  # (var is in m^2: no travel limit in m)
    }


def test_the_travel_limit_metrics_are_those_in_the_signals_unit():
    from suspopt.specs import METRICS

    assert {name for name, m in METRICS.items() if m.unit("m") == "m"} == SAME_UNIT_METRICS


def test_every_entry_of_the_table_is_consistent():
    """Each entry's slips explain values outside its range only, its error limits lie
    outside its plausible range, and every path names a key the config has."""
    from suspopt.config.messages import _place

    for entry in PLAUSIBLE:
        assert 0 <= entry.low < entry.high, entry.what
        assert entry.error_below is None or entry.error_below < entry.low
        assert entry.error_above is None or entry.error_above > entry.high
        assert entry.hint((entry.low + entry.high) / 2) is None
        for pattern in entry.paths:
            place = _place(suspopt.Config, tuple("F1" if p == "*" else p for p in pattern))
            if "corner_defaults" not in pattern and "constraints" not in pattern:
                assert place.field is not None, pattern


def test_union_members_are_one_message_in_the_users_terms():
    with pytest.raises(ConfigError) as caught:
        load_config_text(QUICKSTART + "output: {signals: 3}\n")
    assert caught.value.problems[0].key == "output.signals"
    assert caught.value.problems[0].message == "expected a list or text (got 3)"


def test_a_config_error_keeps_its_problems_between_processes():
    exc = ConfigError(
        problems=[Problem("a.yaml", 3, "road.kind", "bad"), Problem("a.yaml", 4, "x", "worse")],
        hint="run suspopt validate a.yaml",
    )
    again = pickle.loads(pickle.dumps(exc))
    assert again.problems == exc.problems and str(again) == str(exc)
    assert str(exc) == "a.yaml:3: road.kind: bad (+1 more: run suspopt validate a.yaml)"


def test_many_errors_of_every_kind_keep_pydantics_words_out(tmp_path, capsys):
    text = edited(
        ("preset: half_pitch", "preset: [half, pitch]"),
        ("pitch_inertia: 1142", "pitch_inertia: '1142'"),
        ("a_front: 1.61", "a_front: .inf"),
        ("unsprung_mass: 50", "unsprung_mas: 50"),
        ("damper: {c: 3000}", "damper: {c: 3000, kind: pasive}"),
        ("tyre: {stiffness: 8.0e5}", "tyre: {stiffness: true}"),
        ("start: 0.5 ", "start: -1 "),
    ) + (
        "metrics: [notamapping, {metric: 3, signal: body.heave}]\n"
        "optimiser: {algorithm: nsga2, population: 0, generations: 2.5, seed: 1}\n"
        "objectives: {main: [], supplementary: {a: 1}}\n"
        "scenarios: {cases: [{name: a/b}], product: 3}\n"
        "seat: {kind: ps}\n"
    )
    code, _, err = cli(capsys, "validate", "--max-errors", "0", write(tmp_path, text))
    assert code == 2
    found = parsed(err)
    assert len(found) >= 15, err
    for phrase in PYDANTIC:
        assert phrase not in err, phrase


# --- fuzz: random mutations of bundled configs ----------------------------------------------

FUZZED = ["quickstart.yaml", "ch7/sh_2.yaml", "ch8/pareto_ps_class_a.yaml"]
_SEEDS = {name: parse_yaml((CONFIGS / name).read_text())[0] for name in FUZZED}
_WORDS = st.text(string.ascii_lowercase + "_", min_size=1, max_size=10)
_VALUES = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-(10**6), 10**25),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0, -1, 1e-9, 1e9, 1.2, 2700, 72, 0.05]),
    _WORDS,
    st.lists(st.integers(0, 5), max_size=2),
    st.dictionaries(st.sampled_from(["kind", "c", "mass", "x"]), st.integers(0, 9), max_size=2),
)
_MUTATION = st.tuples(
    st.sampled_from(["set", "delete", "rename", "add", "scale"]),
    st.integers(0, 10**6),
    _VALUES,
    _WORDS,
    st.sampled_from([1e3, 1e-3, 3.6, 1 / 3.6, -1.0]),
)


def _mutate(data: dict, mutation) -> None:
    op, which, value, word, factor = mutation
    paths = [path for path, _ in walk(data)]
    if not paths:
        return
    path = paths[which % len(paths)]
    parent = data
    for key in path[:-1]:
        parent = parent[key]
    key = path[-1]
    if op == "set":
        parent[key] = value
    elif op == "delete":
        del parent[key]
    elif op == "rename" and isinstance(parent, dict):
        parent[f"{key}{word}" if which % 2 else word] = parent.pop(key)
    elif op == "add" and isinstance(parent[key], dict):
        parent[key][word] = value
    elif (
        op == "scale"
        and isinstance(parent[key], (int, float))
        and not isinstance(parent[key], bool)
    ):
        parent[key] = parent[key] * factor


@pytest.mark.slow
@settings(
    max_examples=150,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(source=st.sampled_from(FUZZED), mutations=st.lists(_MUTATION, min_size=1, max_size=4))
def test_validate_of_any_mutated_config_is_lines_in_the_users_terms(capsys, source, mutations):
    """Never a traceback; exit 0 or 2; every line of the report ``error|warning: FILE:LINE:
    KEY: message`` with a line of the file, then the count; never pydantic's words."""
    import yaml

    data = copy.deepcopy(_SEEDS[source])
    for mutation in mutations:
        _mutate(data, mutation)
    text = yaml.safe_dump(data, sort_keys=False, allow_unicode=True)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "case.yaml"
        path.write_text(text)
        code, out, err = cli(capsys, "validate", "--max-errors", "0", path)
    assert code in (0, 2), (code, err)
    assert "Traceback" not in out + err
    for phrase in PYDANTIC:
        assert phrase not in err, (phrase, err)
    lines = err.strip().splitlines()
    if code == 0:
        assert out.startswith(f"{path}: valid")
        assert all(LINE.match(line) and line.startswith("warning: ") for line in lines), err
        return
    assert report_problems(lines, str(path)) == [], err
    for match in map(LINE.match, lines[:-1]):
        assert match is not None and match["file"] == str(path), err
        assert match["line"] is None or 1 <= int(match["line"]) <= text.count("\n") + 1, err
        assert match["line"] is not None or "required key is missing" in match["message"], err
