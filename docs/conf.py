"""Sphinx configuration of the skfem-pg documentation.

Build from a clean checkout, offline, warnings as errors::

    pip install ".[docs]"
    sphinx-build -W -b html docs docs/_build/html

The gallery runs ``docs/examples/ex*.py`` (sphinx-gallery) and shows their
figures; ``SKFEM_PG_CACHE`` decides where ex04's overkill is cached.
"""
import os
import sys

import skfem_pg

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import apipages  # noqa: E402  (docs/apipages.py)

# one page per module, made from the package (docs/api/, not in git)
apipages.write(os.path.join(os.path.dirname(os.path.abspath(__file__)),
                            "api"))

project = "skfem-pg"
author = "the skfem-pg developers"
copyright = "skfem-pg developers, BSD-3-Clause"
release = version = skfem_pg.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",     # the numpy-style docstrings
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "myst_parser",             # the guide pages are Markdown
    "sphinx_gallery.gen_gallery",
]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
myst_enable_extensions = ["dollarmath"]
exclude_patterns = ["_build", "examples", "sg_execution_times.rst"]
html_theme = "alabaster"
html_static_path = []
autodoc_member_order = "bysource"
autodoc_default_options = {"members": True, "show-inheritance": False}
napoleon_google_docstring = False
napoleon_use_rtype = False
napoleon_use_ivar = True  # "Attributes" as fields, not a second entry
suppress_warnings = ["myst.header"]

sphinx_gallery_conf = {
    "examples_dirs": "examples",
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/ex\d+_",   # run every example
    "download_all_examples": False,
    "remove_config_comments": True,
    "matplotlib_animations": False,
    "reset_modules": ("matplotlib",),
    "write_computation_times": False,
    # ex01, ex02, ... as numbered (the default orders by file length)
    "within_subsection_order": "FileNameSortKey",
}

# the examples write their own figure too: keep it out of the source tree
os.environ.setdefault("SKFEM_PG_OUT", os.path.join(
    os.path.dirname(os.path.abspath(__file__)), "_build", "example-out"))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
