"""``suspopt validate``: everything a run of a config would reject, without running it
(:func:`check_config`), built on the pre-run checks of :mod:`suspopt.checks` (the time grid,
RK4's stability) that every command that simulates makes, so that what ``validate`` accepts
no other command rejects. It sits above the optimisation (it builds the config's problem and
its optimiser to check them), where the pre-run checks sit below the simulator.
"""

from __future__ import annotations

import numpy as np

from .checks import check_exact, check_stability, check_steps
from .config import Config
from .errors import FAILED, ConfigError

__all__ = ["check_config", "check_scenarios", "bound_corners"]

#: Most corners of the design variables' box whose stability is checked: all of them up to
#: ten variables, else this many drawn with a fixed seed (the same ones every time).
_CORNERS = 1024


def bound_corners(cfg: Config) -> dict[str, np.ndarray]:
    """Designs at the corners of the design variables' bounds, as ``params``."""
    import itertools

    variables = cfg.design_variables
    n = len(variables)
    if 2**n <= _CORNERS:
        upper = np.array(list(itertools.product((False, True), repeat=n)), dtype=bool)
    else:
        upper = np.random.default_rng(0).integers(0, 2, (_CORNERS, n)).astype(bool)
    return {v.path: np.where(upper[:, j], v.upper, v.lower) for j, v in enumerate(variables)}


def check_config(cfg: Config, optimisation: bool = True):
    """Everything about ``cfg`` that a run would reject, without running it: what
    :func:`suspopt.simulation.prepare` checks, RK4's stability limit for the configured design,
    the memory ``suspopt simulate`` needs to write every output signal and, with
    ``optimisation`` and an optimisation section, the problem
    (:meth:`suspopt.Problem.from_config`), the stability limit at the corners of the design
    variables' bounds and the optimiser with its options. ``suspopt validate`` runs all of
    it; the commands that simulate run what they use.

    The checks that do not depend on each other all run, and the ConfigError holds the
    problems of every one of them. A check that needs an earlier part to be sound is skipped
    when that part failed, so that one mistake is said once, where it is: the stability
    limit, the memory, the signals the metrics read and the optimisation's checks need the
    model built (the vehicle, its controller and seat), and the optimisation's checks the
    signals known too (its objectives read them); the stability at the bounds' corners, the
    scenarios and the optimiser need the optimisation's problem built. The time
    grid's checks (:func:`check_steps`) need only the loaded config. A config that does not
    load (a value of the wrong type, out of range or absurd for a road vehicle) gets none of
    these checks: its load errors are all reported instead.

    Returns the run of the config's own design it built and checked
    (:class:`suspopt.simulation.Prepared`), which :func:`suspopt.simulation.simulate` takes as
    ``prepared`` so that a command builds the model once."""
    from .simulation import assemble, check_memory, check_signals, signal_names

    found = cfg.problems()
    found.attempt(check_steps, cfg)
    prepared = found.attempt(assemble, cfg)
    if prepared is FAILED:
        found.raise_if_any()
    signals = found.attempt(check_signals, cfg, prepared) is not FAILED
    found.attempt(check_exact, cfg, prepared)
    pv, model, controller, attachments = prepared
    found.attempt(check_stability, cfg, pv, model, attachments)
    written = (
        cfg.output.signals
        if cfg.output.signals != "all"
        else signal_names(model, getattr(controller, "units", {}), attachments)
    )
    found.attempt(check_memory, cfg, model, attachments, 1, signals=len(written) + len(cfg.metrics))
    if signals and optimisation and (cfg.design_variables or cfg.objectives or cfg.optimiser):
        found.attempt(_check_optimisation, cfg)
    found.raise_if_any()
    return prepared


def _check_optimisation(cfg: Config) -> None:
    """:func:`check_config`'s checks of the optimisation: its problem, then, each on its
    own, the stability limit at the corners of the bounds, the scenarios and the
    optimiser."""
    from .optimisation import Problem, build_optimiser
    from .params import ParamView
    from .seat import build_attachments
    from .vehicle import build_vehicle

    problem = Problem.from_config(cfg)
    found = cfg.problems()
    pv = found.attempt(ParamView, cfg, bound_corners(cfg))
    if pv is not FAILED:
        found.attempt(
            lambda: check_stability(
                cfg,
                pv,
                build_vehicle(cfg, pv),
                build_attachments(cfg, pv),
                what=" at a corner of the design variables' bounds",
            )
        )
    if problem.scenarios is not None:
        found.attempt(check_scenarios, cfg, problem)
    if cfg.optimiser is not None:
        found.attempt(build_optimiser, cfg, problem)
    found.raise_if_any()


def check_scenarios(cfg: Config, problem) -> None:
    """What :func:`check_config` checks of the config, for every scenario group of
    ``problem`` (:mod:`suspopt.optimisation.scenarios`): its road and time grid, the memory of
    its road, and RK4's
    stability limit at the corners of the design variables' bounds under each of its
    scenarios; reported at the scenario's key."""
    from .optimisation.scenarios import Group
    from .params import ParamView
    from .seat import build_attachments
    from .simulation import check_memory, prepare
    from .vehicle import build_vehicle

    corners = bound_corners(cfg)
    count = len(next(iter(corners.values())))
    scenarios = problem.scenarios
    for group in scenarios.groups:
        for member, values, scales, member_cfg in zip(
            group.members, group.values, group.scales, group.configs
        ):
            scenario = scenarios.scenarios[member]
            try:
                if member_cfg is not cfg:
                    _, model, _, attachments = prepare(member_cfg)
                    check_memory(member_cfg, model, attachments, 1)
                alone = Group(member_cfg, [member], [values], [scales], [member_cfg])
                pv = ParamView(member_cfg, scenarios.columns(alone, corners, count))
                check_stability(
                    member_cfg,
                    pv,
                    build_vehicle(member_cfg, pv),
                    build_attachments(member_cfg, pv),
                    what=" at a corner of the design variables' bounds",
                )
            except ConfigError as exc:
                first = exc.problems[0]
                message = f"{first.key}: {first.message}" if first.key else str(first)
                raise cfg.error(scenario.loc, f"in scenario {scenario.name}: {message}") from None
