"""Results from Python without files (issue 59): ``Result.to_xarray()`` / ``to_dataframe()``
give what ``open_dataset`` reads from the file the result writes, and ``Result.plot()`` /
``OptimisationResult.plot()`` return the ``--plot`` figures, drawn from the result's arrays."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from conftest import TINY

import suspopt
from suspopt.config.loader import load_config_text
from suspopt.io import open_dataset, write_simulation
from suspopt.templates import template_text

K = np.array([8.0e3, 1.2e4, 2.0e4])  # three designs of the quarter car's spring [N/m]


@pytest.fixture(scope="module")
def quarter(tmp_path_factory):
    """A quarter car over an ISO 8608 road (seed 1), 1 s, three designs, its metrics, and
    the file ``suspopt.io.write_simulation`` writes of it."""
    text = template_text("quarter").replace("duration: 20.0", "duration: 1.0")
    assert "duration: 1.0" in text
    res = suspopt.simulate(
        load_config_text(text, Path("quarter.yaml")),
        params={"vehicle.corners.F1.spring.linear": K},
    )
    return res, write_simulation(tmp_path_factory.mktemp("quarter") / "q.h5", res)


def _optimised(folder: Path, text: str):
    from suspopt.optimisation import optimise

    return optimise(load_config_text(text, Path("case.yaml")), folder / "front.h5")


@pytest.fixture(scope="module")
def front(tmp_path_factory):
    """A tiny optimisation of the half car (two objectives): a front of several designs."""
    run = _optimised(tmp_path_factory.mktemp("front"), TINY)
    assert len(run.F) >= 3
    return run


@pytest.fixture(scope="module")
def robust(tmp_path_factory):
    """A tiny robust optimisation (two scenarios) of the half car."""
    text = TINY.replace("generations: 4", "generations: 2")
    text += "scenarios:\n  cases: [{name: high, set: {road.height: 0.07}}]\n"
    return _optimised(tmp_path_factory.mktemp("robust"), text)


def _same(mine: xr.Dataset, read: xr.Dataset) -> None:
    """``mine`` is ``read``: variables, coordinates, dims, every attribute; ``created`` (the
    moment each was made) is the only attribute allowed to differ."""
    assert set(mine.attrs) == set(read.attrs)
    xr.testing.assert_identical(mine.assign_attrs(created=read.attrs["created"]), read)


@pytest.mark.parametrize("group", ["signals", "metrics", "designs", "modal", ""])
def test_a_simulation_in_memory_is_the_dataset_its_file_reads_as(quarter, group):
    res, path = quarter
    mine, read = res.to_xarray(group), open_dataset(path, group)
    _same(mine, read)
    assert mine.attrs["seed"] == 1 and mine.attrs["config"] == res.config.text
    assert mine.attrs["suspopt_version"] == suspopt.__version__
    if group == "signals":
        assert mine["body.heave_acc"].dims == ("design", "time")
        assert mine["body.heave_acc"].attrs["units"] == "m/s^2"
        np.testing.assert_array_equal(mine["time"], res.time)
        np.testing.assert_array_equal(mine["travel.F1"], res.signals["travel.F1"])


def test_chosen_signals_as_float32_are_the_file_of_the_same_choice(quarter, tmp_path):
    res, _ = quarter
    names = ["body.heave_acc", "tyre_force.F1"]
    path = write_simulation(tmp_path / "some.h5", res, signals=names, float32=True)
    mine = res.to_xarray(signals=names, float32=True)
    _same(mine, open_dataset(path, "signals"))
    assert list(mine.data_vars) == names and mine["tyre_force.F1"].dtype == np.float32


def test_a_group_the_result_has_not_is_a_key_error_listing_its_groups(quarter):
    res, _ = quarter
    with pytest.raises(KeyError, match="no group 'signal'; it has 'signals', 'metrics'"):
        res.to_xarray("signal")
    with pytest.raises(TypeError, match="group must be a str"):
        res.to_xarray(3)


def test_the_dataframes_are_tidy_with_their_units(quarter):
    res, _ = quarter
    signals = res.to_dataframe(signals=["body.heave_acc", "travel.F1"])
    assert signals.index.names == ["design", "time"]
    assert list(signals.columns) == ["body.heave_acc", "travel.F1"]
    assert signals.attrs["units"] == {"body.heave_acc": "m/s^2", "travel.F1": "m"}
    np.testing.assert_array_equal(
        signals.loc[2, "travel.F1"].to_numpy(), res.signals["travel.F1"][2]
    )
    np.testing.assert_array_equal(signals.loc[1].index.to_numpy(), res.time)
    metrics = res.to_dataframe("metrics")
    assert metrics.index.name == "design" and list(metrics.columns) == list(res.metrics)
    np.testing.assert_array_equal(metrics["RC"], res.metrics["RC"])
    assert metrics.attrs["units"]["RC"] == res.metric_units["RC"] == "m/s^2"
    designs = res.to_dataframe("designs")
    np.testing.assert_array_equal(designs["vehicle.corners.F1.spring.linear"], K)
    assert designs.attrs["units"] == {"vehicle.corners.F1.spring.linear": "N/m"}


@pytest.mark.slow
@pytest.mark.parametrize("group", ["pareto", "history", "baseline", ""])
def test_an_optimisation_in_memory_is_the_dataset_its_file_reads_as(front, group):
    mine, read = front.to_xarray(group), open_dataset(front.path, group)
    xr.testing.assert_identical(mine, read)  # (the file's own attributes, created included)
    assert mine.attrs["status"] == "finished" and mine.attrs["config"].startswith("vehicle:")
    if group == "pareto":
        assert list(mine["objective"].values) == front.obj_names == ["f1", "f3"]
        assert mine["F"].attrs["units"] == front.obj_units
        np.testing.assert_array_equal(mine["X"], front.X)
    with pytest.raises(KeyError, match="no group 'checkpoint'"):
        front.to_xarray("checkpoint")


@pytest.mark.slow
@pytest.mark.parametrize("group", ["pareto", "pareto/scenarios"])
def test_a_robust_optimisation_in_memory_has_its_scenarios(robust, group):
    mine, read = robust.to_xarray(group), open_dataset(robust.path, group)
    xr.testing.assert_identical(mine, read)
    if group == "pareto":
        assert mine["F"].attrs["over_scenarios"] == ["mean", "mean"]
    else:
        assert list(mine["scenario"].values) == ["nominal", "high"]
        assert mine["F"].dims == ("design", "scenario", "objective")


@pytest.mark.slow
def test_the_front_as_a_dataframe_is_one_row_per_design(front):
    df = front.to_dataframe()
    assert len(df) == len(front.F) and df.index.name == "design"
    assert list(df.columns) == [*front.var_names, *front.obj_names, *front.constraint_names]
    np.testing.assert_array_equal(df[front.obj_names].to_numpy(), front.F)
    np.testing.assert_array_equal(df[front.constraint_names].to_numpy(), front.G)
    assert [df.attrs["units"][n] for n in front.var_names] == front.var_units
    history = front.to_dataframe("history")
    assert history.index.name == "generation" and "best[f1]" in history.columns
    np.testing.assert_array_equal(history["best[f3]"], front.history["best"][:, 1])
    assert history.attrs["units"]["time"] == "s"


@pytest.mark.slow
def test_result_plot_draws_the_result_s_arrays_with_units(quarter):
    from matplotlib.figure import Figure

    res, _ = quarter
    fig = res.plot(signals=["body.heave_acc", "travel.F1"], designs=[0, 2])
    assert isinstance(fig, Figure)
    heave = next(ax for ax in fig.axes if ax.get_ylabel() == "body.heave_acc [m/s^2]")
    assert heave.get_xlabel() == "time [s]"
    lines = heave.get_lines()
    assert len(lines) == 2
    for line, design in zip(lines, [0, 2]):
        np.testing.assert_array_equal(line.get_xdata(), res.time)
        np.testing.assert_array_equal(line.get_ydata(), res.signals["body.heave_acc"][design])
    assert any(ax.get_ylabel() == "travel.F1 [m]" for ax in fig.axes)
    labels = [t.get_text() for legend in fig.legends for t in legend.get_texts()]
    assert len(labels) == 2 and labels[0].startswith("#0") and labels[1].startswith("#2")
    with pytest.raises(ValueError, match="unknown signal 'travel'; did you mean"):
        res.plot(signals=["travel"])


@pytest.mark.slow
def test_optimisation_plot_draws_the_front_and_marks_the_picks(front):
    from matplotlib.figure import Figure

    picks = suspopt.pareto_picks(front.F, front.obj_names)
    fig = front.plot(picks)
    assert isinstance(fig, Figure)
    ax = fig.axes[0]
    assert ax.get_xlabel() == "f1 [(m/s^2)^2]" and ax.get_ylabel() == "f3 [m^2]"
    _draws_the_front(ax, front)
    stars = {name: t.xy for t in ax.texts for name in t.get_text().split(", ")}
    assert set(stars) == set(picks)
    for name, row in picks.items():
        np.testing.assert_array_equal(stars[name], front.F[row, :2])
    one = front.plot({"a": 0, "b": 0, "c": 1})  # the names of one design: one label
    assert sorted(t.get_text() for t in one.axes[0].texts) == ["a, b", "c"]
    with pytest.raises(ValueError, match="picks: 'knee': 99 is not a row"):
        front.plot({"knee": 99})


def test_a_pareto_set_read_from_its_file_plots_its_front_history_and_marks(front):
    from suspopt.choosing.selection import read_pareto

    pareto = read_pareto(front.path)
    fig = pareto.plot()
    ax = fig.axes[0]
    assert ax.get_xlabel() == "f1 [(m/s^2)^2]" and ax.get_ylabel() == "f3 [m^2]"
    _draws_the_front(ax, front)
    stars = {name for t in ax.texts for name in t.get_text().split(", ")}
    assert stars == set(pareto.marks())
    hv = fig.axes[1].lines[0].get_ydata()  # the file's hypervolume per generation
    np.testing.assert_array_equal(hv, front.history["hypervolume"])
    with pytest.raises(ValueError, match="picks: 'knee': 99 is not a row"):
        pareto.plot({"knee": 99})


def _draws_the_front(ax, front) -> None:
    """``ax`` shows ``front``'s first two objectives: feasible designs, then infeasible."""
    feasible = (front.G <= 0).all(axis=1)
    kinds = [feasible] + ([~feasible] if (~feasible).any() else [])
    for points, rows in zip(ax.collections, kinds):  # feasible filled, then infeasible
        np.testing.assert_array_equal(points.get_offsets(), front.F[rows][:, :2])
