"""Robust design: P designs under S scenarios as one batch against one batch per scenario.

The problem is configs/robust/hc2_bumps.yaml (the Ch. 5 HC2 half car over bumps of 40, 50
and 60 mm: three roads on one time grid, so one batch of P x 3 columns, each scenario's
columns under its own bump) with three more scenarios of another body mass (per-design
columns): S = 6. For each population size P the table gives the time of
``Problem.evaluate`` of the robust problem (one simulation) and of the same P designs
evaluated by S plain problems, one per scenario (what a loop over scenarios costs: S
simulations of P designs), best of three, and their ratio; and checks that both give the
same values bit for bit. ``--engine`` chooses the integrator (default: compiled when numba
is installed).

Run: ``python benchmarks/bench_scenarios.py [--sizes 10,100,400] [--engine numpy]``. Prints
a table; asserts nothing but the equality.
"""

from __future__ import annotations

import argparse
import timeit
from pathlib import Path

import numpy as np

from suspopt.config.loader import edit_config, load_config_text, set_path
from suspopt.integrator import compiled_available
from suspopt.optimisation import Problem

CONFIG = Path(__file__).resolve().parents[1] / "configs" / "robust" / "hc2_bumps.yaml"
MASSES = """    - {name: heavy_h40mm, set: {road.height: 0.04, vehicle.body.mass: 2500}}
    - {name: heavy_h50mm, set: {vehicle.body.mass: 2500}}
    - {name: heavy_h60mm, set: {road.height: 0.06, vehicle.body.mass: 2500}}
"""


def _best(fn, repeats: int = 3) -> float:
    """The best of ``repeats`` calls [s]."""
    return min(timeit.repeat(fn, number=1, repeat=repeats))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", default="10,100,400")
    parser.add_argument("--engine", default="compiled" if compiled_available() else "numpy")
    args = parser.parse_args()
    text = CONFIG.read_text().replace(
        "simulation: {duration: 3.0, dt: 2.0e-3}",
        f"simulation: {{duration: 3.0, dt: 2.0e-3, engine: {args.engine}}}",
    )
    text = text.replace("\noptimiser:", "\n" + MASSES + "optimiser:", 1)
    robust = Problem.from_config(load_config_text(text))
    scenarios = robust.scenarios
    assert scenarios is not None and len(scenarios.names) == 6
    plain: list = [None] * len(scenarios.names)  # each scenario as a config of its own
    for group in scenarios.groups:
        for member, member_cfg, values in zip(group.members, group.configs, group.values):

            def alone(data: dict, values=values) -> None:
                del data["scenarios"]
                for path, value in values.items():
                    set_path(data, path, value)

            plain[member] = Problem.from_config(edit_config(member_cfg.text, alone))
    print(f"engine {args.engine}; {len(scenarios.names)} scenarios "
          f"({', '.join(scenarios.names)}) in {len(scenarios.groups)} batch(es)")  # fmt: skip
    print("| P | one batch [s] | one per scenario [s] | ratio | same bits |")
    print("|---|---|---|---|---|")
    for P in (int(s) for s in args.sizes.split(",")):
        X = np.random.default_rng(0).uniform(robust.xl, robust.xu, (P, robust.n_var))
        robust.evaluate(X[:2])
        for p in plain:
            p.evaluate(X[:2])
        one = _best(lambda X=X: robust.evaluate(X, return_values_of=["F", "G"]))
        loop = _best(lambda X=X: [p.evaluate(X, return_values_of=["F", "G"]) for p in plain])
        robust._scenario_values.clear()
        FS, GS = robust.scenario_values(robust.to_physical(X))
        same = all(
            np.array_equal(FS[:, s], F) and np.array_equal(GS[:, s], G)
            for s, (F, G) in enumerate(p.evaluate(X, return_values_of=["F", "G"]) for p in plain)
        )
        print(f"| {P} | {one:.3f} | {loop:.3f} | {loop / one:.2f} | {same} |")


if __name__ == "__main__":
    main()
