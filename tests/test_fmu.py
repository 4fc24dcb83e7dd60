"""``suspopt export SOURCE --fmu design.fmu`` (suspopt/fmu/): FMI 2.0 FMUs of the templates'
designs and of a kesort pick, checked with FMPy: ``validate_fmu`` finds no problem; in
co-simulation with the road built in they repeat ``suspopt simulate``'s signals (read from its
HDF5 file) to rounding; fed ``simulate``'s road as inputs, within the error of the inputs'
straight lines between communication points, which falls with the step; model exchange under
FMPy's CVode agrees; tuned parameters agree with ``simulate`` of the changed config; what the
exporter cannot take, and broken targets, are exit 2 in one line with nothing left behind."""

from __future__ import annotations

import hashlib
import re
import zipfile

import numpy as np
import pytest
from conftest import CONFIGS
from fmpy import read_model_description, simulate_fmu
from fmpy.validation import validate_fmu
from typer.testing import CliRunner

import suspopt
import suspopt.fmu
from suspopt.cli import app
from suspopt.config import ConfigError
from suspopt.config.loader import load_config_text
from suspopt.io import read_simulation_signals
from suspopt.simulation import prepare, signal_names

pytestmark = pytest.mark.cli

#: The templates exported, each with the edits that make its run short (and give the full car
#: its anti-roll bars and tyres that may lift off).
CASES = {
    "quarter": [("duration: 20.0", "duration: 2.0")],
    "half_pitch": [],  # (3 s over the half-sine bump)
    "full": [
        ("duration: 20.0", "duration: 2.0"),
        ("front: 0 ", "front: 40000 "),
        ("rear: 0 ", "rear: 40000 "),
        ("tyre_lift_off: false", "tyre_lift_off: true"),
    ],
    "seat": [("duration: 10.0", "duration: 2.0"), ("output_dt: 2.0e-3", "output_dt: 1.0e-3")],
    "semi_active": [("duration: 20.0", "duration: 6.0")],  # (the first refit at 5 s)
}


def invoke(*args) -> tuple[int, list[str], str]:
    res = CliRunner().invoke(app, [str(a) for a in args])
    lines = [line for line in res.stderr.splitlines() if line.strip()]
    assert "Traceback" not in res.output + res.stderr
    return res.exit_code, lines, res.stdout


def peak_error(got: np.ndarray, ref: np.ndarray) -> float:
    """The largest |got - ref| relative to the signal's peak (NaN equal to NaN)."""
    both_nan = np.isnan(got) & np.isnan(ref)
    if both_nan.all():
        return 0.0
    peak = np.nanmax(np.abs(ref)) or 1.0
    diff = np.where(both_nan, 0.0, np.abs(got - ref))
    return float(np.max(diff) / peak)


def worst(signals: dict, get) -> tuple[float, str]:
    """The worst output ``get(name)`` against ``signals`` {name: (T,)}."""
    return max((peak_error(get(name), ref), name) for name, ref in signals.items())


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    """The templates' configs (short runs), their FMUs in both road modes and their simulate
    files; the kesort template after optimise and kesort, its ``chosen`` pick's FMU and the
    simulate file of that pick's config."""
    d = tmp_path_factory.mktemp("fmu")
    out = {"folder": d}
    for kind, edits in CASES.items():
        config = d / f"{kind}.yaml"
        assert invoke("init", kind, "-o", config)[0] == 0
        text = config.read_text()
        for old, new in edits:
            assert old in text, (kind, old)
            text = text.replace(old, new)
        config.write_text(text)
        for road in ("embedded", "input"):
            code, lines, said = invoke(
                "export", config, "--fmu", d / f"{kind}_{road}.fmu", "--road", road
            )
            assert code == 0, lines
            assert "compiled for linux64" in said
        assert invoke("simulate", config, "-o", d / f"{kind}.h5")[0] == 0
        out[kind] = config
    ke = d / "ke.yaml"
    assert invoke("init", "kesort", "-o", ke)[0] == 0
    budget = ["--set", "optimiser.population=8", "--set", "optimiser.generations=2"]
    code, lines, _ = invoke(
        "optimise", ke, "-o", d / "front.h5", *budget, "--set", "simulation.duration=1.0"
    )
    assert code == 0, lines
    code, lines, _ = invoke("kesort", d / "front.h5", "-o", d / "ke.h5", "--keep-infeasible")
    assert code == 0, lines
    code, lines, _ = invoke(
        "export",
        d / "ke.h5",
        "--pick",
        "chosen",
        "--fmu",
        d / "kesort_embedded.fmu",
        "--road",
        "embedded",
    )
    assert code == 0, lines
    code, lines, _ = invoke(
        "export", d / "ke.h5", "--pick", "chosen", "--fmu", d / "kesort_input.fmu"
    )
    assert code == 0, lines
    assert invoke("export", d / "ke.h5", "--pick", "chosen", "-o", d / "chosen.yaml")[0] == 0
    assert invoke("simulate", d / "chosen.yaml", "-o", d / "kesort.h5")[0] == 0
    out["kesort"] = d / "chosen.yaml"
    return out


