r"""The VC constraint system solved on all ranks with PETSc
(``vc_solver="petsc"`` of a distributed basis).

The serial solve (:func:`~skfem_pg.discretization.corrections.
solve_pinned_lu`) works on the scalar matrix :math:`\Phi^T` (row: particle
``i``, column: the family of master ``k``, entry :math:`\varphi^{ki}`).
:math:`\Phi^T` is singular — the scalar linear fields are its left null
space — so the equations at ``d + 1`` anchor particles are dropped and the
unknowns of their families fixed to zero.  Here the same pinned system is
one square distributed matrix in the partition's particle numbering: the
anchors' rows and columns (and those of particles without a family) are
replaced by the identity.  GMRES solves it for the ``d`` components of
:math:`\beta^k = B^k\alpha^k` and, with the anchors' columns lifted, for
the ``d + 1`` null vectors :math:`z`; the minimum-norm projection of
:math:`\alpha` against :math:`\{(B^k)^{-1} e_a z^k\}` goes through the
:math:`(d + 1)d`-square normal equations, summed over ranks.  So no rank
holds more than its own families; the answer equals the serial one to the
Krylov tolerance.

:func:`vc_correction` is what a rank's basis calls (through
:meth:`Partition.vc_correction`): it assembles the pieces of its
families and solves on rank 0 (the serial code) or, with
``vc_solver="petsc"``, by :func:`solve_pinned` on all ranks.
"""
import functools
import time

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from . import petsc as pt
from ..errors import VCSolveError
from .comm import mpi, petsc, raise_together
from ..discretization.vc.local import (family_shares, local_vc_correction,
                                       smoothed_gradients)
from ..discretization.vc.first_order import (
    AMG_VC_LIMIT_3D, VCReport, solve_pinned_lu, anchor_particles,
    linear_fields, scalar_constraint_matrix, vc_apply, vc_parts,
    vc_residual)

#: relative tolerance of the pinned solves (the serial LU reaches round-off)
RTOL = 1e-14
#: refinement steps after the first solve, on the true residual
REFINE = 1


def _ksp(M, part):
    PETSc = petsc()
    ksp = PETSc.KSP().create(comm=part.petsc_comm)
    ksp.setOptionsPrefix("skfem_pg_vc_")
    ksp.setOperators(M)
    ksp.setType("gmres")
    ksp.setGMRESRestart(300)
    pc = ksp.getPC()
    try:  # BoomerAMG where PETSc has hypre, else block Jacobi / ILU
        pc.setType("hypre")
    except PETSc.Error:
        pc.setType("bjacobi")
    ksp.setTolerances(rtol=RTOL, atol=0.0, max_it=5000)
    ksp.setFromOptions()
    return ksp


def _refuse_pieces(part, rows, masters, active):
    """``NotImplementedError`` where the particles fall into several
    pieces that no family connects: all ranks' solve (:func:`solve_pinned`)
    pins the linear fields of one piece, and the others' corrections would
    not be the minimum-norm ones (rank 0's solve pins each piece)."""
    got = part.comm.gather((rows, masters), root=0)
    count = None
    if part.rank == 0:
        r = np.concatenate([g[0] for g in got])
        c = np.concatenate([g[1] for g in got])
        n = part.n
        G = sp.csr_matrix((np.ones(len(r)), (r, c)), shape=(n, n))
        _, label = connected_components(G, directed=False)
        count = len(np.unique(label[np.asarray(active, bool)]))
    count = part.comm.bcast(count, root=0)
    if count > 1:
        raise NotImplementedError(
            "vc_solver='petsc' pins the linear fields of one piece; these "
            "particles fall into {} pieces that no family connects: use "
            "vc_solver='direct' or 'amg' (rank 0 pins each piece)"
            .format(count))


