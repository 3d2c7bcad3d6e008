r"""First-order variationally consistent (VC) correction.

VC correction (5.56)–(5.68)
    Ansatz :math:`G \leftarrow G + C`,
    :math:`C^{kji} = Q^{kj}\alpha^k\varphi^{ki}`, one unknown
    :math:`\alpha^k\in R^d` per family, with correction function
    :math:`\varphi^{ki} = N^{kki}_{MLS1} - \delta_{ki}` (V3 (5.62): no Q;
    V5 (5.64): with the bond projector Q, which keeps the bond mapping).
    The unknowns make the PBG integration constraint (5.18) hold,

    .. math:: r^i = \sum_k\sum_{j\in H^k} w_{kj} G^{kji} - A^i = 0,

    with FE-consistent area vectors :math:`A^i` (zero inside).  The system is
    linear, ``d·np`` equations in ``d·nf`` unknowns, and singular by the
    preserved consistency modes (``d + d²``: constant and linear fields are
    in the left null space).  We take its minimum-norm least-squares
    solution.  Because :math:`\sum_i\varphi^{ki} = 0` and
    :math:`\sum_i\varphi^{ki}\Delta X^{ki} = 0`, the correction keeps linear
    consistency.
"""
import time
from dataclasses import dataclass, field
from typing import Any, NamedTuple, Optional

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spl
from scipy.sparse.csgraph import connected_components

from . import boundary as vc_boundary
from ...errors import VCSolveError
from .boundary import BOUNDARY_VARIANTS
from ..corrections import bond_projectors
from ..shape import mls1_master_values
from ..shape.least_squares import wls2_master_hessians, wls2_master_values


def constraint_residual(G, dx, fam, area):
    r"""Integration-constraint residual (5.18),
    :math:`r^i = \sum_k\sum_j w_{kj} G^{kji} - A^i`, shape ``(np, d)``."""
    mem, _ = fam.padded()
    nf, m, _, d = G.shape
    S = (dx[:, None, :] @ G.reshape(nf, m, m * d)).reshape(nf, m, d)
    n = area.shape[1]
    r = np.stack([np.bincount(mem.ravel(), weights=S[..., a].ravel(),
                              minlength=n) for a in range(d)], axis=1)
    return r - area.T


@dataclass
class VCReport:
    """What the VC correction did (printed by demos, read by tests)."""
    variant: str
    solver: str
    unknowns: int
    constraints: int
    residual_before: float  # max |r^i| / h^(d-1)
    residual_after: float
    iterations: int
    seconds: float
    notes: list = field(default_factory=list)
    boundary: str = "min-norm"
    #: ``(d, np)`` discrete minus FE area vectors where constraints were
    #: released (boundary variants ``s``/``sn``), else ``None``
    area_correction: np.ndarray = None
    #: VC2 with boundary ``s``: ``(d, d, np)`` discrete minus FE
    #: :math:`A_2^i` (the surface term of (5.26))
    area2_correction: np.ndarray = None
    #: ``(np,)`` residual of each particle's imposed constraints after the
    #: correction, relative to h^(d-1) (0 where none is imposed)
    particle_residuals: np.ndarray = None

    def __str__(self):
        return ("VC {}: {} unknowns, {} constraints, solver {} ({} it, "
                "{:.3f} s), max|r|/h^(d-1): {:.3e} -> {:.3e}".format(
                    self.variant, self.unknowns, self.constraints,
                    self.solver, self.iterations, self.seconds,
                    self.residual_before, self.residual_after))


