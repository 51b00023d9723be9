"""Sphinx configuration of the nonsmooth documentation.

Build: ``pip install -e ".[docs]" && sphinx-build -W -b html docs docs/_build/html``.
The gallery (``docs/gallery``, ``docs/tutorials``) is executed at build time by sphinx-gallery;
the paper's reproduction report (quick mode) is generated once into ``docs/_generated`` and
linked from the site.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import nonsmooth

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))  # docs/_ext

project = "nonsmooth"
author = "the nonsmooth developers"
copyright = "2026, the nonsmooth developers"
release = nonsmooth.__version__
version = release

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinx_gallery.gen_gallery",
    "_ext.reproduction_report",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "_generated", "**/README.txt", "Thumbs.db", ".DS_Store"]
myst_enable_extensions = ["dollarmath", "colon_fence", "deflist"]
myst_heading_anchors = 3

autosummary_generate = True
autosummary_imported_members = True
autodoc_default_options = {"members": False, "show-inheritance": False}
autodoc_typehints = "none"
napoleon_numpy_docstring = True
napoleon_google_docstring = False
nitpicky = False

sphinx_gallery_conf = {
    "examples_dirs": ["gallery", "tutorials"],
    "gallery_dirs": ["auto_gallery", "auto_tutorials"],
    "filename_pattern": r"/(plot_|tutorial_)",
    "within_subsection_order": "FileNameSortKey",
    "download_all_examples": False,
    "remove_config_comments": True,
    "image_scrapers": ("_ext.figure_scraper.scrape",),
    "matplotlib_animations": False,
    "reset_modules": ("matplotlib", "_ext.figure_scraper.reset"),
    "capture_repr": (),
    "show_memory": False,
    "min_reported_time": 0,
    "abort_on_example_error": True,
    "plot_gallery": os.environ.get("NONSMOOTH_DOCS_GALLERY", "True"),
}

html_theme = "pydata_sphinx_theme"
html_title = f"nonsmooth {release}"
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc"],
}
html_static_path = []
html_extra_path = ["_generated/extra"]
(HERE / "_generated" / "extra").mkdir(parents=True, exist_ok=True)  # filled at builder-inited
html_show_sourcelink = False
