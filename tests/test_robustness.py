"""No silent wrong answers from the discretization: graded and sliver node
sets pass the linear patch test; bad families and horizons raise."""
import numpy as np
import pytest
import skfem as fem
from scipy.spatial import Delaunay

import skfem_pg as pg
from skfem_pg.analysis import linear_patch_test


def graded(ratio, n):
    """``n`` points on [0, 1], geometric spacing, largest / smallest
    interval = ``ratio``."""
    q = ratio ** (1.0 / (n - 2))
    s = np.cumsum(np.r_[0.0, q ** np.arange(n - 1)])
    return s / s[-1]


def cap_slivers(n=8, eps=1e-3):
    """Triangles whose largest angle is 179.8°: a row of points lifted by
    ``eps h`` above the midpoints of the y = 0.5 grid line."""
    h, g = 1.0 / n, np.linspace(0, 1, n + 1)
    low = fem.MeshTri.init_tensor(g, np.linspace(0, 0.5, n // 2 + 1))
    X, Y = np.meshgrid(g, np.linspace(0.5, 1, n // 2 + 1))
    up = np.r_[np.c_[X.ravel(), Y.ravel()],
               np.c_[g[:-1] + h / 2, np.full(n, 0.5 + eps * h)]]
    pts = np.r_[low.p.T, up]
    t = np.r_[low.t.T, Delaunay(up).simplices + low.nvertices]
    key = np.round(pts * 1e9).astype(np.int64)
    _, first, inv = np.unique(key, axis=0, return_index=True,
                              return_inverse=True)
    return fem.MeshTri(pts[first].T.copy(), inv.ravel()[t].T.copy())


def _max_angle(mesh):
    P = mesh.p[:, mesh.t]
    out = 0.0
    for i in range(3):
        u, v = P[:, (i + 1) % 3] - P[:, i], P[:, (i + 2) % 3] - P[:, i]
        c = (u * v).sum(0) / np.linalg.norm(u, axis=0) \
            / np.linalg.norm(v, axis=0)
        out = max(out, np.degrees(np.arccos(np.clip(c, -1, 1))).max())
    return out


SETS = {
    # measured before the scale-aware moment test: "moment matrix is
    # singular" for the first three, 4.5e-11 for the graded tets
    "quads graded 1000:1 both ways": lambda: fem.MeshQuad.init_tensor(
        graded(1000, 13), graded(1000, 13)),
    "triangles graded 1000:1": lambda: fem.MeshTri.init_tensor(
        graded(1000, 13), np.linspace(0, 1, 7)),
    "needle triangles 1:250 (thin row)": lambda: fem.MeshTri.init_tensor(
        np.linspace(0, 1, 9), np.r_[0, 0.5, 0.5005, 1]),
    "cap slivers 179.8 deg": cap_slivers,
    "tets graded 1000:1": lambda: fem.MeshTet.init_tensor(
        graded(1000, 8), np.linspace(0, 1, 4), np.linspace(0, 1, 4)),
    "quads graded 100:1": lambda: fem.MeshQuad.init_tensor(
        graded(100, 11), np.linspace(0, 1, 9)),
}


@pytest.mark.parametrize("method", ["PBG", "PPG1"])
@pytest.mark.parametrize("name", list(SETS))
def test_graded_and_sliver_sets_pass_the_patch_test(name, method):
    mesh = SETS[name]()
    top = mesh.facets_satisfying(lambda x: x[-1] == 1)
    r = linear_patch_test(mesh, top, method=method)
    # measured <= 1.8e-13 (PBG) / 7.3e-12 (PPG1)
    assert r["max_error"] <= 1e-10
    assert r["basis"].vc_report.residual_after <= 1e-10


@pytest.mark.parametrize("name", list(SETS))
def test_fe_passes_the_patch_test_on_the_same_sets(name):
    """The sets are valid FE meshes: P1/Q1 pass the same patch test (the
    reference behaviour the issue names)."""
    from skfem.helpers import dot
    from skfem_pg.analysis import PATCH_GRADIENT_2D, PATCH_GRADIENT_3D
    from skfem_pg.materials import lame
    from skfem_pg.formulations import linear_elasticity
    mesh = SETS[name]()
    d = mesh.dim()
    e1, _ = pg.particles.linear_elements(mesh)
    basis = fem.Basis(mesh, fem.ElementVector(e1))
    lam, mu = lame(100.0, 0.3)
    G = PATCH_GRADIENT_2D if d == 2 else PATCH_GRADIENT_3D
    eps = 0.5 * (G + G.T)
    sigma = 2 * mu * eps + lam * np.trace(eps) * np.eye(d)
    top = mesh.facets_satisfying(lambda x: x[-1] == 1)
    fb = fem.FacetBasis(mesh, basis.elem, facets=top)
    f = fem.LinearForm(lambda v, w: dot(
        np.einsum("ij,j...->i...", sigma, w.n), v)).assemble(fb)
    K = linear_elasticity(lam, mu).assemble(basis)
    D = basis.get_dofs(np.setdiff1d(mesh.boundary_facets(), top))
    uex = (G @ mesh.p).T.ravel()
    u = fem.solve(*fem.condense(K, f, x=uex, D=D))
    assert np.abs(u - uex).max() <= 1e-10


def test_the_sets_are_what_they_claim():
    x = SETS["quads graded 1000:1 both ways"]().p[0]
    dx = np.diff(np.unique(x))
    assert dx.max() / dx.min() == pytest.approx(1000)
    assert _max_angle(cap_slivers()) > 179.7


@pytest.mark.parametrize("k", [1, 2])
def test_too_few_nearest_neighbours_raise(k):
    # measured before: patch error 5.6 with a warning (k = 2), NaN (k = 1);
    # without ties (with them a grid's k = 1 and 2 take the 4 equidistant
    # neighbours: test_families.py)
    mesh = fem.MeshQuad.init_tensor(np.linspace(0, 1, 9),
                                    np.linspace(0, 1, 9))
    p = pg.Particles.from_mesh(mesh)
    with pytest.raises(pg.CorrectionError, match="particle"):
        pg.FamilyBasis(p, pg.families.nearest(p, k, ties=False), dim=2)


def test_blown_up_corrections_raise():
    from skfem_pg.discretization.corrections import (GRADIENT_LIMIT,
                                                     check_correction)
    mesh = fem.MeshQuad.init_tensor(np.linspace(0, 1, 5),
                                    np.linspace(0, 1, 5))
    b = pg.FamilyBasis(mesh, dim=2)
    G = b.G.copy()
    G[3, 1, 2, 0] = 10 * GRADIENT_LIMIT / 0.25
    with pytest.raises(pg.CorrectionError, match="blew"):
        check_correction(G, b.particles.x, b.families, b.vc_report)
    G[3, 1, 2, 0] = np.nan
    with pytest.raises(pg.CorrectionError, match="non-finite"):
        check_correction(G, b.particles.x, b.families, None)


@pytest.mark.parametrize("kw", [dict(delta=np.nan), dict(delta=1e-6),
                                dict(delta=np.inf), dict(delta=-1.0),
                                dict(delta="a"), dict(factor=np.nan),
                                dict(factor=0.0)])
def test_bad_horizons_raise(kw):
    mesh = fem.MeshQuad.init_tensor(np.linspace(0, 1, 9),
                                    np.linspace(0, 1, 9))
    with pytest.raises(pg.FamilyError, match="horizon"):
        pg.families.horizon(pg.Particles.from_mesh(mesh), **kw)


@pytest.mark.parametrize("n", [2.5, "3", True, None])
def test_non_integer_neighbour_counts_raise(n):
    mesh = fem.MeshQuad.init_tensor(np.linspace(0, 1, 5),
                                    np.linspace(0, 1, 5))
    with pytest.raises(pg.FamilyError, match="integer"):
        pg.families.nearest(pg.Particles.from_mesh(mesh), n)


def test_folded_triangle_mesh_is_rejected():
    m = fem.MeshTri.init_tensor(np.linspace(0, 1, 5), np.linspace(0, 1, 5))
    p = m.p.copy()
    i = np.argmin(np.linalg.norm(p - 0.5, axis=0))
    p[:, i] += [0.3, 0.15]  # pushed through its neighbour at (0.75, 0.5)
    folded = fem.MeshTri(p, m.t)
    # every element is valid on its own; their areas overlap
    assert fem.Basis(folded, fem.ElementTriP1()).dx.sum() > 1.01
    with pytest.raises(pg.ParticleError, match="folded"):
        pg.Particles.from_mesh(folded)
    tet = fem.MeshTet.init_tensor(*(np.linspace(0, 1, 4),) * 3)
    q = tet.p.copy()
    j = np.argmin(np.linalg.norm(q - 1 / 3, axis=0))
    q[:, j] += 0.45
    with pytest.raises(pg.ParticleError, match="folded|inverted"):
        pg.Particles.from_mesh(fem.MeshTet(q, tet.t))


@pytest.mark.parametrize("kind", ["quad", "tri"])
def test_inverted_cells_of_a_particle_displacement(kind):
    from skfem_pg.discretization.particles import inverted_cells
    g = np.linspace(0, 1, 5)
    mesh = (fem.MeshQuad if kind == "quad" else fem.MeshTri).init_tensor(g, g)
    p = pg.Particles.from_mesh(mesh)
    u = np.zeros(2 * mesh.nvertices)
    assert len(inverted_cells(p, u)) == 0
    u = 0.2 * mesh.p.T.ravel()  # a homogeneous stretch inverts nothing
    assert len(inverted_cells(p, u)) == 0
    u[:] = 0.0
    i = np.argmin(np.linalg.norm(mesh.p - 0.5, axis=0))
    u[2 * i] = 0.3  # past its right neighbour at x = 0.75
    bad = inverted_cells(p, u)
    around = np.any(mesh.t[:, bad] == i, axis=0)
    if kind == "quad":  # the two cells whose corner Jacobian flips
        assert len(bad) == 2 and np.all(around)
    else:  # inverted triangles, and the ones they fold onto
        assert 2 <= len(bad) <= 8 and np.sum(around) >= 2


def test_horizon_on_strongly_anisotropic_cells_raises():
    """Cells 30:1 and a horizon of 2.01 mean spacings: the families are
    single columns plus a neighbour or two (enlarged until they span the
    plane) and the VC system is near-singular — |G|·h = 2e19 measured with
    scipy 1.17; scipy 1.9's LU calls it exactly singular and the LSQR
    fallback leaves a residual of 9e-2: refused either way."""
    mesh = fem.MeshQuad.init_tensor(np.linspace(0, 30, 11),
                                    np.linspace(0, 1, 11))
    p = pg.Particles.from_mesh(mesh)
    fam = pg.families.horizon(p, factor=2.01)
    with pytest.raises(pg.CorrectionError, match="blew|residual"):
        pg.FamilyBasis(p, fam, dim=2)
    # the mesh's own connectivity is fine on the same particles
    r = linear_patch_test(mesh, mesh.facets_satisfying(lambda x: x[1] == 1))
    assert r["max_error"] <= 1e-10
