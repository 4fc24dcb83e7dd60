"""Optimisation (Ch. 5-8): the YAML problem as a pymoo ``Problem``, the algorithms (GA,
NSGA-II, SLSQP, hybrid, weighted sum, any pymoo algorithm) and the checkpointed run behind
``suspopt optimise``."""

from .algorithms import (
    Gradient,
    Hybrid,
    Optimiser,
    PymooOptimiser,
    Solutions,
    WeightedSum,
    balanced_weights,
    minimize,
)
from .problem import PENALTY, Problem
from .run import OptimisationResult, Progress, build_optimiser, optimise

__all__ = [
    "Problem",
    "PENALTY",
    "Optimiser",
    "PymooOptimiser",
    "Gradient",
    "Hybrid",
    "WeightedSum",
    "Solutions",
    "balanced_weights",
    "minimize",
    "optimise",
    "build_optimiser",
    "Progress",
    "OptimisationResult",
]
