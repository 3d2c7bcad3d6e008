"""Ten more of scikit-fem's gallery problems with the basis swapped, each
with its class (issue 50): the problem of ``docs/examples/exNN.py``
(same geometry, boundary conditions and load; written here), solved with
the example's linear element and with a :class:`~skfem_pg.FamilyBasis` on
the same nodes, both against an exact solution or an overkill whose own
error is stated.  The classes, tabled in ``docs/guide/accuracy.md``:

- *runs*: the example's code with the basis swapped gives an answer
  within the stated error;
- *runs after the message*: a named error or warning says what to change;
- *refused*: a named error says why PG cannot pose the problem;
- *flagged*: a warning names the way that works;
- *wrong*: a silent wrong answer (none found among these).
"""
import os
import sys
import warnings

import numpy as np
import pytest
import skfem as fem
from scipy.sparse.linalg import splu
from skfem.helpers import dot, grad
from skfem.models.poisson import laplace, mass, unit_load

import skfem_pg as pg


def p1_and_pg(mesh):
    """The example's linear element and the keyword-default PG basis on
    the same nodes."""
    element = {fem.MeshTri: fem.ElementTriP1(),
               fem.MeshQuad: fem.ElementQuad1()}[type(mesh)]
    return fem.Basis(mesh, element), pg.FamilyBasis(mesh)


def test_ex02_plate_bending_is_refused_by_name():
    """ex02, the Kirchhoff plate: its form reads ``dd(u)``.  A particle
    basis (the family basis and the blended PG2) carries first derivatives
    only; both assembly routes name that (until now numpy's "einstein sum
    subscripts" came out of the generic route, after the fast route's
    message had pointed to it).  Class: refused."""
    from skfem.helpers import dd, ddot
    mesh = fem.MeshTri.init_sqsymmetric().refined(2)

    @fem.BilinearForm
    def bilinf(u, v, w):
        return ddot(dd(u), dd(v))

    for basis in (pg.FamilyBasis(mesh), pg.FamilyBasis(mesh, order=2)):
        for assemble in (
                lambda: pg.assemble(bilinf, basis),
                lambda: pg.BilinearForm(bilinf.form).assemble(basis),
                lambda: bilinf.assemble(basis)):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", pg.SlowAssemblyWarning)
                with pytest.raises(pg.SecondDerivativeError, match=(
                        "dd\\(u\\).*first derivatives only.*Morley")):
                    assemble()
        # a form with first derivatives still assembles on the same basis
        assert pg.assemble(laplace, basis).shape == (basis.N, basis.N)


@fem.BilinearForm
def minimal_surface_jacobian(u, v, w):
    p = w["prev"]
    s = 1 + dot(grad(p), grad(p))
    return (dot(grad(u), grad(v)) / np.sqrt(s)
            - dot(grad(u), grad(p)) * dot(grad(p), grad(v)) / s ** 1.5)


@fem.LinearForm
def minimal_surface_residual(v, w):
    p = w["prev"]
    return dot(grad(p), grad(v)) / np.sqrt(1 + dot(grad(p), grad(p)))


#: u(1/2, 1/2) and u(1/4, 1/2): P1 on 32², 64², 128² cells extrapolated
#: (Richardson, ratio of differences 3.75; its correction 1.1e-4)
MINIMAL_SURFACE = np.array([0.273898, 0.202845])


