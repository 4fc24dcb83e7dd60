"""Performance metrics of simulated signals (thesis Sec 2.4 and Eq 5.3), as pure functions.

Each function reduces (or transforms) the time axis, the last one, of ``(T,)`` or ``(P, T)``
signals without looping over the ``P`` designs. One topic per module:

- :mod:`.iso2631`: ISO 2631-1 weightings, weighted r.m.s., running r.m.s., MTVV, VDV, crest
  factor, ratio tests, comfort reactions (Eq 2.78-2.85)
- :mod:`.stats`: generic statistics and handling / road-holding metrics (Eq 2.87-2.91)
- :mod:`.energy`: damper dissipated power and switching (Eq 2.92, Sec 2.4.6)
- :mod:`.transient`: step-response metrics (Sec 2.4.1)
- :mod:`.spectral`: PSD, transfer function, coherence, transmissibility (Eq 2.86)
- :mod:`.springs`: non-linear spring usage ratio (Eq 5.3)
"""

from .._lazy import lazy_names

#: Public name -> the module that defines it; imported when first used (PEP 562), so that
#: a run that computes no metric never loads scipy.
# fmt: off
_MODULES = {
    "iso2631": (
        "WEIGHTINGS", "MTVV_RATIO_LIMIT", "VDV_RATIO_LIMIT", "COMFORT_REACTIONS", "SUM_BLOCK",
        "weighting_response", "weighting_filter", "power_state", "weighted_value",
        "running_state", "weight", "weighted_rms",
        "running_rms", "mtvv", "vdv", "crest_factor", "ratio_tests", "comfort_reaction"
    ),
    "stats": (
        "STATISTICS", "moments", "moment_value", "var", "std", "rms", "maximum", "minimum",
        "max_abs", "mean", "peak_to_peak", "suspension_travel_variance", "suspension_travel_max",
        "suspension_travel_max_abs", "tyre_deflection_variance", "tyre_deflection_max",
        "tyre_deflection_max_abs", "pitch_variance", "dynamic_tyre_load_ratio",
        "peak_dynamic_tyre_load_ratio", "peak_tyre_force"
    ),
    "energy": (
        "mean_dissipated_power", "mean_dissipated_power_from_damping", "damper_switches",
        "share_at_max_damping"
    ),
    "transient": (
        "transient_metrics",
    ),
    "spectral": (
        "psd", "record_psd", "PSD_SEGMENT", "transfer_function", "coherence", "transmissibility"
    ),
    "springs": (
        "nonlinear_spring_usage",
    ),
}
# fmt: on
_HOME = {name: module for module, names in _MODULES.items() for name in names}

__all__ = list(_HOME)


__getattr__, __dir__ = lazy_names(__name__, globals(), _HOME, __all__)
