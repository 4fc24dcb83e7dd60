"""Figures of ``simulate`` and ``optimise`` (``plots.plot_simulation``,
``plots.plot_optimisation``), the models figure's coinciding curves, legends and labels."""

from __future__ import annotations

import subprocess
import sys
from itertools import combinations, pairwise

import numpy as np
import pytest
from conftest import CONFIGS, ROOT, tiny

import suspopt
from suspopt import plots

PNG = b"\x89PNG\r\n\x1a\n"


def drawn(fig):
    """``fig`` drawn on an Agg canvas (text extents need a renderer)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig).draw()
    return fig


def texts(fig):
    """Every visible, non-empty text of ``fig``: titles, axis and tick labels, offsets,
    annotations, legend entries, of every axes and its secondary axes."""
    found = [fig._suptitle] if fig._suptitle is not None else []
    for legend in fig.legends:
        found += legend.get_texts()
    stack = list(fig.axes)
    while stack:
        ax = stack.pop()
        if not ax.get_visible():
            continue
        stack += ax.child_axes
        found += [ax.title, ax._left_title, ax._right_title, *ax.texts]
        for axis in (ax.xaxis, ax.yaxis):
            if not axis.get_visible():
                continue
            found += [axis.label, axis.get_offset_text()]
            low, high = sorted(axis.get_view_interval())
            span = (high - low) * 1e-9
            found += [
                label
                for tick in axis.get_major_ticks() + axis.get_minor_ticks()
                if low - span <= tick.get_loc() <= high + span
                for label in (tick.label1, tick.label2)
            ]
        if ax.get_legend() is not None:
            found += ax.get_legend().get_texts()
    return [t for t in found if t.get_visible() and t.get_text().strip()]


def overlapping_texts(fig):
    """Pairs of texts of ``fig`` whose boxes overlap (more than a pixel)."""
    fig = drawn(fig)
    renderer = fig.canvas.get_renderer()
    boxes = [
        (t.get_text(), t.get_window_extent(renderer).expanded(1.0, 1.0).padded(-1.0))
        for t in texts(fig)
    ]
    return [
        (a, b)
        for (a, box_a), (b, box_b) in combinations(boxes, 2)
        if box_a.width > 0 and box_b.width > 0 and box_a.overlaps(box_b)
    ]


def data_axes(fig):
    return [ax for ax in fig.axes if ax.get_visible() and ax.axison]


def legend_outside_the_panels(fig):
    """The figure's one legend, checked to lie outside every panel with data."""
    fig = drawn(fig)
    renderer = fig.canvas.get_renderer()
    legends = list(fig.legends) + [
        ax.get_legend() for ax in fig.axes if ax.get_legend() is not None
    ]
    assert len(legends) == 1
    box = legends[0].get_window_extent(renderer)
    for ax in data_axes(fig):
        assert ax.get_legend() is None
        assert not box.overlaps(ax.get_window_extent(renderer)), ax.get_ylabel()
    return legends[0]


# --- simulate ------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def sweep():
    """The quickstart half car with three damper settings (P = 3)."""
    cfg = suspopt.load_config(CONFIGS / "quickstart.yaml")
    return suspopt.simulate(
        cfg,
        params={
            "vehicle.corners.F1.damper.c": np.array([1500.0, 3000.0, 6000.0]),
            "vehicle.corners.R1.damper.c": np.array([2000.0, 3500.0, 7000.0]),
        },
    )


