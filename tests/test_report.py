"""``suspopt report``: the self-contained Pareto explorer, checked as text and in headless
Chromium (the ``browser`` tests: Debian's chromium and chromium-driver, which ``.ci/run``
installs; without them the browser tests skip, unless ``SUSPOPT_BROWSER_REQUIRED=1``)."""

from __future__ import annotations

import json
import os
import re
import shlex
import shutil
import time
from pathlib import Path

import h5py
import numpy as np
import pytest
from conftest import CONFIGS, tiny
from typer.testing import CliRunner

import suspopt
from suspopt.cli import app
from suspopt.report import collect
from suspopt.templates import template_text

pytest.importorskip("plotly")

runner = CliRunner()


def _invoke(*args):
    return runner.invoke(app, [str(a) for a in args])


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> dict[str, Path]:
    """A seat front (spectral, fast), its kesort file and its pseudo-fronts on class B, a
    robust front, and a front of three objectives; each written by the commands."""
    folder = tmp_path_factory.mktemp("report")
    text = template_text("spectral").replace("population: 40 ", "population: 12 ")
    text = text.replace("generations: 25 ", "generations: 3 ")
    text = text.replace("# A seat designed", "# </script><script>alert(1)</script> A seat designed")
    (folder / "seat.yaml").write_text(text)
    out = {
        "front": folder / "front.h5",
        "kesort": folder / "picks.h5",
        "roads": folder / "roads.h5",
    }
    assert _invoke("optimise", folder / "seat.yaml", "-o", out["front"]).exit_code == 0
    assert _invoke("kesort", out["front"], "-o", out["kesort"]).exit_code == 0
    res = _invoke("analyse", "roads", out["front"], "--road", "B", "-o", out["roads"])
    assert res.exit_code == 0, res.output
    robust = template_text("robust").replace("population: 30 ", "population: 8 ")
    (folder / "robust.yaml").write_text(robust.replace("generations: 15 ", "generations: 2 "))
    out["robust"] = folder / "robust.h5"
    assert _invoke("optimise", folder / "robust.yaml", "-o", out["robust"]).exit_code == 0
    three = template_text("kesort").replace("population: 40 ", "population: 16 ")
    (folder / "three.yaml").write_text(three.replace("generations: 10 ", "generations: 5 "))
    out["three"] = folder / "three.h5"  # (three objectives: a 3D front)
    assert _invoke("optimise", folder / "three.yaml", "-o", out["three"]).exit_code == 0
    return out


#: Each chapter's report, from tiny runs of its bundled configs (Chapters 3-4 simulate given
#: designs: they have no design sets to explore): (configs, what is made of the fronts).
CHAPTERS = {
    "ch5": (["ch5/case1_s1"], None),
    "ch6": (["ch6/part_b"], "kesort"),
    "ch7": (["ch7/sh_2"], "controllers"),
    "ch8": (["ch8/pareto_ps_class_a"], "roads"),
}


@pytest.fixture(scope="module")
def chapters(tmp_path_factory) -> dict[str, Path]:
    """Each chapter's report page (examples/chapter_reports.sh does the same at full
    budget)."""
    folder = tmp_path_factory.mktemp("chapters")
    pages = {}
    for chapter, (names, then) in CHAPTERS.items():
        fronts = []
        for name in names:
            config = folder / f"{name.replace('/', '_')}.yaml"
            config.write_text(tiny((CONFIGS / f"{name}.yaml").read_text(), 2.0, 8, 2))
            front = config.with_suffix(".h5")
            assert _invoke("optimise", config, "-o", front).exit_code == 0
            fronts.append(front)
        if then == "kesort":
            fronts.append(folder / f"{chapter}_kesort.h5")
            res = _invoke("kesort", fronts[0], "--keep-infeasible", "-o", fronts[-1])
            assert res.exit_code == 0, res.output
        elif then == "controllers":
            fronts.append(folder / f"{chapter}_cdf.h5")
            res = _invoke("analyse", "controllers", fronts[0], "--with",
                          CONFIGS / "ch7" / "sh_2_cdf.yaml", "-o", fronts[-1])  # fmt: skip
            assert res.exit_code == 0, res.output
        elif then == "roads":
            fronts.append(folder / f"{chapter}_roads.h5")
            res = _invoke("analyse", "roads", fronts[0], "--road", "B", "-o", fronts[-1])
            assert res.exit_code == 0, res.output
        pages[chapter] = folder / f"{chapter}.html"
        res = _invoke("report", *fronts, "--title", f"Chapter {chapter[2:]}", "-o", pages[chapter])
        assert res.exit_code == 0, res.output
    return pages


def _payload(page: str) -> dict:
    found = re.search(
        r"<script type='application/json' id='suspopt-data'>(.*?)</script>", page, re.S
    )
    assert found
    return json.loads(found.group(1))


