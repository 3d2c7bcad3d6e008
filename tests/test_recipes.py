"""The kNN recipe (nearest-neighbour families, uniform quadrature weights,
unit bond weights; the keyword default of PBG Unl on 3-D tetrahedra) and
the meshU recipe (mesh families, uniform weights, unit bond weights; the
default on 2-D triangles) keep every guarantee of the thesis' recipe: the
linear patch test, exactly the
rigid-body zero modes, and convergence rates of at least 2 (L2) and 1
(H1); near-singular families are repaired or refused."""
import numpy as np
import pytest
import scipy.linalg
import scipy.spatial
import skfem as fem

import skfem_pg as pg
from skfem_pg.analysis.convergence import (PlaneWaves, rates,
                                           solve_manufactured)
from skfem_pg.analysis.verification import linear_patch_test
from skfem_pg.discretization.recipes import default_recipe
from skfem_pg.errors import FamilyError
from skfem_pg.formulations import linear_elasticity
from skfem_pg.materials import lame
from conftest import cube, square

CUBE = pg.meshing.geo_path("cube.geo")


def test_defaults_by_mesh_kind():
    tets = pg.Particles.from_mesh(cube(2, kind="tet"))
    assert default_recipe(tets) == "kNN"
    assert default_recipe(tets, method="PPG1") == "mesh"
    assert default_recipe(tets, shape="WTE1") == "mesh"
    assert default_recipe(pg.Particles.from_mesh(cube(2))) == "mesh"
    assert default_recipe(pg.Particles.from_mesh(square(3))) == "mesh"
    tris = pg.Particles.from_mesh(square(3, kind="tri"))
    assert default_recipe(tris) == "meshU"
    assert default_recipe(tris, method="PPG1") == "mesh"
    b = pg.FamilyBasis(tris, dim=2)
    assert (b.recipe, b.weights, b.weight_exponent) == ("meshU", "uniform",
                                                        0)
    assert b.options["families"] == "mesh"
    assert pg.FamilyBasis(tris, dim=2, families="mesh").weights == "volume"
    b = pg.FamilyBasis(tets, dim=3)
    assert (b.recipe, b.weights, b.weight_exponent) == ("kNN", "uniform", 0)
    assert b.options["families"] == "nearest"  # what UL rebuilds with
    # PBG weights sum to the master volume per family, whatever the rule
    for w in ("volume", "uniform"):
        dx = pg.FamilyBasis(tets, dim=3, weights=w).dx
        assert np.allclose(dx.sum(axis=1), tets.volumes, rtol=1e-13)


@pytest.mark.parametrize("mesh", [
    pytest.param(lambda: pg.meshing.from_geo(CUBE, size=0.25), id="gmsh"),
    pytest.param(lambda: cube(4, 0.3, seed=3, kind="tet"), id="distorted"),
])
def test_patch_test_3d(mesh):
    r = linear_patch_test(mesh(), lambda x: np.isclose(x[0], 1.0))
    assert r["basis"].recipe == "kNN"
    assert r["max_error"] < 1e-10 and r["H1"] < 1e-10


@pytest.mark.parametrize("mesh", [
    pytest.param(lambda: pg.meshing.from_geo(pg.meshing.geo_path(
        "square.geo"), size=0.15), id="gmsh"),
    pytest.param(lambda: square(8, 0.3, seed=4, kind="tri"),
                 id="distorted"),
])
def test_patch_test_2d_triangles_default(mesh):
    m = mesh()
    x0 = m.p[0].max()
    r = linear_patch_test(m, lambda x: np.isclose(x[0], x0))
    assert r["basis"].recipe == "meshU"
    assert r["max_error"] < 1e-10 and r["H1"] < 1e-10


def test_patch_test_2d_nearest():
    m = square(8, 0.3, seed=4, kind="tri")
    r = linear_patch_test(m, lambda x: np.isclose(x[0], 1.0),
                          families="nearest")
    assert r["basis"].weights == "uniform"
    assert r["max_error"] < 1e-10


def free_spectrum(basis, mesh, elem):
    """Eigenvalues of K phi = lambda M phi with lumped masses (particle
    volumes; FE row sums), PG and linear FE on the same nodes: the
    frequencies of the free body, comparable across methods."""
    form = linear_elasticity(*lame(1.0, 0.3))
    fe = fem.Basis(mesh, fem.ElementVector(elem))
    mass = fem.BilinearForm(lambda u, v, w: sum(
        u[i] * v[i] for i in range(mesh.dim()))).assemble(fe)
    out = []
    for b, m in ((basis, np.repeat(basis.particles.volumes, mesh.dim())),
                 (fe, np.asarray(mass.sum(axis=1)).ravel())):
        s = 1.0 / np.sqrt(m)
        K = pg.assemble(form, b).toarray()
        out.append(scipy.linalg.eigvalsh(s[:, None] * K * s[None, :]))
    return out


@pytest.mark.parametrize("dim", [3, 2])
def test_exactly_the_rigid_body_zero_modes(dim):
    """A free body: 6 (3-D) / 3 (2-D) zero eigenvalues and no soft mode:
    the first deformation frequency is above half of linear FE's (3-D,
    measured: 3.39 against O1's 3.79; the thesis recipe 2.85)."""
    if dim == 3:
        mesh = pg.meshing.from_geo(CUBE, size=0.25)
        basis, elem, rigid = pg.FamilyBasis(mesh, dim=3), \
            fem.ElementTetP1(), 6
    else:
        mesh = square(10, 0.3, seed=5, kind="tri")
        basis, elem, rigid = pg.FamilyBasis(
            mesh, dim=2, families="nearest"), fem.ElementTriP1(), 3
    pgev, feev = free_spectrum(basis, mesh, elem)
    assert np.sum(np.abs(pgev) < 1e-10 * pgev[-1]) == rigid
    assert pgev[rigid] > 0.5 * feev[rigid]