@pytest.mark.slow
def test_the_simulation_figure_has_time_psd_and_comfort_panels_for_every_design(sweep, tmp_path):
    signals = plots.default_signals(sweep)
    assert signals == [
        "body.heave_acc",
        "travel.F1",
        "travel.R1",
        "tyre_deflection.F1",
        "tyre_deflection.R1",
    ]
    labels = plots.design_labels(sweep.designs, [0, 1, 2], 3, sweep.diverged_at)
    assert labels[1] == "#1 F1.damper.c=3000, R1.damper.c=3500"
    fig = plots.simulation_figure(
        sweep.time,
        {n: sweep.signals[n] for n in signals},
        {n: sweep.signal_unit(n) for n in signals},
        labels,
    )
    axes = fig.axes
    assert len(axes) == 2 * len(signals) + 1
    for r, name in enumerate(signals):
        time_ax, psd_ax = axes[2 * r], axes[2 * r + 1]
        assert len(time_ax.get_lines()) == 3 and len(psd_ax.get_lines()) == 3
        assert time_ax.get_xlabel() == "time [s]"
        assert time_ax.get_ylabel() == f"{name} [{sweep.signal_unit(name)}]"
        assert psd_ax.get_xscale() == psd_ax.get_yscale() == "log"
        assert psd_ax.get_xlabel() == "frequency [Hz]" and psd_ax.get_title() == f"PSD of {name}"
        # the design's own data, unchanged
        np.testing.assert_array_equal(time_ax.get_lines()[2].get_ydata(), sweep.signals[name][2])
    assert axes[1].get_ylabel() == "PSD [(m/s^2)^2/Hz]"
    assert axes[3].get_ylabel() == "PSD [m^2/Hz]"
    comfort = axes[-1]
    assert [t.get_text() for t in comfort.get_xticklabels()] == ["body.heave_acc"]
    assert comfort.get_ylabel() == "Wk-weighted r.m.s. [m/s^2]"
    rms = suspopt.metrics.iso2631.weighted_rms(sweep.signals["body.heave_acc"], 1000.0, "Wk")
    points = [
        line.get_ydata()[0]
        for line in comfort.get_lines()
        if line.get_marker() != "None" and line.get_linestyle() == "None"
    ]
    np.testing.assert_allclose(points, rms)
    (second,) = comfort.child_axes
    bands = [t.get_text() for t in second.get_yticklabels()]
    assert "fairly uncomfortable" in bands and "uncomfortable" in bands
    legend = legend_outside_the_panels(fig)
    assert [t.get_text() for t in legend.get_texts()] == labels
    assert overlapping_texts(fig) == []


@pytest.mark.slow
def test_plot_simulation_writes_png_and_svg(sweep, tmp_path):
    png = plots.plot_simulation(sweep, tmp_path / "sim.png", signals=["body.heave_acc"])
    svg = plots.plot_simulation(sweep, tmp_path / "sim.svg", designs=[0, 2])
    assert png.read_bytes()[:8] == PNG
    text = svg.read_text()
    assert "<svg" in text[:1000] and "#2 F1.damper.c=6000" in text and "#1 F1" not in text
    assert text.count('id="axes_') == 2 * 5 + 2  # and the comfort bands' axis


def test_bad_signals_and_designs_are_value_errors_before_anything_is_written(sweep, tmp_path):
    path = tmp_path / "sim.png"
    with pytest.raises(
        ValueError, match="unknown signal 'body.heave_ac'; did you mean body.heave_acc"
    ):
        plots.plot_simulation(sweep, path, signals=["body.heave_ac"])
    with pytest.raises(ValueError, match="3 out of range: the result has 3 designs"):
        plots.plot_simulation(sweep, path, designs=[0, 3])
    with pytest.raises(ValueError, match="at most 8"):
        plots.plot_simulation(sweep, path, designs=range(9))
    with pytest.raises(ValueError, match="suffix must be one of"):
        plots.plot_simulation(sweep, tmp_path / "sim.pdf")
    # 0.5 was design 0; one signal name as a string was read letter by letter ("'b'")
    with pytest.raises(ValueError, match=r"give design indices, whole numbers; got \[0.5\]"):
        plots.plot_simulation(sweep, path, designs=[0.5])
    with pytest.raises(ValueError, match="unknown signal 'body.heave_ac';"):
        plots.plot_simulation(sweep, path, signals="body.heave_ac")
    assert list(tmp_path.iterdir()) == []


def test_each_plot_names_the_result_it_draws_when_given_another(sweep, tmp_path):
    """A config, a file name or None where a result belongs: a TypeError naming what to
    pass (AttributeErrors from inside before: "'Config' object has no attribute 'F'")."""
    path = tmp_path / "plot.png"
    for draw, needle in (
        (plots.plot_simulation, r"result must be a Result \(from suspopt.simulate\(cfg\)\)"),
        (plots.plot_optimisation, r"result must be a OptimisationResult \(from suspopt.optimise"),
        (
            plots.plot_kesort,
            r"selection must be a Selection \(from suspopt.choosing.selection.select",
        ),
    ):
        for wrong in (sweep.config, "front.h5", None):
            if draw is plots.plot_simulation and wrong is None:
                continue  # (covered by the other two)
            with pytest.raises(TypeError, match=needle):
                draw(wrong, path)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow
