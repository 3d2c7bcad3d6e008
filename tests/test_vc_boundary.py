"""The thesis' boundary variants p, s, sn of the VC system (Table 7.1,
section 5.3) and the discrete surface vectors they imply for loads."""
import numpy as np
import pytest
import skfem as fem

import skfem_pg as pg
from skfem_pg.analysis import linear_patch_test
from skfem_pg.discretization.loads import stress_load
from conftest import square, cube
from test_patch import TOP, MESHES_2D, MESHES_3D


@pytest.mark.parametrize("name", ["distorted quads", "gmsh triangles",
                                  "distorted hexes", "gmsh tets"])
@pytest.mark.parametrize("kw", [
    dict(vc_boundary="p"), dict(vc_boundary="s"), dict(vc_boundary="sn"),
    dict(method="PPG1", vc_boundary="s"),
    dict(method="PPG1", vc_boundary="sn")])
def test_boundary_variants_pass_the_patch_test(name, kw):
    mesh = {**MESHES_2D, **MESHES_3D}[name]()
    r = linear_patch_test(mesh, TOP[mesh.dim()], **kw)
    assert r["max_error"] <= 1e-10  # measured <= 4.4e-15 (10x10 quads)
    rep = r["basis"].vc_report
    assert rep.boundary == kw["vc_boundary"]
    assert rep.residual_after < 1e-10
    d, n = mesh.dim(), mesh.nvertices
    if kw["vc_boundary"] == "p":
        assert r["basis"].area_correction is None
        assert rep.unknowns == d * n
    else:  # released surface constraints: the discrete A^i moved
        dA = r["basis"].area_correction
        inner = np.setdiff1d(np.arange(n), mesh.boundary_nodes())
        assert np.abs(dA[:, inner]).max() < 1e-12
        assert np.abs(dA).max() > 1e-3 * np.abs(
            r["basis"].particles.area_vectors()).max()
        n_surf = len(mesh.boundary_nodes())
        expected = d * (n - n_surf) + (
            (d - 1) * n_surf if kw["vc_boundary"] == "sn" else 0)
        assert rep.unknowns == rep.constraints == expected


def test_sn_keeps_the_fe_normal_direction():
    mesh = square(10, 0.3, seed=1)
    b = pg.FamilyBasis(mesh, dim=2, vc_boundary="sn")
    A = b.particles.area_vectors()
    Ah = A + b.area_correction
    cross = A[0] * Ah[1] - A[1] * Ah[0]  # tangential part of A_h
    assert np.abs(cross).max() < 1e-12 * np.abs(A).max() ** 2
    # and s does not
    b = pg.FamilyBasis(mesh, dim=2, vc_boundary="s")
    Ah = A + b.area_correction
    assert np.abs(A[0] * Ah[1] - A[1] * Ah[0]).max() > 1e-4 * np.abs(
        A).max() ** 2


def test_released_constraints_need_discrete_loads():
    """With FE-consistent instead of discrete area vectors in the Neumann
    load, the s variant fails the patch test: the load correction is what
    makes it pass."""
    mesh = square(10, 0.3, seed=1)
    g = pg.analysis.PATCH_GRADIENT_2D
    lam, mu = pg.materials.lame(100.0, 0.3)
    eps = 0.5 * (g + g.T)
    sigma = 2 * mu * eps + lam * np.trace(eps) * np.eye(2)
    b = pg.FamilyBasis(mesh, dim=2, vc_boundary="s")
    top = mesh.facets_satisfying(TOP[2])
    K = pg.assemble(pg.formulations.linear_elasticity(lam, mu), b)
    D = b.get_dofs(np.setdiff1d(mesh.boundary_facets(), top))
    uex = (g @ mesh.p).T.ravel()
    f = stress_load(b, top, sigma)
    b.area_correction, dA = None, b.area_correction
    f_fe = stress_load(b, top, sigma)
    b.area_correction = dA
    u = fem.solve(*fem.condense(K, f, x=uex, D=D))
    u_fe = fem.solve(*fem.condense(K, f_fe, x=uex, D=D))
    assert np.abs(u - uex).max() <= 1e-10
    assert np.abs(u_fe - uex).max() > 1e-5


