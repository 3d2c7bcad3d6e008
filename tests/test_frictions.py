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
        pg.Scene("s", square, materials.NeoHooke(lam=1.0, mu=1.0),
                 clamped=["left"], tractions={"right": [0.0, 1.0]})
    named = square.with_boundaries({"left": lambda x: x[0] == 0})
    with pytest.raises(ValueError, match=r"'right'.*the mesh has 'left'"):
        pg.Scene("s", named, materials.NeoHooke(lam=1.0, mu=1.0),
                 clamped=["left"], tractions={"right": [0.0, 1.0]})


def test_result_prints_one_line(square):
    mesh = square.with_boundaries({"left": lambda x: x[0] == 0,
                                   "right": lambda x: x[0] == 1})
    r = pg.Scene("s", mesh, materials.NeoHooke(lam=1.0, mu=1.0), clamped=["left"],
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


def test_with_element_says_what_to_do(square):
    b = pg.FamilyBasis(square, dim=2)
    with pytest.raises(NotImplementedError, match="particle_fields"):
        b.with_element(fem.ElementDG(fem.ElementQuad1()))


def test_fe_quadrature_data_in_a_pg_form_is_named(square):
    """Data at an FE basis' quadrature points, or a dof vector of another
    element, handed to a PG form: a message naming the coefficient and
    what to pass instead (was scikit-fem's "Quadrature mismatch" or
    "Input array has wrong size")."""
    from skfem.helpers import dot, grad

    @pg.BilinearForm
    def weighted(u, v, w):
        return w.k * dot(grad(u), grad(v))

    b = pg.FamilyBasis(square)
    fe = fem.Basis(square, fem.ElementQuad1())
    k_fe = fe.interpolate(np.ones(fe.N))  # at FE quadrature points
    with pytest.raises(ValueError, match="'k'.*family members.*w.x"):
        weighted.assemble(b, k=k_fe)
    q2 = fem.Basis(square, fem.ElementQuad2())
    with pytest.raises(ValueError, match="'k' has 81 entries.*probes"):
        weighted.assemble(b, k=np.ones(q2.N))
    # what works: a dof vector of this basis, or its interpolation
    K1 = weighted.assemble(b, k=np.ones(b.N))
    K2 = weighted.assemble(b, k=b.interpolate(np.ones(b.N)))
    assert abs(K1 - K2).max() < 1e-12


def test_a_scalar_coefficient_is_evaluated_at_every_family():
    """A scalar dof vector as form coefficient is the particle values at
    each family's members: the same matrix as the coefficient written as
    a function of ``w.x``.  (The scalar ``interpolate`` returned the first
    family's values for every family, shape ``(m,)`` instead of ``(nf,
    m)``, which broadcast silently.)"""
    from skfem.helpers import dot, grad
    mesh = pg.meshing.distort(fem.MeshQuad.init_tensor(
        *(np.linspace(0, 1, 7),) * 2), 0.2, seed=1)
    b = pg.FamilyBasis(mesh)

    @pg.BilinearForm
    def by_values(u, v, w):
        return w.k * dot(grad(u), grad(v))

    @pg.BilinearForm
    def by_position(u, v, w):
        return (1.0 + w.x[0] * w.x[1]) * dot(grad(u), grad(v))

    k = 1.0 + b.particles.x[0] * b.particles.x[1]
    assert np.asarray(b.interpolate(k)).shape == b.dx.shape
    A, B = by_values.assemble(b, k=k), by_position.assemble(b)
    assert abs(A - B).max() <= 1e-12 * abs(B).max()


def test_one_verbosity_convention(square, capsys, monkeypatch):
    """``verbose`` is True, False or "auto" in newton, the integrators and
    Scene.solve; "auto" (the default) is silent for a quick run and prints
    from AUTO_SECONDS on."""
    from skfem_pg import progress
    from skfem_pg.formulations import Hyperelastic
    mesh = square.with_boundaries({"left": lambda x: x[0] == 0,
                                   "right": lambda x: x[0] == 1})
    b = pg.FamilyBasis(mesh, dim=2)
    model = Hyperelastic(b, materials.NeoHooke(lam=1.0, mu=1.0))
    f = pg.traction(b, "right", [0.0, 0.01])
    pg.newton(model, f, D=b.get_dofs("left"))
    pg.newmark(model, pg.lumped_mass(b, 1.0), 0.2, 0.1, f_ext=f,
               D=b.get_dofs("left"))
    assert capsys.readouterr().out == ""  # quick: silent by default
    monkeypatch.setattr(progress, "AUTO_SECONDS", 0.0)
    pg.newton(model, f, D=b.get_dofs("left"), steps=2)
    assert capsys.readouterr().out.count("load ") == 2
    pg.Scene("s", mesh, materials.NeoHooke(lam=1.0, mu=1.0), clamped=["left"],
             tractions={"right": [0.0, 0.01]}).solve("VCBCPBG V5m Unl")
    assert "load 1.0000" in capsys.readouterr().out
    with pytest.raises(ValueError, match="verbose must be True, False or "
                       "'auto'"):
        pg.newton(model, f, D=b.get_dofs("left"), verbose="loud")