def constraint_matrix(phi, B, fam, n_particles, index=None, nf=None):
    r"""Sparse :math:`\partial r / \partial \alpha`: block ``(i, k)`` is
    :math:`\varphi^{ki} B^k`, :math:`B^k = \sum_j w_{kj} Q^{kj}`; shape
    ``(d·np, d·nf)``.  Matrix-valued correction functions (V2,
    ``phi`` of shape ``(nf, m, d, d)``) give blocks :math:`\varphi^{ki}
    B^k`.  The families of ``fam`` (``B`` of shape ``(len(fam), d, d)``)
    are block columns ``index`` of ``nf`` (default: all of them)."""
    mem, mask = fam.padded()
    nfl, m = mem.shape
    d = B.shape[-1]
    a = np.arange(d)
    kl = np.broadcast_to(np.arange(nfl)[:, None], (nfl, m))[mask]
    k = kl if index is None else index[kl]
    i = mem[mask]
    if phi.ndim == 4:
        vals = phi[mask] @ B[kl]
    else:
        vals = phi[mask][:, None, None] * B[kl]  # (nnzb, d, d)
    rows = d * i[:, None, None] + a[None, :, None]
    cols = d * k[:, None, None] + a[None, None, :]
    rows, cols = np.broadcast_arrays(rows, cols)
    return sp.csr_matrix((vals.ravel(), (rows.ravel(), cols.ravel())),
                         shape=(d * n_particles,
                                d * (nfl if nf is None else nf)))


def linear_fields(x, active):
    """Orthonormal basis of constant and linear vector fields on the active
    particles' dofs: the left null space of the constraint matrix."""
    d, n = x.shape
    act = np.nonzero(active)[0]
    cols = []
    for a in range(d):
        for f in [np.ones(n)] + [x[b] - x[b, act].mean() for b in range(d)]:
            v = np.zeros((n, d))
            v[act, a] = f[act]
            cols.append(v.ravel())
    Pm, _ = np.linalg.qr(np.array(cols).T)
    return Pm


def _solve_lsqr(A, b, tol, maxiter):
    out = spl.lsqr(A, b, atol=tol, btol=tol, iter_lim=maxiter)
    return out[0], int(out[2])


def anchor_particles(x, active, PhiT=None, masters=None):
    """``dim + 1`` active particles far apart and affinely independent
    (farthest-point choice): their equations and unknowns pin the singular
    constraint system.  With the scalar constraint matrix ``PhiT``
    (particle × family) and the families' ``masters``, ``dim + 1`` in each
    piece of particles that no family connects to another (a body cut
    through by a crack, two bodies in one set): each piece has its own
    linear fields in the matrix' left null space."""
    if PhiT is not None:
        n = x.shape[1]
        P = sp.csr_matrix((np.ones(len(masters)), (np.arange(len(masters)),
                                                   masters)),
                          shape=(len(masters), n))
        count, label = connected_components(
            abs(PhiT.tocsr()) @ P + sp.eye(n, format="csr"), directed=False)
        if count > 1:
            act = np.asarray(active, bool)
            return np.concatenate([
                anchor_particles(x, act & (label == c))
                for c in np.unique(label[act])])
    act = np.nonzero(active)[0]
    X = x[:, act].T
    d = X.shape[1]
    chosen = [int(np.argmax(((X - X.mean(0)) ** 2).sum(1)))]
    for _ in range(d):
        B = X[chosen] - X[chosen[0]]
        D = X - X[chosen[0]]
        if len(chosen) > 1:  # distance to the affine hull of the chosen
            Qb, _ = np.linalg.qr(B[1:].T)
            D = D - (D @ Qb) @ Qb.T
        chosen.append(int(np.argmax((D ** 2).sum(1))))
    return act[chosen]


class _PermutedLU:
    """SuperLU of ``A[p][:, p]`` (column ordering ``spec``) solving
    ``A x = b``."""

    def __init__(self, A, p, spec="MMD_AT_PLUS_A"):
        self.p = p
        self.lu = spl.splu(A[p][:, p].tocsc(), permc_spec=spec)

    def solve(self, b):
        x = np.empty_like(b, dtype=float)
        x[self.p] = self.lu.solve(b[self.p])
        return x


