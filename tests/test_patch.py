"""Linear patch test (thesis 7.1–7.2, Table 7.2)."""
import numpy as np
import pytest

import skfem_pg as pg
from skfem_pg.analysis import linear_patch_test
from conftest import square, cube

TOP = {2: lambda x: np.isclose(x[1], 1.0), 3: lambda x: np.isclose(x[2], 1.0)}


def gmsh_triangles():
    return pg.meshing.from_geo(pg.meshing.geo_path("square.geo"), size=0.2)


MESHES_2D = {
    "regular quads": lambda: square(10),
    "distorted quads": lambda: square(10, 0.3, seed=1),
    "distorted triangles": lambda: square(10, 0.3, seed=2, kind="tri"),
    "gmsh triangles": gmsh_triangles,
}
MESHES_3D = {
    "distorted hexes": lambda: cube(4, 0.3, seed=1),
    "distorted tets": lambda: cube(4, 0.3, seed=2, kind="tet"),
    "gmsh tets": lambda: pg.meshing.from_geo(pg.meshing.geo_path("cube.geo"),
                                             size=0.3),
}


@pytest.mark.parametrize("name", list(MESHES_2D) + list(MESHES_3D))
def test_vc_pbg_unl_passes(name):
    mesh = {**MESHES_2D, **MESHES_3D}[name]()
    r = linear_patch_test(mesh, TOP[mesh.dim()])  # MTE1 + BC + V5
    assert r["max_error"] <= 1e-10
    assert r["basis"].vc_report.residual_after < 1e-10


@pytest.mark.parametrize("name", ["distorted quads", "distorted hexes"])
@pytest.mark.parametrize("kw", [dict(vc=None), dict(shape="WTE1")])
def test_uncorrected_fails(name, kw):
    mesh = {**MESHES_2D, **MESHES_3D}[name]()
    r = linear_patch_test(mesh, TOP[mesh.dim()], **kw)
    # thesis Table 7.2: uncorrected PBG Unl eps_L2 = 8.6e-3
    assert r["L2"] > 1e-3 and r["max_error"] > 1e-3


def test_v3_without_bond_correction_passes():
    r = linear_patch_test(square(8, 0.3, seed=4), TOP[2], bond=False,
                          vc="V3")
    assert r["max_error"] <= 1e-10


def test_horizon_families_pass():
    mesh = square(8, 0.3, seed=5)
    p = pg.Particles.from_mesh(mesh)
    fam = pg.families.horizon(p, factor=2.01)
    r = linear_patch_test(mesh, TOP[2], particles=p, families=fam)
    assert r["max_error"] <= 1e-10


@pytest.mark.parametrize("mesh", [square(8, 0.3, seed=6),
                                  cube(3, 0.3, seed=6, kind="tet")])
def test_vc_solvers_give_the_same_min_norm_correction(mesh):
    """The scalar pinned LU, its AMG-GMRES solve and LSQR (from zero: the
    minimum-norm solution) agree, and all pass the patch test."""
    G = {}
    for solver in ("direct", "amg", "lsqr"):
        r = linear_patch_test(mesh, TOP[mesh.dim()], vc_solver=solver)
        assert r["basis"].vc_report.solver == solver
        assert r["max_error"] <= 1e-10
        G[solver] = r["basis"].G
    for solver in ("direct", "amg"):
        assert np.abs(G[solver] - G["lsqr"]).max() <= \
            1e-9 * np.abs(G["lsqr"]).max()


@pytest.mark.parametrize("name", ["distorted quads", "distorted hexes"])
@pytest.mark.parametrize("method", ["PBG", "PPG1"])
def test_vc_u2_passes_uncorrected_fails(name, method):
    mesh = {**MESHES_2D, **MESHES_3D}[name]()
    r = linear_patch_test(mesh, TOP[mesh.dim()], shape="WTE2", method=method)
    assert r["max_error"] <= 1e-10
    r0 = linear_patch_test(mesh, TOP[mesh.dim()], shape="WTE2", vc=None,
                           method=method)
    assert r0["max_error"] > 1e-3
    with pytest.raises(ValueError, match="linear bases"):
        pg.FamilyBasis(mesh, dim=mesh.dim(), shape="WTE2", bond=True)


def quadratic_case(n=8, distortion=0.3):
    import skfem as fem
    m = fem.MeshQuad.init_tensor(np.linspace(-1, 1, n + 1),
                                 np.linspace(-1, 1, n + 1))
    m = pg.meshing.distort(m, distortion, seed=1)
    top = m.facets_satisfying(lambda x: np.isclose(x[1], 1.0))
    dirichlet = np.unique(m.facets[:, np.setdiff1d(m.boundary_facets(),
                                                   top)])
    return m, top, dirichlet


