"""scikit-fem's own assembly on family bases: Petrov–Galerkin is never
assembled silently wrong, and the package's form decorators give the fast
path to scripts that only swap the basis (scikit-fem's ex43)."""
import warnings

import numpy as np
import pytest
import skfem as fem
from skfem.helpers import (ddot, det, eye, grad, identity, inv, mul,
                           sym_grad, trace, transpose)

import skfem_pg as pg
from skfem_pg.discretization.basis import form_roles


def _stiffness(u, v, w):
    e = sym_grad(u)
    return ddot(2 * 40.0 * e + 100.0 * eye(trace(e), 2), sym_grad(v))


def _internal(v, w):
    return ddot(w["P"], grad(v))


@pytest.fixture(scope="module")
def cantilever():
    mesh = fem.MeshQuad.init_tensor(np.linspace(0, 48, 13),
                                    np.linspace(0, 4, 3))
    return mesh, pg.FamilyBasis(mesh, dim=2, method="PPG1")


def test_plain_scikit_fem_calls_on_ppg_raise(cantilever):
    _, b = cantilever
    K = fem.BilinearForm(_stiffness)
    f = fem.LinearForm(_internal)
    P = b.interpolate(np.linspace(0, 1, b.N)).grad
    for call in (lambda: K.assemble(b), lambda: K.assemble(b.test),
                 lambda: K.assemble(b.test, b),
                 lambda: f.assemble(b, P=P),
                 lambda: fem.Functional(lambda w: w.x[0]).assemble(b),
                 lambda: b.test.interpolate(np.zeros(b.N))):
        with pytest.raises(ValueError, match="Petrov"):
            call()


def test_ppg_generic_with_test_basis_equals_fast_path(cantilever):
    """scikit-fem's generic path with the roles the package's forms vouch
    for equals the batched path; scikit-fem's forms alone are refused even
    in the right order (they do not say which basis tests), and so is the
    package's assemble with the trial basis as test basis."""
    _, b = cantilever
    K = fem.BilinearForm(_stiffness)
    with pytest.raises(ValueError, match="Petrov"):
        K.assemble(b, b.test)
    with form_roles(K, b, b.test):
        Kg = K.assemble(b, b.test)
    Kf = pg.assemble(K, b)
    Kd = pg.BilinearForm(_stiffness).assemble(b)
    assert abs(Kg - Kf).max() < 1e-12 * abs(Kf).max()
    assert abs(Kd - Kf).max() == 0.0
    P = b.interpolate(np.sin(np.arange(b.N))).grad
    f = fem.LinearForm(_internal)
    with pytest.raises(ValueError, match="Petrov"):
        f.assemble(b.test, P=P)
    with form_roles(f, b, b.test):
        fg = f.assemble(b.test, P=P)
    ff = pg.assemble(f, b, P=P)
    fd = pg.LinearForm(_internal).assemble(b, P=P)
    assert np.abs(fg - ff).max() < 1e-12 * np.abs(ff).max()
    assert np.abs(fd - ff).max() == 0.0
    for call in (lambda: pg.assemble(K, b, b), lambda: pg.assemble(K, b.test),
                 lambda: pg.assemble(f, b, b, P=P),
                 lambda: pg.assemble(fem.Functional(lambda w: w.x[0]), b)):
        with pytest.raises(ValueError, match="Petrov"):
            call()
    # what the refused pairing would give: Bubnov–Galerkin with PPG weights
    with form_roles(K, b, b.test):
        Kbg = K.assemble(b, b)
    assert abs(Kbg - Kf).max() > 1e-2 * abs(Kf).max()


def test_plain_scikit_fem_forms_on_pbg_warn_slow_once_per_assembly():
    b = pg.FamilyBasis(fem.MeshTri().refined(2))
    K = fem.BilinearForm(lambda u, v, w: u * v)
    for _ in range(2):
        with pytest.warns(pg.SlowAssemblyWarning) as record:
            K.assemble(b)
        assert len(record) == 1
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        pg.BilinearForm(lambda u, v, w: u * v).assemble(b)
        area = fem.Functional(lambda w: 1.0 + 0 * w.x[0]).assemble(b)
    assert area == pytest.approx(1.0, rel=1e-12)


def test_ppg_cantilever_through_package_forms():
    """The README's cantilever as PPG: 3.21 through the package's forms
    (Q1 on the same nodes 3.25); the Bubnov–Galerkin matrix with PPG
    weights that ``form.assemble(basis)`` used to build gave 0.388."""
    mesh = fem.MeshQuad.init_tensor(np.linspace(0, 48, 25),
                                    np.linspace(0, 44, 23))
    b = pg.FamilyBasis(mesh, dim=2, method="PPG1")
    f = pg.traction(b, mesh.facets_satisfying(lambda x: x[0] == 48),
                    [0.0, 1.0])
    D = b.get_dofs(mesh.facets_satisfying(lambda x: x[0] == 0))
    tips = []
    K = fem.BilinearForm(_stiffness)
    with form_roles(K, b, b.test):  # the pairing the package refuses
        Kbg = K.assemble(b, b)
    for K in (pg.BilinearForm(_stiffness).assemble(b),
              pg.assemble(fem.BilinearForm(_stiffness), b), Kbg):
        tips.append(fem.solve(*fem.condense(K, f, D=D))[1::2].max())
    assert abs(tips[0] - 3.2107) < 1e-3
    assert tips[1] == pytest.approx(tips[0], rel=1e-10)
    assert tips[2] < 0.5  # the silently wrong Bubnov–Galerkin variant


