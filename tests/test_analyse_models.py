"""``suspopt analyse models``: Ch. 3 models side by side (transient, ride, modes, PSD)."""

from __future__ import annotations

from types import SimpleNamespace

import h5py
import numpy as np
import pytest
from conftest import CONFIGS
from typer.testing import CliRunner

from suspopt.cli import app
from suspopt.metrics import transient_metrics, weighted_rms


def run(*args):
    """The CLI in-process: exit code, stdout, stderr."""
    result = CliRunner().invoke(app, [str(a) for a in args])
    return SimpleNamespace(
        returncode=result.exit_code,
        stdout=result.stdout,
        stderr=result.stderr,
        exception=result.exception,
    )


def short(tmp_path, name: str, duration: float):
    """A Ch. 3 config with a shorter run, written to tmp_path under its own name."""
    text = (CONFIGS / "ch3" / f"{name}.yaml").read_text()
    old = "duration: 9.0" if "bump" in name else "duration: 60.0"
    assert old in text
    path = tmp_path / f"{name}.yaml"
    path.write_text(text.replace(old, f"duration: {duration}"))
    return path


def datasets(h5):
    found = []
    h5.visititems(
        lambda name, obj: found.append((name, obj)) if isinstance(obj, h5py.Dataset) else None
    )
    return found


@pytest.mark.slow
def test_models_on_the_bump_compare_transient_metrics_with_the_reference(tmp_path):
    qc, hc2 = short(tmp_path, "part1a_qc_bump", 6.0), short(tmp_path, "part1a_hc2_bump", 6.0)
    out, fig = tmp_path / "models.h5", tmp_path / "models.svg"
    proc = run("analyse", "models", qc, hc2, "--reference", qc, "-o", out, "--plot", fig)
    assert proc.returncode == 0, proc.stderr
    assert "peak.body.heave_acc" in proc.stdout and "(ref)" in proc.stdout
    assert fig.read_text().lstrip().startswith("<?xml") and "<svg" in fig.read_text()[:2000]
    with h5py.File(out) as h5:
        assert all("units" in ds.attrs for _, ds in datasets(h5))
        assert list(h5.attrs["models"].astype(str)) == ["part1a_qc_bump", "part1a_hc2_bump"]
        assert h5.attrs["reference"] == "part1a_qc_bump"
        assert h5.attrs["config"] == qc.read_text()
        t = h5["models/part1a_qc_bump/time"][()]
        assert t.shape == (6001,) and h5["models/part1a_qc_bump/time"].attrs["units"] == "s"
        value, diff = h5["comparison/value"], h5["comparison/difference"]
        for i, model in enumerate(("part1a_qc_bump", "part1a_hc2_bump")):
            g = h5[f"models/{model}"]
            assert g["signals/body.heave"].attrs["units"] == "m"
            assert g["signals/body.heave_acc"].attrs["units"] == "m/s^2"
            assert g["psd/body.heave_acc"].attrs["units"] == "(m/s^2)^2/Hz"
            assert g["psd/body.heave_acc"].shape == g["psd/frequency"].shape
            # the table's numbers are the transient metrics of the stored signals (Sec 2.4.1)
            for signal in ("body.heave", "body.heave_acc"):
                m = transient_metrics(g["time"][()], g[f"signals/{signal}"][()], start=2.0)
                for key in ("peak", "peak_time", "rise_time", "settling_time"):
                    assert value[f"{key}.{signal}"][i] == m[key]
        assert "overshoot.body.heave" in value and "overshoot.body.heave_acc" not in value
        for name in value:
            v = value[name][()]
            assert value[name].shape == (2,) and diff[name].attrs["units"] == "%"
            np.testing.assert_allclose(diff[name][()], 100 * (v - v[0]) / v[0], rtol=1e-12)
        # the two groups of Sec 3.2.1: HC2's peak acceleration is about half QC's
        assert -55 < diff["peak.body.heave_acc"][1] < -45
        assert np.isnan(value["natural_frequency.body.pitch"][0])