def test_vc2_u2_passes_the_quadratic_patch_test():
    from skfem_pg.analysis import quadratic_patch_test
    m, top, dirichlet = quadratic_case()
    r = quadratic_patch_test(m, top, shape="WTE2", vc="VC2",
                             vc_exclude=dirichlet)
    assert r["max_error"] <= 1e-10  # measured 9.1e-13
    assert r["basis"].vc_report.residual_after < 1e-10
    # enforcing the constraints at the Dirichlet particles too leaves an
    # incompatible system (measured residual 6.4e-2)
    with pytest.raises(pg.CorrectionError, match="vc_exclude"):
        quadratic_patch_test(m, top, shape="WTE2", vc="VC2")
    with pytest.warns(UserWarning, match="vc_exclude"):
        r_all = quadratic_patch_test(m, top, shape="WTE2", vc="VC2",
                                     vc_tolerance=None)
    assert r_all["basis"].vc_report.residual_after > 1e-4


@pytest.mark.parametrize("kw", [dict(vc=None), dict(), dict(shape="WTE2"),
                                dict(method="PPG1", vc=None),
                                dict(method="PPG1")])
def test_first_order_variants_fail_the_quadratic_patch_test(kw):
    # thesis Table 7.3: PPG Unl 1.8e-1, VCPPG V3sn Unl 6.0e-4 (eps_L2)
    from skfem_pg.analysis import quadratic_patch_test
    m, top, _ = quadratic_case()
    r = quadratic_patch_test(m, top, **kw)
    assert r["L2"] > 1e-4 and r["max_error"] > 1e-4


def test_v1_ppg_and_v4_u2_pass_the_linear_patch_test():
    m, top, dirichlet = quadratic_case(12)
    r = linear_patch_test(m, top, method="PPG1", vc="V1")
    assert r["max_error"] <= 1e-10  # measured 4.4e-15
    r = linear_patch_test(m, top, shape="WTE2", vc="V4", vc_exclude=dirichlet)
    assert r["max_error"] <= 1e-10  # measured 7.3e-12
    # V4 on all particles: an incompatible system, LSQR leaves 8.5e-4
    with pytest.raises(pg.CorrectionError, match="residual"):
        linear_patch_test(m, top, shape="WTE2", vc="V4")
    with pytest.warns(UserWarning, match="residual"):
        r = linear_patch_test(m, top, shape="WTE2", vc="V4",
                              vc_tolerance=None)
    assert r["max_error"] > 1e-6


def test_vc_names_and_supports_are_checked():
    m, top, _ = quadratic_case(6)
    with pytest.raises(ValueError, match="V1"):
        pg.FamilyBasis(m, dim=2, vc="V1")  # PBG: V1 breaks the trial
    with pytest.raises(pg.FamilyError, match="at least 7"):
        pg.FamilyBasis(m, dim=2, vc="V4")  # WLS2 on FE-connectivity


def test_vc2_ppg_v1s_u2_passes_the_quadratic_patch_test():
    """The thesis' passing row of Table 7.3, VC2PPG V1s U2: second-order
    VC of the PPG1 test derivatives (5.24) with V1 functions, surface
    correction fixed (``s``): one sparse LU."""
    from skfem_pg.analysis import quadratic_patch_test
    m, top, _ = quadratic_case()
    with pytest.warns(UserWarning, match="unstable"):
        r = quadratic_patch_test(m, top, shape="WTE2", method="PPG1",
                                 vc="VC2", vc_boundary="s")
    assert r["max_error"] <= 1e-10  # measured 1.7e-12
    assert r["basis"].name == "VC2PPG V1s U2 TL"
    assert r["basis"].vc_report.solver == "direct"
    # unlike PBG's VC2 (V4), the full PPG1 system is compatible: LSQR
    # reaches the constraints without excluding particles (its tolerance
    # limits the patch test to 2.2e-10 here)
    with pytest.warns(UserWarning, match="unstable"):
        r_all = quadratic_patch_test(m, top, shape="WTE2", method="PPG1",
                                     vc="VC2")
    assert r_all["basis"].vc_report.residual_after < 1e-8
    # the warning is earned: negative-real eigenvalues of the free tangent
    from skfem_pg.analysis.spectrum import free_modes
    from skfem_pg.materials import lame
    from skfem_pg.formulations import linear_elasticity
    b = r["basis"]
    K = pg.assemble(linear_elasticity(*lame(1.0, 0.4)), b)
    lam = np.asarray(free_modes(K, np.repeat(b.particles.volumes, 2))[
        "eigenvalues"]).real
    assert np.sum(lam < -1e-8 * np.abs(lam).max()) >= 1
    # the constraints hold in the bond-pair (element) view that assembles
    # PPG1, not only in the master view they were solved in
    from skfem_pg.discretization.vc.second_order import vc2_residuals
    b = r["basis"]
    p = b.particles
    r1, r2 = vc2_residuals(b.test.G, b.dx, b.families, p.x, p.volumes,
                           p.area_vectors(), p.area_moments())
    inner = np.setdiff1d(np.arange(p.n), m.boundary_nodes())
    assert np.abs(r1[inner]).max() < 1e-10
    assert np.abs(r2[inner]).max() < 1e-10
