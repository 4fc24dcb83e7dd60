"""k-optimality and k-ε optimality (Eq 6.10-6.12), the Pareto picks, and ``suspopt kesort``."""

from __future__ import annotations

import importlib

import h5py
import numpy as np
import pytest
from conftest import TINY
from typer.testing import CliRunner

import suspopt
from suspopt.choosing.kepsilon import k_eps_levels, kesort, normalise_objectives, pareto_picks
from suspopt.choosing.selection import load_design_sets, select
from suspopt.cli import app
from suspopt.config.loader import load_config_text
from suspopt.optimisation import optimise

# --- the levels, by hand ------------------------------------------------------------------------

# Four solutions, three objectives. Counting the objectives where each is not worse than the
# least favourable other (Eq 6.10-6.11): A, B and D are not worse than any other in two
# objectives (k = 1); C is worse than every other in f1 and f2 (k = 0).
HAND = np.array(
    [
        [1.0, 2.0, 3.0],  # A
        [2.0, 1.0, 3.0],  # B
        [3.0, 3.0, 1.0],  # C
        [2.0, 2.0, 2.0],
    ]
)  # D


def test_k_optimality_levels_of_a_hand_made_set():
    np.testing.assert_array_equal(k_eps_levels(HAND, 0.0), [1, 1, 0, 1])
    np.testing.assert_array_equal(kesort(HAND, P=0.5).k, [1, 1, 0, 1])


def test_k_eps_levels_of_a_hand_made_set():
    # eps = 2: C against A has Δ = (2, 1, -2), Γ = (0, 0.5, 1); against B (0.5, 0, 1);
    # against D (0.5, 0.5, 1): min sum 1.5, level 0.5. A against C: Δ = (-2, -1, 2),
    # Γ = (1, 1, 0): level 1 (B alike). D, the compromise, is never far behind: against A
    # Δ = (1, 0, -1), Γ = (0.5, 1, 1); against B and C the sum is 2.5 too: level 1.5.
    levels = k_eps_levels(HAND, 2.0)
    np.testing.assert_allclose(levels, [1.0, 1.0, 0.5, 1.5])
    assert kesort(HAND, 2.0).chosen == 3
    # eps = 1: Δ = 1 is no longer inside the band (Γ = 0 for Δ >= ε;
    # slip: docs/thesis-slips.md#eq-612)
    np.testing.assert_allclose(k_eps_levels(HAND, 1.0), [1, 1, 0, 1])


def test_a_dominated_solution_is_level_minus_one_and_changes_no_front_level():
    with_e = np.vstack([HAND, [3.0, 3.0, 3.0]])  # E: dominated by D
    np.testing.assert_array_equal(k_eps_levels(with_e, 0.0), [1, 1, 0, 1, -1])


def front(rng, n, m):
    """n non-dominated points of m objectives (on the simplex sum f = 1)."""
    F = rng.dirichlet(np.ones(m), size=n)
    return F + 1.0  # positive, for Eq 7.12


@pytest.mark.parametrize("eps", [0.0, 0.05, 0.3])
def test_dominated_solutions_added_to_a_front_change_no_level_of_the_front(eps):
    rng = np.random.default_rng(3)
    F = front(rng, 40, 4)
    dominated = F[rng.integers(0, 40, 25)] + rng.uniform(0.0, 0.2, (25, 4))
    dominated[:, 0] += 0.01  # strictly worse somewhere
    before = k_eps_levels(F, eps)
    after = k_eps_levels(np.vstack([F, dominated]), eps)
    np.testing.assert_allclose(after[:40], before, rtol=0, atol=1e-12)
    assert (after[40:] <= before.max()).all()


def test_k_eps_tends_to_k_optimality_as_eps_goes_to_zero():
    F = np.random.default_rng(0).random((60, 5))
    k = k_eps_levels(F, 0.0)
    gaps = []
    for eps in (0.3, 0.1, 0.03, 0.01, 1e-3, 1e-9):
        levels = k_eps_levels(F, eps)
        assert (levels >= k - 1e-12).all()  # the soft merit is never below
        gaps.append(np.abs(levels - k).max())
    assert all(a >= b for a, b in zip(gaps, gaps[1:])) and gaps[0] > 0.1
    assert gaps[-1] == 0.0