@pytest.mark.slow
def test_the_page_holds_every_design_and_nothing_from_a_file_as_markup(files, tmp_path):
    page = tmp_path / "study.html"
    res = _invoke("report", files["front"], files["kesort"], files["roads"], "-o", page,
                  "--with-signals", "0")  # fmt: skip
    assert res.exit_code == 0, res.output
    text = page.read_text()
    assert "<meta name='generator' content='suspopt" in text[:4096]
    assert "<script src" not in text and "<link" not in text  # everything inline
    assert "alert(1)</script>" not in text  # the config's text is escaped everywhere
    studies = _payload(text)["studies"]
    with h5py.File(files["front"]) as h5:
        N = len(h5["pareto/X"])
    assert [s["data"]["rows"] for s in studies] == [N, N, N]
    assert [s["kind"] for s in studies] == ["optimise", "kesort", "roads"]
    front, kesort, roads = (s["data"] for s in studies)
    assert len(front["F"]) == N and "history" in front and front["feasible"]
    assert "k_eps" in kesort and "chosen" in kesort["picks"]
    assert roads["pseudo"] and len(roads["pseudo"][0]["F"]) == N
    assert 0 in front["signals"]["rows"] and "seat.acc" in front["signals"]["signals"]
    tr = front["signals"]["transmissibility"]  # a seat: floor to seat (Eq 2.86, linearised)
    assert sorted(tr["rows"]) == sorted(front["signals"]["rows"]) and len(
        tr["dofs"]["seat"]
    ) == len(tr["rows"])
    assert len(front["signals"]["time"]) <= 1000
    assert page.stat().st_size < 10 << 20
    seat = suspopt.load_config(files["front"].with_name("seat.yaml")).design_variables
    robust = collect(files["robust"]).data  # (a design at a bound: the others have none)
    both = suspopt.load_config(files["robust"].with_name("robust.yaml")).design_variables
    for study, variables in [(front, seat), (kesort, seat), (roads, seat), (robust, both)]:
        bounds = [[v.lower for v in variables], [v.upper for v in variables]]
        assert study["variable_bounds"] == bounds  # each variable's search range
        assert study["at_bound"] == at_bound(variables, study["X"])
    assert "-" in "".join(robust["at_bound"]) or "+" in "".join(robust["at_bound"])
    with h5py.File(files["front"]) as h5:  # the config's own design, where the file has it
        own = {k: h5[f"baseline/{k}"][0].tolist() for k in "FXG"}
    assert front["baseline"] == own and "baseline" not in kesort and "baseline" not in roads


def at_bound(variables, X) -> list[str]:
    """Per variable, a character per design of ``X``: ``-`` within 1 % of the variable's
    search range (of log10 for a log scale) of the lower bound, ``+`` of the upper, ``.``
    neither."""
    out = []
    for j, v in enumerate(variables):
        f = np.log10 if v.scale == "log" else float
        where = [(f(row[j]) - f(v.lower)) / (f(v.upper) - f(v.lower)) for row in X]
        out.append("".join("-" if w <= 0.01 else "+" if w >= 0.99 else "." for w in where))
    return out


@pytest.mark.parametrize(
    "args, message",
    [
        (["{yaml}"], "not an HDF5 file"),
        (["{front}", "--with-signals", "knees"], "error: --with-signals knees: "),
        (["{front}", "--with-signals", "9999"], "error: --with-signals 9999: "),
        (["{text}"], "not an HDF5 file"),
        (["{missing}"], "no such file"),
    ],
)
def test_bad_input_is_one_line_and_writes_nothing(files, tmp_path, args, message):
    (tmp_path / "notes.txt").write_text("not a result\n")
    names = {"yaml": files["front"].with_name("seat.yaml"), "front": files["front"],
             "text": tmp_path / "notes.txt", "missing": tmp_path / "none.h5"}  # fmt: skip
    page = tmp_path / "out.html"
    res = _invoke("report", *[a.format(**names) for a in args], "-o", page)
    assert res.exit_code == 2, res.output
    assert message in res.output and len(res.output.strip().splitlines()) == 1
    assert not page.exists()


def test_an_existing_file_of_someone_else_is_not_replaced(files, tmp_path):
    page = tmp_path / "mine.html"
    page.write_text("<html>my own page</html>")
    res = _invoke("report", files["front"], "-o", page)
    assert res.exit_code == 2 and "mine.html" in res.output
    assert page.read_text() == "<html>my own page</html>"


