"""The error every part of suspopt raises for bad input (a light module: the command line
catches it before anything heavy is imported)."""

__all__ = ["ConfigError"]


class ConfigError(ValueError):
    """Bad input: the message is one line naming the file, line and key path (or the file and
    the dataset)."""