def signals_of(path) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """A simulate file's time and its one design's signals."""
    t, signals = read_simulation_signals(path)
    return t, {name: values[0] for name, values in signals.items()}


@pytest.mark.slow
@pytest.mark.parametrize("road", ["embedded", "input"])
@pytest.mark.parametrize("kind", [*CASES, "kesort"])
def test_fmpy_validates_every_fmu(study, kind, road):
    path = study["folder"] / f"{kind}_{road}.fmu"
    assert validate_fmu(str(path)) == []
    md = read_model_description(str(path))
    assert md.coSimulation is not None and md.modelExchange is not None
    with zipfile.ZipFile(path) as fmu:
        names = fmu.namelist()
    assert names[0] == "modelDescription.xml"
    assert {"sources/model.c", "sources/runtime.c", "sources/fmi2Functions.h"} <= set(names)
    assert any(n.startswith("binaries/linux64/") and n.endswith(".so") for n in names)


@pytest.mark.slow
@pytest.mark.parametrize("kind", [*CASES, "kesort"])
def test_cosimulation_with_the_embedded_road_repeats_simulate(study, kind):
    t, signals = signals_of(study["folder"] / f"{kind}.h5")
    result = simulate_fmu(str(study["folder"] / f"{kind}_embedded.fmu"), output_interval=t[1])
    assert np.allclose(result["time"], t, rtol=0, atol=1e-12)
    error, name = worst(signals, lambda n: result[n])
    print(f"{kind}: co-simulation, embedded road: max error {error:.2g} of the peak ({name})")
    assert error <= 1e-9, (error, name)


def cosim_with_inputs(
    path, time, inputs: dict, step: float, order: int = 2
) -> dict[str, np.ndarray]:
    """FMPy's FMU2Slave driven by hand: the inputs {name: values at ``time``} set at each
    communication point with their derivatives up to ``order`` (FMPy's
    ``simulate_fmu(set_input_derivatives=True)`` sets first ones only, and for nine inputs
    only), the outputs read after each step: {name: (T,)}. Over each step the FMU follows
    the inputs' Taylor polynomial: with ``order`` 1 the straight line to the next sample;
    with 2 the parabola through it whose curvature is the smaller of the second differences
    at the step's two ends, or none where they differ in sign (minmod: a bump's edge, a kink,
    bends no step beside it), as a master that holds the input's table can set them."""
    from fmpy import extract
    from fmpy.fmi2 import FMU2Slave

    md = read_model_description(str(path))
    refs = {v.name: v.valueReference for v in md.modelVariables}
    outputs = [v.name for v in md.modelVariables if v.causality == "output"]
    fmu = FMU2Slave(
        guid=md.guid,
        unzipDirectory=extract(str(path)),
        instanceName="road",
        modelIdentifier=md.coSimulation.modelIdentifier,
    )
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    in_refs, table = [refs[n] for n in inputs], np.array(list(inputs.values()))
    h = np.diff(time)
    slopes = np.diff(table, axis=1) / h
    curvature = np.zeros_like(slopes)
    if order == 2 and table.shape[1] > 2:
        second = np.diff(slopes, axis=1) / h[1:]  # (at the inner samples)
        at_samples = np.concatenate([second[:, :1], second, second[:, -1:]], axis=1)
        left, right = at_samples[:, :-1], at_samples[:, 1:]  # (minmod: a kink's is not spread)
        curvature = np.where(left * right > 0, np.sign(left) * np.minimum(abs(left), abs(right)), 0)
        slopes = slopes - 0.5 * curvature * h  # (the parabola still meets the next sample)

    def put(j: int) -> None:
        fmu.setReal(in_refs, list(table[:, j]))
        if j < slopes.shape[1]:
            fmu.setRealInputDerivatives(in_refs, [1] * len(in_refs), list(slopes[:, j]))
            if order == 2:
                fmu.setRealInputDerivatives(in_refs, [2] * len(in_refs), list(curvature[:, j]))

    put(0)
    fmu.exitInitializationMode()
    out_refs = [refs[n] for n in outputs]
    rows = [fmu.getReal(out_refs)]
    for j in range(time.size - 1):
        put(j)
        fmu.doStep(currentCommunicationPoint=time[j], communicationStepSize=step)
        rows.append(fmu.getReal(out_refs))
    fmu.terminate()
    fmu.freeInstance()
    values = np.array(rows)
    return {n: values[:, i] for i, n in enumerate(outputs)}