def test_ex10_minimal_surface_by_newton():
    """ex10, the minimal surface over the unit square with u = sin(πx) on
    the boundary, by the example's damped Newton (factor 0.7) with
    scikit-fem's forms on 33² nodes: P1 +0.62 / +0.65 %, PG +0.50 /
    +0.53 % at the two probes, in 19 and 18 iterations.  Class: runs."""
    mesh = fem.MeshTri().refined(5)
    probes = fem.Basis(mesh, fem.ElementTriP1()).probes(
        np.array([[0.5, 0.25], [0.5, 0.5]]))
    errors = []
    for basis in p1_and_pg(mesh):
        x = basis.zeros()
        D = mesh.boundary_nodes()
        x[D] = np.sin(np.pi * mesh.p[0, D])
        for iteration in range(100):
            w = basis.interpolate(x)
            J = pg.assemble(minimal_surface_jacobian, basis, prev=w)
            F = pg.assemble(minimal_surface_residual, basis, prev=w)
            step = 0.7 * fem.solve(*fem.condense(J, -F, D=D))
            x += step
            if np.linalg.norm(step) < 1e-8:
                break
        assert iteration < 25
        errors.append(probes @ x / MINIMAL_SURFACE - 1)
    fe, family = errors
    assert np.all((0 < fe) & (fe < 0.007))
    assert np.all((0 < family) & (family < fe))


#: the polygon of MeshTri.init_circle(4): area, k = ∫u / A², k' = u(0) / A
#: (P2 on it refined three times; from twice 7e-8 / 7e-8)
K_FACTORS = np.array([3.136548490545945, 0.03978729, 0.07957601])


def test_ex12_boussinesq_k_factors_by_functionals():
    """ex12, Poisson's equation on the disc's polygon and its
    post-processing by linear forms: the area as the sum of the unit
    load vector (exact on both: PG's volume weights tile the cells), the
    k-factor ∫u / A² and k' = u(0) / A by a probe.  Measured on 545
    nodes: P1 −0.14 / −0.20 %, PG −0.73 / +0.59 % (its mean below, its
    peak above: the soft Laplacian and the lumped load).  Class: runs."""
    mesh = fem.MeshTri.init_circle(4)
    errors = []
    for basis in p1_and_pg(mesh):
        b = pg.assemble(unit_load, basis)
        x = fem.solve(*fem.condense(pg.assemble(laplace, basis), b,
                                    D=basis.get_dofs()))
        area = b.sum()
        k = b @ x / area ** 2
        k1 = (basis.probes(np.zeros((2, 1))) @ x)[0] / area
        assert abs(area / K_FACTORS[0] - 1) < 1e-13
        errors.append(np.array([k, k1]) / K_FACTORS[1:] - 1)
    fe, family = errors
    assert np.all((-0.003 < fe) & (fe < 0))
    assert -0.01 < family[0] < 0 < family[1] < 0.01


def test_ex14_inhomogeneous_dirichlet_data():
    """ex14, Laplace's equation with the harmonic x² − y² as Dirichlet
    data, set through ``basis.project`` and ``condense(x=...)``: the
    Dirichlet energy against 8/3 on 17² nodes, P1 −0.098 %, PG −0.38 %;
    the largest nodal error P1 8e-16 (this mesh's P1 is nodally exact
    for a quadratic harmonic), PG 1.5e-3 (its families see the curvature
    of the data).  Class: runs."""
    mesh = fem.MeshTri().refined(4)
    exact = mesh.p[0] ** 2 - mesh.p[1] ** 2
    out = []
    for basis in p1_and_pg(mesh):
        A = pg.assemble(laplace, basis)
        u = basis.project(lambda x: ((x[0] + 1j * x[1]) ** 2).real)
        u = fem.solve(*fem.condense(A, x=u, D=basis.get_dofs()))
        out.append((u @ A @ u / (8 / 3) - 1, np.abs(u - exact).max()))
    (fe_energy, fe_nodal), (pg_energy, pg_nodal) = out
    assert -0.0015 < fe_energy < 0 and fe_nodal < 1e-12
    assert -0.005 < pg_energy < fe_energy and pg_nodal < 0.002


