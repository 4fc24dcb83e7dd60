"""One identity per design (suspopt.design_ids): front -> kesort -> analyse tolerances ->
report name each design by the same id, and ``--pick ID`` gives the same design in every file
that holds it; the robust walk's ``simulate --pick --scenario`` compares the stored scenario
values with the re-simulated ones; optimise's Pareto set line says what its designs are."""

from __future__ import annotations

import dataclasses
import json
import re
from pathlib import Path

import h5py
import numpy as np
import pytest

from suspopt._entry import main
from suspopt.choosing.picks import read_picks, read_table

TEMPLATE = Path(__file__).resolve().parents[1] / "suspopt" / "templates" / "robust.yaml"


def cli(capsys, *args) -> tuple[int, str, str]:
    code = main([str(a) for a in args])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def robust_in_time() -> str:
    """The robust template (9 scenarios) in the time domain with a tiny budget: simulate
    runs the engine the optimisation ran, so the stored scenario values reproduce."""
    text = TEMPLATE.read_text()
    for key, value in (
        ("method", "time"),
        ("duration", "1.0"),
        ("population", "8"),
        ("generations", "2"),
    ):
        text, n = re.subn(rf"(?m)^(\s+{key}:) \S+", rf"\1 {value}", text, count=1)
        assert n == 1, key
    return text


@pytest.fixture(scope="module")
def walk(tmp_path_factory):
    """A robust front, and a kesort file of it that left out its first two designs (as
    ``--builds`` leaves out designs too few of whose builds are feasible)."""
    import suspopt
    from suspopt.choosing.selection import load_design_sets, select, write_selection
    from suspopt.optimisation import optimise

    folder = tmp_path_factory.mktemp("ids")
    config = folder / "robust.yaml"
    config.write_text(robust_in_time())
    front = folder / "front.h5"
    result = optimise(suspopt.load_config(config), front)
    (designs,) = load_design_sets([front])
    kept = designs.feasible.copy()
    kept[:2] = False  # (design 0 and 1 out: kesort's rows are no longer the front's)
    ke = folder / "choice.h5"
    write_selection(ke, select([dataclasses.replace(designs, feasible=kept)], P="auto"))
    return folder, front, ke, result


def rows_of(stdout: str, title: str) -> list[list[str]]:
    """The body rows of the printed table whose title holds ``title`` (its cells)."""
    lines = stdout.splitlines()
    start = next(i for i, line in enumerate(lines) if title in line)
    rows = []
    for line in lines[start + 1 :]:
        if line.startswith("└"):
            break
        if line.startswith("│"):
            rows.append([c.strip() for c in line.strip("│").split("│")])
    return rows


@pytest.mark.slow
@pytest.mark.cli
def test_ids_agree_from_the_front_to_the_report(walk, capsys, tmp_path):
    from suspopt.report import collect

    _, front, ke, _ = walk
    with h5py.File(ke) as h5:
        rows = h5["kesort/row"][()]
        ids = [v.decode() if isinstance(v, bytes) else v for v in h5["kesort/id"][()]]
        assert h5["kesort/id"].attrs["units"] == "1"
    assert ids == [str(r) for r in rows] and rows[0] == 2  # (the front's rows, not kesort's)
    table = read_table(ke)
    chosen = table.ids[table.picks["chosen"]]
    assert chosen != str(table.picks["chosen"])  # (the id is not kesort's own row number)
    # --pick ID: the same design (X) from the front and from the kesort file
    for pick in ids:
        assert np.array_equal(read_picks(front, [pick]).X, read_picks(ke, [pick]).X)
    assert np.array_equal(read_picks(ke, ["chosen"]).X, read_picks(front, [chosen]).X)
    # kesort's own rows are no ids: a design it left out is refused, not another one given
    code, _, err = cli(capsys, "simulate", ke, "--pick", "0")
    assert code == 2 and "no design 0" in err and "2, 3" in err
    # analyse tolerances of kesort's picks: its table and file name them by the same ids
    tol = tmp_path / "tol.h5"
    code, out, err = cli(
        capsys, "analyse", "tolerances", ke, "--pick", f"chosen,{ids[-1]}", "-o", tol
    )
    assert code == 0, err
    shown = rows_of(out, "tolerances:")
    assert [r[0] for r in shown] == list(dict.fromkeys([chosen, ids[-1]]))
    assert shown[0][1] == "chosen"
    assert read_table(tol).ids == [r[0] for r in shown]
    assert np.array_equal(read_picks(tol, [ids[-1]]).X, read_picks(front, [ids[-1]]).X)
    # the report: its data name each design by the same id, and its labels use them
    for path, expected in ((front, [str(k) for k in range(len(read_table(front).X))]),
                           (ke, ids), (tol, read_table(tol).ids)):  # fmt: skip
        data = collect(path).data
        assert data["ids"] == expected
    code, _, err = cli(capsys, "report", front, ke, "-o", tmp_path / "page.html")
    assert code == 0, err
    page = (tmp_path / "page.html").read_text()
    payload = re.search(r"<script type='application/json' id='suspopt-data'>(.*?)</script>", page)
    studies = json.loads(payload.group(1))["studies"]
    assert [study["data"]["ids"] for study in studies] == [collect(front).data["ids"], ids]
    assert '"design " + designId(d, r)' in page and '"row " + r' not in page


