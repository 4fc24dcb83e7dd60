"""``analyse builds``: a front's designs built many times, every design variable off at once."""

from __future__ import annotations

import re
import shutil

import h5py
import numpy as np
import pytest
import yaml
from conftest import CONFIGS, optimised_front
from typer.testing import CliRunner

from suspopt.analyse.builds import builds, draw_builds
from suspopt.choosing.selection import read_pareto
from suspopt.cli import app

pytestmark = pytest.mark.cli


def _invoke(*args):
    return CliRunner().invoke(app, [str(a) for a in args])


@pytest.fixture(scope="module")
def ps_front(tmp_path_factory):
    """A tiny front of the Ch. 8 PS seat (K_v, C_v; RC_se, X_ST), and the limit [m] on the
    static deflection its stored config is given: 3 % below the largest of the front's
    (the builds are evaluated under the stored config, so some of that design's are
    feasible, and the rest not)."""
    folder = tmp_path_factory.mktemp("builds")
    front = optimised_front(folder, "ch8/pareto_ps_class_a", 1.5)[1]
    with h5py.File(front, "r+") as h5:
        assert list(h5["pareto/X"].attrs["names"].astype(str)) == ["K_v", "C_v"]
        assert list(h5["pareto/F"].attrs["names"].astype(str)) == ["RC_se", "X_ST"]
        limit = float(f"{0.97 * h5['pareto/F'][:, 1].max():.6g}")
        text = h5.attrs["config"]
        old = "quantity: seat.static_deflection, max: 0.1}"
        assert text.count(old) == 1
        h5.attrs["config"] = text.replace(old, old.replace("0.1", repr(limit)))
    return front, limit


def test_every_build_moves_the_static_deflection_as_m_g_over_k_and_breaks_its_limit_so(
    ps_front, tmp_path
):
    """Every build has each variable within ±t % of its design's value. The PS seat's static
    deflection is m g / K_v (Eq 8.2), so each build's X_ST is the stored one times
    K_v/K_v_built, whatever C_v is; a build is feasible exactly when that X_ST is within
    the stored config's limit (the comfort constraint, 1 m/s^2, is far). The report's spread and
    share are the file's, and the seed is the stored config's."""
    ps_front, limit = ps_front
    out = tmp_path / "builds.h5"
    res = _invoke("analyse", "builds", ps_front, "-o", out, "--samples", 40, "--tolerance", 8)
    assert res.exit_code == 0, res.output
    with h5py.File(ps_front) as h5:
        X0, F0 = h5["pareto/X"][()], h5["pareto/F"][()]
        seed = yaml.safe_load(h5.attrs["config"])["optimiser"]["seed"]
    with h5py.File(out) as h5:
        assert h5.attrs["analysis"] == "builds" and h5.attrs["seed"] == seed
        assert h5["builds"].attrs["samples"] == 40
        assert h5["builds/tolerance"][()].tolist() == [8, 8]
        assert h5["builds/tolerance"].attrs["units"] == "%"
        X, F = h5["builds/X"][()], h5["builds/F"][()]
        feasible, share = h5["builds/feasible"][()], h5["builds/feasible_share"][()]
        p05, p95 = h5["builds/F_p05"][()], h5["builds/F_p95"][()]
        assert h5["builds/X"].attrs["units"].astype(str).tolist() == ["N/m", "N s/m"]
        assert h5["builds/change"].attrs["units"].astype(str).tolist() == ["%", "%"]
        np.testing.assert_array_equal(h5["pareto/X"][()], X0)
    assert X.shape == (40,) + X0.shape and F.shape == (40,) + F0.shape
    off = X / X0 - 1
    assert np.abs(off).max() <= 0.08 + 1e-12 and np.abs(off).max() > 0.07
    assert off[..., 0].std() > 0.03 and off[..., 1].std() > 0.03  # (every variable drawn)
    np.testing.assert_allclose(F[..., 1], F0[:, 1] * X0[:, 0] / X[..., 0], rtol=1e-9)
    np.testing.assert_array_equal(feasible, F[..., 1] <= limit)
    with h5py.File(out) as h5:
        G, constraints = h5["builds/G"][()], list(h5["builds/G"].attrs["names"].astype(str))
        units = h5["builds/G"].attrs["units"].astype(str).tolist()
    j = constraints.index(f"X_ST <= {limit:g}")
    assert units[j] == "m"
    np.testing.assert_allclose(G[..., j], F[..., 1] - limit, rtol=0, atol=1e-15)
    others = [c for c in range(len(constraints)) if c != j]
    assert (G[..., others] <= 0).all()  # (the builds break the static deflection's alone)
    k = int(np.argmax(F0[:, 1]))
    assert 0 < share[k] < 1 and share[k] == feasible[:, k].mean()
    with h5py.File(out) as h5:  # what drives the spread: X_ST follows K_v alone
        r2 = h5["builds/contribution"][()]  # (design, variable, objective)
    for d in range(len(X0)):
        for i in range(2):
            for o in range(2):
                own = np.corrcoef(X[:, d, i], F[:, d, o])[0, 1] ** 2
                assert r2[d, i, o] == pytest.approx(own, rel=1e-9)
    assert (r2[:, 0, 1] > 0.95).all() and (r2[:, 1, 1] < 0.2).all()
    drivers = np.median(r2, axis=0)
    assert f"X_ST: K_v {drivers[0, 1]:.2f}, C_v {drivers[1, 1]:.2f}" in " ".join(res.output.split())
    np.testing.assert_allclose(p05, np.percentile(F, 5, axis=0))
    np.testing.assert_allclose(p95, np.percentile(F, 95, axis=0))
    said = " ".join(res.output.split())
    change = 100 * (F / F0 - 1)
    low, high = np.percentile(change[:, 0], [5, 95], axis=0)
    assert f"{low[1]:+.1f} to {high[1]:+.1f} %" in said
    assert f"{100 * share[k]:.0f} %" in said and f"(seed {seed})" in said
    assert f"feasible builds: {100 * share.min():.0f} % at the least (design " in said
    broken = F[..., 1] > limit
    assert (
        f"constraints the builds break: X_ST <= {limit:g} in {100 * broken.mean():.0f} % of all "
        f"builds (design {k}: {100 * broken[:, k].mean():.0f} %)" in said
    )


