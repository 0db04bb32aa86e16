"""Sphinx configuration of the rwall_fem documentation: ``make docs`` (see the Makefile).

The pages are MyST markdown; the API pages come from the docstrings through autodoc,
which imports the package, so the build runs in the Debian leg's ``.venv`` (DOLFINx 0.5).
``_ext/rwall_docs.py`` writes the tutorial pages from ``demos/`` and the lists of test
cases from ``tests/``; nothing is executed.
"""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent / "_ext"))

import rwall_fem  # noqa: E402  (after the path: the version, and autodoc's import check)

project = "rwall_fem"
author = "the rwall_fem developers"
copyright = "the rwall_fem developers"
release = version = rwall_fem.__version__

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "rwall_docs",
]
source_suffix = {".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "_ext"]

# MyST: {w=160px} on images (the gallery's thumbnails), anchors for links to sections
# (theory.md#one-point-hexahedra).
myst_enable_extensions = ["attrs_inline", "colon_fence"]
myst_heading_anchors = 3

# autodoc: members in the order of the source, as listed in each module's __all__.
autodoc_member_order = "bysource"
autodoc_default_options = {"members": True}
autodoc_typehints = "description"
napoleon_numpy_docstring = False

html_theme = "alabaster"
html_title = "rwall_fem"
html_theme_options = {
    "description": "Explicit elastodynamics on DOLFINx meshes with Radioss-style rigid walls",
    "fixed_sidebar": True,
    "page_width": "1100px",
    "sidebar_width": "230px",
}
html_show_sourcelink = False