def solve_pinned(part, rows, cols, vals, fid, B, b, anchors, min_norm=True):
    """``alpha`` ``(nf_local, d)`` of this rank's families (global family
    indices ``fid`` = master particles) from the entries ``(rows, cols,
    vals)`` of :math:`\\Phi^T` (global particle / master numbers), their
    ``B`` ``(nf_local, d, d)``, the projected right-hand side ``b``
    (``(n, d)``, every rank) and the ``anchors``.  Returns ``(alpha,
    iterations)``."""
    PETSc, MPI = petsc(), mpi()
    n, d = b.shape
    idx = part.petsc_index
    own = np.zeros(n, dtype=bool)
    own[part.owned] = True
    # identity for particles that master no family (their rows are empty)
    has = np.zeros(n, dtype=bool)
    has[np.concatenate(part.comm.allgather(fid))] = True
    free = np.nonzero(~has & own)[0]
    M = pt.global_matrix(
        np.concatenate([idx[rows], idx[free]]),
        np.concatenate([idx[cols], idx[free]]),
        np.concatenate([vals, np.ones(len(free))]), part, 1)
    pinned = np.concatenate([anchors, np.nonzero(~has)[0]])
    mine = pinned[own[pinned]]
    prow = idx[mine].astype(PETSc.IntType)
    # the anchors' columns before pinning: the null vectors' right sides
    cols_c = []
    for c in anchors:
        v = M.createVecLeft()
        M.getColumnVector(int(idx[c]), v)
        cols_c.append(v)
    M.zeroRowsColumns(prow, diag=1.0)
    ksp = _ksp(M, part)
    order = part.owned  # PETSc order of the owned particles
    its = 0
    sol = np.zeros((len(order), 2 * d + 1))
    x = M.createVecRight()
    for j in range(2 * d + 1):
        rhs = M.createVecLeft()
        if j < d:
            rhs.setArray(np.where(has[order], b[order, j], 0.0))
        else:
            c = anchors[j - d]
            rhs.setArray(-cols_c[j - d].getArray())
        if len(prow):
            rhs.setValues(prow, np.zeros(len(prow)))
        if j >= d and own[c]:
            rhs.setValue(int(idx[c]), 1.0)
        rhs.assemble()
        x.set(0.0)
        dx = x.duplicate()
        res = rhs.duplicate()
        for _ in range(1 + REFINE):  # GMRES, then refinement steps on
            M.mult(x, res)           # the true residual (as the serial
            res.aypx(-1.0, rhs)      # LU's)
            ksp.solve(res, dx)
            if ksp.getConvergedReason() < 0:
                raise VCSolveError(
                    "the distributed VC solve (GMRES + {}) did not "
                    "converge (reason {}); use vc_solver='direct'".format(
                        ksp.getPC().getType(), ksp.getConvergedReason()))
            its += ksp.getIterationNumber()
            x.axpy(1.0, dx)
        sol[:, j] = x.getArray()
    ksp.destroy()
    M.destroy()
    at = np.searchsorted(order, fid)  # rows of the rank's families
    beta, z = sol[at, :d], sol[at, d:]
    Binv = np.linalg.inv(B)
    alpha = (Binv @ beta[:, :, None])[..., 0]
    if not min_norm:
        return alpha, its
    nf = len(fid)
    Z = (Binv[:, None, :, :] * z[:, :, None, None]).transpose(0, 2, 1, 3) \
        .reshape(nf * d, (d + 1) * d)
    G = part.comm.allreduce(Z.T @ Z, op=MPI.SUM)
    r = part.comm.allreduce(Z.T @ alpha.ravel(), op=MPI.SUM)
    coef = np.linalg.lstsq(G, r, rcond=None)[0]
    return (alpha.ravel() - Z @ coef).reshape(nf, d), its