def test_the_same_seed_gives_the_same_builds_and_more_samples_extend_them(ps_front):
    """The draws come in one call from ``default_rng(seed)``: the same seed gives the same
    bits, and the first 6 of 12 builds are the 6 builds of a shorter run, evaluated in a
    batch of another size; another seed gives other builds."""
    pareto = read_pareto(ps_front[0])
    six, twelve = builds(pareto, 6, tolerance=10, seed=3), builds(pareto, 12, tolerance=10, seed=3)
    again = builds(pareto, 6, tolerance=10, seed=3)
    for a, b in ((six, again), (six, twelve)):
        assert a.X.tobytes() == b.X[:6].tobytes() and a.F.tobytes() == b.F[:6].tobytes()
        assert (a.feasible == b.feasible[:6]).all()
    assert not np.array_equal(builds(pareto, 6, tolerance=10, seed=4).X, six.X)


@pytest.mark.parametrize(
    "args, said",
    [
        (["--samples", "0"], "--samples 0: give a whole number of builds from 1 on"),
        (["--samples", "-3"], "--samples -3: give a whole number of builds from 1 on"),
        (["--samples", "10000000"], "more than 1000000; give fewer samples"),
        (["--seed", "-1"], "--seed -1: give a whole number from 0 to 2**63 - 1"),
        (["--seed", str(2**64)], "--seed 18446744073709551616: give a whole number"),
        (["--tolerance", "100"], "--tolerance 100: give a tolerance above 0 and below 100 %"),
        (["--tolerance", "nan"], "--tolerance nan: give a tolerance above 0 and below 100 %"),
        (["--tolerance", "K_v=0"], "--tolerance K_v=0: give a tolerance above 0 and below 100"),
        (["--tolerance", "K_v=x"], "--tolerance K_v='x': give a number of %"),
        (["--tolerance", "k_v=5"], "has no design variable 'k_v'; it has K_v, C_v"),
        (["--tolerance", "5", "--tolerance", "6"], "give one tolerance T for every variable"),
        (["--tolerance", "C_v=5", "--tolerance", "C_v=6"], "--tolerance C_v=: give each"),
    ],
)
def test_bad_samples_seeds_and_tolerances_are_one_line(ps_front, tmp_path, args, said):
    out = tmp_path / "builds.h5"
    res = _invoke("analyse", "builds", ps_front[0], "-o", out, *args)
    assert res.exit_code == 2 and not out.exists()
    assert res.output.strip().startswith("error: ") and said in res.output
    assert len(res.output.strip().splitlines()) == 1


def test_samples_and_seed_are_options_of_builds_alone(ps_front):
    ps_front = ps_front[0]
    res = _invoke("analyse", "tolerances", ps_front, "--samples", "5")
    assert res.exit_code == 2 and "analyse tolerances does not take --samples" in res.output
    res = _invoke("analyse", "roads", ps_front, "--road", "B", "--seed", "5")
    assert res.exit_code == 2 and "analyse roads does not take --seed" in res.output


def test_a_design_of_the_builds_file_is_taken_onward(ps_front, tmp_path):
    """The file holds the stored front with its picks, as every analysis of a front does:
    ``export --pick knee`` writes the knee's config."""
    ps_front, out = ps_front[0], tmp_path / "builds.h5"
    assert _invoke("analyse", "builds", ps_front, "-o", out, "--samples", 3).exit_code == 0
    res = _invoke("export", out, "--pick", "knee", "-o", tmp_path / "knee.yaml")
    assert res.exit_code == 0, res.output
    with h5py.File(out) as h5:
        knee = int(h5["pareto/picks/knee"][()])
        K_v = h5["pareto/X"][knee, 0]
    exported = yaml.safe_load((tmp_path / "knee.yaml").read_text())
    assert exported["seat"]["stiffness"] == pytest.approx(K_v, rel=1e-12)


def test_a_draw_off_its_fields_range_is_held_at_the_limit_and_counted(ps_front, monkeypatch):
    """A drawn value beyond its config field's range is held at the limit, and counted."""
    from suspopt.analyse import builds as module

    pareto = read_pareto(ps_front[0])
    top = float(pareto.X[:, 0].max())
    monkeypatch.setattr(
        module,
        "variable_limits",
        lambda p: [(0.0, True, top, True), (0.0, True, np.inf, True)],
    )
    X, held = module.draw_builds(pareto, 20, 10.0, 7)
    assert X[..., 0].max() == top and held[0] == (X[..., 0] == top).sum() > 0
    assert held[1] == 0


@pytest.mark.parametrize("distribution", ["uniform", "normal"])
def test_the_draws_follow_their_distribution_within_the_band(ps_front, distribution):
    """Each build's relative offset ``u = (x/x0 - 1)/(t/100)`` lies in [-1, 1] and follows
    the distribution asked for, by a Kolmogorov-Smirnov test against scipy's own: uniform
    on [-1, 1], or normal with standard deviation 1/3 truncated at ±1 (±3 σ)."""
    from scipy import stats

    pareto = read_pareto(ps_front[0])
    X, held = draw_builds(pareto, 200, 8.0, 11, distribution)
    assert held.sum() == 0
    u = ((X / pareto.X - 1) / 0.08).ravel()
    assert np.abs(u).max() <= 1 + 1e-12
    expected = {
        "uniform": stats.uniform(loc=-1, scale=2),
        "normal": stats.truncnorm(-3, 3, scale=1 / 3),
    }
    for name, law in expected.items():
        p = stats.kstest(u, law.cdf).pvalue
        assert (p > 0.01) if name == distribution else (p < 1e-6), (name, p)


