"""Pseudo-fronts of a stored Pareto set: ``analyse roads``, ``masses``, ``controllers``.

Tiny fronts come from tiny optimisations (a few seconds each). Re-simulating stored designs
with their own config reproduces the stored objectives and feasibility bit for bit, and the
tests assert exact equality: the fronts have two designs or more, so the batch takes the same
path as the optimiser's population did. (A front of ONE design agrees to rounding only, about
1e-16 relative: the simulator shares matrices common to all designs of a batch, so a single
design takes numpy's 2-D matrix product instead of the batched one.)
"""

from __future__ import annotations

from dataclasses import replace
from types import SimpleNamespace

import h5py
import numpy as np
import pytest
import yaml
from conftest import CONFIGS, optimised_front
from typer.testing import CliRunner

import suspopt
import suspopt.analyse.pseudo
from suspopt.analyse.pseudo import controller_variants, mass_variants
from suspopt.choosing.selection import evaluate_pareto, read_pareto
from suspopt.cli import app
from suspopt.config.loader import load_config_text
from suspopt.params import ParamView
from suspopt.seat import build_seat


def run(*args):
    result = CliRunner().invoke(app, [str(a) for a in args])
    return SimpleNamespace(
        returncode=result.exit_code,
        stdout=result.stdout,
        stderr=result.stderr,
        exception=result.exception,
    )


def front(folder, name: str, duration: float, **budget):
    """A tiny optimised front (two designs or more: the exactness below needs it)."""
    return optimised_front(folder, name, duration, **budget)


@pytest.fixture(scope="module")
def ps_front(tmp_path_factory):
    return front(tmp_path_factory.mktemp("ps"), "ch8/pareto_ps_class_a", 1.5)


@pytest.fixture(scope="module")
def sh2_front(tmp_path_factory):
    return front(tmp_path_factory.mktemp("sh2"), "ch7/sh_2", 2.0, population=8)


def stored(path):
    with h5py.File(path) as h5:
        out = {k: h5[f"pareto/{k}"][()] for k in ("X", "F", "G")}
    out["feasible"] = np.all(out["G"] <= 0, axis=1)
    return out


def datasets(h5):
    found = []
    h5.visititems(lambda name, obj: found.append(obj) if isinstance(obj, h5py.Dataset) else None)
    return found


@pytest.mark.slow
def test_roads_on_the_original_road_reproduce_the_stored_objectives_exactly(tmp_path, ps_front):
    config, pareto = ps_front
    out, fig = tmp_path / "roads.h5", tmp_path / "roads.png"
    proc = run(
        "analyse",
        "roads",
        pareto,
        "--road",
        "A",
        "--road",
        config,
        "--road",
        "B",
        "-o",
        out,
        "--plot",
        fig,
    )
    assert proc.returncode == 0, proc.stderr
    assert "class B" in proc.stdout and fig.stat().st_size > 10_000
    ref = stored(pareto)
    N, m = ref["F"].shape
    with h5py.File(out) as h5:
        assert all("units" in ds.attrs for ds in datasets(h5))
        assert h5.attrs["analysis"] == "roads" and h5.attrs["config"] == config.read_text()
        assert list(h5["pseudo"].attrs["labels"].astype(str)) == ["class A", config.stem, "class B"]
        assert np.array_equal(h5["pareto/F"][()], ref["F"])
        for label in ("class A", config.stem):  # the stored road, two ways
            g = h5[f"pseudo/{label}"]
            assert np.array_equal(g["F"][()], ref["F"])
            assert np.array_equal(g["feasible"][()].astype(bool), ref["feasible"])
            assert np.all(g["change"][()] == 0) and not g["failed"][()].any()
        b = h5["pseudo/class B"]
        assert b["F"].shape == (N, m) and b["change"].shape == (N, m)
        assert list(b["F"].attrs["units"].astype(str)) == ["m/s^2", "m"]
        assert b.attrs["road_class"] == "B"
        assert load_config_text(b.attrs["config"]).road.road_class == "B"
        # a linear seat on the same realisation: class B doubles every amplitude (G_d(n0) x 4)
        np.testing.assert_allclose(b["F"][:, 0], 2 * ref["F"][:, 0], rtol=1e-9)
        assert np.array_equal(b["F"][:, 1], ref["F"][:, 1])  # X_ST: no road in it
        np.testing.assert_allclose(b["change"][:, 0], 100.0, rtol=1e-7)