class _AMGSolve:
    """GMRES preconditioned by smoothed-aggregation AMG (pyamg, the
    nonsymmetric variant, energy-minimising prolongators, coarsest level of
    up to 5000 unknowns by SuperLU) for the pinned scalar VC matrix: its
    cost grows about linearly with the particles, where the sparse LU's
    fill does not (benchmarks/README.md, "Measurements behind the
    defaults").  ``solve`` takes one or several right-hand-side columns;
    a column that does not reach ``tol`` in ``maxiter`` iterations raises
    ``RuntimeError``."""

    def __init__(self, A, tol=1e-12, maxiter=400):
        import pyamg
        from scipy.sparse.csgraph import reverse_cuthill_mckee
        A = A.tocsr()
        # a bandwidth-reducing order: the matrix-vector products and
        # Gauss-Seidel sweeps stay in cache (gmsh numbering has bandwidth
        # ~n), and Gauss-Seidel in this order needs fewer iterations
        # (51.9k particles: 42 against 48, 3.6 s against 5.1 s)
        self.p = reverse_cuthill_mckee(A, symmetric_mode=False)
        self.A = A[self.p][:, self.p].tocsr()
        self.ml = pyamg.smoothed_aggregation_solver(
            self.A, symmetry="nonsymmetric", smooth="energy",
            max_coarse=5000, coarse_solver="splu")
        self.tol, self.maxiter = tol, maxiter
        self.iterations = 0

    def solve(self, b):
        b = np.asarray(b, dtype=float)
        cols = b.reshape(len(b), -1)[self.p]
        out = np.empty_like(cols)
        for j in range(cols.shape[1]):
            nb = np.linalg.norm(cols[:, j])
            if nb == 0:
                out[:, j] = 0.0
                continue
            res = []
            out[:, j] = self.ml.solve(cols[:, j], tol=self.tol,
                                      maxiter=min(self.maxiter, len(b)),
                                      accel="gmres", residuals=res)
            self.iterations += len(res)
            rel = np.linalg.norm(self.A @ out[:, j] - cols[:, j]) / nb
            if not rel <= 1e3 * self.tol:
                raise VCSolveError("AMG-GMRES on the VC system stopped at "
                                   "relative residual {:.1e}".format(rel))
        sol = np.empty_like(out)
        sol[self.p] = out
        return sol.reshape(b.shape)


#: particles above which ``vc_solver="auto"`` takes AMG-GMRES in 3-D (the
#: LU is faster below; benchmarks/README.md, "Measurements behind the
#: defaults")
AMG_VC_LIMIT_3D = 15000


def scalar_constraint_matrix(phi, fam, n_particles, index=None, nf=None):
    r"""Sparse :math:`\Phi^T` with entries :math:`\varphi^{ki}` (row ``i``,
    column ``k``), shape ``(np, nf)``; the families of ``fam`` are columns
    ``index`` (default ``0..len(fam)-1``) of ``nf``."""
    mem, mask = fam.padded()
    index = np.arange(len(fam)) if index is None else index
    k = np.broadcast_to(index[:, None], mem.shape)[mask]
    return sp.csr_matrix((phi[mask], (mem[mask], k)),
                         shape=(n_particles, len(fam) if nf is None else nf))