def test_a_distribution_it_does_not_know_is_one_line(ps_front, tmp_path):
    out = tmp_path / "builds.h5"
    res = _invoke("analyse", "builds", ps_front[0], "-o", out, "--distribution", "triangle")
    assert res.exit_code == 2 and not out.exists()
    assert res.output.strip() == "error: --distribution 'triangle': give one of uniform, normal"


def test_what_drives_a_spread_is_said_from_ten_builds_on(ps_front):
    """Over two builds any two quantities correlate perfectly: the report does not say what
    drives a spread until there are ten."""
    res = _invoke("analyse", "builds", ps_front[0], "--samples", 9)
    assert res.exit_code == 0, res.output
    said = " ".join(res.output.split())
    assert "what drives each objective's spread: give 10 builds or more to see" in said
    res = _invoke("analyse", "builds", ps_front[0], "--samples", 10)
    assert "what drives each objective's spread (squared correlation" in " ".join(
        res.output.split()
    )


def test_kesort_counts_a_design_with_too_few_feasible_builds_infeasible(ps_front, tmp_path):
    """``kesort FRONT --builds BUILDS``: a design fewer of whose builds than
    ``--min-feasible-builds`` % meet the constraints counts as infeasible, so the k-ε
    optimum is chosen among the designs that survive their tolerances."""
    front, _ = ps_front
    builds_file, out = tmp_path / "builds.h5", tmp_path / "ke.h5"
    res = _invoke("analyse", "builds", front, "-o", builds_file, "--samples", 40, "--tolerance", 8)
    assert res.exit_code == 0, res.output
    with h5py.File(builds_file) as h5:
        share = h5["builds/feasible_share"][()]
    assert 0 < (share < 0.95).sum() < len(share)
    res = _invoke("kesort", front, "--builds", builds_file, "-o", out)
    assert res.exit_code == 0, res.output
    with h5py.File(out) as h5:
        feasible = h5["kesort/feasible"][()].astype(bool)
        rows, chosen = h5["kesort/row"][()], int(h5["kesort/chosen"][()])
    with h5py.File(front) as h5:
        stored = (h5["pareto/G"][()] <= 0).all(axis=1)
    np.testing.assert_array_equal(feasible, stored[rows] & (share[rows] >= 0.95))
    assert share[rows[chosen]] >= 0.95
    short = int((share < 0.95).sum())
    said = " ".join(res.output.split())
    assert f"note: {short} of {len(share)} designs have fewer than 95 % of their builds" in said
    res = _invoke("kesort", front, "--builds", builds_file, "--min-feasible-builds", 0)
    assert res.exit_code == 0 and f"note: 0 of {len(share)} designs" in " ".join(res.output.split())


@pytest.mark.parametrize(
    "args, said",
    [
        (["--builds", "{front}"], "not a file of suspopt analyse builds"),
        (["--builds", "{other}"], "its designs (/pareto/X) are not those of"),
        (["--builds", "{builds}", "--min-feasible-builds", "101"], "give a share from 0 to 100"),
        (["--builds", "{builds}", "--min-feasible-builds", "nan"], "give a share from 0 to 100"),
        (["--min-feasible-builds", "90"], "--min-feasible-builds: give --builds too"),
        (["{front}", "--builds", "{builds}"], "--builds: give one per Pareto file, in their"),
        (
            ["--builds", "{builds}", "--builds", "{builds}"],
            "Pareto file, in their order (1), not 2",
        ),
    ],
)
def test_kesort_builds_of_the_wrong_file_are_one_line(ps_front, tmp_path, args, said):
    front, _ = ps_front
    builds_file, other = tmp_path / "builds.h5", tmp_path / "other.h5"
    assert _invoke("analyse", "builds", front, "-o", builds_file, "--samples", 3).exit_code == 0
    with h5py.File(builds_file) as h5:
        X = h5["pareto/X"][()]
    shutil.copyfile(builds_file, other)
    with h5py.File(other, "r+") as h5:
        h5["pareto/X"][0, 0] = X[0, 0] * 1.01
    paths = {"front": front, "builds": builds_file, "other": other}
    out = tmp_path / "ke.h5"
    res = _invoke("kesort", front, *[a.format(**paths) for a in args], "-o", out)
    assert res.exit_code == 2 and not out.exists(), res.output
    assert res.output.startswith("error: ") and said in res.output
    assert len(res.output.strip().splitlines()) == 1