@pytest.mark.parametrize("eps", [0.0, 0.1, 10.0])
def test_a_solution_better_in_every_objective_gets_level_m_minus_one(eps):
    rng = np.random.default_rng(1)
    F = front(rng, 30, 6)
    best = F.min(axis=0) - 0.1
    F = np.insert(F, 17, best, axis=0)
    levels = k_eps_levels(F, eps)
    assert levels[17] == 6 - 1
    assert (np.delete(levels, 17) < 5).all()
    result = kesort(F, eps=eps) if eps else kesort(F)
    assert result.chosen == 17 and result.unique


def test_max_normalisation_makes_the_sort_invariant_to_units():
    F = front(np.random.default_rng(2), 80, 4)
    scaled = F * np.array([1e3, 1e-6, 7.0, 1.0])  # mm, km^2, ... any units
    for P in (0.05, 0.3, "auto"):
        a, b = kesort(F, P=P), kesort(scaled, P=P)
        np.testing.assert_allclose(b.k_eps, a.k_eps, rtol=1e-12, atol=1e-12)
        assert a.chosen == b.chosen and a.P == b.P
        np.testing.assert_allclose(b.epsilon, a.epsilon * [1e3, 1e-6, 7.0, 1.0])
    # Eq 7.12-7.13: epsilon is P times each objective's maximum
    np.testing.assert_allclose(kesort(F, P=0.2).epsilon, 0.2 * F.max(axis=0))


def test_min_max_normalisation_ignores_an_offset_and_max_does_not():
    F = front(np.random.default_rng(4), 50, 3)
    shifted = F + [0.0, 100.0, 0.0]  # f2 in a narrow band far from 0
    mm, mm_shifted = (
        kesort(F, P=0.2, normalise="minmax"),
        kesort(shifted, P=0.2, normalise="minmax"),
    )
    np.testing.assert_allclose(mm_shifted.k_eps, mm.k_eps, atol=1e-9)
    assert not np.allclose(kesort(shifted, P=0.2).k_eps, kesort(F, P=0.2).k_eps, atol=1e-3)


def test_absolute_eps_is_in_the_objectives_units():
    F = front(np.random.default_rng(5), 30, 3)
    eps = np.array([0.05, 0.02, 0.1])
    np.testing.assert_allclose(kesort(F, eps).k_eps, k_eps_levels(F, eps), atol=1e-12)
    np.testing.assert_allclose(
        kesort(F, eps, normalise="minmax").k_eps, k_eps_levels(F, eps), atol=1e-12
    )


def test_auto_P_is_the_smallest_that_leaves_one_best_solution():
    # A and B are the edges, C the middle. For eps <= 0.5 all three hold level 0; above,
    # C alone rises (to 1 - 0.5/eps): the smallest grid P with one best is 0.51.
    F = np.array([[0.0, 1.0], [1.0, 0.0], [0.5, 0.5]])
    result = kesort(F, P="auto", P_range=(0.01, 1.0), P_step=0.01)
    assert pytest.approx(0.51) == result.P and result.P_auto
    assert result.chosen == 2 and result.unique
    tied = kesort(F, P=0.5)
    assert not tied.unique and list(tied.ties) == [0, 1, 2] and tied.chosen == 0


def test_ties_are_reported_when_no_P_separates_them():
    F = np.array([[1.0, 2.0], [1.0, 2.0], [2.0, 1.5]])  # two identical designs
    result = kesort(F)
    assert not result.unique and list(result.ties) == [0, 1]
    assert pytest.approx(1.0) == result.P  # the grid ran out


def _sorted_at_every_P(F, tie_tol=1e-9, step=0.01):
    """P = "auto" the long way: every P of the grid sorts the whole set (normalised by the
    maximum), the first with one solution on top is taken."""
    NF = F / F.max(axis=0)
    for k in range(int(round(0.99 / step)) + 1):
        P = float(f"{0.01 + k * step:.12g}")
        levels = k_eps_levels(NF, P * NF.max(axis=0))
        if (levels >= levels.max() - tie_tol).sum() == 1:
            break
    return P, levels


