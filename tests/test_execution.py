"""The executors of suspopt.execution: a population evaluated in chunks on local processes or a
Dask cluster (a distributed.LocalCluster of 2 worker processes, started and stopped here)
gives the same bits as in this process, survives a killed worker, and says so when the
scheduler is lost or the extra is missing."""

from __future__ import annotations

import os
import re
import signal
import threading
import time

import h5py
import numpy as np
import pytest
from conftest import CONFIGS, TINY, write

import suspopt
from suspopt import execution
from suspopt._entry import main
from suspopt.optimisation import optimise

pytestmark = pytest.mark.slow
distributed = pytest.importorskip("distributed")

#: A chunk width that splits the tiny populations into several chunks.
CHUNK = 3


def cli(capsys, *args) -> tuple[int, str, str]:
    code = main([str(a) for a in args])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


@pytest.fixture(scope="module")
def cluster():
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as c:
        yield c


def _pareto(path):
    with h5py.File(path) as h5:
        return {k: h5[f"pareto/{k}"][()] for k in ("X", "F", "G")}


def _optimised(tmp_path, name, text=TINY, **use):
    config = write(tmp_path, text, f"{name}.yaml")
    out = tmp_path / f"{name}.h5"
    with execution.use(**use):
        optimise(suspopt.load_config(config), out)
    return _pareto(out)


def _same(a: dict, b: dict) -> None:
    for key in a:
        np.testing.assert_array_equal(a[key], b[key], err_msg=key)


def test_nsga2_on_dask_and_on_processes_gives_the_local_pareto_set(tmp_path, cluster):
    local = _optimised(tmp_path, "local")
    on_dask = _optimised(
        tmp_path, "dask", executor="dask", scheduler=cluster.scheduler_address, chunk=CHUNK
    )
    _same(local, on_dask)
    on_processes = _optimised(tmp_path, "processes", executor="processes", workers=2, chunk=CHUNK)
    _same(local, on_processes)


#: A user's module of metrics (suspopt.user_metrics), registered when it is imported.
USER_MODULE = """\
import numpy as np
import suspopt


@suspopt.metric(name="dask_jerk", unit="m/s^3")
def dask_jerk(x, t):
    return np.abs(np.diff(x, axis=-1)).max(axis=-1) / (t[1] - t[0])
"""


def test_a_user_metric_reaches_the_dask_workers_from_its_module(tmp_path, cluster, monkeypatch):
    """The workers have never imported the users' module: the spec they get carries it
    (:class:`suspopt.user_metrics.Source`), they import it and give the local values."""
    import sys

    from suspopt import user_metrics

    (tmp_path / "users_jerk.py").write_text(USER_MODULE)
    monkeypatch.syspath_prepend(str(tmp_path))
    with distributed.Client(cluster) as client:  # (the workers see the module's folder)
        client.run(lambda folder: sys.path.insert(0, folder), str(tmp_path))
        assert not any(client.run(lambda: "users_jerk" in sys.modules).values())
        import users_jerk  # noqa: F401

        text = TINY.replace(
            "metric: var, signal: tyre_deflection, reduce: mean",
            "metric: dask_jerk, signal: body.heave_acc",
        )
        try:
            local = _optimised(tmp_path, "local", text)
            address = cluster.scheduler_address
            _same(
                local,
                _optimised(tmp_path, "dask", text, executor="dask", scheduler=address, chunk=CHUNK),
            )
            assert all(client.run(lambda: "users_jerk" in sys.modules).values())
        finally:
            user_metrics.unregister("dask_jerk")
            sys.modules.pop("users_jerk", None)


METRICS = """\
metrics:
  - {metric: var, signal: body.heave_acc}
  - {metric: rms_weighted, signal: body.heave_acc, weighting: Wk}
  - {metric: max_abs, signal: travel}
"""


def test_an_execution_section_runs_its_chunks_in_the_workers_only(tmp_path, capsys):
    """With ``execution: {executor: processes}`` in the config, the workers simulate their
    chunks themselves (they never hand them on) and the front is the local one."""
    local = write(tmp_path, TINY, "local.yaml")
    section = f"execution: {{executor: processes, workers: 2, chunk: {CHUNK}}}\n"
    pooled = write(tmp_path, TINY + section, "pooled.yaml")
    for path in (local, pooled):
        code, _, err = cli(capsys, "optimise", path, "-o", path.with_suffix(".h5"))
        assert code == 0, err
    _same(_pareto(local.with_suffix(".h5")), _pareto(pooled.with_suffix(".h5")))