def test_roads_from_a_config_take_its_road_and_simulation(tmp_path, ps_front):
    _, pareto = ps_front
    other = yaml.safe_load((CONFIGS / "ch8" / "ps_class_b.yaml").read_text())
    other["simulation"]["duration"] = 1.0
    path = tmp_path / "slow_b.yaml"
    path.write_text(yaml.safe_dump(other))
    out = tmp_path / "roads.h5"
    assert run("analyse", "roads", pareto, "--road", path, "-o", out).returncode == 0
    with h5py.File(out) as h5:
        g = h5["pseudo/slow_b"]
        cfg = load_config_text(g.attrs["config"])
        assert cfg.road.speed == other["road"]["speed"] and cfg.simulation.duration == 1.0
        assert cfg.seat == read_pareto(pareto).config().seat  # only road and run change
        assert np.all(g["F"][:, 0] > stored(pareto)["F"][:, 0])


@pytest.mark.slow
def test_masses_follow_the_k_v_rule_of_sec_8_4_3(tmp_path, ps_front):
    """PS keeps K_v, so X_ST = m g / K_v follows the load exactly."""
    _, pareto = ps_front
    out = tmp_path / "masses.h5"
    proc = run("analyse", "masses", pareto, "-o", out, "--plot", tmp_path / "m.svg")
    assert proc.returncode == 0, proc.stderr
    ref = stored(pareto)
    with h5py.File(out) as h5:
        assert all("units" in ds.attrs for ds in datasets(h5))
        assert list(h5["pseudo"].attrs["labels"].astype(str)) == ["75 kg", "115 kg"]
        for label, load in (("75 kg", 75.0), ("115 kg", 115.0)):
            g = h5[f"pseudo/{label}"]
            assert g.attrs["load_mass"] == load and g.attrs["mass_change"] == load - 95.0
            np.testing.assert_allclose(g["F"][:, 1], ref["F"][:, 1] * load / 95.0, rtol=1e-12)
            assert np.all(g["F"][:, 0] != ref["F"][:, 0])
            assert load_config_text(g.attrs["config"]).seat.mass == load
            assert "X" not in g  # PS: the designs' own values unchanged


@pytest.mark.parametrize("change", ["inf", "-inf", "nan", "-1e9"])
def test_a_mass_change_that_leaves_no_finite_positive_load_is_bad_input(tmp_path, ps_front, change):
    _, pareto = ps_front
    out = tmp_path / "masses.h5"
    proc = run("analyse", "masses", pareto, "--mass-change", change, "-o", out)
    assert proc.returncode == 2, (proc.stdout, proc.stderr, proc.exception)
    message = proc.stderr.strip()
    assert len(message.splitlines()) == 1, message
    assert message.startswith(f"error: --mass-change {float(change):g}: the load would be")
    assert message.endswith("a finite load above 0 kg") and not out.exists()


def test_masses_keep_x_st_and_k_h_of_nss1_designs(tmp_path):
    """NSS1: K_v = m g / X_ST follows the load, the design's own α is rescaled so that
    K_h = α K_v stays as built (Sec 8.4.3)."""
    _, path = front(tmp_path, "ch8/pareto_nss1_class_a", 1.0, population=16, generations=4)
    pareto = read_pareto(path)
    cfg = pareto.config()
    params = {v.path: pareto.X[:, j] for j, v in enumerate(cfg.design_variables)}
    assert "seat.stiffness_ratio" in params
    before = build_seat(cfg, ParamView(cfg, params))
    for variant in mass_variants(pareto, (-20.0, 20.0)):
        new = variant.config
        changed = {v.path: variant.X[:, j] for j, v in enumerate(new.design_variables)}
        after = build_seat(new, ParamView(new, changed))
        np.testing.assert_allclose(after.isolator["load_mass"], variant.attrs["load_mass"])
        np.testing.assert_allclose(after.static_deflection, before.static_deflection, rtol=1e-12)
        np.testing.assert_allclose(
            after.isolator["horizontal_stiffness"],
            before.isolator["horizontal_stiffness"],
            rtol=1e-12,
        )
        assert not np.allclose(
            after.isolator["vertical_stiffness"], before.isolator["vertical_stiffness"]
        )
        values = evaluate_pareto(replace(pareto, X=variant.X), new)
        assert np.array_equal(values.F[:, 1], pareto.F[:, 1])  # X_ST kept