@pytest.mark.parametrize("example, mesh", [
    ("ex15", lambda: fem.MeshLine(np.linspace(0, 1, 11))),
    ("ex16", lambda: fem.MeshLine(np.linspace(-1, 1, 50))),
    ("ex42", lambda: fem.MeshTri1DG.init_tensor(
        np.linspace(0, 1, 10), np.linspace(0, 1, 10), periodic=[0])),
])
def test_one_dimensional_and_periodic_meshes_are_refused(example, mesh):
    """ex15 / ex16 (1-D Poisson, Legendre's equation) and ex42 (a
    periodic mesh, MeshTri1DG): particles are collocated from the linear
    2-D and 3-D meshes only; the refusal names the mesh type and those
    that work.  Class: refused."""
    with pytest.raises(pg.UnsupportedMeshError, match="MeshTri1, MeshQuad1"):
        pg.FamilyBasis(mesh())


def test_ex19_heat_equation_by_crank_nicolson():
    """ex19, the heat equation in the rectangle [−2, 2] × [−3, 3], its
    slowest mode cos(πx/4) cos(πy/6) as the initial value, Crank–Nicolson
    (dt = 0.01, 50 steps) with the Dirichlet rows penalized: the centre
    value at t = 0.5 against the exact decay on 16² nodes, Q1 −1.9 %,
    PG +3.9 % (PG's Laplacian is soft on a coarse grid, and its mass
    lumped at the particles).  Class: runs."""
    half = np.array([2.0, 3.0])
    mesh = fem.MeshQuad.init_tensor(np.linspace(-1, 1, 16) * half[0],
                                    np.linspace(-1, 1, 16) * half[1])
    dt, steps, diffusivity = 0.01, 50, 5.0
    exact = np.exp(-diffusivity * np.pi ** 2 * dt * steps / 4
                   * (half ** -2).sum())
    errors = []
    for basis in p1_and_pg(mesh):
        L = diffusivity * pg.assemble(laplace, basis)
        M = pg.assemble(mass, basis)
        L0, M0 = fem.penalize(L, M, D=basis.get_dofs())
        backsolve = splu((M0 + 0.5 * dt * L0).T.tocsc()).solve
        B = M0 - 0.5 * dt * L0
        u = np.cos(np.pi * basis.doflocs / 2 / half[:, None]).prod(0)
        for _ in range(steps):
            u = backsolve(B @ u)
        errors.append((basis.probes(np.zeros((2, 1))) @ u)[0] / exact - 1)
    fe, family = errors
    assert -0.025 < fe < 0 and 0 < family < 0.05


#: the temperature at (5, 1/4) and (9.9, 1/4): Q2 on the mesh refined
#: twice (from once 3e-7)
GRAETZ = np.array([0.43507566, 0.61239307])


def test_ex25_graetz_problem_with_a_nonsymmetric_form():
    """ex25, forced convection in a channel (plane Poiseuille flow, Péclet
    100): a non-symmetric advection form beside the Laplacian, on the
    example's 320 × 32 nodes.  The temperature at two probes downstream:
    Q1 +0.038 / +0.020 %, PG −0.25 / −0.10 %.  Class: runs."""
    mesh = fem.MeshQuad.init_tensor(np.linspace(0, 10, 320),
                                    np.linspace(0, 0.5, 32)).with_boundaries(
        {"inlet": lambda x: x[0] == 0.0, "floor": lambda x: x[1] == 0.0})

    @fem.BilinearForm
    def advection(u, v, w):
        y = w.x[1]
        return v * 6 * y * (1 - y) * grad(u)[0]

    probes = fem.Basis(mesh, fem.ElementQuad1()).probes(
        np.array([[5.0, 9.9], [0.25, 0.25]]))
    errors = []
    for basis in p1_and_pg(mesh):
        A = pg.assemble(laplace, basis) + 100 * pg.assemble(advection, basis)
        t = basis.zeros()
        t[basis.get_dofs("floor")] = 1.0
        t = fem.solve(*fem.condense(A, x=t, I=basis.complement_dofs(
            basis.get_dofs({"inlet", "floor"}))))
        errors.append(probes @ t / GRAETZ - 1)
    fe, family = errors
    assert np.all((0 < fe) & (fe < 0.001))
    assert np.all((-0.004 < family) & (family < 0))


