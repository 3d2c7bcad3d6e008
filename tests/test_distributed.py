r"""PG on PETSc/MPI (skfem_pg.distributed) against the serial solutions.

Run on two ranks (what CI does, .ci/run):

    mpirun -n 2 python -m pytest -q -p no:cacheprovider \
        tests/test_distributed.py

On one rank (the plain test command) the same tests check the
distributed path with a single part; without mpi4py, petsc4py and
pymetis (the 'mpi' extra) they are skipped.
"""
import numpy as np
import pytest
import skfem as fem

import skfem_pg as pg
from skfem_pg.errors import ParticleError
from skfem_pg.analysis import PATCH_GRADIENT_2D as GEX
from skfem_pg.analysis import PATCH_GRADIENT_3D as GEX3
from skfem_pg.formulations import (CrackAware, CrackAwareU1SIG,
                                   CrackAwareUnlP0, Hyperelastic,
                                   linear_elasticity, model_for)
from skfem_pg.materials import (CriticalStrainDamage, J2Plasticity,
                                NeoHooke, NeoHookeIsoVol, lame)
from conftest import cube, square

pytest.importorskip("mpi4py")
pytest.importorskip("petsc4py")
pytest.importorskip("pymetis")

from mpi4py import MPI  # noqa: E402
from skfem_pg import distributed as dist  # noqa: E402

pytestmark = pytest.mark.mpi  # pytest -m mpi: these alone

COMM = MPI.COMM_WORLD
LAM, MU = lame(100.0, 0.3)
FORM = linear_elasticity(LAM, MU)


def same_on_all_ranks(u):
    """Every rank gathered the same vector."""
    return all(np.array_equal(u, v) for v in COMM.allgather(u))


def rel(u, ref):
    return np.abs(u - ref).max() / np.abs(ref).max()


def cantilever3d(n=5):
    """A distorted hex cube clamped at x = 0, a shear load at x = 1."""
    mesh = cube(n, 0.2, seed=2)
    e = fem.ElementVector(fem.ElementHex1())
    fb = fem.FacetBasis(mesh, e, facets=mesh.facets_satisfying(
        lambda x: np.isclose(x[0], 1)))
    f = fem.LinearForm(lambda v, w: 5.0 * v[2] + 1.0 * v[1]).assemble(fb)
    D = fem.Basis(mesh, e).get_dofs(lambda x: np.isclose(x[0], 0)).all()
    return mesh, f, D


def test_partition_owns_every_particle_once():
    mesh = square(12, 0.3, seed=1)
    part = dist.Partition(mesh, COMM)
    owned = np.concatenate(COMM.allgather(part.owned))
    assert np.array_equal(np.sort(owned), np.arange(mesh.nvertices))
    counts = part.counts
    assert counts.min() >= 0.8 * counts.max()  # METIS balance
    # PETSc numbering: each rank's particles contiguous, ascending
    ids = part.petsc_index[part.owned]
    assert np.array_equal(ids, np.arange(part.offsets[part.rank],
                                         part.offsets[part.rank + 1]))


def test_rank_families_are_the_serial_ones():
    """Families built from the rings of cells around the owned particles
    equal the serial families of those masters (members in order)."""
    mesh = cube(4, 0.25, seed=5, kind="tet")
    part = dist.Partition(mesh, COMM)
    serial = pg.families.from_mesh(mesh)
    mine = part.families()
    assert np.array_equal(mine.masters, part.owned)
    assert np.array_equal(mine.sizes, serial.sizes[part.owned])
    ref = np.concatenate([serial.members[serial.offsets[k]:
                                         serial.offsets[k + 1]]
                          for k in part.owned])
    assert np.array_equal(mine.members, ref)


@pytest.mark.parametrize("kw", [dict(), dict(vc=None),
                                dict(shape="WTE1", vc="V3", bond=True),
                                dict(vc_solver="petsc"),
                                dict(vc_solver="petsc", vc_boundary="p")])
def test_linear_elasticity_equals_serial(kw):
    mesh, f, D = cantilever3d()
    sb = pg.FamilyBasis(mesh, dim=3, **{k: v for k, v in kw.items()
                                        if k != "vc_solver"})
    u_s = fem.solve(*fem.condense(pg.assemble(FORM, sb), f, D=D))
    part = dist.Partition(mesh, COMM)
    basis = part.basis(dim=3, **kw)
    if kw.get("vc", "auto") is not None:
        assert basis.vc_report.residual_after < 1e-12
    u, info = dist.solve(pg.assemble(FORM, basis), part, f, D=D)
    assert rel(u, u_s) <= 1e-10  # measured 8e-13 (2 ranks)
    assert same_on_all_ranks(u)
    assert info["iterations"] < 100  # CG + GAMG with rigid-body modes


def _simplex_cantilever(kind):
    """A distorted triangle square or tetrahedron cube, clamped on one
    side, loaded on the opposite one: ``(mesh, f, D)``."""
    if kind == "tri":
        mesh, elem = square(8, 0.3, seed=3, kind="tri"), fem.ElementTriP1()
    else:
        mesh, elem = cube(4, 0.2, seed=4, kind="tet"), fem.ElementTetP1()
    e = fem.ElementVector(elem)
    fb = fem.FacetBasis(mesh, e, facets=mesh.facets_satisfying(
        lambda x: np.isclose(x[0], 1)))
    f = fem.LinearForm(lambda v, w: 1.0 * v[1] + 0.5 * v[0]).assemble(fb)
    D = fem.Basis(mesh, e).get_dofs(
        lambda x: np.isclose(x[0], -1 if kind == "tri" else 0)).all()
    return mesh, f, D


