"""Write the optimisation configs of Chapters 5-8 (configs/ch5, ch6, ch7, ch8/pareto_*).

Run from anywhere: ``python examples/make_optimise_configs.py``. Every file is plain YAML with
comments; this script only saves typing the 46 of them consistently. The thesis tables each
block reproduces are named in the comments of the files it writes.
"""

from __future__ import annotations

from pathlib import Path

import yaml

CONFIGS = Path(__file__).resolve().parents[1] / "configs"

# --- Chapter 5: HC2 of Table 5.1 over the Sec 5.1.3 bump (configs/quickstart.yaml) ----------

HC2_CH5 = """\
vehicle:
  preset: half_pitch
  body: {mass: 2210, pitch_inertia: 1142, a_front: 1.61, a_rear: 1.67}   # m_1/2, I_yy (Table 5.1)
  corners:
    F1:
      unsprung_mass: 50
      tyre: {stiffness: 4.0e5}                  # c_T = 0 (Sec 5.1.2)
      spring: {linear: 5.0e4, cubic: 1.0e7}     # k_l [N/m], k_nl [N/m^3] (Eq 2.31)
      damper: {c: 3000}                         # [N s/m]
    R1:
      unsprung_mass: 100
      tyre: {stiffness: 8.0e5}
      spring: {linear: 6.0e4, cubic: 1.0e7}
      damper: {c: 3500}
road:
  kind: bump_half_sine
  height: 0.05           # h [m]
  length: 1.0            # base length on the road [m]: the thesis's L/2 with L = 2 m (slip: docs/thesis-slips.md#eq-2101)
  speed: 11.111          # 40 km/h
  start: 0.5             # front wheel reaches the bump [s]
simulation: {duration: 3.0, dt: 2.0e-3}   # RK4 and the sample grid: f1-f3 within 0.06 % of dt -> 0 (configs/README.md)
"""

DESIGN_VARIABLES_CH5 = """\
design_variables:        # Eq 5.1, bounds of Table 5.2
  - {name: K_lF1, path: vehicle.corners.F1.spring.linear, lower: 3.2e4, upper: 1.5e5}
  - {name: C_F1, path: vehicle.corners.F1.damper.c, lower: 2.0e3, upper: 1.0e4}
  - {name: K_lR1, path: vehicle.corners.R1.spring.linear, lower: 3.2e4, upper: 1.5e5}
  - {name: C_R1, path: vehicle.corners.R1.damper.c, lower: 2.0e3, upper: 1.0e4}
  # Table 5.2 prints 3.0e8 as the K_nl upper bound; Tables 5.4-5.15 use 0.5-30e6 (slip: docs/thesis-slips.md#table-52)
  - {name: K_nlF1, path: vehicle.corners.F1.spring.cubic, lower: 5.0e5, upper: 3.0e7}
  - {name: K_nlR1, path: vehicle.corners.R1.spring.cubic, lower: 5.0e5, upper: 3.0e7}
"""

F = {  # Eq 5.4-5.6 (= Eq 6.13-6.15), SI: (m/s^2)^2 and m^2
    "f1": "{name: f1, metric: var, signal: body.heave_acc}                   # Eq 5.4",
    "f2": "{name: f2, metric: var, signal: travel, reduce: mean}             # Eq 5.5",
    "f3": "{name: f3, metric: var, signal: tyre_deflection, reduce: mean}    # Eq 5.6",
    "f4": "{name: f4, metric: vdv, signal: head.acc}                         # Eq 6.16",
    "f5": "{name: f5, metric: crest_factor, signal: head.acc}                # Eq 6.17",
    "f6": "{name: f6, metric: var, signal: body.pitch}                       # Eq 6.18",
}

CONSTRAINTS_CH5 = """\
constraints:
  - {name: RC_s, metric: rms_weighted, signal: body.heave_acc, weighting: Wk, max: 0.8}  # Eq 5.2 [m/s^2]
  - {name: ratio, metric: spring_usage, min: 0.1, max: 0.3}     # Eq 5.3, each of F1 and R1
"""