def test_a_page_over_its_size_is_refused_once_its_data_show_it(files, tmp_path, monkeypatch):
    """The page is refused when it would pass ``MAX_BYTES`` (10 MB), and as soon as the data
    of the files read so far pass it: 200 files were all read (20 s, 0.9 GB) before."""
    import suspopt.report as report
    from suspopt.report.page import data_bytes

    one = data_bytes(report.collect(files["front"]))
    read = []
    collect = report.collect

    def counted(path, with_signals=()):
        read.append(path)
        return collect(path, with_signals)

    monkeypatch.setattr(report, "collect", counted)
    monkeypatch.setattr(report, "MAX_BYTES", int(1.5 * one))
    page = tmp_path / "out.html"
    res = _invoke("report", *[files["front"]] * 10, "-o", page)
    assert res.exit_code == 2, res.output
    assert res.output.startswith(
        "error: report: the page would be more than 0 MB (the data of its first 2 of 10 files"
    ), res.output
    assert res.output.strip().endswith("MB): give fewer files"), res.output  # (no rows asked)
    assert len(read) == 2 and not page.exists()
    monkeypatch.setattr(report, "MAX_BYTES", one + 1)  # the data fit; the page does not
    res = _invoke("report", files["front"], "-o", page)
    assert res.exit_code == 2 and "error: report: the page would be more than 0 MB (" in res.output
    assert len(res.output.strip().splitlines()) == 1 and not page.exists()
    res = _invoke("report", files["front"], "-o", page, "--with-signals", "0")  # (rows asked)
    assert res.output.strip().endswith("give fewer --with-signals designs or fewer files")
    assert res.exit_code == 2 and not page.exists()


def _browser():
    """A headless Chromium driven by selenium, or a skip (a failure when required)."""
    required = os.environ.get("SUSPOPT_BROWSER_REQUIRED") == "1"
    chromium, driver = shutil.which("chromium"), shutil.which("chromedriver")
    try:
        from selenium import webdriver
        from selenium.webdriver.chrome.service import Service
    except ImportError:
        webdriver = None
    if webdriver is None or chromium is None or driver is None:
        if required:
            pytest.fail(
                "SUSPOPT_BROWSER_REQUIRED=1 but chromium, chromedriver or selenium is missing"
            )
        pytest.skip("needs chromium, chromium-driver (Debian) and selenium")
    options = webdriver.ChromeOptions()
    options.binary_location = chromium
    for arg in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                "--window-size=1400,2600"):  # fmt: skip
        options.add_argument(arg)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL", "performance": "ALL"})
    return webdriver.Chrome(options=options, service=Service(driver))


def _wait(browser, script: str, what: str, seconds: float = 30.0):
    deadline = time.monotonic() + seconds
    while not (value := browser.execute_script(script)):
        assert time.monotonic() < deadline, f"{what} in {seconds:.0f} s"
        time.sleep(0.05)
    return value


@pytest.fixture(scope="module")
def browser():
    driver = _browser()
    yield driver
    driver.quit()