@pytest.mark.parametrize("kind, recipe", [("tri", "meshU"),
                                          ("tet", "kNN")])
def test_default_recipe_on_ranks_equals_serial(kind, recipe):
    """The keyword default's recipe on ranks (issue 45): 2-D triangles
    take ``meshU`` (uniform weights, unit bond weights), 3-D tetrahedra
    ``kNN`` (nearest families with ties, from the replicated positions),
    as serial :class:`~skfem_pg.FamilyBasis` does."""
    mesh, f, D = _simplex_cantilever(kind)
    d = mesh.dim()
    sb = pg.FamilyBasis(mesh, dim=d)
    assert sb.recipe == recipe
    u_s = fem.solve(*fem.condense(pg.assemble(FORM, sb), f, D=D))
    part = dist.Partition(mesh, COMM)
    basis = part.basis(dim=d)
    assert (basis.weights, basis.weight_exponent) == ("uniform", 0)
    u, _ = dist.solve(pg.assemble(FORM, basis), part, f, D=D)
    assert rel(u, u_s) <= 1e-10


@pytest.mark.parametrize("kind", ["tri", "tet"])
def test_moment_quadrature_on_ranks_equals_serial(kind):
    """``shape="WTE2", family_quadrature="moments"`` on ranks: the same
    families (1-ring enlarged to a quadratic fit), hat-function moments
    from the replicated mesh and the VC correction over the ranks give
    the serial solution."""
    mesh, f, D = _simplex_cantilever(kind)
    d = mesh.dim()
    kw = dict(shape="WTE2", family_quadrature="moments")
    sb = pg.FamilyBasis(mesh, dim=d, **kw)
    u_s = fem.solve(*fem.condense(pg.assemble(FORM, sb), f, D=D))
    part = dist.Partition(mesh, COMM)
    basis = part.basis(dim=d, **kw)
    assert basis.vc_report.residual_after < 1e-12
    u, _ = dist.solve(pg.assemble(FORM, basis), part, f, D=D)
    assert rel(u, u_s) <= 1e-10


def test_options_string_reaches_the_ksp():
    mesh, f, D = cantilever3d(3)
    sb = pg.FamilyBasis(mesh, dim=3)
    u_s = fem.solve(*fem.condense(pg.assemble(FORM, sb), f, D=D))
    part = dist.Partition(mesh, COMM)
    K = pg.assemble(FORM, part.basis(dim=3))
    u, info = dist.solve(K, part, f, D=D,
                         options="-ksp_type gmres -pc_type jacobi "
                         "-ksp_gmres_restart 400")
    assert rel(u, u_s) <= 1e-10
    assert info["iterations"] > 30  # Jacobi: far more than GAMG's
    with pytest.raises(ValueError, match="not an option"):
        dist.solve(K, part, f, D=D, options="ksp_type cg")
    with pytest.raises(ValueError, match="serial numbering"):
        dist.solve(K, part, f, D=[-1])


def test_neo_hooke_newton_equals_serial():
    mesh, f, D = cantilever3d(4)
    mat = NeoHooke(lam=LAM, mu=MU)
    u_s, _ = pg.solvers.newton(Hyperelastic(pg.FamilyBasis(mesh, dim=3),
                                            mat), 3 * f, D=D, steps=2,
                               tol=1e-12, verbose=False)
    part = dist.Partition(mesh, COMM)
    model = Hyperelastic(part.basis(dim=3), mat)
    u, hist = dist.newton(model, part, 3 * f, D=D, steps=2, tol=1e-12,
                          verbose=False)
    assert np.abs(u_s).max() > 0.1  # a nonlinear solve: 0.19 at the tip
    assert rel(u, u_s) <= 1e-10  # measured 5e-14
    assert hist[-1]["load"] == 1.0 and len(hist) >= 2  # steps adapt
    for h in hist:  # quadratic convergence: a few iterations per step
        assert len(h["residuals"]) <= 9
        assert h["residuals"][-1] <= 1e-10 * max(h["residuals"])


def test_prescribed_displacement_newton():
    """Displacement-driven: the prescribed values enter the first solve."""
    mesh = cube(3, 0.2, seed=4)
    mat = NeoHooke(lam=LAM, mu=MU)
    e = fem.ElementVector(fem.ElementHex1())
    fb = fem.Basis(mesh, e)
    D = fb.get_dofs(lambda x: np.isclose(x[0], 0) |
                    np.isclose(x[0], 1)).all()
    u_D = np.zeros(fb.N)
    right = fb.get_dofs(lambda x: np.isclose(x[0], 1)).nodal["u^1"]
    u_D[right] = 0.15
    u_s, _ = pg.solvers.newton(Hyperelastic(pg.FamilyBasis(mesh, dim=3),
                                            mat), D=D, u_D=u_D, steps=2,
                               tol=1e-12, verbose=False)
    part = dist.Partition(mesh, COMM)
    u, _ = dist.newton(Hyperelastic(part.basis(dim=3), mat), part, D=D,
                       u_D=u_D, steps=2, tol=1e-12, verbose=False)
    assert rel(u, u_s) <= 1e-10
    # the same run posed as a Problem (serial vectors, the rank's model)
    problem = pg.Problem(Hyperelastic(part.basis(dim=3), mat), D=D, u_D=u_D)
    sol = dist.newton(problem, part, steps=2, tol=1e-12, verbose=False)
    assert np.array_equal(sol.x, u)