def test_a_picked_design_is_built_as_it_is_in_its_whole_front(ps_front, tmp_path):
    """Each design's draws come from a stream of its own, keyed by the seed and its values:
    built alone (``--pick``) and in another order, a design has the builds it has when the
    whole front is built, bit for bit. The file holds the picked designs once each, in the
    order first named, their rows in the source and the named picks."""
    front, _ = ps_front
    whole_file, picked_file = tmp_path / "whole.h5", tmp_path / "picked.h5"
    res = _invoke("analyse", "builds", front, "-o", whole_file, "--samples", 12)
    assert res.exit_code == 0, res.output
    with h5py.File(whole_file) as h5:
        knee, N = int(h5["pareto/picks/knee"][()]), len(h5["pareto/X"])
        whole = {k: h5[f"builds/{k}"][()] for k in ("X", "F", "G", "change", "feasible")}
    other = N - 1 if knee != N - 1 else 0
    picks = ["--pick", f"{other},knee", "--pick", str(other)]
    res = _invoke("analyse", "builds", front, "-o", picked_file, "--samples", 12, *picks)
    assert res.exit_code == 0, res.output
    with h5py.File(picked_file) as h5:
        assert list(h5["pareto/source_row"][()]) == [other, knee]
        assert list(h5["pareto/picks"]) == ["knee"] and int(h5["pareto/picks/knee"][()]) == 1
        for key, values in whole.items():
            assert h5[f"builds/{key}"][()].tobytes() == values[:, [other, knee]].tobytes(), key
    said = " ".join(res.output.split())
    assert f"2 design(s) of {front.name} (--pick): design {other}; design {knee} (knee)" in said


def test_the_chosen_design_of_a_kesort_file_is_built_as_in_its_front(ps_front, tmp_path):
    """``analyse builds CHOICE.h5 --pick chosen`` builds the k-ε optimum under its set's
    config: its builds are those of its row of the front. The builds of picked designs are
    not the builds of a front: ``kesort --builds`` refuses them, and a kesort file without
    ``--pick`` is one line that says to give it."""
    front, _ = ps_front
    choice, whole_file, picked_file = (tmp_path / f"{n}.h5" for n in ("choice", "whole", "one"))
    assert _invoke("kesort", front, "-o", choice).exit_code == 0
    assert _invoke("analyse", "builds", front, "-o", whole_file, "--samples", 5).exit_code == 0
    figure = tmp_path / "one.png"
    res = _invoke(
        "analyse", "builds", choice, "-o", picked_file, "--samples", 5, "--pick", "chosen",
        "--plot", figure,
    )  # fmt: skip
    assert res.exit_code == 0, res.output
    assert figure.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with h5py.File(choice) as h5:
        row = int(h5["kesort/row"][int(h5["kesort/chosen"][()])])
    with h5py.File(whole_file) as whole, h5py.File(picked_file) as one:
        np.testing.assert_array_equal(one["pareto/F"][()], whole["pareto/F"][[row]])
        for key in ("X", "F", "change", "feasible"):
            assert one[f"builds/{key}"][()].tobytes() == whole[f"builds/{key}"][:, [row]].tobytes()
    res = _invoke("kesort", front, "--builds", picked_file, "-o", tmp_path / "ke.h5")
    assert res.exit_code == 2 and len(res.output.strip().splitlines()) == 1
    assert "holds the builds of 1 picked design(s) (--pick); kesort needs" in res.output
    res = _invoke("analyse", "builds", choice, "-o", tmp_path / "no.h5")
    assert res.exit_code == 2 and not (tmp_path / "no.h5").exists()
    assert "the file holds a k-ε selection (suspopt kesort); to analyse designs of it, give " in (
        " ".join(res.output.split())
    )
    res = _invoke("export", picked_file, "--pick", "chosen", "-o", tmp_path / "chosen.yaml")
    assert res.exit_code == 0, res.output


def test_each_variable_is_built_to_its_own_tolerance(ps_front, tmp_path):
    """A design variable's ``tolerance`` in the stored config is its band (10 % where it has
    none); ``--tolerance T`` sets every variable's over the config, and ``--tolerance
    NAME=T`` NAME's over both. Each variable's offsets fill its own band, and ``analyse
    tolerances`` moves each by its own."""
    front, _ = ps_front
    own = tmp_path / "own.h5"
    shutil.copyfile(front, own)
    with h5py.File(own, "r+") as h5:
        text = h5.attrs["config"]
        old = "{name: K_v, path: seat.stiffness,"
        assert text.count(old) == 1
        h5.attrs["config"] = text.replace(old, "{name: K_v, tolerance: 3, path: seat.stiffness,")
        X0 = h5["pareto/X"][()]
    cases = (([], [3, 10]), (["--tolerance", "K_v=6"], [6, 10]), (["--tolerance", "4"], [4, 4]))
    cases += ((["--tolerance", "12", "--tolerance", "K_v=6"], [6, 12]),)
    for given, bands in cases:
        out = tmp_path / "builds.h5"
        res = _invoke("analyse", "builds", own, "-o", out, "--samples", 40, "--force", *given)
        assert res.exit_code == 0, res.output
        with h5py.File(out) as h5:
            assert h5["builds/tolerance"][()].tolist() == bands
            off = np.abs(h5["builds/X"][()] / X0 - 1).max(axis=(0, 1))
        assert (off <= np.array(bands) / 100 + 1e-12).all() and (
            off > 0.85 * np.array(bands) / 100
        ).all()
        said = " ".join(res.output.split())
        one = f"±{bands[0]} % of its value" if bands[0] == bands[1] else ""
        each = f"its tolerance (K_v ±{bands[0]} %, C_v ±{bands[1]} %)"
        assert f"within {one or each} (seed" in said
    res = _invoke("analyse", "tolerances", own, "-o", tmp_path / "tol.h5")
    assert res.exit_code == 0, res.output
    with h5py.File(tmp_path / "tol.h5") as h5:
        labels = list(h5["pseudo"].attrs["labels"].astype(str))
    assert labels == ["K_v -3 %", "K_v +3 %", "C_v -10 %", "C_v +10 %"]


