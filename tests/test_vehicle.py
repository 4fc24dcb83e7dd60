"""Vehicle assembly and modal analysis against Table 3.5 and closed forms."""

from __future__ import annotations

import re

import numpy as np
import pytest
from conftest import CONFIGS, corner, make_config

import suspopt
from suspopt.vehicle import build_vehicle, modal_analysis


def quarter_car_frequencies(m_s, m_u, k, k_t):
    """Closed form of the 2-DOF quarter car (Eq 2.1-2.2, undamped): roots of
    ω⁴ - ω² (k/m_s + (k + k_t)/m_u) + k k_t/(m_s m_u) = 0, in Hz, ascending."""
    b = k / m_s + (k + k_t) / m_u
    c = k * k_t / (m_s * m_u)
    disc = np.sqrt(b * b - 4 * c)
    return np.sqrt([(b - disc) / 2, (b + disc) / 2]) / (2 * np.pi)


def modes(load, rel):
    return modal_analysis(build_vehicle(load(rel)))


def freq_of(result, dof):
    """Frequency of the lowest mode dominated by ``dof`` (design 0)."""
    idx = np.flatnonzero(result.dominant[0] == dof)
    return result.frequency[0, idx[0]]


# Table 3.5 prints two decimals; one unit in the last place is the tolerance.
TABLE_TOL = 0.01


def test_quarter_car_matches_table_3_5_and_closed_form(load):
    res = modes(load, "ch3/part1a_qc_bump.yaml")
    assert np.allclose(
        res.frequency[0], quarter_car_frequencies(1085 / 4, 40, 1e4, 1.5e5), rtol=1e-10
    )
    assert abs(freq_of(res, "body.heave") - 0.93) <= TABLE_TOL
    assert abs(freq_of(res, "wheel.F1") - 10.07) <= TABLE_TOL


def test_half_roll_and_half_pitch_match_table_3_5(load):
    hc1 = modes(load, "ch3/part1a_hc1_bump.yaml")
    assert abs(freq_of(hc1, "body.roll") - 0.78) <= TABLE_TOL
    assert abs(freq_of(hc1, "body.heave") - 0.94) <= TABLE_TOL
    hc2 = modes(load, "ch3/part1a_hc2_bump.yaml")
    assert abs(freq_of(hc2, "body.pitch") - 1.33) <= TABLE_TOL
    assert abs(freq_of(hc2, "body.heave") - 0.93) <= TABLE_TOL
    fc = modes(load, "ch3/part1a_fc_bump.yaml")
    for dof, table in (("body.heave", 0.93), ("body.roll", 0.78), ("body.pitch", 1.33)):
        assert abs(freq_of(fc, dof) - table) <= TABLE_TOL


@pytest.mark.parametrize(
    "preset,inertia,geom",
    [
        ("half_pitch", "pitch_inertia", {"a_front": 1.2, "a_rear": 1.2}),
        ("half_roll", "roll_inertia", {"b_right": 0.8, "b_left": 0.8}),
    ],
)
def test_symmetric_half_car_rotation_closed_form(preset, inertia, geom):
    """With equal lever arms a, the rotation mode is a quarter car of mass I/(2 a²)."""
    m, I, a = 600.0, 700.0, 1.2 if preset == "half_pitch" else 0.8
    cfg = make_config(
        {
            "vehicle": {
                "preset": preset,
                "body": {"mass": m, inertia: I, **geom},
                "corner_defaults": corner(m_u=45, k_t=2e5, k=2.5e4),
            },
            "road": {"kind": "bump_step", "height": 0.01, "length": 1, "speed": 10, "start": 0},
            "simulation": {"duration": 1.0},
        }
    )
    f = modal_analysis(build_vehicle(cfg)).frequency[0]
    heave = quarter_car_frequencies(m / 2, 45, 2.5e4, 2e5)
    rotation = quarter_car_frequencies(I / (2 * a * a), 45, 2.5e4, 2e5)
    assert np.allclose(np.sort(f), np.sort(np.r_[heave, rotation]), rtol=1e-10)


def test_anti_roll_bar_raises_only_the_roll_frequency(load):
    plain = modes(load, "ch3/part2a_fc_no_arb_bump.yaml")
    bars = modes(load, "ch3/part2a_fc_arb_bump.yaml")
    assert freq_of(bars, "body.roll") > freq_of(plain, "body.roll") + 0.1
    for dof in ("body.heave", "body.pitch"):
        # b1 != b2 couples heave and roll a little; Table 3.15 prints both as equal
        assert freq_of(bars, dof) == pytest.approx(freq_of(plain, dof), abs=0.005)