@pytest.mark.parametrize("kw", [dict(), dict(vc_boundary="p"),
                                dict(shape="WTE1", bond=False, vc="V3")])
def test_patch_test(kw):
    """Linear field on the boundary of a distorted square: exact inside."""
    mesh = square(10, 0.3, seed=7, kind="tri")
    part = dist.Partition(mesh, COMM)
    basis = part.basis(dim=2, **kw)
    D = fem.Basis(mesh, fem.ElementVector(fem.ElementTriP1())).get_dofs()
    uex = (GEX @ mesh.p).T.ravel()
    u, _ = dist.solve(pg.assemble(FORM, basis), part, D=D, u_D=uex)
    assert np.abs(u - uex).max() <= 1e-10  # measured 1e-13


@pytest.mark.parametrize("vc_solver", ["direct", "petsc"])
def test_patch_test_3d(vc_solver):
    """Also with the VC system solved on all ranks (GMRES, no gather)."""
    mesh = cube(4, 0.25, seed=3, kind="tet")
    part = dist.Partition(mesh, COMM)
    basis = part.basis(dim=3, vc_solver=vc_solver)
    assert basis.vc_report.solver.startswith(vc_solver)
    D = fem.Basis(mesh, fem.ElementVector(fem.ElementTetP1())).get_dofs()
    uex = (GEX3 @ mesh.p).T.ravel()
    u, _ = dist.solve(pg.assemble(FORM, basis), part, D=D, u_D=uex)
    assert np.abs(u - uex).max() <= 1e-10


def test_ppg1_equals_serial():
    """PPG1: pairwise families across ranks, test derivatives from the
    halo's families, GMRES."""
    mesh = square(12, 0.3, seed=3, kind="tri")
    top = mesh.facets_satisfying(lambda x: np.isclose(x[1], 1))
    sb = pg.FamilyBasis(mesh, dim=2, method="PPG1")
    f = pg.traction(sb, top, [0.3, -1.0])
    D = sb.get_dofs(mesh.facets_satisfying(lambda x: np.isclose(x[1], -1)))
    u_s = fem.solve(*fem.condense(pg.assemble(FORM, sb), f, D=D))
    part = dist.Partition(mesh, COMM)
    basis = part.basis(dim=2, method="PPG1")
    assert basis.test is not None
    u, _ = dist.solve(pg.assemble(FORM, basis), part, f, D=D,
                      symmetric=False)  # a DofsView
    assert rel(u, u_s) <= 1e-10  # measured 3e-13


def test_coupled_fe_pg_patch_test():
    """Q1 on the left, PG on the right, one PETSc system."""
    mesh = square(10, 0.3, seed=7)
    left = mesh.elements_satisfying(lambda x: x[0] < 0)
    right = mesh.elements_satisfying(lambda x: x[0] >= 0)
    e = fem.ElementVector(fem.ElementQuad1())
    fe = fem.Basis(mesh, e, elements=left)
    pgb = pg.FamilyBasis(pg.Particles.from_mesh(mesh, elements=right),
                         dim=2)
    eps = 0.5 * (GEX + GEX.T)
    sigma = 2 * MU * eps + LAM * np.trace(eps) * np.eye(2)
    top = mesh.facets_satisfying(lambda x: np.isclose(x[1], 1))
    f = pg.stress_load(pgb, top, sigma)
    D = fe.get_dofs(lambda x: np.isclose(np.abs(x[0]), 1) |
                    np.isclose(x[1], -1)).all()
    uex = (GEX @ mesh.p).T.ravel()
    K_s = FORM.assemble(fe) + pg.assemble(FORM, pgb)
    u_s = fem.solve(*fem.condense(K_s, f, x=uex, D=D))
    part = dist.Partition(mesh, COMM, elements=right)
    basis = part.basis(dim=2)
    K = pg.assemble(FORM, basis) + part.fe_assemble(FORM, e)
    u, _ = dist.solve(K, part, f, D=D, u_D=uex)
    assert np.abs(u - uex).max() <= 1e-10  # measured 1e-13
    assert rel(u, u_s) <= 1e-10
    cells = COMM.allreduce(len(part.fe_cells))
    assert cells == len(left)


def test_dofs_without_stiffness_are_named():
    """A PG element subset solved without its FE cells: the vertices outside
    the subset have no stiffness (was PETSc error 73 from
    MatZeroRowsColumns, 'missing diagonal entry')."""
    from skfem_pg.errors import SingularSystemError
    mesh = square(10, 0.3, seed=7)
    right = mesh.elements_satisfying(lambda x: x[0] >= 0)
    part = dist.Partition(mesh, COMM, elements=right)
    K = pg.assemble(FORM, part.basis(dim=2))
    D = np.arange(2 * mesh.nvertices)[::7]  # row 0 prescribed, too
    with pytest.raises(SingularSystemError, match="no stiffness.*particle"):
        dist.solve(K, part, np.zeros(2 * mesh.nvertices), D=D)


def test_ranks_with_different_meshes_are_refused():
    """Was a CorrectionError about families on the ranks."""
    mesh = square(6, 0.2, seed=1 + (COMM.rank > 0))
    if COMM.size == 1:
        dist.Partition(mesh, COMM)  # one rank: nothing to compare
        return
    with pytest.raises(ValueError, match="same mesh: rank 1 differs"):
        dist.Partition(mesh, COMM)
    same = square(6, 0.2, seed=1)
    right = same.elements_satisfying(lambda x: x[0] >= 0)
    with pytest.raises(ValueError, match="same elements"):
        dist.Partition(same, COMM, elements=right if COMM.rank == 0
                       else np.arange(3))


