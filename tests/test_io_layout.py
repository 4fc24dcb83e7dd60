"""Files that read back anywhere: HDF5 dimension scales (xarray with h5netcdf, pandas), names
as variable-length UTF-8, ``suspopt.io.open_dataset`` and the CSV export."""

from __future__ import annotations

import csv
import sys

import h5py
import numpy as np
import pandas as pd
import pytest
import xarray as xr
from conftest import CONFIGS, optimised_front

import suspopt
from suspopt.analyse import models, transmissibility
from suspopt.analyse.builds import builds as draw_and_evaluate
from suspopt.analyse.builds import write_builds
from suspopt.analyse.pseudo import pseudo_fronts, road_variants, write_pseudo_fronts
from suspopt.choosing.picks import read_front
from suspopt.choosing.selection import load_design_sets, read_pareto, select, write_selection
from suspopt.config import ConfigError
from suspopt.config.loader import load_config_text
from suspopt.export import write_csv
from suspopt.io import is_suspopt_output, open_dataset, write_dataset, write_simulation

K = [4.0e4, 6.0e4]  # two designs: the design axis is not a single row


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """A simulate file of two designs with metrics, a tiny Pareto front, a kesort file of two
    cases, and ``analyse roads``, ``transmissibility`` and ``models`` files."""
    d = tmp_path_factory.mktemp("layout")
    text = (CONFIGS / "quickstart.yaml").read_text().replace("duration: 3.0", "duration: 1.0")
    text += (
        "metrics:\n  - {name: RC, metric: rms_weighted, signal: body.heave_acc, "
        "weighting: Wk}\n  - {name: peak_heave, metric: max_abs, signal: body.heave}\n"
    )
    res = suspopt.simulate(
        load_config_text(text), params={"vehicle.corners.F1.spring.linear": np.array(K)}
    )
    sim = write_simulation(d / "sim.h5", res)
    _, optimised = optimised_front(d, "ch8/pareto_ps_class_a", 2.0)
    front = optimised.rename(d / "front.h5")
    ke = write_selection(
        d / "ke.h5", select(load_design_sets([front, front], labels=["A", "B"]), P="auto")
    )
    pareto = read_pareto(front)
    roads = write_pseudo_fronts(
        d / "roads.h5", pseudo_fronts("roads", pareto, road_variants(pareto, ["B"]))
    )
    builds = write_builds(d / "builds.h5", draw_and_evaluate(pareto, 4, tolerance=10.0, seed=1))
    knee = read_front(ke, ["chosen", "knee"])  # (designs picked from a kesort file)
    picked = write_builds(d / "picked.h5", draw_and_evaluate(knee, 3, tolerance="C_v=5", seed=1))
    transmissibility.run(front).write(d / "stht.h5")
    models.run([CONFIGS / "ch3/part1a_qc_bump.yaml", CONFIGS / "ch3/part1a_hc1_bump.yaml"]).write(
        d / "models.h5"
    )
    return {
        "sim": sim,
        "front": front,
        "ke": ke,
        "roads": roads,
        "stht": d / "stht.h5",
        "models": d / "models.h5",
        "builds": builds,
        "picked": picked,
    }


def groups(path) -> list[str | None]:
    found = [None]
    with h5py.File(path) as h5:
        h5.visititems(lambda n, o: found.append(n) if isinstance(o, h5py.Group) else None)
    return found


#: Attributes of the HDF5 dimension-scale API itself (fixed-length ASCII by its standard).
H5DS = {"CLASS", "NAME", "REFERENCE_LIST", "DIMENSION_LIST"}


def datasets(path) -> list[tuple[str, tuple, dict]]:
    """(path, dims (its own name for a scale), dtype, attributes' dtypes) of every dataset."""
    out = []
    with h5py.File(path) as h5:

        def visit(name, obj):
            if isinstance(obj, h5py.Dataset):
                dims = (
                    (name.rsplit("/", 1)[-1],)
                    if obj.is_scale
                    else tuple(d[0].name.rsplit("/", 1)[-1] if len(d) else None for d in obj.dims)
                )
                out.append(
                    (
                        name,
                        dims,
                        obj.dtype,
                        {k: obj.attrs.get_id(k).dtype for k in obj.attrs if k not in H5DS},
                    )
                )

        h5.visititems(visit)
    return out