@pytest.mark.parametrize("kind", ["pooled twice", "straight front", "random"])
def test_auto_P_asks_only_which_solution_leads_and_agrees_with_sorting_every_P(kind, monkeypatch):
    """After the first P, each P of the grid is answered from bounds and the exact levels of
    the leading solutions: the same P and the same bits as sorting the whole set at every
    P, in a fraction of the pairs (a tie no P breaks, as a design pooled twice, made every
    P of the grid a whole sort; benchmarks/bench_kesort.py times both)."""
    ke = importlib.import_module("suspopt.choosing.kepsilon")

    rng = np.random.default_rng(8)
    if kind == "pooled twice":
        F = np.tile(rng.dirichlet(np.ones(3), 150), (2, 1))
    elif kind == "straight front":
        F = np.column_stack([np.linspace(1, 2, 300), np.linspace(2, 1, 300)])
    else:
        F = rng.uniform(0.1, 1.0, (300, 4))
    P, levels = _sorted_at_every_P(F)
    pairs = []
    sums = ke._Merits.sums
    monkeypatch.setattr(
        ke._Merits, "sums", lambda self, r, c: pairs.append(r.size * c.size) or sums(self, r, c)
    )
    result = kesort(F, P="auto")
    assert result.P == P and result.unique == (kind == "random")
    np.testing.assert_array_equal(result.k_eps, levels)
    if kind != "random":  # (100 values of P: 100 N² pairs the long way)
        assert sum(pairs) < 30 * len(F) ** 2


def test_blocks_of_rows_give_the_same_levels():
    F = np.random.default_rng(6).random((101, 4))
    whole = k_eps_levels(F, 0.2)
    np.testing.assert_array_equal(k_eps_levels(F, 0.2, chunk_bytes=16 * 101 * 7), whole)
    np.testing.assert_array_equal(k_eps_levels(F, 0.0, chunk_bytes=1), k_eps_levels(F, 0.0))


def test_one_solution_and_bad_input():
    assert k_eps_levels([[1.0, 2.0, 3.0]], 0.1)[0] == 2
    with pytest.raises(ValueError, match=r"F\[1, 0\] is nan"):
        kesort([[1.0, 2.0], [np.nan, 1.0]])
    with pytest.raises(ValueError, match="f2 has maximum -1 <= 0.*min-max"):
        normalise_objectives([[1.0, -2.0], [2.0, -1.0]], "max")
    with pytest.raises(ValueError, match="not both"):
        kesort(HAND, 0.1, P=0.2)
    with pytest.raises(ValueError, match="unknown normalisation"):
        kesort(HAND, normalise="range")


@pytest.mark.parametrize("eps", [1e-320, [1e-320, 0.0, 1e-310, 5e-324, 1e-300]])
def test_thresholds_below_the_float_spacing_give_the_crisp_levels_without_overflow(eps):
    """|f/ε| beyond the floating-point range: Γ is 0 or 1 (the limit), computed without an
    overflow (which numpy would report as a warning on the command line)."""
    F = np.random.default_rng(7).random((60, 5))
    with np.errstate(over="raise", divide="raise", invalid="raise"):
        np.testing.assert_array_equal(k_eps_levels(F, eps), k_eps_levels(F, 0.0))
        np.testing.assert_array_equal(kesort(F, P=1e-320).k_eps, k_eps_levels(F, 0.0))
        huge = np.array([[1e308, 1.0], [-1e308, 0.5], [0.0, 0.7]])  # Δ itself overflows
        np.testing.assert_array_equal(k_eps_levels(huge, 1e-300), [-1.0, 1.0, -1.0])


def test_objectives_beyond_the_floating_point_range_once_normalised_are_named():
    F = np.array([[0.18, -7.1e306], [0.2, 0.0324], [0.25, 0.024]])  # a damaged file's F
    with np.errstate(over="raise", divide="raise", invalid="raise"):
        with pytest.raises(ValueError, match=r"objective f2 spans -7\.1e\+306 to 0\.0324: "):
            kesort(F)
        with pytest.raises(ValueError, match=r"objective RC spans -1e\+308 to 1e\+308"):
            pareto_picks([[1e308, 1.0], [-1e308, 2.0], [0.0, 0.0]], names=["RC", "X_ST"])
        with pytest.raises(ValueError, match="eps 1 of objective f1 is beyond"):
            kesort([[1e-320, 1.0], [2e-320, 0.5]], eps=1.0)
        assert kesort(F, normalise="minmax").chosen == 0  # min-max keeps it in range


@pytest.mark.parametrize(
    "options, needle",
    [
        ({"P": np.inf}, "P must be finite and > 0"),
        ({"P": np.nan}, "P must be finite and > 0"),
        ({"P": "bogus"}, "P must be finite and > 0, or 'auto'; got 'bogus'"),  # (float's message)
        ({"tie_tol": np.nan}, "tie_tol must be finite and >= 0; got nan"),  # (an IndexError)
        ({"tie_tol": -1.0}, "tie_tol must be finite and >= 0"),
        ({"P_range": (0.5,)}, r"P_range must be two numbers \(low, high\)"),  # (unpacking's)
        ({"P_step": "x"}, "and P_step one; got .*'x'"),
        ({"P_range": (0.01, np.inf)}, "all finite"),
        ({"P_step": np.nan}, "all finite"),
        ({"P_step": 1e-12}, r"a grid of 9.9e\+11 values of P; at most 10000"),
        ({"P_range": (0.01, 1e300), "P_step": 1e-300}, "a grid of inf values of P"),
    ],
)
def test_options_that_are_not_finite_or_make_a_runaway_grid_are_refused(options, needle):
    """Before any work: a grid of 10^12 values of P was an allocation of 7 TB."""
    with pytest.raises(ValueError, match=needle):
        kesort(HAND, **options)