def test_unsupported_options_are_refused():
    mesh = square(6)
    part = dist.Partition(mesh, COMM)
    for kw, what in ((dict(method="PPG2"), "PPG2"), (dict(vc="V4"), "V4"),
                     (dict(shape="WTE2", bond=False), "WTE2"),
                     (dict(vc_boundary="s"), "vc_boundary")):
        with pytest.raises(NotImplementedError, match=what):
            part.basis(dim=2, **kw)


def test_bad_owner_is_refused():
    mesh = square(4)
    with pytest.raises(ValueError, match="owner"):
        dist.Partition(mesh, COMM, owner=np.full(mesh.nvertices, 99))
    if COMM.size > 1:
        with pytest.raises(ValueError, match="owns no particle"):
            dist.Partition(mesh, COMM,
                           owner=np.zeros(mesh.nvertices, dtype=int))


def test_scene_result_on_ranks():
    """Scene.solve(..., comm=...) returns the serial Result's fields:
    displacements, probes, reactions."""
    from skfem_pg.scenes import Scene
    mesh = cube(3, 0.2, seed=6).with_boundaries(
        {"left": lambda x: np.isclose(x[0], 0),
         "right": lambda x: np.isclose(x[0], 1)})
    sc = Scene("cube", mesh, NeoHooke(lam=LAM, mu=MU), clamped=["left"],
               tractions={"right": [0.0, 0.0, 2.0]},
               probes={"corner": (1.0, 1.0, 1.0)}, steps=2)
    r_s = sc.solve("VCPBG V5m Unl", tol=1e-12)
    r = sc.solve("VCPBG V5m Unl", tol=1e-12, comm=COMM)
    assert rel(r.u, r_s.u) <= 1e-10
    assert np.allclose(r.probes["corner"], r_s.probes["corner"],
                       rtol=1e-10, atol=0)
    assert np.allclose(r.reaction("left"), r_s.reaction("left"),
                       rtol=1e-8, atol=1e-10)
    assert abs(r.reaction("left")[2] + 2.0) < 1e-8  # balances the load
    with pytest.raises(NotImplementedError, match="UnlP0"):
        sc.solve("VCPBG V5m UnlP0", comm=COMM)


def test_options_do_not_leak_into_the_next_solve():
    from petsc4py import PETSc
    mesh, f, D = cantilever3d(2)
    part = dist.Partition(mesh, COMM)
    K = pg.assemble(FORM, part.basis(dim=3))
    dist.solve(K, part, f, D=D, options="-ksp_type gmres -pc_type jacobi")
    A = dist.petsc.matrix(K, part)
    ksp = dist.petsc.krylov(A, part)
    assert (ksp.getType(), ksp.getPC().getType()) == ("cg", "gamg")
    assert not PETSc.Options().hasName("skfem_pg_pc_type")
    # options GAMG reads at set-up (its levels') reach it too
    smoother_its = ksp.getPC().getMGSmoother(1).getTolerances()[3]
    ksp = dist.petsc.krylov(A, part, options="-mg_levels_ksp_max_it 3")
    assert ksp.getPC().getMGSmoother(1).getTolerances()[3] == 3
    assert smoother_its != 3
    dist.petsc.release_options(ksp)  # a KSP not solved: its options go
    assert not PETSc.Options().hasName("skfem_pg_mg_levels_ksp_max_it")


def test_bad_options_are_named_and_leave_no_state_behind():
    """A typo is reported (it used to be dropped unread), a value PETSc
    rejects raises and the next solve (no options) still works, a solver
    that does not solve (preonly + none) is caught by the true residual,
    and a system without Dirichlet conditions is singular (it used to
    "converge" to 1e13)."""
    from skfem_pg.errors import SingularSystemError
    mesh, f, D = cantilever3d(2)
    part = dist.Partition(mesh, COMM)
    K = pg.assemble(FORM, part.basis(dim=3))
    ref, _ = dist.solve(K, part, f, D=D)
    with pytest.raises(ValueError, match="did not use the options "
                       "-ksp_tyep"):
        dist.solve(K, part, f, D=D, options="-ksp_tyep gmres")
    with pytest.raises(ValueError, match="rejected the options"):
        dist.solve(K, part, f, D=D, options="-ksp_type cgg")
    u, _ = dist.solve(K, part, f, D=D)
    assert rel(u, ref) <= 1e-10
    with pytest.raises(dist.petsc.KSPError, match="true relative residual"):
        dist.solve(K, part, f, D=D, options="-ksp_type preonly "
                   "-pc_type none")
    with pytest.raises(SingularSystemError, match="6 of its 6"):
        dist.solve(K, part, f, D=[])