CASES = {
    1: ("f1, the body acceleration variance (Eq 5.4)", ["f1"], ["f2", "f3"], None),
    2: ("f2, the mean suspension travel variance (Eq 5.5)", ["f2"], ["f1", "f3"], None),
    3: ("f3, the mean tyre deflection variance (Eq 5.6)", ["f3"], ["f1", "f2"], None),
    4: (
        "f4 = w1 f1 + w2 f2 + w3 f3 with balanced weights (Eq 5.7)",
        ["f1", "f2", "f3"],
        [],
        "  weighted_sum:             # Eq 5.7, Case 4: w_i = 1/median f_i of 200 random designs\n"
        "    balance: {samples: 200}\n",
    ),
    5: (
        "f5 = w1 f1 + w2 f2 + w3 f3 with f1 one order above f2, f3 (Eq 5.7)",
        ["f1", "f2", "f3"],
        [],
        "  weighted_sum:             # Eq 5.7, Case 5: f1's term ten times the others'\n"
        "    balance: {samples: 200, dominant: f1, factor: 10}\n",
    ),
}

# MATLAB R2016a ga defaults (the thesis's tool, Sec 5.2.2): 100 generations per variable,
# 50 stall generations, function tolerance 1e-6.
SCENARIOS = {
    1: ("GA, population 200", "ga", 200, 600),
    2: ("GA, population 1000", "ga", 1000, 600),
    3: ("hybrid: GA (population 200) for 10 generations, then SLSQP", "hybrid", 200, 110),
    4: ("hybrid: GA (population 1000) for 10 generations, then SLSQP", "hybrid", 1000, 110),
    5: ("gradient based (SLSQP; the thesis's fmincon active-set)", "gradient", None, 100),
}


def objectives_block(main: list[str], supplementary: list[str]) -> str:
    text = "objectives:\n  main:\n" + "".join(f"    - {F[k]}\n" for k in main)
    if supplementary:
        text += "  supplementary:\n" + "".join(f"    - {F[k]}\n" for k in supplementary)
    return text


def optimiser_block(
    algorithm: str, population: int | None, generations: int, extra: str = "", seed: int = 1
) -> str:
    text = f"optimiser:\n  algorithm: {algorithm}\n  seed: {seed}\n"
    if population is not None:
        text += f"  population: {population}\n"
    text += f"  generations: {generations}\n  tolerance: 1.0e-6\n"
    if algorithm != "gradient":
        text += "  stall_generations: 50\n"
    if algorithm == "hybrid":
        text += (
            "  hybrid: {ga_generations: 10, shrink: 0.2}   # Sec 5.1.1: GA active 10 generations\n"
        )
    return text + extra


def write(path: Path, text: str) -> None:
    yaml.safe_load(text)  # every file must parse
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)


def chapter5() -> None:
    for case, (what, main, supplementary, weights) in CASES.items():
        for s, (how, algorithm, population, generations) in SCENARIOS.items():
            header = (
                f"# Ch. 5, Case {case}: {what};\n# scenario S{s} of Table 5.3: {how}.\n"
                f"# HC2 of Table 5.1 over the Sec 5.1.3 bump (as configs/quickstart.yaml);\n"
                f"# constraints Eq 5.2-5.3; budget: MATLAB ga defaults (600 generations,\n"
                f"# 50 stall generations, tolerance 1e-6), SLSQP at most 100 iterations.\n"
            )
            write(
                CONFIGS / "ch5" / f"case{case}_s{s}.yaml",
                header
                + HC2_CH5
                + DESIGN_VARIABLES_CH5
                + objectives_block(main, supplementary)
                + CONSTRAINTS_CH5
                + optimiser_block(algorithm, population, generations, weights or ""),
            )


# --- Chapter 6: HC2 of Chapter 5 with a PS seat and the Table 2.3 passenger ------------------

SEAT_CH6 = """\
seat:                    # Sec 6.1.2: PS seat at the centre of the vehicle, driven by the body
  kind: ps
  stiffness: 3.0e4       # K_v [N/m]; Ch. 6 prints none: the PS seat of Table 7.1
  damping: 1200          # C_v [N s/m] (Table 7.1)
  mass: 13.6             # seat alone [kg] (Sec 8.2); the passenger rides on it
  passenger: {}          # Table 2.3 passenger (82.21 kg; slip: docs/thesis-slips.md#table-23)
  position: {x: 0.0, y: 0.0}
  coupling: one_way
"""

