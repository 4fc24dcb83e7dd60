"""suspopt: simulate, optimise and select vehicle and seat suspension designs from YAML.

A library first (``load_config``, ``simulate``, ...); the ``suspopt`` command is a thin layer
over it. Nothing in the library prints.

The names below are imported when first used (PEP 562), so that ``import suspopt`` and the
command's start-up do not pay for numpy, scipy and pymoo until something needs them.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ._lazy import lazy_names
from ._version import __version__

#: Public name -> the module that defines it.
_EXPORTS = {
    "Config": "config",
    "InputError": "errors",
    "ConfigError": "errors",
    "config_schema": "config",
    "load_config": "config",
    "load_template": "templates",
    "Result": "simulation",
    "simulate": "simulation",
    "build_vehicle": "vehicle",
    "modal_analysis": "vehicle",
    "frequency_response": "vehicle",
    "Problem": "optimisation",
    "OptimisationResult": "optimisation",
    "optimise": "optimisation.run",
    "load_design_sets": "choosing.selection",
    "select": "choosing.selection",
    "run_analysis": "analyse",
    "Analysis": "analyse",
    "open_dataset": "h5read",
    "kesort": "choosing.kepsilon",
    "KEpsilonSort": "choosing.kepsilon",
    "pareto_picks": "choosing.kepsilon",
    "reuse_memory": "memory",
    "metric": "user_metrics",
}

__all__ = ["__version__", *_EXPORTS]


__getattr__, __dir__ = lazy_names(__name__, globals(), _EXPORTS, __all__)


if TYPE_CHECKING:
    from .analyse import Analysis, run_analysis
    from .choosing.kepsilon import KEpsilonSort, kesort, pareto_picks
    from .choosing.selection import load_design_sets, select
    from .config import Config, config_schema, load_config
    from .errors import ConfigError, InputError
    from .h5read import open_dataset
    from .memory import reuse_memory
    from .optimisation import OptimisationResult, Problem
    from .simulation import Result, simulate
    from .templates import load_template
    from .user_metrics import metric
    from .vehicle import build_vehicle, frequency_response, modal_analysis