def test_parallel_vtu():
    """One piece per rank, the .pvtu names them; the pieces hold every
    cell once and the gathered values at their points."""
    import os
    import tempfile
    import xml.etree.ElementTree as ET
    import meshio
    mesh = cube(3, 0.2, seed=1)
    part = dist.Partition(mesh, COMM)
    part.basis(dim=3)
    u = np.arange(3 * mesh.nvertices, dtype=float)
    root = COMM.bcast(tempfile.mkdtemp() if COMM.rank == 0 else None)
    name = os.path.join(root, "cube.pvtu")
    dist.write_pvtu(name, part, u=u)
    sources = [p.get("Source") for p in ET.parse(name).iter("Piece")]
    assert len(sources) == COMM.size
    cells = 0
    for s in sources:
        m = meshio.read(os.path.join(root, s))
        cells += len(m.cells[0].data)
        k = np.argmin(((m.points[:, None, :] - mesh.p.T[None]) ** 2)
                      .sum(-1), axis=1)
        assert np.array_equal(m.point_data["u"], u.reshape(-1, 3)[k])
    assert cells == mesh.nelements
    with pytest.raises(ValueError, match="pvtu"):
        dist.write_pvtu(os.path.join(root, "cube.vtu"), part, u=u)


def test_a_set_in_pieces_on_ranks():
    """Two bodies in one particle set: rank 0's pinned solve pins each
    piece (the patch test holds on both); the all-ranks solve, which pins
    one piece, refuses by name."""
    a = fem.MeshTri.init_tensor(np.linspace(0, 1, 7), np.linspace(0, 1, 6))
    b = fem.MeshTri.init_tensor(np.linspace(2, 3, 6), np.linspace(0, 1, 8))
    both = fem.MeshTri(np.hstack([a.p, b.p]),
                       np.hstack([a.t, b.t + a.p.shape[1]]))
    part = dist.Partition(both, COMM)
    with pytest.raises(NotImplementedError, match="2 pieces"):
        part.basis(dim=2, vc_solver="petsc")
    basis = part.basis(dim=2, vc_solver="direct")
    assert basis.vc_report.residual_after < 1e-12
    D = fem.Basis(both, fem.ElementVector(fem.ElementTriP1())).get_dofs()
    uex = (GEX @ both.p).T.ravel()
    u, _ = dist.solve(pg.assemble(FORM, basis), part, D=D, u_D=uex)
    assert np.abs(u - uex).max() <= 1e-10


# -- explicit central differences on ranks ------------------------------------
def _plate(n=9):
    """A plate of 9 × 17 nodes thrown (and turning) at a rigid wall."""
    mesh = fem.MeshQuad.init_tensor(np.linspace(0, 1, n),
                                    np.linspace(0, 2, 2 * n - 1))
    v = np.zeros_like(mesh.p)
    v[1] = -3.0 - 0.3 * mesh.p[0]
    v[0] = 0.2 * mesh.p[1]
    return mesh, v.T.ravel()


def _wall():
    from skfem_pg.solvers import RigidWall
    return RigidWall(axis=1, position=0.0, side=1)


ACCOUNTS = ("kinetic", "internal_work", "external_work", "contact_loss",
            "stored", "dissipation", "error")


def assert_runs_agree(td, ts, tol=1e-10, wall=True):
    """Same steps, same times; displacements, velocities and every energy
    account of the last record to ``tol`` relative (the accounts'
    differences relative to the largest account); with ``wall`` the wall
    acted."""
    assert same_on_all_ranks(td.x)
    assert td.steps == ts.steps >= 100 and td.t == ts.t
    assert rel(td.x, ts.x) <= tol and rel(td.v, ts.v) <= tol
    a, b = td.history[-1], ts.history[-1]
    scale = max(abs(b[k]) for k in ACCOUNTS)
    for k in ACCOUNTS:
        assert abs(a[k] - b[k]) <= tol * scale, k
    assert b["contact_loss"] > 0 or not wall


T_END = 0.3  # over 100 steps
LAME = dict(zip(("lam", "mu"), lame(1000.0, 0.3)))
# the moduli these runs have always used: they were written
# J2Plasticity(*lame(1000.0, 0.3), ...), Lamé's (lam, mu) landing on
# (mu, K) -- the trap the keyword-only constructors close (nu = 0 here).
# With E = 1000, nu = 0.3 the damaged U1SIG plate's ranks differ from
# serial by 3.6e-9 relative: a failure whose threshold round-off decides
# (issue 51)
J2_MODULI = dict(mu=LAME["lam"], K=LAME["mu"])
J2 = J2Plasticity(**J2_MODULI, sigma_y0=5.0)
J2_DAMAGE = J2Plasticity(**J2_MODULI, sigma_y0=1e3,  # brittle: no yield
                         damage=CriticalStrainDamage(0.03))


@pytest.mark.parametrize("formulation, material", [
    ("Unl", NeoHooke(**LAME)), ("UnlP0", J2), ("U1SIG", J2),
    ("U1SIG", J2_DAMAGE)])
def test_explicit_pg_equals_serial(formulation, material):
    """A thrown plate hitting a wall: the run on ranks takes the serial
    steps (stable steps by distributed Lanczos) to round-off, plastic
    history per rank included."""
    mesh, v0 = _plate()
    t_end = 1.5 * T_END if material is J2_DAMAGE else T_END  # >= 100 steps
    sb = pg.FamilyBasis(mesh, dim=2)
    ts = pg.central_difference(model_for(formulation, sb, material),
                               pg.lumped_mass(sb, 1.0), t_end, v0=v0,
                               wall=_wall(), verbose=False)
    part = dist.Partition(mesh, COMM)
    b = part.basis(dim=2)
    td = dist.central_difference(model_for(formulation, b, material), part,
                                 dist.lumped_mass(b, part, 1.0), t_end, v0=v0,
                                 wall=_wall(), verbose=False)
    assert_runs_agree(td, ts)
    if material is J2_DAMAGE:
        fracture = ts.history[-1]["fracture"]
        assert fracture > 0  # points failed (damage on ranks)
        assert abs(td.history[-1]["fracture"] - fracture) <= 1e-10 * abs(
            ts.history[-1]["kinetic"] + fracture)
    elif material is J2:
        assert ts.history[-1]["dissipation"] > 0