@pytest.mark.browser
@pytest.mark.slow
@pytest.mark.parametrize("which", [*CHAPTERS, "robust"])
def test_the_report_in_a_real_browser(files, chapters, browser, tmp_path, monkeypatch, which):
    """In headless Chromium: the plots render, the console has no error, the front has one
    point per design, a click shows the design's row, and the page asks the network for
    nothing. A screenshot is kept in ``$SUSPOPT_ARTEFACTS`` (default: the test's folder):
    one per chapter's report and per kind of file."""
    if which in chapters:
        page = chapters[which]
        N = _payload(page.read_text())["studies"][0]["data"]["rows"]
    else:
        page = tmp_path / f"{which}.html"
        assert _invoke("report", files[which], "-o", page).exit_code == 0
        with h5py.File(files[which]) as h5:
            N = len(h5["kesort/X" if which == "kesort" else "pareto/X"])
    browser.get_log("performance")  # (what earlier pages asked for)
    browser.get_log("browser")
    browser.get(page.resolve().as_uri())
    _wait(browser, "return document.body.getAttribute('data-rendered')", "the plots rendered")
    _wait(  # (on screen in this window: drawn after the rest)
        browser, "return document.getElementById('parallel-0').hasAttribute('data-drawn')",
        "the first parallel coordinates drew",
    )  # fmt: skip
    errors = [e for e in browser.get_log("browser") if e["level"] == "SEVERE"]
    assert errors == []
    points, drawn = browser.execute_script(
        "return [window.suspoptReport.studies[0].points,"
        " document.getElementById('front-0').data[0].x.length]"
    )
    assert points == drawn == N
    every = browser.execute_script(  # every study of the page: one point per design
        "return window.suspoptReport.studies.map((s, i) =>"
        " [s.points, document.getElementById('front-' + i).data[0].x.length])"
    )
    assert all(p == d for p, d in every) and len(every) == len(
        _payload(page.read_text())["studies"]
    )
    row = N - 1
    browser.execute_script(
        "document.getElementById('front-0')"
        ".emit('plotly_click', {points: [{customdata: arguments[0]}]})",
        row,
    )
    shown = browser.execute_script(
        "const box = document.getElementById('design-0');"
        " return [box.getAttribute('data-row'), box.textContent, window.suspoptReport.selected.row]"
    )
    assert shown[0] == str(row) and f"design {row}" in shown[1] and shown[2] == row
    study = _payload(page.read_text())["studies"][0]["data"]
    lower, upper = study["variable_bounds"]
    ranges = browser.execute_script(  # a variable's axis spans its search range
        "return document.getElementById('parallel-0').data[0].dimensions.map(d => d.range)"
    )[len(study["objectives"]) :]
    for j, (lo, hi) in enumerate(zip(lower, upper)):
        values = [r[j] for r in study["X"] if r[j] is not None]
        assert ranges[j] == pytest.approx([min(lo, *values), max(hi, *values)], rel=1e-12)
    bounded = [r for r in range(N) if any(sides[r] != "." for sides in study["at_bound"])]
    for r in {row, *bounded[:2]}:  # the panel says which values lie at a bound
        browser.execute_script("window.suspoptReport.select(0, arguments[0])", r)
        notes = browser.execute_script(
            "return [...document.querySelectorAll('#design-0 tr')]"
            ".map(tr => [tr.cells[0].textContent, tr.cells.length > 3 ? tr.cells[3].textContent : ''])"
        )
        said = {"-": "at lower bound", "+": "at upper bound", ".": ""}
        expected = [said[sides[r]] for sides in study["at_bound"]]
        assert [dict(notes)[name] for name in study["variables"]] == expected
        assert all(note == "" for name, note in notes if name not in study["variables"])
    assert which != "robust" or bounded  # (one page at least shows the note)
    if "baseline" in study:  # the config's own design on the front, at its values
        trace = browser.execute_script(
            "const t = document.getElementById('front-0').data"
            '.find(t => t.name === "the config\'s design"); return t && [t.x, t.y]'
        )
        x, y = (browser.execute_script(f"return document.getElementById('{a}-0').value")
                for a in "xy")  # fmt: skip
        at = {f"F:{j}": v for j, v in enumerate(study["baseline"]["F"])}
        at.update({f"X:{j}": v for j, v in enumerate(study["baseline"]["X"])})
        assert trace == [[at[x]], [at[y]]]
        browser.execute_script(  # clicked, the panel shows its values
            "document.getElementById('front-0').emit('plotly_click', {points: [{customdata: 'config'}]})"
        )
        panel = browser.execute_script(
            "const box = document.getElementById('design-0'); return [box.getAttribute('data-row'),"
            " box.querySelector('h3').textContent, [...box.querySelectorAll('tr')]"
            ".map(tr => [tr.cells[0].textContent, Number(tr.cells[1].textContent)])]"
        )
        assert panel[:2] == ["config", "the config's design"]
        shown = dict(panel[2])
        names = study["objectives"] + study["variables"]
        values = study["baseline"]["F"] + study["baseline"]["X"]
        assert [shown[n] for n in names] == pytest.approx(values, rel=1e-4)
    assert which != "ch5" or "baseline" in study
    browser.execute_script("window.suspoptReport.select(0, arguments[0])", row)
    onward = browser.execute_script(  # the commands that take the design on, run as shown
        "return [...document.querySelectorAll('#design-0 .onward code')].map(c => c.textContent)"
    )
    source = shlex.split(study["source"])[0]
    assert [shlex.split(c)[:3] for c in onward] == [
        ["suspopt", "export", source],
        ["suspopt", "simulate", source],
        ["suspopt", "analyse", "builds"],
    ]
    monkeypatch.chdir(tmp_path)
    for command in onward if which == "ch5" else onward[:1]:  # (one run of each is enough)
        res = _invoke(*shlex.split(command)[1:])
        assert res.exit_code == 0, (command, res.output)
    exported = (tmp_path / f"design_{row}.yaml").read_text().splitlines()[0]
    assert exported.startswith(f"# Design '{row}' (row {row} of /")
    assert exported.endswith(f" of {shlex.split(onward[0])[2]}")
    assert which != "ch5" or (tmp_path / f"design_{row}.h5").exists()
    if which == "ch5":  # the design's builds, as the file's own row
        with h5py.File(tmp_path / f"design_{row}_builds.h5") as h5:
            assert h5["pareto/source_row"][()].tolist() == [row]
    requests = [
        json.loads(entry["message"])["message"]["params"]["request"]["url"]
        for entry in browser.get_log("performance")
        if '"Network.requestWillBeSent"' in entry["message"]
    ]
    assert requests and all(url == page.resolve().as_uri() for url in requests), requests
    artefacts = Path(os.environ.get("SUSPOPT_ARTEFACTS", tmp_path))
    artefacts.mkdir(parents=True, exist_ok=True)
    browser.save_screenshot(str(artefacts / f"report_{which}.png"))