PARTS_CH6 = {
    "part_a_c1": ("Part A, case C1: f1 alone", "ga", ["f1"], ["f2", "f3", "f4", "f5", "f6"], ""),
    "part_a_c2": ("Part A, case C2: f2 alone", "ga", ["f2"], ["f1", "f3", "f4", "f5", "f6"], ""),
    "part_a_c3": ("Part A, case C3: f3 alone", "ga", ["f3"], ["f1", "f2", "f4", "f5", "f6"], ""),
    "part_a_c4": (
        "Part A, case C4: w1 f1 + w2 f2 + w3 f3 (Eq 5.7, Case 4 weights)",
        "ga",
        ["f1", "f2", "f3"],
        ["f4", "f5", "f6"],
        "  weighted_sum: {balance: {samples: 200}}   # Case 4 of Ch. 5\n",
    ),
    "part_b": (
        "Part B: NSGA-II on the main f1-f3; f4-f6 supplementary (Fig. 6.5)",
        "nsga2",
        ["f1", "f2", "f3"],
        ["f4", "f5", "f6"],
        "",
    ),
    "part_c": (
        "Part C: NSGA-II on all six objectives f1-f6 (Fig. 6.6)",
        "nsga2",
        ["f1", "f2", "f3", "f4", "f5", "f6"],
        [],
        "",
    ),
}


def chapter6() -> None:
    for name, (what, algorithm, main, supplementary, extra) in PARTS_CH6.items():
        header = (
            f"# Ch. 6, {what} (Table 6.1).\n"
            f"# HC2 and bump of Ch. 5 with the PS seat and the seated passenger (Sec 6.1.2,\n"
            f"# Fig. 6.3); design variables, bounds and constraints of Ch. 5 (Sec 6.2.1);\n"
            f"# objectives Eq 6.13-6.18 (f4 VDV and f5 crest factor of the head, unweighted\n"
            f"# as printed). Ch. 6 states no budget: population 100, 100 generations.\n"
        )
        write(
            CONFIGS / "ch6" / f"{name}.yaml",
            header
            + HC2_CH5
            + SEAT_CH6
            + DESIGN_VARIABLES_CH5
            + objectives_block(main, supplementary)
            + CONSTRAINTS_CH5
            + optimiser_block(algorithm, 100, 100, extra),
        )


# --- Chapter 7: HC2 of Table 7.1 with semi-active dampers and a PS seat ------------------------

CONTROL_CH7 = "control: {sample_time: 0.004}   # Delta T = 4 ms (Sec 4.2)\n"

# Sec 7.2.2 states no learning time for the CDF cases: the 7.2 s run learns for 2 s (the base
# law), then refits every 2 s, from the empirical distribution as configs/ch4 (see configs/README.md).
CONTROL_CH7_CDF = """\
control:                 # Delta T = 4 ms (Sec 4.2); CDF strategy of Ch. 4 (Fig. 4.4)
  sample_time: 0.004
  threshold:
    mode: adaptive
    c_max_share: 0.27    # 1 - N% = 27 % at C_max (Sec 4.3)
    learn_time: 2.0      # base law for the first 2 s of the 7.2 s run (ours: Ch. 7 states none)
    refit_factor: 1.0    # refit every 2 s
    distribution: empirical
"""


def vehicle_ch7(law: str, control: str = CONTROL_CH7) -> str:
    alpha = (
        "\n      crossover_frequency: 39    # alpha [rad/s] (Sec 4.2.2)"
        if law == "sh_add_2"
        else ""
    )
    damper = f"kind: semi_active\n      c_min: 1500\n      c_max: 3500\n      law: {law}{alpha}"
    return f"""\
vehicle:                 # HC2 of Table 7.1
  preset: half_pitch
  body: {{mass: 520, pitch_inertia: 473, a_front: 0.91, a_rear: 1.55}}
  corner_defaults:
    unsprung_mass: 25
    tyre: {{stiffness: 2.0e5}}
    spring: {{linear: 4.0e4}}         # linear springs K_F1, K_R1 [N/m] (Eq 2.30)
    damper:
      {damper}
  corners: {{F1: {{}}, R1: {{}}}}
seat:                    # PS seat of Table 7.1, e = 0.4 m ahead of the CG, seat and driver lumped
  kind: ps
  mass: 90
  stiffness: 3.0e4
  damping: 1200
  position: {{x: 0.4, y: 0.0}}
  coupling: one_way
road:                    # Sec 7.1.3: ISO 8608 class C, 50 km/h over 100 m
  kind: iso8608
  road_class: C
  convention: thesis
  speed: 13.8889
  seed: 1
{control}simulation: {{duration: 7.2, dt: 1.0e-3}}
"""


