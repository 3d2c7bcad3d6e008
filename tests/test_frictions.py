"""Small frictions a new user meets (issue 30): each either works or
says what to do."""
import numpy as np
import meshio
import pytest
import skfem as fem

import skfem_pg as pg
from skfem_pg import materials


@pytest.fixture
def square():
    return fem.MeshQuad.init_tensor(*(np.linspace(0, 1, 5),) * 2)


def test_everyday_names_at_the_top_level():
    for name in ("Scene", "newton", "newmark", "central_difference",
                 "lumped_mass", "NewtonControls", "FamilyBasis",
                 "write_vtu", "traction"):
        assert hasattr(pg, name) and name in pg.__all__


def test_a_scene_names_missing_boundaries_at_construction(square):
    with pytest.raises(ValueError, match=r"'left', 'right'.*has none"):
        pg.Scene("s", square, materials.NeoHooke(1.0, 1.0),
                 clamped=["left"], tractions={"right": [0.0, 1.0]})
    named = square.with_boundaries({"left": lambda x: x[0] == 0})
    with pytest.raises(ValueError, match=r"'right'.*the mesh has 'left'"):
        pg.Scene("s", named, materials.NeoHooke(1.0, 1.0),
                 clamped=["left"], tractions={"right": [0.0, 1.0]})


def test_result_prints_one_line(square):
    mesh = square.with_boundaries({"left": lambda x: x[0] == 0,
                                   "right": lambda x: x[0] == 1})
    r = pg.Scene("s", mesh, materials.NeoHooke(1.0, 1.0), clamped=["left"],
                 tractions={"right": [0.0, 0.01]},
                 probes={"tip": (1.0, 1.0)}).solve("VCBCPBG V5m Unl")
    text = repr(r)
    assert "\n" not in text and len(text) < 200
    assert "'VCBCPBG V5m Unl'" in text and "tip=(" in text


def test_write_vtu_takes_a_basis(square, tmp_path):
    b = pg.FamilyBasis(square, dim=2)
    u = np.arange(b.N, dtype=float)
    pg.write_vtu(str(tmp_path / "a.vtu"), b, u=u)
    m = meshio.read(str(tmp_path / "a.vtu"))
    assert np.allclose(m.point_data["u"][:, :2], u.reshape(-1, 2))
    with pytest.raises(TypeError, match="mesh.save"):
        pg.write_vtu(str(tmp_path / "b.vtu"),
                     fem.Basis(square, fem.ElementQuad1()), u=u)


def test_traction_on_a_scikit_fem_basis(square):
    """``pg.traction`` on an FE basis integrates like on a family basis
    of the same mesh (it raised AttributeError)."""
    right = square.facets_satisfying(lambda x: x[0] == 1)
    fe = pg.traction(fem.Basis(square, fem.ElementVector(fem.ElementQuad1())),
                     right, [0.0, 2.0])
    pgf = pg.traction(pg.FamilyBasis(square, dim=2), right, [0.0, 2.0])
    assert np.allclose(fe, pgf) and np.isclose(fe[1::2].sum(), 2.0)
    scalar = pg.traction(fem.Basis(square, fem.ElementQuad1()), right, 3.0)
    assert np.isclose(scalar.sum(), 3.0)
