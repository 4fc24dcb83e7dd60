"""The report's charts as a browser draws them: each read back from the rendered plotly figure
(its data, its axes' ranges and titles, its legend and its labels' boxes on screen), on one
small page built once (a three-objective front with a seat, and its kesort file)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import h5py
import numpy as np
import pytest
from test_report import _browser, _invoke, _wait

from suspopt.metrics.spectral import PSD_SEGMENT, record_psd
from suspopt.plots.style import PSD_BAND, PSD_DECADES
from suspopt.templates import template_text

pytest.importorskip("plotly")
pytestmark = [pytest.mark.browser, pytest.mark.slow]


@pytest.fixture(scope="module")
def page(tmp_path_factory) -> Path:
    """A front of three objectives with a seat whose parameters are not designed (each pick
    has the same transmissibility), its kesort file (picks that share a design), and their
    report."""
    folder = tmp_path_factory.mktemp("charts")
    text = template_text("kesort").replace("population: 40 ", "population: 16 ")
    (folder / "three.yaml").write_text(text.replace("generations: 10 ", "generations: 5 "))
    front, picks, out = folder / "three.h5", folder / "picks.h5", folder / "charts.html"
    assert _invoke("optimise", folder / "three.yaml", "-o", front).exit_code == 0
    assert _invoke("kesort", front, "-o", picks).exit_code == 0
    assert _invoke("report", front, picks, "-o", out).exit_code == 0
    return out


@pytest.fixture(scope="module")
def shown(page):
    """The page open in headless Chromium, drawn."""
    driver = _browser()
    driver.get(page.resolve().as_uri())
    _wait(driver, "return document.body.getAttribute('data-rendered')", "the plots rendered")
    yield driver
    driver.quit()


def _payload(page: Path) -> dict:
    found = re.search(
        r"<script type='application/json' id='suspopt-data'>(.*?)</script>", page.read_text(), re.S
    )
    assert found
    return json.loads(found.group(1))


def test_every_history_series_is_on_an_axis_that_shows_it(page, shown):
    """One panel per series of /history, each on its own y axis titled with its quantity and
    unit, every value inside the axis' visible range and spanning a visible part of it."""
    panels = shown.execute_script(
        "const div = document.getElementById('history-0'), fl = div._fullLayout;"
        " return div.data.map(t => { const ya = fl[t.yaxis.replace('y', 'yaxis')],"
        " xa = fl[t.xaxis.replace('x', 'xaxis')];"
        " return [t.name, t.y, ya.range, ya.title.text, xa.range, xa.title.text]; })"
    )
    with h5py.File(page.with_name("three.h5")) as h5:
        names = [str(n) for n in h5["history/best"].attrs["names"]]
        units = [str(u) for u in h5["history/best"].attrs["units"]]
        hypervolume = h5["history/hypervolume"][()]
    expected = [f"best {n}" for n in names] + ["hypervolume (normalised)", "feasible share"]
    assert [p[0] for p in panels] == expected
    titles = [f"best {n} [{u}]" for n, u in zip(names, units)]
    assert [p[3] for p in panels] == titles + ["hypervolume (normalised) [1]", "feasible share [1]"]
    assert np.nanmax(hypervolume) > 1.05  # (the old shared [0, 1.05] axis hid it)
    for name, y, (low, high), _title, x_range, x_title in panels:
        values = np.array([v for v in y if v is not None])
        assert values.size and low <= values.min() and values.max() <= high, name
        if name != "feasible share":  # (a share keeps its 0-1 axis)
            assert np.ptp(values) >= 0.5 * (high - low), name
        assert x_title == "generation [1]" and x_range[0] < 1 and x_range[1] > 5
    shown.execute_script(  # a best value that did not change: its axis about it, not about 0
        "const div = document.createElement('div'); div.id = 'flat'; document.body.appendChild(div);"
        " window.suspoptCharts.history(div, {generation: [1, 2, 3], best: [[null, 0.007, 0.007]],"
        " best_names: ['X_ST'], best_units: ['m'], feasible: [0, 1, 1]})"
        ".then(() => div.setAttribute('data-done', '1'))"
    )
    _wait(shown, "return document.getElementById('flat').hasAttribute('data-done')", "drawn")
    low, high = shown.execute_script(
        "return document.getElementById('flat')._fullLayout.yaxis.range"
    )
    assert 0.0065 <= low < 0.007 < high <= 0.0075