def test_more_designs_than_fit_are_thinned_evenly_and_the_title_says_so(tmp_path):
    cfg = suspopt.load_config(CONFIGS / "quickstart.yaml")
    res = suspopt.simulate(
        cfg, params={"vehicle.corners.F1.damper.c": np.linspace(1000.0, 8000.0, 20)}
    )
    chosen, note = plots.chosen_designs(20, None)
    assert chosen == [0, 3, 5, 8, 11, 14, 16, 19] and note.startswith("8 of 20 designs drawn")
    assert plots.chosen_designs(5, None) == ([0, 1, 2, 3, 4], "")
    path = plots.plot_simulation(res, tmp_path / "many.svg", signals=["body.heave_acc"])
    text = path.read_text()
    assert "8 of 20 designs drawn" in text and "#19 F1.damper.c=8000" in text  # (its corner)
    assert "#1 F1.damper.c" not in text
    names = [f"pick {i}" for i in range(20)]  # (the picks of simulate --pick)
    path = plots.plot_simulation(res, tmp_path / "named.svg", "body.heave_acc", design_names=names)
    assert "pick 19 F1.damper.c=8000" in path.read_text() and "#19" not in path.read_text()
    for wrong in (names[:19], [*names[:19], 3], "pick"):
        with pytest.raises(ValueError, match=r"design_names: give one text per design \(20\)"):
            plots.plot_simulation(res, tmp_path / "wrong.svg", design_names=wrong)
    assert not (tmp_path / "wrong.svg").exists()


def test_a_signal_every_design_shares_is_one_curve_and_one_design_has_no_legend():
    t = np.arange(0, 2.0, 0.005)
    body = np.tile(np.sin(2 * np.pi * t), (3, 1))
    seat = body * np.array([[0.5], [1.0], [2.0]])
    fig = plots.simulation_figure(
        t,
        {"body.heave_acc": body, "seat.acc": seat},
        {"body.heave_acc": "m/s^2", "seat.acc": "m/s^2"},
        ["a", "b", "c"],
    )
    body_ax, _, seat_ax, _, comfort = fig.axes
    assert len(body_ax.get_lines()) == 1 and body_ax.get_title() == "the same for all 3 designs"
    assert len(seat_ax.get_lines()) == 3
    assert [t.get_text() for t in comfort.get_xticklabels()] == ["body.heave_acc", "seat.acc"]
    single = plots.simulation_figure(t, {"seat.acc": seat[:1]}, {"seat.acc": "m/s^2"}, ["a"])
    assert single.legends == [] and single.axes[0].get_lines()[0].get_marker() == "None"


def test_the_comfort_panel_says_why_it_is_empty_below_100_hz():
    t = np.arange(0, 10.0, 0.02)  # 50 Hz
    fig = plots.simulation_figure(
        t, {"body.heave_acc": np.sin(t)[None]}, {"body.heave_acc": "m/s^2"}, ["design"]
    )
    comfort = fig.axes[-1]
    assert not comfort.axison and "needs 100 Hz or more" in comfort.texts[0].get_text()


def test_design_labels_show_what_varies_and_where_a_design_diverged():
    designs = {
        "vehicle.corners.F1.spring.linear": np.array([1e4, 2e4]),
        "vehicle.corners.R1.spring.linear": np.array([1e4, 3e4]),
        "vehicle.body.mass": np.array([300.0, 300.0]),
    }
    assert plots.design_labels(designs, [0, 1], 2, np.array([np.nan, 1.25])) == [
        "#0 F1.spring.linear=1e+04, R1.spring.linear=1e+04",
        "#1 F1.spring.linear=2e+04, R1.spring.linear=3e+04 (diverged at 1.25 s)",
    ]
    assert plots.design_labels({}, [0], 1, np.array([np.nan])) == ["design"]
    assert plots.design_labels({}, [0], 1, np.array([np.nan]), ["knee"]) == ["knee"]
    assert plots.design_labels(designs, [1], 2, np.array([np.nan, np.nan]), ["a", "b"]) == [
        "b F1.spring.linear=2e+04, R1.spring.linear=3e+04"
    ]


# --- optimise ------------------------------------------------------------------------------

