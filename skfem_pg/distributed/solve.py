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
from ..progress import Echo
from ..solvers.controls import NewtonControls
from ..solvers.problem import Problem, Solution
from ..discretization.follower import split_loads
from ..solvers.static import (LinearSolveFailed, load_stepping,
                              newton_iterations)


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


#: the distributed Newton's defaults where they differ from the serial
#: ones (:class:`~skfem_pg.solvers.static.NewtonControls`): no secant
#: predictor, a tighter tolerance, at most six halvings
DISTRIBUTED_DEFAULTS = {"tol": 1e-10, "min_step": 1.0 / 64,
                        "predictor": False}


def newton(model, part, f_ext=None, D=None, u_D=None, options=None,
           rtol=1e-8, controls=None, **kw):
    r"""Newton's method for :math:`f_{int}(u) = \lambda f_{ext}` up to
    :math:`\lambda = 1` on a distributed model, with adaptive load steps:
    the serial driver (:func:`~skfem_pg.solvers.static.load_stepping`,
    :func:`~skfem_pg.solvers.static.newton_iterations`) on PETSc vectors
    and Krylov solves (:class:`PetscAlgebra`).

    ``model`` is a :class:`~skfem_pg.solvers.problem.Problem` or a
    displacement model (e.g.
    :class:`~skfem_pg.formulations.Hyperelastic`) on the rank's local
    basis (:meth:`Partition.basis`); ``f_ext`` (the problem's or the
    keyword) (at load factor 1) is a
    serial vector, ``D`` serial dofs, ``u_D`` a serial vector at load
    factor 1 (scaled) or a callable ``u_D(t)`` returning it at load
    factor ``t`` (a rotation), as in the serial solver.

    ``controls`` / ``kw``: the serial
    :class:`~skfem_pg.solvers.static.NewtonControls` (``steps``, ``tol``,
    ``maxiter``, ``min_step``, ``adaptive``, ``predictor``,
    ``line_search``, ``verbose``), defaults :data:`DISTRIBUTED_DEFAULTS`.
    A step converges by the serial criteria.  Each linear solve is
    :func:`~skfem_pg.distributed.petsc.krylov` (CG + GAMG to the relative
    tolerance ``rtol``; PETSc ``options`` override): the answer's accuracy
    is set by ``tol`` on the true residual, an inexact solve only costs
    iterations.  A step that does not converge within ``maxiter``,
    reaches :math:`J \le 0` or a non-finite residual, or whose Krylov
    solve diverges (an indefinite tangent far from equilibrium) is
    halved, as in the serial solver.

    Returns a :class:`~skfem_pg.solvers.problem.Solution` ``(x,
    history)`` like :func:`skfem_pg.solvers.newton`: ``x``
    in the serial numbering on every rank, ``history`` one dict per
    converged step (load, residual norms, increment energies, KSP
    iterations, minimum J, seconds).
    """
    opts = NewtonControls.of(controls, defaults=DISTRIBUTED_DEFAULTS, **kw)
    problem = Problem.of(model, "newton", f_ext=f_ext, D=D, u_D=u_D)
    model, f_ext, D, u_D = problem.model, problem.f_ext, problem.D, \
        problem.u_D
    if opts.reuse:
        raise NotImplementedError(
            "reuse=True (modified Newton with kept factors) is serial: the "
            "distributed Newton refactorizes PETSc's preconditioner every "
            "iteration; drop reuse=")
    if model.N != model.n_u:
        raise NotImplementedError(
            "{} has global extra fields; the distributed Newton solves "
            "displacement models".format(type(model).__name__))
    if model.N != len(part.local) * part.ncomp:
        raise ValueError("the model is not on this partition's local "
                         "basis ({} dofs, the partition has {} local dofs)"
                         .format(model.N, len(part.local) * part.ncomp))
    if split_loads(f_ext)[1]:
        raise NotImplementedError(
            "follower loads (FollowerPressure) on MPI ranks: the "
            "distributed Newton takes dead load vectors; run it serially")
    F = pt.from_serial(np.zeros(part.N) if f_ext is None else f_ext, part)
    if callable(u_D):
        rows = _dirichlet(part, D, None)[0]

        def prescribed(t):
            return _dirichlet(part, D, u_D(t))[1]
    else:
        rows, values = _dirichlet(part, D, u_D)

        def prescribed(t):
            return t * values
    algebra = PetscAlgebra(model, part, F, rows, options, rtol)

    def step(start, target):
        n0 = len(algebra.krylov)
        out = newton_iterations(model, algebra, start, target,
                                prescribed(target), opts.tol, opts.maxiter,
                                opts.line_search)
        out[2]["krylov"] = algebra.krylov[n0:]
        return out

    return Solution(*load_stepping(
        model, step, algebra, pt.empty_vector(part), 0.0, 1.0 / opts.steps,
        opts, echo=Echo(opts.verbose if part.rank == 0 else False)))


