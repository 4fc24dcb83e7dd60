"""``analyse tolerances``: a front's designs with each design variable off by ±t % in turn."""

from __future__ import annotations

import h5py
import numpy as np
import pytest
from conftest import optimised_front
from typer.testing import CliRunner

from suspopt.analyse.pseudo import Variant
from suspopt.analyse.tolerances import _held_notes, inside
from suspopt.cli import app

pytestmark = pytest.mark.cli


def _invoke(*args):
    return CliRunner().invoke(app, [str(a) for a in args])


@pytest.fixture(scope="module")
def ps_front(tmp_path_factory):
    """A tiny front of the Ch. 8 PS seat (K_v, C_v; RC_se, X_ST)."""
    return optimised_front(tmp_path_factory.mktemp("tol"), "ch8/pareto_ps_class_a", 1.5)[1]


@pytest.mark.slow
def test_each_variable_off_by_its_tolerance_moves_the_static_deflection_as_m_g_over_k(
    ps_front, tmp_path
):
    """Each variable in turn times 0.9 and 1.1, the others as designed. The PS seat's static
    deflection is m g / K_v (Eq 8.2), so K_v off by -10 % and +10 % moves X_ST of every
    design by 1/0.9 - 1 and 1/1.1 - 1, and C_v leaves it where it was."""
    out = tmp_path / "tol.h5"
    res = _invoke("analyse", "tolerances", ps_front, "-o", out, "--tolerance", "10")
    assert res.exit_code == 0, res.output
    with h5py.File(ps_front) as h5:
        X = h5["pareto/X"][()]
        names = list(h5["pareto/X"].attrs["names"].astype(str))
        objectives = list(h5["pareto/F"].attrs["names"].astype(str))
    assert names == ["K_v", "C_v"] and objectives == ["RC_se", "X_ST"]
    with h5py.File(out) as h5:
        assert h5.attrs["analysis"] == "tolerances"
        labels = list(h5["pseudo"].attrs["labels"].astype(str))
        assert labels == ["K_v -10 %", "K_v +10 %", "C_v -10 %", "C_v +10 %"]
        for label, (j, factor) in zip(labels, [(0, 0.9), (0, 1.1), (1, 0.9), (1, 1.1)]):
            g = h5["pseudo"][label]
            assert g.attrs["variable"] == names[j]
            assert g.attrs["tolerance"] == pytest.approx(100 * (factor - 1))
            changed = X.copy()
            changed[:, j] *= factor
            np.testing.assert_array_equal(g["X"][()], changed)
            change = g["change"][()]
            x_st = 100 * (1 / factor - 1) if j == 0 else 0.0
            np.testing.assert_allclose(change[:, 1], x_st, atol=1e-9)
            assert (g["failed"][()] == 0).all()
        assert np.abs(h5["pseudo/C_v +10 %/change"][:, 0]).max() > 0.01  # (damping: comfort)
        changes = np.array([h5["pseudo"][label]["change"][:, 0] for label in labels])
    assert "K_v +10 %: " in res.output and "X_ST -9.1 to -9.1 %" in res.output
    i, row = np.unravel_index(np.argmax(np.abs(changes)), changes.shape)  # the worst for RC_se
    said = " ".join(res.output.split())
    assert (
        f"largest change of each objective: RC_se {changes[i, row]:+.3g} % ({labels[i]}, " in said
    )
    assert "; X_ST +11.1 % (K_v -10 %, design " in said


@pytest.mark.parametrize("value", ["0", "100", "-5", "nan", "inf"])
def test_a_tolerance_out_of_range_is_one_line(ps_front, tmp_path, value):
    out = tmp_path / "tol.h5"
    res = _invoke("analyse", "tolerances", ps_front, "-o", out, "--tolerance", value)
    assert res.exit_code == 2 and not out.exists()
    assert res.output.strip().startswith("error: --tolerance ")
    assert len(res.output.strip().splitlines()) == 1


def test_tolerance_is_an_option_of_tolerances_alone(ps_front):
    res = _invoke("analyse", "roads", ps_front, "--road", "B", "--tolerance", "5")
    assert res.exit_code == 2 and "analyse roads does not take --tolerance" in res.output


def test_a_value_off_its_fields_range_is_held_at_the_limit_and_said():
    closed, open_top = (0.0, True, 1.0, True), (0.0, True, 1.0, False)
    np.testing.assert_array_equal(inside(np.array([-0.1, 0.5, 1.1]), closed), [0.0, 0.5, 1.0])
    top = inside(np.array([1.1]), open_top)[0]
    assert top < 1.0 and top == np.nextafter(1.0, 0.0)
    held = [
        Variant("a +10 %", None, attrs={"held_at_limit": 3}),  # type: ignore[arg-type]
        Variant("a -10 %", None, attrs={"held_at_limit": 0}),  # type: ignore[arg-type]
    ]
    assert _held_notes(held) == ["a +10 %: 3 design(s) held at the field's limit"]


def test_picked_designs_are_analysed_as_in_their_whole_front(ps_front, tmp_path):
    """``--pick`` analyses those designs alone (here of a pseudo-front analysis: each
    variable off in turn): each has the values it has in the whole front's analysis, and
    the file's ``/pareto`` holds them, so a pick is taken onward from it."""
    whole_file, picked_file = tmp_path / "whole.h5", tmp_path / "picked.h5"
    assert _invoke("analyse", "tolerances", ps_front, "-o", whole_file).exit_code == 0
    res = _invoke("analyse", "tolerances", ps_front, "-o", picked_file, "--pick", "best_X_ST,knee")
    assert res.exit_code == 0, res.output
    with h5py.File(whole_file) as whole, h5py.File(picked_file) as picked:
        rows = [int(whole["pareto/picks"][k][()]) for k in ("best_X_ST", "knee")]
        assert list(picked["pareto/source_row"][()]) == rows
        np.testing.assert_array_equal(picked["pareto/X"][()], whole["pareto/X"][()][rows])
        for label in whole["pseudo"].attrs["labels"].astype(str):
            for key in ("F", "change", "feasible"):
                got, want = picked["pseudo"][label][key][()], whole["pseudo"][label][key][()][rows]
                assert got.tobytes() == want.tobytes(), (label, key)
    res = _invoke("export", picked_file, "--pick", "knee", "-o", tmp_path / "knee.yaml")
    assert res.exit_code == 0, res.output
    # designs picked by row number have no names: none is computed over the few picked
    rows_file = tmp_path / "rows.h5"
    assert (
        _invoke("analyse", "tolerances", ps_front, "-o", rows_file, "--pick", "0,1").exit_code == 0
    )
    res = _invoke("export", rows_file, "--pick", "knee", "-o", tmp_path / "no.yaml")
    assert res.exit_code == 2 and "has no such pick; it has a design id" in res.output


def test_pick_is_an_option_of_the_front_analyses_alone(ps_front):
    res = _invoke("analyse", "cdf-sensitivity", ps_front, "--pick", "knee")
    assert res.exit_code == 2 and "analyse cdf-sensitivity does not take --pick" in res.output
