"""suspopt's version, written once here (``suspopt.__version__``; pyproject.toml reads it)."""

__version__ = "0.1.0"
