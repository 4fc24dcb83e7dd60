"""``suspopt export FILE.h5 --mat out.mat`` (suspopt/matfile.py): every dataset of a result
file back bit for bit from the .mat file (dtype and shape included), names valid in MATLAB with
the map of those that changed, units and provenance beside the values, bad input and bad
targets refused in one line with nothing left behind."""

from __future__ import annotations

import errno
import os
import re

import fuzz_harness as fh
import h5py
import numpy as np
import pytest
import scipy.io
from conftest import CONFIGS, optimised_front
from typer.testing import CliRunner

import suspopt
from suspopt.analyse.builds import builds as draw_and_evaluate
from suspopt.analyse.builds import write_builds
from suspopt.choosing.selection import load_design_sets, read_pareto, select, write_selection
from suspopt.cli import app
from suspopt.config import ConfigError
from suspopt.config.loader import load_config_text
from suspopt.io import is_suspopt_output, write_simulation
from suspopt.matfile import MAX_NAME, read_mat, write_mat

VALID = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """A ``simulate`` file of two designs with metrics, an ``optimise`` front, a ``kesort``
    file of two cases and an ``analyse builds`` file, each tiny."""
    d = tmp_path_factory.mktemp("mat")
    text = (CONFIGS / "quickstart.yaml").read_text().replace("duration: 3.0", "duration: 1.0")
    text += "metrics:\n  - {name: peak_heave, metric: max_abs, signal: body.heave}\n"
    res = suspopt.simulate(
        load_config_text(text), params={"vehicle.corners.F1.spring.linear": np.array([4e4, 6e4])}
    )
    sim = write_simulation(d / "sim.h5", res)
    _, front = optimised_front(d, "ch8/pareto_ps_class_a", 0.3, population=8)
    ke = write_selection(
        d / "ke.h5", select(load_design_sets([front, front], labels=["A", "B"]), P="auto")
    )
    builds = write_builds(
        d / "builds.h5", draw_and_evaluate(read_pareto(front), 3, tolerance=10.0, seed=1)
    )
    return {"simulate": sim, "optimise": front, "kesort": ke, "builds": builds}


def h5_datasets(path) -> dict[str, tuple]:
    """Every dataset of the HDF5 file ``path``, read: {path: (values, attributes)}, the values
    as an array of the dataset's own dtype and shape (h5py gives a 0-d text dataset as bytes)."""
    out = {}
    with h5py.File(path) as h5:

        def visit(name, obj):
            if isinstance(obj, h5py.Dataset):
                out[obj.name] = (np.asarray(obj[()], dtype=obj.dtype), dict(obj.attrs))

        h5.visititems(visit)
        out["/"] = (None, dict(h5.attrs))
    return out


def same(a: np.ndarray, b: np.ndarray) -> bool:
    """Equal bit for bit: dtype, shape and values (NaN equal to NaN)."""
    a, b = np.asarray(a), np.asarray(b)
    nan = a.dtype.kind in "fc"
    return a.dtype == b.dtype and a.shape == b.shape and np.array_equal(a, b, equal_nan=nan)


def fields(struct) -> dict:
    """The fields of a struct as plain ``scipy.io.loadmat`` reads it."""
    if struct.dtype.names is None:
        return {}
    return {n: struct[n][0, 0] for n in struct.dtype.names}


def names_in(value, found: list[str]) -> list[str]:
    """Every field name of every struct in ``value`` (as loadmat reads it), recursively."""
    if isinstance(value, np.ndarray) and value.dtype.names is not None:
        for name, inner in fields(value).items():
            found.append(name)
            names_in(inner, found)
    return found


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["optimise", "kesort", "simulate", "builds"])
def test_every_dataset_round_trips_bit_for_bit(files, kind, tmp_path):
    out = write_mat(files[kind], tmp_path / f"{kind}.mat")
    datasets, attributes = read_mat(out)
    expected = h5_datasets(files[kind])
    assert set(datasets) == set(expected) - {"/"} and len(datasets) > 10
    for path, (values, attrs) in expected.items():
        if path != "/":
            assert same(datasets[path], values), (path, values.dtype, values.shape)
        if "units" in attrs:
            units = attrs["units"]
            assert np.array_equal(np.atleast_1d(attributes[path]["units"]), np.atleast_1d(units))
    root = expected["/"][1]
    for key in ("suspopt_version", "created", "command", "config", "seed"):
        assert attributes["/"][key] == root[key], key  # the provenance, beside the values
    assert is_suspopt_output(out)  # (export again replaces it without --force)