def test_a_batch_simulate_gives_the_same_metric_bits_on_dask(tmp_path, cluster, capsys):
    text = (CONFIGS / "quickstart.yaml").read_text() + METRICS + f"execution: {{chunk: {CHUNK}}}\n"
    path = write(tmp_path, text)
    sweep = ("--sweep", "vehicle.corners.F1.damper.c=1000:6000:7")
    outputs = {}
    for name, extra in (("local", ()), ("dask", ("--scheduler", cluster.scheduler_address))):
        out = tmp_path / f"{name}.h5"
        code, _, err = cli(capsys, "simulate", path, *sweep, "-o", out, *extra)
        assert code == 0, err
        with h5py.File(out) as h5:
            outputs[name] = {
                f"{group}/{k}": h5[group][k][()]
                for group in ("metrics", "signals")
                for k in h5[group]
            }
    assert outputs["local"].keys() == outputs["dask"].keys() and len(outputs["local"]) > 20
    _same(outputs["local"], outputs["dask"])


def _kill_a_busy_worker(client, pids: dict, done: list) -> None:
    """Kill (SIGKILL) the first worker seen processing a chunk."""
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and not done:
        busy = [w for w, tasks in client.processing().items() if tasks]
        if busy:
            os.kill(pids[busy[0]], signal.SIGKILL)
            done.append(busy[0])
            return
        time.sleep(0.005)


def test_a_worker_killed_during_a_generation_does_not_change_the_result(tmp_path, cluster):
    local = _optimised(tmp_path, "local")
    client = distributed.Client(cluster)
    pids = client.run(os.getpid)
    killed: list = []
    killer = threading.Thread(target=_kill_a_busy_worker, args=(client, pids, killed))
    killer.start()
    try:
        survived = _optimised(
            tmp_path, "killed", executor="dask", scheduler=cluster.scheduler_address, chunk=1
        )
    finally:
        killed.append("stop")
        killer.join()
        client.close()
    assert killed[0] != "stop", "no worker was seen busy: the test killed nothing"
    _same(local, survived)


def test_process_workers_rerun_a_killed_workers_chunks_and_never_hand_one_on(tmp_path):
    cfg = suspopt.load_config(write(tmp_path, TINY))
    problem = suspopt.Problem.from_config(cfg)
    X = problem.xl + np.random.default_rng(3).random((12, problem.n_var)) * (
        problem.xu - problem.xl
    )
    whole = problem.evaluate(X, return_values_of=["F", "G"])
    executor = execution.ProcessExecutor(workers=2)
    try:
        executor.map(_chunk, problem, [X[:1]])  # the pool is up, holding the problem
        victim = next(iter(executor._pool._processes))
        os.kill(victim, signal.SIGKILL)
        time.sleep(0.2)
        parts = executor.map(_chunk, problem, [X[s] for s in execution.chunks(len(X), CHUNK)])
        # in a worker, a config's own section never hands a chunk on
        section = suspopt.load_config(write(tmp_path, TINY + "execution: {executor: processes}\n"))
        assert executor.map(_executor_in_worker, section.execution, [0]) == ["local"]
    finally:
        executor.close()
    np.testing.assert_array_equal(np.concatenate([p[0] for p in parts]), whole[0])
    np.testing.assert_array_equal(np.concatenate([p[1] for p in parts]), whole[1])


def _executor_in_worker(section, item):
    return execution.settings(section)["executor"]


def _chunk(problem, X):
    return problem._evaluate_batch(X, False)


def test_a_lost_scheduler_keeps_the_checkpoint_and_resume_continues_locally(
    tmp_path, capsys, monkeypatch
):
    monkeypatch.setattr(execution, "CONNECT_TIMEOUT", 2)
    config = write(tmp_path, TINY.replace("generations: 4", "generations: 6"))
    complete = tmp_path / "complete.h5"
    code, _, err = cli(capsys, "optimise", config, "-o", complete)
    assert code == 0, err
    out = tmp_path / "lost.h5"
    cluster = distributed.LocalCluster(
        n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None
    )
    address = cluster.scheduler_address
    real = execution.DaskExecutor.map
    calls = []

    def map_then_lose(self, *args, **kwargs):
        calls.append(1)
        if len(calls) == 3:  # after two generations: the scheduler goes away
            cluster.close()
        return real(self, *args, **kwargs)

    execution.DaskExecutor.map = map_then_lose
    try:
        code, _, err = cli(capsys, "optimise", config, "-o", out, "--scheduler", address)
    finally:
        execution.DaskExecutor.map = real
        cluster.close()
    assert code == 1, err
    errors = [line for line in err.splitlines() if line.startswith("error:")]
    assert len(errors) == 1 and "Traceback" not in err, err
    assert "lost the Dask scheduler" in errors[0] and "--resume" in errors[0]
    with h5py.File(out) as h5:
        assert h5.attrs["status"] == "running" and h5.attrs["generations"] == 2
    code, _, err = cli(capsys, "optimise", config, "-o", out, "--resume")
    assert code == 0, err
    _same(_pareto(complete), _pareto(out))


