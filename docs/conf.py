"""Sphinx configuration of polind's documentation (``make docs``).

Built offline: MathJax is served from the build's own ``_static`` (the
``sphinx-mathjax-offline`` package ships it), the theme's fonts and icons are
its own, and nothing is loaded from the network when a page opens.  The
tables of file keys, system keys, sweep metrics and default bounds are made
at build time from the code (``_ext/polind_docs.py``), so they cannot drift
from what polind reads.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
sys.path.insert(0, str(DOCS / "_ext"))
# An installed polind is used when there is one (``pip install -e .``); else the source tree.
try:
    import polind  # noqa: F401
except ImportError:                                   # pragma: no cover
    sys.path.insert(0, str(ROOT / "src"))
    import polind  # noqa: F401

project = "polind"
author = "the polind developers"
copyright = "2026, the polind developers"
version = release = polind.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx.ext.intersphinx",
    "numpydoc",
    "sphinx_click",
    "sphinx_gallery.gen_gallery",
    "polind_docs",
]

# The root document and what is not a source.
root_doc = "index"
exclude_patterns = ["_build", "**/_build", "Thumbs.db", ".DS_Store"]
templates_path = ["_templates"]
html_static_path = ["_static"]

# --- cross-references ------------------------------------------------------------------
nitpicky = True
# Objects of other projects: no inventories are fetched (the build is offline), so a
# reference to one of them is left as plain text instead of a broken link.
nitpick_ignore_regex = [
    (r"py:.*", r"(numpy|np|scipy|pandas|control|numba|distributed|dask|matplotlib|"
               r"SurfaceTopography|pyarrow|click|os|pathlib|collections|typing|io|"
               r"threading|json|concurrent|dataclasses)(\..*)?"),
    (r"py:.*", r"(ndarray|Path|PathLike|Callable|Mapping|Sequence|Iterable|Any|ClassVar|"
               r"NonlinearIOSystem|Figure|Axes|DataFrame|Client)"),
    # Python's own types (no inventory of the standard library either).
    (r"py:.*", r"(int|float|complex|str|bool|bytes|dict|list|tuple|set|frozenset|object|"
               r"type|None|True|False|Exception|BaseException|ValueError|TypeError|"
               r"KeyboardInterrupt|UserWarning|ImportError|OSError)"),
]
# The contact-table slots of polind.kernels.structure (FIRST, SECOND, SIGN), named by its
# docstrings, are plain comments there, not documented constants (#:).
nitpick_ignore = [("py:data", name) for name in ("FIRST", "SECOND", "SIGN")]
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False

autosummary_generate = True
autosummary_imported_members = True
autodoc_typehints = "none"
autodoc_member_order = "bysource"

# --- HTML ----------------------------------------------------------------------------------
html_theme = "pydata_sphinx_theme"
html_title = f"polind {release}"
html_theme_options = {
    "navbar_align": "left",
    "show_toc_level": 2,
    "navigation_with_keys": False,
    "secondary_sidebar_items": ["page-toc"],
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version"],
    "article_footer_items": [],
    "content_footer_items": [],
}
html_show_sourcelink = False
html_copy_source = False
html_context = {"default_mode": "light"}
html_sidebars = {"index": [], "cli": [], "formats": []}

# MathJax from the build directory (polind_docs copies it there): pages render equations
# with no network.
mathjax_path = "mathjax/tex-chtml.js"

# --- the gallery: examples/*.py, run at build time -----------------------------------------
from polind_docs import GalleryArgv, PngScraper, write_api_pages  # noqa: E402

# The API pages list polind.__all__ and the subpackages' __all__ (written before the
# sources are read, so that autosummary makes a page for every public name).
write_api_pages(DOCS)

# Each example writes into its own empty directory here (outside the sources).
_gallery_argv = GalleryArgv(Path(os.environ.get("POLIND_GALLERY_OUTPUT",
                                                DOCS / "_build" / "gallery-output")))

sphinx_gallery_conf = {
    "examples_dirs": [str(ROOT / "examples")],
    "gallery_dirs": ["auto_examples"],
    # Every script of examples/ is an example, run in name order.
    "filename_pattern": r"\.py$",
    "ignore_pattern": r"__init__\.py$",
    "within_subsection_order": "FileNameSortKey",
    # The scripts write their figures (PNG) to an output directory given on their command
    # line, as a user runs them; the scraper picks those files up.
    "reset_argv": _gallery_argv,
    "image_scrapers": (PngScraper(_gallery_argv),),
    "capture_repr": (),
    "download_all_examples": False,
    "show_signature": False,
    "remove_config_comments": True,
    # The data the scripts read ships with polind: a script that fails is a broken
    # example, and `make docs` fails with it (after building the rest of the site).
    "only_warn_on_example_error": False,
    "default_thumb_file": str(DOCS / "_static" / "thumbnail.png"),
    "line_numbers": False,
    # The timing pages load a sortable table from a CDN: not written, so every page
    # opens offline (the timings are printed by the build).
    "write_computation_times": False,
    "parallel": False,
}
