"""The repository's layout as the wheel sees it: every subpackage listed in
``pyproject.toml``, the ``.geo`` sources kept once (top-level ``meshes/``)
and found by :func:`skfem_pg.meshing.geo_path`; every source compiles
without a warning."""
import os

import pytest

import skfem_pg as pg

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PYPROJECT = os.path.join(ROOT, "pyproject.toml")


def _subpackages():
    found = []
    for here, _, files in os.walk(os.path.join(ROOT, "skfem_pg")):
        if "__init__.py" in files:
            found.append(os.path.relpath(here, ROOT).replace(os.sep, "."))
    return found


@pytest.mark.skipif(not os.path.isfile(PYPROJECT),
                    reason="runs in the repository")
def test_pyproject_lists_every_subpackage():
    tomllib = pytest.importorskip("tomllib")
    with open(PYPROJECT, "rb") as f:
        config = tomllib.load(f)["tool"]["setuptools"]
    assert sorted(config["packages"]) == sorted(_subpackages()
                                                + ["skfem_pg.meshes"])
    assert config["package-dir"] == {"skfem_pg.meshes": "meshes"}


@pytest.mark.skipif(not os.path.isfile(PYPROJECT),
                    reason="runs in the repository")
def test_geo_sources_are_kept_once():
    inside = [f for _, _, files in os.walk(os.path.join(ROOT, "skfem_pg"))
              for f in files if f.endswith(".geo")]
    assert inside == []
    top = sorted(f for f in os.listdir(os.path.join(ROOT, "meshes"))
                 if f.endswith(".geo"))
    assert top == ["beam3d.geo", "bracket.geo", "cook.geo", "cook3d.geo",
                   "cube.geo", "kalthoff_winkler.geo", "plate_hole3d.geo",
                   "plate_slot.geo", "plate_two_holes.geo", "square.geo"]


def test_geo_path_finds_every_source_and_names_a_missing_one():
    for name in ("cook.geo", "cook3d.geo", "cube.geo", "square.geo",
                 "beam3d.geo", "plate_hole3d.geo", "plate_slot.geo",
                 "plate_two_holes.geo", "kalthoff_winkler.geo"):
        assert os.path.isfile(pg.meshing.geo_path(name))
    with pytest.raises(FileNotFoundError, match="cook.geo"):
        pg.meshing.geo_path("nothing.geo")


def test_the_public_api_is_typed():
    """PEP 561: ``py.typed`` ships with the package and the public entry
    points' hints resolve (no name a type checker could not find)."""
    import importlib.resources
    import typing

    import skfem_pg as pg
    assert importlib.resources.files("skfem_pg").joinpath("py.typed") \
        .is_file()
    for fn in (pg.FamilyBasis.__init__, pg.FamilyBasis.from_name,
               pg.FamilyBasis.from_spec, pg.assemble, pg.traction,
               pg.stress_load, pg.body_force, pg.lumped_mass, pg.newton,
               pg.newmark, pg.central_difference, pg.Scene.__init__,
               pg.Scene.solve, pg.write_vtu):
        hints = typing.get_type_hints(fn)
        assert "return" in hints, fn.__qualname__


def test_every_source_compiles_without_a_warning():
    # an invalid escape in a docstring (a DeprecationWarning, then a
    # SyntaxWarning; a SyntaxError in a later Python) slipped in once
    import warnings
    found = []
    for top in ("skfem_pg", "meshes", "demos", "benchmarks", "tests", "docs"):
        for here, _, files in os.walk(os.path.join(ROOT, top)):
            for name in files:
                if not name.endswith(".py"):
                    continue
                path = os.path.join(here, name)
                with open(path, encoding="utf-8") as f:
                    text = f.read()
                with warnings.catch_warnings(record=True) as caught:
                    warnings.simplefilter("always")
                    compile(text, path, "exec")
                found += ["{}:{}: {}".format(os.path.relpath(path, ROOT),
                                             w.lineno, w.message)
                          for w in caught]
    assert found == []
