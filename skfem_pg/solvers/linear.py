r"""Linear solvers for FE and PG systems: sparse direct (SuperLU orderings,
optional MKL PARDISO) and AMG-Krylov with a kept hierarchy.

"""
import inspect
import time
import warnings

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spl

from ..errors import SingularSystemError


def rigid_body_modes(doflocs, components=None):
    """Rigid-body modes of a vector field with dofs at ``doflocs``
    (``(d, N)``): ``d`` translations and ``d(d-1)/2`` rotations, as
    columns.  ``components`` ``(N,)``: each dof's component — needed when
    the dofs are a subset (free dofs with sliding boundaries: not whole
    nodes); default: interleaved whole nodes (``j % d``)."""
    d, N = doflocs.shape
    if components is None:
        if N % d:
            raise ValueError("{} dofs are not whole nodes of {} components:"
                             " pass components=".format(N, d))
        components = np.arange(N) % d
    c = np.asarray(components)
    if c.shape != (N,):
        raise ValueError("components: one per dof ({}), got {}".format(
            N, c.shape))
    modes = [(c == a).astype(float) for a in range(d)]
    for a in range(d):
        for b in range(a + 1, d):
            modes.append(np.where(c == a, -doflocs[b], 0.0)
                         + np.where(c == b, doflocs[a], 0.0))
    return np.column_stack(modes)


def submatrix(A, I):
    """``A[I][:, I]`` of a sparse matrix in one pass: the condensed system
    on the free dofs ``I`` (sorted indices or a boolean mask), as CSR.

    scipy's ``A[I][:, I]`` builds the row selection and then a column
    selection of it, two copies of the large matrix; this keeps one mask
    over ``A``'s non-zeros and copies the kept entries once (the 1 M dof
    scale run: see ``benchmarks/README.md``, "3-D scale run")."""
    A = A.tocsr()
    n = A.shape[0]
    keep = np.zeros(n, dtype=bool)
    keep[I] = True
    new = np.full(n, -1, dtype=A.indices.dtype)
    new[keep] = np.arange(int(keep.sum()), dtype=A.indices.dtype)
    mask = np.repeat(keep, np.diff(A.indptr))
    mask &= keep[A.indices]
    counts = np.zeros(n, dtype=np.int64)
    full = np.diff(A.indptr) > 0
    if full.any():
        counts[full] = np.add.reduceat(mask, A.indptr[:-1][full],
                                       dtype=np.int64)
    indices = new[A.indices[mask]]
    data = A.data[mask]
    del mask
    m = int(keep.sum())
    indptr = np.zeros(m + 1, dtype=A.indptr.dtype)
    np.cumsum(counts[keep], out=indptr[1:])
    return sp.csr_matrix((data, indices, indptr), shape=(m, m))


def pardiso_available():
    """Whether ``pypardiso`` (Intel MKL PARDISO; in the default install on
    x86-64 Linux and Windows, elsewhere ``pip install skfem-pg[pardiso]``)
    can be imported."""
    try:
        import pypardiso  # noqa: F401
    except ImportError:
        return False
    return True


#: largest relative residual ``|A x - b| / |b|`` a solve may return: a
#: singular system (too few Dirichlet conditions) comes back from PARDISO
#: with a residual of order 1 and ``|x|`` ~ 1e13; a well-posed system with a
#: condition number up to about 1e10 stays below it
RESIDUAL_CHECK = 1e-6
#: above :data:`RESIDUAL_CHECK`, an ill-conditioned but regular system (a
#: nearly incompressible one, a saddle point's late Newton increment
#: whose right-hand side is at round-off: 2.7e-6 with ``|A| |x| / |b|``
#: = 5e5) is accepted up to this relative residual ...
RESIDUAL_LIMIT = 1e-3
#: ... while ``|A| |x| / |b|``, a lower bound of the condition number,
#: stays below this (a singular matrix solved by SuperLU: 2e16; by PARDISO,
#: which perturbs its pivots: 2e11 with a relative residual of 11)
SINGULAR_CONDITION = 1e13

#: names of the rigid-body modes of :func:`rigid_body_modes`, per dimension
MODE_NAMES = {1: ["translation x"],
              2: ["translation x", "translation y", "rotation in the x-y plane"],
              3: ["translation x", "translation y", "translation z",
                  "rotation about z", "rotation about y",
                  "rotation about x"]}