def test_v4_and_vc2_with_s_solve_their_constraints_by_lu():
    """V4's and VC2's full systems are incompatible (LSQR leaves a
    residual unless the Dirichlet particles are excluded); with the surface
    constraints released they are square and regular: one sparse LU
    satisfies them.  (Their patch-test errors are then limited by the
    conditioning of the WTE2 boundary families: 2.7e-11 on 10x10, 3.3e-8
    on 12x12 for V4 — the minimum-norm solve with ``vc_exclude`` is the
    accurate one.)"""
    mesh = square(12, 0.3, seed=1)
    b = pg.FamilyBasis(mesh, dim=2, shape="WTE2", vc="V4", vc_boundary="s")
    assert b.vc_report.solver == "direct"
    assert b.vc_report.residual_after < 1e-10
    b = pg.FamilyBasis(mesh, dim=2, shape="WTE2", vc="VC2", vc_boundary="s")
    assert b.vc_report.solver == "direct"
    assert b.vc_report.residual_after < 1e-10
    assert b.area2_correction.shape == (2, 2, mesh.nvertices)


def test_singular_reduced_systems_raise():
    # V4 with sn: the reduced system is singular to working precision
    with pytest.raises(pg.VCSolveError,
                       match="V4 with boundary variant 'sn'") as err:
        pg.FamilyBasis(square(10, 0.3, seed=1), dim=2, shape="WTE2",
                       vc="V4", vc_boundary="sn")
    # a CorrectionError, and a RuntimeError as before the type existed
    assert isinstance(err.value, pg.CorrectionError)
    assert isinstance(err.value, RuntimeError)


def test_bad_boundary_options_are_named():
    mesh = square(6, 0.3, seed=1)
    with pytest.raises(ValueError, match="boundary variant 'x'"):
        pg.FamilyBasis(mesh, dim=2, vc_boundary="x")
    with pytest.raises(ValueError, match="'p' pins"):
        pg.FamilyBasis(mesh, dim=2, method="PPG1", vc="V1",
                       vc_boundary="p")
    with pytest.raises(ValueError, match="vc_exclude"):
        pg.FamilyBasis(mesh, dim=2, vc_boundary="s", vc_exclude=[0])
    with pytest.raises(NotImplementedError, match="vc_boundary"):
        pg.FamilyBasis(mesh, dim=2, vc=None, vc_boundary="sn")
    with pytest.raises(NotImplementedError, match="vc_boundary"):
        pg.FamilyBasis(mesh, dim=2, shape="WTE2", vc="VC2",
                       vc_boundary="sn")


@pytest.mark.parametrize("mesh", [square(10, 0.3, seed=2, kind="tri"),
                                  cube(4, 0.3, seed=2, kind="tet")],
                         ids=["triangles", "tets"])
@pytest.mark.parametrize("boundary", ["s", "sn"])
def test_v2_passes_with_released_surface_constraints(mesh, boundary):
    """V2 (second derivatives of WLS2, (5.61)): its full system is
    incompatible (LSQR leaves a residual, with a hint); with the thesis'
    surface variants it passes the patch test."""
    d = mesh.dim()
    p = pg.Particles.from_mesh(mesh)
    fam = pg.families.horizon(p, factor=2.01, min_size=3 + d + d * (d + 1)
                              // 2)
    for method in ("PBG", "PPG1"):
        r = linear_patch_test(mesh, TOP[d], particles=p, families=fam,
                              bond=False, vc="V2", method=method,
                              vc_boundary=boundary)
        assert r["max_error"] <= 1e-10  # measured <= 9.4e-14
    if boundary == "s":
        with pytest.raises(pg.CorrectionError,
                           match="vc_boundary='s' or 'sn'"):
            linear_patch_test(mesh, TOP[d], particles=p, families=fam,
                              bond=False, vc="V2")
        with pytest.warns(UserWarning, match="vc_boundary='s' or 'sn'"):
            r = linear_patch_test(mesh, TOP[d], particles=p, families=fam,
                                  bond=False, vc="V2", vc_tolerance=None)
        assert r["max_error"] > 1e-6


@pytest.mark.parametrize("test_shape", ["MLS1", "WLS2"])
def test_least_squares_test_functions_pass_with_vc(test_shape):
    mesh = cube(4, 0.3, seed=2, kind="tet")
    p = pg.Particles.from_mesh(mesh)
    fam = pg.families.horizon(p, factor=2.01, min_size=12)
    r = linear_patch_test(mesh, TOP[3], particles=p, families=fam,
                          method="PPG1", test_shape=test_shape)
    assert r["max_error"] <= 1e-10  # measured 5.6e-16 / 1.5e-12
    r = linear_patch_test(mesh, TOP[3], particles=p, families=fam,
                          method="PPG1", test_shape=test_shape, vc=None)
    assert r["max_error"] > 1e-3