def test_the_dask_executor_without_its_extra_is_bad_input(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(execution, "dask_available", lambda: False)
    code, _, err = cli(capsys, "simulate", CONFIGS / "quickstart.yaml", "--executor", "dask")
    assert code == 2 and 'pip install "suspopt[dask]"' in err and len(err.splitlines()) == 1
    config = write(
        tmp_path, (CONFIGS / "quickstart.yaml").read_text() + "execution: {executor: dask}\n"
    )
    code, _, err = cli(capsys, "validate", config)
    assert code == 2 and 'pip install "suspopt[dask]"' in err and "execution.executor" in err


@pytest.mark.parametrize(
    "args, needle",
    [
        (("--executor", "cluster"), "choose one of local, processes, dask"),
        (("--executor", "processes", "--workers", "0"), "4 per core"),
        (("--executor", "local", "--workers", "2"), "needs --executor processes or dask"),
        (("--executor", "processes", "--scheduler", "tcp://h:1"), "give --executor dask"),
        # the address's form (a traceback from distributed before: ValueError, TypeError)
        (("--executor", "dask", "--scheduler", "http://h:1"), "not http://"),
        (("--executor", "dask", "--scheduler", "inproc://"), "give [scheme://]host:port"),
        (("--executor", "dask", "--scheduler", "::::"), "IPv6 host in brackets"),
        (("--executor", "dask", "--scheduler", "tcp://h"), "give the scheduler's port"),
        (("--executor", "dask", "--scheduler", "h:99999"), "from 1 to 65535"),
        (("--executor", "dask", "--scheduler", ""), "is not a scheduler address"),
    ],
)
def test_bad_executor_options_exit_2_with_one_line(capsys, args, needle):
    code, _, err = cli(capsys, "simulate", CONFIGS / "quickstart.yaml", *args)
    assert code == 2 and needle in err and len(err.splitlines()) == 1, err


@pytest.mark.parametrize(
    "settings, needle",
    [
        ({"executor": "cluster"}, "executor cluster: choose one of local, processes, dask"),
        ({"executor": "processes", "workers": 0}, "workers 0: give a number of worker"),
        ({"executor": "processes", "workers": 10**6}, "4 per core of this machine"),
        ({"executor": "processes", "workers": "2"}, "workers '2': give a number"),
        ({"executor": "local", "workers": 2}, "workers needs executor processes or dask"),
        ({"executor": "dask", "scheduler": "tcp://h"}, "scheduler 'tcp://h': give the"),
        ({"executor": "processes", "chunk": 0}, "chunk 0: give a whole number"),
    ],
)
def test_the_library_settings_are_checked_as_the_command_lines(settings, needle):
    """``execution.use`` took any settings: 10**6 workers, 0 workers, workers "2" (a
    TypeError from a comparison), a chunk of 0; they are the command line's checks now,
    in the library's words, and nothing is put in force."""
    with pytest.raises(ValueError, match=re.escape(needle)), execution.use(**settings):
        pass
    assert execution.settings()["executor"] == "local"


@pytest.mark.parametrize(
    "section, needle",
    [
        ("{executor: local, workers: 2}", "workers needs executor"),
        ("{scheduler: tcp://h:1}", "set executor: dask"),
        ("{executor: processes, chunk: 0}", "execution.chunk"),
        ("{executor: processes, workers: 1000}", "4 per core"),
        ("{executor: dask, workers: 2, scheduler: tcp://h:1}", "a running one has its own"),
        ("{executor: processes, chunk: 1.0e9}", "execution.chunk"),
        ("5", "execution"),
        ("{executor: [dask]}", "execution.executor"),
        ("{executor: dask, scheduler: 'ws://h'}", "execution.scheduler: 'ws://h': give"),
    ],
)
def test_a_bad_execution_section_is_bad_input(tmp_path, capsys, section, needle):
    config = write(tmp_path, (CONFIGS / "quickstart.yaml").read_text() + f"execution: {section}\n")
    code, _, err = cli(capsys, "validate", config)
    assert code == 2 and needle in err and err.splitlines()[1:] == [f"1 error in {config}"], err


def test_a_scheduler_that_cannot_be_reached_is_one_line(capsys):
    """A well-formed address that cannot be connected to (tls:// without Dask's TLS
    settings: a TypeError traceback from distributed before) is the executor's failure,
    exit 1 with one line, as a scheduler that does not answer is."""
    code, _, err = cli(
        capsys, "simulate", CONFIGS / "quickstart.yaml", "--executor", "dask",
        "--scheduler", "tls://127.0.0.1:1", "--sweep", "vehicle.body.mass=2000:2100:2",
    )  # fmt: skip
    assert code == 1 and len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
    assert "cannot connect to tls://127.0.0.1:1" in err
