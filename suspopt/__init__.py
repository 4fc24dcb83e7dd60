"""suspopt: simulate, optimise and select vehicle and seat suspension designs from YAML.

A library first (``load_config``, ``simulate``, ...); the ``suspopt`` command is a thin layer
over it. Nothing in the library prints.
"""

__version__ = "0.1.0"

from .config import Config, ConfigError, config_schema, load_config  # noqa: E402
from .simulate import Result, simulate  # noqa: E402
from .vehicle import build_vehicle, frequency_response, modal_analysis  # noqa: E402
from .optimise import Problem  # noqa: E402
from .kesort import KEpsilonSort, kesort, pareto_picks  # noqa: E402
from .memory import reuse_memory  # noqa: E402

__all__ = ["__version__", "Config", "ConfigError", "config_schema", "load_config", "Result",
           "simulate", "build_vehicle", "modal_analysis", "frequency_response", "Problem",
           "kesort", "KEpsilonSort", "pareto_picks", "reuse_memory"]
