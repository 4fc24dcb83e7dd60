"""suspopt: simulate, optimise and select vehicle and seat suspension designs from YAML.

A library first (``load_config``, ``simulate``, ...); the ``suspopt`` command is a thin layer
over it. Nothing in the library prints.

The names below are imported when first used (PEP 562), so that ``import suspopt`` and the
command's start-up do not pay for numpy, scipy and pymoo until something needs them.
"""

from __future__ import annotations

import importlib
import sys
import types
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
    "Result": "simulate",
    "simulate": "simulate",
    "build_vehicle": "vehicle",
    "modal_analysis": "vehicle",
    "frequency_response": "vehicle",
    "Problem": "optimise",
    "OptimisationResult": "optimise",
    "kesort": "kesort",
    "KEpsilonSort": "kesort",
    "pareto_picks": "kesort",
    "reuse_memory": "memory",
    "metric": "user_metrics",
}

__all__ = ["__version__", *_EXPORTS]


class _Package(types.ModuleType):
    """The package's module type: ``simulate`` and ``kesort`` are functions that share their
    names with their modules, so importing ``suspopt.simulate`` (which sets the module as an
    attribute of the package) must not hide the function."""

    def _function(name: str) -> property:
        def get(self):
            return getattr(importlib.import_module(f"suspopt.{name}"), name)

        def keep(self, module):
            """The import system sets the submodule as an attribute: ignored, the function
            stays."""

        return property(get, keep)

    simulate = _function("simulate")
    kesort = _function("kesort")
    del _function


sys.modules[__name__].__class__ = _Package


__getattr__, __dir__ = lazy_names(__name__, globals(), _EXPORTS, __all__)


if TYPE_CHECKING:
    from .config import Config, config_schema, load_config
    from .errors import ConfigError, InputError
    from .kesort import KEpsilonSort, kesort, pareto_picks
    from .memory import reuse_memory
    from .optimise import OptimisationResult, Problem
    from .simulate import Result, simulate
    from .templates import load_template
    from .user_metrics import metric
    from .vehicle import build_vehicle, frequency_response, modal_analysis