def test_kesort_of_pooled_fronts_takes_the_builds_of_each(ps_front, tmp_path):
    """Pooled Pareto files take one ``--builds`` each, in their order: each set's designs
    with too few feasible builds count as infeasible, and a note says how many, per file."""
    front, _ = ps_front
    twin, builds_file, out = tmp_path / "twin.h5", tmp_path / "builds.h5", tmp_path / "ke.h5"
    shutil.copyfile(front, twin)
    res = _invoke("analyse", "builds", front, "-o", builds_file, "--samples", 40, "--tolerance", 8)
    assert res.exit_code == 0, res.output
    with h5py.File(builds_file) as h5:
        share = h5["builds/feasible_share"][()]
    assert 0 < (share < 0.95).sum() < len(share)
    pool = [front, twin, "--label", "a", "--label", "b"]
    res = _invoke("kesort", *pool, "--builds", builds_file, "--builds", builds_file, "-o", out)
    assert res.exit_code == 0, res.output
    with h5py.File(out) as h5:
        feasible = h5["kesort/feasible"][()].astype(bool)
        rows, source = h5["kesort/row"][()], h5["kesort/source"][()]
    with h5py.File(front) as h5:
        stored = (h5["pareto/G"][()] <= 0).all(axis=1)
    assert sorted(set(source.tolist())) == [0, 1]
    np.testing.assert_array_equal(feasible, stored[rows] & (share[rows] >= 0.95))
    said = " ".join(res.output.split())
    assert said.count(f"{int((share < 0.95).sum())} of {len(share)} designs have fewer") == 2


def _with_batch(front, dst, *labels, name="made"):
    """A copy of ``front`` whose stored config gives the variables ``labels`` the batch
    ``name``."""
    shutil.copyfile(front, dst)
    with h5py.File(dst, "r+") as h5:
        text = h5.attrs["config"]
        for label in labels:
            old = f"{{name: {label}, path:"
            assert text.count(old) == 1
            text = text.replace(old, f"{{name: {label}, batch: {name}, path:")
        h5.attrs["config"] = text
    return dst


def test_the_parts_of_one_batch_are_off_alike_each_within_its_own_band(ps_front, tmp_path):
    """``--batch K_v,C_v``: in every build both variables are off by the same fraction of
    their own band (K_v ±5 %, C_v ±15 %), the first one's draw is that of a run without the
    batch, bit for bit, and the static deflection still follows m g / K_v (Eq 8.2). The file
    names each variable's batch; the report says which parts are off alike and gives the
    batch one share of each spread, the one both columns of ``contribution`` hold."""
    front, _ = ps_front
    alone, together = tmp_path / "alone.h5", tmp_path / "together.h5"
    bands = ["--tolerance", "K_v=5", "--tolerance", "C_v=15", "--samples", 30]
    assert _invoke("analyse", "builds", front, "-o", alone, *bands).exit_code == 0
    res = _invoke("analyse", "builds", front, "-o", together, *bands, "--batch", "K_v, C_v")
    assert res.exit_code == 0, res.output
    with h5py.File(front) as h5:
        X0, F0 = h5["pareto/X"][()], h5["pareto/F"][()]
    with h5py.File(alone) as h5:
        X_alone = h5["builds/X"][()]
        assert h5["builds/batch"][()].astype(str).tolist() == ["", ""]
    with h5py.File(together) as h5:
        X, F, r2 = h5["builds/X"][()], h5["builds/F"][()], h5["builds/contribution"][()]
        assert h5["builds/batch"][()].astype(str).tolist() == ["K_v+C_v", "K_v+C_v"]
        assert [s.name for s in h5["builds/batch"].dims[0].values()] == ["/builds/variable"]
    u = (X / X0 - 1) / np.array([0.05, 0.15])
    np.testing.assert_allclose(u[..., 1], u[..., 0], rtol=0, atol=1e-12)
    assert np.abs(u).max() > 0.9 and u[..., 0].std() > 0.3
    assert X[..., 0].tobytes() == X_alone[..., 0].tobytes()
    assert not np.allclose(X[..., 1], X_alone[..., 1])
    np.testing.assert_allclose(F[..., 1], F0[:, 1] * X0[:, 0] / X[..., 0], rtol=1e-9)
    np.testing.assert_allclose(r2[:, 0], r2[:, 1], rtol=1e-9)
    said = " ".join(res.output.split())
    assert "(seed 1), the parts of one batch off alike (K_v and C_v);" in said
    drivers = said.split("what drives each objective's spread")[1].split(" wrote ")[0]
    assert re.findall(r"(\S+) \d\.\d\d", drivers) == ["K_v+C_v", "K_v+C_v"], drivers


def test_the_stored_configs_batches_are_drawn_unless_batch_says_none(ps_front, tmp_path):
    """``design_variables[i].batch`` in the stored config makes the variables of one name a
    batch, as ``--batch`` does; ``--batch none`` draws every variable alone, the builds of
    a config without batches bit for bit."""
    front, _ = ps_front
    own = _with_batch(front, tmp_path / "own.h5", "K_v", "C_v")
    runs = {}
    for key, source, given in (
        ("plain", front, []),
        ("stored", own, []),
        ("option", front, ["--batch", "K_v,C_v"]),
        ("none", own, ["--batch", "none"]),
    ):
        out = tmp_path / f"{key}.h5"
        res = _invoke("analyse", "builds", source, "-o", out, "--samples", 8, *given)
        assert res.exit_code == 0, res.output
        with h5py.File(out) as h5:
            runs[key] = (h5["builds/X"][()], h5["builds/batch"][()].astype(str).tolist())
    assert runs["stored"][0].tobytes() == runs["option"][0].tobytes()
    assert runs["stored"][1] == ["made", "made"] and runs["option"][1] == ["K_v+C_v"] * 2
    assert runs["none"][0].tobytes() == runs["plain"][0].tobytes()
    assert runs["none"][1] == ["", ""]
    assert not np.array_equal(runs["stored"][0], runs["plain"][0])