@pytest.mark.slow
def test_plain_loadmat_reads_the_layout(files, tmp_path):
    """What docs/guide/export-mat.md tells a scipy user: structs per group, 1-D as columns,
    ``meta.<name>.shape`` for the HDF5 shape, units and provenance as fields."""
    out = write_mat(files["simulate"], tmp_path / "sim.mat")
    m = scipy.io.loadmat(out)
    with h5py.File(files["simulate"]) as h5:
        time, acc = h5["time"][()], h5["signals/body.heave_acc"][()]
        config = h5.attrs["config"]
    signals = fields(m["signals"])
    assert np.array_equal(signals["body_heave_acc"], acc) and acc.shape == (2, len(time))
    assert m["time"].shape == (len(time), 1)  # (a 1-D dataset: a column)
    shape = fields(fields(m["meta"])["time"])["shape"]
    assert np.array_equal(m["time"].reshape(shape.ravel()), time)
    assert fields(signals["units"])["body_heave_acc"][0] == "m/s^2"
    assert fields(m["attributes"])["config"][0] == config
    loose = scipy.io.loadmat(out, squeeze_me=True, struct_as_record=False)
    assert np.array_equal(loose["signals"].body_heave_acc, acc)
    assert loose["signals"].meta.body_heave_acc.path == "/signals/body.heave_acc"
    assert list(loose["signals"].meta.body_heave_acc.dims) == ["design", "time"]
    pairs = [tuple(row) for row in loose["names_map"]]
    assert ("/signals/body.heave_acc", "signals.body_heave_acc") in pairs


def odd_file(path):
    """A suspopt file with names MATLAB cannot take and every kind of value savemat changes."""
    with h5py.File(path, "w") as h5:
        h5.attrs["suspopt_version"] = suspopt.__version__
        h5.attrs["seed"] = np.int64(7)
        g = h5.create_group("odd.group")
        g.attrs["a weird-attr"] = "x"
        g["body.heave_acc"] = np.array([[1.0, np.nan]])
        g["body_heave_acc"] = np.arange(3, dtype=np.int8)  # (taken once the first is mapped)
        g["x" * 80] = np.array(True)
        g["x" * 70] = np.array([True, False])  # (cut to the same 63 characters)
        g["2nd"] = np.uint64([2**64 - 1])
        g["end"] = np.float16([1.5, -0.0])
        g["units"] = np.zeros((0, 3))  # (a reserved field)
        g["ü"] = np.zeros(0, dtype=np.float32)
        g["big"] = np.arange(4, dtype=">f8").reshape(2, 2, 1)
        g["complex"] = np.array([1 + 2j, np.nan])
        g["fixed"] = np.array([b"ab", b"", b"abc"], dtype="S3")
        g.create_dataset("text", data=["ü€😀", "", "a b"], dtype=h5py.string_dtype())
        g.create_dataset("scalar_text", data="one", dtype=h5py.string_dtype())
        g["scalar"] = np.int64(-3)
        g["scalar"].attrs["units"] = "m"
        g["fixed"].attrs["units"] = np.array(["m", "s", "1"], dtype=h5py.string_dtype())
        g.create_group("empty")
        h5.create_group("names_map")  # (a reserved variable)
        h5["flag"] = np.array([True, False])
    return path