def solve_pinned_lu(PhiT, masters, B, b, x, active, refine=2,
                     min_norm=True, iterative=False):
    r"""Minimum-norm solution of the consistent, singular, square system
    ``A α = b``, :math:`A_{ik} = \varphi^{ki} B^k`, by one *scalar* sparse
    LU (with ``min_norm=False``: the pinned solution itself, the thesis'
    boundary variant ``p``).

    With :math:`\beta^k = B^k\alpha^k` (``B^k`` is SPD) the system
    decouples into the scalar matrix :math:`\Phi^T` applied to each
    component of ``β`` — ``d³`` times cheaper to factorise than ``A``.
    :math:`\Phi^T` is singular: the ``1 + d`` scalar linear fields of each
    piece of particles that the families connect are its left null space,
    so the equations at ``d + 1`` affinely independent anchor particles
    per piece (:func:`anchor_particles`) follow from the others and are
    dropped, and the unknowns of the anchors' families are fixed to zero.
    The reduced matrix is regular (else ``RuntimeError``); its LU gives a
    particular solution and, with the fixed columns as right-hand sides,
    the null space :math:`z` of :math:`\Phi^T`.  The null space of ``A`` is
    :math:`\{B^{-1}(z\,e_a)\}`; projecting it out gives the minimum-norm
    ``α``.  With ``iterative`` the reduced matrix is solved by AMG-GMRES
    (:class:`_AMGSolve`) instead, falling back to the LU if it does not
    converge; the refinement steps and the projection are the same.
    """
    d, n = x.shape
    nf = len(masters)
    PhiT = PhiT.tocsr()
    family_of = np.full(n, -1)
    family_of[masters] = np.arange(nf)
    anchors = anchor_particles(x, active, PhiT, masters)
    fix = family_of[anchors]
    rows = np.setdiff1d(np.nonzero(active)[0], anchors)
    cols = np.setdiff1d(np.arange(nf), fix)
    if len(rows) != len(cols) or np.any(fix < 0):
        raise RuntimeError("every active particle must master one family "
                           "({} equations, {} unknowns)".format(len(rows),
                                                                len(cols)))
    Ar = PhiT[rows].tocsc()
    # orderings by measurement (benchmarks/README.md): in 2-D a
    # bandwidth-reducing permutation first (SuperLU's orderings alone are
    # erratic on randomly numbered particle sets); in 3-D COLAMD, whose
    # fill grows slower on gmsh tetrahedra
    from scipy.sparse.csgraph import reverse_cuthill_mckee
    Ac = Ar[:, cols].tocsr()
    bb = b.reshape(n, d)[rows]
    rhs = np.column_stack([bb, -Ar[:, fix].toarray()])
    sol = None
    if iterative:
        try:
            lu = _AMGSolve(Ac)
            sol = lu.solve(rhs)
        except RuntimeError:
            sol = None  # the LU below
    if sol is None:
        if d == 3:  # COLAMD alone (faster in 3-D, benchmarks/README.md)
            lu = _PermutedLU(Ac, np.arange(Ac.shape[0]), "COLAMD")
        else:  # 2-D: RCM + MMD_AT_PLUS_A
            lu = _PermutedLU(Ac, reverse_cuthill_mckee(
                Ac, symmetric_mode=False))
        sol = lu.solve(rhs)
    if not np.all(np.isfinite(sol)):
        raise VCSolveError("the pinned constraint matrix is singular")
    beta = np.zeros((nf, d))
    beta[cols] = sol[:, :d]
    # refinement steps for the LU; AMG-GMRES has reached 1e-12 already
    for _ in range(refine if isinstance(lu, _PermutedLU) else 0):
        beta[cols] += lu.solve(bb - Ar @ beta)
    used = "amg" if isinstance(lu, _AMGSolve) else "direct"
    its = lu.iterations if used == "amg" else 1 + refine
    if not min_norm:
        return (np.linalg.inv(B) @ beta[:, :, None])[..., 0].ravel(), its, \
            used
    z = np.zeros((nf, len(fix)))
    z[cols] = sol[:, d:]
    z[fix, np.arange(len(fix))] = 1.0
    Binv = np.linalg.inv(B)
    alpha = (Binv @ beta[:, :, None])[..., 0].ravel()
    # null space of A: alpha^k = (B^k)^-1 e_a z^k, a = 1..d
    Z = Binv[:, None, :, :] * z[:, :, None, None]  # (nf, nz, d(out), d(a))
    Z = Z.transpose(0, 2, 1, 3).reshape(nf * d, len(fix) * d)
    coef = np.linalg.lstsq(Z, alpha, rcond=None)[0]
    return alpha - Z @ coef, its, used