def vc_correction(part, system, variant="V5", solver="auto", exclude=None,
                  boundary="min-norm"):
    """:func:`~skfem_pg.discretization.vc.first_order.vc_correction` of the
    families of partition ``part`` with the global constraint system
    (:mod:`~skfem_pg.distributed.partition`): ``system`` (a
    :class:`~skfem_pg.discretization.vc.first_order.VCSystem`) holds the
    local arrays, as the basis passes them.  ``solver`` ``"direct"``/``"amg"``
    (``"auto"``): rank 0 solves the gathered system with the serial code;
    ``"petsc"``: all ranks (:func:`solve_pinned`)."""
    G, dx, x, volumes, fam, area, phi, surface, index = system
    t0 = time.perf_counter()
    grouped = isinstance(G, (list, tuple))
    parts, masters_l, B_l, Qs = vc_parts(G, dx, fam, phi, index, x,
                                         variant)
    p, d = part.particles, x.shape[0]
    xg, active = p.x, p.active
    A = part.area_vectors()
    fid = part._family_index[part.local[masters_l]]
    r0 = part.sum_particles(
        vc_residual(parts, [q[0] for q in parts], len(part.local))) \
        - A.T
    b = -r0.ravel()
    P = linear_fields(xg, active)
    b = b - P @ (P.T @ b)
    PhiT = sum(scalar_constraint_matrix(ph, f, len(part.local), idx,
                                        len(masters_l))
               for _, _, f, ph, idx in parts).tocoo()
    rows = part.local[PhiT.row]
    nf = len(part._masters)
    if solver == "auto":
        solver = ("amg" if d == 3 and int(active.sum()) > AMG_VC_LIMIT_3D
                  else "direct")
    if solver not in ("direct", "amg", "petsc"):
        raise NotImplementedError(
            "vc_solver={!r} on MPI: use 'direct' or 'amg' (rank 0 "
            "solves the pinned scalar system) or 'petsc' (all ranks)"
            .format(solver))
    if solver == "petsc":
        mp = part.local[masters_l]  # the families' master particles
        _refuse_pieces(part, rows, mp[PhiT.col], active)
        al, its = solve_pinned(
            part, rows, mp[PhiT.col], PhiT.data, mp, B_l,
            b.reshape(-1, d), anchor_particles(xg, active),
            min_norm=boundary == "min-norm")
        return _finish(part, parts, Qs, al, r0, grouped, variant, solver,
                       nf, its, boundary, t0)
    cols = fid[PhiT.col]
    got = part.comm.gather((rows, cols, PhiT.data, fid, B_l), root=0)
    alpha = err = None
    if part.rank == 0:
        R = np.concatenate([g[0] for g in got])
        C = np.concatenate([g[1] for g in got])
        V = np.concatenate([g[2] for g in got])
        Bg = np.empty((nf, d, d))
        for g in got:
            Bg[g[3]] = g[4]
        M = sp.csr_matrix((V, (R, C)), shape=(part.n, nf))
        try:
            alpha, its, _ = solve_pinned_lu(
                M, part._masters, Bg, b, xg, active,
                min_norm=boundary == "min-norm",
                iterative=solver == "amg")
        except RuntimeError as e:
            err = str(e)
    alpha, its, err = part.comm.bcast(
        (alpha, its if alpha is not None else 0, err), root=0)
    if err is not None:
        raise VCSolveError("the distributed VC solve failed on rank 0: "
                           "{}".format(err))
    return _finish(part, parts, Qs, alpha.reshape(-1, d)[fid], r0, grouped,
                   variant, solver + " (rank 0)", nf, its, boundary, t0)


def _finish(part, parts, Qs, alpha, r0, grouped, variant, solver, nf, its,
            boundary, t0):
    """Apply ``alpha`` (the rank's families) and report."""
    p, A = part.particles, part.area_vectors()
    active, d = p.active, p.dim
    Gc = vc_apply(parts, Qs, alpha)
    r1 = part.sum_particles(
        vc_residual(parts, Gc, len(part.local))) - A.T
    h = np.mean(p.volumes[active]) ** (1.0 / d)
    scale = h ** (d - 1)
    per = np.abs(r1 * active[:, None]).max(axis=1) / scale
    rep = VCReport(
        variant=variant, solver=solver, unknowns=d * nf,
        constraints=int(active.sum()) * d,
        residual_before=float(np.abs(r0[active]).max() / scale),
        residual_after=float(np.abs(r1[active]).max() / scale),
        iterations=its, seconds=time.perf_counter() - t0,
        boundary=boundary, particle_residuals=per[part.local])
    return (Gc if grouped else Gc[0]), rep


def local_solver(part):
    """The ``vc_solve`` of a rank's basis with ``vc_solver="local"``
    (:func:`skfem_pg.discretization.vc.local.local_vc_correction`): the
    shares of the partition's owned masters on the replicated mesh, the
    residual summed over the ranks, an error of one rank's families
    raised on every rank — no other communication."""
    glob = part.particles
    S = []
    A = part.area_vectors()

    def shares(masters, mem, mask):
        if not S:
            S.extend(smoothed_gradients(part.mesh, glob.elements,
                                        rows=part.owned))
        return family_shares(S, part.local[masters], part.local[mem], mask,
                             glob.x)

    def complete(sums):
        return part.sum_particles(sums) - A.T, glob.active
    return functools.partial(
        local_vc_correction, shares=shares, complete=complete,
        together=functools.partial(raise_together, part.comm))
