"""The reproduction report's pieces (examples/): the thesis's values file, the budget copies,
and Chapter 3's tables from small synthetic `analyse models` files. The report itself runs
outside the suite (examples/reproduce_thesis.sh; SUSPOPT_QUICK=1 for its structure)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
sys.path.insert(0, str(EXAMPLES))

import mdtables as md

pytest.importorskip("matplotlib")
import report

THESIS = md.thesis_values()


def test_thesis_values_are_complete():
    ch3 = THESIS["ch3"]
    assert set(ch3["tables"]) == {f"3.{i}" for i in range(3, 22)}
    for number, table in ch3["tables"].items():
        assert set(report.CH3_FILES) >= {number}
        for row in table["rows"]:
            assert row["unit"] in md.UNITS, (number, row)
            assert set(row) - {"quantity", "label", "unit"} <= set(ch3["columns"]), row
    for table in THESIS["ch4"]["tables"].values():
        assert set(table["roads"]) == {"bump", "class_a", "class_b", "class_c"}
        for road in table["roads"].values():
            assert all(len(road[k]) == 3 for k in ("SW", "RC", "ST", "TD", "DE"))
    ch5 = THESIS["ch5"]
    for case in ch5["cases"].values():
        assert set(case["variables"]) == set(ch5["variables"])
        assert set(case["metrics"]) == set(ch5["metrics"])
        assert all(
            len(v) == 5
            for v in [*case["variables"].values(), *case["metrics"].values(), case["time"]]
        )
    assert set(THESIS["ch6"]["objectives"]) == {f"f{i}" for i in range(1, 7)}
    assert all(len(v["values"]) == 5 for v in THESIS["ch7"]["objectives"].values())
    assert set(THESIS["ch8"]["table_8_12"]) == set(THESIS["ch8"]["seats"])


def test_number_cells():
    assert md.num(0.12345) == "0.123" and md.num(102620.0) == "102620"
    assert md.num(float("nan")) == "-" and md.printed(None) == "-"
    assert md.pct(md.difference(1.1, 1.0)) == "+10.0 %"
    assert md.table(["a", "b"], [["1", "x|y"]]).splitlines()[2] == "| 1 | x\\|y |"


def test_budget_copies(tmp_path):
    cfg = Path(__file__).resolve().parents[1] / "configs" / "ch5" / "case1_s2.yaml"

    def run(env):
        command = [str(EXAMPLES / "budget_config.sh"), str(cfg), str(tmp_path)]
        return subprocess.run(
            command,
            capture_output=True,
            text=True,
            env={"PATH": "/usr/bin:/bin", **env},
            check=True,
        ).stdout

    assert run({}).strip() == str(cfg)
    copy = Path(run({"SUSPOPT_MAX_EVALUATIONS": "5000", "SUSPOPT_GENERATIONS": "7"}).strip())
    text = copy.read_text()
    assert "  max_evaluations: 5000\n" in text and "  generations: 7\n" in text
    assert "  population: 1000\n" in text
    quick = Path(run({"SUSPOPT_QUICK": "1"}).strip()).read_text()
    assert "  population: 8\n" in quick and "max_evaluations" not in quick


def _models_file(path: Path, labels: list[str], metrics: set[str], rng) -> None:
    with h5py.File(path, "w") as h5:
        h5.attrs["models"] = np.array(labels, dtype="S")
        for group in ("value", "difference"):
            g = h5.create_group(f"comparison/{group}")
            for m in metrics:
                g.create_dataset(m, data=rng.uniform(0.5, 1.5, len(labels))).attrs["units"] = "SI"


def _metrics_file(path: Path, metrics: set[str], rng, config: Path | None = None) -> None:
    """A `simulate` file's metrics; with ``config`` also its text and a 3 s body.heave_acc."""
    with h5py.File(path, "w") as h5:
        for m in metrics:
            h5.create_dataset(f"metrics/{m}", data=rng.uniform(0.5, 1.5, 1))
        if config is not None:
            h5.attrs["config"] = config.read_text()
            h5["time"] = np.arange(3001) * 1e-3
            h5["signals/body.heave_acc"] = rng.normal(size=(1, 3001))
            h5["metrics/peak_time.body.heave_acc"] = [2.025]