def input_run(path, signals, t, order: int = 2) -> tuple[float, str]:
    """The worst output of the FMU at ``path`` fed ``signals``' road (``road.*``, and
    ``road_vel.*`` where it has that input); ``road_vel.*`` without an input of its own is the
    height's slope, left out."""
    names = {v.name for v in read_model_description(str(path)).modelVariables}
    inputs = {f"input.{n}": v for n, v in signals.items() if f"input.{n}" in names}
    got = cosim_with_inputs(path, t, inputs, t[1] - t[0], order)
    compared = {
        n: v for n, v in signals.items() if not n.startswith("road_vel.") or f"input.{n}" in names
    }
    return worst(compared, lambda n: got[n])


#: The largest error allowed with the road from inputs, relative to each signal's peak, at
#: the config's dt (issue 56). The inputs' parabolas between samples
#: (:func:`cosim_with_inputs`) miss the road most where a half-sine bump's edge, a kink,
#: falls between two samples (the half cars: 4.5-4.9e-4) and on the seat's class A road at
#: 33 m/s (4.2e-4); the straight lines alone miss the latter by 1.9e-3.
INPUT_TOLERANCE = 1e-3


@pytest.mark.slow
@pytest.mark.parametrize("order", [2, 1])
@pytest.mark.parametrize("kind", [*CASES, "kesort"])
def test_cosimulation_fed_simulates_road_agrees(study, kind, order):
    """The road fed as inputs with its first and second derivatives within 1e-3 of each
    signal's peak; with the first only (straight lines), within 3e-3 (said for masters that
    set no second derivative)."""
    t, signals = signals_of(study["folder"] / f"{kind}.h5")
    error, name = input_run(study["folder"] / f"{kind}_input.fmu", signals, t, order)
    print(
        f"{kind}: co-simulation, road from inputs every {t[1]:g} s with derivatives to order "
        f"{order}: max error {error:.2g} of the peak ({name})"
    )
    assert error <= (INPUT_TOLERANCE if order == 2 else 3 * INPUT_TOLERANCE), (error, name)


@pytest.mark.slow
def test_the_input_roads_error_falls_with_the_step(study, tmp_path):
    errors = []
    for dt in ("1.0e-3", "5.0e-4"):
        text = study["quarter"].read_text().replace("dt: 1.0e-3", f"dt: {dt}")
        config = tmp_path / f"q{dt}.yaml"
        config.write_text(text)
        assert invoke("export", config, "--fmu", tmp_path / f"q{dt}.fmu")[0] == 0
        result = suspopt.simulate(suspopt.load_config(config))
        signals = {n: result.signals[n][0] for n in result.signals}
        errors.append(input_run(tmp_path / f"q{dt}.fmu", signals, result.time)[0])
    print(f"quarter, road from inputs: {errors[0]:.2g} at dt = 1 ms, {errors[1]:.2g} at 0.5 ms")
    assert errors[1] < 0.15 * errors[0]  # (fourth order: a sixteenth of it)