def test_hessian_form_falls_back_to_generic():
    mesh = fem.MeshTri().refined(2)
    basis = fem.Basis(mesh, fem.ElementTriMorley())

    def biharmonic(u, v, w):
        return ddot(u.hess, v.hess)
    K1 = pg.BilinearForm(biharmonic).assemble(basis)
    K2 = fem.BilinearForm(biharmonic).assemble(basis)
    assert abs(K1 - K2).max() == 0.0


MU, LMBDA = 1.0, 2.0


def _deformation_gradient(w):
    dudX = grad(w["displacement"])
    F = dudX + identity(dudX)
    return F, inv(F)


def _ex43_L(v, w):
    F, iF = _deformation_gradient(w)
    dF = grad(v)
    lnJ = np.log(det(F))
    return MU * ddot(F, dF) + (LMBDA * lnJ - MU) * ddot(transpose(iF), dF)


def _ex43_a(u, v, w):
    F, iF = _deformation_gradient(w)
    DF, dF = grad(u), grad(v)
    dFiF, DFiF = mul(dF, iF), mul(DF, iF)
    lnJ = np.log(det(F))
    return (MU * ddot(DF, dF) - (LMBDA * lnJ - MU)
            * ddot(transpose(dFiF), DFiF)
            + LMBDA * trace(dFiF) * trace(DFiF))


def _ex43(basis, L, a, nsteps=7, right=-0.1, tol=1e-10):
    """scikit-fem's docs/examples/ex43.py (hyperelastic twist of a hex
    beam), its Newton loop verbatim."""
    u = basis.zeros()
    uv = basis.interpolate(u)
    dofs = basis.get_dofs('right')
    dirichlet = basis.get_dofs({'right', 'left'})
    f = L.assemble(basis, displacement=uv)
    K = a.assemble(basis, displacement=uv)
    iterations = []
    for step in range(nsteps):
        for iteration in range(10):
            c = (step + 1.) / nsteps
            du_D = u.copy()
            x, y, z = basis.doflocs[:, dofs.nodal['u^1']]
            du_D[dofs.nodal['u^1']] = c * right - du_D[dofs.nodal['u^1']]
            du_D[dofs.nodal['u^2']] = (
                y * np.cos(c * np.pi) - z * np.sin(c * np.pi) - y
                - du_D[dofs.nodal['u^2']])
            du_D[dofs.nodal['u^3']] = (
                y * np.sin(c * np.pi) + z * np.cos(c * np.pi) - z
                - du_D[dofs.nodal['u^3']])
            du = fem.solve(*fem.condense(K, -f, x=du_D, D=dirichlet))
            norm_du = np.linalg.norm(du)
            u += du
            uv = basis.interpolate(u)
            f = L.assemble(basis, displacement=uv)
            K = a.assemble(basis, displacement=uv)
            if norm_du < tol:
                break
        iterations.append(iteration + 1)
    return u, iterations


@pytest.fixture(scope="module")
def ex43_mesh():
    return fem.MeshHex.init_tensor(
        np.linspace(0, 1, 10), np.linspace(-.1, .1, 3),
        np.linspace(-.1, .1, 3)).with_boundaries({
            'left': lambda x: x[0] == 0., 'right': lambda x: x[0] == 1.})


@pytest.mark.slow
def test_ex43_with_family_basis(ex43_mesh):
    """ex43 with ``Basis`` swapped for ``FamilyBasis`` and the forms
    imported from skfem_pg: u.max 0.25391 (FE H1: 0.24666), every load
    step converges to 1e-10 within 10 Newton iterations."""
    fe = fem.Basis(ex43_mesh, fem.ElementVector(fem.ElementHex1()),
                   intorder=1)
    u_fe, it_fe = _ex43(fe, fem.LinearForm(_ex43_L),
                        fem.BilinearForm(_ex43_a))
    basis = pg.FamilyBasis(ex43_mesh, dim=3)
    u, it = _ex43(basis, pg.LinearForm(_ex43_L), pg.BilinearForm(_ex43_a))
    assert abs(u_fe.max() - 0.24666) < 1e-4
    assert abs(u.max() - 0.25391) < 1e-4
    assert max(it) < 10 and max(it_fe) < 10
    assert abs(sum(it) - sum(it_fe)) <= 3  # measured 47 vs 49


def test_ex43_generic_assembly_equals_fast_path(ex43_mesh):
    basis = pg.FamilyBasis(ex43_mesh, dim=3)
    x = basis.doflocs
    u = 0.05 * np.sin(3 * x[0]) * (x[1] + 2 * x[2])
    uv = basis.interpolate(u)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pg.SlowAssemblyWarning)
        Kg = fem.BilinearForm(_ex43_a).assemble(basis, displacement=uv)
    Kf = pg.BilinearForm(_ex43_a).assemble(basis, displacement=uv)
    assert abs(Kg - Kf).max() < 1e-12 * abs(Kf).max()