def check_solution(A, b, x, what="the direct solve"):
    """Raise :class:`~skfem_pg.errors.SingularSystemError` unless ``x``
    is finite and ``|A x - b| <= RESIDUAL_CHECK |b|`` (max norms), or
    within :data:`RESIDUAL_LIMIT` for a system whose condition is not
    that of a singular matrix (:data:`SINGULAR_CONDITION`); returns
    ``x``."""
    if not np.all(np.isfinite(x)):
        raise SingularSystemError(
            "{} returned non-finite values ({} of {} entries): the matrix "
            "({} unknowns) is singular — too few Dirichlet conditions, or a "
            "mechanism".format(what, int(np.sum(~np.isfinite(x))), len(x),
                               A.shape[0]))
    nb = np.abs(b).max() if b.size else 0.0
    r = np.abs(A @ x - b).max() if b.size else 0.0
    if r <= RESIDUAL_CHECK * nb:
        return x
    kappa = abs(A).sum(axis=1).max() * np.abs(x).max() / max(nb, 1e-300)
    if r <= RESIDUAL_LIMIT * nb and kappa <= SINGULAR_CONDITION:
        return x
    raise SingularSystemError(
        "{} did not solve the system: relative residual {:.2e}, max |x| "
        "{:.2e} (|A| |x| / |b| = {:.1e}); the matrix ({} unknowns) is "
        "singular or nearly so — too few Dirichlet conditions, or a "
        "mechanism".format(what, r / max(nb, 1e-300), np.abs(x).max(),
                           kappa, A.shape[0]))


#: a rigid-body mode ``r`` is free where ``|A r| <= tol max|diag A| |r|``.
#: A free mode leaves round-off, 2e-17 .. 2e-16 (FE, PG on quadrilaterals,
#: tetrahedra, hexahedra).  A held one is resisted only at the nodes next to
#: the Dirichlet conditions, and near incompressibility only by the shear
#: modulus there: on the clamped Cook membrane with lambda/mu = 2e7 (Q1P0)
#: a translation along the clamped edge gives 4e-9 / 2.8e-9 / 1.9e-9 at
#: 16 / 32 / 64 elements per side (1e-9 refused its 256 mesh), so the
#: bound sits near round-off.
RIGID_MODE_TOL = 1e-12


def free_rigid_body_modes(A, doflocs, components=None, tol=RIGID_MODE_TOL):
    """Names of the rigid-body modes (:data:`MODE_NAMES`) that ``A``
    (condensed onto the dofs at ``doflocs``) leaves without stiffness:
    ``|A r| <= tol max|diag A| |r|`` (:data:`RIGID_MODE_TOL`)."""
    B = rigid_body_modes(doflocs, components)
    scale = np.abs(A.diagonal()).max() if A.shape[0] else 0.0
    names = MODE_NAMES.get(doflocs.shape[0], [])
    free = []
    for i in range(B.shape[1]):
        r = B[:, i]
        nr = np.linalg.norm(r)
        if nr > 0 and np.linalg.norm(A @ r) <= tol * scale * nr:
            free.append(names[i] if i < len(names) else "mode {}".format(i))
    return free


