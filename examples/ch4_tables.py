"""Tables 4.2 and 4.3 of the thesis (SH-2 vs SH-2-CDF, SH-ADD-2 vs SH-ADD-2-CDF) from the HDF5
files that ``suspopt simulate`` wrote for configs/ch4 (examples/ch4_runs.sh).

Run from the repository root:

    examples/ch4_runs.sh out/ch4                     # the CLI runs (about a minute)
    python examples/ch4_tables.py out/ch4 > ch4_tables.md

For each law and road the base run (``OUT/<law>_<road>.h5``) and the CDF run
(``OUT/<law>_cdf_<road>.h5``) give, in markdown:

1. the tables in the form of Tables 4.2-4.3, each value beside the thesis's printed one
   (examples/thesis_values.yaml); change = (X_base - X_CDF) / X_base * 100 % as in the thesis
   (positive: smaller with CDF);
2. the thresholds and C_max shares the three fits give (student_t, the thesis's stated fit;
   normal, its computation T = mu + Z sigma; empirical, the configs' choice), with the changes
   of each. The runs with the other two fits are copies of the CDF configs that
   ``python examples/ch4_tables.py --fits OUT`` writes to ``OUT/fits/`` from the config stored
   in each CDF run's file: on the random roads with ``distribution`` changed; on the bump with
   the fixed threshold of that fit designed offline from the base law's run (Sec 4.2.3). It
   stops if a bump config's own threshold is not the offline empirical design (except with
   SUSPOPT_QUICK=1, whose shortened runs design other thresholds).

The metrics are suspopt.analyse.cdf.semi_active_metrics of the stored signals.
"""

from __future__ import annotations

import argparse
import os
import re
import sys
from pathlib import Path
from types import SimpleNamespace

import h5py
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import mdtables as md

from suspopt.analyse.cdf import semi_active_metrics
from suspopt.config.loader import load_config_text
from suspopt.control import threshold_for_share
from suspopt.io import read_simulation_signals

ROADS = {
    "bump": "Road bump",
    "class_a": "Road class A",
    "class_b": "Road class B",
    "class_c": "Road class C",
}
LAWS = {
    "sh_2": ("SH-2", "SH-2-CDF", "4.2", "T_A"),
    "sh_add_2": ("SH-ADD-2", "SH-ADD-2-CDF", "4.3", "T_B"),
}
FITS = ("student_t", "normal", "empirical")
#: Display: label, our unit, the printed unit's factor from SI, significant digits.
INDEX = {
    "SW": ("Switches", "#", 1.0, 4),
    "RC": ("RC", "m/s²", 1.0, 3),
    "ST": ("ST (r.m.s.)", "mm", 1e3, 3),
    "TD": ("TD (r.m.s.)", "mm", 1e3, 3),
    "DE": ("DE", "W", 1.0, 3),
}


def change(base: float, cdf: float) -> float:
    """The thesis's percentage change (X - X_CDF)/X * 100 (Sec 4.3)."""
    return 100.0 * (base - cdf) / base


def stored_config(path: Path):
    """The config a ``suspopt simulate`` file was written with, and its YAML text."""
    with h5py.File(path, "r") as h5:
        text = h5.attrs["config"]
    return load_config_text(text, path.with_name(path.name + ":config")), text


def stored_metrics(path: Path, share_after: float = 0.0) -> dict[str, float]:
    """semi_active_metrics of one stored run (design 0), from its file."""
    cfg, _ = stored_config(path)
    time, signals = read_simulation_signals(path)
    run = SimpleNamespace(
        config=cfg,
        time=time,
        signals=signals,
        model=SimpleNamespace(corners=tuple(cfg.vehicle.corners)),
    )
    return {k: float(v[0]) for k, v in semi_active_metrics(run, share_after).items()}


def offline_thresholds(base: Path, law: str, share: float) -> dict[str, float]:
    """The bump's thresholds designed offline from the base law's run, one per fit."""
    _, signals = read_simulation_signals(base)
    condition = signals["control_condition.F1"]
    return {fit: float(threshold_for_share(condition, share, law, fit)[0]) for fit in FITS}


def fit_variant(text: str, fit: str, value: float | None) -> str:
    """A CDF config's YAML with another fit: the distribution (adaptive) or the fixed value."""
    if value is None:
        new, n = re.subn(r"(?m)^(\s*distribution:) *\w+", rf"\1 {fit}", text)
    else:
        new, n = re.subn(r"(?m)^(\s*value:) *[-+0-9.eE]+", rf"\g<1> {value:.6g}", text)
    if n != 1:
        sys.exit(f"cannot set the {fit} fit in the config (found {n} places)")
    return new


def write_fit_configs(out: Path) -> list[Path]:
    """OUT/fits/<law>_cdf_<road>_<fit>.yaml for the fits the configs do not use."""
    share = md.thesis_values()["ch4"]["c_max_share"]
    written = []
    for law in LAWS:
        for road in ROADS:
            cdf_cfg, text = stored_config(out / f"{law}_cdf_{road}.h5")
            spec = cdf_cfg.control.threshold
            offline = None
            if spec.mode == "fixed":
                offline = offline_thresholds(out / f"{law}_{road}.h5", law, share)
                if (
                    not np.isclose(offline["empirical"], spec.value, rtol=1e-3, atol=0.0)
                    and os.environ.get("SUSPOPT_QUICK") != "1"
                ):
                    sys.exit(
                        f"{law}_cdf_{road}: the config's threshold {spec.value} is not the "
                        f"offline empirical design {offline['empirical']:.6g}; update the "
                        f"config"
                    )
            fit_used = "empirical" if offline else spec.distribution
            for fit in FITS:
                if fit == fit_used:
                    continue
                path = out / "fits" / f"{law}_cdf_{road}_{fit}.yaml"
                path.parent.mkdir(parents=True, exist_ok=True)
                path.write_text(fit_variant(text, fit, offline[fit] if offline else None))
                written.append(path)
    return written