@pytest.mark.cli
def test_names_that_matlab_cannot_take_are_mapped_and_the_map_stored(tmp_path):
    source = odd_file(tmp_path / "odd.h5")
    out = tmp_path / "odd.mat"
    res = CliRunner().invoke(app, ["export", str(source), "--mat", str(out)])
    assert res.exit_code == 0, res.output
    m = scipy.io.loadmat(out)
    names = [k for k in m if not k.startswith("__")]
    names_in_structs = [n for k in names for n in names_in(m[k], [])]
    assert all(VALID.match(n) and len(n) <= MAX_NAME for n in names + names_in_structs)
    pairs = {tuple(str(v[0]) for v in row) for row in m["names_map"]}
    group = "odd_group"
    assert {
        ("/odd.group", group),
        ("/odd.group/body.heave_acc", f"{group}.body_heave_acc"),
        ("/odd.group/body_heave_acc", f"{group}.body_heave_acc_2"),
        ("/odd.group/" + "x" * 70, f"{group}." + "x" * 63),
        ("/odd.group/" + "x" * 80, f"{group}." + "x" * 61 + "_2"),
        ("/odd.group/2nd", f"{group}.x2nd"),
        ("/odd.group/end", f"{group}.end_"),
        ("/odd.group/units", f"{group}.units_2"),
        ("/odd.group/ü", f"{group}.x_"),
        ("/odd.group@a weird-attr", f"{group}.attributes.a_weird_attr"),
        ("/names_map", "names_map_2"),
    } <= pairs
    datasets, attributes = read_mat(out)
    expected = h5_datasets(source)
    assert set(datasets) == set(expected) - {"/"}
    for path, (values, _) in expected.items():
        if path != "/":
            assert same(datasets[path], values), path
    assert attributes["/odd.group"] == {"a weird-attr": "x"}
    assert attributes["/odd.group/fixed"]["units"] == ["m", "s", "1"]
    assert attributes["/odd.group/scalar"]["units"] == "m"
    assert attributes["/"]["seed"] == 7 and attributes["/"]["seed"].dtype == np.int64
    classes = {name: kind for name, _, kind in scipy.io.whosmat(out)}
    assert classes["flag"] == "logical" and classes["odd_group"] == "struct"


def invoke(*args) -> tuple[int, list[str], str]:
    res = CliRunner().invoke(app, [str(a) for a in args])
    lines = [line for line in res.stderr.splitlines() if line.strip()]
    assert "Traceback" not in res.output + res.stderr
    return res.exit_code, lines, res.stdout


def left_in(folder) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


@pytest.mark.cli
@pytest.mark.slow
def test_bad_targets_and_bad_inputs_are_one_line_and_leave_nothing(files, tmp_path):
    source = files["kesort"]
    (tmp_path / "a_folder.mat").mkdir()
    foreign = tmp_path / "theirs.mat"
    foreign.write_bytes(b"MATLAB 5.0 MAT-file of someone else")
    truncated = tmp_path / "truncated.h5"
    truncated.write_bytes(source.read_bytes()[:3000])
    flipped = tmp_path / "flipped.h5"  # (the object header of /kesort/k_eps zeroed)
    with h5py.File(source) as h5:
        at = h5py.h5o.get_info(h5["kesort/k_eps"].id).addr
    data = bytearray(source.read_bytes())
    data[at : at + 64] = bytes(64)
    flipped.write_bytes(bytes(data))
    compound = tmp_path / "compound.h5"
    with h5py.File(compound, "w") as h5:
        h5.attrs["suspopt_version"] = suspopt.__version__
        h5["records"] = np.zeros(2, dtype=[("a", "f8"), ("b", "i4")])
    nul = tmp_path / "nul.h5"
    with h5py.File(nul, "w") as h5:
        h5.attrs["suspopt_version"] = suspopt.__version__
        h5["names"] = np.array([b"a\x00b"], dtype="S3")
    before = left_in(tmp_path)
    cases = [
        ((source, "--mat", tmp_path / "a_folder.mat"), "a_folder.mat: is a directory"),
        ((source, "--mat", tmp_path), "is a directory"),
        ((source, "--mat", tmp_path / "out.txt"), "out.txt: a MATLAB file's name ends in .mat"),
        ((source, "--mat", tmp_path / "nowhere" / "x.mat"), "does not exist"),
        ((source, "--mat", foreign), "theirs.mat: exists and was not written by suspopt"),
        ((source, "--mat", source), "is the same file as the input"),
        ((source, "--mat", tmp_path / "x.mat", "--pick", "knee"), "--pick is for -o"),
        ((truncated, "--mat", tmp_path / "x.mat"), "truncated.h5"),
        ((flipped, "--mat", tmp_path / "x.mat"), "flipped.h5: /kesort/k_eps: damaged"),
        ((tmp_path / "none.h5", "--mat", tmp_path / "x.mat"), "none.h5: no such file"),
        ((CONFIGS / "quickstart.yaml", "--mat", tmp_path / "x.mat"), "quickstart.yaml"),
        ((compound, "--mat", tmp_path / "x.mat"), "compound.h5: /records: data of type"),
        ((nul, "--mat", tmp_path / "x.mat"), "nul.h5: /names: text with a NUL character"),
    ]
    for args, words in cases:
        code, lines, _ = invoke("export", *args)
        assert code == 2 and len(lines) == 1 and words in lines[0], (args, lines)
        assert left_in(tmp_path) == before, args  # (no target, temporary or lock left)
    assert foreign.read_bytes() == b"MATLAB 5.0 MAT-file of someone else"
    code, _, said = invoke("export", source, "--mat", foreign, "--force")
    assert code == 0 and said.strip() == f"wrote {foreign}"
    assert "/kesort/k_eps" in read_mat(foreign)[0]


