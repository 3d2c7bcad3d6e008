"""scikit-fem's gallery problems with the basis swapped (issue 30).

Each test poses a problem of scikit-fem's ``docs/examples`` (same kind of
geometry, boundary conditions and load; written here), solves it with a
scikit-fem element and with a :class:`~skfem_pg.FamilyBasis` on the same
nodes the way a user would (the library's own forms from
``skfem.models``, ``pg.assemble``), and compares both with an exact
solution or a quadratic-element overkill.  The numbers in the docstrings
are the measured ones; where PG does not come within FE's discretization
error the test says so with ``xfail(strict=True)``, so that a fix shows.
"""
import warnings

import numpy as np
import pytest
import scipy.sparse as sp
import skfem as fem
from scipy.sparse.linalg import eigsh
from skfem.helpers import dot
from skfem.models.elasticity import linear_elasticity
from skfem.models.poisson import laplace, unit_load

import skfem_pg as pg


def cube_poisson(x, terms=31):
    """The triple sine series of -Δu = 1 in the unit cube, u = 0 on its
    boundary."""
    k = np.arange(1, 2 * terms, 2)
    a, b, c = np.meshgrid(k, k, k, indexing="ij")
    coef = 64 / np.pi ** 5 / (a * b * c * (a ** 2 + b ** 2 + c ** 2))
    s = [np.sin(np.pi * np.outer(k, xi)) for xi in x]
    return np.einsum("abc,ai,bi,ci->i", coef, *s)


def poisson(basis):
    K, f = pg.assemble(laplace, basis), pg.assemble(unit_load, basis)
    return fem.solve(*fem.condense(K, f, D=basis.get_dofs()))


def test_library_forms_take_the_fast_path_with_pg_assemble():
    """``skfem.models`` forms carry scikit-fem's decorator, so
    ``laplace.assemble(basis)`` takes the generic path on a FamilyBasis
    (a SlowAssemblyWarning says so); ``pg.assemble(laplace, basis)`` is
    the one call that takes the fast path, with the same matrix."""
    mesh = fem.MeshTri.init_sqsymmetric().refined(2)
    basis = pg.FamilyBasis(mesh)
    with pytest.warns(pg.SlowAssemblyWarning, match="pg.assemble|"
                      "skfem_pg.assemble"):
        generic = laplace.assemble(basis)
    fast = pg.assemble(laplace, basis)
    assert abs(generic - fast).max() <= 1e-12 * abs(fast).max()


def cube(n, cells):
    mesh = fem.MeshHex.init_tensor(*(np.linspace(0, 1, n + 1),) * 3)
    return mesh if cells == "hex" else mesh.to_meshtet()


def cube_errors(cells, n):
    """``(PG, FE)`` errors of the centre value and the largest nodal
    errors, relative to the exact centre value."""
    mesh = cube(n, cells)
    centre = pg.meshing.vertex_at(mesh, (0.5, 0.5, 0.5))
    exact = cube_poisson(mesh.p)
    fe = fem.Basis(mesh, fem.ElementHex1() if cells == "hex"
                   else fem.ElementTetP1())
    out = []
    for basis in (pg.FamilyBasis(mesh), fe):
        u = poisson(basis)
        out.append((u[centre] / exact[centre] - 1,
                    np.abs(u - exact).max() / exact[centre]))
    return out


def test_poisson_in_the_unit_cube_on_hexahedra():
    """ex09's problem, -Δu = 1 in the unit cube: the centre value against
    the series solution, on 7³ and 11³ nodes.  Measured: PG (thesis
    recipe) +10.6 / +5.7 %, H1 +4.5 / +1.6 %: PG converges, more slowly
    and from above (its 1-ring families average the curvature, the
    softness ex02 shows in bending)."""
    (pg6, _), (fe6, _) = cube_errors("hex", 6)
    (pg10, _), (fe10, _) = cube_errors("hex", 10)
    assert 0 < pg10 < 0.07 and pg6 / pg10 > 1.5
    assert 0 < fe10 < 0.02


