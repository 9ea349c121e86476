"""Sphinx configuration of the anthroarm documentation site.

Build: ``sphinx-build -W --keep-going -b html docs docs/_build/html`` (the test suite runs this:
tests/docs/test_docs_build.py).  Why Sphinx + PyData theme + myst-nb: the docstrings are numpydoc,
so autodoc/autosummary (with napoleon) turn them into the API reference, ``nitpicky`` turns every
broken cross-reference into an error, and myst-nb executes the notebooks at build time and keeps
their outputs and plots, with the pages in Markdown like the rest of the repository.

Generated at build time (not committed, see docs/.gitignore), so they cannot go stale:
* ``notebooks/*.ipynb`` — copies of the repository's ``notebooks/``, executed by myst-nb;
* ``benchmarks/generated/*.md`` — one page per committed ``benchmarks/results/*.md`` (+ plots);
* ``book_map_equations.md`` — every ``Eq. (…)`` named in a docstring, with its function.
"""

from __future__ import annotations

import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
sys.path.insert(0, str(DOCS / "_ext"))
sys.path.insert(0, str(ROOT / "src"))

import build_pages  # noqa: E402  (docs/_ext/build_pages.py)

import anthroarm  # noqa: E402

project = "anthroarm"
author = "the anthroarm developers"
copyright = "2026, the anthroarm developers"
release = version = anthroarm.__version__

extensions = [
    "myst_nb",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "reexports",  # docs/_ext/reexports.py: a re-exported name links to where it is defined
]

# ---------------------------------------------------------------- pages generated from the repo
build_pages.copy_notebooks(ROOT / "notebooks", DOCS / "notebooks")
build_pages.benchmark_pages(ROOT / "benchmarks" / "results", DOCS / "benchmarks" / "generated")
build_pages.equation_table(DOCS / "book_map_equations.md")
build_pages.PUBLIC.update(build_pages.public_paths())  # anthroarm.robot.load -> anthroarm.load
build_pages.api_pages(DOCS / "api" / "generated")
# the guide's table of contents: docs/batch.md (batch jobs, local or Dask) joins it when it exists
GUIDE = [
    "load",
    "osim",
    "kinematics",
    "ik",
    "compiled",
    "dynamics",
    "mechanisms",
    "design",
    "hand",
    "grasp",
    "collision",
    "motion",
    "opensim_ik",
    "muscles",
    "prosthesis",
    "emg",
    "control",
    "book_systems",
    "viewer",
    "cli",
    *(["/batch"] if (DOCS / "batch.md").is_file() else []),
    "benchmarks",
]
build_pages.write_if_changed(
    DOCS / "guide" / "_toc.md", "```{toctree}\n:maxdepth: 1\n\n" + "\n".join(GUIDE) + "\n```\n"
)

exclude_patterns = [
    "_build",
    "jupyter_execute",
    "**.ipynb_checkpoints",
    "guide/_toc.md",
    "book_map_equations.md",
]
templates_path: list[str] = []
source_suffix = {
    ".rst": "restructuredtext",
    ".md": "myst-nb",
    ".ipynb": "myst-nb",
}  # .rst first: autosummary writes its pages with the first suffix

# ---------------------------------------------------------------- warnings are errors (-W)
nitpicky = True
# third-party and builtin types named in our docstrings: the site is built offline, so there is
# no intersphinx inventory to resolve them against.  Our own names are never listed here.
nitpick_ignore_regex = [
    (
        r"py:.*",
        r"(numpy|np|scipy|sympy|pinocchio|pin|meshcat|matplotlib|dask|distributed|xarray"
        r"|yourdfpy|lxml|qpsolvers|osqp|tornado|zmq|pathlib|os|typing|collections|concurrent"
        r"|threading|subprocess|argparse|io|numbers|enum|abc|types|weakref|tqdm|ctypes|numba"
        r"|datetime)(\..*)?",
    ),
    # prose in numpydoc type fields ("array (N, 3)", "float, rad") is not a Python name
    (r"py:class", r"[a-z_][a-z0-9_]*|.*[^\w.].*|True|False|[A-Z]|\d+|Eq\.?|\."),
    # module constants without a doc comment are not in the reference (names in prose)
    (r"py:data", r"(.*\.)?[A-Z][A-Z0-9_]*"),
    # private objects are not part of the API reference
    (r"py:.*", r"(.*\.)?_[^.]*(\..*)?"),
    (
        r"py:.*",
        r"(ndarray|ArrayLike|NDArray|Path|PathLike|Sequence|Mapping|Iterable|Iterator|Callable"
        r"|Any|Optional|Union|Literal|Self|TypeVar|Generator|Hashable|Enum|IntEnum|Exception"
        r"|RuntimeError|ValueError|TypeError|KeyError|FileNotFoundError|OSError|LookupError"
        r"|int|float|str|bytes|bool|complex|dict|list|tuple|set|frozenset|object|type|None"
        r"|array_like|array-like|optional|callable|sequence|mapping|iterable|default|shape"
        r"|N|n|m|nq|nv)",
    ),
]

# ---------------------------------------------------------------- API reference
autodoc_default_options = {
    "members": True,
    "undoc-members": True,
    "show-inheritance": True,
    # document each object once, in the module that defines it (packages re-export names)
    "ignore-module-all": True,
}
autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_typehints_format = "short"
autodoc_preserve_defaults = True
napoleon_numpy_docstring = True
napoleon_google_docstring = False
napoleon_use_rtype = False
napoleon_use_ivar = True  # "Attributes" sections as fields: dataclass fields are documented once
# a short attribute name (:attr:`nq`) defined on several classes links to one of them: not an error
suppress_warnings = ["ref.python"]

# ---------------------------------------------------------------- notebooks (myst-nb)
# Executed once per build, here; see docs/index.md ("How this site is built") for why.
nb_execution_mode = "force"
nb_execution_timeout = 300
nb_execution_raise_on_error = True
nb_execution_show_tb = True
nb_merge_streams = True
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]
myst_heading_anchors = 3

# ---------------------------------------------------------------- HTML
html_theme = "pydata_sphinx_theme"
html_title = f"anthroarm {release}"
# docs/_static/anthroarm.css: long commands wrap, wide tables fit the page, CJK fonts (仿生机械学)
html_static_path = ["_static"]
html_css_files = ["anthroarm.css"]
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc"],
}
html_show_sourcelink = False


def setup(app):
    app.connect("autodoc-process-docstring", build_pages.escape_bars)
    app.connect("autodoc-skip-member", build_pages.skip_shadowing)
    app.connect("autodoc-skip-member", build_pages.skip_moved)