def test_validate_refuses_a_batch_of_one_variable_at_its_line(tmp_path):
    """A batch is two variables or more: a batch name given to one variable alone (a
    misspelt name) is refused by ``validate`` at its line, and the same batch named by both
    is accepted."""
    from suspopt.templates import template_text

    text = template_text("spectral")
    old = "{name: C_v, path: seat.damping,"
    assert text.count(old) == 1
    config = tmp_path / "study.yaml"
    config.write_text(text.replace(old, "{name: C_v, batch: made, path: seat.damping,"))
    res = _invoke("validate", config)
    line = 1 + text[: text.index(old)].count("\n")
    assert res.exit_code == 2, res.output
    assert f"study.yaml:{line}: design_variables[1].batch: batch 'made' has this" in res.output
    assert res.output.strip().splitlines()[1:] == [f"1 error in {config}"]
    both = text.replace(old, "{name: C_v, batch: made, path: seat.damping,")
    both = both.replace("{name: K_v, path:", "{name: K_v, batch: made, path:")
    config.write_text(both)
    res = _invoke("validate", config)
    assert res.exit_code == 0, res.output


@pytest.mark.parametrize(
    "args, said",
    [
        (["--batch", "K_v"], "--batch K_v: batch 'K_v' has one design variable"),
        (["--batch", "K_v,k_v"], "--batch K_v,k_v: ps_front.h5 has no design variable 'k_v'"),
        (["--batch", "K_v,K_v"], "--batch K_v,K_v: K_v is in two batches (K_v+K_v, K_v+K_v)"),
        (["--batch", "K_v,C_v", "--batch", "C_v,K_v"], "C_v is in two batches (K_v+C_v, C_v+K_v)"),
        (["--batch", "K_v,"], "--batch 'K_v,': give the names of two design variables or more"),
        (["--batch", "none", "--batch", "K_v,C_v"], "--batch 'none': give the names"),
        (["--batch", ""], "--batch '': give the names of two design variables or more"),
        (["--batch", "x" * 5000], "has no design variable 'xxxxxxxx"),
    ],
)
def test_bad_batches_are_one_line(ps_front, tmp_path, args, said):
    front = shutil.copyfile(ps_front[0], tmp_path / "ps_front.h5")
    out = tmp_path / "builds.h5"
    res = _invoke("analyse", "builds", front, "-o", out, *args)
    assert res.exit_code == 2 and not out.exists(), res.output
    assert res.output.strip().startswith("error: ") and said in res.output
    assert len(res.output.strip().splitlines()) == 1


def test_a_stored_batch_of_one_variable_is_the_files_fault_in_one_line(ps_front, tmp_path):
    """A file whose stored config was edited to give one variable a batch of its own is bad
    input, named, with or without ``--batch`` (its designs are evaluated under that config,
    which ``validate`` refuses: at its line); ``--batch`` is an option of builds alone."""
    own = _with_batch(ps_front[0], tmp_path / "own.h5", "C_v")
    out = tmp_path / "builds.h5"
    res = _invoke("analyse", "builds", own, "-o", out, "--samples", 3)
    assert res.exit_code == 2 and not out.exists(), res.output
    assert f"{own}: the stored config's design_variables: batch 'made' has one" in res.output
    assert len(res.output.strip().splitlines()) == 1
    res = _invoke("analyse", "builds", own, "-o", out, "--samples", 3, "--batch", "none")
    assert res.exit_code == 2 and not out.exists(), res.output  # (the evaluation's check)
    assert (
        f"{own}:config:" in res.output and "design_variables[1].batch: batch 'made'" in res.output
    )
    assert len(res.output.strip().splitlines()) == 1
    res = _invoke("analyse", "tolerances", own, "--batch", "K_v,C_v")
    assert res.exit_code == 2 and "analyse tolerances does not take --batch" in res.output


@pytest.fixture(scope="module")
def ps_builds(ps_front, tmp_path_factory):
    """40 builds (±8 %) of every design of the PS seat front."""
    path = tmp_path_factory.mktemp("as_built") / "builds.h5"
    res = _invoke("analyse", "builds", ps_front[0], "-o", path, "--samples", 40, "--tolerance", 8)
    assert res.exit_code == 0, res.output
    return path


