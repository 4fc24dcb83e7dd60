"""``suspopt analyse transmissibility PARETO.h5``: STHT of the edges and knee of a front
(Sec 8.4.4, Fig. 8.26)."""

from __future__ import annotations

from types import SimpleNamespace

import h5py
import numpy as np
import pytest
from conftest import CONFIGS, optimised_front
from typer.testing import CliRunner

import suspopt
from suspopt.choosing.kepsilon import pareto_picks
from suspopt.cli import app
from suspopt.seat import build_seat

PASSENGER = CONFIGS / "ch8" / "ps_class_a_passenger.yaml"


def run(*args):
    result = CliRunner().invoke(app, [str(a) for a in args])
    return SimpleNamespace(
        returncode=result.exit_code,
        stdout=result.stdout,
        stderr=result.stderr,
        exception=result.exception,
    )


@pytest.fixture(scope="module")
def ps_front(tmp_path_factory):
    _, path = optimised_front(tmp_path_factory.mktemp("ps"), "ch8/pareto_ps_class_a", 1.5)
    with h5py.File(path) as h5:
        F, X = h5["pareto/F"][()], h5["pareto/X"][()]
        names = list(h5["pareto/F"].attrs["names"].astype(str))
    picks = pareto_picks(F, names)
    rows = list(dict.fromkeys(picks.values()))
    assert len(rows) >= 2
    return SimpleNamespace(path=path, F=F, X=X, picks=picks, rows=rows)


@pytest.mark.slow
def test_front_picks_as_stored_reproduce_their_objectives(tmp_path, ps_front):
    """Without a passenger the seat is the stored one: the picks' Wk r.m.s. of seat.acc and
    X_ST are their stored objectives RC_se and X_ST (Eq 8.1-8.2): X_ST bit for bit, RC_se to
    rounding (the evaluation forms and sums the weighted signal in the compiled kernel)."""
    out, fig = tmp_path / "stht.h5", tmp_path / "stht.svg"
    proc = run("analyse", "transmissibility", ps_front.path, "-o", out, "--plot", fig)
    assert proc.returncode == 0, proc.stderr
    text = " ".join(proc.stdout.split())  # the notes, whatever the terminal width
    assert "picks of the front" in text and "STHT needs one" in text
    assert "<svg" in fig.read_text()[:2000]
    P = len(ps_front.rows)
    with h5py.File(out) as h5:
        found = []
        h5.visititems(lambda n, o: found.append(o) if isinstance(o, h5py.Dataset) else None)
        assert all("units" in ds.attrs for ds in found)
        assert list(h5["designs/row"][()]) == ps_front.rows
        assert np.array_equal(h5["designs/X"][()], ps_front.X[ps_front.rows])
        assert list(h5["designs/X"].attrs["units"].astype(str)) == ["N/m", "N s/m"]
        labels = list(h5["designs"].attrs["picks"].astype(str))
        for key, row in ps_front.picks.items():
            assert key in labels[ps_front.rows.index(row)]
        assert h5["linear/seat"].shape == (P, 500) and "head" not in h5["linear"]
        got, stored = h5["weighted_rms/seat.acc"][()], ps_front.F[ps_front.rows, 0]
        np.testing.assert_allclose(got, stored, rtol=1e-13)  # (the kernel's sums: to rounding)
        assert np.array_equal(h5["statics/static_deflection"][()], ps_front.F[ps_front.rows, 1])