@pytest.mark.browser
@pytest.mark.slow
def test_a_page_of_many_studies_keeps_every_parallel_plot_it_shows(
    files, chapters, browser, tmp_path, monkeypatch
):
    """Six studies: their parallel-coordinates plots (three WebGL contexts each) would hold
    18 contexts, over the 16 Chromium keeps, which loses the oldest plots' lines. Scrolled
    to four of them, each plot on screen is drawn with one line per design on live contexts,
    at most three are drawn at once, the console never reports a lost context; scrolled
    back, the first is drawn again, with the range brushed on it before it was freed: the
    designs in the range are the front's selected points (in 3D too), and the command shown
    simulates them. Its lines take the front's colour."""
    folder = chapters["ch6"].parent
    sources = [files["front"], files["kesort"], files["roads"], files["robust"],
               files["three"], folder / "ch8_pareto_ps_class_a.h5"]  # fmt: skip
    page = tmp_path / "many.html"
    assert _invoke("report", *sources, "-o", page).exit_code == 0
    with h5py.File(files["front"]) as h5:
        f1 = h5["pareto/F"][:, 0]
    brush = [float(f1.min()), float(sorted(f1)[len(f1) // 2])]
    inside = [r for r, v in enumerate(f1) if brush[0] <= v <= brush[1]]
    assert 0 < len(inside) < len(f1)
    with h5py.File(files["three"]) as h5:  # three objectives: a 3D front
        F3 = h5["pareto/F"][:]
    brush3 = [float(F3[:, 0].min()), float(sorted(F3[:, 0])[len(F3) // 2])]
    inside3 = [r for r, v in enumerate(F3[:, 0]) if brush3[0] <= v <= brush3[1]]
    browser.get_log("browser")
    browser.get(page.resolve().as_uri())
    _wait(browser, "return document.body.getAttribute('data-rendered')", "the plots drew")
    for k, i in enumerate([0, 4, 1, 2, 0]):  # (the others' plots: the chapter tests)
        div = f"document.getElementById('parallel-{i}')"
        browser.execute_script(f"{div}.scrollIntoView({{block: 'center'}})")
        _wait(browser, f"return {div}.getAttribute('data-drawn')", f"parallel-{i} drew")
        lines, points, lost = browser.execute_script(
            f"return [{div}.data[0].dimensions[0].values.length,"
            f" window.suspoptReport.studies[{i}].points,"
            f" [...{div}.querySelectorAll('canvas.gl-canvas')]"
            "  .map(c => c.getContext('webgl').isContextLost())]"
        )
        assert lines == points and lost == [False, False, False], (i, lines, points, lost)
        drawn = browser.execute_script("return document.querySelectorAll('[data-drawn]').length")
        assert 1 <= drawn <= 3
        if k < 2:  # brushing f1 of the first and the 3D study
            browser.execute_script(
                f"Plotly.restyle({div}, {{'dimensions[0].constraintrange': [arguments[0]]}})",
                brush if i == 0 else brush3,
            )
    warnings = [e["message"] for e in browser.get_log("browser") if "WebGL" in e["message"]]
    assert not [m for m in warnings if "context" in m.lower()], warnings
    kept, selected, note = browser.execute_script(
        "return [document.getElementById('parallel-0').data[0].dimensions[0].constraintrange,"
        " document.getElementById('front-0').data[0].selectedpoints,"
        " document.getElementById('brush-0').textContent]"
    )
    assert kept in (brush, [brush]) and selected == inside
    assert note == f"{len(inside)} of {len(f1)} designs in the brushed ranges"
    command = browser.execute_script(  # the brushed designs in one batch, run as shown
        "return document.querySelector('#brush-command-0 code').textContent"
    )
    monkeypatch.chdir(tmp_path)
    args = shlex.split(command)
    assert args[:2] == ["suspopt", "simulate"] and args[3:5] == [
        "--pick",
        ",".join(map(str, inside)),
    ]
    res = _invoke(*args[1:])
    assert res.exit_code == 0, (command, res.output)
    with h5py.File(tmp_path / "brushed.h5") as h5:
        assert h5["designs/row"][:].tolist() == inside
    browser.execute_script(
        "const c = document.getElementById('c-0'); c.value = 'F:1';"
        " c.dispatchEvent(new Event('change'))"
    )
    with h5py.File(files["front"]) as h5:
        f2 = h5["pareto/F"][:, 1]
    line = browser.execute_script("return document.getElementById('parallel-0').data[0].line")
    assert line["color"] == f2.tolist() and line["colorscale"] == "Viridis"
    shown = browser.execute_script(  # in 3D: the brushed designs, and the rest in grey
        "document.getElementById('d3-4').click(); return document.getElementById('front-4')"
        '.data.map(t => [t.type, t.customdata || null, t.name === "the config\'s design" ? t.z : null])'
    )
    outside = [r for r in range(len(F3)) if r not in inside3]
    with h5py.File(files["three"]) as h5:  # and the config's own design, where it started
        own = h5["baseline/F"][0, 2]
    assert shown == [["scatter3d", inside3, None]] + (
        [["scatter3d", outside, None]] if outside else []
    ) + [["scatter3d", ["config"], [own]]]


def test_the_commands_shown_for_a_design_name_its_file_as_a_shell_reads_it(files, tmp_path):
    """The page shows, for the clicked design, the commands that take it on (``export``,
    ``simulate``) with the file's path as given; quoted, a name with spaces, quotes or ``$(...)``
    reads back as that name and runs nothing."""
    odd = tmp_path / "my 'front' $(touch pwned).h5"
    shutil.copyfile(files["front"], odd)
    page = tmp_path / "odd.html"
    assert _invoke("report", odd, "-o", page).exit_code == 0
    source = _payload(page.read_text())["studies"][0]["data"]["source"]
    assert shlex.split(f"suspopt export {source} --pick 0") == [
        "suspopt", "export", str(odd), "--pick", "0"]  # fmt: skip


@pytest.mark.browser
@pytest.mark.slow
def test_a_design_of_an_analyse_builds_file_shows_the_spread_of_its_builds(
    files, browser, tmp_path
):
    """Clicked on the page of an ``analyse builds`` file, a design's panel shows each
    objective's 5th to 95th percentile over its builds, what its spread comes from (each
    variable's squared correlation, largest first) and its share of feasible builds, as the
    file holds them."""
    builds, page = tmp_path / "builds.h5", tmp_path / "builds.html"
    with h5py.File(files["front"]) as h5:
        first, second = h5["pareto/X"].attrs["names"].astype(str)[:2]
    res = _invoke(
        "analyse",
        "builds",
        files["front"],
        "--samples",
        12,
        "--distribution",
        "normal",
        "--tolerance",
        f"{first}=7.5",
        "-o",
        builds,
    )
    assert res.exit_code == 0, res.output
    assert _invoke("report", builds, "-o", page).exit_code == 0
    with h5py.File(builds) as h5:
        low, high = h5["builds/F_p05"][()], h5["builds/F_p95"][()]
        share = h5["builds/feasible_share"][()]
        names = list(h5["builds/F"].attrs["names"].astype(str))
        variables = list(h5["builds/X"].attrs["names"].astype(str))
        r2 = h5["builds/contribution"][()]
    browser.get(page.resolve().as_uri())
    _wait(browser, "return document.body.getAttribute('data-rendered')", "the plots rendered")
    for row in (0, len(share) - 1):
        browser.execute_script("window.suspoptReport.select(0, arguments[0])", row)
        rows = browser.execute_script(
            "return [...document.querySelectorAll('#design-0 tr')]"
            ".map(tr => [...tr.cells].map(c => c.textContent))"
        )
        cells = {r[0]: r[1] for r in rows}
        notes = {r[0]: r[3] if len(r) > 3 else "" for r in rows}
        for j, name in enumerate(names):
            lo, hi = cells[f"{name}, built 5-95 %"].split(" to ")
            assert [float(lo), float(hi)] == pytest.approx([low[row, j], high[row, j]], rel=1e-4)
            order = sorted(range(len(variables)), key=lambda i: -r2[row, i, j])
            drivers = ", ".join(f"{variables[i]} {r2[row, i, j]:.2f}" for i in order)
            assert notes[f"{name}, built 5-95 %"] == f"spread from: {drivers}"
        assert float(cells["feasible builds"]) == pytest.approx(100 * share[row], rel=1e-4)
        note = browser.execute_script(
            "return document.querySelector('#design-0 > div.note').textContent"
        )
        within = f"each variable within its tolerance ({first} ±7.5 %, {second} ±10 %)"
        assert note == f"12 builds, {within} (normal)"
    # the parts of one batch (--batch): one driver, named by the batch, and the note says so
    batched, page = tmp_path / "batched.h5", tmp_path / "batched.html"
    res = _invoke(
        "analyse", "builds", files["front"], "--samples", 12, "--batch", f"{first},{second}",
        "-o", batched,
    )  # fmt: skip
    assert res.exit_code == 0, res.output
    assert _invoke("report", batched, "-o", page).exit_code == 0
    with h5py.File(batched) as h5:
        r2 = h5["builds/contribution"][()]
        variables = list(h5["builds/X"].attrs["names"].astype(str))
    browser.get(page.resolve().as_uri())
    _wait(browser, "return document.body.getAttribute('data-rendered')", "the plots rendered")
    browser.execute_script("window.suspoptReport.select(0, 0)")
    rows = browser.execute_script(
        "return [...document.querySelectorAll('#design-0 tr')]"
        ".map(tr => [...tr.cells].map(c => c.textContent))"
    )
    notes = {r[0]: r[3] if len(r) > 3 else "" for r in rows}
    for j, name in enumerate(names):
        shares = [f"{r2[0, i, j]:.2f}" for i in range(len(variables))]
        alone = [f"{v} {c}" for v, c in zip(variables[2:], shares[2:])]
        drivers = sorted(
            [f"{first}+{second} {shares[0]}", *alone], key=lambda d: -float(d.split()[-1])
        )
        assert notes[f"{name}, built 5-95 %"] == "spread from: " + ", ".join(drivers)
    note = browser.execute_script(
        "return document.querySelector('#design-0 > div.note').textContent"
    )
    assert note.endswith(f"; the parts of one batch off alike ({first} and {second})")


@pytest.fixture(scope="module")
def builds_file(files, tmp_path_factory) -> Path:
    """An ``analyse builds`` file of the seat front (5 builds of each design)."""
    path = tmp_path_factory.mktemp("builds") / "builds.h5"
    res = _invoke("analyse", "builds", files["front"], "--samples", 5, "-o", path)
    assert res.exit_code == 0, res.output
    return path


def _set(group, key, value):
    del group[key]
    group[key] = value


@pytest.mark.parametrize(
    "damage, message",
    [
        (lambda g: _set(g, "tolerance", np.array([b"ten", b"ten"])), "not numbers"),
        (lambda g: _set(g, "tolerance", np.array([np.nan, 10.0])), "not one tolerance in (0,"),
        (lambda g: _set(g, "tolerance", np.array([100.0, 10.0])), "not one tolerance in (0,"),
        (lambda g: _set(g, "tolerance", np.array([10.0])), "for each of the front's 2 variables"),
        (lambda g: g.__delitem__("tolerance"), "/builds/tolerance: missing"),
        (lambda g: g.attrs.__delitem__("samples"), "attribute 'samples': missing or not a whole"),
        (lambda g: _set(g, "F_p05", np.zeros((3, 2))), "do not have the front's"),
        (lambda g: _set(g, "feasible_share", np.zeros((3, 2))), "expected 1 dimension"),
        (lambda g: _set(g, "feasible_share", np.array([b"a"] * 3)), "not numbers"),
        (lambda g: g.__delitem__("F_p95"), "/builds/F_p95: missing"),
        (lambda g: _set(g, "contribution", np.zeros((3, 2, 2))), "do not have the front's"),
        (lambda g: _set(g, "contribution", np.zeros((3, 2))), "expected 3 dimensions"),
        (lambda g: _set(g, "contribution", g["contribution"][:, :1]), "2 variables and 2"),
        (
            lambda g: g.attrs.__setitem__("distribution", "<b>x</b>"),
            "is not one of uniform, normal",
        ),
        (
            lambda g: g.attrs.__delitem__("distribution"),
            "attribute 'distribution' of /builds: missing",
        ),
        (lambda g: _set(g, "batch", np.zeros(2)), "/builds/batch: expected 2 entries of text"),
        (lambda g: _set(g, "batch", np.array([b"a"])), "/builds/batch: expected 2 entries"),
        (lambda g: _set(g, "batch", np.array([[b"a", b"a"]])), "/builds/batch: expected 2"),
        (lambda g: _set(g, "batch", np.array([b"\xff", b""])), "/builds/batch: not UTF-8 text"),
    ],
)
def test_a_damaged_builds_file_is_one_line_and_no_page(builds_file, tmp_path, damage, message):
    broken, page = tmp_path / "broken.h5", tmp_path / "page.html"
    shutil.copyfile(builds_file, broken)
    with h5py.File(broken, "r+") as h5:
        damage(h5["builds"])
    res = _invoke("report", broken, "-o", page)
    assert res.exit_code == 2 and not page.exists()
    assert res.output.startswith(f"error: {broken}: ") and message in res.output
    assert "/builds" in res.output
    assert len(res.output.strip().splitlines()) == 1


def test_a_builds_file_of_before_batches_is_shown_with_every_variable_alone(builds_file, tmp_path):
    """A builds file written before ``/builds/batch`` existed is read as one whose
    variables were drawn alone."""
    old, page = tmp_path / "old.h5", tmp_path / "page.html"
    shutil.copyfile(builds_file, old)
    with h5py.File(old, "r+") as h5:
        del h5["builds/batch"]
    assert _invoke("report", old, "-o", page).exit_code == 0
    assert _payload(page.read_text())["studies"][0]["data"]["builds"]["batch"] == ["", ""]


@pytest.mark.browser
@pytest.mark.slow
def test_a_design_of_a_kesort_as_built_file_shows_its_as_built_values(
    files, builds_file, browser, tmp_path
):
    """A kesort file sorted as built (``--as-built 95``): a clicked design's panel gives
    each objective's nominal value and, under it, the percentile the sort ranked; the
    study's notes say how it was sorted."""
    choice, page = tmp_path / "choice.h5", tmp_path / "choice.html"
    res = _invoke(
        "kesort", files["front"], "--builds", builds_file, "--as-built", 95,
        "--min-feasible-builds", 0, "-o", choice,
    )  # fmt: skip
    assert res.exit_code == 0, res.output
    assert _invoke("report", choice, "-o", page).exit_code == 0
    with h5py.File(choice) as h5:
        F, built = h5["kesort/F"][()], h5["kesort/F_as_built"][()]
        names = list(h5["kesort/F"].attrs["names"].astype(str))
        chosen = int(h5["kesort/chosen"][()])
    browser.get(page.resolve().as_uri())
    _wait(browser, "return document.body.getAttribute('data-rendered')", "the plots rendered")
    browser.execute_script("window.suspoptReport.select(0, arguments[0])", chosen)
    rows = browser.execute_script(
        "return [...document.querySelectorAll('#design-0 tr')]"
        ".map(tr => [...tr.cells].map(c => c.textContent))"
    )
    labels, cells = [r[0] for r in rows], {r[0]: r[1] for r in rows}
    for j, name in enumerate(names):
        i = labels.index(name)
        assert labels[i + 1] == f"{name}, as built (p95)"
        assert float(cells[name]) == pytest.approx(F[chosen, j], rel=1e-4)
        assert float(cells[labels[i + 1]]) == pytest.approx(built[chosen, j], rel=1e-4)
        assert built[chosen, j] != F[chosen, j]
    assert "sorted as built" in page.read_text()
    # the front drawn at the values as built: the axes offer them beside the nominal ones
    options = browser.execute_script(
        "return [...document.getElementById('x-0').options].map(o => [o.value, o.textContent])"
    )
    assert [v for v, _ in options if v.startswith("B:")] == [f"B:{j}" for j in range(len(names))]
    assert dict(options)["B:1"] == f"{names[1]}, as built (p95)"
    drawn = browser.execute_script(
        "for (const a of ['x', 'y']) { const e = document.getElementById(a + '-0');"
        " e.value = a === 'x' ? 'B:0' : 'B:1'; e.dispatchEvent(new Event('change')); }"
        " const t = document.getElementById('front-0').data[0];"
        " return [t.x, t.y, document.getElementById('front-0').layout.xaxis.title.text]"
    )
    assert drawn[0] == pytest.approx(built[:, 0].tolist()) and drawn[1] == pytest.approx(
        built[:, 1].tolist()
    )
    assert drawn[2].startswith(f"{names[0]}, as built (p95) [")


@pytest.mark.browser
@pytest.mark.slow
def test_the_brushed_designs_command_lists_at_most_its_cap_of_rows(
    files, browser, tmp_path, monkeypatch
):
    """The command that simulates the brushed designs lists at most
    ``page.BRUSH_COMMAND_ROWS`` rows (100); above, the page asks for narrower ranges.
    Here the cap is 3: three brushed designs give the command, four the request."""
    from suspopt.report import page as page_module

    monkeypatch.setattr(page_module, "BRUSH_COMMAND_ROWS", 3)
    page = tmp_path / "front.html"
    assert _invoke("report", files["front"], "-o", page).exit_code == 0
    with h5py.File(files["front"]) as h5:
        f1 = np.sort(h5["pareto/F"][:, 0])
    assert len(f1) >= 4 and len(set(f1[:5])) == min(5, len(f1))
    browser.get(page.resolve().as_uri())
    _wait(browser, "return document.body.getAttribute('data-rendered')", "the plots rendered")
    div = "document.getElementById('parallel-0')"
    browser.execute_script(f"{div}.scrollIntoView({{block: 'center'}})")
    _wait(browser, f"return {div}.getAttribute('data-drawn')", "parallel-0 drew")
    for count in (3, 4):
        top = (f1[count - 1] + f1[count]) / 2 if count < len(f1) else f1[-1]
        browser.execute_script(
            f"Plotly.restyle({div}, {{'dimensions[0].constraintrange': [arguments[0]]}})",
            [float(f1[0]) - 1e-12, float(top)],
        )
        note, codes, box = browser.execute_script(
            "return [document.getElementById('brush-0').textContent,"
            " [...document.querySelectorAll('#brush-command-0 code')].map(c => c.textContent),"
            " document.getElementById('brush-command-0').textContent]"
        )
        assert note == f"{count} of {len(f1)} designs in the brushed ranges"
        if count == 3:
            assert len(codes) == 1 and len(shlex.split(codes[0])[4].split(",")) == 3
        else:
            assert codes == [] and "more than 3 designs: narrow the ranges" in box
