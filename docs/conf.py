"""Sphinx configuration of the surfmod documentation.

Build (warnings are errors, as in CI)::

    python -m sphinx -W --keep-going -b html docs docs/_build/html

The API reference is generated from ``surfmod.__all__`` through the ``surfmod``
namespace (``surfmod.plane``, not ``surfmod.construct.plane.plane``), so moving a
function between modules does not change its page.  The command-line reference is
generated from the ``surfmod`` argument parser itself.
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # the checkout's surfmod, also without an install
sys.path.insert(0, str(HERE))

import surfmod  # noqa: E402

project = "surfmod"
author = "the surfmod developers"
copyright = "the surfmod developers, Apache-2.0"
release = surfmod.__version__
version = release

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.napoleon",
    "sphinx.ext.viewcode",
    "sphinx.ext.mathjax",
    "_ext.generated",
]

source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store", "_ext"]

myst_enable_extensions = ["colon_fence", "deflist", "dollarmath"]
myst_heading_anchors = 3

autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_default_options = {"members": True, "undoc-members": False, "show-inheritance": True}
autosummary_generate = False
napoleon_google_docstring = True
napoleon_numpy_docstring = True

html_theme = "furo"
html_title = f"surfmod {release}"
html_static_path = []