def test_front_picks_with_the_passenger_give_stht(tmp_path, ps_front):
    """Sec 8.4.4: the Table 2.3 passenger on the 13.6 kg seat. PS keeps K_v, so X_ST is the
    whole load's weight over each design's K_v."""
    out = tmp_path / "stht.h5"
    proc = run(
        "analyse",
        "transmissibility",
        ps_front.path,
        "--with",
        PASSENGER,
        "-o",
        out,
        "--plot",
        tmp_path / "stht.png",
    )
    assert proc.returncode == 0, proc.stderr
    assert "with the passenger of" in " ".join(proc.stdout.split())
    load = build_seat(suspopt.load_config(PASSENGER)).isolator["load_mass"][0]
    K_v = ps_front.X[ps_front.rows, 0]
    with h5py.File(out) as h5:
        assert h5["linear/head"].shape == (len(ps_front.rows), 500)
        np.testing.assert_allclose(
            h5["statics/static_deflection"][()], load * 9.81 / K_v, rtol=1e-12
        )
        head = h5["linear/head"][()]  # on LINEAR_FREQUENCIES, from 0.1 Hz
        np.testing.assert_allclose(head[:, 0], 1.0, atol=0.01)  # rigid at 0.1 Hz
        assert np.all(head.max(axis=1) > 1.5)  # the seat resonance
        assert h5["weighted_rms/head.acc"].attrs["units"] == "m/s^2"
        cfg = suspopt.config.loader.load_config_text(h5.attrs["config"])
        assert cfg.seat.mass == 13.6 and cfg.seat.passenger is not None


@pytest.mark.parametrize(
    "case, needle",
    [
        ("config_with", "--with is for a result file"),
        ("no_passenger", "has no seat.passenger"),
        ("two", "takes one --with"),
    ],
)
def test_front_bad_input_exits_2_with_one_line(tmp_path, ps_front, case, needle):
    lumped = CONFIGS / "ch8" / "ps_class_a.yaml"
    args = {
        "config_with": [PASSENGER, "--with", PASSENGER],
        "no_passenger": [ps_front.path, "--with", lumped],
        "two": [ps_front.path, "--with", PASSENGER, "--with", PASSENGER],
    }[case]
    out = tmp_path / "out.h5"
    proc = run("analyse", "transmissibility", *args, "-o", out)
    assert proc.returncode == 2, (proc.stdout, proc.stderr, proc.exception)
    message = proc.stderr.strip()
    assert len(message.splitlines()) == 1 and needle in message, message
    assert not out.exists()


def test_the_designs_picked_are_analysed_and_keep_their_picks(tmp_path, ps_front):
    """``--pick`` analyses the designs it names (a row number too), each once, and the file
    keeps each design's picks (``/designs`` attribute ``picks``), which ``export`` and
    ``simulate --pick`` read back: a pick the file does not hold is bad input there, not
    one computed anew over the few designs it has."""
    edge = next(iter(ps_front.picks))  # best_<first objective>
    row = next(r for r in range(len(ps_front.X)) if r not in ps_front.picks.values())
    out = tmp_path / "tr.h5"
    proc = run(
        "analyse", "transmissibility", ps_front.path, "-o", out, "--pick", f"{edge},{row},{edge}"
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    edge_id = ps_front.picks[edge]  # (a front's designs: their rows are their ids)
    assert f"2 design(s) of {ps_front.path.name} (--pick): design {edge_id} ({edge})" in " ".join(
        proc.stdout.split()
    )
    with h5py.File(out) as h5:
        assert list(h5["designs"].attrs["picks"].astype(str)) == [edge, f"design {row}"]
        np.testing.assert_array_equal(h5["designs/X"][()], ps_front.X[[ps_front.picks[edge], row]])
    res = run("export", out, "--pick", edge, "-o", tmp_path / "edge.yaml")
    assert res.returncode == 0, res.stdout + res.stderr
    picked = suspopt.load_config(tmp_path / "edge.yaml")
    assert picked.seat.stiffness == pytest.approx(ps_front.X[ps_front.picks[edge], 0], rel=1e-12)
    res = run("export", out, "--pick", "knee", "-o", tmp_path / "knee.yaml")
    assert res.returncode == 2 and "has no such pick; it has " in res.stderr
    for damaged, said in (([edge], "1 entries for 2 designs"), (np.arange(2), "not text")):
        with h5py.File(out, "r+") as h5:
            h5["designs"].attrs["picks"] = damaged
        res = run("export", out, "--pick", edge, "-o", tmp_path / "no.yaml")
        assert res.returncode == 2 and f"/designs: attribute 'picks': {said}" in res.stderr
    res = run("analyse", "transmissibility", PASSENGER, "--pick", "knee")
    assert res.returncode == 2 and "--pick is for a result file" in res.stderr