def _chapter3_files(tmp_path: Path) -> None:
    """Every file chapter3 reads, with random values."""
    rng = np.random.default_rng(0)
    d = tmp_path / "ch3"
    (d / "checks").mkdir(parents=True)
    models = {
        "part1a": ["qc", "hc1", "hc2", "fc"],
        "part1b": ["qc", "hc1", "hc2", "fc"],
        "part2a": ["fc_no_arb", "fc_arb"],
        "part2b": ["qc_ct0", "qc_ct49"],
    }
    for part, road in set(report.CH3_FILES.values()):
        metrics = {
            r["quantity"]
            for n, (p, rd) in report.CH3_FILES.items()
            if (p, rd) == (part, road)
            for r in THESIS["ch3"]["tables"][n]["rows"]
        }
        _models_file(
            d / f"{part}_models_{road}.h5",
            [f"{part}_{m}_{road}" for m in models[part]],
            metrics,
            rng,
        )
    transient = {"peak.body.heave_acc"}
    random_road = {"RC", "max_body_acc", "VST.F1", "MST.F1", "VTD.F1", "MTD.F1"}
    configs = Path(__file__).resolve().parents[1] / "configs" / "ch3"
    _metrics_file(d / "part1a_qc_bump.h5", transient, rng, configs / "part1a_qc_bump.yaml")
    _metrics_file(d / "part2a_fc_arb_bump.h5", set(), rng, configs / "part2a_fc_arb_bump.yaml")
    _metrics_file(d / "checks" / "part1a_qc_bump_dt_half.h5", transient, rng)
    _metrics_file(d / "checks" / "part1a_qc_class_b_double_length.h5", random_road, rng)
    for m in ("qc", "fc"):  # seed 1 is the config's own run
        _metrics_file(d / f"part1a_{m}_class_b.h5", random_road, rng)
        for seed in range(2, 6):
            _metrics_file(d / "checks" / f"part1a_{m}_class_b_seed_{seed}.h5", random_road, rng)


def test_chapter3_tables_from_synthetic_files(tmp_path):
    _chapter3_files(tmp_path)
    doc = report.Doc(tmp_path / "report")
    headline = report.chapter3(tmp_path, doc)
    text = doc.text()
    for number in THESIS["ch3"]["tables"]:
        assert f"**Table {number}:" in text
    assert "| Peak, M_p | m/s^2 | QC |" in text and "thesis inside?" in text
    assert headline and headline[0].startswith("Ch. 3:")


# --- the conclusions follow their measurements (thresholds: report.CONVERGED, AGREE, ...) ----


@pytest.mark.parametrize(
    "factor, verdict",
    [(1.003, "the peak is converged in the step size"), (1.086, "the peak is not converged")],
)
def test_chapter3_step_size_conclusion_follows_the_dt_check(tmp_path, factor, verdict):
    _chapter3_files(tmp_path)
    d = tmp_path / "ch3"
    with h5py.File(d / "part1a_qc_bump.h5", "r") as h5:
        base = float(h5["metrics/peak.body.heave_acc"][0])
    with h5py.File(d / "checks" / "part1a_qc_bump_dt_half.h5", "w") as h5:
        h5["metrics/peak.body.heave_acc"] = [base * factor]
    doc = report.Doc(tmp_path / "report")
    report.chapter3(tmp_path, doc)
    text = doc.text()
    assert verdict in text
    assert ("not converged" in text) == (factor > 1.01)
    assert f"moves QC's peak z̈_s by {md.pct(100 * (factor - 1))}" in text


