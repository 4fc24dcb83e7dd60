"""The ``control:`` section: the digital controller of the semi-active dampers (Sec 2.1.6, Ch. 4).

The laws themselves belong to each damper (``vehicle.corners.<c>.damper.law``); this section
holds what is common to the controller: the sample time ``ΔT`` (Sec 4.2: 4 ms), an optional
first-order actuator lag, and the threshold of the CDF strategy (Eq 4.2-4.7). The section is
optional; without it a semi-active damper is sampled every 4 ms with no lag and no threshold.
It is ignored when every damper is passive.
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, model_validator

from .base import Duration, Section, bounds

__all__ = ["Threshold", "Control", "DEFAULT_SAMPLE_TIME"]

#: The thesis's controller sample time ΔT [s] (Sec 4.2).
DEFAULT_SAMPLE_TIME = 0.004


class Threshold(Section):
    """Threshold ``T`` on each law's operational condition in place of 0 (CDF strategy, Eq 4.2).

    ``fixed``: ``T = value`` for every corner and the whole run. ``adaptive`` (Fig. 4.4): the
    base law runs (``T = 0``) until ``t >= learn_time``; then, and every
    ``refit_factor * learn_time`` seconds, the condition history of each corner (every sample
    since ``t = 0``) is fitted with ``distribution`` and ``T`` is set to the quantile that leaves
    the share ``c_max_share`` of the samples at ``C_max`` (Eq 4.5-4.7 as mended, ``T = μ + Z σ``,
    the quantile of the fitted distribution; slip: docs/thesis-slips.md#eq-47).

    ``c_max_share`` is the thesis's ``1 - N%`` (Tables 4.2-4.3 use 27 %); the quantile level is
    ``1 - c_max_share`` for laws that stiffen above the threshold and ``c_max_share`` for SH-ADD-2,
    which stiffens below it (Eq 4.4).
    """

    mode: Literal["fixed", "adaptive"] = Field(
        description="fixed: T = value; adaptive: T re-fitted from the condition history"
    )
    value: Annotated[float, bounds(-1e12, 1e12)] | None = Field(
        None,
        description="fixed threshold T in the unit of the laws' condition (m^2/s^2 for SH-2, "
        "SH-L, SH-ADD-1, groundhook, hybrid; m^2/s^3 for ADD; m^2/s^4 for SH-ADD-2); mode "
        "fixed only",
    )
    c_max_share: float | None = Field(
        None,
        gt=0,
        lt=1,
        allow_inf_nan=False,
        description="share of the samples to operate at C_max, the thesis's 1 - N% (0.27 in "
        "Tables 4.2-4.3) [-]; mode adaptive only",
    )
    learn_time: Duration = Field(
        5.0,
        description="T_learn: the base law runs until t >= learn_time, then the first fit "
        "is made [s] (Fig. 4.4; the thesis says 'a few seconds')",
    )
    refit_factor: Annotated[float, bounds(1e-3, 1e3)] = Field(
        1.0,
        description="kappa: the threshold is re-fitted every refit_factor * learn_time "
        "seconds (Fig. 4.4) [-]",
    )
    distribution: Literal["student_t", "normal", "empirical"] = Field(
        "student_t",
        description="fit of the condition history: student_t (the thesis's, "
        "location-scale t by a Newton maximum-likelihood fit of a fixed-size summary of the "
        "history), normal (mean and standard deviation) or empirical (the "
        "sample quantile)",
    )

    @model_validator(mode="after")
    def _check(self) -> Threshold:
        if self.mode == "fixed":
            if self.value is None:
                raise ValueError("mode 'fixed' needs value (the threshold T)")
            if self.c_max_share is not None:
                raise ValueError(
                    "c_max_share is for mode 'adaptive'; a fixed threshold is given by value"
                )
        else:
            if self.c_max_share is None:
                raise ValueError(
                    "mode 'adaptive' needs c_max_share (share of samples at C_max, e.g. 0.27)"
                )
            if self.value is not None:
                raise ValueError(
                    "value is for mode 'fixed'; an adaptive threshold starts at 0 "
                    "(the base law) and is fitted from c_max_share"
                )
        return self


class Control(Section):
    """Digital controller of the semi-active dampers (Sec 4.2).

    It samples the vehicle every ``sample_time`` and holds each damper's command until the next
    sample (zero-order hold); ``sample_time`` must be a whole multiple of ``simulation.dt``.
    With ``actuator_lag`` τ > 0 the coefficient follows the command as a first-order lag,
    updated exactly once per integration step.
    """

    sample_time: Annotated[float, bounds(1e-7, 10.0)] = Field(
        DEFAULT_SAMPLE_TIME,
        description="controller sample time ΔT [s], a whole multiple of "
        "simulation.dt (Sec 4.2: 4 ms)",
    )
    actuator_lag: Annotated[float, bounds(0.0, 10.0)] = Field(
        0.0,
        description="time constant τ of the damper's first-order response to a new "
        "command [s]; 0 switches instantly",
    )
    threshold: Threshold | None = Field(
        None,
        description="CDF strategy (Ch. 4): a threshold on the condition in place of 0; "
        "omit it for the base laws",
    )