def direct(A, b, ordering="auto", definite=None, **kwargs):
    """Sparse direct solve for FE and PG systems alike.

    ``ordering="auto"``: MKL PARDISO if ``pypardiso`` is installed
    (benchmarks/README.md), else ``"rcm+mmd"``.  ``"pardiso"``: MKL
    PARDISO (its own nested-dissection ordering, MKL's threads); a
    symmetric matrix in its symmetric indefinite mode on the upper
    triangle (LDL^T), a non-symmetric one by LU.  ``ordering="rcm+mmd"``: reverse
    Cuthill–McKee permutation, then SuperLU's ``MMD_AT_PLUS_A`` (on 2-D
    elasticity systems the fastest of scipy's options or close to it).  A
    symmetric matrix is factorized with diagonal pivots
    (SuperLU's ``SymmetricMode``), a non-symmetric one with threshold
    pivoting that keeps the diagonal (:data:`DIAG_PIVOT`); either is
    checked by its residual and refactorized with partial pivoting if that
    is above :data:`PIVOT_CHECK`.  A saddle point (zero diagonal entries:
    the pressure rows of IUnlP0, U2P1C) goes to ``COLAMD`` instead.
    ``ordering="colamd"``: SuperLU's ``COLAMD`` (the faster one on 3-D
    tetrahedra).  Measured: benchmarks/README.md, "Measurements behind
    the defaults".  Usable as ``fem.solve(A, b, solver=direct)``.

    Every answer is checked (:func:`check_solution`): a singular system
    raises :class:`~skfem_pg.errors.SingularSystemError` instead of
    returning a solution with a large residual or non-finite entries.
    To solve many right-hand sides with one matrix keep its
    :class:`Factorization`; ``definite=False`` skips PARDISO's Cholesky
    attempt on a symmetric matrix known to be indefinite.
    """
    f = Factorization(A, ordering, definite)
    try:
        return f.solve(b)
    finally:
        f.free()


#: ``PyPardisoSolver`` instances per matrix type that hold no factors,
#: kept: creating one looks up MKL's library, which costs more than
#: factorizing a small system
_PARDISO_SOLVERS = {}


def _checked_matrix(A):
    """``A`` as CSR, refused with a named error if it is not square or has
    non-finite entries (which SuperLU and PARDISO report as a singular
    matrix)."""
    A = sp.csr_matrix(A) if not sp.issparse(A) else A.tocsr()
    if A.ndim != 2 or A.shape[0] != A.shape[1]:
        raise ValueError("a direct solve needs a square matrix, got shape "
                         "{}".format(A.shape))
    bad = np.flatnonzero(~np.isfinite(A.data))
    if bad.size:
        row = int(np.searchsorted(A.indptr, bad[0], side="right") - 1)
        raise ValueError(
            "the matrix has {} non-finite entries (first: row {}, column "
            "{} = {}): a NaN or inf in the assembled system (a material "
            "parameter, a coefficient or a state), not a singular one"
            .format(bad.size, row, int(A.indices[bad[0]]), A.data[bad[0]]))
    return A