def _select_signal(driver, name: str) -> None:
    driver.execute_script(
        "const s = document.getElementById('s-1'); s.value = arguments[0];"
        " s.dispatchEvent(new Event('change'));",
        name,
    )
    _wait(
        driver,
        "return document.getElementById('psd-1').layout.yaxis.title.text"
        f".includes({json.dumps(name)})",
        f"the spectrum of {name} drawn",
    )


def test_the_spectrum_has_the_plot_estimators_resolution_and_shows_the_body_mode(page, shown):
    """The PSD's points are those of :func:`record_psd` (the ``--plot`` figure's estimator),
    spaced 1/(its segment) Hz, within the figures' band; the body's heave mode lies among the
    drawn points; the value axis spans at most
    PSD_DECADES decades below the highest value, and every drawn point of the highest."""
    from suspopt.choosing.picks import read_picks
    from suspopt.simulation import prepare
    from suspopt.vehicle import modal_analysis

    _select_signal(shown, "body.heave_acc")
    x, curves, x_range, y_range, title = shown.execute_script(
        "const div = document.getElementById('psd-1'), fl = div._fullLayout;"
        " return [div.data[0].x, div.data.map(t => t.y), fl.xaxis.range, fl.yaxis.range,"
        " fl.yaxis.title.text]"
    )
    signals = _payload(page)["studies"][1]["data"]["signals"]
    row = signals["rows"][0]
    picked = read_picks(page.with_name("picks.h5"), [str(row)])
    duration, fs = picked.config.simulation.duration, picked.config.simulation.output_rate
    assert signals["time"][-1] == pytest.approx(duration)
    f, _ = record_psd(np.zeros(int(round(duration * fs)) + 1), fs)
    band = f[(f >= PSD_BAND[0]) & (f <= PSD_BAND[1])]
    assert np.diff(x) == pytest.approx(1.0 / min(PSD_SEGMENT, duration), rel=1e-3)
    assert x == pytest.approx(band.tolist(), rel=1e-12)
    assert title == "PSD of body.heave_acc [(m/s^2)^2/Hz]"
    modes = modal_analysis(prepare(picked.config, picked.params()).model)
    body = float(modes.frequency[0][list(modes.dominant[0]).index("body.heave")])
    assert 0.5 < body < 3.0
    assert 10 ** x_range[0] <= x[0] < body < x[-1] <= 10 ** x_range[1]
    assert np.min(np.abs(np.array(x) - body)) <= 0.5 / min(PSD_SEGMENT, duration)
    values = np.array([v for c in curves for v in c if v is not None], dtype=float)
    top = np.log10(values.max())
    assert y_range[0] >= top - PSD_DECADES - 0.2 and y_range[1] >= top


def _groups(curves) -> list[list[int]]:
    """The indices of ``curves`` in groups of curves equal to 1e-12 of their largest value."""
    groups: list[list[int]] = []
    for k, c in enumerate(curves):
        c = np.array(c, dtype=float)
        for g in groups:
            ref = np.array(curves[g[0]], dtype=float)
            if np.nanmax(np.abs(c - ref)) <= 1e-12 * max(
                np.nanmax(np.abs(c)), np.nanmax(np.abs(ref))
            ):
                g.append(k)
                break
        else:
            groups.append([k])
    return groups


def test_the_transmissibility_legend_has_one_entry_per_distinct_curve(page, shown):
    """Curves the same to 1e-12 are one line and one legend entry, naming every design
    that shares it (here the seat is not designed: every pick's is the same)."""
    data = _payload(page)["studies"][1]["data"]
    tr = data["signals"]["transmissibility"]
    ids = data.get("ids") or [str(r) for r in range(data["rows"])]
    names, entries = shown.execute_script(
        "const div = document.getElementById('tr-1');"
        " return [div.data.map(t => t.name), div.querySelectorAll('.legend .traces').length]"
    )
    expected = []
    for dof, curves in tr["dofs"].items():
        prefix = "STHT (head)" if dof == "head" else dof
        for g in _groups(curves):
            expected.append(prefix + ", " + ", ".join(f"design {ids[tr['rows'][k]]}" for k in g))
    assert names == expected and entries == len(expected)
    assert len(expected) == 2 < sum(len(c) for c in tr["dofs"].values())