@pytest.mark.slow
def test_a_damping_tyre_takes_the_road_rate_as_an_input_too(study, tmp_path):
    text = study["quarter"].read_text().replace("damping: 0 ", "damping: 49 ")  # (Part 2b)
    config = tmp_path / "damped.yaml"
    config.write_text(text)
    assert invoke("export", config, "--fmu", tmp_path / "damped.fmu")[0] == 0
    md = read_model_description(str(tmp_path / "damped.fmu"))
    rate = next(v for v in md.modelVariables if v.name == "input.road_vel.F1")
    assert rate.causality == "input" and rate.unit == "m/s"
    result = suspopt.simulate(suspopt.load_config(config))
    signals = {n: result.signals[n][0] for n in result.signals}
    error, name = input_run(tmp_path / "damped.fmu", signals, result.time)
    print(f"quarter, c_T = 49 N s/m, road and its rate from inputs: max error {error:.2g} ({name})")
    assert error <= 1e-3, (error, name)


@pytest.mark.slow
@pytest.mark.parametrize("kind", [*CASES, "kesort"])
def test_model_exchange_under_cvode_agrees(study, kind):
    t, signals = signals_of(study["folder"] / f"{kind}.h5")
    result = simulate_fmu(
        str(study["folder"] / f"{kind}_embedded.fmu"),
        fmi_type="ModelExchange",
        output_interval=t[1],
        relative_tolerance=1e-8,
    )
    last = np.r_[result["time"][1:] != result["time"][:-1], True]  # (after each event)

    def at_samples(name):
        return np.interp(t, result["time"][last], result[name][last])

    error, name = worst(signals, at_samples)
    print(f"{kind}: model exchange (CVode, rtol 1e-8): max error {error:.2g} of the peak ({name})")
    assert error <= 1e-4, (error, name)


@pytest.mark.slow
@pytest.mark.parametrize(
    "kind, changes",
    [
        ("quarter", {"vehicle.body.mass": 300.0, "vehicle.corners.F1.spring.linear": 1.5e4}),
        ("full", {"vehicle.body.mass": 1200.0, "vehicle.anti_roll_bars.front": 3.0e4}),
        ("seat", {"seat.passenger.head.mass": 7.0, "seat.stiffness": 6.0e4}),
        ("half_pitch", {"vehicle.corners.F1.spring.cubic": 2.0e7, "road.height": 0.07}),
    ],
)
def test_tuned_parameters_agree_with_simulate_of_the_changed_config(study, kind, changes):
    cfg = suspopt.load_config(study[kind])
    changed = suspopt.params.apply_sets(cfg, [f"{k}={v}" for k, v in changes.items()])
    result = suspopt.simulate(changed)
    before = suspopt.simulate(cfg)
    path = study["folder"] / f"{kind}_embedded.fmu"
    tuned = simulate_fmu(str(path), output_interval=result.time[1], start_values=changes)
    error, name = worst({n: result.signals[n][0] for n in result.signals}, lambda n: tuned[n])
    moved = max(peak_error(before.signals[n][0], result.signals[n][0]) for n in result.signals)
    assert moved > 1e-2  # (the change matters)
    assert error <= 1e-9, (error, name)


@pytest.mark.slow
@pytest.mark.parametrize(
    "law",
    [
        "sh_l\n        linear_weight: 0.5",
        "add",
        "sh_add_1\n        crossover_frequency: 39.0",
        "sh_add_2\n        crossover_frequency: 39.0",
        "groundhook",
        "hybrid\n        skyhook_weight: 0.7",
    ],
    ids=lambda law: law.split()[0],
)
def test_every_control_law_with_a_lag_repeats_simulate(study, tmp_path, law):
    text = study["semi_active"].read_text()
    text = text.replace("law: sh_2 ", f"law: {law} ").replace(
        "actuator_lag: 0.0 ", "actuator_lag: 0.005 "
    )
    config = tmp_path / "law.yaml"
    config.write_text(text)
    cfg = suspopt.load_config(config)
    done = suspopt.fmu.export_fmu(cfg, tmp_path / "law.fmu", road="embedded")
    result = suspopt.simulate(cfg)
    got = simulate_fmu(str(done.path), output_interval=result.time[1])
    error, name = worst({n: result.signals[n][0] for n in result.signals}, lambda n: got[n])
    assert error <= 1e-9, (error, name)