@pytest.mark.slow
@pytest.mark.cli
def test_pooled_fronts_name_their_front_in_the_id(walk, capsys):
    folder, front, _, _ = walk
    pooled = folder / "pooled.h5"
    code, out, err = cli(
        capsys, "kesort", front, front, "--label", "a", "--label", "b", "-o", pooled
    )
    assert code == 0, err
    shown = {r[0]: r[1] for r in rows_of(out, "Pareto picks")}
    assert shown and all(re.fullmatch(r"[ab]:\d+", i) for i in shown.values())
    with h5py.File(pooled) as h5:
        ids = [v.decode() if isinstance(v, bytes) else v for v in h5["kesort/id"][()]]
        source, row = h5["kesort/source"][()], h5["kesort/row"][()]
    assert ids == [f"{'ab'[s]}:{r}" for s, r in zip(source, row)]
    knee = shown["knee"]
    assert np.array_equal(read_picks(pooled, [knee]).X, read_picks(front, [knee[2:]]).X)
    code, out, err = cli(capsys, "simulate", pooled, "--pick", knee)
    assert code == 0, err
    assert rows_of(out, "picked designs")[0][1] == knee


@pytest.mark.slow
@pytest.mark.cli
def test_a_kesort_pick_under_a_scenario_is_compared_with_its_stored_values(walk, capsys, tmp_path):
    _, front, ke, _ = walk
    table = read_table(ke)
    design = table.ids[table.picks["chosen"]]
    with h5py.File(front) as h5:
        names = [n.decode() for n in h5["pareto/scenarios/scenario"][()]]
        expected = h5["pareto/scenarios/F"][int(design), names.index("C/115kg")]
    for source in (ke, front):
        pick = "chosen" if source == ke else design
        out_h5 = tmp_path / f"{source.stem}_C115.h5"
        code, out, err = cli(
            capsys, "simulate", source, "--pick", pick, "--scenario", "C/115kg", "-o", out_h5
        )
        assert code == 0, err
        rows = rows_of(out, "the picked designs' objectives")
        assert rows[0][1] == design and len(rows) == len(expected)
        assert all(r[3] and r[5] for r in rows)  # (the stored and change columns are filled)
        assert np.allclose([float(r[3]) for r in rows], expected, rtol=1e-5)  # (6 digits)
        with h5py.File(out_h5) as h5:
            stored, simulated = h5["objectives/stored_F"][0], h5["objectives/F"][0]
            assert [v.decode() if isinstance(v, bytes) else v for v in h5["designs/id"][()]] == [
                design
            ]
        assert np.array_equal(stored, expected)
        np.testing.assert_allclose(simulated, stored, rtol=1e-12)  # (the same engine ran)


def test_the_pareto_set_line_says_what_its_designs_are(walk):
    from suspopt.cli.optimisation import _optimum_table

    *_, result = walk
    N = len(result.X)
    title = str(_optimum_table(result, rows=3).title)
    assert title == (
        f"Pareto set: the {N} non-dominated designs of generation 2's population; 3 of them "
        f"shown, evenly spaced by RC_se"
    )
    assert str(_optimum_table(result).title).endswith(f"the {N} non-dominated designs of "
                                                      f"generation 2's population, by RC_se")  # fmt: skip


@pytest.mark.slow
def test_a_file_without_stored_ids_names_its_designs_by_their_rows(walk, tmp_path):
    import shutil

    _, _, ke, _ = walk
    old = tmp_path / "old.h5"
    shutil.copy(ke, old)
    with h5py.File(old, "a") as h5:
        del h5["kesort/id"]  # (as kesort wrote it before ids were stored)
    table = read_table(old)
    assert table.ids == [str(k) for k in range(len(table.X))]
    assert np.array_equal(read_picks(old, ["0"]).X, table.X[[0]])
    assert np.array_equal(read_picks(old, ["0"]).X, read_picks(ke, ["2"]).X)


@pytest.mark.slow
@pytest.mark.cli
def test_a_builds_file_of_kesort_picks_names_them_by_their_ids(walk, capsys, tmp_path):
    _, front, ke, _ = walk
    table = read_table(ke)
    chosen = table.ids[table.picks["chosen"]]
    builds = tmp_path / "builds.h5"
    code, out, err = cli(
        capsys, "analyse", "builds", ke, "--pick", "chosen", "--samples", 4, "-o", builds
    )
    assert code == 0, err
    assert rows_of(out, "builds:")[0][:2] == [chosen, "chosen"]
    assert read_table(builds).ids == [chosen]
    for pick in (chosen, "chosen"):
        assert np.array_equal(read_picks(builds, [pick]).X, read_picks(front, [chosen]).X)