def test_poisson_in_the_unit_cube_on_tetrahedra():
    """The same on the cubes split into tetrahedra (the kNN recipe):
    centre −0.17 % (O1 −1.49 %) on 11³ nodes, but the largest nodal error
    6.8 % (O1 1.5 %), next to the Dirichlet boundary, where the ten
    nearest particles of a family lie on one side (the README's "avoid
    kNN for smooth fields with full Dirichlet data")."""
    (pg_c, pg_max), (fe_c, fe_max) = cube_errors("tet", 10)
    assert abs(pg_c) <= abs(fe_c) < 0.02
    assert fe_max < 0.02 and pg_max < 0.08


def beam(n):
    mesh = fem.MeshHex.init_tensor(np.linspace(0, 5, 5 * n + 1),
                                   *(np.linspace(0, 1, n + 1),) * 2)
    return mesh.with_boundaries({"left": lambda x: x[0] == 0,
                                 "right": lambda x: x[0] == 5})


STIFFNESS = linear_elasticity(1.0, 1.0)
TIP = np.array([[5.0], [0.5], [0.5]])
#: H2 on 20 x 4 x 4 cells (its change from 15 x 3 x 3: 6e-4)
TIP_H2, OMEGA_H2 = -0.20384497, 0.062729572


def bend_and_vibrate(basis, mass):
    K = pg.assemble(STIFFNESS, basis)
    D = basis.get_dofs("left")
    f = pg.traction(basis, "right", [0.0, 0.0, -1e-3])
    u = fem.solve(*fem.condense(K, f, D=D))
    free = basis.complement_dofs(D)
    M = mass(basis).tocsr()[free][:, free]
    omega2 = eigsh(K.tocsr()[free][:, free], 1, M, sigma=0.0)[0][0]
    return (basis.probes(TIP) @ u)[2] / TIP_H2 - 1, \
        np.sqrt(omega2) / OMEGA_H2 - 1


@fem.BilinearForm
def consistent_mass(u, v, w):
    return dot(u, v)


def fe_mass(basis):
    return consistent_mass.assemble(basis)


def pg_mass(basis):
    return sp.diags(pg.lumped_mass(basis, 1.0))


def test_elastic_beam_bends_and_vibrates_with_nearest_families():
    """ex11 / ex21's kind of problem, a 5 x 1 x 1 elastic beam clamped at
    one end: tip deflection under an end shear and the first
    eigenfrequency, on 5n x n x n hexahedra (n = 4, 525 nodes).  Measured:
    H1 −3.4 % / +1.8 %; PG with the 18 nearest particles and their ties
    (the whole 3 x 3 x 3 grid stencil, uniform weights, unit bond weights)
    −2.3 % / +0.6 %.  With the ``kNN`` recipe's 10 nearest the tie rule
    (:func:`skfem_pg.families.nearest`) takes all 18 face and edge
    neighbours, a soft family: +11.2 % / −5.3 %; without ties the
    KD-tree's order picked 4 of the 12 edge neighbours, −2.0 % / +0.7 %,
    an accident of that order (issue 45)."""
    mesh = beam(4)
    fe = bend_and_vibrate(fem.Basis(mesh, fem.ElementVector(
        fem.ElementHex1())), fe_mass)
    p = pg.Particles.from_mesh(mesh)
    stencil = bend_and_vibrate(pg.FamilyBasis(
        p, pg.families.nearest(p, 18), dim=3, weights="uniform",
        weight_exponent=0), pg_mass)
    assert abs(fe[0]) < 0.04 and abs(fe[1]) < 0.02
    assert abs(stencil[0]) <= abs(fe[0]) and abs(stencil[1]) < 0.02


