"""User-defined metrics (:mod:`suspopt.user_metrics`): registered from Python with
``@suspopt.metric`` or installed as an entry point of the ``suspopt.metrics`` group, used
by name in YAML wherever a built-in metric goes, checked like the built-ins, and carried to
the workers.

The entry point tests install a tiny distribution the way pip leaves one on a path: a
module beside its ``*.dist-info`` folder (METADATA and entry_points.txt), on the PYTHONPATH
of a ``python -m suspopt`` subprocess."""

from __future__ import annotations

import importlib.util
import json
import os
import pickle
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import h5py
import numpy as np
import pytest
from conftest import ROOT, TINY, write
from typer.testing import CliRunner

import suspopt
from suspopt import user_metrics
from suspopt.cli import app
from suspopt.errors import ConfigError
from suspopt.specs import METRICS

#: The users' module: a jerk metric registered with the decorator (its unit a function of
#: the signal's), a plain function whose entry point gives it its name, and a broken one.
MODULE = '''\
import numpy as np
import suspopt


@suspopt.metric(name="peak_jerk", unit=lambda u: f"({u})/s", description="largest jerk")
def peak_jerk(x, t):
    return np.abs(np.diff(x, axis=-1)).max(axis=-1) / (t[1] - t[0])


def settled(x, t):
    """mean of the last tenth"""
    return x[:, -max(1, x.shape[-1] // 10):].mean(axis=-1)


def whole_signal(x, t):
    """gives the signal itself, (P, T): not one value per design"""
    return x
'''
ENTRY_POINTS = """\
[suspopt.metrics]
peak_jerk = jerkmetrics:peak_jerk
settled = jerkmetrics:settled
whole_signal = jerkmetrics:whole_signal
"""


def peak_jerk(x: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The module's jerk, recomputed here: the largest |Δx| / Δt over the record (P,)."""
    return np.abs(np.diff(x, axis=-1)).max(axis=-1) / (t[1] - t[0])


def _distribution(folder: Path, entry_points: str = ENTRY_POINTS) -> Path:
    """A folder holding the installed distribution ``jerkmetrics``; its path."""
    (folder / "jerkmetrics").mkdir(parents=True)
    (folder / "jerkmetrics" / "__init__.py").write_text(MODULE)
    info = folder / "jerkmetrics-1.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: jerkmetrics\nVersion: 1.0\n")
    (info / "entry_points.txt").write_text(entry_points)
    return folder