def test_models_natural_frequencies_are_the_quarter_cars_closed_form(tmp_path):
    """QC of Table 3.1: the two roots of m_s m_u w^4 - (k m_u + (k + k_T) m_s) w^2 + k k_T."""
    qc, hc1 = short(tmp_path, "part1a_qc_bump", 3.0), short(tmp_path, "part1a_hc1_bump", 3.0)
    out = tmp_path / "modes.h5"
    assert run("analyse", "models", qc, hc1, "-o", out).returncode == 0
    m_s, m_u, k, k_t = 271.25, 40.0, 1.0e4, 1.5e5
    w2 = np.roots([m_s * m_u, -(k * m_u + (k + k_t) * m_s), k * k_t])
    f = np.sort(np.sqrt(w2)) / (2 * np.pi)
    with h5py.File(out) as h5:
        value = h5["comparison/value"]
        assert value["natural_frequency.body.heave"][0] == pytest.approx(f[0], rel=1e-9)
        assert value["natural_frequency.wheel_hop"][0] == pytest.approx(f[1], rel=1e-9)
        np.testing.assert_allclose(
            np.sort(h5["models/part1a_qc_bump/modal/frequency"][()]), f, rtol=1e-9
        )
        assert h5["models/part1a_hc1_bump/modal/frequency"].shape == (4,)
        assert value["natural_frequency.body.roll"][1] > 0


@pytest.mark.slow
def test_models_on_a_random_road_compare_ride_metrics_per_corner(tmp_path):
    qc, fc = short(tmp_path, "part1a_qc_class_b", 4.0), short(tmp_path, "part1a_fc_class_b", 4.0)
    out, fig = tmp_path / "ride.h5", tmp_path / "ride.png"
    proc = run("analyse", "models", qc, fc, "-o", out, "--plot", fig)
    assert proc.returncode == 0, proc.stderr
    assert fig.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with h5py.File(out) as h5:
        value, diff = h5["comparison/value"], h5["comparison/difference"]
        fs = 1.0 / 1.0e-3
        for i, model in enumerate(("part1a_qc_class_b", "part1a_fc_class_b")):
            acc = h5[f"models/{model}/signals/body.heave_acc"][()]
            assert value["RC"][i] == weighted_rms(acc, fs, "Wk")
            assert value["max_body_acc"][i] == np.max(np.abs(acc))
        assert value["VST.F1"].attrs["units"] == "m^2" and value["MST.F1"].attrs["units"] == "m"
        assert np.isnan(value["VST.R2"][0]) and value["VST.R2"][1] > 0
        # QC's one corner stands for each of FC's (as Table 3.7 compares them)
        vst = value["VST.F1"][0]
        for corner in ("F1", "F2", "R1", "R2"):
            assert diff[f"VST.{corner}"][1] == pytest.approx(
                100 * (value[f"VST.{corner}"][1] - vst) / vst, rel=1e-12
            )
        assert "body.roll_acc" in h5["models/part1a_fc_class_b/psd"]
        assert "body.roll_acc" not in h5["models/part1a_qc_class_b/psd"]
        assert "var.body.roll" not in value  # QC has no roll: not compared


@pytest.mark.parametrize(
    "case, needle",
    [
        ("one", "at least two configs"),
        ("mixed", "one kind of road"),
        ("reference", "not one of the configs compared"),
        ("pareto", "not a YAML config"),
    ],
)
def test_models_bad_input_exits_2_with_one_line_and_no_output(tmp_path, case, needle):
    qc = short(tmp_path, "part1a_qc_bump", 3.0)
    other = {
        "one": [],
        "mixed": [short(tmp_path, "part1a_qc_class_b", 3.0)],
        "reference": [short(tmp_path, "part1a_hc1_bump", 3.0)],
        "pareto": [tmp_path / "front.h5"],
    }[case]
    if case == "pareto":
        with h5py.File(other[0], "w") as h5:
            h5["x"] = 1
    extra = ["--reference", CONFIGS / "ch3" / "part1a_fc_bump.yaml"] if case == "reference" else []
    out = tmp_path / "out.h5"
    proc = run("analyse", "models", qc, *other, *extra, "-o", out, "--plot", tmp_path / "f.png")
    assert proc.returncode == 2, (proc.stdout, proc.stderr, proc.exception)
    message = proc.stderr.strip()
    assert len(message.splitlines()) == 1 and needle in message, message
    assert "Traceback" not in message
    assert not out.exists() and not (tmp_path / "f.png").exists()