@pytest.mark.slow
def test_controllers_with_the_stored_control_reproduce_the_front(tmp_path, sh2_front):
    config, pareto = sh2_front
    same = tmp_path / "same.yaml"
    same.write_text("control: {sample_time: 0.004}\n")
    cdf = tmp_path / "cdf.yaml"
    cdf.write_text(
        (CONFIGS / "ch7" / "sh_2_cdf.yaml")
        .read_text()
        .replace("learn_time: 2.0", "learn_time: 1.0")
    )
    add = tmp_path / "add.yaml"
    add.write_text(
        yaml.safe_dump(
            {
                "vehicle": {
                    "corner_defaults": {
                        "damper": {
                            "kind": "semi_active",
                            "c_min": 1500,
                            "c_max": 3500,
                            "law": "sh_add_2",
                            "crossover_frequency": 39,
                        }
                    }
                }
            }
        )
    )
    out = tmp_path / "ctl.h5"
    proc = run(
        "analyse",
        "controllers",
        pareto,
        "--with",
        same,
        "--with",
        cdf,
        "--with",
        add,
        "-o",
        out,
        "--plot",
        tmp_path / "ctl.png",
    )
    assert proc.returncode == 0, proc.stderr
    ref = stored(pareto)
    with h5py.File(out) as h5:
        assert all("units" in ds.attrs for ds in datasets(h5))
        g = h5["pseudo/same"]
        assert np.array_equal(g["F"][()], ref["F"])
        assert np.array_equal(g["feasible"][()].astype(bool), ref["feasible"])
        assert list(g["S"].attrs["names"].astype(str)) == ["f3", "f4", "f5", "f6"]
        assert list(g["S"].attrs["units"].astype(str)) == ["m^2", "rad^2", "W", "1"]
        assert g["S"].shape == (len(ref["X"]), 4)
        # the file has no supplementary objectives: the stored designs are re-simulated for them
        assert np.array_equal(h5["pareto/S"][()], g["S"][()]) and np.all(g["S_change"][()] == 0)
        assert list(h5["pseudo/cdf/S_change"].attrs["units"].astype(str)) == ["%"] * 4
        c = load_config_text(h5["pseudo/cdf"].attrs["config"])
        assert c.control.threshold.c_max_share == 0.27 and c.control.threshold.learn_time == 1.0
        assert not np.array_equal(h5["pseudo/cdf/F"][()], ref["F"])
        a = load_config_text(h5["pseudo/add"].attrs["config"])
        assert {a.vehicle.corners[c].damper.law for c in a.vehicle.corners} == {"sh_add_2"}
        # the designs' own c_min, c_max win over the file's
        cmax = read_pareto(pareto).var_names.index("Cmax_F1")
        assert ref["X"][0, cmax] != 3500
        assert not np.array_equal(h5["pseudo/add/F"][()], ref["F"])


def test_controller_files_without_a_controller_or_with_unknown_corners_are_rejected(
    tmp_path, sh2_front
):
    _, pareto = sh2_front
    p = read_pareto(pareto)
    empty, stranger = tmp_path / "empty.yaml", tmp_path / "stranger.yaml"
    empty.write_text("road: {kind: iso8608}\n")
    stranger.write_text(yaml.safe_dump({"vehicle": {"corners": {"R2": {"damper": {"c": 1}}}}}))
    with pytest.raises(suspopt.ConfigError, match="no control: section and no damper"):
        controller_variants(p, [empty])
    with pytest.raises(suspopt.ConfigError, match="R2 are not in"):
        controller_variants(p, [stranger])


def test_the_library_takes_one_path_or_road_as_a_list_of_one(ps_front):
    """A library call given one file or road where it takes several read the string letter
    by letter ("f: no such file", "a config is given twice"); a kind that is not a pseudo
    front's and no changes at all gave a front of nothing."""
    from suspopt.analyse.models import compare_models
    from suspopt.analyse.pseudo import pseudo_fronts, road_variants
    from suspopt.choosing.selection import load_design_sets

    _, path = ps_front
    pareto = read_pareto(path)
    assert [s.label for s in load_design_sets(str(path), labels="mine")] == ["mine"]
    assert [v.label for v in road_variants(pareto, "B")] == ["class B"]
    assert len(mass_variants(pareto, "20")) == 1 == len(mass_variants(pareto, 20.0))  # ("2", "0")
    assert len(controller_variants(pareto, str(CONFIGS / "ch8" / "pareto_ps_class_a.yaml"))) == 1
    with pytest.raises(suspopt.ConfigError, match="compares at least two configs"):
        compare_models(str(CONFIGS / "quickstart.yaml"))
    with pytest.raises(suspopt.ConfigError, match="'road': not a kind of pseudo front"):
        pseudo_fronts("road", pareto, road_variants(pareto, "B"))
    with pytest.raises(suspopt.ConfigError, match="no changes to evaluate the designs under"):
        pseudo_fronts("roads", pareto, [])