def _run(site: Path, *args, cwd: Path) -> subprocess.CompletedProcess:
    """``python -m suspopt ARGS`` with ``site`` (and this checkout) on its PYTHONPATH."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(site), str(ROOT)]))
    return subprocess.run(
        [sys.executable, "-m", "suspopt", *map(str, args)],
        capture_output=True,
        text=True,
        cwd=cwd,
        env=env,
        timeout=300,
    )


def _config(metric: str, engine: str = "auto") -> str:
    """TINY with its second objective the metric ``metric`` of the heave acceleration."""
    text = TINY.replace(
        "{name: f3, metric: var, signal: tyre_deflection, reduce: mean}",
        f"{{name: jerk, metric: {metric}, signal: body.heave_acc}}",
    )
    assert "name: jerk" in text
    return text.replace("dt: 1.0e-3}", f"dt: 1.0e-3, engine: {engine}}}")


def _one_error_line(result) -> str:
    """The one error line of a command that exits 2 (``validate``'s count after it)."""
    assert result.returncode == 2, (result.stdout, result.stderr)
    lines = result.stderr.strip().splitlines()
    if "validate" in result.args:
        assert lines[1:] == ["1 error in case.yaml"], result.stderr
        lines = lines[:1]
    assert len(lines) == 1 and "Traceback" not in result.stderr, result.stderr
    return lines[0]


def _payload(page: str) -> dict:
    found = re.search(
        r"<script type='application/json' id='suspopt-data'>(.*?)</script>", page, re.S
    )
    assert found
    return json.loads(found.group(1))


def _recomputed(config: Path, front: Path) -> tuple[np.ndarray, np.ndarray]:
    """(the front's jerk values, the jerk of a numpy-engine simulate of its designs): the
    config simulated here without the users' metric, which this process has not loaded."""
    text = config.read_text().replace("metric: peak_jerk", "metric: max")
    cfg = suspopt.load_config(write(config.parent, text, "here.yaml"))
    with h5py.File(front) as h5:
        X, F = h5["pareto/X"][()], h5["pareto/F"]
        jerk = F[:, list(F.attrs["names"]).index("jerk")]
        assert F.attrs["units"][list(F.attrs["names"]).index("jerk")] == "(m/s^2)/s"
    paths = [v.path for v in cfg.design_variables]
    cfg.simulation.engine = "numpy"
    result = suspopt.simulate(cfg, params={p: X[:, j] for j, p in enumerate(paths)})
    return jerk, peak_jerk(result.signals["body.heave_acc"], result.time)


@pytest.fixture(autouse=True)
def _forget_registrations():
    """Each test's user metrics are forgotten after it (other test modules walk METRICS)."""
    before = set(METRICS)
    yield
    for name in set(METRICS) - before:
        user_metrics.unregister(name)


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    return _distribution(tmp_path_factory.mktemp("site"))


@pytest.mark.slow
@pytest.mark.cli
def test_an_entry_point_metric_is_optimised_from_yaml_and_reported_with_its_unit(site, tmp_path):
    """The compiled engine's streamed evaluation (``engine: compiled``) keeps the signal of
    the ``keep`` metric: the front's values are the users' function of the signal that a
    numpy ``simulate`` of the same designs gives, and the report names it with its unit."""
    engine = "compiled" if importlib.util.find_spec("numba") else "numpy"
    write(tmp_path, _config("peak_jerk", engine=engine), "cfg.yaml")
    done = _run(site, "optimise", "cfg.yaml", "-o", "front.h5", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert "(m/s^2)/s" in done.stdout  # (the best design's table)
    jerk, expected = _recomputed(tmp_path / "cfg.yaml", tmp_path / "front.h5")
    assert len(jerk) >= 2 and np.all(expected > 1.0)
    np.testing.assert_allclose(jerk, expected, rtol=1e-9)
    done = _run(site, "report", "front.h5", "-o", "report.html", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    data = _payload((tmp_path / "report.html").read_text())["studies"][0]["data"]
    assert data["objective_units"][data["objectives"].index("jerk")] == "(m/s^2)/s"


@pytest.mark.slow
@pytest.mark.cli
def test_a_plain_function_entry_point_takes_its_signals_unit(site, tmp_path):
    write(tmp_path, TINY.replace("metric: var, signal: tyre", "metric: settled, signal: tyre"))
    done = _run(site, "validate", "case.yaml", cwd=tmp_path)
    assert done.returncode == 0, done.stderr


@pytest.mark.cli
def test_a_misspelt_metric_suggests_the_installed_ones(site, tmp_path):
    write(tmp_path, _config("peak_jerkk"))
    line = _one_error_line(_run(site, "validate", "case.yaml", cwd=tmp_path))
    assert "case.yaml" in line and "metric" in line and "peak_jerk" in line, line
    assert re.search(r":\d+", line), line  # (its line in the file)


@pytest.mark.slow
@pytest.mark.cli
def test_a_metric_of_the_wrong_shape_is_one_line_naming_it_and_writes_nothing(site, tmp_path):
    write(tmp_path, _config("whole_signal"))
    line = _one_error_line(_run(site, "optimise", "case.yaml", "-o", "front.h5", cwd=tmp_path))
    assert "'whole_signal'" in line and "jerkmetrics.whole_signal" in line, line
    assert "shape (8, 501)" in line and "(8,)" in line, line
    assert not (tmp_path / "front.h5").exists()


@pytest.mark.slow
@pytest.mark.cli
def test_an_entry_point_may_not_take_a_built_in_name(tmp_path):
    site = _distribution(tmp_path / "site", ENTRY_POINTS + "rms = jerkmetrics:settled\n")
    write(tmp_path, _config("peak_jerk"))
    line = _one_error_line(_run(site, "validate", "case.yaml", cwd=tmp_path))
    assert "rms = jerkmetrics:settled" in line and "built-in" in line, line


def _jerk_from_python():
    @suspopt.metric(name="py_jerk", unit="m/s^3", description="largest jerk")
    def py_jerk(x, t):
        return peak_jerk(x, t)

    return py_jerk


@pytest.mark.slow
def test_a_decorated_metric_is_simulated_and_optimised_from_python(tmp_path):
    _jerk_from_python()
    cfg = suspopt.load_config(write(tmp_path, _config("py_jerk")))
    cfg.metrics = [{"metric": "py_jerk", "signal": "body.heave_acc"}]
    result = suspopt.simulate(cfg)
    assert result.metric_units == {"py_jerk.body.heave_acc": "m/s^3"}
    expected = peak_jerk(result.signals["body.heave_acc"], result.time)
    np.testing.assert_array_equal(result.metrics["py_jerk.body.heave_acc"], expected)

    from suspopt.optimisation import optimise

    limit = {"name": "jerk_max", "metric": "py_jerk", "signal": "body.heave_acc", "max": 1e3}
    cfg.constraints = [*cfg.constraints, limit]
    optimise(cfg, tmp_path / "front.h5")
    with h5py.File(tmp_path / "front.h5") as h5:
        X, F, G = h5["pareto/X"][()], h5["pareto/F"], h5["pareto/G"]
        j = list(F.attrs["names"]).index("jerk")
        assert F.attrs["units"][j] == "m/s^3"
        jerk = F[:, j]
        g = list(G.attrs["names"]).index("jerk_max <= 1000")
        assert G.attrs["units"][g] == "m/s^3"
        margin = G[:, g]  # g = value - max
    np.testing.assert_allclose(margin, jerk - 1e3)
    params = {v.path: X[:, i] for i, v in enumerate(cfg.design_variables)}
    again = suspopt.simulate(cfg, params=params)
    np.testing.assert_allclose(jerk, peak_jerk(again.signals["body.heave_acc"], again.time))
    done = CliRunner().invoke(
        app, ["report", str(tmp_path / "front.h5"), "-o", str(tmp_path / "r.html")]
    )
    assert done.exit_code == 0, done.output
    data = _payload((tmp_path / "r.html").read_text())["studies"][0]["data"]
    assert data["objective_units"][data["objectives"].index("jerk")] == "m/s^3"


@pytest.mark.parametrize("engine", ["numpy", "compiled"])
def test_a_streamed_evaluation_keeps_the_signal_of_a_user_metric(tmp_path, monkeypatch, engine):
    """:func:`suspopt.streaming.reduce` (what an evaluation runs, in windows; on the compiled
    engine the kernel reduces the variance itself) gives the user metric of the whole
    signal."""
    if engine == "compiled":
        pytest.importorskip("numba")
    from suspopt import streaming
    from suspopt.specs import spec_signals

    _jerk_from_python()
    cfg = suspopt.load_config(write(tmp_path, TINY.replace("0.5, dt", "3.0, dt")))
    cfg.simulation.engine = engine
    cfg.metrics = [
        {"metric": "py_jerk", "signal": "body.heave_acc"},
        {"metric": "var", "signal": "body.heave_acc"},
    ]
    params = {"vehicle.corners.F1.damper.c": np.array([2000.0, 3000.0, 4000.0])}
    whole = suspopt.simulate(cfg, params=params)
    requests = [(s, spec_signals(s, list(whole.signals), whole.model.corners)) for s in cfg.metrics]
    monkeypatch.setattr(streaming, "WINDOW_BYTES", 1)  # windows of one block each
    assert streaming.window_width(cfg, whole.model, {}, 3, 2) < len(whole.time)
    reduced = streaming.reduce(cfg, params, requests)
    assert reduced.engine == engine
    jerk = reduced.metric(cfg.metrics[0], "body.heave_acc")
    np.testing.assert_allclose(jerk, whole.metrics["py_jerk.body.heave_acc"], rtol=1e-12)
    assert len(set(jerk)) == 3


def test_a_misspelt_metric_from_python_suggests_the_registered_one(tmp_path):
    _jerk_from_python()
    done = CliRunner().invoke(app, ["validate", str(write(tmp_path, _config("py_jerc")))])
    assert done.exit_code == 2
    lines = done.output.strip().splitlines()
    assert len(lines) == 2 and "py_jerk" in lines[0] and "case.yaml" in lines[0], done.output
    assert lines[1].startswith("1 error in ") and lines[1].endswith("case.yaml"), done.output


@pytest.mark.parametrize("name", ["rms", "spring_usage"])
def test_a_user_metric_may_not_take_a_built_in_name(name):
    with pytest.raises(ValueError, match=f"metric '{name}' is built into suspopt"):
        suspopt.metric(name=name)(peak_jerk)
    assert METRICS[name].kind != "user"


@pytest.mark.parametrize(
    ("returns", "message"),
    [
        (lambda x, t: x[:, :2], r"gave values of shape \(2, 2\)"),
        (lambda x, t: x[0], r"gave values of shape \(\d+,\)"),
        (lambda x, t: np.array(["a", "b"]), r"gave <U1 values of shape \(2,\)"),
        (lambda x, t: 1 / 0, r"failed on body.heave_acc: ZeroDivisionError: division by zero"),
    ],
)
def test_a_broken_user_metric_is_a_config_error_naming_it(tmp_path, returns, message):
    user_metrics.register(returns, "broken")
    cfg = suspopt.load_config(write(tmp_path, TINY))
    cfg.metrics = [{"metric": "broken", "signal": "body.heave_acc"}]
    params = {"vehicle.corners.F1.damper.c": np.array([2000.0, 4000.0])}
    with pytest.raises(ConfigError, match=r"^metric 'broken' \(.*<lambda>\) " + message):
        suspopt.simulate(cfg, params=params)


def test_a_user_metric_does_not_write_into_the_signal(tmp_path):
    user_metrics.register(lambda x, t: x.__setitem__(Ellipsis, 0.0), "writer")
    cfg = suspopt.load_config(write(tmp_path, TINY))
    cfg.metrics = [{"metric": "writer", "signal": "body.heave_acc"}]
    with pytest.raises(ConfigError, match="metric 'writer'.*read-only"):
        suspopt.simulate(cfg)


@pytest.mark.slow
def test_a_spec_carries_its_metric_to_a_process_that_has_not_imported_it(tmp_path, monkeypatch):
    """A pickled config (what the ``processes`` and ``dask`` workers get) registers its user
    metric in the process that unpickles it, from the module that defined it."""
    site = _distribution(tmp_path / "site")
    monkeypatch.syspath_prepend(str(site))
    monkeypatch.delitem(sys.modules, "jerkmetrics", raising=False)
    import jerkmetrics  # noqa: F401  (the users' import: registers peak_jerk)

    cfg = suspopt.load_config(write(tmp_path, _config("peak_jerk")))
    (tmp_path / "cfg.pickle").write_bytes(pickle.dumps(cfg))
    script = textwrap.dedent(f"""\
        import pickle, sys
        sys.path.insert(0, {str(site)!r})
        from suspopt.specs import METRICS
        assert "peak_jerk" not in METRICS and "jerkmetrics" not in sys.modules
        cfg = pickle.loads(open({str(tmp_path / "cfg.pickle")!r}, "rb").read())
        print(METRICS["peak_jerk"].unit("m"), cfg.objectives.main[1].metric)
    """)
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["(m)/s", "peak_jerk"]


def test_a_metric_a_worker_cannot_register_is_one_line_from_the_worker(tmp_path):
    """A spec unpickled where its metric's module does not register it (a worker that does
    not run the script's ``__main__``) evaluates to a ConfigError saying so, not to a
    KeyError deep in the streaming code."""

    def jerk(x, t):
        return peak_jerk(x, t)

    jerk.__module__ = "__main__"  # (as if defined in a notebook)
    user_metrics.register(jerk, "main_jerk")
    cfg = suspopt.load_config(write(tmp_path, TINY))
    cfg.metrics = [{"metric": "main_jerk", "signal": "body.heave_acc"}]
    shipped = pickle.dumps(cfg)
    user_metrics.unregister("main_jerk")
    in_worker = pickle.loads(shipped)  # (pytest's __main__ registers no metric)
    with pytest.raises(ConfigError, match="^metric 'main_jerk' is registered by module '__main__'"):
        suspopt.simulate(in_worker)