@pytest.mark.parametrize("mesh", [
    pytest.param(lambda: square(10, 0.3, seed=5, kind="tri"),
                 id="distorted"),
    pytest.param(lambda: pg.meshing.from_geo(pg.meshing.geo_path(
        "cook.geo"), size=6.0), id="gmsh-cook"),
])
def test_meshu_has_exactly_the_rigid_body_zero_modes(mesh):
    """The 2-D triangle default (meshU): 3 zero eigenvalues of the free
    body and the first deformation frequency above half of T1's."""
    m = mesh()
    basis = pg.FamilyBasis(m, dim=2)
    assert basis.recipe == "meshU"
    pgev, feev = free_spectrum(basis, m, fem.ElementTriP1())
    assert np.sum(np.abs(pgev) < 1e-10 * pgev[-1]) == 3
    assert pgev[3] > 0.5 * feev[3]


@pytest.mark.study
def test_manufactured_rates_3d():
    """L2 and H1 rates on unstructured gmsh tetrahedra (144 ... 1879
    nodes; measured 2.17 and 1.27)."""
    field = PlaneWaves(3)
    runs = [solve_manufactured(pg.meshing.from_geo(CUBE, size=s), field,
                               1.0, 1.0) for s in (0.25, 0.17, 0.12, 0.085)]
    h = [r["h"] for r in runs]
    l2, _ = rates(h, [r["L2"] for r in runs])
    h1, _ = rates(h, [r["H1"] for r in runs])
    assert l2 >= 2.0 and h1 >= 1.0


def test_manufactured_rates_2d_nearest():
    field = PlaneWaves(2)
    runs = [solve_manufactured(square(n, 0.3, seed=n, kind="tri"), field,
                               1.0, 1.0, families="nearest")
            for n in (8, 16, 32)]
    h = [r["h"] for r in runs]
    l2, _ = rates(h, [r["L2"] for r in runs])
    h1, _ = rates(h, [r["H1"] for r in runs])
    assert l2 >= 2.0 and h1 >= 1.0


def test_manufactured_rates_2d_triangles_default():
    """meshU on ±0.3h distorted triangles (81 ... 1089 nodes)."""
    field = PlaneWaves(2)
    runs = [solve_manufactured(square(n, 0.3, seed=n, kind="tri"), field,
                               1.0, 1.0) for n in (8, 16, 32)]
    h = [r["h"] for r in runs]
    l2, _ = rates(h, [r["L2"] for r in runs])
    h1, _ = rates(h, [r["H1"] for r in runs])
    assert l2 >= 2.0 and h1 >= 1.0


def test_flat_neighbourhoods_are_repaired():
    """A particle whose ten nearest neighbours lie in one plane (a dense
    layer between coarse ones): its family is enlarged until its members
    span the space, and its derivatives reproduce a linear field."""
    g = np.linspace(0.0, 1.0, 13)
    X, Y = np.meshgrid(g, g)
    layer = np.array([X.ravel(), Y.ravel(), 0.5 + 0 * X.ravel()])
    x = np.hstack([layer, cube(3, kind="tet").p])
    p = pg.Particles(x, np.full(x.shape[1], 1.0 / x.shape[1]))
    k = 13 * 6 + 6  # the middle of the layer
    _, near = scipy.spatial.cKDTree(x.T).query(x[:, k], 11)
    assert np.ptp(x[2, near]) == 0  # its ten nearest are flat
    b = pg.FamilyBasis(p, pg.families.nearest(p, 10), dim=3, vc=None,
                       weights="uniform", weight_exponent=0)
    row = np.nonzero(b.families.masters == k)[0][0]
    members = b.families.members[b.families.offsets[row]:
                                 b.families.offsets[row + 1]]
    assert np.ptp(x[2, members]) > 0
    grad = np.array([[0.1, 0.3, -0.2], [0.2, 0.4, 0.1], [-0.1, 0.05, 0.3]])
    u = (grad @ x).T.ravel()
    F = b.interpolate(u).grad
    mask = b.families.padded()[1]
    assert np.abs(F - grad[:, :, None, None])[..., mask].max() < 1e-10


def test_refusals():
    tets = pg.Particles.from_mesh(cube(2, kind="tet"))
    with pytest.raises(ValueError, match="PBG option"):
        pg.FamilyBasis(tets, dim=3, method="PPG1", weights="uniform")
    with pytest.raises(ValueError, match="weights"):
        pg.FamilyBasis(tets, dim=3, weights="gauss")
    with pytest.raises(ValueError, match="weight_exponent"):
        pg.FamilyBasis(tets, dim=3, weight_exponent=-1)
    with pytest.raises(FamilyError, match="family rule"):
        pg.FamilyBasis(tets, dim=3, families="ring")
    no_mesh = pg.Particles(tets.x, tets.volumes)
    with pytest.raises(FamilyError, match="no mesh"):
        pg.FamilyBasis(no_mesh, dim=3, families="mesh", vc=None)
