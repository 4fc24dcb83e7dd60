"""The wheel works outside the source tree: ``python -m build`` makes an sdist and a wheel (the
wheel built from the sdist, so the sdist holds everything too), the wheel alone installs into
a fresh virtual environment with its dependencies from the package index, and from an empty
folder that install runs the walk of docs/getting-started/walk.md: ``init kesort``,
``validate``, ``optimise --plot``, ``kesort``, ``report``, each exit 0, with the plot and the
report's page written. The starter configs, the JSON Schema and the report's page come from
the installed package, never from this checkout.

It needs the network (or pip's cache) for the build backend and the dependencies, and takes
a minute or more. The compiled kernel is shared with this checkout's through the machine's
cache (docs/guide/engines.md#the-first-compiled-run-on-a-machine): the installed copy has
the same sources, so it compiles nothing when this checkout's kernel is compiled.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent

pytestmark = [pytest.mark.slow, pytest.mark.cli]


def _run(args, cwd, env, timeout=900) -> subprocess.CompletedProcess:
    proc = subprocess.run(
        [str(a) for a in args],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=timeout,
    )
    assert proc.returncode == 0, (args, proc.stdout[-2000:], proc.stderr[-4000:])
    return proc


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    """A fresh virtual environment with the wheel built from this checkout installed
    alone: ``(its bin folder, an environment for its commands)``."""
    base = tmp_path_factory.mktemp("wheel")
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PYTHON", "VIRTUAL_ENV"))}
    env["PIP_DISABLE_PIP_VERSION_CHECK"] = "1"
    dist = base / "dist"
    _run([sys.executable, "-m", "build", "--outdir", dist, ROOT], base, env)
    wheels, sdists = sorted(dist.glob("*.whl")), sorted(dist.glob("*.tar.gz"))
    assert len(wheels) == 1 and len(sdists) == 1, sorted(dist.iterdir())
    names = zipfile.ZipFile(wheels[0]).namelist()
    for data in ("suspopt/schema.json", "suspopt/templates/kesort.yaml"):
        assert data in names, f"{data} is not in the wheel"
    assert not any(n.startswith(("tests/", "docs/", "configs/")) for n in names)
    venv = base / "venv"
    _run([sys.executable, "-m", "venv", venv], base, env)
    bin_ = venv / "bin"
    # (--no-compile: the packages are byte-compiled on import, as a user's first run does)
    _run([bin_ / "python", "-m", "pip", "install", "-q", "--no-compile", wheels[0]], base, env)
    env["PATH"] = f"{bin_}{os.pathsep}{env.get('PATH', '')}"
    env["MPLBACKEND"] = "Agg"
    return bin_, env


def test_the_wheel_alone_does_the_walk_from_an_empty_folder(installed, tmp_path):
    bin_, env = installed
    work = tmp_path / "study"
    work.mkdir()
    where = _run([bin_ / "python", "-c", "import suspopt; print(suspopt.__file__)"], work, env)
    assert str(bin_.parent) in where.stdout and str(ROOT) not in where.stdout
    _run([bin_ / "python", "-c", "import numba, plotly, matplotlib, xarray, h5netcdf"], work, env)
    suspopt = bin_ / "suspopt"
    _run([suspopt, "init", "kesort", "-o", "study.yaml"], work, env)
    _run([suspopt, "validate", "study.yaml"], work, env)
    schema = json.loads(_run([suspopt, "schema"], work, env).stdout)
    assert schema["$id"] == "urn:suspopt:schema:config"
    _run([suspopt, "optimise", "study.yaml", "-o", "front.h5", "--plot", "front.png"], work, env)
    _run([suspopt, "kesort", "front.h5", "-o", "choice.h5"], work, env)
    _run([suspopt, "report", "front.h5", "choice.h5", "-o", "study.html"], work, env)
    for name in ("front.h5", "front.png", "choice.h5", "study.html"):
        assert (work / name).stat().st_size > 0, name
    page = (work / "study.html").read_text(encoding="utf-8")
    assert "plotly" in page and "suspoptReport" in page
    assert sorted(p.name for p in work.iterdir()) == sorted(
        ["study.yaml", "front.h5", "front.png", "choice.h5", "study.html"]
    )
