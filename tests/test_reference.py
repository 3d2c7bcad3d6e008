"""The FE-overkill cache is never stale and never corrupt."""
import os

import numpy as np
import pytest
import skfem as fem

from skfem_pg import materials as mat
from skfem_pg.scenes.reference import cache_dir, overkill
from skfem_pg.scenes import Scene


def _mesh(loaded="right"):
    m = fem.MeshQuad.init_tensor(np.linspace(0, 4, 5), np.linspace(0, 1, 3))
    return m.with_boundaries({
        "left": lambda x: x[0] == 0,
        "right": (lambda x: x[0] == 4) if loaded == "right"
        else (lambda x: x[1] == 1)})


def _scene(mesh=None, mu=1.0, probe=(4.0, 1.0)):
    return Scene("cache-test", _mesh() if mesh is None else mesh,
                 mat.NeoHooke(lam=2.0, mu=mu), clamped=["left"],
                 tractions={"right": [0.0, 0.01]}, probes={"tip": probe})


@pytest.fixture
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv("SKFEM_PG_CACHE", str(tmp_path / "cache"))
    return tmp_path / "cache"


def _tip(scene):
    return overkill(scene, refine=1, verbose=False).probes["tip"][1]


def test_changed_problems_never_reuse_a_reference(cache):
    base = _tip(_scene())
    assert _tip(_scene()) == base and len(os.listdir(cache)) == 1
    # the loaded boundary redefined under the same name (was: 77 % off)
    moved = _tip(_scene(_mesh(loaded="top")))
    assert abs(moved - base) > 0.1 * abs(base)
    # a probe moved to another point
    s = _scene(probe=(2.0, 1.0))
    assert abs(_tip(s) - base) > 0.1 * abs(base)
    # a material parameter changed in the 9th digit
    s = _scene(mu=1.0 + 1e-9)
    assert _tip(s) != base
    assert len(os.listdir(cache)) == 4


def test_a_corrupt_entry_is_recomputed(cache):
    base = _tip(_scene())
    (fn,) = list(cache.iterdir())
    fn.write_bytes(fn.read_bytes()[:100])  # truncated
    with pytest.warns(UserWarning, match=str(fn.name)):
        again = _tip(_scene())
    assert again == base
    assert _tip(_scene()) == base  # rewritten whole


def test_an_unwritable_cache_warns_and_returns(tmp_path, monkeypatch):
    blocker = tmp_path / "not-a-directory"
    blocker.write_text("x")  # a file where the cache directory should be
    monkeypatch.setenv("SKFEM_PG_CACHE", str(blocker / "cache"))
    with pytest.warns(UserWarning, match="could not write"):
        tip = _tip(_scene())
    assert np.isfinite(tip) and cache_dir() == str(blocker / "cache")


def test_prescribed_components_of_quadratic_elements():
    """A symmetry condition u_x = 0 on a line holds at the Q2 facet
    (mid-side) dofs too: before, only the nodal dofs were constrained and
    the Q2 reference of the plate with a hole had Kt = 10.9 instead of
    3.36."""
    mesh = _mesh().with_boundaries({"bottom": lambda x: x[1] == 0})
    # u_y = 0 on the bottom holds the y translation (without it the
    # system is singular and the solve refuses it)
    s = Scene("sym", mesh, mat.NeoHooke(lam=2.0, mu=1.0),
              prescribed={"left": {0: 0.0}, "right": {0: 0.05},
                          "bottom": {1: 0.0}})
    r = s.solve("Q2")
    D = r.basis.get_dofs("left").all("u^1")
    assert len(D) > len(r.basis.get_dofs("left").nodal["u^1"])
    assert np.abs(r.u[D]).max() == 0.0
    Dr = r.basis.get_dofs("right").all("u^1")
    assert np.allclose(r.u[Dr], 0.05)


def test_linear_cook_reference_is_cached_and_checked(cache, capsys):
    from skfem_pg.scenes.reference import linear_cook
    v, (c, f) = linear_cook(1.0, 0.5, sizes=(4, 8))
    assert v == pytest.approx(f + (f - c) / 3.0)
    assert "Q2 overkill" in capsys.readouterr().out
    assert linear_cook(1.0, 0.5, sizes=(4, 8)) == (v, (c, f))
    assert capsys.readouterr().out == ""  # from the cache
    (fn,) = [os.path.join(cache_dir(), n) for n in os.listdir(cache_dir())]
    size = os.path.getsize(fn)
    with open(fn, "r+b") as fh:  # a truncated entry: recomputed, named
        fh.truncate(size // 2)
    with pytest.warns(UserWarning, match="linear-cook"):
        assert linear_cook(1.0, 0.5, sizes=(4, 8))[0] == pytest.approx(v)
    assert linear_cook(1.0, 0.6, sizes=(4, 8))[0] != v  # another key


def test_vertex_at_names_a_point_without_vertex():
    import skfem_pg as pg
    mesh = pg.meshing.cook_membrane(4)
    assert np.allclose(mesh.p[:, pg.meshing.vertex_at(mesh, (48, 52))],
                       (48, 52))
    with pytest.raises(ValueError, match=r"no vertex at \(48.0, 51.0\)"):
        pg.meshing.vertex_at(mesh, (48, 51))