class Factorization:
    """A sparse direct factorization of ``A``, kept for many right-hand
    sides (:func:`direct` is one of them; Newton's method keeps one for
    several iterations, :class:`~skfem_pg.solvers.controls.NewtonControls`
    ``reuse``).

    ``ordering`` as in :func:`direct`.  :meth:`solve` checks every answer
    (:func:`check_solution`); PARDISO's answers are refined with the same
    factors, and a system PARDISO's perturbed pivots cannot solve (a
    saddle point at nu = 0.5) is refactorized by SuperLU with real
    pivoting.  :meth:`free` releases the factors (PARDISO's live outside
    Python's memory).

    >>> import scipy.sparse as sp
    >>> f = Factorization(sp.diags([2.0, 4.0]).tocsr())
    >>> f.solve([2.0, 2.0])
    array([1. , 0.5])
    >>> f.free()
    """

    def __init__(self, A, ordering="auto", definite=None):
        self.A = _checked_matrix(A)
        self.definite = definite  # False: skip PARDISO's Cholesky
        if ordering == "auto":
            ordering = "pardiso" if pardiso_available() else "rcm+mmd"
        if ordering not in ("pardiso", "rcm+mmd", "colamd"):
            raise ValueError("ordering must be 'auto', 'pardiso', 'rcm+mmd' "
                             "or 'colamd', got {!r}".format(ordering))
        self.ordering = ordering
        self._pardiso = self._superlu = None
        self._checked = False  # SuperLU's diagonal pivots not yet checked
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", spl.MatrixRankWarning)
            self._factor(ordering)

    def _factor(self, ordering, pivot=False):
        A = self.A
        if ordering == "rcm+mmd" and np.any(A.diagonal() == 0.0):
            ordering = "colamd"  # a saddle point: RCM + MMD fills in badly
        self.ordering = ordering
        if ordering == "pardiso":
            import pypardiso
            from pypardiso.pardiso_wrapper import PyPardisoError
            symmetric = _symmetric(A)
            self.factored = A
            if symmetric:
                # the upper triangle with every diagonal entry stored
                # (PARDISO's symmetric modes need them; a saddle point's
                # are zero)
                U = sp.triu(A, format="coo")
                n = A.shape[0]
                self.factored = sp.csr_matrix(
                    (np.r_[U.data, np.zeros(n)],
                     (np.r_[U.row, np.arange(n)],
                      np.r_[U.col, np.arange(n)])), shape=A.shape)
            # a symmetric matrix: Cholesky (mtype 2) first, 15-20 % faster
            # than LDL^T on 3-D tangents (benchmarks/README.md), which
            # MKL refuses (error -4) for an indefinite matrix; then the
            # symmetric indefinite LDL^T with Bunch-Kaufman pivots
            for mtype in ((2, -2) if symmetric and self.definite is not
                          False else (-2,) if symmetric else (11,)):
                pool = _PARDISO_SOLVERS.setdefault(mtype, [])
                self._pardiso = pool.pop() if pool else \
                    pypardiso.PyPardisoSolver(mtype=mtype)
                self.mtype = mtype
                try:
                    self._pardiso.factorize(self.factored)
                except PyPardisoError:
                    if mtype != 2:
                        raise
                    self.free()
                    self.definite = False
                    continue
                self.definite = mtype == 2 or self.definite
                return
        if ordering == "colamd":
            self.perm = None
            self._superlu = spl.splu(A.tocsc(), permc_spec="COLAMD")
            self._checked = True
            return
        from scipy.sparse.csgraph import reverse_cuthill_mckee
        p = self.perm = reverse_cuthill_mckee(A, symmetric_mode=True)
        Ap = A[p][:, p].tocsc()
        # diagonal pivots first (symmetric: SuperLU's SymmetricMode;
        # otherwise threshold pivoting that prefers the diagonal), checked
        # by the residual of the first solve
        opts = ({} if pivot else
                dict(diag_pivot_thresh=0.0, options={"SymmetricMode": True})
                if _symmetric(A) else dict(diag_pivot_thresh=DIAG_PIVOT))
        self._checked = pivot
        try:
            self._superlu = spl.splu(Ap, permc_spec="MMD_AT_PLUS_A", **opts)
        except RuntimeError:  # a zero pivot: pivot partially
            if pivot:
                raise SingularSystemError(
                    "SuperLU found an exactly singular matrix ({} unknowns)"
                    ": too few Dirichlet conditions, or a mechanism"
                    .format(A.shape[0]))
            self._factor(ordering, pivot=True)

    def _solve_superlu(self, b):
        p = self.perm
        if p is None:
            return self._superlu.solve(b)
        x = np.empty_like(b)
        x[p] = self._superlu.solve(b[p])
        return x

    def _solve_pardiso(self, b):
        # PARDISO perturbs tiny pivots (a nearly incompressible tangent):
        # refine with the same factors while the residual fails
        # check_solution's first test and decreases (a saddle point's can
        # grow)
        solver, full = self._pardiso, self.A
        x = solver.solve(self.factored, b)
        nb = np.abs(b).max() if b.size else 0.0
        r = b - full @ x
        for _ in range(PARDISO_REFINEMENTS):
            rn = np.abs(r).max()
            if not rn > RESIDUAL_CHECK * nb:
                break
            y = x + solver.solve(self.factored, r)
            ry = b - full @ y
            if not np.abs(ry).max() < rn:
                break
            x, r = y, ry
        return x

    def solve(self, b):
        """``A⁻¹ b`` by the kept factors, checked."""
        b = np.asarray(b, dtype=float)
        A = self.A
        if b.ndim not in (1, 2) or b.shape[0] != A.shape[0]:
            raise ValueError("the right-hand side must have {} rows (shape "
                             "({},) or ({}, k)) for a {} x {} matrix, got "
                             "shape {}".format(A.shape[0], A.shape[0],
                                               A.shape[0], *A.shape,
                                               b.shape))
        bad = np.flatnonzero(~np.isfinite(b.ravel()))
        if bad.size:
            raise ValueError(
                "the right-hand side has {} non-finite entries (first: "
                "entry {} = {}): the load, not the matrix".format(
                    bad.size, bad[0], b.ravel()[bad[0]]))
        if self._pardiso is not None:
            x = self._solve_pardiso(b)
            try:
                return check_solution(A, b, x)
            except SingularSystemError:  # PARDISO's perturbed pivots (a
                # saddle point at nu = 0.5): SuperLU pivots for real
                self.free()
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore", spl.MatrixRankWarning)
                    self._factor("rcm+mmd")  # COLAMD for a saddle point
        x = self._solve_superlu(b)
        if not self._checked:  # diagonal pivots: checked by the residual
            scale = np.abs(A).max() * max(np.abs(x).max(), 1e-300)
            if np.all(np.isfinite(x)) and np.abs(A @ x - b).max() \
                    <= PIVOT_CHECK * max(scale, np.abs(b).max()):
                self._checked = True
            else:  # refactorize with partial pivoting
                self._factor(self.ordering, pivot=True)
                x = self._solve_superlu(b)
        return check_solution(A, b, x)

    def free(self):
        """Release the factors (PARDISO's instance goes back to the
        pool)."""
        if self._pardiso is not None:
            self._pardiso.free_memory(everything=True)
            _PARDISO_SOLVERS.setdefault(self.mtype, []).append(self._pardiso)
            self._pardiso = None
        self._superlu = None