def vc_parts(G, dx, fam, phi, index, x, variant):
    """The pieces of :func:`vc_correction` (its arguments) per part — one
    part per size group (list arguments) or one in all: ``parts`` of
    ``(G, dx, fam, phi, index)``, the ``(nf,)`` masters, the ``(nf, d,
    d)`` matrices :math:`B^k = \\sum_j w_{kj} Q^{kj}` and the projectors
    :math:`Q^{kj}` per part (the bond projectors for V5, else ``I``)."""
    if isinstance(G, (list, tuple)):
        nf = sum(len(f) for f in fam)
        parts = list(zip(G, dx, fam, phi, index))
    else:
        nf = len(fam)
        parts = [(G, dx, fam, phi, None)]
    d = x.shape[0]
    masters = np.empty(nf, dtype=np.int64)
    Qs, B = [], np.empty((nf, d, d))
    for Gp, dxp, f, _, idx in parts:
        at = slice(None) if idx is None else idx
        masters[at] = f.masters
        mem = f.padded()[0]
        if variant == "V5":
            Q = bond_projectors(x, f)
        else:
            Q = np.broadcast_to(np.eye(d), mem.shape + (d, d))
        nfp, m = mem.shape
        B[at] = (dxp[:, None, :] @ np.reshape(Q, (nfp, m, d * d))).reshape(
            nfp, d, d)
        Qs.append(Q)
    return parts, masters, B, Qs


def vc_residual(parts, Gl, n):
    """``(n, d)`` sum over the parts' families of
    :math:`\\sum_{kj} w_{kj} G^{kji}` per particle ``i`` (the constraint
    residual without the area vectors), ``Gl`` the derivatives per
    part."""
    d = parts[0][0].shape[-1]
    return sum(constraint_residual(Gp, p[1], p[2], np.zeros((d, n)))
               for Gp, p in zip(Gl, parts))


def vc_apply(parts, Qs, alpha):
    r"""The corrected derivatives per part, :math:`G^{kji} + \varphi^{ki}
    Q^{kj}\alpha^k` (V2: :math:`\varphi^{ki}\alpha^k` at every member),
    ``alpha`` of shape ``(nf, d)``."""
    Gc = []
    for (Gp, _, f, ph, idx), Q in zip(parts, Qs):
        mask = f.padded()[1]
        al = alpha if idx is None else alpha[idx]
        if ph.ndim == 4:  # V2: C^{kji} = phi^{ki} alpha^k, every member j
            Ha = (ph @ al[:, None, :, None])[..., 0]  # (nf, m_i, d)
            Gc.append(Gp + mask[:, :, None, None] * Ha[:, None, :, :])
        else:
            Qa = (Q @ al[:, None, :, None])[..., 0] * mask[..., None]
            Gc.append(Gp + ph[:, None, :, None] * Qa[:, :, None, :])
    return Gc


class VCSystem(NamedTuple):
    r"""The arrays a VC correction reads (:func:`vc_correction`,
    :func:`~skfem_pg.discretization.vc2.vc2_correction`,
    :func:`~skfem_pg.discretization.local_vc.local_vc_correction`, the
    distributed solve): what the integration constraint (5.18) is made
    of.

    Attributes
    ----------
    G
        ``(nf, m, m, d)`` derivatives (bond corrected for V5).  Unpadded:
        ``G``, ``dx``, ``families`` and ``phi`` may instead be lists with
        one entry per size group (:mod:`skfem_pg.discretization.layout`;
        ``families`` the groups'
        :meth:`~skfem_pg.discretization.layout.SizeGroups.subset`
        families) and ``index`` the groups' family indices; the corrected
        ``G`` is then a list too.
    dx
        ``(nf, m)`` PBG weights :math:`w_{kj}`.
    x, volumes
        Particle positions ``(d, np)`` and volumes.
    families
        :class:`~skfem_pg.discretization.families.Families`.
    area
        ``(d, np)`` area vectors :math:`A^i`.
    phi
        ``(nf, m)`` correction function values
        (:func:`correction_functions`).
    surface
        ``(d, np)`` area vectors over the true surface only (default
        ``area``): with ``s``/``sn`` the particles where it is non-zero
        are the surface particles, and its direction their normal.  For a
        PG subdomain coupled to FE the interface particles have a non-zero
        ``area`` but keep their constraints
        (:meth:`~skfem_pg.Particles.surface_area_vectors`); under ``sn``
        the surface particles on the interface's edge are fixed fully, as
        under ``s``
        (:func:`~skfem_pg.discretization.vc_boundary.interface_edge`).
    index
        With list arguments: per group its family indices.

    Examples
    --------
    The system of a default basis, corrected again: the constraint holds
    already, so the correction changes nothing:

    >>> import numpy as np, skfem as fem, skfem_pg as pg
    >>> p = pg.Particles.from_mesh(fem.MeshQuad().refined(2))
    >>> b = pg.FamilyBasis(p, dim=2, vc="V3", bond=False)
    >>> phi = correction_functions("V3", p.x, p.volumes, b.families)
    >>> G, rep = vc_correction(VCSystem(np.asarray(b.G), np.asarray(b.dx),
    ...     p.x, p.volumes, b.families, p.area_vectors(), phi), variant="V3")
    >>> bool(np.abs(G - b.G).max() < 1e-10), rep.residual_after < 1e-10
    (True, True)

    """

    G: Any
    dx: Any
    x: np.ndarray
    volumes: np.ndarray
    families: Any
    area: np.ndarray
    phi: Any
    surface: Optional[np.ndarray] = None
    index: Any = None