def design_variables_ch7(law: str) -> str:
    text = "design_variables:        # Table 7.2, bounds of Table 7.3\n"
    for c in ("F1", "R1"):
        text += (
            f"  - {{name: K_{c}, path: vehicle.corners.{c}.spring.linear, lower: 15000, upper: 70000}}\n"
            f"  - {{name: Cmax_{c}, path: vehicle.corners.{c}.damper.c_max, lower: 2500, upper: 5000}}\n"
            f"  - {{name: Cmin_{c}, path: vehicle.corners.{c}.damper.c_min, lower: 500, upper: 2500}}\n"
        )
    if law == "sh_add_2":
        for c in ("F1", "R1"):
            text += (
                f"  - {{name: a_{c}, path: vehicle.corners.{c}.damper.crossover_frequency, "
                f"lower: 10, upper: 60}}\n"
            )
    return text


OBJECTIVES_CH7 = """\
objectives:
  main:
    - {name: f1, metric: rms_weighted, signal: seat.acc, weighting: Wk}   # Eq 7.1, RC_se [m/s^2]
    - {name: f2, metric: var, signal: tyre_deflection, reduce: mean}     # Eq 7.2: mean VTD (Ch. 5) [m^2]
  supplementary:                 # Eq 7.7-7.10, for the k-epsilon selection (Sec 7.2.2)
    - {name: f3, metric: var, signal: travel, reduce: mean}              # Eq 7.7 [m^2]
    - {name: f4, metric: var, signal: body.pitch}                        # Eq 7.8, PTC [rad^2]
    - {name: f5, metric: dissipated_power, reduce: sum}                  # Eq 7.9, DE_F + DE_R [W]
    - {name: f6, metric: switches, signal: damper_state, reduce: sum}    # Eq 7.10, SW_F + SW_R
constraints:
  - {name: max_acc, metric: max_abs, signal: body.heave_acc, max: 4.5}    # Eq 7.3 [m/s^2]
  - {name: MST, metric: max_abs, signal: travel, max: 0.13}              # Eq 7.4, each corner [m]
  - {name: MTD, metric: max_abs, signal: tyre_deflection, max: 0.05}     # Eq 7.5, each corner [m]
  - {name: max_z_F1, metric: max_abs, signal: wheel.F1.heave, max: 0.07} # Eq 7.6 [m]
  - {name: max_z_R1, metric: max_abs, signal: wheel.R1.heave, max: 0.07}
"""

CASES_CH7 = {
    "sh_2": "Case 1, SH-2 (Eq 2.34)",
    "add": "Case 2, ADD (Eq 2.36)",
    "sh_add_2": "Case 3, SH-ADD-2 (Eq 2.39)",
}


def chapter7() -> None:
    for law, what in CASES_CH7.items():
        header = (
            f"# Ch. 7, {what}: NSGA-II on RC_se and the tyre deflection (Tables 7.2-7.3).\n"
            f"# Ch. 7 states no budget: population 100, 100 generations. Eq 7.3 and 7.6 bound\n"
            f"# maxima: taken as maxima of magnitudes (max_abs). The dampers' starting\n"
            f"# values are mid-range; the optimiser sets them.\n"
        )
        write(
            CONFIGS / "ch7" / f"{law}.yaml",
            header
            + vehicle_ch7(law)
            + design_variables_ch7(law)
            + OBJECTIVES_CH7
            + optimiser_block("nsga2", 100, 100),
        )
    for case, law in ((4, "sh_2"), (5, "sh_add_2")):
        name = law.upper().replace("_", "-")
        header = (
            f'# Ch. 7, {name}-CDF (Table 7.4, case {case}): the "pseudo Pareto front" of\n'
            f"# Fig. 7.4b: the designs of ch7/{law}.yaml's front simulated again with the CDF\n"
            f"# strategy (Eq 4.3-4.4), not optimised (no optimiser: run\n"
            f"#   suspopt kesort {law}.h5 --config configs/ch7/{law}_cdf.yaml).\n"
            f"# Same car, road, design variables, objectives and constraints as {law}.yaml.\n"
        )
        write(
            CONFIGS / "ch7" / f"{law}_cdf.yaml",
            header + vehicle_ch7(law, CONTROL_CH7_CDF) + design_variables_ch7(law) + OBJECTIVES_CH7,
        )


# --- Chapter 8: seat isolators, RC_se against X_ST (Pareto fronts, Sec 8.2) --------------------