@pytest.mark.cli
def test_a_folder_that_cannot_be_written_is_one_line(files, tmp_path, monkeypatch):
    """A read-only folder (as root, which writes anywhere, the refusal the system gives
    another user: EACCES from every file made there) and a read-only file system."""
    folder = tmp_path / "locked"
    folder.mkdir()
    folder.chmod(0o555)
    if os.geteuid() == 0:
        real = os.open

        def refused(path, flags, *args, **kwargs):
            if str(path).startswith(str(folder)) and flags & os.O_CREAT:
                raise PermissionError(errno.EACCES, os.strerror(errno.EACCES), str(path))
            return real(path, flags, *args, **kwargs)

        monkeypatch.setattr(os, "open", refused)
    code, lines, _ = invoke("export", files["kesort"], "--mat", folder / "x.mat")
    assert code == 2 and len(lines) == 1 and "x.mat: cannot write in" in lines[0], lines
    assert left_in(folder) == []


@pytest.mark.slow
def test_a_write_that_fails_leaves_the_old_file(files, tmp_path, monkeypatch):
    """A full disk in the middle of savemat: the old .mat file stays as it was, no temporary."""
    out = write_mat(files["kesort"], tmp_path / "ke.mat")
    old = out.read_bytes()

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(scipy.io, "savemat", full)
    with pytest.raises(ConfigError, match=r"ke.mat: cannot write it \(No space left"):
        write_mat(files["simulate"], out)
    assert out.read_bytes() == old and left_in(tmp_path) == ["ke.mat"]


@pytest.mark.cli
@pytest.mark.slow
def test_hostile_target_names_are_refused_in_one_line(files, tmp_path):
    """The fuzz harness's hostile option values (:data:`fuzz_harness.OPTION_VALUES`) as the
    --mat target, as given (none ends in .mat) and, for those in the case's folder, with
    ``.mat`` added: each is refused with exit 2 and one line, or written."""
    (tmp_path / "study.yaml").write_text("a file, not a folder\n")
    os.mkfifo(tmp_path / "fifo")
    os.mkfifo(tmp_path / "fifo.mat")
    before = set(left_in(tmp_path))
    for value in fh.OPTION_VALUES:
        target = value.replace("{path}", str(tmp_path))
        code, lines, _ = invoke("export", files["kesort"], "--mat", target)
        assert code == 2 and len(lines) == 1, (value, code, lines)
        if "{path}" not in value:
            continue
        code, lines, _ = invoke("export", files["kesort"], "--mat", target + ".mat")
        assert code in (0, 2) and len(lines) == (code == 2), (value, code, lines)
        if code == 0:
            assert read_mat(target + ".mat")[0]
    made = set(left_in(tmp_path)) - before  # (new names in the folder: no lock, no temporary)
    assert made == {"front.h5.mat", "study.yaml.mat"}, made
    assert (tmp_path / "fifo.mat").is_fifo()
