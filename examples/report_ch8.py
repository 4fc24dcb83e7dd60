"""Chapter 8 of the reproduction report: seat suspensions."""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import mdtables as md
from report_ch7 import read_pseudo
from report_common import (
    BUDGET_HEADER,
    SAME,
    Chapter,
    Doc,
    budget_row,
    command_list,
    finite,
    listed,
    placed,
    read_run,
    side,
    span,
    text,
)

from suspopt import plots
from suspopt.analyse import relative_change

# --- Chapter 8 ---------------------------------------------------------------------------------

SEATS = {"ps": "PS", "nss1": "NSS1", "nss2": "NSS2", "nss3": "NSS3", "nss4": "NSS4"}


@dataclass
class Stht:
    """Seat-to-head transmissibility of one design: X_ST [m]; the linearised resonance (the
    peak above ``F_MIN``; ``at_edge`` when it sits at F_MIN, i.e. lower) and its peak [-]; the
    simulated (H1) peak above F_MIN where the coherence is >= 0.8 (``simulated_at_edge``
    likewise)."""

    x_st: float
    linear_f: float
    linear_peak: float
    at_edge: bool
    simulated_f: float
    simulated_peak: float
    simulated_at_edge: bool


F_MIN = 0.2  # [Hz] lowest frequency searched for a resonance


def stht_peaks(path: Path) -> dict[str, Stht]:
    """Per pick (edges, knee) of a front's STHT file (``analyse transmissibility``); a design
    that is several picks (an edge that is also the knee) serves each of them."""
    with h5py.File(path, "r") as h5:
        picks = [text(p) for p in h5["designs"].attrs["picks"]]
        fl, lin = h5["linear/frequency"][()], h5["linear/head"][()]
        fs, sim = h5["simulated/frequency"][()], h5["simulated/head"][()]
        coherence = h5["simulated/coherence/head"][()]
        x_st = h5["statics/static_deflection"][()]
    band = fl >= F_MIN
    out = {}
    for i, pick in enumerate(picks):
        k = int(np.argmax(np.where(band, lin[i], -np.inf)))
        ok = (coherence[i] >= 0.8) & (fs >= F_MIN)
        j = int(np.argmax(np.where(ok, sim[i], -np.inf)))
        peak = Stht(
            float(x_st[i]),
            float(fl[k]),
            float(lin[i, k]),
            k == int(np.argmax(band)),
            float(fs[j]) if ok.any() else math.nan,
            float(sim[i, j]) if ok.any() else math.nan,
            bool(ok.any()) and j == int(np.argmax(ok)),
        )
        for name in pick.split(", "):  # the file joins a design's picks
            out[name] = peak
    return out


def b_over_a(front_a: dict, front_b: dict) -> np.ndarray:
    """RC_se of front B over front A at the same X_ST [%, one per design of A inside B's X_ST
    range]: front B interpolated in X_ST."""
    xb, yb = front_b["X_ST"], front_b["RC_se"]
    order = np.argsort(xb)
    xb, yb = xb[order], yb[order]
    xa, ya = front_a["X_ST"], front_a["RC_se"]
    inside = (xa >= xb[0]) & (xa <= xb[-1])
    if inside.sum() == 0 or len(xb) < 2:
        return np.array([])
    return np.asarray(relative_change(np.interp(xa[inside], xb, yb), ya[inside]))


def edge_change_cells(
    variant: dict, edges: tuple[int, int], printed: list, deviations: list[float]
) -> list[str]:
    """Cells ours / thesis / difference [points] of RC_se's change at Edges 1 and 2 of one
    pseudo-front; appends the differences to ``deviations``."""
    cells = []
    for k, i in enumerate(edges):
        if variant["failed"][i]:
            cells += ["failed", md.printed(printed[k]), "-"]
            continue
        ours = variant["change"]["RC_se"][i]
        deviations.append(ours - printed[k])
        cells += [md.pct(ours), md.printed(printed[k]), f"{ours - printed[k]:+.1f}"]
    return cells


def chapter8(out, doc) -> list[str]:
    return _Chapter8(out).write(doc)


