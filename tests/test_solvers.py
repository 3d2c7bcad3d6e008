"""Newton with adaptive load steps on PG and FE bases."""
import numpy as np
import pytest
import scipy.sparse as sp
import skfem as fem

import skfem_pg as pg
from skfem_pg import materials as mat
from skfem_pg.formulations import linear_elasticity
from skfem_pg.formulations import Hyperelastic
from skfem_pg.solvers import newton, linear_solver, ConvergenceError

LAM, MU = 100.0, 40.0


@pytest.fixture(scope="module")
def beam():
    mesh = pg.meshing.distort(fem.MeshQuad.init_tensor(
        np.linspace(0, 4, 17), np.linspace(0, 1, 5)), 0.3, seed=1)
    mesh = mesh.with_boundaries({"left": lambda x: np.isclose(x[0], 0),
                                 "right": lambda x: np.isclose(x[0], 4)})
    return mesh, pg.FamilyBasis(pg.Particles.from_mesh(mesh), dim=2)


def test_small_load_matches_linear_solution(beam):
    mesh, b = beam
    f = pg.traction(b, "right", [0.0, 1e-4])
    D = b.get_dofs("left")
    u, hist = newton(Hyperelastic(b, mat.NeoHooke(lam=LAM, mu=MU)), f, D=D,
                     verbose=False)
    ul = fem.solve(*fem.condense(pg.assemble(linear_elasticity(LAM, MU), b),
                                 f, D=D))
    assert np.abs(u - ul).max() <= 1e-4 * np.abs(ul).max()


def test_newton_converges_quadratically(beam):
    mesh, b = beam
    f = pg.traction(b, "right", [0.0, 0.5])
    u, hist = newton(Hyperelastic(b, mat.NeoHooke(lam=LAM, mu=MU)), f,
                     D=b.get_dofs("left"),
                     tol=1e-12, verbose=False)
    r = np.array(hist[-1]["residuals"])
    r = r / r[0]
    print("relative residuals:", r)
    # pairs above the round-off floor (~1e-12 relative here)
    late = np.nonzero((r[:-1] < 1e-1) & (r[1:] > 1e-10))[0]
    assert len(late) >= 2
    for k in late:
        assert r[k + 1] <= 10 * r[k] ** 2


def test_step_is_cut_when_J_becomes_negative(beam):
    mesh, b = beam
    f = pg.traction(b, "right", [0.0, 2.0])
    u, hist = newton(Hyperelastic(b, mat.NeoHooke(lam=LAM, mu=MU)), f,
                     D=b.get_dofs("left"),
                     steps=1, verbose=False)
    assert len(hist) >= 2 and hist[-1]["load"] == 1.0
    assert min(h["min_J"] for h in hist) > 0


def test_impossible_compression_reports_the_load_factor(beam):
    mesh, b = beam
    D = b.get_dofs({"left", "right"})
    u_D = np.zeros(b.N)
    right = b.get_dofs("right").nodal["u^1"]
    u_D[right] = -5.0  # squeeze a bar of length 4 by 5
    with pytest.raises(ConvergenceError, match="load factor") as err:
        newton(Hyperelastic(b, mat.NeoHooke(lam=LAM, mu=MU)), D=D, u_D=u_D, steps=2,
               min_step=1 / 16, verbose=False)
    # the last converged state is reported: a bar of length 4 cannot be
    # squeezed by more than 4
    assert 0 < err.value.load < 0.8
    assert np.all(err.value.u[right] == err.value.load * -5.0)


def test_same_newton_on_scikit_fem_q1(beam):
    mesh, _ = beam
    fe = fem.Basis(mesh, fem.ElementVector(fem.ElementQuad1()))
    fb = fem.FacetBasis(mesh, fem.ElementVector(fem.ElementQuad1()),
                        facets="right")
    f = fem.LinearForm(lambda v, w: 1e-4 * v[1]).assemble(fb)
    D = fe.get_dofs("left")
    u, _ = newton(Hyperelastic(fe, mat.NeoHooke(lam=LAM, mu=MU)), f, D=D,
                  verbose=False)
    ul = fem.solve(*fem.condense(linear_elasticity(LAM, MU).assemble(fe), f,
                                 D=D))
    assert np.abs(u - ul).max() <= 1e-4 * np.abs(ul).max()


