"""Sphinx configuration of the clutchlab documentation site.

Build (warnings are errors): ``tools/build-docs`` or
``python -m sphinx -W --keep-going -b html -d docs/_build/doctrees docs docs/_build/html`` (the doctrees,
Sphinx's cache, outside the site: they were 29 MB of a 67 MB folder, #33).
Needs the ``docs`` extra: ``pip install -e ".[docs]"``.

The pages are Markdown (MyST); the API reference is generated from the numpydoc
docstrings by autodoc; equations are ``$...$``/``$$...$$`` rendered by MathJax,
which is shipped with the site (the part of ``sphinx-mathjax-offline``'s copy the
pages load), so neither the build nor viewing the pages needs the network.
"""

import os
import pathlib
import re
import sys
import warnings

DOCS = pathlib.Path(__file__).resolve().parent
ROOT = DOCS.parent
# Document the source tree next to this file, also when clutchlab is not installed (or installed elsewhere).
sys.path.insert(0, str(ROOT / "src"))
os.environ.setdefault("MPLBACKEND", "Agg")

import clutchlab  # noqa: E402

project = "clutchlab"
author = "clutchlab developers"
copyright = "clutchlab developers, BSD-3-Clause"
release = version = clutchlab.__version__

extensions = [
    "myst_parser",
    "numpydoc",
    "sphinx.ext.autodoc",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
]

source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store"]
nitpicky = False

# -- MyST: Markdown pages with math ---------------------------------------------------------------------------------
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]
myst_dmath_double_inline = True
myst_heading_anchors = 3

# -- autodoc + numpydoc ------------------------------------------------------------------------------------------------
autodoc_default_options = {"members": True, "show-inheritance": True}
autodoc_member_order = "bysource"
autodoc_typehints = "none"            # numpydoc's Parameters sections carry the types and units
autodoc_preserve_defaults = True
numpydoc_show_class_members = False   # members are documented by autodoc itself, once
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

# -- MathJax, shipped with the site: pages render math offline --------------------------------------------------------
# sphinx-mathjax-offline would copy all of MathJax 3 (24 MB: SVG and MathML outputs and combined builds the pages never
# load).  The site takes what tex-chtml.js loads: the TeX extensions it autoloads, its CHTML fonts, and the menu's
# accessibility explorer with its speech rules (a11y, sre, ui); 7 MB.
mathjax_path = "mathjax/tex-chtml.js"
MATHJAX_FILES = ("tex-chtml.js", "input/tex", "output/chtml/fonts/woff-v2", "a11y", "sre", "ui")


def _copy_mathjax(app, exc):
    import importlib.util
    import shutil

    if exc is not None or app.builder.format != "html":
        return
    spec = importlib.util.find_spec("sphinx-mathjax-offline")  # the docs extra's MathJax, no network
    if spec is None or spec.origin is None:
        raise RuntimeError("MathJax for the offline site: pip install -e '.[docs]' (sphinx-mathjax-offline)")
    source = pathlib.Path(spec.origin).parent / "static" / "mathjax"
    target = pathlib.Path(app.outdir) / "_static" / "mathjax"
    for part in MATHJAX_FILES:
        if (source / part).is_dir():
            shutil.copytree(source / part, target / part, dirs_exist_ok=True)
        else:
            (target / part).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(source / part, target / part)


# -- HTML ------------------------------------------------------------------------------------------------------------
html_theme = "furo"
html_title = f"clutchlab {release}"
html_static_path = []
html_show_sourcelink = False


# -- module docstrings -----------------------------------------------------------------------------------------------
# numpydoc turns the sections of function and class docstrings into rubrics, but leaves a module docstring's
# underlined headings ("References" / "----------") as real section titles: on a page that documents several
# modules they collide ("Duplicate ID: references") and nest under the page's headings.  Make them rubrics too, and
# cite the references once in a LaTeX-only block, as numpydoc does for functions (the text cites them as plain "[1]").
_UNDERLINE = set("-=~^")
_CITATION = re.compile(r"^\s*\.\. \[([\w.-]+)\]")


def _module_sections_as_rubrics(app, what, name, obj, options, lines):
    if what != "module":
        return
    out = []
    i = 0
    while i < len(lines):
        line = lines[i]
        nxt = lines[i + 1] if i + 1 < len(lines) else ""
        title = line.strip()
        if (title and not line.startswith(" ") and len(set(nxt.strip())) == 1 and nxt.strip()[0] in _UNDERLINE
                and len(nxt.strip()) >= len(title)):
            out += [f".. rubric:: {title}", ""]
            i += 2
            continue
        out.append(line)
        i += 1
    labels = [m.group(1) for m in map(_CITATION.match, out) if m]
    if labels:
        out += ["", ".. only:: latex", "", "   " + ", ".join(f"[{label}]_" for label in labels), ""]
    lines[:] = out


# numpydoc reports a malformed docstring (an unknown section, ...) as a Python UserWarning, which Sphinx's -W does not
# see; report it as a Sphinx warning so that the build fails on it.
def _numpydoc_warnings_as_sphinx_warnings():
    from sphinx.util import logging

    logger = logging.getLogger("numpydoc")
    show = warnings.showwarning

    def showwarning(message, category, filename, lineno, file=None, line=None):
        if "numpydoc" in pathlib.Path(filename).parts:
            logger.warning("numpydoc: %s", message)
        else:
            show(message, category, filename, lineno, file, line)

    warnings.showwarning = showwarning


def setup(app):
    app.connect("autodoc-process-docstring", _module_sections_as_rubrics, priority=400)
    app.connect("build-finished", _copy_mathjax)
    _numpydoc_warnings_as_sphinx_warnings()