#: iterative refinement steps after a PARDISO solve whose residual fails
#: :data:`RESIDUAL_CHECK` (perturbed pivots: the clamped 3-D punch at
#: nu = 0.49999 left a relative residual of 2e-3 without them)
PARDISO_REFINEMENTS = 10

#: largest relative residual ``|A x - b| / (|A| |x|)`` accepted from a
#: factorization with diagonal pivots before partial pivoting is tried
PIVOT_CHECK = 1e-11
#: SuperLU's ``diag_pivot_thresh`` for non-symmetric matrices: the diagonal
#: is kept while it is at least this fraction of the column's largest entry
#: (about ten times faster than partial pivoting on condensed PPG tangents)
DIAG_PIVOT = 0.01


def _symmetric(A, tol=1e-12):
    d = A - A.T
    return d.nnz == 0 or np.abs(d.data).max() <= tol * np.abs(A.data).max()


#: ``"auto"``: the largest direct solve (unknowns) per spatial dimension
#: with the default install's SuperLU: the measured crossover with AMG-CG
#: (``benchmarks/solvers_3d.py``; benchmarks/README.md, "Measurements behind
#: the defaults").
DIRECT_LIMIT = {2: 60_000, 3: 6_000}
#: the same with MKL PARDISO (the default install's on x86-64 Linux and
#: Windows; its symmetric LDL^T),
#: which also stops at :data:`DIRECT_NNZ_LIMIT_PARDISO` non-zeros.
DIRECT_LIMIT_PARDISO = {2: 60_000, 3: 150_000}
#: ``"auto"`` with PARDISO: the largest direct solve in non-zeros per
#: spatial dimension.  Its cost follows the matrix graph, not the unknowns
#: alone (``benchmarks/solvers_3d.py``, ``benchmarks/newton_3d.py``;
#: benchmarks/README.md, "Measurements behind the defaults"); on
#: tetrahedra the unknowns' limit comes first.
DIRECT_NNZ_LIMIT_PARDISO = {3: 24_000_000}


def auto_direct_limit(dim):
    """``(unknowns, non-zeros)``: the ``"auto"`` solver's largest direct
    solve in ``dim`` dimensions — :data:`DIRECT_LIMIT_PARDISO` and
    :data:`DIRECT_NNZ_LIMIT_PARDISO` if PARDISO is installed, else
    :data:`DIRECT_LIMIT` (no limit on non-zeros)."""
    if pardiso_available():
        return (DIRECT_LIMIT_PARDISO.get(dim, 60_000),
                DIRECT_NNZ_LIMIT_PARDISO.get(dim))
    return DIRECT_LIMIT.get(dim, 60_000), None


def _node_blocks(doflocs):
    """Node block size ``d`` if the condensed dofs come in whole nodes
    (``d`` consecutive dofs at one location), else 1."""
    d, n = doflocs.shape
    if n % d:
        return 1
    X = doflocs.reshape(d, -1, d)
    return d if np.all(X == X[:, :, :1]) else 1


#: MINRES' tolerance keyword (scipy < 1.12: ``tol``)
_MINRES_TOL = ("rtol" if "rtol" in inspect.signature(spl.minres).parameters
               else "tol")