def test_elastic_beam_bends_and_vibrates_with_the_moment_quadrature():
    """The same beam with ``family_quadrature="moments"`` (the quadratic
    fit WTE2 at points matching the hat functions' moments, issue 45):
    measured tip −0.16 % and frequency −0.33 % at 525 nodes (H1 −3.4 % /
    +1.8 %; the H2 reference's own uncertainty 0.06 %)."""
    mesh = beam(4)
    fe = bend_and_vibrate(fem.Basis(mesh, fem.ElementVector(
        fem.ElementHex1())), fe_mass)
    mq = bend_and_vibrate(pg.FamilyBasis(
        mesh, dim=3, shape="WTE2", family_quadrature="moments"), pg_mass)
    assert abs(mq[0]) <= 0.1 * abs(fe[0]) and abs(mq[1]) < 0.01


@pytest.mark.xfail(strict=True, reason=(
    "the default (thesis) recipe on hexahedra is soft in bending: tip "
    "+38 % and first frequency −15 % at 525 nodes (+18 % tip at 1519), "
    "against H1's −3.4 % / +1.8 %; the kNN recipe is not the hex default "
    "(a change of default needs the studies of issue 27)"))
def test_elastic_beam_with_the_default_recipe_is_within_fe_error():
    mesh = beam(4)
    fe = bend_and_vibrate(fem.Basis(mesh, fem.ElementVector(
        fem.ElementHex1())), fe_mass)
    default = bend_and_vibrate(pg.FamilyBasis(mesh, dim=3), pg_mass)
    assert abs(default[0]) <= 2 * abs(fe[0])
    assert abs(default[1]) <= 2 * abs(fe[1])


def two_materials(n):
    """ex17's kind of problem: -div(k grad u) = 1 in the unit square, u =
    0 on its boundary, k = 1 for x < 1/2 and 10 beyond (the interface
    through vertices)."""
    mesh = fem.MeshQuad.init_tensor(*(np.linspace(0, 1, n + 1),) * 2)
    centre = mesh.p[:, mesh.t].mean(axis=1)
    return mesh, np.where(centre[0] < 0.5, 1.0, 10.0)


@pg.BilinearForm
def conduction(u, v, w):
    return w.k * dot(fem.helpers.grad(u), fem.helpers.grad(v))


@pg.LinearForm
def heat(v, w):
    return 1.0 * v


PROBES = np.array([[0.25, 0.5, 0.75], [0.5, 0.5, 0.5]])
#: Q2 on 128 x 128 cells (Q1 on 32 x 32: within 0.1 %)
TWO_MATERIALS_Q2 = np.array([0.03371649, 0.01339479, 0.00809533])


def test_two_materials_evaluated_per_bond():
    """A value per particle puts an interface particle on one side: the
    interface value moves by 5 % with the choice (+5.4 % left, +0.4 %
    right at 33² nodes), the left probe by 7 %.  The per-bond evaluation
    (``coefficients.cell_values_at_members``: the cell at each bond's
    midpoint, their mean for a bond along the interface, the cells' mean
    at the master) lets an interface family see both sides: −1.29 /
    −0.04 / +1.33 % (until issue 47, scikit-fem's finder put the bonds
    along the interface on one side: −0.06 / +0.57 / +1.37 %; Q1 +0.09 /
    0.08 / 0.07 %).  A
    value per cell handed to a PG form is refused with that pointer."""
    from skfem_pg.discretization.coefficients import cell_values_at_members
    mesh, k_cells = two_materials(32)
    basis = pg.FamilyBasis(mesh)
    probes = fem.Basis(mesh, fem.ElementQuad1()).probes(PROBES)

    def solve(k):
        K = conduction.assemble(basis, k=k)
        u = fem.solve(*fem.condense(K, heat.assemble(basis),
                                    D=basis.get_dofs()))
        return probes @ u / TWO_MATERIALS_Q2 - 1

    x = basis.particles.x[0]
    left = solve(np.where(x <= 0.5 + 1e-12, 1.0, 10.0))
    right = solve(np.where(x < 0.5 - 1e-12, 1.0, 10.0))
    per_bond = solve(cell_values_at_members(basis, k_cells))
    assert abs(left[1] - right[1]) > 0.04  # the choice matters
    assert np.all(np.abs(per_bond) < 0.015)
    assert np.abs(per_bond).max() < np.abs(left).max()
    assert np.abs(per_bond).max() < np.abs(right).max()
    with pytest.raises(ValueError, match="cell_values_at_members"):
        conduction.assemble(basis, k=k_cells)