def vc_correction(system, variant="V5", solver="auto", tol=1e-14,
                  maxiter=None, exclude=None, boundary="min-norm"):
    r"""Correct the derivatives of ``system`` so the PBG integration
    constraint holds.

    Parameters
    ----------
    system
        :class:`VCSystem`: the derivatives, weights, particles, families,
        area vectors and correction functions.
    variant
        ``"V5"`` (with bond projector, keeps the bond mapping), ``"V3"``,
        ``"V4"``, ``"V1"`` (no projector) or ``"V2"`` (matrix-valued
        :math:`\varphi^{ki} = \partial^2 N^{ki}_{WLS2}` (5.61),
        :math:`C^{kji} = \varphi^{ki}\alpha^k`).
    solver
        ``"direct"`` (one scalar sparse LU of the pinned system; the
        default, ``"auto"``), ``"amg"`` (the same pinned system by
        AMG-GMRES, linear in the particle count; ``"auto"`` in 3-D above
        :data:`AMG_VC_LIMIT_3D` particles) or ``"lsqr"`` (scipy LSQR; a
        reference, its iteration count grows with the node count).  V1, V2 and
        V4, and any ``exclude``, take LSQR: their systems lack the structure
        the direct solve relies on (V4's left null space holds the quadratic
        fields and is incompatible with the surface terms, V1 does not
        keep the linear fields in it).
    exclude
        Particles whose constraints are not enforced (Dirichlet particles,
        whose equations are eliminated); needed by V4 for round-off
        patch tests.
    boundary
        How the singular system is made regular
        (:mod:`skfem_pg.discretization.vc_boundary`): ``"min-norm"`` (default:
        all constraints with FE-consistent
        :math:`A^i`, minimum-norm solution), or the thesis' variants
        ``"p"`` (V3/V5: correction fixed at ``d + 1`` anchor particles),
        ``"s"`` (fixed at all surface particles, their constraints
        released) and ``"sn"`` (normal component fixed at surface
        particles, the normal constraint released), both by one sparse LU.
        With ``s``/``sn`` the surface particles' discrete area vectors
        differ from :math:`A^i` by ``VCReport.area_correction``, which
        consistent Neumann loads must include.

    Returns
    -------
    G_corrected, VCReport

    """
    G, dx, x, volumes, fam, area, phi, surface, index = system
    _check_vc_options(variant, boundary, exclude)
    grouped = isinstance(G, (list, tuple))
    parts, masters, B, Qs = vc_parts(G, dx, fam, phi, index, x, variant)
    nf = len(masters)
    d, n = x.shape
    active = volumes > 0
    h = np.mean(volumes[active]) ** (1.0 / d)
    area_scale = h ** (d - 1)
    t0 = time.perf_counter()

    def residual(Gl):
        return vc_residual(parts, Gl, n) - area.T

    def matrix(scalar=False):
        out = 0
        for _, _, f, ph, idx in parts:
            Bp = B if idx is None else B[idx]
            out = out + (scalar_constraint_matrix(ph, f, n, idx, nf)
                         if scalar else
                         constraint_matrix(ph, Bp, f, n, idx, nf))
        return out.tocsr()

    r0 = residual([p[0] for p in parts])
    b = -r0.ravel()
    # the part of b outside range(A) (e.g. volumes that do not add up to
    # the enclosed volume) cannot be corrected: least squares drops it
    keep = active.copy()
    if exclude is not None:
        keep[np.asarray(exclude, dtype=np.int64)] = False
    structured = variant in ("V3", "V5") and exclude is None \
        and boundary in ("min-norm", "p")
    if structured:
        P = linear_fields(x, active)
        b = b - P @ (P.T @ b)
    solver = _vc_solver(solver, structured, boundary, d, int(active.sum()))
    notes = []
    unknowns = d * nf

    def lsqr():  # the full block system, only built when needed
        A = matrix()
        rows = np.repeat(keep, d)
        return _solve_lsqr(A[rows], b[rows], tol, maxiter or 20 * unknowns)

    R = None
    if boundary in ("s", "sn"):
        R, T = vc_boundary.reduction(
            masters, area if surface is None else surface, boundary, n,
            active, full=vc_boundary.interface_edge(area, surface))
        try:
            alpha = vc_boundary.solve_reduced(matrix(), b, R, T)
        except RuntimeError as err:
            raise VCSolveError("VC {} with boundary variant {!r}: {}".format(
                variant, boundary, err)) from None
        its, unknowns = 2, T.shape[1]
        notes.append("boundary {}: {} equations and unknowns".format(
            boundary, R.shape[0]))
    else:
        alpha, its, solver = _solve_pinned_or_lsqr(
            solver, matrix, lsqr, masters, B, b, x, active, boundary, notes)
    Gc = vc_apply(parts, Qs, alpha.reshape(-1, d))
    r1 = residual(Gc)
    if not grouped:
        Gc = Gc[0]
    rep = _vc_report(variant, solver, boundary, unknowns, its, notes, r0, r1,
                     R, keep, area_scale, time.perf_counter() - t0)
    return Gc, rep


