"""Semi-active dampers: the control laws (:mod:`.laws`, Sec 2.1.6), the digital controller
(:mod:`.controller`, Sec 4.2) and the fits of the CDF threshold (:mod:`.stats`, Ch. 4) and the
summary an adaptive threshold refits from (:mod:`.summary`).

The laws and the fits sit below the config (:mod:`suspopt.config.vehicle` reads the laws);
the controller, built from a config, is imported when first used."""

from .laws import LAWS, PARAMETERS, Law, Motion, Parameter, law_condition, stiff_coefficient
from .stats import distribution_quantile, fit_student_t, t_quantile, threshold_for_share
from .summary import StudentTSummary

__all__ = [
    "LAWS",
    "PARAMETERS",
    "Law",
    "Motion",
    "Parameter",
    "law_condition",
    "stiff_coefficient",
    "fit_student_t",
    "distribution_quantile",
    "threshold_for_share",
    "t_quantile",
    "StudentTSummary",
    "SemiActiveController",
    "build_controller",
]


def __getattr__(name: str):
    if name in ("SemiActiveController", "build_controller"):
        from . import controller

        return getattr(controller, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