def test_kesort_as_built_sorts_and_picks_on_a_percentile_of_each_designs_builds(
    ps_front, ps_builds, tmp_path
):
    """``kesort FRONT --builds B --as-built 90``: each design is judged by the 90th
    percentile of each objective over its builds. Its static deflection as built is m g /
    K_v of each build (Eq 8.2), so that percentile is the one of ``X_ST K_v / K_v_built``.
    The k-ε levels and picks are those of these values; ``/kesort/F`` keeps the nominal
    ones, which ``simulate --pick chosen`` reproduces, and the report says how it was
    sorted."""
    front, _ = ps_front
    out = tmp_path / "ke.h5"
    res = _invoke("kesort", front, "--builds", ps_builds, "--as-built", 90, "-o", out)
    assert res.exit_code == 0, res.output
    with h5py.File(front) as h5:
        X0, F0 = h5["pareto/X"][()], h5["pareto/F"][()]
    with h5py.File(ps_builds) as h5:
        X, F = h5["builds/X"][()], h5["builds/F"][()]
        assert not h5["builds/failed"][()].any()
    with h5py.File(out) as h5:
        rows, built, nominal = h5["kesort/row"][()], h5["kesort/F_as_built"][()], h5["kesort/F"][()]
        assert h5["kesort/F_as_built"].attrs["percentile"] == 90
        assert h5["kesort/F_as_built"].attrs["units"].astype(str).tolist() == ["m/s^2", "m"]
        k_eps, picks = (
            h5["kesort/k_eps"][()],
            {k: int(v[()]) for k, v in h5["kesort/picks"].items()},
        )
        chosen = int(h5["kesort/chosen"][()])
    np.testing.assert_array_equal(nominal, F0[rows])
    np.testing.assert_allclose(built, np.percentile(F, 90, axis=0)[rows], rtol=1e-12)
    X_ST = np.percentile(F0[:, 1] * X0[:, 0] / X[..., 0], 90, axis=0)
    np.testing.assert_allclose(built[:, 1], X_ST[rows], rtol=1e-9)
    assert (built > nominal).any(axis=1).all()  # (a 90th percentile: worse than nominal)
    assert picks["best_X_ST"] == int(np.argmin(built[:, 1]))
    assert picks["best_RC_se"] == int(np.argmin(built[:, 0]))
    plain = tmp_path / "plain.h5"
    assert _invoke("kesort", front, "--builds", ps_builds, "-o", plain).exit_code == 0
    with h5py.File(plain) as h5:
        assert "F_as_built" not in h5["kesort"]
        assert not np.array_equal(h5["kesort/k_eps"][()], k_eps)
    said = " ".join(res.output.split())
    assert "note: sorted as built: each objective's 90th percentile over each design's" in said
    assert "X_ST, as built (p90)" in said
    res = _invoke("simulate", out, "--pick", "chosen", "-o", tmp_path / "chosen.h5")
    assert res.exit_code == 0, res.output
    with h5py.File(tmp_path / "chosen.h5") as h5:
        np.testing.assert_allclose(h5["objectives/F"][0], nominal[chosen], rtol=1e-9)
    page = tmp_path / "ke.html"
    assert _invoke("report", out, "-o", page).exit_code == 0
    assert "sorted as built: the k-ε levels and picks rank each objective" in page.read_text()


def test_kesort_as_built_leaves_out_a_design_none_of_whose_builds_simulated(
    ps_front, ps_builds, tmp_path
):
    """A design every build of which failed to simulate has no as-built value: it is left
    out of the sort, and a note says so."""
    front, _ = ps_front
    broken, out = tmp_path / "broken.h5", tmp_path / "ke.h5"
    shutil.copyfile(ps_builds, broken)
    with h5py.File(broken, "r+") as h5:
        h5["builds/failed"][:, 0] = 1
        h5["builds/failed"][:-1, 1] = 1  # (one build left: its values)
        F = h5["builds/F"][()]
    res = _invoke(
        "kesort", front, "--builds", broken, "--as-built", 50, "--keep-infeasible", "-o", out
    )
    assert res.exit_code == 0, res.output
    with h5py.File(out) as h5:
        rows, built = list(h5["kesort/row"][()]), h5["kesort/F_as_built"][()]
    assert 0 not in rows and 1 in rows
    np.testing.assert_array_equal(built[rows.index(1)], F[-1, 1])
    said = " ".join(res.output.split())
    assert f"note: 1 design(s) of {front} with no build that simulated ({broken}): left out" in said


@pytest.mark.parametrize(
    "args, said",
    [
        (["--as-built", "95"], "--as-built: give --builds too"),
        (["--builds", "{builds}", "--as-built", "101"], "--as-built 101: give a percentile from"),
        (["--builds", "{builds}", "--as-built", "-1"], "--as-built -1: give a percentile from 0"),
        (["--builds", "{builds}", "--as-built", "nan"], "--as-built nan: give a percentile"),
        (["--builds", "{builds}", "--as-built", "inf"], "--as-built inf: give a percentile"),
        (["--builds", "{builds}", "--as-built", "95", "--config", "{config}"], "give one or the"),
        (["--builds", "{renamed}", "--as-built", "95"], "holds no builds of X_ST (it has RC_se, x"),
        (["--builds", "{flat}", "--as-built", "95"], "/builds/F: expected 3 dimensions"),
        (["--builds", "{short}", "--as-built", "95"], "/builds/failed: shape (40, 2), not (b"),
        (["--builds", "{infinite}", "--as-built", "95"], "X_ST of build 3 of design 1 is inf, "),
    ],
)
def test_kesort_as_built_of_bad_input_is_one_line(ps_front, ps_builds, tmp_path, args, said):
    front, _ = ps_front
    paths = {"builds": ps_builds, "config": CONFIGS / "ch8" / "pareto_ps_class_a.yaml"}
    for key, edit in (
        ("renamed", lambda h5: h5["builds/F"].attrs.__setitem__("names", ["RC_se", "x"])),
        ("flat", lambda h5: _replace(h5, "builds/F", h5["builds/F"][0])),
        ("short", lambda h5: _replace(h5, "builds/failed", h5["builds/failed"][:, :2])),
        ("infinite", lambda h5: h5["builds/F"].__setitem__((3, 1, 1), np.inf)),
    ):
        paths[key] = tmp_path / f"{key}.h5"
        shutil.copyfile(ps_builds, paths[key])
        with h5py.File(paths[key], "r+") as h5:
            edit(h5)
    out = tmp_path / "ke.h5"
    res = _invoke("kesort", front, *[a.format(**paths) for a in args], "-o", out)
    assert res.exit_code == 2 and not out.exists(), res.output
    assert res.output.startswith("error: ") and said in " ".join(res.output.split())
    assert len(res.output.strip().splitlines()) == 1


def _replace(h5, name, values):
    del h5[name]
    h5[name] = values


