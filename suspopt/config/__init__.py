"""Validated configuration: pydantic sections and YAML loading with line-numbered errors."""

from .loader import Config, ConfigError, config_schema, load_config

__all__ = ["Config", "ConfigError", "load_config", "config_schema"]