def test_static_tyre_loads_carry_the_weight(load):
    for rel in ("ch3/part1a_fc_bump.yaml", "quickstart.yaml"):
        cfg = load(rel)
        model = build_vehicle(cfg)
        weight = cfg.vehicle.gravity * (cfg.vehicle.body.mass + model.unsprung_mass.sum())
        assert model.static_tyre_load.sum() == pytest.approx(weight, rel=1e-12)
    hc2 = build_vehicle(load("quickstart.yaml"))
    # moments about the CG: front load a_F = rear load a_R for the sprung part
    body = hc2.static_tyre_load[0, 0] - hc2.unsprung_mass[0, 0] * 9.81
    assert body[0] * 1.61 == pytest.approx(body[1] * 1.67, rel=1e-9)


def test_travel_sign_convention(load):
    """ST_i = z_s + y_i φ - x_i θ - z_ui (docs/architecture.md#conventions; Eq 2.26 as mended,
    slip: docs/thesis-slips.md#eq-226)."""
    model = build_vehicle(load("ch3/part1a_fc_bump.yaml"))
    q = np.zeros((model.n_dof, 1, 1))
    q[1] = 0.01  # roll
    q[2] = 0.02  # pitch
    st = model.network.group("suspension").deformation(q, None)[:, 0, 0]
    b1, b2, aF, aR = 0.7, 0.75, 1.4, 1.47
    expect = [
        b1 * 0.01 - aF * 0.02,
        -b2 * 0.01 - aF * 0.02,
        b1 * 0.01 + aR * 0.02,
        -b2 * 0.01 + aR * 0.02,
    ]
    assert np.allclose(st, expect, rtol=1e-14)


def test_frequency_response_peaks_at_body_mode(load):
    cfg = load("ch3/part1a_qc_bump.yaml")
    model = build_vehicle(cfg)
    f = np.linspace(0.2, 3, 2000)
    H = suspopt.frequency_response(model, f)[0, :, 0]
    assert f[np.argmax(np.abs(H))] == pytest.approx(0.93, abs=0.05)
    assert abs(H[0]) == pytest.approx(1.0, rel=0.05)  # body follows the road at low frequency


@pytest.mark.parametrize(
    "kwargs, needle",
    [
        ({"f": np.ones((2, 2))}, "1-D array of frequencies"),
        ({"f": [1.0, np.nan]}, "f[1] is nan"),
        ({"f": [-1.0]}, "f[0] is -1.0"),
        ({"f": [np.inf]}, "f[0] is inf"),
        ({"f": [1.0], "speed": -3.0}, "speed must be finite and >= 0"),
        ({"f": [1.0], "speed": np.nan}, "speed must be finite and >= 0"),
        ({"f": [1.0], "corners": ("X9",)}, "corners must be a tuple of this model's corners"),
        ({"f": [1.0], "corners": ("F1", 3)}, "got ('F1', 3)"),
        ({"f": [1.0], "corners": ()}, "got ()"),
    ],
)
def test_frequency_response_refuses_arguments_it_cannot_answer(load, kwargs, needle):
    """A 2-D ``f``, a frequency that is not finite and >= 0, a negative or NaN speed and a
    corner the model lacks are a ValueError naming the argument (they gave NaN, numpy's
    broadcasting message, or an unknown corner silently left out; a corner name as a
    string was read letter by letter)."""
    model = build_vehicle(load("ch3/part1a_hc2_bump.yaml"))
    with pytest.raises(ValueError, match=re.escape(needle)):
        suspopt.frequency_response(model, **kwargs)


def test_one_corner_named_as_a_string_is_that_corner(load):
    """``corners="F1"`` is the corner F1, as one string is one item everywhere else in the
    library (it was an error, and before that read letter by letter); the front wheel alone
    moves the half car differently from both wheels."""
    model = build_vehicle(load("ch3/part1a_hc2_bump.yaml"))
    f = np.linspace(0.5, 20.0, 40)
    one = suspopt.frequency_response(model, f, speed=10.0, corners="F1")
    assert np.array_equal(one, suspopt.frequency_response(model, f, speed=10.0, corners=("F1",)))
    both = suspopt.frequency_response(model, f, speed=10.0)
    assert not np.allclose(one, both)