def _check_vc_options(variant, boundary, exclude):
    if variant not in ("V1", "V2", "V3", "V4", "V5"):
        raise ValueError("VC variant {!r} is not available (V1, V2, V3, "
                         "V4, V5; second order: skfem_pg.discretization.vc2)"
                         .format(variant))
    if boundary not in BOUNDARY_VARIANTS:
        raise ValueError("VC boundary variant {!r} is not available: use "
                         "one of {}".format(boundary,
                                            ", ".join(BOUNDARY_VARIANTS)))
    if boundary != "min-norm" and exclude is not None:
        raise ValueError("vc_exclude is for the minimum-norm solve; the "
                         "boundary variants 'p', 's', 'sn' choose the "
                         "released constraints themselves")
    if boundary == "p" and variant not in ("V3", "V5"):
        raise ValueError("boundary variant 'p' pins the d + d² linear "
                         "modes of V3/V5; {} has others: use 's' or 'sn'"
                         .format(variant))


def _vc_solver(solver, structured, boundary, d, n_active):
    """The solver ``"auto"`` stands for, or a named error for one that
    cannot solve this system (:func:`vc_correction`'s ``solver``)."""
    if solver == "auto":
        solver = "direct" if structured or boundary in ("s", "sn") \
            else "lsqr"
        if solver == "direct" and structured and d == 3 \
                and n_active > AMG_VC_LIMIT_3D:
            solver = "amg"
    if boundary in ("s", "sn"):
        if solver != "direct":
            raise ValueError("the boundary variants 's'/'sn' are solved by "
                             "sparse LU (solver='direct' or 'auto')")
    elif solver in ("direct", "amg") and not structured:
        raise ValueError("the {} VC solve needs V3/V5 without exclude; "
                         "use solver='lsqr'".format(solver))
    elif solver not in ("direct", "amg", "lsqr"):
        raise ValueError("unknown VC solver {!r}: use 'direct', 'amg', "
                         "'lsqr' or 'auto'".format(solver))
    return solver