def test_amg_with_rigid_body_modes_matches_direct():
    mesh = fem.MeshQuad.init_tensor(*[np.linspace(0, 1, 41)] * 2)
    b = pg.FamilyBasis(pg.Particles.from_mesh(mesh), dim=2)
    K = pg.assemble(linear_elasticity(LAM, MU), b)
    f = pg.body_force(b, [0.0, -1.0])
    D = b.get_dofs(lambda x: np.isclose(x[0], 0))
    I = b.complement_dofs(D)
    A, rhs = K[I][:, I].tocsr(), f[I]
    x_direct = linear_solver("direct")(A, rhs)
    x_amg = linear_solver("amg", b.doflocs[:, I], tol=1e-12)(A, rhs)
    assert np.abs(x_amg - x_direct).max() <= 1e-8 * np.abs(x_direct).max()
    # an indefinite system (shifted into the spectrum): CG breaks down,
    # GMRES (or, failing that, the direct solve) still answers
    import scipy.sparse as sp
    import scipy.sparse.linalg as spl
    import warnings
    lmax = spl.eigsh(A, k=1, which="LA", return_eigenvectors=False)[0]
    S = (A - 0.3 * lmax * sp.identity(A.shape[0])).tocsr()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        x = linear_solver("amg", b.doflocs[:, I], tol=1e-12)(S, rhs)
    assert np.linalg.norm(S @ x - rhs) <= 1e-9 * np.linalg.norm(rhs)
    # pyamg's CG breakdown note is an expected step of the fallback
    # chain, not news for the user: only the package's own warning shows
    assert not [w for w in caught if "Indefinite" in str(w.message)]


@pytest.mark.parametrize("pardiso", [False, True])
def test_auto_direct_limit_follows_the_installed_direct_solver(
        pardiso, monkeypatch):
    """``auto_direct_limit(dim)``: with PARDISO its unknowns and non-zeros
    tables, else SuperLU's unknowns (its 3-D crossover is far lower) and
    no limit on non-zeros."""
    from skfem_pg.solvers import linear
    monkeypatch.setattr(linear, "pardiso_available", lambda: pardiso)
    for d in (2, 3):
        if pardiso:
            assert linear.auto_direct_limit(d) == (
                linear.DIRECT_LIMIT_PARDISO[d],
                linear.DIRECT_NNZ_LIMIT_PARDISO.get(d))
        else:
            assert linear.auto_direct_limit(d) == (linear.DIRECT_LIMIT[d],
                                                   None)
    assert linear.DIRECT_LIMIT[3] < linear.DIRECT_LIMIT_PARDISO[3]


def test_auto_solver_is_direct_up_to_the_limit_then_amg():
    """``linear_solver("auto")`` solves directly up to ``direct_limit``
    unknowns and ``direct_nnz_limit`` non-zeros and by AMG above either,
    with the same answer."""
    mesh = fem.MeshTet.init_tensor(*[np.linspace(0, 1, 6)] * 3)
    b = fem.Basis(mesh, fem.ElementVector(fem.ElementTetP1()))
    K = pg.assemble(linear_elasticity(LAM, MU), b)
    D = b.get_dofs(lambda x: np.isclose(x[0], 0)).all()
    I = np.setdiff1d(np.arange(b.N), D)
    A, rhs = K[I][:, I].tocsr(), np.ones(len(I))
    x = []
    for limits, amg in (((len(I), None), False), ((len(I) - 1, None), True),
                        ((len(I), A.nnz), False), ((len(I), A.nnz - 1), True)):
        solve = linear_solver("auto", b.doflocs[:, I], tol=1e-12,
                              direct_limit=limits[0],
                              direct_nnz_limit=limits[1])
        x.append(solve(A, rhs))
        assert solve.amg.stats["solves"] == amg
    for xi in x[1:]:
        assert np.abs(xi - x[0]).max() <= 1e-8 * np.abs(x[0]).max()