class _Chapter8(Chapter):
    """Chapter 8, one method per table or paragraph (:class:`report_common.Chapter`)."""

    NAME = "ch8"
    SECTIONS = (
        "what_was_run",
        "table_8_12",
        "table_8_13",
        "fig_8_26",
        "class_b_fronts",
        "fronts_figure",
        "figure_list",
        "fronts_ends",
        "road_changes",
        "resonances",
    )

    def what_was_run(self, doc: Doc) -> None:
        d, ref = self.d, self.ref
        runs = {(s, r): read_run(d / f"pareto_{s}_class_{r}.h5") for s in SEATS for r in "ab"}
        roads = {s: read_pseudo(d / f"{s}_roads.h5") for s in SEATS}
        masses = {s: read_pseudo(d / f"{s}_masses.h5") for s in SEATS}
        peaks = {s: stht_peaks(d / f"{s}_front_stht.h5") for s in SEATS}
        doc("# Chapter 8: seat suspensions (Tables 8.12-8.13, Fig. 8.26)", "")
        doc("## What was run", "")
        doc.para(
            "The Table 8.1 quarter car on 1000 m of ISO 8608 class A (120 km/h) and B (85",
            "km/h), thesis convention, seed 1, drives each seat isolator one way (seat and",
            "passenger lumped, 95 kg). NSGA-II on RC_se and X_ST (Eq 8.1-8.2) within Tables",
            "8.2-8.11; the class A fronts re-simulated on classes B and C (Sec 8.4.2) and with",
            "the passenger 20 kg lighter and heavier (Sec 8.4.3), and the STHT of their edges",
            "and knee with the Table 2.3 passenger (Sec 8.4.4):",
        )
        command_list(
            doc,
            [
                "examples/ch8_optimise.sh OUT/ch8 a b && examples/ch8_pseudo_fronts.sh "
                "OUT/ch8 && examples/ch8_stht.sh OUT/ch8",
                "# i.e. suspopt optimise configs/ch8/pareto_<seat>_class_<a|b>.yaml -o ...",
                "#      suspopt analyse roads OUT/ch8/pareto_<seat>_class_a.h5 --road "
                "configs/ch8/<seat>_class_b.yaml --road configs/ch8/<seat>_class_c.yaml",
                "#      suspopt analyse masses OUT/ch8/pareto_<seat>_class_a.h5",
                "#      suspopt analyse transmissibility OUT/ch8/pareto_<seat>_class_a.h5 "
                "--with configs/ch8/<seat>_class_a_passenger.yaml",
            ],
        )
        doc.para(
            "**Budget:** the configs' own, population 100 and 100 generations (Ch. 8 states",
            "none):",
        )
        doc.table(
            BUDGET_HEADER,
            [budget_row(f"{SEATS[s]} class {r.upper()}", run) for (s, r), run in runs.items()],
        )
        doc.para(
            "Edge 1 is the front's small-X_ST end (its highest RC_se, `best_X_ST`), Edge 2",
            "the large-X_ST end (`best_RC_se`), Mid the knee (`suspopt.choosing.kepsilon.pareto_picks`).",
            "Percentage cells: ours, the thesis's, and their difference in points.",
        )

        def edges(data):
            return data["picks"]["best_X_ST"], data["picks"]["best_RC_se"]

        self.d = d
        self.edges = edges
        self.masses = masses
        self.peaks = peaks
        self.ref = ref
        self.roads = roads
        self.runs = runs

    def table_8_12(self, doc: Doc) -> None:
        edges = self.edges
        ref = self.ref
        roads = self.roads
        doc("## Table 8.12: other roads", "")
        rows, dev_b, dev_c = [], [], []
        for s, name in SEATS.items():
            t = ref["table_8_12"][s]
            e = edges(roads[s])
            rc = [roads[s]["front"]["RC_se"][i] for i in e]
            cells = [
                x
                for k in range(2)
                for x in (
                    md.num(rc[k], 3),
                    md.printed(t["road_a"][k]),
                    md.pct(md.difference(rc[k], t["road_a"][k])),
                )
            ]
            for label, key, dev in (
                (f"{s}_class_b", "road_b", dev_b),
                (f"{s}_class_c", "road_c", dev_c),
            ):
                cells += edge_change_cells(roads[s]["pseudo"][label], e, t[key], dev)
            rows.append([name] + cells)
        doc.table(
            ["seat"]
            + [f"A, Edge {k} {w}" for k in (1, 2) for w in ("ours [m/s²]", "thesis", "diff.")]
            + [
                f"A→{r}, Edge {k} {w}"
                for r in "BC"
                for k in (1, 2)
                for w in ("ours", "thesis", "diff. [points]")
            ],
            rows,
        )
        doc.para(
            "The thesis drives class B at 85 km/h and C at 50 km/h (the configs follow it), so",
            "these changes mix the class with the speed. With the class alone changed (same",
            "120 km/h and realisation, `--road B --road C`):",
        )
        rows = []
        for s, name in SEATS.items():
            e = edges(roads[s])
            rows.append(
                [name]
                + [
                    "failed"
                    if roads[s]["pseudo"][f"class {c}"]["failed"][e[k]]
                    else md.pct(roads[s]["pseudo"][f"class {c}"]["change"]["RC_se"][e[k]])
                    for c in "BC"
                    for k in range(2)
                ]
            )
        doc.table(["seat", "A→B Edge 1", "A→B Edge 2", "A→C Edge 1", "A→C Edge 2"], rows)
        failures = [
            f"{SEATS[s]} {v['failed'].sum()} of {len(v['failed'])} on {label}"
            for s in SEATS
            for label, v in roads[s]["pseudo"].items()
            if v["failed"].any()
        ]
        doc.para(
            "*failed:* the simulation of the design failed on that road, so it has no",
            "objectives there (the file records no cause). Failed designs: "
            + ("; ".join(failures) if failures else "none")
            + ".",
        )
        self.dev_b = dev_b
        self.dev_c = dev_c

    def table_8_13(self, doc: Doc) -> None:
        edges = self.edges
        masses = self.masses
        ref = self.ref
        doc("## Table 8.13: other passengers", "")
        rows, dev_m, mass_cells = [], [], []
        for s, name in SEATS.items():
            t = ref["table_8_13"][s]
            e = edges(masses[s])
            by_change = {float(v["attrs"]["mass_change"]): v for v in masses[s]["pseudo"].values()}
            cells = []
            for change_kg, key in ((max(by_change), "increase"), (min(by_change), "decrease")):
                cells += edge_change_cells(by_change[change_kg], e, t[key], dev_m)
                mass_cells += [
                    (
                        abs(t[key][k]),
                        f"{name} {change_kg:+g} kg Edge {k + 1}: thesis "
                        f"{md.printed(t[key][k])} %, ours "
                        f"{md.pct(by_change[change_kg]['change']['RC_se'][i])}",
                    )
                    for k, i in enumerate(e)
                ]
            rows.append([name] + cells)
        doc.table(
            ["seat"]
            + [
                f"{w0} Edge {k} {w}"
                for w0 in ("+20 kg,", "-20 kg,")
                for k in (1, 2)
                for w in ("ours", "thesis", "diff. [points]")
            ],
            rows,
        )
        doc.para(
            "NSS1-NSS3 keep X_ST (their K_v follows the load, Sec 8.4.3); PS and NSS4 keep",
            "their stiffnesses, so their X_ST follows the load.",
        )
        self.dev_m = dev_m
        self.mass_cells = mass_cells

    def fig_8_26(self, doc: Doc) -> None:
        peaks = self.peaks
        ref = self.ref
        doc("## Fig. 8.26: seat-to-head transmissibility of the edges and knee", "")
        st = ref["stht"]
        rows = []
        for s, name in SEATS.items():
            for pick, label, key in (
                ("best_X_ST", "Edge 1", None),
                ("knee", "Mid", "resonance_mid"),
                ("best_RC_se", "Edge 2", "resonance_edge_2"),
            ):
                p = peaks[s].get(pick)
                if p is None:
                    continue
                resonance = f"≤ {md.num(F_MIN, 2)}" if p.at_edge else md.num(p.linear_f, 3)
                rows.append(
                    [
                        name if pick == "best_X_ST" else "",
                        label,
                        md.num(1e3 * p.x_st, 3),
                        f"{resonance} ({md.num(p.linear_peak, 3)})",
                        f"{md.num(p.simulated_peak, 3)} @ "
                        f"{'≤ ' if p.simulated_at_edge else ''}{md.num(p.simulated_f, 3)}",
                        md.printed(st[key].get(s)) if key else "-",
                        md.printed(1e3 * st["x_st_edge_2"][s])
                        if key == "resonance_edge_2" and s in st["x_st_edge_2"]
                        else "-",
                    ]
                )
        doc.table(
            [
                "seat",
                "design",
                "X_ST [mm]",
                "linearised resonance [Hz] (peak [-])",
                "simulated peak [-] @ [Hz]",
                "thesis resonance [Hz]",
                "thesis X_ST [mm]",
            ],
            rows,
        )
        doc.para(
            f"*Thesis:* {st['notes']} Ours: the STHT",
            "|z̈_head/z̈_s| (Eq 2.86) of each design with the Table 2.3 passenger, linearised",
            "about the static equilibrium and simulated on class A (H1, where the coherence",
            f"is at least 0.8); peaks searched above {md.num(F_MIN, 2)} Hz (≤: the peak lies",
            "at the lowest frequency searched, or below it).",
        )
        self.st = st

    def class_b_fronts(self, doc: Doc) -> None:
        ref = self.ref
        runs = self.runs
        doc("## Sec 8.3: the class B fronts against the class A fronts", "")
        rows = []
        for s, name in SEATS.items():
            ratio = b_over_a(
                {k: v for k, v in zip(runs[s, "a"].obj_names, runs[s, "a"].F.T)},
                {k: v for k, v in zip(runs[s, "b"].obj_names, runs[s, "b"].F.T)},
            )
            lo, hi = ref["class_b_increase"][s]
            rows.append(
                [
                    name,
                    str(len(ratio)),
                    span(ratio),
                    md.pct(float(np.median(ratio))) if len(ratio) else "-",
                    f"{lo}" if lo == hi else f"{lo}-{hi}",
                ]
            )
        doc.table(
            [
                "seat",
                "designs compared",
                "RC_se of front B over front A at equal X_ST",
                "median",
                "thesis (text) [%]",
            ],
            rows,
        )
        doc.para(f"*Thesis:* {ref['class_b_increase']['notes']}")

    def fronts_figure(self, doc: Doc) -> None:
        out = self.out
        runs = self.runs
        figures = out / "report_figures"
        figures.mkdir(exist_ok=True)
        fig, (ax,) = plots.new_figure(1, panel_size=(7.5, 4.5))
        for i, s in enumerate(SEATS):
            for r, style in (
                ("a", {"color": f"C{i}"}),
                ("b", {"facecolors": "none", "edgecolors": f"C{i}"}),
            ):
                F = dict(zip(runs[s, r].obj_names, runs[s, r].F.T))
                ax.scatter(
                    1e3 * F["X_ST"],
                    F["RC_se"],
                    s=14,
                    label=f"{SEATS[s]} class {r.upper()}",
                    **style,
                )
        ax.set_xlabel("X_ST [mm]")
        ax.set_ylabel("RC_se [m/s²]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, ncols=2)
        ax.set_title(
            "Pareto fronts of the five seats, class A (filled) and B (hollow); Figs. 8.22a, 8.27",
            fontsize=9,
        )
        plots.save(fig, figures / "ch8_fronts.png")
        self.figures = figures

    def figure_list(self, doc: Doc) -> None:
        d = self.d
        figures = self.figures
        runs = self.runs
        doc("## Figures", "")
        doc.figure(figures / "ch8_fronts.png", "ch8_fronts.png", "The ten Pareto fronts")
        doc.figure(
            d / "nss4_roads.png",
            "ch8_nss4_roads.png",
            "NSS4: the class A front on classes B and C, and the design variables along it "
            "(Figs. 8.20, 8.23e)",
        )
        doc.figure(
            d / "nss1_masses.png",
            "ch8_nss1_masses.png",
            "NSS1: the class A front with the passenger 20 kg lighter and heavier (Fig. 8.24b)",
        )
        doc.figure(
            d / "nss4_front_stht.png",
            "ch8_nss4_front_stht.png",
            "NSS4: STHT of the front's edges and knee (Fig. 8.26)",
        )
        doc.para(
            "The other seats' figures are in OUT/ch8 (`<seat>_roads.png`, `<seat>_masses.png`,",
            "`<seat>_front_stht.png`, `<seat>_stht.png` for the bundled designs).",
        )

        x_range = {
            s: (
                1e3 * runs[s, "a"].F[:, runs[s, "a"].obj_names.index("X_ST")].min(),
                1e3 * runs[s, "a"].F[:, runs[s, "a"].obj_names.index("X_ST")].max(),
            )
            for s in SEATS
        }
        self.x_range = x_range

    def fronts_ends(self, doc: Doc) -> None:
        roads = self.roads
        x_range = self.x_range
        doc("## Why they differ (measured)", "")
        runs_at_edge = []
        for s in SEATS:
            F = roads[s]["front"]
            e1 = roads[s]["picks"]["best_X_ST"]
            near = np.abs(F["X_ST"] / F["X_ST"][e1] - 1) <= 0.01
            if near.sum() > 1:
                runs_at_edge.append(
                    f"{SEATS[s]}: {near.sum()} designs within 1 % of Edge 1's X_ST, "
                    f"RC_se {md.num(F['RC_se'][near].min(), 3)}-"
                    f"{md.num(F['RC_se'][near].max(), 3)} m/s²"
                )
        doc.para(
            "- **The fronts' ends.** The edges' RC_se depend on where each front ends; ours",
            "span X_ST of",
            ", ".join(
                f"{SEATS[s]} {md.num(lo, 3)}-{md.num(hi, 3)} mm" for s, (lo, hi) in x_range.items()
            )
            + ".",
            "The thesis's fronts (Figs. 8.10-8.19) and budget are not given numerically.",
            "Sec 8.4.1 prunes runs of designs with (nearly) equal X_ST or RC_se before it takes",
            "the edges; we take them from the fronts as optimised"
            + (
                f" ({'; '.join(runs_at_edge)}: Edge 1 is the top of such a run)."
                if runs_at_edge
                else "."
            ),
        )

    def road_changes(self, doc: Doc) -> None:
        dev_b = self.dev_b
        dev_c = self.dev_c
        edges = self.edges
        roads = self.roads
        ps_e = edges(roads["ps"])
        ps_class = [
            roads["ps"]["pseudo"][f"class {c}"]["change"]["RC_se"][i] for c in "BC" for i in ps_e
        ]
        ps_speed = [
            roads["ps"]["pseudo"][f"ps_class_{c}"]["change"]["RC_se"][i] for c in "bc" for i in ps_e
        ]
        linear = [
            100 * ((1 + v / 100) / 2**n - 1)  # class B: RC_se x2, class C: x4
            for v, n in zip(ps_class, (1, 1, 2, 2))
        ]
        doc.para(
            "- **Road changes.** A→B changes differ from the thesis's by",
            f"{span(dev_b, lambda v: f'{v:+.1f}')} points and A→C by",
            f"{span(dev_c, lambda v: f'{v:+.1f}')} points over the ten edges. Each class",
            "doubles the road's amplitude, so a linear seat's RC_se doubles per class at one",
            f"speed on one realisation: the PS changes by {span(ps_class)} with the class",
            f"alone (table above), {span(linear)} from that doubling"
            + (
                f" (< {SAME:g} %, as a linear seat must)."
                if side(linear, SAME) == "within"
                else f" ({SAME:g} % or more: not the linear doubling)."
            ),
            f"At the thesis's lower speeds on B and C it changes by {span(ps_speed)}",
            (
                "instead: the speed takes part of the class's increase back"
                if np.all(finite(np.subtract(ps_speed, ps_class)) < 0)
                else "instead: the speed does not take the class's increase back at every edge"
            )
            + "; the realisations (seed 1) are ours.",
        )

    def resonances(self, doc: Doc) -> None:
        peaks = self.peaks
        st = self.st
        ps_f = [peaks["ps"][k].linear_f for k in peaks["ps"]]
        ps_thesis = {st[key]["ps"] for key in ("resonance_mid", "resonance_edge_2")}
        # the designs the thesis moves below the PS's resonance, and their resonance there
        moved = [
            (s, pick, label, st[key][s])
            for key, pick, label in (
                ("resonance_mid", "knee", "Mid"),
                ("resonance_edge_2", "best_RC_se", "Edge 2"),
            )
            for s in SEATS
            if st[key].get(s, math.inf) < st[key]["ps"] and pick in peaks[s]
        ]
        low_t = [t for *_, t in moved]
        ours_f = {f"{SEATS[s]} {label}": peaks[s][pick] for s, pick, label, _ in moved}
        moved_diff = [
            md.difference(F_MIN if p.at_edge else p.linear_f, t)  # at_edge: F_MIN or less
            for p, t in zip(ours_f.values(), low_t)
        ]
        floor = [n for n, p in ours_f.items() if p.at_edge]
        stht = [
            f"- **STHT.** The PS resonates at {span(ps_f, lambda v: md.num(v, 3))} Hz over its",
            f"front, {placed([md.difference(f, t) for f in ps_f for t in ps_thesis], 'the')}",
            f"thesis's about {listed(md.printed(t) for t in sorted(ps_thesis))} Hz.",
            "The thesis moves the resonance to about",
            f"{listed(md.printed(t) for t in sorted(set(low_t)))} Hz for {listed(ours_f)};",
            "our linearised resonances of those designs:",
            listed(
                (f"{n} ≤ {md.num(F_MIN, 2)}" if p.at_edge else f"{n} {md.num(p.linear_f, 3)}")
                for n, p in ours_f.items()
            )
            + " Hz,",
            placed(moved_diff) + ".",
        ]
        if floor and len(floor) == len(ours_f):
            stht += [
                f"All sit at or below {md.num(F_MIN, 2)} Hz: those designs reach quasi-zero",
                "stiffness, and simulated on class A their STHT stays at or below",
                f"{md.num(max(p.simulated_peak for p in ours_f.values()), 3)} where it is",
                "coherent. We disagree with the thesis's resonance there: our optimiser takes",
                "these isolators further toward zero stiffness within the same bounds.",
            ]
        elif floor:
            stht += [
                f"{listed(floor)} sit at or below {md.num(F_MIN, 2)} Hz (quasi-zero stiffness)."
            ]
        doc.para(*stht)
        self.floor = floor
        self.low_t = low_t
        self.ours_f = ours_f
        self.ps_f = ps_f
        self.ps_thesis = ps_thesis

    def headline(self, doc: Doc) -> list[str]:
        dev_b = self.dev_b
        dev_c = self.dev_c
        dev_m = self.dev_m
        floor = self.floor
        low_t = self.low_t
        mass_cells = self.mass_cells
        ours_f = self.ours_f
        ps_f = self.ps_f
        ps_thesis = self.ps_thesis
        largest = [text_ for _, text_ in sorted(mass_cells, reverse=True)[:3]]
        doc.para(
            "- **Passenger mass.** Our changes differ from Table 8.13 by",
            f"{span(dev_m, lambda v: f'{v:+.1f}')} points; the thesis's largest:",
            "; ".join(largest) + ".",
        )
        return [
            f"Ch. 8: RC_se changes A→B {span(dev_b, lambda v: f'{v:+.1f}')} points and A→C "
            f"{span(dev_c, lambda v: f'{v:+.1f}')} points from Table 8.12; passenger ±20 kg "
            f"{span(dev_m, lambda v: f'{v:+.1f}')} points from Table 8.13; PS resonance "
            f"{span(ps_f, lambda v: md.num(v, 3))} Hz (thesis about "
            f"{listed(md.printed(t) for t in sorted(ps_thesis))}); {len(floor)} of the "
            f"{len(ours_f)} designs the thesis moves to about "
            f"{listed(md.printed(t) for t in sorted(set(low_t)))} Hz resonate at or below "
            f"{md.num(F_MIN, 2)} Hz"
        ]
