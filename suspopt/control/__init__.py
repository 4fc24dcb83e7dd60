"""Semi-active dampers: the control laws (:mod:`.laws`, Sec 2.1.6), the fits of the CDF
threshold (:mod:`.stats`, Ch. 4) and the summary an adaptive threshold refits from
(:mod:`.summary`).

They sit below the config (:mod:`suspopt.config.vehicle` reads the laws); the digital
controller built from a config (Sec 4.2) is :mod:`suspopt.controller`, above it."""

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
]