@pytest.mark.parametrize("n", [1, 7, 60])
def test_submatrix_equals_scipy_row_then_column_selection(n):
    """``submatrix(A, I)`` (one copy) equals ``A[I][:, I]`` for index
    arrays and masks, empty rows and an empty selection included."""
    rng = np.random.default_rng(n)
    A = sp.random(n, n, density=0.2, random_state=n, format="csr")
    A = A.tolil()
    A[n // 2, :] = 0  # an empty row
    A = A.tocsr()
    for I in (np.arange(n), np.sort(rng.choice(n, n // 2, replace=False)),
              rng.random(n) < 0.4, np.zeros(n, dtype=bool)):
        S, R = pg.solvers.submatrix(A, I), A[I][:, I].tocsr()
        S.check_format(full_check=True)
        assert S.shape == R.shape
        assert abs(S - R).sum() == 0


def test_fd_tangent_matches_consistent_tangent(beam):
    from skfem_pg.formulations import material_tangent
    from skfem_pg.formulations.tangents import fd_tangent
    mesh, b = beam
    rng = np.random.default_rng(2)
    u = 0.02 * rng.standard_normal(b.N)
    F = b.interpolate(u).grad + np.eye(2)[:, :, None, None]
    m = mat.NeoHooke(lam=LAM, mu=MU)
    K = pg.assemble(material_tangent, b, A=m.tangent(F))
    Kfd = fd_tangent(b, m, F)
    assert abs(K - Kfd).max() <= 1e-6 * abs(K).max()
    # and Newton with it converges to the same solution
    f = pg.traction(b, "right", [0.0, 0.5])
    D = b.get_dofs("left")
    u1, _ = newton(Hyperelastic(b, m), f, D=D, verbose=False)
    u2, _ = newton(Hyperelastic(b, m, tangent="fd"), f, D=D, verbose=False)
    assert np.abs(u1 - u2).max() <= 1e-8 * np.abs(u1).max()


def test_fixed_steps_neither_grow_nor_cut(beam):
    """adaptive=False: exactly ``steps`` equal steps (no doubling after an
    easy step), and a failing step raises at once (no halving)."""
    mesh, b = beam
    model = Hyperelastic(b, mat.NeoHooke(lam=LAM, mu=MU))
    f = pg.traction(b, "right", [0.0, 0.05])
    D = b.get_dofs("left")
    _, hist = newton(model, f, D=D, steps=4, adaptive=False, verbose=False)
    assert [h["load"] for h in hist] == [0.25, 0.5, 0.75, 1.0]
    _, hist = newton(model, f, D=D, steps=4, verbose=False)  # adaptive
    assert len(hist) < 4
    f = pg.traction(b, "right", [0.0, 2.0])  # J <= 0 in one step
    with pytest.raises(ConvergenceError) as err:
        newton(model, f, D=D, steps=1, adaptive=False, verbose=False)
    assert err.value.load == 0.0 and err.value.history == []


def test_nearly_incompressible_small_load_converges_at_the_round_off_floor():
    """K = 2e7 mu (the nearly incompressible Cook membrane): the residual
    stalls at a floor set by K eps, not by the load (5e-8 with a load of
    1e-5: 2 % of the first residual), so Newton stops on the increments'
    energy, and the displacement is the linear solution's."""
    G, LAM_ = 0.375, 7.5e6
    mesh = pg.meshing.distort(pg.meshing.cook_membrane(8), 0.3, seed=8)
    mesh = mesh.with_boundaries({"left": lambda x: np.isclose(x[0], 0.0),
                                 "right": lambda x: np.isclose(x[0], 48.0)})
    basis = fem.Basis(mesh, fem.ElementVector(fem.ElementQuad2()))
    load = 1e-5
    f = fem.asm(fem.LinearForm(lambda v, w: load / 16 * v[1]),
                basis.boundary("right"))
    D = basis.get_dofs("left").all()
    model = Hyperelastic(basis, mat.NeoHookeIsoVol(mu=G, K=LAM_ + 2 * G / 3))
    u, hist = newton(model, f, D=D, verbose=False)
    assert len(hist) == 1  # no cut step
    assert hist[0]["reason"] == "round-off floor"
    assert hist[0]["residuals"][-1] > 1e-3 * hist[0]["residuals"][0]
    ul = fem.solve(*fem.condense(
        linear_elasticity(LAM_, G).assemble(basis), f, D=D))
    assert np.abs(u - ul).max() <= 1e-4 * np.abs(ul).max()


@pytest.mark.parametrize("kind", ["symmetric", "saddle", "needs pivoting",
                                  "nonsymmetric"])
def test_direct_solver_paths(kind):
    """pg.solvers.direct: diagonal pivots for symmetric matrices, threshold
    pivoting keeping the diagonal for the others (both checked by the
    residual, refactorized with partial pivoting when they fail), COLAMD
    for saddle points: all exact."""
    import scipy.sparse as sp
    rng = np.random.default_rng(3)
    n = 60
    A = sp.random(n, n, density=0.1, random_state=rng) + 10 * sp.eye(n)
    if kind != "nonsymmetric":
        A = A + A.T
    if kind == "saddle":
        B = sp.random(10, n, density=0.3, random_state=rng)
        A = sp.bmat([[A, B.T], [B, None]])
    if kind == "needs pivoting":  # tiny diagonal pivots, large off-diagonal
        A = sp.bmat([[sp.eye(n) * 1e-14, sp.eye(n)], [sp.eye(n), A]])
    A = A.tocsr()
    b = rng.standard_normal(A.shape[0])
    from unittest import mock
    from skfem_pg.solvers import linear
    splu = linear.spl.splu
    with mock.patch.object(linear.spl, "splu", side_effect=splu) as lu:
        x = pg.solvers.direct(A, b, ordering="rcm+mmd")
    assert np.abs(A @ x - b).max() <= 1e-10 * np.abs(b).max()
    # partial pivoting (SuperLU's default threshold) only for saddle points
    # (COLAMD) and where diagonal pivots fail
    partial = [c for c in lu.call_args_list
               if "diag_pivot_thresh" not in c.kwargs]
    assert bool(partial) == (kind in ("saddle", "needs pivoting"))
    assert len(lu.call_args_list) == 1 + (kind == "needs pivoting")


def test_a_failed_step_is_never_retried_unchanged(beam, monkeypatch):
    """A step clipped at the end of the load (target 1) that fails is
    halved from its actual size, not from the unclipped one (which tried
    the same step again)."""
    from skfem_pg.solvers import static
    mesh, b = beam
    model = Hyperelastic(b, mat.NeoHooke(lam=LAM, mu=MU))
    tried, done = [], [0.0]  # (from, to, converged), last converged load
    step = static.newton_step

    def fails_above(model, u, lam, *args):
        if lam == 1.0 and lam - done[0] > 0.05:  # the last bit is hard
            tried.append((done[0], lam, False))
            return False, u, {"residuals": [1.0], "reason": "test",
                              "min_J": 1.0}, None
        ok, u, info, state = step(model, u, lam, *args)
        tried.append((done[0], lam, ok))
        done[0] = lam if ok else done[0]
        return ok, u, info, state
    monkeypatch.setattr(static, "newton_step", fails_above)
    f = pg.traction(b, "right", [0.0, 0.01])
    newton(model, f, D=b.get_dofs("left"), predictor=False, verbose=False)
    attempts = [(s, t) for s, t, _ in tried]
    assert all(a != b for a, b in zip(attempts, attempts[1:]))
    assert tried[-1][1:] == (1.0, True)


def test_amg_on_sliding_boundaries_and_the_step_callback():
    """Symmetry planes leave free dofs that are not whole nodes: the AMG's
    rigid-body modes take each dof's component (they broke pyamg's shape
    check before); the callback sees every converged step with its
    internal force (the reactions)."""
    from skfem_pg.scenes import Scene
    from skfem_pg.solvers import rigid_body_modes
    mesh = fem.MeshHex.init_tensor(*[np.linspace(0, 1, 5)] * 3)
    sc = Scene("sym", mesh.with_defaults(), mat.NeoHookeIsoVol(mu=1.0, K=3.0),
               prescribed={"left": {0: 0.0}, "bottom": {1: 0.0},
                           "front": {2: 0.0}, "right": {0: 0.1}})
    basis, model, f, D, u_D, _ = sc.setup("H1")
    seen = []
    x1, hist = newton(model, f, D=D, u_D=u_D, solver="amg", steps=2,
                      adaptive=False, verbose=False,
                      callback=lambda x, t, f_int: seen.append(
                          (t, x.copy(), f_int)))
    x2, _ = newton(model, f, D=D, u_D=u_D, solver="direct", verbose=False)
    assert np.abs(x1 - x2).max() < 1e-9 * np.abs(x2).max()
    assert [t for t, _, _ in seen] == [0.5, 1.0]
    assert np.array_equal(seen[-1][1], x1)
    f_end = model.internal_force(model.state(x1))
    assert np.abs(seen[-1][2] - f_end).max() < 1e-12 * np.abs(f_end).max()
    # the modes of a subset equal the restriction of the whole nodes'
    locs = basis.doflocs
    free = np.setdiff1d(np.arange(basis.N), D)
    B = rigid_body_modes(locs)
    assert np.array_equal(rigid_body_modes(locs[:, free], free % 3),
                          B[free])
    with pytest.raises(ValueError, match="components"):
        rigid_body_modes(locs[:, free[:-1]])


class _Arctan:
    """r(x) = arctan(x) per unknown: Newton from |x| > 1.39 oscillates
    with growing amplitude (the classic counterexample)."""

    def __init__(self, max_x=np.inf):
        self.max_x = max_x

    def state(self, x):
        return x.copy()

    def min_J(self, x):  # an 'inverted' iterate beyond max_x
        return 1.0 if np.abs(x).max() < self.max_x else -1.0

    def internal_force(self, x):
        return np.arctan(x)

    def tangent(self, x):
        import scipy.sparse as sp
        return sp.diags(1.0 / (1.0 + x * x))


@pytest.mark.parametrize("max_x", [np.inf, 2.0])
def test_line_search_tames_an_oscillating_newton(max_x):
    """Without the line search the iterates 1.5, -1.69, 2.32, ... diverge
    (or, beyond max_x, fail as J <= 0); halving the increment that raises
    the residual (or fails) converges to the root."""
    from scipy.sparse.linalg import spsolve
    from skfem_pg.solvers.static import newton_step
    model = _Arctan(max_x)
    x0 = np.array([1.5, 0.3])
    none = np.array([], dtype=int)

    def step(line_search):
        return newton_step(model, x0, 0.0, np.zeros(2), none, np.zeros(0),
                            np.arange(2), spsolve, 1e-10, 25, line_search)

    ok, x, info, _ = step(False)
    assert not ok
    assert info["reason"] == ("diverging" if max_x == np.inf else "J <= 0")
    ok, x, info, _ = step(True)
    assert ok and np.abs(x).max() < 1e-10
    assert info["backtracks"] >= 1
    r = info["residuals"]
    assert all(b <= a for a, b in zip(r[1:], r[2:]))  # after the first


@pytest.mark.parametrize("kind", ["spd", "indefinite", "saddle",
                                  "nonsymmetric"])
def test_pardiso_symmetric_mode_equals_superlu(kind):
    """With pypardiso installed, symmetric matrices go to PARDISO's
    symmetric indefinite mode (upper triangle, LDL^T), others to its LU:
    the same solution as SuperLU to 1e-10, PG's 3-D tangent included."""
    pytest.importorskip("pypardiso")
    import scipy.sparse as sp
    from skfem_pg.formulations import linear_elasticity
    rng = np.random.default_rng(5)
    b3 = pg.FamilyBasis(fem.MeshTet.init_tensor(*[np.linspace(0, 1, 5)] * 3),
                        dim=3)
    A = pg.assemble(linear_elasticity(1.0, 1.0), b3)
    A = (A + 1e-3 * sp.eye(A.shape[0])).tocsr()  # regular: free body
    if kind == "indefinite":
        A = (A - 0.5 * sp.diags(A.diagonal())).tocsr()
    if kind == "nonsymmetric":
        A = (A + 1e-2 * sp.random(*A.shape, density=0.01,
                                  random_state=rng)).tocsr()
    if kind == "saddle":  # zero diagonal block: stored zeros for PARDISO
        B = sp.random(10, A.shape[0], density=0.3, random_state=rng)
        A = sp.bmat([[A, B.T], [B, None]]).tocsr()
    b = rng.standard_normal(A.shape[0])
    x = pg.solvers.direct(A, b, ordering="pardiso")
    y = pg.solvers.direct(A, b, ordering="rcm+mmd")
    assert np.abs(x - y).max() <= 1e-10 * np.abs(y).max()


@pytest.mark.parametrize("name, nu", [("VCBCPBG V5m Unl", 0.49999),
                                      ("VCBCPBG V5m IUnlP0", 0.5)])
def test_pardiso_nearly_incompressible_newton_equals_superlu(name, nu,
                                                            monkeypatch):
    """The clamped 3-D punch (demos/punch_3d.py, 4 x 4 x 2 hexahedra):
    PARDISO's perturbed pivots left a relative residual of 2e-3 at
    nu = 0.49999 (refined now) and a useless answer for the saddle point
    at nu = 0.5 (SuperLU takes over); both were refused as singular."""
    pytest.importorskip("pypardiso")
    from skfem_pg.scenes import Scene
    from skfem_pg.solvers import linear
    e = 4.8293
    material = (mat.NeoHookeIsoVol.incompressible(e / 3.0) if nu == 0.5
                else mat.NeoHookeIsoVol(mu=e / (2 * (1 + nu)),
                                        K=e / (3 * (1 - 2 * nu))))
    mesh = fem.MeshHex.init_tensor(np.linspace(0, 0.1, 5),
                                   np.linspace(0, 0.1, 5),
                                   np.linspace(0, 0.05, 3)).with_boundaries({
        "x0": lambda x: np.isclose(x[0], 0.0),
        "y0": lambda x: np.isclose(x[1], 0.0),
        "bottom": lambda x: np.isclose(x[2], 0.0),
        "load": lambda x: np.isclose(x[2], 0.05) & (x[0] <= 0.05 + 1e-12)
        & (x[1] <= 0.05 + 1e-12)})
    sc = Scene("punch", mesh, material,
               prescribed={"x0": {0: 0.0}, "y0": {1: 0.0},
                           "bottom": {2: 0.0}, "load": {0: 0.0, 1: 0.0}},
               tractions={"load": [0.0, 0.0, -9.0]}, steps=4)
    u = sc.solve(name).u
    monkeypatch.setattr(linear, "pardiso_available", lambda: False)
    v = sc.solve(name).u
    assert np.abs(u - v).max() <= 1e-8 * np.abs(v).max()


@pytest.mark.parametrize("solver", ["direct", "superlu"])
def test_modified_newton_equals_full_newton(beam, solver):
    """reuse=True (kept factorizations) reaches full Newton's answer to
    1e-10 on a bent PG cantilever in large deflection (tip > 1/4 of the
    length), with fewer fresh tangents than increments; prescribed
    displacements ride on kept factors too."""
    from skfem_pg.solvers.linear import Factorization
    mesh, b = beam
    f = pg.traction(b, "right", [0.0, -0.6])
    D = b.get_dofs("left")
    lin = solver if solver == "direct" else linear_solver("direct")
    if solver == "superlu":  # the scipy path of the kept factorization
        lin.factorize = lambda A: Factorization(A, "rcm+mmd")
    kw = dict(D=D, steps=4, tol=1e-12, verbose=False, solver=lin)
    model = Hyperelastic(b, mat.NeoHooke(lam=LAM, mu=MU))
    u, hist = newton(model, f, **kw)
    v, kept = newton(model, f, reuse=True, **kw)
    assert np.abs(v - u).max() <= 1e-10 * np.abs(u).max()
    assert np.abs(u).max() > 1.0  # large deflection
    tangents = sum(h["tangents"] for h in kept)
    increments = sum(len(h["residuals"]) - 1 for h in kept)
    assert 0 < tangents < increments
    # a prescribed tip displacement in steps: the first increment of each
    # step carries it (K_ID du_D by the kept tangent)
    tip = b.get_dofs("right").nodal["u^2"]
    u_D = np.zeros(b.N)
    u_D[tip] = -1.0
    DD = np.union1d(D.flatten(), tip)
    kw.update(D=DD, u_D=u_D)
    u, _ = newton(model, **kw)
    v, kept = newton(model, reuse=True, **kw)
    assert np.abs(v - u).max() <= 1e-10 * np.abs(u).max()
    assert np.allclose(v[tip], -1.0)


def test_modified_newton_without_kept_factors_is_newton(beam):
    """A solver without a kept factorization (a user's callable) makes
    reuse=True plain Newton: every increment a fresh tangent."""
    mesh, b = beam
    f = pg.traction(b, "right", [0.0, -0.01])
    D = b.get_dofs("left")
    model = Hyperelastic(b, mat.NeoHooke(lam=LAM, mu=MU))
    u, hist = newton(model, f, D=D, verbose=False,
                     solver=lambda A, r: pg.solvers.direct(A, r))
    v, kept = newton(model, f, D=D, verbose=False, reuse=True,
                     solver=lambda A, r: pg.solvers.direct(A, r))
    assert np.array_equal(u, v)
    assert [h["tangents"] for h in kept] \
        == [len(h["residuals"]) - 1 for h in hist]


@pytest.mark.parametrize("ordering", ["pardiso", "rcm+mmd", "colamd"])
def test_factorization_solves_many_right_hand_sides(ordering):
    """A kept Factorization solves several right-hand sides exactly; on a
    symmetric indefinite matrix PARDISO's Cholesky attempt falls back to
    LDL^T (and says so: definite False)."""
    from skfem_pg.solvers import Factorization
    if ordering == "pardiso" and not pg.solvers.pardiso_available():
        pytest.skip("pypardiso is not installed")
    rng = np.random.default_rng(5)
    n = 80
    R = sp.random(n, n, density=0.1, random_state=rng)
    for shift, definite in ((20.0, True), (-3.0, False)):
        A = (R + R.T + shift * sp.eye(n)).tocsr()
        if not definite:  # make sure of a negative eigenvalue
            assert np.linalg.eigvalsh(A.toarray()).min() < 0
        f = Factorization(A, ordering)
        for _ in range(3):
            b = rng.standard_normal(n)
            x = f.solve(b)
            assert np.abs(A @ x - b).max() <= 1e-10 * np.abs(b).max()
        if ordering == "pardiso":
            assert f.definite is definite
        f.free()
    with pytest.raises(ValueError, match="ordering"):
        Factorization(A, "umfpack")
    # issue 47: a NaN in the matrix or the load was "a singular matrix —
    # too few Dirichlet conditions", a dense array an AttributeError
    bad = A.copy()
    bad.data[7] = np.nan
    with pytest.raises(ValueError, match=r"non-finite entries \(first: row "
                                         r"\d+, column \d+ = nan\)"):
        Factorization(bad, ordering)
    f = Factorization(A.toarray(), ordering)
    with pytest.raises(ValueError, match="right-hand side has 1 non-finite"):
        f.solve(np.r_[np.nan, np.ones(n - 1)])
    with pytest.raises(ValueError, match="must have 80 rows"):
        f.solve(np.ones(n + 1))
    B = rng.standard_normal((n, 2))
    assert np.abs(A @ f.solve(B) - B).max() <= 1e-10 * np.abs(B).max()
    f.free()
    with pytest.raises(ValueError, match="square matrix"):
        Factorization(sp.csr_matrix(np.ones((2, 3))), ordering)


def test_solver_docstring_examples_run():
    """The examples in the Newton and linear solver docstrings are what
    the code gives."""
    import doctest
    from skfem_pg.solvers import linear, static
    for module in (linear, static):
        result = doctest.testmod(module, optionflags=doctest.ELLIPSIS)
        assert result.attempted > 0 and result.failed == 0, module