@pytest.mark.slow
@pytest.mark.parametrize(
    "name, form",
    [
        ("nss1", "exact"),
        ("nss2", "exact"),
        ("nss3", "exact"),
        ("nss4", "exact"),
        ("nss2", "taylor"),
    ],
)
def test_the_negative_stiffness_seats_repeat_simulate(tmp_path, name, form):
    text = (CONFIGS / "ch8" / f"{name}_class_b_passenger.yaml").read_text()
    text = re.sub(r"(?m)^(\s+form:) exact", rf"\1 {form}", text)
    text = re.sub(r"duration: [0-9.e]+", "duration: 1.0", text)
    config = tmp_path / f"{name}.yaml"
    config.write_text(text)
    cfg = suspopt.load_config(config)
    assert cfg.seat.kind == name and cfg.seat.form == form
    done = suspopt.fmu.export_fmu(cfg, tmp_path / f"{name}.fmu", road="embedded")
    assert validate_fmu(str(done.path)) == []
    result = suspopt.simulate(cfg)
    got = simulate_fmu(str(done.path), output_interval=result.time[1])
    error, signal = worst({n: result.signals[n][0] for n in result.signals}, lambda n: got[n])
    assert error <= 1e-9, (error, signal)


@pytest.mark.slow
def test_a_constant_of_the_fmu_cannot_be_set_and_says_why(study):
    path = study["folder"] / "full_input.fmu"
    md = read_model_description(str(path))
    spring = next(v for v in md.modelVariables if v.name == "vehicle.corners.F1.spring.cubic")
    assert spring.causality == "local" and spring.variability == "constant"
    assert "structure" in spring.description  # (a Duffing term at 0 would be a new law)
    with pytest.raises(Exception, match="could not be set"):
        simulate_fmu(str(path), stop_time=0.01, start_values={spring.name: 1e6})


@pytest.mark.slow
def test_the_model_description_records_provenance_units_and_the_pick(study):
    path = study["folder"] / "kesort_embedded.fmu"
    md = read_model_description(str(path))
    with zipfile.ZipFile(path) as fmu:
        config = fmu.read("resources/config.yaml")
        xml = fmu.read("modelDescription.xml").decode()
    digest = hashlib.sha256(config).hexdigest()
    assert f"config sha256 {digest}" in md.description
    assert f'config_sha256="{digest}"' in xml and 'pick="chosen"' in xml
    assert f"suspopt {suspopt.__version__}" in md.generationTool
    units = {u.name: u for u in md.unitDefinitions}
    acc = units["m/s^2"].baseUnit
    assert (acc.m, acc.s, acc.kg) == (1, -2, 0)
    var = {v.name: v for v in md.modelVariables}
    assert var["head.acc"].unit == "m/s^2" and var["head.acc"].causality == "output"
    assert var["vehicle.corners.F1.damper.c"].variability == "tunable"
    knl = var["vehicle.corners.F1.spring.cubic"]  # (the design variable K_nlF1 of the pick)
    assert knl.variability == "tunable" and knl.description.startswith("design variable K_nlF1")
    prepared = prepare(load_config_text(config.decode()))
    every = signal_names(prepared.model, {}, prepared.attachments)
    assert {n for n, v in var.items() if v.causality == "output"} == set(every)