class PetscAlgebra:
    """The linear algebra of the serial Newton driver
    (:func:`~skfem_pg.solvers.static.newton_iterations`) on a partition:
    PETSc vectors of the owned dofs, the model evaluated on the rank's
    local dofs (:func:`~skfem_pg.distributed.petsc.to_local`), the minimum
    J reduced over the ranks, Dirichlet rows ``rows`` by
    ``MatZeroRowsColumns`` and Krylov solves
    (:func:`~skfem_pg.distributed.petsc.krylov`, ``ksp_options``,
    ``rtol``)."""

    def __init__(self, model, part, F, rows, ksp_options=None, rtol=1e-8):
        self.model, self.part, self.F, self.rows = model, part, F, rows
        self.ksp_options, self.rtol = ksp_options, rtol
        self.krylov = []  # KSP iterations of every solve
    @staticmethod
    def copy(u):
        return u.copy()

    @staticmethod
    def add(u, du, s=1.0):
        u.axpy(s, du)
        return u

    @staticmethod
    def extrapolate(u, prev, c):
        diff = u.copy()
        diff.axpy(-1.0, prev)
        out = u.copy()
        out.axpy(c, diff)
        diff.destroy()
        return out

    @staticmethod
    def release(u):
        u.destroy()

    def serial(self, u):
        return self.part.gather(u)

    def increment_at_dirichlet(self, u, values):
        rows = self.rows
        current = u.getValues(rows) if len(rows) else np.zeros(0)
        pending = self.part.comm.allreduce(
            bool(np.any(values != current)), op=mpi().LOR)
        return values - current, pending

    def state(self, u):
        return self.model.state(pt.to_local(u, self.part))

    def min_J(self, state):
        return self.part.comm.allreduce(self.model.min_J(state),
                                        op=mpi().MIN)

    def residual(self, state, lam, u=None):
        """``R = λ f_ext - f_int`` with zeros at the Dirichlet rows, its
        norm, and ``None`` (the internal force stays distributed)."""
        R = pt.vector(-self.model.internal_force(state), self.part)
        R.axpy(lam, self.F)
        if len(self.rows):
            R.setValues(self.rows, np.zeros(len(self.rows)))
        R.assemble()
        return R, R.norm(), None

    def load_norm(self, lam):
        return lam * self.F.norm()

    def solve(self, state, u, R, du_D, first, lam=1.0):
        t0 = time.perf_counter()
        K = pt.matrix(self.model.tangent(state), self.part)
        _lifted(K, R, self.rows,
                np.zeros(len(self.rows)) if du_D is None else du_D,
                self.part)
        if first:
            pt.check_rigid_body_modes(K, self.part)
        t1 = time.perf_counter()
        ksp = pt.krylov(K, self.part, self.ksp_options, rtol=self.rtol)
        try:
            dU, its = pt.solve_ksp(ksp, R, self.part)
        except pt.KSPError as err:  # an indefinite tangent: cut the step
            raise LinearSolveFailed("KSP diverged (reason {})".format(
                err.reason)) from None
        finally:
            ksp.destroy()
            K.destroy()
        self.krylov.append(its)
        return dU, abs(dU.dot(R)), t1 - t0, time.perf_counter() - t1

    def impose(self, u, values):
        _impose(u, self.rows, values)  # the Krylov solve is inexact there
        return u

    @staticmethod
    def small_increment(du, u):
        return False


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