def test_an_equal_order_pg_pressure_pair_is_flagged():
    """ex36's mixed displacement–pressure problem with both bases swapped
    diverges to NaN (equal-order PG u–p pairs fail the inf-sup condition):
    assembling the coupling form warns and names the package's mixed
    formulations instead."""
    from skfem.helpers import div
    mesh = fem.MeshQuad.init_tensor(*(np.linspace(0, 1, 5),) * 2)
    particles = pg.Particles.from_mesh(mesh)
    ubasis = pg.FamilyBasis(particles, dim=2)
    pbasis = pg.FamilyBasis(particles)

    @fem.BilinearForm
    def coupling(u, q, w):
        return div(u) * q

    with pytest.warns(pg.MixedBasisWarning, match="IUnlP0"):
        B = pg.assemble(coupling, ubasis, pbasis)
    assert B.shape == (pbasis.N, ubasis.N)
    fe_u = fem.Basis(mesh, fem.ElementVector(fem.ElementQuad1()))
    with warnings.catch_warnings():
        warnings.simplefilter("error", pg.MixedBasisWarning)
        coupling.assemble(fe_u, fe_u.with_element(fem.ElementQuad0()))


def test_cell_values_find_every_bond_midpoint_vectorized():
    """Issue 47 (scikit-fem's ex17): bond midpoints on a curved mesh's
    boundary chords died with scikit-fem's "Point is outside of the
    mesh".  ``locate`` finds the cell of every point, vectorized: the
    same cells as scikit-fem's finder inside distorted quads, hexahedra
    and tetrahedra (a regular hex grid: planar faces); a point on the
    boundary gets a boundary cell, a point outside the mesh its closest
    cell; a bond along the material interface the mean of both sides."""
    from skfem_pg.discretization.coefficients import (
        cell_values_at_members, locate)
    circle = fem.MeshTri.init_circle(4)
    b = pg.FamilyBasis(circle)
    k = np.where(np.hypot(*circle.p[:, circle.t].mean(axis=1)) < 0.5,
                 10.0, 1.0)  # a wire in insulation
    v = cell_values_at_members(b, k)
    mem, mask = b.families.padded()
    bonds = v[:, 1:][mask[:, 1:]]  # masters: volume-weighted means
    assert set(np.unique(bonds)) == {1.0, 5.5, 10.0}  # 5.5: along the
    # interface, a bond half on either side
    # a family on the interface sees both sides
    both = [(row[m[1:]] == 1.0).any() and (row[m[1:]] == 10.0).any()
            for row, m in zip(v[:, 1:], mask)]
    assert any(both)
    rng = np.random.default_rng(4)
    for mesh in (pg.meshing.distort(fem.MeshQuad.init_tensor(
            *(np.linspace(0, 1, 7),) * 2), 0.3, seed=2),
                 fem.MeshTet.init_tensor(*(np.linspace(0, 1, 4),) * 3),
                 fem.MeshHex.init_tensor(*(np.linspace(0, 1, 4),) * 3)):
        x = rng.uniform(0.02, 0.98, size=(mesh.dim(), 300))
        ref = mesh.element_finder()(*x)
        assert np.array_equal(locate(mesh, x), ref)
    # on the boundary and outside: the nearest cell
    sq = fem.MeshTri.init_tensor(*(np.linspace(0, 1, 5),) * 2)
    c = locate(sq, np.array([[1.0, 1.5, -0.2], [0.6, 0.5, 0.1]]))
    cen = sq.p[:, sq.t].mean(axis=1)
    assert np.all(cen[0, c[:2]] > 0.75) and cen[0, c[2]] < 0.25
    import doctest
    from skfem_pg.discretization import coefficients
    result = doctest.testmod(coefficients)
    assert result.attempted > 0 and result.failed == 0


