"""Sphinx configuration of the boxtrees site: the user guide (the Markdown pages of docs/,
read by myst-parser), the API reference (autosummary + numpydoc) and the example gallery
(sphinx-gallery, scripts under examples/ at the top of the repository).

Build from the repository's root::

    python -m sphinx -b html docs docs/_build/html
"""
import ast
import re
import sys
from pathlib import Path

import matplotlib
from sphinx.errors import PycodeError
from sphinx.pycode import ModuleAnalyzer

matplotlib.use("Agg")

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT))   # the packages of a checkout (built in place)

import boxtrees  # noqa: E402

# -- Project ----------------------------------------------------------------------------------

project = "boxtrees"
copyright = "the boxtrees developers"
version = release = boxtrees.__version__

# -- General ----------------------------------------------------------------------------------

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
templates_path = ["_templates"]
html_static_path = ["_static"]
exclude_patterns = ["_build", "_templates"]

# `name` in the docstrings: a Python object, linked where Sphinx knows it, else code.
default_role = "py:obj"
add_function_parentheses = False
pygments_style = "sphinx"

# -- API reference: autosummary + numpydoc -----------------------------------------------------

autosummary_generate = True
autosummary_imported_members = True
autodoc_default_options = {"members": True}
autodoc_typehints = "none"       # the numpydoc sections give the types
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_attributes_as_param_list = True
numpydoc_xref_param_type = False

# -- User guide: the Markdown pages -----------------------------------------------------------

# The pages are written for GitHub and read here as they are: their links to each other
# ("[text](page.md)", "[text](page.md#a-heading)") become links between the site's pages.
myst_heading_anchors = 3

# -- Example gallery --------------------------------------------------------------------------
# (in file name order: the estimator, the Q-forest, then the agent on any env)

sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "examples"),
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "reference_url": {"boxtrees": None, "envs": None, "fqi": None},
    "doc_module": ("boxtrees", "envs", "fqi"),
    "backreferences_dir": "gen_modules/backreferences",
    "matplotlib_animations": False,
    "show_memory": False,
    "min_reported_time": 1,
}

# -- HTML -------------------------------------------------------------------------------------

html_theme = "pydata_sphinx_theme"
html_title = f"boxtrees {release}"
html_theme_options = {
    "navbar_align": "left",
    "header_links_before_dropdown": 5,
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc"],
    "footer_start": ["copyright"],
    "footer_end": [],
}
html_context = {"default_mode": "light"}
html_sidebars = {"index": []}
html_css_files = ["custom.css"]
html_show_sourcelink = False

# -- Hooks ------------------------------------------------------------------------------------

_OWN = ("boxtrees", "envs", "fqi")


def _defined_in(obj):
    """The module that defines a class member (a function, a property or a descriptor)."""
    obj = getattr(obj, "fget", obj)
    return getattr(obj, "__module__", None) or ""


def _skip_foreign_members(app, what, name, obj, skip, options):
    """Document the members the project defines; leave out those inherited from
    scikit-learn, gymnasium or torch, whose docstrings refer to labels of their own sites
    (their pages are the reference for them)."""
    if what == "class" and _defined_in(obj).split(".")[0] not in _OWN:
        return True
    return None


_ANCHOR = re.compile(r'^<a id="([^"]+)"></a>\s*$', re.MULTILINE)


def _anchors_as_targets(app, docname, source):
    """``<a id="name"></a>`` lines, which GitHub renders as anchors of the Markdown pages
    (docs/results/REPORT.md, written by the reproduction harness, links its rows to its
    sections with them), become MyST targets ``(name)=`` for the same links here."""
    if app.env.doc2path(docname).suffix == ".md":
        source[0] = _ANCHOR.sub(r"(\1)=", source[0])


def _definitions(body, prefix=""):
    """The functions and classes of a module's `body` (methods too, as ``Class.name``) as
    viewcode's tags: ``{name: ("def" | "class", first line, last line)}``, the first line that
    of the first decorator."""
    tags = {}
    for node in body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            name = prefix + node.name
            start = min([node.lineno] + [d.lineno for d in node.decorator_list])
            is_class = isinstance(node, ast.ClassDef)
            tags[name] = ("class" if is_class else "def", start, node.end_lineno)
            if is_class:
                tags.update(_definitions(node.body, name + "."))
    return tags


_SOURCES = {}


def _source_and_tags(app, modname):
    """viewcode's source and tags of one of our modules that Sphinx's own module parser
    cannot read; None for any other (viewcode reads it itself).

    Sphinx 9.0's parser unparses each decorator and fails on a dict display holding
    ``**mapping`` (``sphinx.pycode.ast``: "zip() argument 2 is longer than argument 1"), as
    in ``@validate_params({**_COMMON, ...})`` of ``boxtrees/_inspection.py``; viewcode then
    drops the module: no [source] link for ``type_importance`` and ``region_importance``,
    and no ``_modules/boxtrees/_inspection.html``. Python's own parser reads it.
    """
    if modname.split(".")[0] not in _OWN:
        return None
    if modname not in _SOURCES:
        try:
            ModuleAnalyzer.for_module(modname).find_tags()
            _SOURCES[modname] = None
        except PycodeError:
            try:
                _, code = ModuleAnalyzer.get_module_source(modname)
                _SOURCES[modname] = code, _definitions(ast.parse(code).body)
            except (PycodeError, SyntaxError):
                _SOURCES[modname] = None
    return _SOURCES[modname]


def setup(app):
    app.connect("autodoc-skip-member", _skip_foreign_members)
    app.connect("source-read", _anchors_as_targets)
    app.connect("viewcode-find-source", _source_and_tags)