#: the four lowest Dirichlet eigenvalues of MeshTri.init_circle(4)'s
#: polygon (P2 on it refined three times; from twice 5e-6 / 1.4e-5)
POLYGON_EIGENVALUES = np.array([5.79259425, 14.70585558, 14.70585558,
                                26.41752263])


def test_ex31_laplace_eigenvalues_on_a_polygon():
    """ex31's eigenvalue problem (there on curved elements) on the
    disc's polygon, 545 nodes: the four lowest eigenvalues, P1 +0.17 /
    +0.60 / +0.60 / +1.0 %, PG −0.73 / −1.36 / −1.36 / −3.3 % (below, as
    PG's soft bending; the polygon's, not the disc's: 5.783 is the
    disc's first).  Class: runs."""
    mesh = fem.MeshTri.init_circle(4)
    errors = []
    for basis in p1_and_pg(mesh):
        lam, _ = fem.solve(*fem.condense(
            pg.assemble(laplace, basis), pg.assemble(mass, basis),
            D=basis.get_dofs()), solver=fem.solver_eigen_scipy_sym(k=4))
        errors.append(lam / POLYGON_EIGENVALUES - 1)
    fe, family = errors
    assert np.all((0 < fe) & (fe < 0.012))
    assert np.all((-0.04 < family) & (family < 0))


def greens(a, s, x):
    """The Green's function of the disc of radius ``a``, source at
    ``s``."""
    sn = np.linalg.norm(s)
    return np.log(np.linalg.norm(sn ** 2 * x - a ** 2 * s[:, None], axis=0)
                  / (a * sn * np.linalg.norm(x - s[:, None], axis=0))) \
        / 2 / np.pi


def test_ex38_point_source_by_the_basis_point_source():
    """ex38, a point source in the disc: ``basis.point_source`` (PG: the
    values at the source of the interpolant its probes use; they sum to
    1) against the
    Green's function of the disc, at the nodes more than 0.3 from the
    source, on 2,113 nodes: largest error P1 6.0e-4, PG 5.5e-4 (of a
    largest value 0.187 there).  Class: runs."""
    mesh = fem.MeshTri.init_circle(5)
    source = np.array([0.3, 0.2])
    far = np.linalg.norm(mesh.p - source[:, None], axis=0) > 0.3
    exact = greens(np.linalg.norm(mesh.p, axis=0).max(), source, mesh.p)
    errors = []
    for basis in p1_and_pg(mesh):
        b = basis.point_source(source)
        assert abs(b.sum() - 1) < 1e-13
        x = fem.solve(*fem.condense(pg.assemble(laplace, basis), b,
                                    D=basis.get_dofs()))
        errors.append(np.abs(x - exact)[far].max())
    fe, family = errors
    assert fe < 7e-4 and family < fe


ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir)
TABLE = os.path.join(ROOT, "docs", "guide", "accuracy.md")


@pytest.mark.skipif(not os.path.isfile(TABLE), reason="docs/ not here")
def test_the_gallery_table_names_every_gallery_test():
    """The class table in ``docs/guide/accuracy.md`` and the gallery tests
    cannot drift apart: every test it names exists, and every gallery
    test whose docstring names an example is in it."""
    import re
    import test_gallery
    text = open(TABLE).read()
    named = set(re.findall(r"`(test_\w+)`", text))
    tests = {name: getattr(module, name).__doc__ or ""
             for module in (test_gallery, sys.modules[__name__])
             for name in dir(module) if name.startswith("test_")}
    assert named and named <= set(tests), named - set(tests)
    posed = {name for name, doc in tests.items()
             if re.search(r"\bex\d\d", doc)}
    assert posed <= named, posed - named