HISTORY = {
    "generation": np.arange(1.0, 5.0),
    "evaluations": np.arange(1.0, 5.0) * 10,
    "time": np.arange(1.0, 5.0),
    "feasible": np.array([0.0, 0.2, 0.5, 0.9]),
    "hypervolume": np.array([np.nan, 0.2, 0.3, 0.35]),
    "best": np.array([[np.nan], [3.0], [2.5], [2.0]]),
}


@pytest.mark.slow
def test_two_objectives_draw_the_front_and_the_history(tmp_path):
    F = np.array([[1.0, 4.0], [2.0, 2.0], [3.0, 1.0], [1.5, 5.0], [1e10, 1e10]])
    G = np.array([[-1.0], [-0.5], [0.0], [0.3], [1.0]])
    fig = plots.optimisation_figure(F, G, ["RC", "X_ST"], ["m/s^2", "m"], HISTORY, "run")
    front, hv, share = fig.axes
    feasible, infeasible = front.collections
    np.testing.assert_array_equal(feasible.get_offsets(), F[:3])
    np.testing.assert_array_equal(infeasible.get_offsets(), F[3:4])  # the failed one: none
    assert (front.get_xlabel(), front.get_ylabel()) == ("RC [m/s^2]", "X_ST [m]")
    assert hv.get_ylabel() == "hypervolume (normalised) [-]"
    np.testing.assert_array_equal(hv.get_lines()[0].get_ydata(), HISTORY["hypervolume"])
    assert hv.get_title() == "generation 4: 0.35" and hv.get_xlim()[0] < 1.0
    assert share.get_ylabel() == "feasible share [-]" and share.get_xlabel() == "generation [-]"
    assert fig._suptitle.get_text() == "run (1 failed design not drawn)"
    legend = legend_outside_the_panels(fig)
    assert [t.get_text() for t in legend.get_texts()] == [
        "feasible",
        "infeasible (a constraint G > 0)",
    ]
    assert overlapping_texts(fig) == []


@pytest.mark.slow
def test_three_objectives_draw_every_pair():
    F = np.random.default_rng(1).random((12, 3))
    fig = plots.optimisation_figure(
        F, np.zeros((12, 0)), ["f1", "f2", "f3"], ["(m/s^2)^2", "m^2", "1"], HISTORY
    )
    panels = data_axes(fig)
    assert [(ax.get_xlabel(), ax.get_ylabel()) for ax in panels[:3]] == [
        ("f1 [(m/s^2)^2]", "f2 [m^2]"),
        ("f1 [(m/s^2)^2]", "f3 [-]"),
        ("f2 [m^2]", "f3 [-]"),
    ]
    assert len(panels) == 5 and len(panels[0].collections[0].get_offsets()) == 12
    legend_outside_the_panels(fig)  # in the grid's spare cell
    assert overlapping_texts(fig) == []


def test_one_objective_or_a_weighted_sum_draws_the_best_value():
    fig = plots.optimisation_figure(
        np.array([[2.0]]), np.array([[-1.0]]), ["f1"], ["(m/s^2)^2"], HISTORY
    )
    best, _share = fig.axes
    assert best.get_ylabel() == "best f1 [(m/s^2)^2]"
    assert best.get_title() == "best design: f1 = 2 (m/s^2)^2"
    np.testing.assert_array_equal(best.get_lines()[0].get_ydata(), HISTORY["best"][:, 0])
    weighted = plots.optimisation_figure(
        np.array([[2.0, 0.01]]),
        np.array([[-1.0]]),
        ["f1", "f3"],
        ["(m/s^2)^2", "m^2"],
        HISTORY,
        weights=np.array([1.0, 100.0]),
    )
    best, _ = weighted.axes
    assert best.get_ylabel() == "best weighted sum [-]"
    assert best.get_title() == "best design: f1 = 2 (m/s^2)^2, f3 = 0.01 m^2"
    assert overlapping_texts(weighted) == []


@pytest.mark.slow
def test_plot_optimisation_draws_a_run(tmp_path):
    from suspopt.optimisation import optimise

    path = tmp_path / "ps.yaml"
    path.write_text(tiny((CONFIGS / "ch8/pareto_ps_class_a.yaml").read_text(), 1.5))
    result = optimise(suspopt.load_config(path), tmp_path / "ps.h5")
    png = plots.plot_optimisation(result, tmp_path / "ps.png")
    svg = plots.plot_optimisation(result, tmp_path / "ps.svg")
    assert png.read_bytes()[:8] == PNG
    text = svg.read_text()
    assert "ps.h5 (finished)" in text and "RC_se" in text and text.count('id="axes_') == 3