class AMGSolver:
    """CG (GMRES if not ``symmetric``) preconditioned by pyamg smoothed
    aggregation with rigid-body modes, for a sequence of related systems
    (Newton's tangents).

    * The hierarchy is kept and reused while it pays: it is rebuilt for
      the next system once the iterations a reused hierarchy needs beyond
      those right after its build cost more time than its setup did, and
      at once when a reused one fails.
    * Aggregation by nodes (BSR blocks of ``d`` dofs) when the condensed
      dofs come in whole nodes; prolongator smoothing ``smooth`` (default
      ``"energy"``: on 3-D Cook PG tangents 50 CG iterations against 65
      for Jacobi smoothing, benchmarks/README.md).
    * ``candidates`` random vectors, smoothed by 10 fine-level
      Gauss-Seidel sweeps, join the rigid-body modes as near-null-space
      candidates: PG tangents have many soft modes (Jacobi-scaled
      condition number 8e4 against O1's 2e3 on a 1.2k-node cube), which
      the rigid-body modes alone leave to CG.  More candidates cut the CG
      iterations and raise the setup (benchmarks/README.md,
      "Measurements behind the defaults").
    * ``graph``: a sparse node adjacency (free nodes) whose standard
      aggregates replace the tangent's on the first level, e.g. the
      families' one-ring graph for PG, whose tangent couples two rings and
      aggregates too coarsely (operator complexity 1.03).  Fewer CG
      iterations at a costlier setup; not the default
      (benchmarks/README.md, "Measurements behind the defaults").
    * Fallback chain: CG fails on indefinite tangents (past a limit point,
      or PG at an overshooting Newton iterate); then MINRES with the same
      (positive) preconditioner; above ``direct_limit`` unknowns GMRES with
      the same hierarchy; then the direct solve, with a warning.

    ``stats`` counts builds, solves, iterations and fallbacks.

    Examples
    --------
    An elastic block clamped at the left, its free dofs solved to the
    tolerance; the hierarchy is built once and reused for the next
    right-hand side:

    >>> import numpy as np, skfem as fem
    >>> from skfem.models.elasticity import linear_elasticity
    >>> mesh = fem.MeshQuad().refined(4)
    >>> basis = fem.Basis(mesh, fem.ElementVector(fem.ElementQuad1()))
    >>> A = linear_elasticity(1.0, 1.0).assemble(basis)
    >>> I = basis.complement_dofs(basis.get_dofs(lambda x: x[0] == 0))
    >>> b = np.ones(len(I))
    >>> amg = AMGSolver(basis.doflocs[:, I])
    >>> Acc = A[I][:, I]
    >>> x = amg(Acc, b)
    >>> bool(np.linalg.norm(Acc @ x - b) < 1e-8 * np.linalg.norm(b))
    True
    >>> x = amg(Acc, 2 * b); amg.stats["builds"]
    1

    """

    def __init__(self, doflocs=None, tol=1e-10, symmetric=True,
                 smooth="energy", maxiter=500,
                 direct_limit=4 * DIRECT_LIMIT[3], ordering="auto",
                 candidates=0, graph=None, components=None):
        self.doflocs, self.tol, self.symmetric = doflocs, tol, symmetric
        self.components = components
        self.candidates, self.graph = int(candidates), graph
        self.smooth, self.maxiter = smooth, maxiter
        self.direct_limit, self.ordering = direct_limit, ordering
        self.ml, self.base_its, self.stale, self.t_setup = None, None, \
            False, 0.0
        self.stats = {"builds": 0, "solves": 0, "iterations": [],
                      "fallbacks": 0, "setup_seconds": 0.0}

    def _build(self, A):
        import pyamg
        t0 = time.perf_counter()
        locs = self.doflocs
        B = rigid_body_modes(locs, self.components) if locs is not None \
            else None
        bs = _node_blocks(locs) if locs is not None else 1
        M = A.tobsr(blocksize=(bs, bs)) if bs > 1 else A
        kw = {}
        if self.candidates and B is not None:
            # PG's soft modes: random vectors smoothed by the fine-level
            # Gauss-Seidel join the rigid-body modes
            rng = np.random.default_rng(0)
            B = np.hstack([B, rng.normal(size=(A.shape[0], self.candidates))])
            kw["improve_candidates"] = [
                ("block_gauss_seidel" if bs > 1 else "gauss_seidel",
                 {"sweep": "symmetric", "iterations": 10}), None]
        if self.graph is not None and bs > 1 \
                and self.graph.shape[0] == A.shape[0] // bs:
            # first-level aggregates on the given node graph (PG: the
            # families', one ring) instead of the tangent's (two rings)
            from pyamg.aggregation.aggregate import standard_aggregation
            agg, _ = standard_aggregation(self.graph.tocsr())
            kw["aggregate"] = [("predefined", {"AggOp": agg.tocsr()})] \
                + ["standard"] * 9
        self.ml = pyamg.smoothed_aggregation_solver(
            M, B=B, smooth=self.smooth,
            symmetry="hermitian" if self.symmetric else "nonsymmetric", **kw)
        self.base_its, self.stale = None, False
        self.t_setup = time.perf_counter() - t0
        self.stats["builds"] += 1
        self.stats["setup_seconds"] += self.t_setup

    def _krylov(self, A, b, accel, x0=None):
        """Krylov solve of ``A`` (the current matrix, which a reused
        hierarchy was not built from) preconditioned by one V-cycle."""
        from pyamg import krylov
        res = []
        # CG's indefinite note: pyamg re-enables it with an 'always' filter
        # inside the call, so record (and drop) instead of ignoring
        with warnings.catch_warnings(record=True):
            x, _ = getattr(krylov, accel)(
                A, b, x0=x0, tol=self.tol, M=self.ml.aspreconditioner(),
                maxiter=min(self.maxiter, A.shape[0]), residuals=res)
        bn = max(np.linalg.norm(b), 1e-300)
        rel = np.linalg.norm(b - A @ x) / bn  # the true residual
        # preconditioned vs true residual
        return x, len(res), rel <= 1e3 * self.tol, rel

    def _minres(self, A, b):
        its = [0]

        def count(xk):
            its[0] += 1
        try:
            x, _ = spl.minres(A, b, M=self.ml.aspreconditioner(),
                              maxiter=min(self.maxiter, A.shape[0]),
                              callback=count, **{_MINRES_TOL: self.tol})
        except ValueError:  # a hierarchy built from an indefinite matrix
            return None, its[0], False, np.inf
        rel = np.linalg.norm(b - A @ x) / max(np.linalg.norm(b), 1e-300)
        return x, its[0], rel <= 1e3 * self.tol, rel

    def __call__(self, A, b, **kwargs):
        A = A.tocsr()
        self.stats["solves"] += 1
        fresh = (self.ml is None or self.stale
                 or self.ml.levels[0].A.shape != A.shape)
        if fresh:
            self._build(A)
        accel = "cg" if self.symmetric else "gmres"
        t0 = time.perf_counter()
        x, its, ok, rel = self._krylov(A, b, accel)
        t_it = (time.perf_counter() - t0) / max(its, 1)
        if not ok and not fresh:  # stale: rebuild and solve again
            self._build(A)
            fresh = True
            t0 = time.perf_counter()
            x, its2, ok, rel = self._krylov(A, b, accel)
            t_it = (time.perf_counter() - t0) / max(its2, 1)
            its += its2
        if ok and (fresh or self.base_its is None):
            self.base_its = its
        elif ok:  # reused: rebuild for the next system once the extra
            # iterations cost more than a setup
            self.stale = (its - self.base_its) * t_it > self.t_setup
        self.stats["iterations"].append(its)
        if ok:
            return x
        self.stats["fallbacks"] += 1
        if accel == "cg":  # an indefinite tangent (past a limit point, or
            # PG at an overshooting Newton iterate): MINRES with the same
            # symmetric positive preconditioner
            x, its, ok, rel = self._minres(A, b)
            self.stats["iterations"][-1] += its
            if ok:
                return x
        tried = ["CG", "MINRES"] if accel == "cg" else [accel.upper()]
        if A.shape[0] > self.direct_limit and accel == "cg":
            tried.append("GMRES")
            x, its, ok, rel = self._krylov(A, b, "gmres")
            self.stats["iterations"][-1] += its
            if ok:
                return x
        warnings.warn("AMG-{} failed (relative residual {:.2e}); solving "
                      "directly".format(", ".join(tried), rel))
        self.ml = None  # the next tangent gets a fresh hierarchy
        return direct(A, b, self.ordering)