def test_kesort_as_built_of_pooled_fronts_takes_each_sets_own_builds(ps_front, ps_builds, tmp_path):
    """Pooled fronts sorted as built: each set's values are the percentiles of its own
    builds file, and each case's sort ranks them too (its levels are those of the case's
    designs sorted alone on the same values)."""
    from suspopt.choosing.kepsilon import kesort

    front, _ = ps_front
    twin, out = tmp_path / "twin.h5", tmp_path / "ke.h5"
    shutil.copyfile(front, twin)
    other = tmp_path / "other_builds.h5"
    res = _invoke("analyse", "builds", twin, "-o", other, "--samples", 40, "--seed", 9)
    assert res.exit_code == 0, res.output
    pool = [front, twin, "--label", "a", "--label", "b", "--builds", ps_builds, "--builds", other]
    res = _invoke("kesort", *pool, "--as-built", 75, "--keep-infeasible", "-o", out)
    assert res.exit_code == 0, res.output
    percentiles = []
    for path in (ps_builds, other):
        with h5py.File(path) as h5:
            percentiles.append(np.percentile(h5["builds/F"][()], 75, axis=0))
    with h5py.File(out) as h5:
        rows, source = h5["kesort/row"][()], h5["kesort/source"][()]
        built, P = h5["kesort/F_as_built"][()], float(h5["kesort"].attrs["P"])
        case_rows = h5["kesort/cases/b/rows"][()]
        case_levels, case_P = h5["kesort/cases/b/k_eps"][()], float(h5["kesort/cases/b"].attrs["P"])
    for i in (0, 1):
        mine = source == i
        np.testing.assert_allclose(built[mine], percentiles[i][rows[mine]], rtol=1e-12)
    assert not np.allclose(built[source == 0], built[source == 1])
    alone = kesort(built[case_rows], P=case_P)
    np.testing.assert_allclose(case_levels, alone.k_eps, rtol=1e-12)
    assert np.isfinite(P)


@pytest.mark.parametrize("value", ["x", np.nan, 200.0, None, True])
def test_a_damaged_as_built_percentile_is_one_line_of_the_report(
    ps_front, ps_builds, tmp_path, value
):
    front, _ = ps_front
    out, page = tmp_path / "ke.h5", tmp_path / "ke.html"
    assert (
        _invoke("kesort", front, "--builds", ps_builds, "--as-built", 95, "-o", out).exit_code == 0
    )
    with h5py.File(out, "r+") as h5:
        attrs = h5["kesort/F_as_built"].attrs
        if value is None:
            del attrs["percentile"]
        else:
            attrs["percentile"] = value
    res = _invoke("report", out, "-o", page)
    assert res.exit_code == 2 and not page.exists(), res.output
    said = " ".join(res.output.split())
    assert f"error: {out}: /kesort/F_as_built: attribute 'percentile': missing or not a" in said
    assert len(res.output.strip().splitlines()) == 1


@pytest.mark.parametrize(
    "edit, said",
    [
        (lambda v: v[:-1], "/kesort/F_as_built: "),
        (lambda v: v[:, :1], "/kesort/F_as_built: expected 2 columns, got 1"),
        (lambda v: v.astype("S8"), "/kesort/F_as_built: holds |S8 values, not numbers"),
    ],
)
def test_damaged_as_built_values_are_one_line_of_the_report(
    ps_front, ps_builds, tmp_path, edit, said
):
    front, _ = ps_front
    out, page = tmp_path / "ke.h5", tmp_path / "ke.html"
    assert (
        _invoke("kesort", front, "--builds", ps_builds, "--as-built", 95, "-o", out).exit_code == 0
    )
    with h5py.File(out, "r+") as h5:
        values, attrs = h5["kesort/F_as_built"][()], dict(h5["kesort/F_as_built"].attrs)
        _replace(h5, "kesort/F_as_built", edit(values))
        h5["kesort/F_as_built"].attrs["percentile"] = attrs["percentile"]
    res = _invoke("report", out, "-o", page)
    assert res.exit_code == 2 and not page.exists(), res.output
    assert f"error: {out}: {said}" in " ".join(res.output.split())
    assert len(res.output.strip().splitlines()) == 1


def test_select_refuses_as_built_values_that_do_not_fit_its_sets(ps_front):
    """From Python: values as built of another shape than the set's objectives, a
    percentile outside 0-100, and sets of which only some are sorted as built are refused,
    named."""
    from dataclasses import replace

    from suspopt.choosing.selection import load_design_sets, select

    front, _ = ps_front
    (s,) = load_design_sets([front])
    with pytest.raises(
        ValueError, match=r"F_as_built of shape \(2,\) at percentile 95: give one value"
    ):
        select([replace(s, F_as_built=np.zeros(2), as_built=95)])
    with pytest.raises(
        ValueError, match="at percentile 101: give one value per design and objective"
    ):
        select([replace(s, F_as_built=s.F, as_built=101)])
    with pytest.raises(ValueError, match="sorted as built .F_as_built. and not"):
        select([replace(s, F_as_built=s.F, as_built=95), s])
    for q in (0, 50, 100):  # (the values themselves: the sort of F)
        assert select([replace(s, F_as_built=s.F, as_built=q)]).chosen == select([s]).chosen


def test_kesort_as_built_plots_the_front_at_the_values_it_sorted(ps_front, ps_builds, tmp_path):
    """``kesort --as-built 90 --plot`` draws the levels over the values as built, and its
    axes say so (SVG text)."""
    front, _ = ps_front
    figure = tmp_path / "ke.svg"
    res = _invoke("kesort", front, "--builds", ps_builds, "--as-built", 90, "--plot", figure)
    assert res.exit_code == 0, res.output
    text = figure.read_text()
    assert "RC_se, as built (p90) [m/s^2]" in text and "X_ST, as built (p90) [m]" in text
    plain = tmp_path / "plain.svg"
    assert _invoke("kesort", front, "--builds", ps_builds, "--plot", plain).exit_code == 0
    assert "as built" not in plain.read_text() and "X_ST [m]" in plain.read_text()