# --- the models figure (Figs. 3.2-3.24) -----------------------------------------------------


def coinciding(n: int = 4):
    t = np.linspace(0.0, 5.0, 2000)
    y = np.exp(-t) * np.sin(2 * np.pi * t)
    f = np.linspace(0.1, 30.0, 300)
    return (
        {"body.heave_acc": [(f"model {i}", t, y) for i in range(n)]},
        {"body.heave_acc": [(f"model {i}", f, 1 / f) for i in range(n)]},
        {"body.heave_acc": "m/s^2", "PSD of body.heave_acc": "(m/s^2)^2/Hz"},
    )


def test_coinciding_model_curves_get_distinct_styles_and_interleaved_markers():
    fig = plots.model_figure("models", *coinciding())
    for ax in data_axes(fig):
        lines = ax.get_lines()
        assert len(lines) == 4
        styles = [(l.get_color(), str(l.get_linestyle()), l.get_marker()) for l in lines]
        assert len(set(styles)) == 4
        widths = [l.get_linewidth() for l in lines]
        # drawn widest first: each curve shows at both edges of the narrower ones on it
        assert all(a - b >= 0.5 for a, b in pairwise(widths))
        marks = [set(l.get_markevery()) for l in lines]
        assert all(len(m) >= 6 for m in marks)
        assert all(not a & b for a, b in combinations(marks, 2))
        np.testing.assert_array_equal(lines[3].get_ydata(), lines[0].get_ydata())
    legend = legend_outside_the_panels(fig)
    assert [t.get_text() for t in legend.get_texts()] == [f"model {i}" for i in range(4)]
    assert overlapping_texts(fig) == []


def test_coinciding_model_curves_all_show_their_colour():
    """Four identical curves: every model's colour covers a fair share of pixels (with one
    width and no markers the ones underneath showed a few dozen)."""
    from matplotlib.colors import to_rgb

    fig = drawn(plots.model_figure("models", *coinciding()))
    image = np.asarray(fig.canvas.buffer_rgba())[..., :3] / 255.0
    ax = fig.axes[0]
    x0, y0, x1, y1 = ax.get_window_extent().extents.astype(int)
    panel = image[image.shape[0] - y1 : image.shape[0] - y0, x0:x1]
    shown = [
        int((np.abs(panel - to_rgb(line.get_color())).max(axis=-1) < 0.08).sum())
        for line in ax.get_lines()
    ]
    assert min(shown) >= 150, shown


@pytest.mark.slow
def test_analyse_models_figure_uses_the_styles(tmp_path):
    from suspopt.analyse.models import compare_models, plot_models

    paths = []
    for name in ("part1a_qc_bump", "part1a_hc1_bump"):
        text = (
            (CONFIGS / "ch3" / f"{name}.yaml").read_text().replace("duration: 9.0", "duration: 3.0")
        )
        paths.append(tmp_path / f"{name}.yaml")
        paths[-1].write_text(text)
    svg = plot_models(compare_models(paths), tmp_path / "m.svg", "QC and HC1")
    text = svg.read_text()
    # one legend (two entries), five panels and the legend's cell
    assert text.count("part1a_hc1_bump") == 1 and text.count('id="axes_') == 6


# --- labels and the matplotlib dependency --------------------------------------------------


def test_comfort_labels_that_would_touch_are_left_out_and_their_lines_stay():
    fig, (ax,) = plots.new_figure(1)
    ax.set_xlim(0.0, 60.0)
    plots.draw_comfort_levels(ax, "x")
    assert len(ax.get_lines()) == 5
    assert [t.get_text() for t in ax.texts] == ["a little uncomfortable"]
    assert overlapping_texts(fig) == []
    fig, (ax,) = plots.new_figure(1)
    ax.set_ylim(0.05, 5.0)
    ax.set_yscale("log")
    plots.draw_comfort_levels(ax, "y", outside=True)
    (second,) = ax.child_axes
    assert [t.get_text() for t in second.get_yticklabels()] == [
        label for _, _, label in suspopt.metrics.COMFORT_REACTIONS[1:]
    ]