def require_stiffness(A, doflocs, components=None):
    """Raise :class:`~skfem_pg.errors.SingularSystemError` naming the
    rigid-body modes :func:`free_rigid_body_modes` finds free.  A residual
    check cannot: a singular system with self-equilibrated loads is
    consistent, and a direct solver returns one of its solutions."""
    free = free_rigid_body_modes(A, doflocs, components)
    if free:
        raise SingularSystemError(
            "the system ({} unknowns) has no stiffness against {}: add "
            "Dirichlet conditions (or springs) that hold {}".format(
                A.shape[0], ", ".join(free),
                "it" if len(free) == 1 else "them"))


def linear_solver(kind="auto", doflocs=None, tol=1e-10, direct_limit=None,
                  symmetric=True, candidates=0, components=None,
                  direct_nnz_limit=None):
    """A solver ``(A, b) -> x`` for ``fem.solve`` and Newton's method.

    ``"direct"``: :func:`direct` (PARDISO if installed, else SuperLU with
    ordering ``rcm+mmd`` in 2-D, ``colamd`` in 3-D);
    ``"amg"``: :class:`AMGSolver` (needs ``doflocs`` of the condensed
    system for the rigid-body modes; keeps its hierarchy across calls;
    ``candidates`` extra near-null-space vectors, :data:`PG_CANDIDATES`
    for family bases in Newton's method);
    ``"auto"``: direct up to ``direct_limit`` unknowns and
    ``direct_nnz_limit`` non-zeros (defaults: :func:`auto_direct_limit`
    of the dimension of ``doflocs``), else AMG.
    ``components``: each condensed dof's component (for the rigid-body
    modes when the free dofs are not whole nodes, e.g. with symmetry
    planes); Newton's method passes them.

    ``solver.factorize(A)``: the kept :class:`Factorization` of ``A``
    where the choice is a direct solve, else ``None`` (Newton's method
    with ``reuse``).

    With ``doflocs``, every call first checks that the system resists
    each rigid-body mode (:func:`free_rigid_body_modes`) and raises
    :class:`~skfem_pg.errors.SingularSystemError` naming the free ones;
    every answer is checked by its residual (:func:`check_solution`).
    """
    dim = 2 if doflocs is None else doflocs.shape[0]
    ordering = ("pardiso" if pardiso_available()
                else "colamd" if dim == 3 else "rcm+mmd")
    if direct_limit is None and direct_nnz_limit is None:
        direct_limit, direct_nnz_limit = auto_direct_limit(dim)
    elif direct_limit is None:
        direct_limit = auto_direct_limit(dim)[0]
    if kind not in ("auto", "direct", "amg"):
        raise ValueError("unknown linear solver {!r}: use 'auto', 'direct' "
                         "or 'amg'".format(kind))
    amg = AMGSolver(doflocs, tol=tol, symmetric=symmetric,
                    direct_limit=4 * direct_limit, ordering=ordering,
                    candidates=candidates, components=components)

    def choice(A):
        if doflocs is not None and A.shape[0] == doflocs.shape[1]:
            require_stiffness(A, doflocs, components)
        if kind != "auto":
            return kind
        small = A.shape[0] <= direct_limit and (
            direct_nnz_limit is None or A.nnz <= direct_nnz_limit)
        return "direct" if small or doflocs is None else "amg"

    seen = {}  # an indefinite matrix met: no more Cholesky attempts

    def factorize(A):
        """A kept :class:`Factorization` of ``A`` where this solver
        solves ``A`` directly, else ``None`` (AMG keeps its hierarchy
        instead)."""
        if choice(A) != "direct":
            return None
        f = Factorization(A, ordering, seen.get("definite"))
        if f.definite is False:
            seen["definite"] = False
        return f

    def solve(A, b, **kwargs):
        f = factorize(A)
        if f is None:
            return amg(A, b)
        try:
            return f.solve(b)
        finally:
            f.free()
    solve.amg = amg
    solve.factorize = factorize
    return solve