def test_frequency_response_in_blocks_is_the_whole_solve_and_bounded(load, monkeypatch):
    """The response is solved a block of frequencies at a time: the same bits as one solve
    of all of them; a response larger than the memory limit is refused before anything is
    allocated (10^9 frequencies were the process killed by the kernel, its (F, n, n)
    matrices at once)."""
    from suspopt import memory, network

    model = build_vehicle(load("ch3/part1a_hc2_bump.yaml"))
    f = np.linspace(0.0, 30.0, 1000)
    blocks = suspopt.frequency_response(model, f, speed=20.0)
    monkeypatch.setattr(network, "_BLOCK", f.size)
    np.testing.assert_array_equal(suspopt.frequency_response(model, f, speed=20.0), blocks)
    monkeypatch.setattr(memory, "_limit", 1 << 16)  # (about 230 kB are needed)
    with pytest.raises(suspopt.ConfigError, match="frequency response of 1 designs at 1000 "):
        suspopt.frequency_response(model, f)


@pytest.mark.parametrize(
    "name, field",
    [
        ("ch3/part1a_hc1_bump.yaml", "roll_inertia"),
        ("ch3/part1a_hc1_bump.yaml", "b_left"),
        ("ch3/part1a_hc2_bump.yaml", "pitch_inertia"),
        ("ch3/part1a_hc2_bump.yaml", "a_rear"),
        ("ch3/part1a_fc_bump.yaml", "pitch_inertia"),
        ("ch3/part1a_fc_bump.yaml", "roll_inertia"),
    ],
)
def test_a_preset_without_a_body_field_it_needs_is_bad_input(name, field):
    import re

    from suspopt.config.loader import load_config_text

    text = (CONFIGS / name).read_text()
    cut = re.sub(rf"{field}: [-0-9.e+]+,? ?", "", text, count=1)
    assert cut != text
    with pytest.raises(suspopt.ConfigError, match=f"body.{field}"):
        load_config_text(cut)


def test_the_entry_points_name_the_object_they_want_when_given_another(load, tmp_path):
    """A path given where the loaded config belongs, a list where the designs' mapping
    belongs, a config where its model belongs: a TypeError that says what to pass and how to
    make it (they were AttributeErrors from deep inside, "'str' object has no attribute
    'simulation'")."""
    from suspopt.analyse.transmissibility import seat_transmissibility
    from suspopt.config.loader import load_config_text
    from suspopt.optimisation.problem import Problem
    from suspopt.optimisation.run import optimise
    from suspopt.params import sweep
    from suspopt.seat import passenger_mass_change, seat_constraints

    path = str(CONFIGS / "ch8" / "pareto_ps_class_a.yaml")
    load_first = re.escape(f"cfg must be a Config (load it first: suspopt.load_config({path!r}))")
    for call in (
        lambda: suspopt.simulate(path),
        lambda: build_vehicle(path),
        lambda: Problem.from_config(path),
        lambda: optimise(path, tmp_path / "front.h5"),
        lambda: sweep(path, ["vehicle.body.mass=1:2:3"]),
        lambda: seat_constraints(path),
        lambda: passenger_mass_change(path, [95.0]),
        lambda: seat_transmissibility(path),
    ):
        with pytest.raises(TypeError, match=load_first):
            call()
    assert not (tmp_path / "front.h5").exists()
    with pytest.raises(TypeError, match=r"cfg must be a Config \(from suspopt.load_config"):
        suspopt.simulate(None)
    cfg = load("ch3/part1a_qc_bump.yaml")
    with pytest.raises(TypeError, match="params must be a mapping of dotted config paths"):
        suspopt.simulate(cfg, [1000.0, 2000.0])
    for call in (
        lambda: modal_analysis(cfg),
        lambda: suspopt.frequency_response(cfg, [1.0]),
    ):
        with pytest.raises(TypeError, match=r"model must be a VehicleModel .*got Config"):
            call()
    for call, needle in (
        (lambda: suspopt.load_config(None), "path must be a str or Path to a YAML config"),
        (lambda: suspopt.load_config(cfg), "path must be a str or Path to a YAML config"),
        (lambda: load_config_text(None), "text must be the YAML as a str; got NoneType"),
        (lambda: load_config_text(b"vehicle: {}"), "text must be the YAML as a str; got bytes"),
    ):
        with pytest.raises(TypeError, match=re.escape(needle)):
            call()
    text = (CONFIGS / "ch3" / "part1a_qc_bump.yaml").read_text()
    same = load_config_text(text, str(CONFIGS / "ch3" / "part1a_qc_bump.yaml"))  # str source
    assert same.source == CONFIGS / "ch3" / "part1a_qc_bump.yaml"
