"""The ``>>>`` examples of every module of the package run and print what
they show (issue 49: examples in the docstrings, run by the tests)."""
import doctest
import importlib
import pkgutil

import pytest

import skfem_pg

MODULES = sorted(m.name for m in pkgutil.walk_packages(
    skfem_pg.__path__, "skfem_pg."))


@pytest.mark.parametrize("name", [m for m in MODULES
                                  if not m.startswith("skfem_pg.distributed")])
def test_docstring_examples_run(name):
    module = importlib.import_module(name)
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS)
    assert result.failed == 0, name


def test_the_examples_are_there():
    """Not vacuous: the modules hold examples (the parts, the spec, the
    problem record, the naming round trip among them)."""
    finder = doctest.DocTestFinder()
    counted = {}
    for name in MODULES:
        if name.startswith("skfem_pg.distributed"):
            continue
        tests = finder.find(importlib.import_module(name))
        counted[name] = sum(len(t.examples) for t in tests)
    for name in ("skfem_pg.discretization.parts",
                 "skfem_pg.discretization.builder", "skfem_pg.naming",
                 "skfem_pg.solvers.problem"):
        assert counted[name] > 0, name
    assert sum(counted.values()) >= 60


def test_every_module_is_in_the_api_reference():
    """docs/api.rst lists every module of the package (a module added
    without it is missing from the reference)."""
    import pathlib
    import re
    path = pathlib.Path(__file__).resolve().parents[1] / "docs" / "api.rst"
    if not path.exists():
        pytest.skip("the tests run outside the repository (no docs/)")
    api = path.read_text()
    listed = set(re.findall(r"automodule:: (\S+)", api))
    assert [m for m in MODULES if m not in listed] == []