@pytest.mark.parametrize("element", [fem.ElementQuad1(),
                                     fem.ElementTriP1()])
def test_explicit_fe_equals_serial(element):
    """The FE comparator on ranks: each rank assembles its cells; the
    lumped mass and the forces are summed to the vertices' owners."""
    mesh, v0 = _plate()
    if isinstance(element, fem.ElementTriP1):
        mesh = fem.MeshTri.init_tensor(np.linspace(0, 1, 9),
                                       np.linspace(0, 2, 17))
    e = fem.ElementVector(element)
    material = NeoHooke(**LAME)
    sb = fem.Basis(mesh, e)
    ts = pg.central_difference(Hyperelastic(sb, material),
                               pg.lumped_mass(sb, 1.0), T_END, v0=v0,
                               wall=_wall(), verbose=False)
    part = dist.Partition(mesh, COMM, fe_elements=np.arange(mesh.nelements))
    b = part.fe_basis(e)
    wall = _wall()
    td = dist.central_difference(Hyperelastic(b, material), part,
                                 dist.lumped_mass(b, part, 1.0), T_END, v0=v0,
                                 wall=wall, verbose=False)
    assert_runs_agree(td, ts)
    assert wall.tol is None  # the caller's wall is not changed
    problem = pg.Problem(Hyperelastic(b, material), walls=wall,
                         mass=dist.lumped_mass(b, part, 1.0))
    tp = dist.central_difference(problem, part, t_end=T_END, v0=v0,
                                 verbose=False)
    assert np.array_equal(tp.x, td.x) and tp.steps == td.steps


def _killed_at(call):
    """``(Stop, callback)``: the callback raises ``Stop`` at its
    ``call``-th call (a run killed in the middle)."""
    class Stop(Exception):
        pass

    count = [0]

    def kill(*args):
        count[0] += 1
        if count[0] == call:
            raise Stop
    return Stop, kill


def test_explicit_checkpoint_restart_on_ranks():
    """Killed at step 60 of a run writing every 25 steps: every rank
    wrote its piece of step 50, rank 0 the manifest; the resumed run ends
    where the uninterrupted and the serial ones do."""
    import os
    import tempfile
    from skfem_pg.solvers import checkpoint
    mesh, v0 = _plate()
    sb = pg.FamilyBasis(mesh, dim=2)
    ts = pg.central_difference(model_for("UnlP0", sb, J2),
                               pg.lumped_mass(sb, 1.0), T_END, v0=v0,
                               wall=_wall(), verbose=False)
    part = dist.Partition(mesh, COMM)
    b = part.basis(dim=2)
    m = dist.lumped_mass(b, part, 1.0)
    root = COMM.bcast(tempfile.mkdtemp() if COMM.rank == 0 else None)
    path = os.path.join(root, "drop")

    Stop, kill = _killed_at(61)
    with pytest.raises(Stop):
        dist.central_difference(model_for("UnlP0", b, J2), part, m, T_END,
                                v0=v0, wall=_wall(), verbose=False,
                                callback=kill, output_every=1,
                                checkpoint=checkpoint.Every(path, steps=25))
    COMM.barrier()
    names = sorted(os.listdir(root))
    assert names == ["drop.npz"] + ["drop.rank{}.step50.npz".format(r)
                                    for r in range(COMM.size)]
    td = dist.central_difference(model_for("UnlP0", b, J2), part, m, T_END,
                                 v0=v0, wall=_wall(), verbose=False,
                                 resume=path)
    assert_runs_agree(td, ts)


def test_explicit_refusals_on_ranks():
    """What the explicit driver on ranks does not take is named."""
    mesh, v0 = _plate(5)
    part = dist.Partition(mesh, COMM)
    b = part.basis(dim=2)
    m = dist.lumped_mass(b, part, 1.0)
    model = Hyperelastic(b, NeoHooke(**LAME))
    with pytest.raises(ValueError, match="serial vector of 90 entries"):
        dist.central_difference(model, part, m, 0.01, v0=v0[:-2],
                                verbose=False)
    # nodal fields (Unl+P1C) need a family at every particle: a rank's
    # part refuses them (the driver would: "beyond the displacements")
    with pytest.raises((NotImplementedError, ParticleError),
                       match="beyond the displacements|masters no family"):
        dist.central_difference(model_for("Unl+P1C", b, J2), part, m, 0.01,
                                verbose=False)
    # crack-aware families rebuild from the partition's mesh: its
    # particles must be the mesh's vertices
    cent = dist.Partition(mesh, COMM)
    cent.particles = pg.Particles.from_mesh(mesh, kind="centroids")
    b.distributed = cent
    with pytest.raises(ValueError, match="collocation mesh"):
        CrackAware(b, J2_DAMAGE)


