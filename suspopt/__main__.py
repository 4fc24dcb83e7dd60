"""``python -m suspopt`` runs the command-line interface."""

from ._entry import run

run()