def test_fe_quadrature_data_on_the_generic_path_is_named():
    """Issue 47 (scikit-fem's ex17): a P0 field interpolated at an FE
    basis' quadrature points, handed to scikit-fem's own assembly on a
    FamilyBasis, died in scikit-fem's "Quadrature mismatch"; the PG ways
    are named now, as on the fast path."""
    import warnings
    from skfem.helpers import dot, grad
    mesh = fem.MeshQuad.init_tensor(*(np.linspace(0, 1, 5),) * 2)
    basis = pg.FamilyBasis(mesh)
    k_cells = np.ones(mesh.nelements)

    @fem.BilinearForm
    def conduction_generic(u, v, w):
        return w.k * dot(grad(u), grad(v))
    p0 = fem.Basis(mesh, fem.ElementQuad0()).interpolate(k_cells)
    conduction = pg.BilinearForm(conduction_generic.form)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(ValueError, match="integrates at its family "
                                             "members.*cell_values_at_"
                                             "members"):
            conduction.assemble(basis, k=p0)
        # scikit-fem's own form: its message names the coefficient
        with pytest.raises(ValueError, match="Quadrature mismatch: 'k'"):
            conduction_generic.assemble(basis, k=p0)
        for form in (conduction, conduction_generic):
            with pytest.raises(ValueError, match="cell_values_at_members"):
                form.assemble(basis, k=k_cells)


def test_port_flux_on_the_basis_own_facet_basis():
    """Issue 47 (scikit-fem's ex13): the current through a port of the
    quarter annulus (u = 2θ/π, current 2 ln 2 / π).  ``basis.boundary``
    is scikit-fem's ``CellBasis.boundary``: a facet basis of the
    collocation mesh's linear element, which takes the particle vector
    (a facet basis of another element refuses it in scikit-fem's own
    ``interpolate``).  The facet flux of the linear trace is first order
    (P1 on the same facets +3.7 / −3.5 %, PG +2.9 / −1.8 %); the reaction
    at the port's dofs is the consistent one (P1 +0.13 %, PG −0.16 %)."""
    from skfem.helpers import dot, grad
    from skfem.models.poisson import laplace
    polar = fem.MeshTri.init_tensor(np.linspace(1, 2, 11),
                                    np.linspace(0, np.pi / 2, 32))
    r, th = polar.p
    mesh = fem.MeshTri(np.array([r * np.cos(th), r * np.sin(th)]),
                       polar.t).with_boundaries(
        {"ground": lambda x: np.abs(x[1]) < 1e-12,
         "positive": lambda x: np.abs(x[0]) < 1e-12})
    exact = 2 * np.log(2) / np.pi

    @fem.Functional
    def port_flux(w):
        return dot(w.n, grad(w.u))

    basis = pg.FamilyBasis(mesh)
    A = pg.assemble(laplace, basis)
    u = basis.zeros()
    u[basis.get_dofs("positive")] = 1.0
    u = fem.solve(*fem.condense(A, x=u, D=basis.get_dofs(
        {"positive", "ground"})))
    p1 = fem.FacetBasis(mesh, fem.ElementTriP1(),
                        facets=mesh.boundaries["ground"])
    for port, sign in (("positive", 1), ("ground", -1)):
        fb = basis.boundary(mesh.boundaries[port])
        current = sign * port_flux.assemble(fb, u=fb.interpolate(u))
        reaction = sign * (A @ u)[basis.get_dofs(port).all()].sum()
        assert abs(current / exact - 1) < 0.035
        assert abs(reaction / exact - 1) < 0.003
    fb = basis.boundary(mesh.boundaries["ground"])
    assert np.isclose(port_flux.assemble(fb, u=fb.interpolate(u)),
                      port_flux.assemble(p1, u=p1.interpolate(u)),
                      rtol=1e-14)
    with pytest.raises(NotImplementedError, match="vertices"):
        pg.FamilyBasis(pg.Particles.from_mesh(mesh, kind="centroids")
                       ).boundary()
