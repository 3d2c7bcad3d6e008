"""Ordinary mistakes raise with a message instead of a plausible wrong
number: moduli, load shapes, Dirichlet dofs, form dimensions."""
import numpy as np
import pytest
import skfem as fem

import skfem_pg as pg
from skfem_pg import materials as mat
from skfem_pg.formulations import Hyperelastic
from skfem_pg.materials import lame
from skfem_pg.formulations import linear_elasticity


@pytest.mark.parametrize("E, nu, match", [
    (-1.0, 0.3, "Young"), (0.0, 0.3, "Young"), (1.0, 0.5, "incompressible"),
    (1.0, 0.7, r"\(-1, 0.5\)"), (1.0, -1.0, r"\(-1, 0.5\)"),
    (np.nan, 0.3, "finite"), ("a", 0.3, "number")])
def test_lame_rejects_non_physical_constants(E, nu, match):
    with pytest.raises(ValueError, match=match):
        lame(E, nu)


@pytest.mark.parametrize("make, match", [
    (lambda: mat.NeoHooke(lam=1.0, mu=-2.0), "shear"),
    (lambda: mat.NeoHooke(lam=-1.0, mu=1.0), "bulk"),
    (lambda: mat.StVenantKirchhoff(lam=1.0, mu=0.0), "shear"),
    (lambda: mat.LinearElastic(lam=np.inf, mu=1.0), "finite"),
    (lambda: mat.NeoHookeIsoVol(mu=1.0, K=0.0), "bulk modulus K"),
    (lambda: mat.NeoHookeIsoVol(mu=-1.0, K=1.0), "shear"),
    (lambda: linear_elasticity(1.0, -1.0), "shear")])
def test_materials_reject_non_physical_constants(make, match):
    with pytest.raises(ValueError, match=match):
        make()


@pytest.fixture(scope="module")
def square():
    mesh = fem.MeshQuad.init_tensor(np.linspace(0, 1, 5),
                                    np.linspace(0, 1, 5))
    return mesh, pg.FamilyBasis(mesh, dim=2)


def test_loads_reject_wrong_shapes(square):
    mesh, b = square
    right = mesh.facets_satisfying(lambda x: x[0] == 1)
    with pytest.raises(ValueError, match="2 components"):
        pg.traction(b, right, [0.0, 1.0, 0.0])  # was silently dropped
    with pytest.raises(ValueError, match=r"\(2, 2\)"):
        pg.stress_load(b, right, np.ones((1, 2)))
    with pytest.raises(ValueError, match="length 2"):
        pg.body_force(b, [1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="shape"):
        pg.body_force(b, lambda x: x[:1])
    # scikit-fem bases: the consistent load (it used to refuse them)
    area = float(pg.body_force(fem.Basis(mesh, fem.ElementQuad1()),
                               1.0).sum())
    assert area == pytest.approx(1.0, rel=1e-12)
    fe = fem.Basis(mesh, fem.ElementVector(fem.ElementQuad1()))
    with pytest.raises(ValueError, match="2 components"):
        pg.body_force(fe, [1.0, 2.0, 3.0])
    fx = pg.body_force(fe, lambda x: np.array([x[0], 0 * x[0]]), rho=3.0)
    assert fx[fe.nodal_dofs[0]].sum() == pytest.approx(1.5, rel=1e-12)
    f = pg.traction(b, right, [0.0, 1.0])
    assert f.shape == (b.N,) and f[1::2].sum() == pytest.approx(1.0)
    assert pg.body_force(b, [0.0, 2.0])[1::2].sum() == pytest.approx(2.0)


@pytest.mark.parametrize("D, match", [
    (np.array([0, 1, -1]), "negative"), (np.array([0, 10 ** 6]), "0..49"),
    (np.ones(50, dtype=bool), "boolean"), (np.array([0.5, 1.0]), "integer")])
def test_newton_rejects_bad_dirichlet_dofs(square, D, match):
    _, b = square
    model = Hyperelastic(b, mat.NeoHooke(lam=1.0, mu=1.0))
    with pytest.raises(ValueError, match=match):
        pg.solvers.newton(model, D=D, verbose=False)


def test_newton_rejects_wrong_length_vectors(square):
    _, b = square
    model = Hyperelastic(b, mat.NeoHooke(lam=1.0, mu=1.0))
    with pytest.raises(ValueError, match="f_ext"):
        pg.solvers.newton(model, f_ext=np.zeros(b.N + 1), verbose=False)


def test_form_dimension_must_match_the_basis(square):
    mesh, _ = square
    scalar = pg.FamilyBasis(mesh)  # dim=None
    with pytest.raises(ValueError, match="dim="):
        pg.assemble(linear_elasticity(1.0, 1.0), scalar)

    @fem.BilinearForm
    def laplace(u, v, w):
        return u.grad[0] * v.grad[0] + u.grad[1] * v.grad[1]
    with pytest.raises(ValueError, match="scalar"):
        pg.assemble(laplace, pg.FamilyBasis(mesh, dim=2))
    assert pg.assemble(laplace, scalar).shape == (25, 25)


def test_scikit_fem_idioms_on_a_family_basis(square):
    import matplotlib
    matplotlib.use("Agg")
    mesh, b = square
    lin = lambda x: np.array([x[0] + 2 * x[1], 3 * x[0] - x[1]])  # noqa
    u = b.project(lin)
    assert np.allclose(u.reshape(-1, 2).T, lin(mesh.p))
    x = np.array([[0.3, 0.71], [0.4, 0.13]])
    # the collocation mesh's Q1 interpolant: exact for linear fields,
    # like scikit-fem's own probes on the same mesh
    fe = fem.Basis(mesh, fem.ElementVector(fem.ElementQuad1()))
    assert np.allclose(b.probes(x) @ u, fe.probes(x) @ fe.project(lin))
    assert np.allclose(b.probes(x) @ u, lin(x).ravel())
    scalar = pg.FamilyBasis(mesh)
    z = scalar.project(lambda x: x[0])
    assert scalar.plot(z) is not None and scalar.draw() is not None
    with pytest.raises(ValueError, match="component"):
        b.plot(u)
    with pytest.raises(NotImplementedError, match="particle_fields"):
        b.project(b.interpolate(u))
    cloud = pg.Particles(mesh.p, np.full(mesh.nvertices, 1 / 16))
    pb = pg.FamilyBasis(cloud, dim=2, vc=None)
    with pytest.raises(NotImplementedError, match="particle_fields"):
        pb.probes(x)


def test_get_dofs_of_point_particles_checks_indices():
    mesh = fem.MeshQuad.init_tensor(np.linspace(0, 1, 3),
                                    np.linspace(0, 1, 3))
    cloud = pg.Particles(mesh.p, np.full(mesh.nvertices, 1 / 9))
    b = pg.FamilyBasis(cloud, dim=2, vc=None)
    assert list(b.get_dofs(nodes=[0, 8])) == [0, 1, 16, 17]
    for bad in ([-1], [9], [0.5]):
        with pytest.raises(ValueError, match="particle indices"):
            b.get_dofs(nodes=bad)