@pytest.mark.parametrize(
    "kind", ["sim", "front", "ke", "roads", "stht", "models", "builds", "picked"]
)
@pytest.mark.slow
def test_every_group_opens_in_xarray_with_named_dimensions(files, kind):
    """No phony_dim anywhere; the whole file is one DataTree (one length per name)."""
    path = files[kind]
    for group in groups(path):
        ds = xr.open_dataset(path, engine="h5netcdf", group=group, phony_dims="sort")
        assert not [d for d in ds.sizes if d.startswith("phony_dim")], (group, ds.sizes)
        mine = open_dataset(path, group)
        assert all(d in mine.coords for d in mine.sizes), (group, mine.sizes)
    assert xr.open_datatree(path, engine="h5netcdf").groups
    for name, dims, _, _ in datasets(path):
        assert None not in dims, name  # every axis has its scale


@pytest.mark.slow
def test_simulate_file_has_time_and_design(files):
    path = files["sim"]
    with h5py.File(path) as h5:
        time, acc = h5["time"][()], h5["signals/body.heave_acc"][()]
        rc = h5["metrics/RC"][()]
    root = xr.open_dataset(path, engine="h5netcdf")
    assert dict(root.sizes) == {"design": 2, "time": len(time)}
    assert np.array_equal(root["time"].values, time) and root["time"].attrs["units"] == "s"
    assert root["diverged_at"].dims == ("design",)
    signals = xr.open_dataset(path, engine="h5netcdf", group="signals")
    assert signals["body.heave_acc"].dims == ("design", "time")
    inherited = xr.open_datatree(path, engine="h5netcdf")["signals"].to_dataset()
    assert np.array_equal(inherited["time"].values, time)
    ds = open_dataset(path, "signals")
    assert np.array_equal(ds["time"].values, time) and list(ds["design"].values) == [0, 1]
    assert ds["body.heave_acc"].attrs["units"] == "m/s^2"
    frame = open_dataset(path, "signals").to_dataframe()  # the one-liner
    assert list(frame.index.names) == ["design", "time"] and len(frame) == 2 * len(time)
    assert np.array_equal(frame["body.heave_acc"].to_numpy().reshape(2, -1), acc)
    metrics = open_dataset(path, "metrics").to_dataframe()
    assert list(metrics.index) == [0, 1] and np.array_equal(metrics["RC"].to_numpy(), rc)
    modal = open_dataset(path, "modal")
    assert modal["energy_share"].dims == ("design", "mode", "dof")
    assert list(modal["dof"].values) == list(modal["energy_share"].attrs["dofs"])
    designs = open_dataset(path, "designs")["X"].to_pandas()
    assert list(designs.columns) == ["vehicle.corners.F1.spring.linear"]
    assert designs.iloc[:, 0].tolist() == K


def test_pareto_file_has_names_as_coordinates(files):
    path = files["front"]
    pareto = read_pareto(path)
    ds = xr.open_dataset(path, engine="h5netcdf", group="pareto")
    assert ds["F"].dims == ("design", "objective") and ds["X"].dims == ("design", "variable")
    assert ds["G"].dims == ("design", "constraint")
    assert list(ds["constraint"].values) == pareto.constraint_names
    F = ds["F"].to_pandas()  # the one-liner
    assert list(F.columns) == pareto.obj_names == ["RC_se", "X_ST"]
    assert list(F.index) == list(range(len(pareto.F))) and np.array_equal(F.to_numpy(), pareto.F)
    X = ds["X"].to_pandas()
    assert list(X.columns) == pareto.var_names and np.array_equal(X.to_numpy(), pareto.X)
    assert list(ds["X"].attrs["units"]) == pareto.var_units  # per column, as before
    history = open_dataset(path, "history")
    assert history["best"].dims == ("generation", "objective")
    checkpoint = open_dataset(path, "checkpoint")
    assert checkpoint["X"].dims == ("evaluation", "variable")
    assert list(checkpoint["variable"].values) == pareto.var_names


def test_kesort_file_has_design_and_case_dimensions(files):
    path = files["ke"]
    ds = open_dataset(path, "kesort")
    assert ds["F"].dims == ("design", "objective") and ds["k_eps"].dims == ("design",)
    assert list(ds["objective"].values) == ["RC_se", "X_ST"]
    assert set(ds["case"].values) == {"A", "B"} and ds["ties"].dims == ("tie",)
    frame = ds[["case", "k_eps", "k", "feasible"]].to_dataframe()
    assert len(frame) == ds.sizes["design"] and frame.index.name == "design"
    case = open_dataset(path, "kesort/cases/B")
    with h5py.File(path) as h5:
        rows = h5["kesort/cases/B/rows"][()]
    assert case["k_eps"].dims == ("rows",) and np.array_equal(case["rows"].values, rows)
    assert case["ties"].dims == ("case_tie",)
    sets = open_dataset(path, "kesort/sets")
    assert list(sets["label"].values) == ["A", "B"]


