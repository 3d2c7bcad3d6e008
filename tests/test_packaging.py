"""The repository's layout as the wheel sees it: every subpackage listed in
``pyproject.toml``, the ``.geo`` sources kept once (top-level ``meshes/``)
and found by :func:`skfem_pg.meshing.geo_path`."""
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
    assert top == ["beam3d.geo", "cook.geo", "cook3d.geo", "cube.geo",
                   "plate_hole3d.geo", "square.geo"]


def test_geo_path_finds_every_source_and_names_a_missing_one():
    for name in ("cook.geo", "cook3d.geo", "cube.geo", "square.geo",
                 "beam3d.geo", "plate_hole3d.geo"):
        assert os.path.isfile(pg.meshing.geo_path(name))
    with pytest.raises(FileNotFoundError, match="cook.geo"):
        pg.meshing.geo_path("nothing.geo")
