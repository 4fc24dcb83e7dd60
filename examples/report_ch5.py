"""Chapter 5 of the reproduction report: optimisation methods and fitness functions."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import mdtables as md
from report_common import (
    AGREE,
    BUDGET_HEADER,
    REPRODUCED,
    SAME,
    SCENARIOS,
    STALLED,
    Chapter,
    Doc,
    batched_performance,
    budget_row,
    command_list,
    finite,
    listed,
    narrowed,
    placed,
    read_run,
    span,
    spread,
)

from suspopt import plots
from suspopt.choosing.selection import read_pareto

# --- Chapter 5 ---------------------------------------------------------------------------------


def at_bounds(X: np.ndarray, cfg) -> dict[str, str]:
    """The variables of a design ``X (n,)`` that sit at a bound (within 0.1 % of the range):
    ``{name: 'lower' | 'upper'}``."""
    out = {}
    for x, dv in zip(X, cfg.design_variables):
        tol = 1e-3 * (dv.upper - dv.lower)
        if x - dv.lower <= tol:
            out[dv.name] = "lower"
        elif dv.upper - x <= tol:
            out[dv.name] = "upper"
    return out


def bounds_text(at: dict[str, str]) -> str:
    """'C_F1, C_R1 at the lower bound; K_nlF1 at the upper' of :func:`at_bounds`."""
    parts = [
        f"{', '.join(n for n, b in at.items() if b == side_)} at the {side_} bound"
        for side_ in ("lower", "upper")
        if side_ in at.values()
    ]
    return "; ".join(parts) or "none at a bound"


def reproduced(deviation: float) -> str:
    """Whether re-simulated objectives reproduce the stored ones (largest relative deviation)."""
    if deviation < REPRODUCED:
        return (
            f"Re-simulated objectives reproduce the stored ones: they differ by at most"
            f" {deviation:.1e} (relative, < {REPRODUCED:.0e})."
        )
    return (
        f"Re-simulated objectives differ from the stored ones by up to {deviation:.1e}"
        f" (relative, ≥ {REPRODUCED:.0e}): the performance metrics below are not exactly"
        " the stored optima's."
    )


def late_gain_sentence(gains) -> str:
    """Whether the runs had stopped improving: their gains [%] over the last 20 %."""
    g = finite(gains)
    if len(g) and np.all(g < STALLED):
        return (
            f"under {STALLED:g} %: the runs had stopped improving, so a larger budget would"
            " hardly move their optima"
        )
    return (
        f"{STALLED:g} % or more in some runs: those were still improving, so a larger budget"
        " could move their optima"
    )


def chapter5(out, doc) -> list[str]:
    return _Chapter5(out).write(doc)


class _Chapter5(Chapter):
    """Chapter 5, one method per table or paragraph (:class:`report_common.Chapter`)."""

    NAME = "ch5"
    SECTIONS = (
        "what_was_run",
        "reproduced",
        "case_tables",
        "table_5_14",
        "f4_figure",
        "figure_list",
        "gradient_runs",
        "bump_length",
        "bounds_reached",
        "budgets",
    )

    def what_was_run(self, doc: Doc) -> None:
        d, ref = self.d, self.ref
        runs = {(c, s): read_run(d / f"case{c}_s{s}.h5") for c in range(1, 6) for s in range(1, 6)}
        perf = batched_performance({key: (run.path, run.X[:1]) for key, run in runs.items()})
        weights = runs[4, 1].weights
        cfg = read_pareto(runs[1, 1].path).config()
        bounds = {dv.name: (dv.lower, dv.upper) for dv in cfg.design_variables}
        doc("# Chapter 5: optimisation methods and fitness functions (Tables 5.4-5.14)", "")
        doc("## What was run", "")
        doc.para(
            "The HC2 of Table 5.1 over the 0.05 m half-sine bump at 40 km/h (3 s, dt = 2 ms),",
            "six design variables (Eq 5.1, Table 5.2 with the K_nl bound of",
            "docs/thesis-slips.md#table-52), RC_s < 0.8",
            "m/s² and 10-30 % spring usage (Eq 5.2-5.3); Cases 1-5 (f1, f2, f3, the balanced",
            "sum, the f1-dominated sum; Eq 5.4-5.7) × scenarios S1-S5 (GA population 200 and",
            "1000, hybrid GA 10 generations + SLSQP, SLSQP; Table 5.3), seed 1:",
        )
        command_list(
            doc,
            [
                "SUSPOPT_MAX_EVALUATIONS=N examples/ch5_optimise.sh OUT/ch5",
                "# i.e. suspopt optimise <budget copy of configs/ch5/caseC_sS.yaml> "
                "-o OUT/ch5/caseC_sS.h5",
            ],
        )
        s2 = runs[1, 2]
        cap = s2.max_evaluations
        doc.para(
            "**Budget (reduced).** The configs carry MATLAB ga's defaults (600 generations,",
            "stop after 50 generations without a 10⁻⁶ improvement; SLSQP at most 100",
            "iterations). "
            + (
                f"The report caps every run at {cap:,} simulated designs: S2 "
                f"(population {s2.population}) stops after {cap // s2.population} of its "
                f"{s2.max_generations} generations unless it stalls first, and runs within the cap "
                "are not cut."
                if cap
                else "The runs kept the configs' budgets."
            ),
            "The budget table of each case",
            "gives the generations, evaluations and wall time of every run, what stopped it,",
            "and how much its best value improved over its last 20 % of evaluations (a",
            "measure of how far from convergence it stopped). The performance metrics",
            "(MST = max |travel|, tyre force = K_T · max |tyre deflection|, spring usage) come",
            "from simulating each stored optimum again with its file's config.",
        )
        self.bounds = bounds
        self.cap = cap
        self.cfg = cfg
        self.perf = perf
        self.ref = ref
        self.runs = runs
        self.weights = weights

    def reproduced(self, doc: Doc) -> None:
        perf = self.perf
        runs = self.runs
        deviation = []
        for (c, s), run in runs.items():
            for j, name in enumerate(run.obj_names):
                deviation.append(abs(perf[c, s][name][0] / run.F[0, j] - 1))
        doc.para(reproduced(max(deviation)))

        direct, hybrid, thesis_spreads, ours_spreads, trapped = {}, {}, {}, {}, {}
        self.direct = direct
        self.hybrid = hybrid
        self.ours_spreads = ours_spreads
        self.thesis_spreads = thesis_spreads
        self.trapped = trapped

    def case_tables(self, doc: Doc) -> None:
        bounds = self.bounds
        direct = self.direct
        hybrid = self.hybrid
        ours_spreads = self.ours_spreads
        perf = self.perf
        ref = self.ref
        runs = self.runs
        thesis_spreads = self.thesis_spreads
        trapped = self.trapped
        for c in range(1, 6):
            case = ref["cases"][c]
            t_vars, t_met = case["tables"]
            doc(f"## Case {c}: Tables {t_vars} and {t_met}", "")
            header = (
                ["quantity", "unit"]
                + [f"{s} {w}" for s in SCENARIOS for w in ("ours", "thesis", "diff.")]
                + ["LB", "UB"]
            )
            rows = []
            for name, spec in ref["variables"].items():
                j = runs[c, 1].var_names.index(name)
                cells = []
                for s in range(1, 6):
                    ours = runs[c, s].X[0, j] * spec["factor"]
                    thesis = case["variables"][name][s - 1]
                    cells += [
                        md.num(ours, 4),
                        md.printed(thesis),
                        md.pct(md.difference(ours, thesis)),
                    ]
                lo, hi = bounds[name]
                rows.append(
                    [name, spec["unit"]]
                    + cells
                    + [md.num(lo * spec["factor"]), md.num(hi * spec["factor"])]
                )
            for name, spec in ref["metrics"].items():
                key = name.replace("_F1", ".F1").replace("_R1", ".R1")
                cells = []
                for s in range(1, 6):
                    ours = perf[c, s][key][0] * md.UNITS[spec["unit"]]
                    thesis = case["metrics"][name][s - 1]
                    cells += [
                        md.num(ours, 3),
                        md.printed(thesis),
                        md.pct(md.difference(ours, thesis)),
                    ]
                rows.append([spec.get("label", name), spec["unit"]] + cells + ["", ""])
            for f in ("f1", "f2", "f3"):
                unit = "(m/s^2)^2" if f == "f1" else "m^2"
                rows.append(
                    [f"{f} (ours only)", unit]
                    + [x for s in range(1, 6) for x in (md.num(perf[c, s][f][0], 4), "-", "")]
                    + ["", ""]
                )
            doc.table(header, rows)
            doc(f"*Budget, Case {c}:*", "")
            doc.table(
                BUDGET_HEADER,
                [budget_row(f"S{s}", runs[c, s], case["time"][s - 1]) for s in range(1, 6)],
            )
            objective = [
                float(
                    runs[c, s].F[0] @ runs[c, s].weights
                    if runs[c, s].weights is not None
                    else runs[c, s].F[0, 0]
                )
                for s in range(1, 6)
            ]
            low = min(objective[0], objective[1], objective[4])
            direct[c] = 100 * (max(objective[0], objective[1], objective[4]) - low) / low
            hybrid[c] = 100 * (max(objective[2], objective[3]) - low) / low
            kl = np.array(case["variables"]["K_lF1"], dtype=float)
            thesis_spreads[c] = 100 * (kl.max() - kl.min()) / kl.min()
            ours_spreads[c] = spread(
                [runs[c, s].X[0, runs[c, s].var_names.index("K_lF1")] for s in range(1, 6)]
            )
            trapped[c] = 100 * (objective[4] - min(objective[:2])) / min(objective[:2])

    def table_5_14(self, doc: Doc) -> None:
        perf = self.perf
        ref = self.ref
        runs = self.runs
        weights = self.weights
        # Table 5.14: the Case 4 terms of every optimum
        doc("## Sec 5.4: every optimum on Case 4's fitness (Table 5.14, Fig. 5.8)", "")
        terms = {
            key: weights * np.array([perf[key][f][0] for f in ("f1", "f2", "f3")]) for key in runs
        }
        f4 = {key: float(v.sum()) for key, v in terms.items()}
        doc.para(
            "Case 4's weights (w_i = 1/median f_i over 200 random designs, seed 1):",
            ", ".join(f"w{i + 1} = {md.num(w, 4)}" for i, w in enumerate(weights)),
            "(SI: (m/s²)⁻², m⁻², m⁻²). The thesis prints no weights, so its terms",
            "compare with ours only in their balance. Each case's optimum is its scenario with",
            "the lowest f4.",
        )
        rows = []
        best = {}
        for c in range(1, 6):
            s = min(range(1, 6), key=lambda s: f4[c, s])
            best[c] = s
            t = ref["table_5_14"][c]
            rows.append(
                [f"Case {c}", f"S{s}", f"S{t['scenario']}"]
                + [
                    x
                    for i, k in enumerate(("w1f1", "w2f2", "w3f3"))
                    for x in (md.num(terms[c, s][i], 3), md.printed(t[k]))
                ]
                + [
                    md.num(f4[c, s], 4),
                    md.printed(t["f4"]),
                    md.pct(md.difference(f4[c, s], t["f4"])),
                ]
            )
        doc.table(
            [
                "case",
                "scenario (ours)",
                "(thesis)",
                "w1 f1",
                "thesis",
                "w2 f2",
                "thesis",
                "w3 f3",
                "thesis",
                "f4",
                "thesis",
                "diff.",
            ],
            rows,
        )
        among = min(f4, key=f4.get)
        t_among = ref["optimum_among_all"]
        doc.para(
            f"**Optimum among all:** ours Case {among[0]}/S{among[1]}",
            f"(f4 = {md.num(f4[among], 4)});",
            f"the thesis's Case {t_among['case']}/S{t_among['scenario']}.",
        )
        doc.table(
            ["f4 of every optimum", *SCENARIOS],
            [[f"Case {c}"] + [md.num(f4[c, s], 4) for s in range(1, 6)] for c in range(1, 6)],
        )
        self.among = among
        self.f4 = f4
        self.t_among = t_among

    def f4_figure(self, doc: Doc) -> None:
        f4 = self.f4
        out = self.out
        runs = self.runs
        figures = out / "report_figures"
        figures.mkdir(exist_ok=True)
        fig, (ax,) = plots.new_figure(1, panel_size=(8.0, 3.6))
        width = 0.16
        for c in range(1, 6):
            ax.bar(
                np.arange(5) + (c - 3) * width,
                [f4[c, s] for s in range(1, 6)],
                width,
                label=f"Case {c}",
            )
        ax.set_xticks(np.arange(5), SCENARIOS)
        ax.set_ylabel("f4 = w1 f1 + w2 f2 + w3 f3 (Case 4 weights) [-]")
        low = min(f4.values())
        ax.set_ylim(0.98 * low, 1.02 * max(f4.values()))
        ax.grid(alpha=0.3, axis="y")
        ax.legend(fontsize=8, ncols=5)
        ax.set_title("Every optimum on Case 4's fitness (Fig. 5.8)")
        plots.save(fig, figures / "ch5_f4.png")
        fig, axes = plots.new_figure(5, columns=3, panel_size=(4.2, 3.0))
        for c, ax in zip(range(1, 6), axes):
            floor = min(
                float(np.min(b[np.isfinite(b)]))
                for s in range(1, 6)
                if np.isfinite(b := runs[c, s].best[:, 0]).any()
            )
            for s in range(1, 6):
                run = runs[c, s]
                with np.errstate(invalid="ignore"):
                    (line,) = ax.loglog(
                        run.history_evaluations,
                        np.maximum(run.best[:, 0] / floor - 1, 1e-9),
                        label=f"S{s}",
                    )
                final = float(run.F[0] @ run.weights if run.weights is not None else run.F[0, 0])
                ax.scatter(
                    [run.evaluations],
                    [max(final / floor - 1, 1e-9)],
                    marker="o",
                    s=14,
                    color=line.get_color(),
                    zorder=4,
                )
            ax.set_title(f"Case {c}", fontsize=9)
            ax.set_xlabel("evaluations")
            ax.set_ylabel("best / lowest of all - 1")
            ax.grid(alpha=0.3, which="both")
            ax.legend(fontsize=7)
        fig.suptitle(
            "Convergence: best feasible fitness per generation (iteration) relative to the "
            "lowest of the case, floor 1e-9; dots: the stored optima"
        )
        plots.save(fig, figures / "ch5_convergence.png")
        self.figures = figures

    def figure_list(self, doc: Doc) -> None:
        figures = self.figures
        doc("## Figures", "")
        doc.figure(figures / "ch5_f4.png", "ch5_f4.png", "f4 of every optimum (Fig. 5.8's data)")
        doc.figure(
            figures / "ch5_convergence.png",
            "ch5_convergence.png",
            "Best value against evaluations, relative to the lowest any scenario of the case found",
        )

    def gradient_runs(self, doc: Doc) -> None:
        bounds = self.bounds
        direct = self.direct
        hybrid = self.hybrid
        ours_spreads = self.ours_spreads
        ref = self.ref
        runs = self.runs
        thesis_spreads = self.thesis_spreads
        trapped = self.trapped
        thesis_knl = [
            v
            for c in ref["cases"].values()
            for k in ("K_nlF1", "K_nlR1")
            for v in c["variables"][k]
        ]
        knl_upper = bounds["K_nlF1"][1] * 1e-6
        over = sum(v > knl_upper for v in thesis_knl)
        s2_gain = [runs[c, 2].late_gain() for c in range(1, 6)]
        pts = lambda v: md.pct(v, False)  # noqa: E731
        not_one = [c for c in direct if not direct[c] < SAME]
        one = not not_one
        doc("## Why they differ (measured)", "")
        reached = [c for c in trapped if trapped[c] < SAME]
        short = [f"{c} ({md.pct(trapped[c])})" for c in trapped if not trapped[c] < SAME]
        doc.para(
            f"- **{'One optimum' if one else 'Optima'} per case.** The GA (S1, S2) and SLSQP",
            f"(S5) runs of a case end {span(direct.values(), pts)} apart in the case's own",
            "fitness ("
            + (
                f"all under {SAME:g} %: one optimum per case"
                if one
                else f"{SAME:g} % or more in Cases {listed(not_one)}: no common optimum there"
            )
            + f"; SLSQP alone in {span([runs[c, 5].evaluations for c in range(1, 6)], md.num)}",
            "evaluations); the hybrids S3 and S4 (their SLSQP starts from the GA's",
            "10-generation best, inside ±10 % of each range) end",
            f"{span(hybrid.values(), pts)} from the best of those,",
            placed(list(hybrid.values()), "it", SAME) + ".",
            f"The thesis's K_lF1 spans {span(thesis_spreads.values(), pts)} (max/min - 1)",
            f"within a case, ours {span(ours_spreads.values(), pts)}"
            + (
                ": the thesis's scenarios scatter more than ours in every case."
                if all(thesis_spreads[c] > ours_spreads[c] for c in thesis_spreads)
                else ": the thesis's scenarios do not scatter more than ours in every case."
            ),
            "The thesis's gradient runs 'get trapped' in Cases 2, 4 and 5; our SLSQP (S5)",
            f"ends within {SAME:g} % of the GA's best or below it in Cases {listed(reached)}"
            + (f" and {SAME:g} % or more above it in Cases {', '.join(short)}." if short else "."),
        )
        self.knl_upper = knl_upper
        self.not_one = not_one
        self.one = one
        self.over = over
        self.pts = pts
        self.s2_gain = s2_gain
        self.thesis_knl = thesis_knl

    def bump_length(self, doc: Doc) -> None:
        perf = self.perf
        ref = self.ref
        runs = self.runs
        bump = read_pareto(runs[1, 1].path).config().road.length
        longer = batched_performance(
            {key: (runs[key].path, runs[key].X[:1]) for key in ((1, 1), (3, 1))}, 2 * bump
        )
        t_mst = [v for case in ref["cases"].values() for v in case["metrics"]["MST_F1"]]
        t_ft = [
            v
            for k in ("F_T_F1", "F_T_R1")
            for case in ref["cases"].values()
            for v in case["metrics"][k]
        ]
        ours_mst = [perf[k]["MST.F1"][0] * 1e3 for k in runs]
        ours_ft = [perf[k][f"F_T.{c}"][0] for k in runs for c in ("F1", "R1")]
        maxima_diff = [
            md.difference(
                perf[c, s]["MST.F1"][0] * 1e3, ref["cases"][c]["metrics"]["MST_F1"][s - 1]
            )
            for c, s in runs
        ]
        maxima_diff += [
            md.difference(perf[c, s][f"F_T.{w}"][0], ref["cases"][c]["metrics"][f"F_T_{w}"][s - 1])
            for c, s in runs
            for w in ("F1", "R1")
        ]
        rc_diff = [
            md.difference(perf[c, s]["RC_s"][0], ref["cases"][c]["metrics"]["RC_s"][s - 1])
            for c, s in runs
        ]
        gap = {}  # (before, after) of MST_F1 and both tyre forces
        for key in ((1, 1), (3, 1)):
            t = ref["cases"][key[0]]["metrics"]
            for ours, thesis, scale in (
                ("MST.F1", "MST_F1", 1e3),
                ("F_T.F1", "F_T_F1", 1.0),
                ("F_T.R1", "F_T_R1", 1.0),
            ):
                gap[key, ours] = (
                    md.difference(perf[key][ours][0] * scale, t[thesis][key[1] - 1]),
                    md.difference(longer[key][ours][0] * scale, t[thesis][key[1] - 1]),
                )
        before, after = zip(*gap.values())
        doc.para(
            f"- **The bump's severity.** Our maxima lie {placed(maxima_diff)}",
            "(MST_F1 and the tyre forces, case by case):",
            f"MST_F1 {span(ours_mst, lambda v: md.num(v, 3))} mm against",
            f"{span(t_mst, md.printed)} mm,",
            f"the dynamic tyre force {span(ours_ft, lambda v: md.num(v, 3))} N against",
            f"{span(t_ft, md.printed)} N, while RC_s lies {span(rc_diff)} from the thesis's.",
            "The configs read the thesis's L = 2 m as the full sine period, a",
            f"{md.num(bump, 2)} m half-sine on the road (slip: docs/thesis-slips.md#eq-2101).",
            "Simulated again",
            f"over a {md.num(2 * bump, 2)} m half-sine, the Case 1/S1 optimum gives MST_F1",
            f"{md.num(longer[1, 1]['MST.F1'][0] * 1e3, 3)} mm, tyre forces",
            f"{md.num(longer[1, 1]['F_T.F1'][0], 3)} /",
            f"{md.num(longer[1, 1]['F_T.R1'][0], 3)} N and",
            f"RC_s {md.num(longer[1, 1]['RC_s'][0], 3)} m/s² (Case 3/S1:",
            f"{md.num(longer[3, 1]['MST.F1'][0] * 1e3, 3)} mm,",
            f"{md.num(longer[3, 1]['F_T.F1'][0], 3)} / {md.num(longer[3, 1]['F_T.R1'][0], 3)}",
            f"N, {md.num(longer[3, 1]['RC_s'][0], 3)} m/s²): their differences from the",
            f"thesis's span {span(before)} on our bump and {span(after)} on the longer one, so",
            "the bump's length",
            f"{narrowed(before, after)}; the thesis's Fig. 5.2 is not in the text.",
        )
        self.maxima_diff = maxima_diff

    def bounds_reached(self, doc: Doc) -> None:
        cfg = self.cfg
        knl_upper = self.knl_upper
        over = self.over
        perf = self.perf
        runs = self.runs
        thesis_knl = self.thesis_knl
        at = at_bounds(runs[1, 1].X[0], cfg)
        usage = next(c for c in cfg.constraints if c.name == "ratio")
        doc.para(
            f"- **Bounds.** Our Case 1 optimum has {len(at)} of {len(cfg.design_variables)}",
            f"variables at a bound ({bounds_text(at) + '; ' if at else ''}spring usage",
            f"{md.num(100 * perf[1, 1]['ratio.F1'][0], 3)} /",
            f"{md.num(100 * perf[1, 1]['ratio.R1'][0], 3)} % at F1 / R1, the constraint",
            f"{md.num(100 * usage.min, 2)}-{md.num(100 * usage.max, 2)} %).",
            f"Of the thesis's {len(thesis_knl)} printed K_nl optima {over} exceed the",
            f"{md.num(knl_upper, 3)}·10⁶ N/m³ upper bound its own tables state"
            + (
                ", so its runs searched a wider K_nl range than the bound the configs use"
                " (docs/thesis-slips.md#table-52; new slip, listed in the notes below)."
                if over
                else "."
            ),
        )

    def budgets(self, doc: Doc) -> None:
        among = self.among
        f4 = self.f4
        perf = self.perf
        ref = self.ref
        runs = self.runs
        s2_gain = self.s2_gain
        s2_gens = [runs[c, 2].generations for c in range(1, 6)]
        time_share = [100 * runs[c, s].seconds / ref["cases"][c]["time"][s - 1] for c, s in runs]
        stops = {}
        for c in range(1, 6):
            stops.setdefault(runs[c, 2].stop, []).append(str(c))
        doc.para(
            f"- **Budget.** S2 ran {min(s2_gens)}-{max(s2_gens)} generations (stopped by",
            "; ".join(f"{why} in Cases {', '.join(cs)}" for why, cs in stops.items()) + ");",
            "over its last 20 % of evaluations its best improved by",
            f"{span(s2_gain, lambda v: md.num(v, 2))} %, {late_gain_sentence(s2_gain)}.",
            "Our wall times are",
            f"{span(time_share, lambda v: md.num(v, 2))} %",
            "of the thesis's (batched numpy RK4 against MATLAB; the machine: docs/performance.md).",
        )
        c5_vs_c1 = 100 * max(
            abs(perf[5, s]["f1"][0] / perf[1, s]["f1"][0] - 1) for s in range(1, 6)
        )
        t514 = ref["table_5_14"]
        t_best4 = t514[4]["f4"]
        beaten = [c for c in t514 if t514[c]["f4"] < t_best4]
        own4 = min(f4[4, s] for s in range(1, 6))
        sentences = [
            "- **Where the cases compare.** Case 5's f1-dominated sum"
            + (
                f" reaches Case 1's f1 within {md.pct(c5_vs_c1, False)} in every scenario"
                f" (< {AGREE:g} %), close to Case 1 as Sec 5.4 finds."
                if c5_vs_c1 < AGREE
                else f" differs from Case 1's f1 by up to {md.pct(c5_vs_c1, False)}"
                f" (≥ {AGREE:g} %), where Sec 5.4 finds it close to Case 1."
            ),
            "On Case 4's fitness our optimum among all is",
            f"Case {among[0]}/S{among[1]}"
            + (
                ", Case 4's own, as it must be when the runs converge: Case 4 minimises f4 itself."
                if among[0] == 4
                else f", not Case 4's own (whose best f4 is"
                f" {md.pct(100 * (own4 / f4[among] - 1))} above it): a Case 4 run stopped"
                " short of f4's minimum."
            ),
        ]
        if beaten:
            sentences += [
                f"The thesis's Case {', '.join(str(c) for c in beaten)} optimum beats",
                "its Case 4 optimum on f4",
                f"({', '.join(md.printed(t514[c]['f4']) for c in beaten)}",
                f"against {md.printed(t_best4)}), which a converged Case 4 cannot allow",
                "with the same weights: its Case 4 runs stopped short of the minimum, or",
                "Sec 5.4 scaled the terms otherwise.",
            ]
        doc.para(*sentences)

    def headline(self, doc: Doc) -> list[str]:
        among = self.among
        cap = self.cap
        direct = self.direct
        hybrid = self.hybrid
        maxima_diff = self.maxima_diff
        not_one = self.not_one
        one = self.one
        ours_spreads = self.ours_spreads
        perf = self.perf
        pts = self.pts
        ref = self.ref
        t_among = self.t_among
        thesis_spreads = self.thesis_spreads
        doc("**Slips in the thesis's Chapter 5 tables** (examples/thesis_values.yaml):", "")
        doc(*[f"- {n}" for n in ref["notes"]], "")
        c1 = [
            md.difference(perf[1, s]["RC_s"][0], ref["cases"][1]["metrics"]["RC_s"][s - 1])
            for s in range(1, 6)
        ]
        budget = f"at most {cap:,} evaluations per run" if cap else "the configs' budgets"
        one_text = (
            f"one optimum per case: all under {SAME:g} %"
            if one
            else f"no common optimum in Cases {listed(not_one)}: {SAME:g} % or more"
        )
        return [
            f"Ch. 5 ({budget}): in each case the GA and SLSQP runs end "
            f"{span(direct.values(), pts)} apart ({one_text}), the hybrids "
            f"{span(hybrid.values(), pts)} from the best of them; the thesis's K_lF1 spans "
            f"{span(thesis_spreads.values(), pts)} within a case, ours "
            f"{span(ours_spreads.values(), pts)}; Case 1 RC_s "
            f"{span(c1)} from Table 5.5; our maxima (MST, tyre force) lie "
            f"{placed(maxima_diff)}; optimum among "
            f"all Case {among[0]}/S{among[1]} (thesis Case {t_among['case']}/S"
            f"{t_among['scenario']})"
        ]