def _solve_pinned_or_lsqr(solver, matrix, lsqr, masters, B, b, x, active,
                          boundary, notes):
    """``(alpha, iterations, solver used)`` of the min-norm / ``p``
    system: the pinned scalar LU (or AMG-GMRES), falling back to LSQR
    where the system is singular beyond the linear fields."""
    if solver == "lsqr":
        return lsqr() + (solver,)
    try:
        alpha, its, used = solve_pinned_lu(
            matrix(scalar=True), masters, B, b, x, active,
            min_norm=boundary == "min-norm", iterative=solver == "amg")
        if used != solver:
            notes.append("AMG-GMRES did not converge; solved by LU")
        return alpha, its, used
    except RuntimeError as err:  # singular beyond the linear fields
        notes.append("direct solve failed ({}); fell back to LSQR"
                     .format(err))
        return lsqr() + ("lsqr",)


def _vc_report(variant, solver, boundary, unknowns, its, notes, r0, r1, R,
               keep, area_scale, seconds):
    n, d = r1.shape
    if R is not None:  # imposed: R r = 0; the rest moves A^i
        imposed = (R @ r0.ravel(), R @ r1.ravel())
        area_correction = r1.T.copy()
        per_particle = (R.T @ imposed[1]).reshape(n, d)
    else:
        imposed = (r0[keep], r1[keep])
        area_correction = None
        per_particle = r1 * keep[:, None]
    rep = VCReport(variant=variant, solver=solver, unknowns=unknowns,
                   constraints=(R.shape[0] if R is not None
                                else int(keep.sum()) * d),
                   residual_before=float(np.abs(imposed[0]).max()
                                         / area_scale),
                   residual_after=float(np.abs(imposed[1]).max()
                                        / area_scale),
                   iterations=its, seconds=seconds,
                   notes=notes, boundary=boundary,
                   area_correction=area_correction,
                   particle_residuals=np.abs(per_particle).max(axis=1)
                   / area_scale)
    if variant in ("V2", "V4"):
        rep.notes.append(
            "{}'s full system is incompatible: release the surface "
            "constraints (vc_boundary='s' or 'sn') or pass the Dirichlet "
            "particles as vc_exclude".format(variant))
    return rep


def correction_functions(variant, x, volumes, fam, n=1):
    r"""Correction functions :math:`\varphi^{ki}`, shape ``(nf, m)`` (zero
    in padded slots):

    * V1: :math:`1 - \delta_{ki} n_k` (zeroth order only; PPG);
    * V2: :math:`\partial^2 N^{ki}_{WLS2}` (5.61), shape ``(nf, m, d, d)``
      (keeps linear consistency);
    * V3, V5: :math:`N^{kki}_{MLS1} - \delta_{ki}` (keep linear
      consistency; V5 adds the bond projector in :func:`vc_correction`);
    * V4, VC2: :math:`N^{kki}_{WLS2} - \delta_{ki}` (keep quadratic
      consistency, for U2).
    """
    mem, mask = fam.padded()
    if variant == "V1":
        phi = mask.astype(float)
        phi[:, 0] -= fam.sizes
        return phi
    if variant == "V2":
        return wls2_master_hessians(x, volumes, fam, n=n) \
            * mask[..., None, None]
    if variant in ("V3", "V5"):
        phi = mls1_master_values(x, volumes, fam, n=n)
    elif variant in ("V4", "VC2"):
        phi = wls2_master_values(x, volumes, fam, n=n)
    else:
        raise ValueError("no correction function for {!r}".format(variant))
    phi[:, 0] -= 1.0
    return phi * mask