def test_select_of_no_design_set_is_a_config_error():
    with pytest.raises(suspopt.ConfigError, match="give at least one design set"):
        select([])  # (an IndexError before)


def test_a_grid_of_tiny_P_keeps_its_values():
    """The grid's values are rounded to 12 significant digits, not decimals (which made a
    grid of 1e-320 all zeros)."""
    result = kesort(HAND, P_range=(1e-320, 1e-319), P_step=1e-321)
    assert 1e-320 <= result.P <= 1e-319
    assert kesort(HAND, P_range=(0.15, 0.15)).P == 0.15


def test_pareto_picks_edges_and_knee():
    theta = np.linspace(0.0, np.pi / 2, 21)
    F = np.column_stack([1 - np.cos(theta), 1 - np.sin(theta)])  # convex towards utopia
    F = np.vstack([F, [0.0, 2.0]])  # dominated twin of the f1 edge
    assert pareto_picks(F) == {"best_f1": 0, "best_f2": 20, "knee": 10}
    assert pareto_picks(F * [1e3, 1.0], names=["RC", "X_ST"]) == {
        "best_RC": 0,
        "best_X_ST": 20,
        "knee": 10,
    }


# --- Pareto files: re-simulation, pooling, the command -------------------------------------------

FEASIBLE = (
    TINY.replace("min: 0.1, max: 0.3", "min: 0.0, max: 1.0")
    .replace("weighting: Wk, max: 1.4", "weighting: Wk, max: 3.0")
    .replace("generations: 4", "generations: 2")
)


@pytest.fixture(scope="module")
def pareto(tmp_path_factory):
    folder = tmp_path_factory.mktemp("kesort")
    config = folder / "tiny.yaml"
    config.write_text(FEASIBLE)
    path = folder / "tiny.h5"
    optimise(suspopt.load_config(config), path)
    return path


def test_supplementary_objectives_are_the_problems_own_in_one_batch(pareto):
    [designs] = load_design_sets([pareto])
    problem = suspopt.Problem.from_config(load_config_text(FEASIBLE))
    with h5py.File(pareto) as h5:
        X, F = h5["pareto/X"][()], h5["pareto/F"][()]
    F2, _, S = problem.evaluate(problem.to_search(X), return_values_of=["F", "G", "S"])
    assert designs.names == ["f1", "f3", "f2"] and designs.resimulated
    np.testing.assert_allclose(designs.F, np.hstack([F2, S]), rtol=1e-12)
    np.testing.assert_allclose(designs.F[:, :2], F, rtol=1e-9)
    np.testing.assert_allclose(problem.to_physical(problem.to_search(X)), X, rtol=1e-12)


def test_another_config_gives_a_pseudo_front_and_pooling_keeps_the_case(pareto, tmp_path):
    stiff = tmp_path / "stiff_rear.yaml"  # same designs, another rear damper
    stiff.write_text(FEASIBLE.replace("damper: {c: 3500}", "damper: {c: 8000}"))
    own, other = load_design_sets([pareto, pareto], [pareto.with_suffix(".yaml"), stiff])
    assert (own.label, other.label) == ("tiny", "stiff_rear")
    np.testing.assert_array_equal(own.X, other.X)
    assert not np.allclose(own.F, other.F)
    sel = select([own, other], P=0.2)
    N = len(own.X)
    assert sel.F.shape == (2 * N, 3) and list(sel.case) == ["tiny"] * N + ["stiff_rear"] * N
    assert set(sel.case_sorts) == {"tiny", "stiff_rear"}
    assert sel.case_sorts["stiff_rear"].chosen >= N  # indices in the pool
    np.testing.assert_array_equal(sel.row, np.tile(np.arange(N), 2))


