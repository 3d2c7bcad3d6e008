r"""Linear and Newton solves of distributed models on PETSc.

Inputs that describe the whole problem — external forces, prescribed dofs
and values — are given as in serial runs, in scikit-fem's serial numbering
and the same on every rank (they come from the replicated mesh, e.g.
``pg.traction`` on a serial FE basis).  Each rank assembles its families
on its local basis; :mod:`~skfem_pg.distributed.petsc` sums the ranks'
parts into one PETSc matrix and vector.  Results come back in the serial
numbering on every rank (:meth:`Partition.gather`), so output and
post-processing are the serial ones.

Dirichlet conditions are PETSc's ``MatZeroRowsColumns``: the rows and
columns of the prescribed dofs are replaced by the identity and the
prescribed values lifted to the right-hand side (the serial solver's
``K_II u_I = f_I - K_ID u_D``).
"""
import time
from dataclasses import dataclass

import numpy as np

from . import petsc as pt
from .comm import mpi
from ..dofs import as_dofs
from ..solvers.result import Result
from ..solvers.static import ConvergenceError, verdict


def _dirichlet(part, D, u_D):
    """``(rows, values)``: the owned PETSc rows of the serial dofs ``D``
    (indices or a scikit-fem ``DofsView``) and the values of ``u_D``
    (serial vector or None) there."""
    D = as_dofs(D, part.N, "Dirichlet dofs (serial numbering)")
    mine = D[part.owner[D // part.ncomp] == part.rank]
    rows = part.serial_to_petsc(mine)
    if u_D is None:
        return rows, np.zeros(len(rows))
    u_D = np.asarray(u_D, dtype=float)
    if u_D.shape != (part.N,):
        raise ValueError("u_D is a serial vector of {} entries, got shape "
                         "{}".format(part.N, u_D.shape))
    return rows, u_D[mine]


def _lifted(K, rhs, rows, values, part):
    """``K`` and ``rhs`` with the identity at ``rows``, ``values`` lifted
    (in place)."""
    x = pt.empty_vector(part)
    if len(rows):
        x.setValues(rows, values)
    x.assemble()
    K.zeroRowsColumns(rows, diag=1.0, x=x, b=rhs)
    x.destroy()


def _impose(x, rows, values):
    """Set the prescribed values exactly (an iterative solve meets the
    identity rows only to its tolerance, and a boundary off by 1e-10
    moves the interior as much)."""
    if len(rows):
        x.setValues(rows, values)
    x.assemble()


def solve(K, part, f=None, D=None, u_D=None, options=None, symmetric=True,
          rtol=pt.RTOL):
    """Solve the linear system whose rank-local parts are ``K`` (scipy
    sparse, local dofs of ``part``'s basis) with the serial load ``f``
    and Dirichlet dofs ``D`` (values ``u_D``, serial vectors) by
    :func:`~skfem_pg.distributed.petsc.krylov` (CG, GMRES if not
    ``symmetric``; GAMG; relative tolerance ``rtol``; ``options``).

    Returns ``(u, info)``: ``u`` in the serial numbering on every rank,
    ``info`` with the KSP iterations and seconds for assembly and solve.
    """
    t0 = time.perf_counter()
    A = pt.matrix(K, part)
    b = pt.from_serial(np.zeros(part.N) if f is None else f, part)
    rows, values = _dirichlet(part, D, u_D)
    _lifted(A, b, rows, values, part)
    pt.check_rigid_body_modes(A, part)
    t1 = time.perf_counter()
    ksp = pt.krylov(A, part, options, symmetric=symmetric, rtol=rtol)
    try:
        x, its = pt.solve_ksp(ksp, b, part)
    finally:
        ksp.destroy()
    _impose(x, rows, values)  # the Krylov solve is inexact there
    t2 = time.perf_counter()
    u = part.gather(x)
    A.destroy()
    return u, {"iterations": its, "t_assemble": t1 - t0,
               "t_linear": t2 - t1}


def newton(model, part, f_ext=None, D=None, u_D=None, steps=1, tol=1e-10,
           maxiter=25, min_step=1.0 / 64, options=None, rtol=1e-8,
           verbose=True):
    r"""Newton's method for :math:`f_{int}(u) = \lambda f_{ext}` up to
    :math:`\lambda = 1` on a distributed model, with adaptive load steps.

    ``model`` is a displacement model (e.g.
    :class:`~skfem_pg.formulations.Hyperelastic`) on the rank's local
    basis (:meth:`Partition.basis`); ``f_ext`` (at load factor 1) is a
    serial vector, ``D`` serial dofs, ``u_D`` a serial vector at load
    factor 1 (scaled) or a callable ``u_D(t)`` returning it at load
    factor ``t`` (a rotation), as in the serial solver.

    A step converges when :math:`|r_{free}| \le` ``tol``
    :math:`\max(|\lambda f_{ext}|, |r_0|)`, or by the serial solver's
    energy and round-off-floor criteria (:func:`skfem_pg.solvers.newton`).
    Each linear solve is :func:`~skfem_pg.distributed.petsc.krylov` (CG +
    GAMG to the relative tolerance ``rtol``; ``options`` override): the
    answer's accuracy is set by ``tol`` on the true residual, an inexact
    solve only costs iterations.  A step that does not converge within
    ``maxiter``, reaches :math:`J \le 0` or a non-finite residual, or
    whose Krylov solve diverges (an indefinite tangent far from
    equilibrium) is halved; a step that converges in at most 4
    iterations doubles the next (the serial policy).  Below ``min_step``
    :class:`~skfem_pg.solvers.ConvergenceError` is raised.

    Returns ``(u, history)`` like :func:`skfem_pg.solvers.newton`: ``u``
    in the serial numbering on every rank, ``history`` one dict per
    converged step (load, residual norms, increment energies, KSP
    iterations, minimum J, seconds).
    """
    if getattr(model, "N", None) != getattr(model, "n_u", model.N):
        raise NotImplementedError(
            "{} has global extra fields; the distributed Newton solves "
            "displacement models".format(type(model).__name__))
    if model.N != len(part.local) * part.ncomp:
        raise ValueError("the model is not on this partition's local "
                         "basis ({} dofs, the partition has {} local dofs)"
                         .format(model.N, len(part.local) * part.ncomp))
    F = pt.from_serial(np.zeros(part.N) if f_ext is None else f_ext, part)
    if callable(u_D):
        rows = _dirichlet(part, D, None)[0]

        def prescribed(t):
            return _dirichlet(part, D, u_D(t))[1]
    else:
        rows, values = _dirichlet(part, D, u_D)

        def prescribed(t):
            return t * values
    U = pt.empty_vector(part)
    history = []
    lam, dlam = 0.0, 1.0 / steps
    while lam < 1.0 - 1e-14:
        target = min(1.0, lam + dlam)
        t0 = time.perf_counter()
        ok, Uk, info, state = _newton_step(model, part, U, target, F, rows,
                                           prescribed(target), tol, maxiter,
                                           options, rtol)
        info.update(load=target, seconds=time.perf_counter() - t0)
        if verbose and part.rank == 0:
            print("  load {:.4f}: {} in {} it, |r| {}, KSP {}, min J "
                  "{:.3g}".format(
                      target, "converged" if ok else "FAILED ({})".format(
                          info["reason"]), len(info["residuals"]) - 1,
                      " ".join("{:.1e}".format(r)
                               for r in info["residuals"]),
                      info["krylov"], info["min_J"]), flush=True)
        if ok:
            if hasattr(model, "commit"):
                model.commit(state)
            U.destroy()
            U, lam = Uk, target
            history.append(info)
            if len(info["residuals"]) <= 5:
                dlam = min(2 * dlam, 1.0)
            continue
        Uk.destroy()
        dlam = (target - lam) / 2
        if dlam < min_step:
            raise ConvergenceError(
                "Newton failed at load factor {:.6g} ({}); the step fell "
                "below min_step = {:.3g} after reaching load {:.6g}".format(
                    target, info["reason"], min_step, lam), load=lam,
                u=part.gather(U), history=history)
    return part.gather(U), history


def _newton_step(model, part, U0, lam, F, rows, prescribed, tol, maxiter,
                 options, rtol):
    """Newton iterations at load factor ``lam`` from the converged ``U0``
    (not changed), ``prescribed`` the values at ``rows`` at this load.
    Returns ``(ok, U, info, state)``."""
    MPI = mpi()
    U = U0.copy()
    res, energy = [], []  # residual norms, |dU . R| per solve
    info = {"residuals": res, "energies": energy, "krylov": [],
            "min_J": np.nan, "reason": "", "t_assemble": 0.0,
            "t_linear": 0.0}
    pending = part.comm.allreduce(
        bool(np.any(prescribed != U.getValues(rows))) if len(rows)
        else False, op=MPI.LOR)
    ref = None
    for it in range(maxiter + 1):
        t0 = time.perf_counter()
        state = model.state(pt.to_local(U, part))
        info["min_J"] = part.comm.allreduce(model.min_J(state), op=MPI.MIN)
        if not info["min_J"] > 0:
            info["reason"] = "J <= 0"
            return False, U, info, None
        R = pt.vector(-model.internal_force(state), part)
        R.axpy(lam, F)  # R = lam f_ext - f_int
        if len(rows):
            R.setValues(rows, np.zeros(len(rows)))
        R.assemble()
        rn = R.norm()
        res.append(rn)
        if not np.isfinite(rn):
            info["reason"] = "non-finite residual"
            return False, U, info, None
        if not pending:  # the serial solver's criteria
            if ref is None:
                ref = max(lam * F.norm(), rn, 1e-300)
            done, info["reason"] = verdict(res, energy, ref, tol)
            if done is not None:
                return done, U, info, state if done else None
        if it == maxiter:
            info["reason"] = "maxiter"
            return False, U, info, None
        K = pt.matrix(model.tangent(state), part)
        inc = (prescribed - U.getValues(rows) if pending
               else np.zeros(len(rows)))
        _lifted(K, R, rows, inc, part)
        if it == 0:
            pt.check_rigid_body_modes(K, part)
        t1 = time.perf_counter()
        ksp = pt.krylov(K, part, options, rtol=rtol)
        try:
            dU, its = pt.solve_ksp(ksp, R, part)
        except pt.KSPError as err:  # an indefinite tangent: cut the step
            info["reason"] = "KSP diverged (reason {})".format(err.reason)
            return False, U, info, None
        finally:
            ksp.destroy()
            K.destroy()
        energy.append(abs(dU.dot(R)))
        U.axpy(1.0, dU)
        dU.destroy()
        _impose(U, rows, prescribed)  # the Krylov solve is inexact there
        pending = False
        info["krylov"].append(its)
        info["t_assemble"] += t1 - t0
        info["t_linear"] += time.perf_counter() - t1


@dataclass
class DistributedResult(Result):
    """A scene's :class:`~skfem_pg.solvers.result.Result` from a distributed
    solve: the same fields, in the serial numbering on every rank;
    ``model`` is the rank's part, and :meth:`residual` (so
    :meth:`reaction`) gathers the internal forces of all ranks."""
    partition: object = None

    def residual(self):
        part = self.partition
        x = self.x[part.local_serial_dofs()]
        f = pt.vector(self.model.internal_force(self.model.state(x)), part)
        return part.gather(f) - self.f_ext