@pytest.fixture
def seatless_front(tmp_path):
    """A Pareto file written by hand with the documented layout: quickstart's car, no seat."""
    text = (CONFIGS / "quickstart.yaml").read_text() + (
        "design_variables:\n"
        "  - {name: C_F1, path: vehicle.corners.F1.damper.c, lower: 2.0e3, upper: 1.0e4}\n"
        "objectives:\n  main:\n    - {name: f1, metric: var, signal: body.heave_acc}\n"
    )
    path = tmp_path / "seatless.h5"
    with h5py.File(path, "w") as h5:
        h5.attrs["config"] = text
        grp = h5.create_group("pareto")
        for key, data, names, units in (
            ("X", [[3000.0], [4000.0]], ["C_F1"], ["N s/m"]),
            ("F", [[1.0], [2.0]], ["f1"], ["(m/s^2)^2"]),
            ("G", [[-1.0], [-1.0]], ["simulation_failed"], ["1"]),
        ):
            ds = grp.create_dataset(key, data=np.array(data))
            ds.attrs["names"] = np.array(names, dtype="S")
            ds.attrs["units"] = np.array(units, dtype="S")
    return path


def test_a_hand_written_front_on_its_own_road_gives_the_simulated_objective(seatless_front):
    pareto = read_pareto(seatless_front)
    cfg = pareto.config()
    res = suspopt.simulate(cfg, params={"vehicle.corners.F1.damper.c": np.array([3000.0, 4000.0])})
    same = suspopt.analyse.pseudo.config_with(pareto, lambda data: None, "no change")
    values = evaluate_pareto(pareto, same)
    # (the evaluation merges the variance over windows of time: equal to rounding)
    np.testing.assert_allclose(
        values.F[:, 0], np.var(res.signals["body.heave_acc"], axis=1), rtol=1e-13
    )


@pytest.mark.parametrize(
    "args, needle",
    [
        (["analyse", "masses", "{seatless}"], "needs a seat"),
        (["analyse", "roads", "{seatless}", "--road", "B"], "needs an ISO 8608 road"),
        (["analyse", "roads", "{seatless}"], "give at least one --road"),
        (
            ["analyse", "roads", "{seatless}", "--road", "Q"],
            "neither a road class (A-E) nor a file",
        ),
        (["analyse", "controllers", "{seatless}"], "give at least one --with"),
        (["analyse", "controllers", "{seatless}", "--with", "{tmp}/none.yaml"], "no such file"),
        # a --with file's sections of the wrong type: AttributeError tracebacks before
        (
            ["analyse", "controllers", "{seatless}", "--with", "{tmp}/flat.yaml"],
            "flat.yaml:1: vehicle: must be a mapping, not bool",
        ),
        (
            ["analyse", "controllers", "{seatless}", "--with", "{tmp}/listed.yaml"],
            "listed.yaml:2: vehicle.corners: must be a mapping, not list",
        ),
        (["analyse", "masses", "{config}"], "not an HDF5 file"),
        (["analyse", "masses", "{tmp}/missing.h5"], "no such file"),
        (["analyse", "histogram", "{seatless}"], "unknown kind 'histogram'"),
        (["analyse", "masses", "{seatless}", "{seatless}"], "takes one SOURCE, got 2"),
        (["analyse", "transmissibility", "{config}", "--road", "B"], "does not take --road"),
        (["analyse", "masses", "{seatless}", "--plot", "{tmp}/f.jpg"], "suffix must be one of"),
    ],
)
def test_bad_input_exits_2_with_one_line_and_no_partial_output(
    tmp_path, seatless_front, args, needle
):
    config = tmp_path / "case.yaml"
    config.write_text((CONFIGS / "quickstart.yaml").read_text())
    (tmp_path / "flat.yaml").write_text("vehicle: true\ncontrol: {sample_time: 0.001}\n")
    (tmp_path / "listed.yaml").write_text("vehicle:\n  corners: [F1, R1]\n")
    fill = {"seatless": seatless_front, "config": config, "tmp": tmp_path}
    out = tmp_path / "out.h5"
    proc = run(*[a.format(**fill) for a in args], "-o", out)
    assert proc.returncode == 2, (proc.stdout, proc.stderr, proc.exception)
    message = proc.stderr.strip()
    assert len(message.splitlines()) == 1 and needle in message, message
    assert "Traceback" not in message and not out.exists()
    assert not list(tmp_path.glob("*.png")) + list(tmp_path.glob("*.jpg"))


def test_an_error_located_in_the_edited_config_keeps_its_own_place(tmp_path, sh2_front):
    """SH-ADD-2-CDF's control (one fixed threshold over conditions of two units) on the SH-2
    front: the error, located at control.threshold.value of the edited config, was nested
    inside a second location, at design_variables."""
    _, path = sh2_front
    out = tmp_path / "out.h5"
    proc = run(
        "analyse", "controllers", path, "--with", CONFIGS / "ch4" / "sh_add_2_cdf_bump.yaml",
        "-o", out,
    )  # fmt: skip
    message = proc.stderr.strip()
    assert proc.returncode == 2 and len(message.splitlines()) == 1, message
    assert message.count(":config:") == 1 and "design_variables" not in message, message
    assert ": control.threshold.value: one fixed threshold" in message and not out.exists()
