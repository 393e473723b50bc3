"""Sphinx configuration of the snapping documentation.

Build (from the repository root, after ``pip install -e ".[docs]"``)::

    sphinx-build -W --keep-going -b html docs docs/_build/html

Nothing is executed in the build but the imports of autodoc: the notebooks are
rendered as stored (``nb_execution_mode = "off"``; ``tests/test_notebooks.py``
executes them), and the command-line page formats ``snapping.cli.build_parser()``'s
help texts.
"""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
sys.path.insert(0, str(ROOT / "src"))  # document this tree's package, installed or not
sys.path.insert(0, str(DOCS / "_ext"))

import snapping  # noqa: E402

project = "snapping"
author = "snapping developers"
copyright = "2026, snapping developers"
release = snapping.__version__
version = ".".join(release.split(".")[:2])

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "myst_nb",
    "snapping_cli",
]

# --- sources -----------------------------------------------------------------------
source_suffix = {".rst": "restructuredtext", ".md": "myst-nb", ".ipynb": "myst-nb"}
root_doc = "index"
exclude_patterns = ["_build", "scripts", "Thumbs.db", ".DS_Store", "**.ipynb_checkpoints"]

# The notebooks live in ../notebooks (where tests/test_notebooks.py runs them); Sphinx
# reads only its source folder, so they are copied into docs/notebooks/ (ignored by git)
# before the build, unchanged files left alone so that incremental builds stay quick.
NB_SRC, NB_DST = ROOT / "notebooks", DOCS / "notebooks"
NB_DST.mkdir(exist_ok=True)
_wanted = {p.name for p in NB_SRC.glob("*.ipynb")}
for stale in NB_DST.glob("*.ipynb"):
    if stale.name not in _wanted:
        stale.unlink()
for src in sorted(NB_SRC.glob("*.ipynb")):
    dst = NB_DST / src.name
    if not dst.exists() or dst.read_bytes() != src.read_bytes():
        shutil.copy2(src, dst)

# --- MyST and notebooks ------------------------------------------------------------
nb_execution_mode = "off"  # rendered as stored: the test suite executes them
myst_enable_extensions = ["dollarmath", "colon_fence", "deflist"]
myst_heading_anchors = 3

# --- autodoc, autosummary, numpydoc -----------------------------------------------
autodoc_default_options = {"members": True, "member-order": "bysource"}
autodoc_typehints = "none"  # the numpydoc sections give the types
autosummary_generate = False  # tables only; each module has its hand-written page
numpydoc_show_class_members = False  # autodoc's :members: lists them once
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

# --- HTML ------------------------------------------------------------------------
html_theme = "furo"
html_title = f"snapping {release}"
html_static_path: list[str] = []


# --- docstrings written as plain-text math -------------------------------------------
# The docstrings write absolute values and norms as |x| (|E(t) - E(0)|, |d_k|), which
# reST reads as substitution references (an error under -W). Outside literal blocks,
# doctest lines and ``inline literals``, such a pair is escaped before parsing.
import re  # noqa: E402

_ABS = re.compile(r"(?<![\w`\\|])\|(?=[^\s|`])([^|`\n]*?[^\s|`\\])\|(?![\w`|])")


def _escape_abs_bars(app, what, name, obj, options, lines):
    literal_indent = None
    for i, line in enumerate(lines):
        stripped = line.lstrip()
        indent = len(line) - len(stripped)
        if literal_indent is not None:
            if stripped and indent <= literal_indent:
                literal_indent = None
            else:
                continue
        table_row = stripped.startswith("|") and stripped.rstrip().endswith("|")
        if stripped.startswith((">>>", "...", "| ", "+-", "+=")) or table_row:  # doctest, line block, table
            continue
        lines[i] = _ABS.sub(r"\\|\1\\|", line)
        if line.rstrip().endswith("::"):
            literal_indent = indent


def setup(app):
    app.connect("autodoc-process-docstring", _escape_abs_bars, priority=600)  # after numpydoc (500)