# -- crack-aware families on ranks --------------------------------------------
def _notched_strip_run(kind, vc_solver, part=None, **kw):
    """The notched strip of ``test_fracture`` (4 x 8 cells) pulled apart
    with crack-aware families (Johnson–Cook damage), serial or on the
    ranks of ``part``: ``(model, trajectory)``."""
    from test_fracture import HEIGHT, RHO, STEEL, strip
    mesh, _ = strip(4, notch_cells=True)
    opts = dict(dim=2, vc_solver=vc_solver)
    if kind == "U1SIG":
        opts.update(shape="WTE1", bond=False, vc="V3")
    Model = {"U1SIG": CrackAwareU1SIG, "UnlP0": CrackAwareUnlP0}.get(
        kind, CrackAware)
    t_end, speed, ramp = 0.003, 2000.0, 0.0003
    X = np.repeat(mesh.p, 2, axis=1)  # serial dof locations
    N = X.shape[1]
    top = np.flatnonzero(X[1] > HEIGHT - 1e-9)
    D = np.concatenate([np.flatnonzero(X[1] < 1e-9), top])

    def u_D(t):
        u = np.zeros(N)
        u[top[top % 2 == 1]] = speed * (
            (t - ramp / np.pi * np.sin(np.pi * t / ramp)) / 2 if t < ramp
            else t - ramp / 2)
        return u
    if part is None:
        b = pg.FamilyBasis(mesh, **opts)
        model = Model(b, STEEL)
        return model, pg.central_difference(
            model, pg.lumped_mass(b, RHO), t_end, D=D, u_D=u_D,
            verbose=False, **kw)
    b = part.basis(**opts)
    model = Model(b, STEEL)
    return model, dist.central_difference(
        model, part, dist.lumped_mass(b, part, RHO), t_end, D=D, u_D=u_D,
        verbose=False, **kw)


def test_restricted_basis_keeps_the_local_particles():
    """``Partition.restricted(cells).basis(local=...)``: the basis on
    fewer cells shares the first basis' dofs; a vertex of no kept cell
    masters no family; local particles that do not start with the owned
    ones, or miss a member, are refused by name."""
    from skfem_pg.errors import FamilyError
    mesh, _ = _plate(5)
    part = dist.Partition(mesh, COMM)
    b = part.basis(dim=2)
    local = part.local.copy()
    c = mesh.p[:, mesh.t].mean(axis=1)
    keep = np.flatnonzero(~((c[0] < 0.25) & (c[1] < 0.25)))  # corner cut
    sub = part.restricted(keep)
    b2 = sub.basis(local=local, dim=2)
    assert b2.N == b.N and np.array_equal(sub.local, local)
    corner = np.flatnonzero((mesh.p[0] < 1e-9) & (mesh.p[1] < 1e-9))
    masters = np.concatenate(COMM.allgather(local[b2.families.masters]))
    assert corner[0] not in masters and len(masters) == part.n - 1
    with pytest.raises(ValueError, match="PG cells"):
        dist.Partition(mesh, COMM, elements=keep).restricted(
            np.arange(mesh.nelements))
    if len(part.owned) > 1:
        with pytest.raises(ValueError, match="start with the rank's owned"):
            sub.basis(local=local[::-1], dim=2)
    if len(local) > len(part.owned):  # a halo: leave it out
        with pytest.raises(FamilyError, match="beyond the rank's local"):
            sub.basis(local=part.owned, dim=2)


def test_an_error_on_one_rank_is_raised_on_every_rank():
    """A basis that fails on rank 0 only (its local particles out of
    order) raises there and, naming rank 0, on every other rank: no rank
    is left waiting in the basis' collectives."""
    mesh, _ = _plate(5)
    part = dist.Partition(mesh, COMM)
    part.basis(dim=2)
    local = part.local.copy()
    if COMM.rank == 0:
        local[[0, 1]] = local[[1, 0]]
    error = ValueError if COMM.rank == 0 else RuntimeError
    with pytest.raises(error, match="start with the rank's owned"):
        part.basis(local=local, dim=2)
    assert COMM.allreduce(1) == COMM.size  # every rank got here


@pytest.mark.parametrize("kind, vc_solver", [
    ("Unl", "local"), ("U1SIG", "local"), ("Unl", "auto"),
    ("UnlP0", "local")])
def test_explicit_crack_aware_equals_serial(kind, vc_solver):
    """Crack-aware families on ranks: the cell failures are counted over
    the ranks, every rank fails the same cells and rebuilds its part of
    the basis on its local particles (local VC: no communication; global:
    rank 0's solve).  Same steps, updates and intact cells as the serial
    run; x, v and every energy account to 1e-10 (measured: 241 steps, 3
    updates, x 6.6e-15 (Unl, local); 213 steps, 5 updates, 4.3e-13
    (U1SIG); 334 steps, 3 updates, 1.4e-15 (Unl, global VC); 232 steps,
    3 updates, 6.2e-15 (UnlP0, local))."""
    ms, ts = _notched_strip_run(kind, vc_solver)
    part = dist.Partition(ms._mesh, COMM)
    md, td = _notched_strip_run(kind, vc_solver, part)
    assert_runs_agree(td, ts, wall=False)
    assert md.updates == ms.updates >= 2
    assert np.array_equal(md.intact, ms.intact)
    fracture = ts.history[-1]["fracture"]
    # UnlP0's updates can release a negative energy (CrackAwareUnlP0)
    assert fracture > 0 or kind == "UnlP0" and fracture != 0
    assert abs(td.history[-1]["fracture"] - fracture) <= 1e-10 * abs(
        fracture)
    if vc_solver == "local":
        assert md.point_basis.vc_report.solver == "local"


