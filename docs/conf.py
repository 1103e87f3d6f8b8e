"""Sphinx configuration of fracid's documentation site.

Build (after ``pip install ".[docs]"``), warnings as errors::

    python -m sphinx -W --keep-going -b html docs docs/_build/html

The pages are Markdown (MyST); the API reference is generated from the numpydoc docstrings (autosummary), the
command-line reference from the argparse parsers (sphinx-argparse), the configuration reference from
:func:`fracid.config.reference.entries` (the registries the checker reads) and the gallery from
``examples/gallery/`` (sphinx-gallery, executed at every build).
"""

import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
sys.path.insert(0, str(DOCS / "_ext"))

project = "fracid"
author = "the fracid developers"
copyright = "2026, the fracid developers"
try:
    from fracid.store.provenance import fracid_version

    release = fracid_version()
except Exception:  # the site still builds from a tree without an installed fracid's metadata
    release = "0.1.0"
version = release

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx.ext.intersphinx",
    "numpydoc",
    "sphinxarg.ext",
    "sphinx_gallery.gen_gallery",
    "fracid_api_reference",
    "fracid_config_reference",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "tutorials/files/**", "**/runs.sqlite*", "gallery/*.ipynb", "gallery/*.py", "gallery/*.zip",
                    "gallery/*.json", "sg_execution_times.rst"]
templates_path = ["_templates"]

# MyST: $...$ maths, anchors for the headings a page links to, ```{directive} blocks
myst_enable_extensions = ["dollarmath", "colon_fence", "deflist"]
myst_heading_anchors = 4

# API: one page per public name, from the numpydoc docstrings
autosummary_generate = True
autodoc_default_options = {"members": False}
autodoc_typehints = "none"
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False
numpydoc_validation_checks = set()

intersphinx_mapping = {}

# the gallery: the scripts of examples/gallery/, executed at each build (small meshes: minutes, not hours)
sphinx_gallery_conf = {
    "examples_dirs": str(DOCS.parent / "examples" / "gallery"),
    "gallery_dirs": "gallery",
    "filename_pattern": r"/plot_",
    "download_all_examples": False,
    "remove_config_comments": True,
    "abort_on_example_error": True,
    "matplotlib_animations": False,
    "within_subsection_order": "FileNameSortKey",
    "show_signature": False,
}

html_theme = "furo"
html_title = f"fracid {release}"
html_static_path = []
html_show_sourcelink = False