@pytest.mark.slow
def test_cli_kesort_writes_the_layout(pareto, tmp_path):
    out, fig = tmp_path / "ke.h5", tmp_path / "ke.png"
    result = CliRunner().invoke(
        app,
        [
            "kesort",
            str(pareto),
            str(pareto),
            "-l",
            "A",
            "-l",
            "A",
            "--P",
            "0.3",
            "-o",
            str(out),
            "--plot",
            str(fig),
        ],
    )
    assert result.exit_code == 0, result.output
    assert "k-ε optimum" in result.stdout and "knee" in result.stdout
    assert fig.stat().st_size > 0
    with h5py.File(pareto) as h5:
        N = h5["pareto/X"].shape[0]
        config = h5.attrs["config"]
    with h5py.File(out) as h5:
        for key in ("suspopt_version", "created", "command", "config", "seed"):
            assert key in h5.attrs
        assert h5.attrs["config"] == config
        g = h5["kesort"]
        assert g["F"].shape == (2 * N, 3)
        assert list(g["F"].attrs["names"]) == ["f1", "f3", "f2"]  # UTF-8 text
        assert list(g["F"].attrs["units"]) == ["(m/s^2)^2", "m^2", "m^2"]
        assert list(g["X"].attrs["names"]) == ["k_F1", "c_F1", "knl_F1"]
        assert g["k_eps"].shape == (2 * N,) and 0 <= g["chosen"][()] < 2 * N
        assert g.attrs["P"] == 0.3 and g.attrs["epsilon"].shape == (3,)
        np.testing.assert_allclose(g.attrs["epsilon"], 0.3 * g["F"][()].max(axis=0))
        assert {k.decode() for k in g["case"][()]} == {"A"} and "cases" not in g
        assert set(g["picks"]) == {"best_f1", "best_f3", "best_f2", "knee"}
        assert not g.attrs["unique"] and len(g["ties"]) == 2  # each design twice
        datasets = []
        h5.visititems(
            lambda name, obj: datasets.append(obj) if isinstance(obj, h5py.Dataset) else None
        )
        assert datasets and all("units" in ds.attrs for ds in datasets)


def _pareto_without_F(path, pareto):
    with h5py.File(pareto) as src, h5py.File(path, "w") as h5:
        h5.attrs["config"] = src.attrs["config"]
        src.copy("pareto/X", h5, "pareto/X")


@pytest.mark.parametrize(
    "case, needle",
    [
        ("missing", "nowhere.h5: no such file"),
        ("not_hdf5", "notes.h5: not an HDF5 file"),
        ("no_F", "noF.h5: /pareto/F: missing"),
        ("other_variables", "do not fit its design_variables"),
        ("eps", "--eps 1,x: expected numbers"),
        ("eps_count", "eps gives 4 values for 3 objectives (f1, f3, f2)"),
        ("plot", "fig.jpg: give a .png or .svg file"),
        ("normalise", "unknown normalisation 'range'"),
        ("configs", "--config: give one config for every file, or one per file (1); got 2"),
        ("grid", "--P-range (0.01, 1.0) with --P-step 1e-12 is a grid of 9.9e+11 values"),
    ],
)
def test_cli_kesort_bad_input_exits_2_with_one_line(pareto, tmp_path, case, needle):
    out = tmp_path / "ke.h5"
    args = {
        "missing": [str(tmp_path / "nowhere.h5")],
        "not_hdf5": [str(tmp_path / "notes.h5")],
        "no_F": [str(tmp_path / "noF.h5")],
        "other_variables": [str(pareto), "--config", str(tmp_path / "other.yaml")],
        "eps": [str(pareto), "--eps", "1,x"],
        "eps_count": [str(pareto), "--eps", "1,2,3,4"],
        "plot": [str(pareto), "--plot", str(tmp_path / "fig.jpg")],
        "normalise": [str(pareto), "--normalise", "range"],
        "grid": [str(pareto), "--P-step", "1e-12"],
        "configs": [
            str(pareto),
            "-c",
            str(pareto.with_suffix(".yaml")),
            "-c",
            str(pareto.with_suffix(".yaml")),
        ],
    }[case]
    (tmp_path / "notes.h5").write_text("not HDF5")
    _pareto_without_F(tmp_path / "noF.h5", pareto)
    (tmp_path / "other.yaml").write_text(FEASIBLE.replace("name: c_F1", "name: c_front"))
    result = CliRunner().invoke(app, ["kesort", *args, "-o", str(out)])
    assert result.exit_code == 2, result.output
    message = result.stderr.strip()
    assert len(message.splitlines()) == 1 and "Traceback" not in result.output
    assert needle in message, message
    assert not out.exists() and not list(tmp_path.glob(".*.tmp"))