def test_crack_aware_checkpoint_after_an_update_on_ranks():
    """A run on ranks killed after the crack has formed resumes from the
    pieces (each rank rebuilds its part of the basis on the saved intact
    cells) and ends where the serial run ends."""
    import os
    import tempfile
    from skfem_pg.solvers import checkpoint
    ms, ts = _notched_strip_run("Unl", "local")
    part = dist.Partition(ms._mesh, COMM)
    root = COMM.bcast(tempfile.mkdtemp() if COMM.rank == 0 else None)
    path = os.path.join(root, "crack")

    Stop, kill = _killed_at(221)
    with pytest.raises(Stop):
        _notched_strip_run("Unl", "local", part, callback=kill,
                           output_every=1,
                           checkpoint=checkpoint.Every(path, steps=200))
    COMM.barrier()
    with np.load(os.path.join(root, "crack.rank0.step200.npz")) as f:
        assert not (f["history_crack_intact"] > 0.5).all()  # after a crack
    md, td = _notched_strip_run("Unl", "local", part, resume=path)
    assert_runs_agree(td, ts, wall=False)
    assert np.array_equal(md.intact, ms.intact)


# -- local VC: no global system ----------------------------------------------
@pytest.mark.parametrize("dim", [2, 3])
def test_local_vc_patch_test_on_ranks(dim):
    """``vc_solver="local"``: each rank corrects its own families (no
    system on rank 0); the patch test holds and the basis is the serial
    one (the serial solution to round-off)."""
    if dim == 2:
        mesh = square(10, 0.3, seed=7, kind="tri")
        e, G = fem.ElementVector(fem.ElementTriP1()), GEX
    else:
        mesh = cube(4, 0.25, seed=3)
        e, G = fem.ElementVector(fem.ElementHex1()), GEX3
    part = dist.Partition(mesh, COMM)
    basis = part.basis(dim=dim, vc_solver="local")
    assert basis.vc_report.solver == "local"
    assert basis.vc_report.residual_after < 1e-12
    D = fem.Basis(mesh, e).get_dofs()
    uex = (G @ mesh.p).T.ravel()
    u, _ = dist.solve(pg.assemble(FORM, basis), part, D=D, u_D=uex)
    assert np.abs(u - uex).max() <= 1e-10
    # a load: the serial local-VC solution
    sb = pg.FamilyBasis(mesh, dim=dim, vc_solver="local")
    Dl = fem.Basis(mesh, e).get_dofs(
        lambda x: np.isclose(x[0], mesh.p[0].min())).all()
    f = np.zeros(sb.N)
    f[1::dim] = 1e-3
    u_s = fem.solve(*fem.condense(pg.assemble(FORM, sb), f, D=Dl))
    u, _ = dist.solve(pg.assemble(FORM, basis), part, f, D=Dl,
                      options="-ksp_rtol 1e-13")
    assert rel(u, u_s) <= 1e-9


# -- family-local mixed fields in Newton -------------------------------------
@pytest.mark.parametrize("formulation, material", [
    ("UnlP0", NeoHookeIsoVol(mu=MU, K=LAM + 2 * MU / 3)),
    ("UnlP0", J2Plasticity(mu=LAM, K=MU, sigma_y0=20.0)),
    ("U1SUnl", J2Plasticity(mu=LAM, K=MU, sigma_y0=20.0)),
    ("U1SIG", J2Plasticity(mu=LAM, K=MU, sigma_y0=20.0))])
def test_condensed_mixed_newton_equals_serial(formulation, material):
    """UnlP0 (a pressure and dilatation per family, condensed), U1SUnl
    (its U1 basis and the full-integration stabilization, both on the
    rank) and U1SIG (the stabilization at the masters) in the distributed
    Newton, elastic and plastic (history per rank): the serial solution
    to round-off."""
    mesh, f, D = cantilever3d(4)
    load = 0.5 * f  # tip 0.19, max e_p 0.11 (UnlP0), 0.024 (U1SIG)
    ms = model_for(formulation, pg.FamilyBasis(mesh, dim=3), material)
    u_s, hs = pg.solvers.newton(ms, load, D=D, steps=2, tol=1e-12,
                                verbose=False)
    part = dist.Partition(mesh, COMM)
    md = model_for(formulation, part.basis(dim=3), material)
    u, hist = dist.newton(md, part, load, D=D, steps=2, tol=1e-12,
                          verbose=False)
    assert rel(u, u_s) <= 1e-10
    assert [h["load"] for h in hist] == [h["load"] for h in hs]
    if isinstance(material, J2Plasticity):
        ep_s = ms.plastic_strain()[1]
        ep = max(COMM.allgather(md.plastic_strain()[1]))
        assert ep_s > 0 and abs(ep - ep_s) <= 1e-10 * ep_s


def test_mpi_guide_blocks_run_on_the_ranks():
    """The MPI guide's code blocks (docs/guide/mpi.md) run as written on
    these ranks, each in a namespace of its own (tests/test_doc_blocks.py
    runs the serial pages' blocks)."""
    import os
    import tempfile
    from test_doc_blocks import MPI_PAGES, HAS_DOCS, blocks, run_doc_block
    if not HAS_DOCS:
        pytest.skip("needs the source tree's docs/")
    root = COMM.bcast(tempfile.mkdtemp() if COMM.rank == 0 else None)
    here = os.getcwd()
    try:
        os.chdir(root)
        found = 0
        for page in MPI_PAGES:
            for line, code in blocks(page):
                run_doc_block(code, "{}:{}".format(page, line))
                found += 1
        assert found == 2
        COMM.Barrier()
        assert os.path.isfile("u.pvtu")
    finally:
        os.chdir(here)