def collect(out: Path) -> dict:
    """Every law and road: base metrics, and per fit (metrics, threshold); the configs' fit."""
    results = {}
    for law in LAWS:
        for road in ROADS:
            cdf_file = out / f"{law}_cdf_{road}.h5"
            cdf_cfg, _ = stored_config(cdf_file)
            spec = cdf_cfg.control.threshold
            fixed = spec.mode == "fixed"
            fit_used = "empirical" if fixed else spec.distribution
            share_after = 0.0 if fixed else spec.learn_time
            fits = {}
            for fit in FITS:
                path = cdf_file if fit == fit_used else out / "fits" / f"{law}_cdf_{road}_{fit}.h5"
                cfg, _ = stored_config(path)
                if fixed:
                    threshold = cfg.control.threshold.value
                else:
                    threshold = float(
                        read_simulation_signals(path)[1]["control_threshold.F1"][0, -1]
                    )
                fits[fit] = (stored_metrics(path, share_after), threshold)
            results[law, road] = {
                "base": stored_metrics(out / f"{law}_{road}.h5"),
                "fits": fits,
                "config_fit": fit_used,
            }
    return results


def table_markdown(results: dict, law: str) -> str:
    """Table 4.2 or 4.3 in the thesis's form: ours, the thesis's, their difference."""
    base_name, cdf_name, table, symbol = LAWS[law]
    thesis = md.thesis_values()["ch4"]
    printed = thesis["tables"][table]["roads"]
    rows = []
    for road, road_name in ROADS.items():
        r = results[law, road]
        cdf, threshold = r["fits"][r["config_fit"]]
        t = printed[road]
        rows.append(
            [
                f"*{road_name}*",
                f"*{symbol}*",
                f"*{md.num(threshold)}*",
                f"*{md.printed(t['threshold'])}*",
                "",
                "",
                "",
                "",
                "",
                "",
            ]
        )
        for key, (label, unit, factor, digits) in INDEX.items():
            b, c = factor * r["base"][key], factor * cdf[key]
            tb, tc, tp = t[key]
            unit_cell = (
                unit
                if thesis["units"][key] == unit.replace("²", "^2")
                else f"{unit} (thesis: {thesis['units'][key]})"
            )
            rows.append(
                [
                    "",
                    f"{label} [{unit_cell}]",
                    md.num(b, digits),
                    md.printed(tb),
                    md.pct(md.difference(b, tb)),
                    md.num(c, digits),
                    md.printed(tc),
                    md.pct(md.difference(c, tc)),
                    md.pct(change(b, c), False),
                    md.pct(tp, False),
                ]
            )
        rows.append(
            [
                "",
                "C_max share [%]",
                md.num(100 * r["base"]["share"]),
                "-",
                "",
                md.num(100 * cdf["share"]),
                md.num(100 * thesis["c_max_share"]),
                "",
                "",
                "",
            ]
        )
    header = [
        "road",
        "index",
        base_name,
        "thesis",
        "diff.",
        cdf_name,
        "thesis",
        "diff.",
        "change",
        "thesis change",
    ]
    return md.table(header, rows)


def fits_markdown(results: dict) -> str:
    """Threshold, C_max share and the changes of each fit, beside the thesis's threshold."""
    thesis = md.thesis_values()["ch4"]["tables"]
    rows = []
    for (law, road), r in results.items():
        printed = thesis[LAWS[law][2]]["roads"][road]["threshold"]
        for fit in FITS:
            cdf, threshold = r["fits"][fit]
            mark = " (configs)" if fit == r["config_fit"] else ""
            rows.append(
                [
                    LAWS[law][0],
                    road,
                    fit + mark,
                    md.num(threshold),
                    md.printed(printed),
                    md.pct(100 * cdf["share"], False),
                ]
                + [md.pct(change(r["base"][k], cdf[k]), False) for k in INDEX]
            )
    header = [
        "law",
        "road",
        "fit",
        "T",
        "T thesis",
        "C_max share",
        "SW change",
        "RC change",
        "ST change",
        "TD change",
        "DE change",
    ]
    return md.table(header, rows)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path, help="folder of examples/ch4_runs.sh")
    parser.add_argument(
        "--fits",
        action="store_true",
        help="write the configs of the other fits to OUT/fits and list them",
    )
    args = parser.parse_args()
    if args.fits:
        for path in write_fit_configs(args.out):
            print(path)
        return
    results = collect(args.out)
    for law, (base_name, cdf_name, table, _) in LAWS.items():
        print(
            f"\n**Table {table} form: {base_name} against {cdf_name}** (diff. = (ours - "
            "thesis)/thesis; change = (X - X_CDF)/X)\n"
        )
        print(table_markdown(results, law))
    print(
        f"\n**Threshold fits at a requested "
        f"{100 * md.thesis_values()['ch4']['c_max_share']:.0f} % C_max share**\n"
    )
    print(fits_markdown(results))


if __name__ == "__main__":
    main()