def test_without_matplotlib_every_figure_is_a_clear_value_error(sweep, tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib.figure", None)  # import fails
    history = dict(HISTORY)
    for draw in (
        lambda p: plots.plot_simulation(sweep, p),
        lambda p: plots.model_comparison(p, "m", *coinciding()),
        lambda p: plots.save(
            plots.optimisation_figure(np.ones((1, 1)), np.zeros((1, 1)), ["f"], ["m"], history), p
        ),
    ):
        with pytest.raises(
            ValueError,
            match=r"--plot needs matplotlib, a dependency of suspopt .*: pip install matplotlib",
        ):
            draw(tmp_path / "f.png")
    assert list(tmp_path.iterdir()) == []


def test_importing_the_plots_module_does_not_import_matplotlib():
    code = "import sys, suspopt.plots; print('matplotlib' in sys.modules)"
    out = subprocess.run(
        [sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, check=True
    )
    assert out.stdout.strip() == "False"


@pytest.mark.parametrize("home_writable", [False, True])
def test_an_unwritable_home_gives_matplotlib_a_private_folder(tmp_path, monkeypatch, home_writable):
    """A container's or CI's user whose HOME cannot be written: matplotlib printed two
    warning lines on every plotting run and rebuilt its font cache each time. Its folders
    then go to a private folder of the user in the temporary directory."""
    import os
    import tempfile

    from suspopt.plots import style

    home = tmp_path / "home"
    if home_writable:
        home.mkdir()
    else:
        (tmp_path / "file").write_text("")
        home = tmp_path / "file" / "home"  # (cannot be made: under a file)
    for variable in ("MPLCONFIGDIR", "XDG_CONFIG_HOME", "XDG_CACHE_HOME"):
        monkeypatch.delenv(variable, raising=False)
    monkeypatch.setenv("HOME", str(home))
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path / "tmp"))
    (tmp_path / "tmp").mkdir()
    monkeypatch.delitem(sys.modules, "matplotlib", raising=False)  # (as in a fresh process)
    style._matplotlib_folders()
    private = tmp_path / "tmp" / f"suspopt-matplotlib-{os.getuid()}"
    if home_writable:
        assert "MPLCONFIGDIR" not in os.environ and not private.exists()
        assert (home / ".config" / "matplotlib").is_dir()
    else:
        assert os.environ["MPLCONFIGDIR"] == str(private)
        assert private.is_dir() and private.stat().st_mode & 0o777 == 0o700


def test_the_psd_panel_has_the_record_psd_points_and_no_noise_floor():
    """The simulation figure's PSD is :func:`record_psd`'s (segments of PSD_SEGMENT or the
    record: 1/3 Hz for 3 s), within the band, and its value axis stops PSD_DECADES decades
    below the highest value, however far the computed values fall."""
    from suspopt.metrics.spectral import PSD_SEGMENT, record_psd
    from suspopt.plots.style import PSD_BAND, PSD_DECADES

    t = np.arange(0, 3.0, 0.001)
    y = np.exp(-(((t - 1.5) / 0.1) ** 2))  # (a smooth pulse: its PSD falls to numerical noise)
    fig = plots.simulation_figure(
        t, {"body.heave_acc": y[None]}, {"body.heave_acc": "m/s^2"}, ["a"]
    )
    (line,) = fig.axes[1].get_lines()
    f, p = record_psd(y, 1000.0)
    band = (f >= PSD_BAND[0]) & (f <= PSD_BAND[1])
    np.testing.assert_array_equal(line.get_xdata(), f[band])
    assert np.diff(line.get_xdata()) == pytest.approx(1.0 / min(PSD_SEGMENT, 3.0))
    low, high = fig.axes[1].get_ylim()
    assert p[band].min() < low  # (the computed noise is off the axis)
    assert np.log10(high / low) == pytest.approx(PSD_DECADES + 0.2)
    assert high > p[band].max()


def test_spectrum_limits_span_the_values_or_the_decades_below_the_highest():
    from suspopt.plots.style import spectrum_limits

    low, high = spectrum_limits(np.array([1e-3, 1e-2, 1.0, np.nan, 0.0]))
    assert low == pytest.approx(1e-3 / 10**0.1) and high == pytest.approx(10**0.1)
    low, _ = spectrum_limits(np.array([1e-16, 2.0]), decades=3)
    assert low == pytest.approx(2e-3 / 10**0.1)
    assert spectrum_limits(np.array([0.0, np.nan, -1.0])) is None