BOUNDS_CH8 = {  # Tables 8.2, 8.4, 8.6, 8.8, 8.10: (config field, label, lower, upper)
    "ps": ("Tables 8.2-8.3", [("stiffness", "K_v", 1.0e4, 1.5e5)]),
    "nss1": (
        "Tables 8.4-8.5",
        [
            ("gamma", "gamma", 0.01, 0.99),
            ("stiffness_ratio", "alpha", 0.0, 5.0),
            ("wall_distance", "a_o", 0.10, 0.30),
        ],
    ),
    "nss2": (
        "Tables 8.6-8.7",
        [
            ("stiffness_ratio", "alpha", 0.0, 1.0),
            ("spring_free_length", "L_o", 0.10, 0.30),
            ("wall_distance", "a_o", 0.10, 0.30),
            ("bar_length", "b", 0.05, 0.30),
        ],
    ),
    "nss3": (
        "Tables 8.8-8.9",
        [
            ("stiffness_ratio", "alpha", 0.0, 5.0),
            ("cam_radius", "R", 0.01, 0.25),
            ("cam_offset", "d", 0.0, 0.25),
            ("roller_radius", "r", 0.01, 0.25),
        ],
    ),
    "nss4": (
        "Tables 8.10-8.11",
        [
            ("wall_distance", "a_o", 0.10, 0.30),
            ("spring_free_length", "L_o", 0.10, 0.30),
            ("bar_length", "b", 0.10, 0.30),
            ("support_stiffness", "K_S", 1.0e4, 1.5e5),
            ("inner_stiffness", "K_v", 2.0e3, 7.0e4),
            ("horizontal_stiffness", "K_h", 2.0e3, 7.0e4),
        ],
    ),
}

GEOMETRY_CH8 = {  # the seat's own conditions of each table, plus static stability
    "ps": ["stability"],
    "nss1": ["stability"],
    "nss2": [
        "stability",
        "stiffness_ratio_limit",
        "static_deflection_exists",
        "gamma2_above_one",
    ],  # Table 8.7 #3-5
    "nss3": ["stability", "roller_within_cam", "cam_offset_ratio"],  # Table 8.9 #3-4
    "nss4": ["stability", "c_I_upper", "c_I_lower"],  # Table 8.11 #3
}


def chapter8() -> None:
    for kind, (tables, bounds) in BOUNDS_CH8.items():
        for road in ("a", "b"):
            base = (CONFIGS / "ch8" / f"{kind}_class_{road}.yaml").read_text()
            body = base[base.index("vehicle:") :]
            dv = "design_variables:\n" + "".join(
                f"  - {{name: {label}, path: seat.{field}, lower: {lo:g}, upper: {hi:g}}}\n"
                for field, label, lo, hi in bounds
            )
            dv += "  - {name: C_v, path: seat.damping, lower: 200, upper: 2500}\n"
            margin = (
                ""
                if kind in ("ps", "nss1")
                else (
                    "  - {name: travel_margin, metric: min, signal: seat.travel_margin, min: 0}"
                    "   # the mechanism's reach\n"
                )
            )
            conditions = ", ".join(GEOMETRY_CH8[kind])
            text = (
                f"# Ch. 8 Pareto front of the {kind.upper()} seat, {tables}: RC_se against X_ST\n"
                f"# (Eq 8.1-8.2) on an ISO 8608 class {road.upper()} road; vehicle, road and seat as\n"
                f"# configs/ch8/{kind}_class_{road}.yaml. Ch. 8 states no budget: population 100,\n"
                f"# 100 generations. Constraint 'stability' (a statically stable isolator) is ours.\n"
                + body.rstrip("\n")
                + "\n"
                + dv
                + "objectives:\n  main:\n"
                "    - {name: RC_se, metric: rms_weighted, signal: seat.acc, weighting: Wk}   # Eq 8.1 [m/s^2]\n"
                "    - {name: X_ST, quantity: seat.static_deflection}                        # Eq 8.2 [m]\n"
                "constraints:\n"
                "  - {name: RC_se, metric: rms_weighted, signal: seat.acc, weighting: Wk, max: 1.0}   # constraint 1\n"
                "  - {name: X_ST, quantity: seat.static_deflection, max: 0.1}                       # constraint 2\n"
                f"  - {{name: seat, quantity: seat.geometry, max: 0, conditions: [{conditions}]}}\n"
                + margin
                + optimiser_block("nsga2", 100, 100)
            )
            write(CONFIGS / "ch8" / f"pareto_{kind}_class_{road}.yaml", text)


if __name__ == "__main__":
    chapter5()
    chapter6()
    chapter7()
    chapter8()