def test_the_time_histories_merge_only_identical_curves(page, shown):
    """The time histories of the picks: one line per distinct history over the whole run,
    thinned with the highest and lowest values kept; the spectrum record_psd's of the whole
    history."""
    data = _payload(page)["studies"][1]["data"]
    signals = data["signals"]
    ids = data.get("ids") or [str(r) for r in range(data["rows"])]
    _select_signal(shown, "seat.acc")
    names, x_range = shown.execute_script(
        "const div = document.getElementById('signal-1');"
        " return [div.data.map(t => t.name), div._fullLayout.xaxis.range]"
    )
    groups = _groups(signals["signals"]["seat.acc"])
    assert names == [", ".join(f"design {ids[signals['rows'][k]]}" for k in g) for g in groups]
    assert x_range[0] <= signals["time"][0] and x_range[1] >= signals["time"][-1]
    import suspopt
    from suspopt.choosing.picks import read_picks

    picked = read_picks(page.with_name("picks.h5"), [str(signals["rows"][0])])
    y = suspopt.simulate(picked.config, picked.params()).signals["seat.acc"][0]
    drawn = np.array(signals["signals"]["seat.acc"][0], dtype=float)
    assert len(drawn) == len(signals["time"]) < len(y)  # (thinned, its peaks kept)
    assert [drawn.min(), drawn.max()] == pytest.approx([y.min(), y.max()], rel=1e-12)
    f, p = record_psd(y, picked.config.simulation.output_rate)  # (the spectrum: --plot's)
    band = (f >= PSD_BAND[0]) & (f <= PSD_BAND[1])
    assert signals["psd"]["seat.acc"][0] == pytest.approx(p[band].tolist(), rel=1e-9)


def _labels(driver, i: int) -> list:
    return driver.execute_script(
        "const div = document.getElementById('front-' + arguments[0]);"
        " return [...div.querySelectorAll('.annotation')].map(a => {"
        " const r = a.querySelector('.annotation-text-g').getBoundingClientRect();"
        " return [a.textContent, [r.left, r.top, r.right, r.bottom]]; })",
        i,
    )


def _overlap(a, b) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def test_pick_labels_do_not_overlap_and_name_every_pick(page, shown):
    """Each point of the picks has one label naming every pick there, and no two labels'
    boxes overlap on screen, for the first pair of objectives and another pair."""
    data = _payload(page)["studies"][1]["data"]
    picks = data["picks"]
    for x, y in (("F:0", "F:1"), ("F:1", "F:2")):
        shown.execute_script(
            "document.getElementById('front-1').removeAttribute('data-labelled');"
            " document.getElementById('x-1').value = arguments[0];"
            " const s = document.getElementById('y-1'); s.value = arguments[1];"
            " s.dispatchEvent(new Event('change'));",
            x,
            y,
        )
        _wait(
            shown,
            "return document.getElementById('front-1').hasAttribute('data-labelled')",
            "the labels placed",
        )
        labels = _labels(shown, 1)
        jx, jy = int(x[2:]), int(y[2:])
        points = {(data["F"][r][jx], data["F"][r][jy]) for r in picks.values()}
        assert len(labels) == len(points)
        named = sorted(n for text, _ in labels for n in text.split(", "))
        assert named == sorted(picks)
        boxes = [b for _, b in labels]
        for k, a in enumerate(boxes):
            for b in boxes[k + 1 :]:
                assert not _overlap(a, b), labels
        assert any(", " in text for text, _ in labels)  # (picks that share a design: one label)
        marks = shown.execute_script(  # (one marker per point, its hover naming its picks)
            "const t = document.getElementById('front-1').data.find(t => t.name === 'picks');"
            " return t.x.map((x, k) => [x, t.y[k], t.text[k]])"
        )
        assert sorted(marks) == sorted(
            [a["x"], a["y"], a["text"]] for a in shown.execute_script(
                "return document.getElementById('front-1').layout.annotations"
            )
        )  # fmt: skip