def test_roads_file_has_pareto_and_pseudo_dimensions(files):
    path = files["roads"]
    front = open_dataset(path, "pareto")["F"].to_pandas()
    pseudo = open_dataset(path, "pseudo/class B")
    assert pseudo["change"].dims == ("design", "objective")
    assert list(pseudo["objective"].values) == list(front.columns)
    assert pseudo.sizes["design"] == len(front)


def test_names_and_text_are_variable_length_utf8(files):
    for path in files.values():
        with h5py.File(path) as h5:
            roots = {k: h5.attrs.get_id(k).dtype for k in h5.attrs}
        for name, _, dtype, attrs in datasets(path) + [("/", (), np.dtype(float), roots)]:
            for key, kind in [("data", dtype), *attrs.items()]:
                assert kind.kind != "S", (path.name, name, key)  # no fixed-length bytes
                info = h5py.check_string_dtype(kind)
                if info is not None:
                    assert info.encoding == "utf-8" and info.length is None, (name, key)
    with h5py.File(files["front"]) as h5:
        assert list(h5["pareto/F"].attrs["names"]) == ["RC_se", "X_ST"]
        assert h5["pareto/objective"].asstr()[()].tolist() == ["RC_se", "X_ST"]


def test_write_dataset_keeps_one_length_per_dimension(tmp_path):
    with h5py.File(tmp_path / "x.h5", "w") as h5:
        write_dataset(h5, "time", np.arange(3.0), "s", dims=("time",))
        g = h5.create_group("signals")
        ds = write_dataset(g, "a", np.zeros((2, 3)), "m", dims=("design", "time"))
        assert ds.dims[1][0] == h5["time"] and g["design"][()].tolist() == [0, 1]
        with pytest.raises(ValueError, match="2 axes"):
            write_dataset(g, "b", np.zeros((2, 3)), "m", dims=("design",))
        with pytest.raises(ValueError, match="'time' of length 4"):
            write_dataset(g, "c", np.zeros((2, 4)), "m", dims=("design", "time"))
        sub = g.create_group("sub")
        with pytest.raises(ValueError, match="'time' of length 5"):
            write_dataset(sub, "time", np.arange(5.0), "s", dims=("time",))
        write_dataset(
            g, "F", np.zeros((2, 2)), ["m", "s"], dims=("design", "objective"), names=["f1", "f2"]
        )
        with pytest.raises(ValueError, match="are not the values"):
            write_dataset(
                g, "S", np.zeros((2, 2)), "m", dims=("design", "objective"), names=["f3", "f4"]
            )


def test_open_dataset_names_the_extra_when_xarray_is_missing(files, monkeypatch):
    monkeypatch.setitem(sys.modules, "xarray", None)
    with pytest.raises(ModuleNotFoundError, match=r"pip install xarray h5netcdf"):
        open_dataset(files["front"], "pareto")


@pytest.mark.slow
def test_open_dataset_of_a_group_the_file_lacks_lists_its_groups(files, tmp_path):
    """xarray said "[Errno group not found: bogus] 'bogus'", and h5py "Unable to
    synchronously open file (file signature not found)" for a file that is no HDF5."""
    pytest.importorskip("xarray")
    with pytest.raises(KeyError, match=r"no group 'pareto/F'; it has .*pareto"):
        open_dataset(files["front"], "pareto/F")
    (tmp_path / "case.yaml").write_text("vehicle: {}\n")
    with pytest.raises(suspopt.ConfigError, match="case.yaml: not an HDF5 file"):
        open_dataset(tmp_path / "case.yaml")
    with pytest.raises(suspopt.ConfigError, match="nowhere.h5: no such file"):
        open_dataset(tmp_path / "nowhere.h5", "pareto")


def test_open_dataset_reads_dot_as_the_root_and_refuses_a_way_out(files):
    """``"."`` and ``"./pareto/"`` name the root and ``/pareto`` as h5py reads them (xarray
    said "group not found: ."); ``"pareto/.."`` leaves the group it names, and a group that
    is no string is a TypeError, not xarray's."""
    pytest.importorskip("xarray")
    assert open_dataset(files["front"], "./pareto/").equals(open_dataset(files["front"], "pareto"))
    assert open_dataset(files["front"], ".").equals(open_dataset(files["front"]))
    with pytest.raises(KeyError, match=r"no group 'pareto/\.\.'"):
        open_dataset(files["front"], "pareto/..")
    with pytest.raises(TypeError, match="group must be a str"):
        open_dataset(files["front"], 3)


def read_table(path):
    """Header and rows of a CSV file of suspopt's, with the Python csv module."""
    with open(path, newline="", encoding="utf-8") as stream:
        first = stream.readline()
        rows = list(csv.reader(stream))
    return first, rows[0], rows[1:]


