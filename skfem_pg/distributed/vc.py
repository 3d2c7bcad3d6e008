r"""The VC constraint system solved on all ranks with PETSc
(``vc_solver="petsc"`` of a distributed basis).

The serial solve (:func:`~skfem_pg.discretization.corrections.
_solve_pinned_lu`) works on the scalar matrix :math:`\Phi^T` (row: particle
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
"""
import numpy as np

from . import petsc as pt
from .comm import mpi, petsc

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
                raise RuntimeError(
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