def test_dt_sentence_turns_at_the_threshold():
    assert report.CONVERGED == 1.0
    ok = report.dt_sentence(0.3, -12.0, "7.92 m/s²")
    assert "converged in the step size (0.3 % < 1 %)" in ok and "no integration error" in ok
    assert "within 1 % of the thesis's" in report.dt_sentence(-0.3, 0.5, "7.92 m/s²")
    bad = report.dt_sentence(8.6, -12.0, "7.92 m/s²")
    assert "not converged in the step size (8.6 % ≥ 1 %)" in bad
    assert "integration error may be part of" in bad and "no integration error" not in bad
    assert "not converged" in report.dt_sentence(-1.0, -12.0, "x")  # the threshold itself


def test_side_and_placed():
    assert report.side([1.0, -4.9], 5.0) == "within"
    assert report.side([1.0, 6.0], 5.0) == "above"
    assert report.side([-1.0, -6.0], 5.0) == "below"
    assert report.side([-6.0, 6.0], 5.0) == "both"
    assert report.side([float("nan"), None], 5.0) == "none"
    assert report.placed([2.0, -3.0]) == "within 5 % of the thesis's"
    assert report.placed([2.0, 30.0]) == "above the thesis's"
    assert report.placed([-20.0], "it", 1.0) == "below it"


def test_seed_sentence():
    inside = report.seed_sentence("The maxima", 12.0, [], 6)
    assert "inside our five seeds for all 6" in inside and "can account" in inside
    outside = report.seed_sentence("The maxima", 12.0, ["QC MST_1"], 6)
    assert "outside our five seeds for QC MST_1 (1 of 6)" in outside
    assert "no realisation of ours explains those" in outside


def test_grid_sentence():
    assert "moves the peak toward" in report.grid_sentence(0.5, 1.4)
    assert "does not explain" in report.grid_sentence(-2.6, 1.4)


def test_share_sentence():
    t = 0.27
    assert "softens them" in report.share_sentence("SH-2", np.array([0.5, 0.6]), t)
    assert "stiffens them" in report.share_sentence("SH-2", np.array([0.1, 0.2]), t)
    assert "changes them little" in report.share_sentence("SH-2", np.array([0.26, 0.285]), t)


def test_narrowed():
    assert report.narrowed([20.0, 40.0], [1.0, -4.0]).startswith("closes the gap")
    assert report.narrowed([20.0, 40.0], [10.0, 30.0]) == "accounts for part of the gap"
    assert report.narrowed([20.0, 40.0], [25.0, 40.0]) == "does not explain the gap"
    assert report.narrowed([20.0, 40.0], [10.0, 50.0]).startswith("narrows some")


def test_reproduced_and_late_gain():
    assert "reproduce the stored ones" in report.reproduced(3e-12)
    assert "differ from the stored ones" in report.reproduced(2e-6)
    assert "had stopped improving" in report.late_gain_sentence([0.2, 0.9, float("nan")])
    assert "still improving" in report.late_gain_sentence([0.2, 1.5])


def test_spread_and_bounds_text():
    assert report.spread([100.0, 110.0, 105.0]) == pytest.approx(10.0)
    assert np.isnan(report.spread([3.0]))
    text = report.bounds_text({"C_F1": "lower", "C_R1": "lower", "K_nlF1": "upper"})
    assert text == "C_F1, C_R1 at the lower bound; K_nlF1 at the upper bound"


@pytest.mark.slow
def test_a_partial_output_names_what_is_missing(tmp_path):
    """report.py on the outputs of a run that stopped early: each chapter it cannot build
    says which file is missing, and the rest is written."""
    out, folder = tmp_path / "out", tmp_path / "report"
    (out / "ch3").mkdir(parents=True)
    proc = subprocess.run(
        [sys.executable, str(EXAMPLES / "report.py"), str(out), str(folder)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0 and "Traceback" not in proc.stderr, proc.stderr
    assert "not built: chapter 8:" in proc.stderr and "no such file" in proc.stderr
    readme = (folder / "README.md").read_text()
    assert "Ch. 8: not built - " in readme
    assert (folder / "ch8.md").read_text().startswith("# Chapter 8: Seat suspensions\n\nNot built")
