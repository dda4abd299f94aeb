"""Sphinx configuration of the ambseal manual.

Build: ``sphinx-build -W --keep-going -n docs docs/_build/html`` (``.ci/run`` does, with
warnings as errors). The reference pages are generated from the code by the small
extension in ``docs/_ext/ambseal_docs.py`` (rig-file keys from the pydantic models, the
command line from argparse, JSON schemas) and by autodoc, so they cannot drift from it.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))
sys.path.insert(0, str(HERE.parent / "src"))  # the worktree's code, installed or not
os.environ.setdefault("MPLBACKEND", "Agg")

import ambseal  # noqa: E402

project = "ambseal"
author = "the ambseal authors"
copyright = "ambseal authors; source: J. S. Lauridsen, PhD thesis, DTU 2017"
version = release = ambseal.__version__

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "sphinx_copybutton",
    "ambseal_docs",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store", "**/README.md"]
root_doc = "index"
templates_path = ["_templates"]
autosummary_ignore_module_all = False

myst_enable_extensions = ["colon_fence", "dollarmath", "deflist"]
myst_heading_anchors = 3

# autodoc: the public faces; signatures without type hints (the numpydoc sections state
# the types in words, and hints such as ``control.StateSpace`` have no inventory offline)
autosummary_generate = True
autodoc_typehints = "none"
autodoc_member_order = "bysource"
autodoc_default_options = {"members": True, "imported-members": True}
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False
numpydoc_validation_checks = set()  # another page's job: no validation in the build

# nitpicky (-n): references the docstrings make to names outside ambseal
nitpick_ignore_regex = [
    (r"py:.*", r"(control|np|numpy|scipy|cvxopt|pydantic|dask|matplotlib|typing)\..*"),
]

html_theme = "furo"
html_title = f"ambseal {release}"
html_static_path = ["_static"]
html_css_files = ["ambseal.css"]
html_show_sourcelink = False

copybutton_prompt_text = r"\$ "
copybutton_prompt_is_regexp = True
copybutton_only_copy_prompt_lines = True
copybutton_line_continuation_character = "\\"

# option names (--truth) and quotes stay as typed, not typographic dashes and quotes
smartquotes = False

pygments_style = "friendly"
pygments_dark_style = "monokai"
