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
    """The API reference has a page per module, headed by its name, and
    every package's page lists its modules (docs/apipages.py makes them
    from the package; a module added has its page)."""
    import pathlib
    import sys
    docs = pathlib.Path(__file__).resolve().parents[1] / "docs"
    if not (docs / "apipages.py").exists():
        pytest.skip("the tests run outside the repository (no docs/)")
    sys.path.insert(0, str(docs))
    try:
        import apipages
    finally:
        sys.path.remove(str(docs))
    pages = apipages.pages()
    assert [m for m in MODULES if m + ".rst" not in pages] == []
    listed = set()
    for name, text in pages.items():
        module = name[:-len(".rst")]
        assert text.startswith("``{}``\n".format(module))
        assert ".. automodule:: " + module in text
        listed |= {line.strip() for line in text.split("\n")
                   if line.startswith("   skfem_pg")}
    assert {m + ".rst" for m in listed} == set(pages) - {"skfem_pg.rst"}
    flow = [line.strip() for line in pages["skfem_pg.rst"].split("\n")
            if line.startswith("   skfem_pg.")]
    assert flow[:3] == ["skfem_pg.discretization", "skfem_pg.formulations",
                        "skfem_pg.materials"]
    assert "docs/api/" in (docs.parent / ".gitignore").read_text()