def test_every_law_translates_and_an_untranslatable_rule_is_refused(monkeypatch):
    from suspopt.control import laws
    from suspopt.fmu.laws import law_functions

    source = law_functions(list(laws.LAWS))
    assert source.count("static double su_law_") == len(laws.LAWS) + 2  # two continuous laws

    def odd_rule(st, zs, zu, za, linear_weight, crossover, skyhook_weight):
        return np.tanh(st * zs)

    monkeypatch.setitem(laws.LAWS, "sh_2", laws.Law("sh_2", odd_rule, "m^2/s^2", "Eq 2.34"))
    with pytest.raises(ConfigError, match="control law sh_2: its rule cannot be exported"):
        law_functions(["sh_2"])


@pytest.mark.slow
def test_a_student_t_threshold_is_refused_in_one_line_and_nothing_written(study, tmp_path):
    text = (
        study["semi_active"]
        .read_text()
        .replace("distribution: empirical", "distribution: student_t")
    )
    config = tmp_path / "t.yaml"
    config.write_text(text)
    code, lines, _ = invoke("export", config, "--fmu", tmp_path / "t.fmu")
    assert code == 2 and len(lines) == 1
    assert "Student-t" in lines[0] and "control.threshold.distribution" in lines[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.yaml"]


@pytest.mark.slow
def test_hostile_targets_and_picks_are_one_line_and_leave_nothing(study, tmp_path):
    config, ke = study["quarter"], study["folder"] / "ke.h5"
    (tmp_path / "a_folder.fmu").mkdir()
    foreign = tmp_path / "theirs.fmu"
    foreign.write_bytes(b"PK\x03\x04 someone else's")
    cases = [
        ((config, "--fmu", tmp_path / "missing" / "x.fmu"), "does not exist"),
        ((config, "--fmu", tmp_path / "a_folder.fmu"), "is a directory"),
        ((config, "--fmu", tmp_path / "x.zip"), "give a name ending in .fmu"),
        ((config, "--fmu", foreign), "was not written by suspopt"),
        ((config, "--fmu", config), "is the same file as the input"),
        ((config, "--fmu", tmp_path / "x.fmu", "--pick", "knee"), "is a config"),
        ((config, "--fmu", tmp_path / "x.fmu", "--road", "sideways"), "use input or embedded"),
        ((config, "-o", tmp_path / "x.yaml", "--road", "embedded"), "--road is for --fmu"),
        ((ke, "--fmu", tmp_path / "x.fmu", "--pick", "nosuch"), "has no such pick"),
        ((ke, "--fmu", tmp_path / "x.fmu", "--pick", "knee,knee"), "the same FMU twice"),
        ((ke, "--fmu", tmp_path / "x.fmu"), "--pick: name a design"),
    ]
    for args, message in cases:
        code, lines, _ = invoke("export", *args)
        assert code == 2 and len(lines) == 1, (args, lines)
        assert message in lines[0], (args, lines)
    left = sorted(p.name for p in tmp_path.iterdir())
    assert left == ["a_folder.fmu", "theirs.fmu"]
    assert foreign.read_bytes() == b"PK\x03\x04 someone else's"


@pytest.mark.slow
def test_without_a_compiler_the_fmu_is_source_only_and_says_so(study, tmp_path, monkeypatch):
    from suspopt.fmu import build

    monkeypatch.setattr(build, "compiler", lambda: None)
    code, lines, said = invoke("export", study["quarter"], "--fmu", tmp_path / "src.fmu")
    assert code == 0, lines
    assert re.search(r"source-only \(no C compiler", said)
    with zipfile.ZipFile(tmp_path / "src.fmu") as fmu:
        assert not [n for n in fmu.namelist() if n.startswith("binaries/")]
        assert "sources/model.c" in fmu.namelist()


@pytest.mark.slow
def test_several_picks_write_one_fmu_each(study, tmp_path):
    code, lines, said = invoke(
        "export",
        study["folder"] / "ke.h5",
        "--pick",
        "chosen,knee",
        "--fmu",
        tmp_path / "design.fmu",
    )
    assert code == 0, lines
    for pick in ("chosen", "knee"):
        path = tmp_path / f"design-{pick}.fmu"
        assert f"wrote {path}" in " ".join(said.split())
        assert f'pick="{pick}"' in zipfile.ZipFile(path).read("modelDescription.xml").decode()
