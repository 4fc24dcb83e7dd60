"""Sphinx configuration of suspopt's documentation site.

Build it from the repository's root (CI does, with ``-W``: any warning fails)::

    python -m pip install -e ".[docs]"
    sphinx-build -W -n docs docs/_build/html

The pages are Markdown (MyST) and reStructuredText; the API reference comes from the
numpydoc docstrings of ``suspopt.__all__`` (autosummary), the configuration reference from
the config's JSON Schema (``_ext/suspopt_docs.py``), and the gallery from the scripts of
``examples/gallery/``, which sphinx-gallery runs at every build (a script that fails fails
the build).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT))  # the checkout's suspopt, whatever is installed
sys.path.insert(0, str(HERE / "_ext"))
# the gallery's figures: no screen, and every script's figures closed after it
os.environ.setdefault("MPLBACKEND", "Agg")

import suspopt  # noqa: E402

project = "suspopt"
author = "the suspopt developers"
copyright = "2026, the suspopt developers"
version = release = suspopt.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
    "suspopt_docs",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "**/_build", "gallery/*.ipynb", "gallery/*.py", "gallery/*.zip"]
templates_path = ["_templates"]

# MyST: GitHub's heading anchors (``thesis-slips.md#eq-2104``), ``:::`` fences, definitions
myst_enable_extensions = ["colon_fence", "deflist", "dollarmath"]
myst_heading_anchors = 4

# GitHub's anchors, which the pages' links and the code's citations use (tests/test_docs.py)
myst_heading_slug_func = "suspopt_docs.github_slug"

# numpydoc and autosummary: one page per public name, no per-member stub tables
autosummary_generate = True
autosummary_imported_members = True
autodoc_default_options = {"members": True, "inherited-members": False}
autodoc_typehints = "none"  # the numpydoc sections say the types, in the domain's words
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_validation_checks: set[str] = set()

# Without network access at build time there is no intersphinx: names of other libraries
# stay plain text, and nitpicky mode (-n) checks suspopt's own references only.
nitpick_ignore_regex = [
    (r"py:.*", r"(numpy|np|scipy|pymoo|pydantic|h5py|xarray|pandas|matplotlib|typer)\b.*"),
    (r"py:.*", r"(optional|array_like|array-like|ndarray|callable|path-like)"),
]

# sphinx-gallery: every script of examples/gallery runs at build time, its figures kept
sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "examples" / "gallery"),
    "gallery_dirs": "gallery",
    "filename_pattern": r"plot_",
    "within_subsection_order": "FileNameSortKey",
    "abort_on_example_error": True,
    "only_warn_on_example_error": False,
    "download_all_examples": False,
    "remove_config_comments": True,
    "min_reported_time": 1,
    "show_memory": False,
    "capture_repr": (),
    "image_scrapers": ("matplotlib",),
    "reset_modules": ("matplotlib",),
}

html_theme = "pydata_sphinx_theme"
html_title = f"suspopt {release}"
html_theme_options = {
    "navbar_align": "left",
    "show_toc_level": 2,
    "navigation_with_keys": False,
    "secondary_sidebar_items": ["page-toc"],
    "footer_start": ["copyright"],
    "footer_end": [],
}
html_show_sourcelink = False