def test_csv_export_has_units_in_the_header_and_round_trips(files, tmp_path):
    folder = tmp_path / "csv"
    written = {
        p.name: p
        for kind in ("sim", "front", "ke", "roads")
        for p in write_csv(files[kind], folder)
    }
    assert {
        "sim.signals.csv",
        "sim.csv",
        "sim.metrics.csv",
        "sim.modal.energy_share.csv",
        "front.pareto.X.csv",
        "front.pareto.F.csv",
        "front.pareto.G.csv",
        "front.history.csv",
        "ke.kesort.F.csv",
        "ke.kesort.design.csv",
        "ke.kesort.cases.A.rows.csv",
        "roads.pseudo.class_B.F.csv",
        "roads.pseudo.class_B.change.csv",
    } <= set(written)
    assert not [n for n in written if "checkpoint" in n]
    for path in written.values():
        assert is_suspopt_output(path) and path.read_text().startswith("# written by suspopt")
    with h5py.File(files["sim"]) as h5:
        time, acc = h5["time"][()], h5["signals/body.heave_acc"][()]
        T = len(time)
        first, header, rows = read_table(written["sim.signals.csv"])
        assert "sim.h5 (/signals)" in first
        assert header[:2] == ["design [1]", "time [s]"] and "body.heave_acc [m/s^2]" in header
        assert len(header) == 2 + len(h5["signals"]) and len(rows) == 2 * T
        col = header.index("body.heave_acc [m/s^2]")
        assert np.array_equal([float(r[col]) for r in rows], acc.ravel())  # bit for bit
        assert [float(r[1]) for r in rows[:T]] == time.tolist()
        assert [int(r[0]) for r in rows[T - 1 : T + 1]] == [0, 1]
        frame = pd.read_csv(written["sim.metrics.csv"], skiprows=1)
        assert list(frame.columns) == ["design [1]", "RC [m/s^2]", "peak_heave [m]"]
        assert np.array_equal(frame["RC [m/s^2]"].to_numpy(), h5["metrics/RC"][()])
    pareto = read_pareto(files["front"])
    F = pd.read_csv(written["front.pareto.F.csv"], skiprows=1)
    assert list(F.columns) == ["design [1]", "RC_se [m/s^2]", "X_ST [m]"]
    assert np.array_equal(F.iloc[:, 1:].to_numpy(), pareto.F)
    X = pd.read_csv(written["front.pareto.X.csv"], skiprows=1)
    assert list(X.columns)[1:] == [f"{n} [{u}]" for n, u in zip(pareto.var_names, pareto.var_units)]
    assert np.array_equal(X.iloc[:, 1:].to_numpy(), pareto.X)
    G = pd.read_csv(written["front.pareto.G.csv"], skiprows=1)
    assert list(G.columns)[-1] == "simulation_failed [1]"
    with h5py.File(files["ke"]) as h5:
        ke = pd.read_csv(written["ke.kesort.design.csv"], skiprows=1)
        assert np.array_equal(ke["k_eps [1]"].to_numpy(), h5["kesort/k_eps"][()])
        assert ke["case [1]"].tolist() == h5["kesort/case"].asstr()[()].tolist()
        sets = pd.read_csv(written["ke.kesort.sets.csv"], skiprows=1)
        assert sets["config [1]"].tolist() == h5["kesort/sets/config"].asstr()[()].tolist()
    change = pd.read_csv(written["roads.pseudo.class_B.change.csv"], skiprows=1)
    assert list(change.columns) == ["design [1]", "RC_se [%]", "X_ST [%]"]


def test_csv_export_replaces_only_its_own_files(files, tmp_path):
    folder = tmp_path / "out"
    folder.mkdir()
    foreign = folder / "sim.signals.csv"
    foreign.write_text("a,b\n1,2\n")
    with pytest.raises(ConfigError, match="sim.signals.csv: exists and was not written by"):
        write_csv(files["sim"], folder)
    assert sorted(p.name for p in folder.iterdir()) == ["sim.signals.csv"]  # nothing written
    written = write_csv(files["sim"], folder, force=True)
    assert foreign in written and foreign.read_text().startswith("# written by suspopt")
    assert write_csv(files["sim"], folder) == written  # its own files: replaced
    assert not [p for p in folder.iterdir() if p.name.startswith(".")]  # no temporary left


def test_csv_export_needs_a_suspopt_file(tmp_path):
    other = tmp_path / "other.h5"
    with h5py.File(other, "w") as h5:
        h5["x"] = np.arange(3)
    with pytest.raises(ConfigError, match="other.h5: not a file suspopt wrote"):
        write_csv(other, tmp_path / "csv")
    with pytest.raises(ConfigError, match="nowhere.h5: no such file"):
        write_csv(tmp_path / "nowhere.h5", tmp_path / "csv")
