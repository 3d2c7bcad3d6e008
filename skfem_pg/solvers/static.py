r"""Newton's method with adaptive load stepping.

Newton drives a model of :mod:`skfem_pg.formulations`: residual
:math:`r(u) = f_{int}(u) - \lambda f_{ext}`, tangent
:math:`\partial f_{int}/\partial u`.

Load stepping: the load factor :math:`\lambda` goes from 0 to 1 (external
forces and prescribed displacements are scaled).  A converged step is
committed (``model.commit``: the internal variables of a plastic
material); a failed one is not, so the history after it is the last
converged one.  A step is cut in half when Newton diverges, exceeds
``maxiter`` or meets :math:`J \le 0` anywhere (with ``line_search``, after
halving the increment); a :class:`ConvergenceError` names the load factor
once the step would fall below ``min_step``.
"""
from __future__ import annotations

import time
from typing import Callable

import numpy as np
from numpy.typing import ArrayLike

from ..formulations.protocol import Model
from .problem import Problem, Solution
from ..dofs import as_dofs, check_sliding
from ..materials import ReturnMapError
from .checkpoint import Every, load as load_checkpoint
from .controls import NewtonControls, check_controls
from ..progress import Echo
from .linear import linear_solver, submatrix
from ..discretization.follower import split_loads
from ..discretization.layout import is_family_basis


class ConvergenceError(RuntimeError):
    """Newton's method could not reach the requested load.

    ``load``, ``u`` and ``history`` hold the last converged state, so a
    caller can report how far the loading got."""

    def __init__(self, message, load=0.0, u=None, history=None):
        super().__init__(message)
        self.load, self.u, self.history = load, u, history or []


#: extra smoothed random near-null-space candidates of the AMG hierarchy
#: for family bases (:class:`AMGSolver`).  12 is the measured compromise:
#: 18 needs the fewest iterations but the longest setup, which Newton's
#: rebuilds (after load steps and fallbacks) pay again (benchmarks/README.md,
#: "Measurements behind the defaults")
PG_CANDIDATES = 12


def condensed_solver(kind, basis, I, extra_fields=False, symmetric=None):
    """The linear solver of the free dofs ``I``; ``symmetric=None``: as
    the basis says (a Petrov–Galerkin basis is not), ``False``: not
    (a follower load's stiffness)."""
    if extra_fields:  # a saddle point or a coupled u-p system: no
        # rigid-body AMG; the direct solve (partial pivoting)
        if kind == "amg":
            raise ValueError("the AMG solver is for displacement unknowns; "
                             "this model has extra global fields: use "
                             "solver='direct' (or 'auto')")
        return linear_solver("direct", None)
    locs = getattr(basis, "doflocs", None)
    # scikit-fem's vector dofs (and the family bases') are interleaved:
    # dof j is component j % d of its node, also for a subset of them
    return linear_solver(kind, None if locs is None else locs[:, I],
                         symmetric=getattr(basis, "test", None) is None
                         and symmetric is not False,
                         candidates=PG_CANDIDATES if is_family_basis(basis)
                         else 0,
                         components=None if locs is None
                         else I % locs.shape[0])


def newton(model: Model, f_ext: ArrayLike | None = None, D=None,
           u_D: ArrayLike | Callable | None = None,
           u0: ArrayLike | None = None, solver: str | Callable = "auto",
           load0: float = 0.0, callback: Callable | None = None,
           checkpoint=None, resume: str | None = None,
           controls: NewtonControls | None = None,
           **kw) -> Solution:
    r"""Solve :math:`f_{int}(x) = \lambda f_{ext}` up to :math:`\lambda = 1`
    with adaptive load steps.

    Parameters
    ----------
    model
        A :class:`~skfem_pg.solvers.problem.Problem` (the model with its
        ``f_ext``, ``D``, ``u_D``), or a :mod:`skfem_pg.formulations`
        model, e.g. ``Hyperelastic(basis, NeoHooke(lam=lam, mu=mu))``, with the
        keywords below.  Its unknowns ``x`` are the displacements
        (``model.n_u``, scikit-fem numbering of ``model.basis``) followed
        by its global extra fields, if any (``model.N`` in all).
    f_ext
        External force vector at load factor 1 (default 0): one entry per
        displacement dof (or per unknown).
    D, u_D
        Prescribed displacement dofs and their values: a vector (one entry
        per displacement dof, or per unknown; only the entries at ``D``
        are read) at load factor 1, scaled by the load factor, or a
        callable ``u_D(t)`` returning that vector at load factor ``t``
        (e.g. a rotation, which is not ``t`` times its end value).
        Default 0.
    u0
        Initial unknowns (displacements, or all unknowns).
    solver
        Linear solver: ``"auto"``, ``"direct"`` or ``"amg"``
        (:func:`linear_solver` on the free dofs), or a callable ``(A, b)
        -> x`` for the condensed systems, e.g. a :func:`linear_solver`
        built once and shared by several calls.
    load0
        The load factor of ``u0``: resume a run there (with a model
        whose history was restored, :mod:`skfem_pg.solvers.checkpoint`).
    callback
        ``callback(x, load, f_int)`` after each converged (and committed)
        step: its unknowns, load factor and internal force vector (the
        reactions at the Dirichlet dofs) — output of load–displacement
        curves and time series without a second evaluation.
    checkpoint
        A path (or :class:`~skfem_pg.solvers.checkpoint.Every`): after
        every converged step (or as often as it says) the unknowns, the
        load factor, the committed history and the step controller (the
        next step, the predictor's previous state) are written there
        atomically (:mod:`~skfem_pg.solvers.checkpoint`).
    resume
        A path written by ``checkpoint``: start from it (instead of
        ``u0`` / ``load0``); the run then ends where the uninterrupted run
        ends, to round-off.  A checkpoint of another model raises.
    controls, **kw
        :class:`NewtonControls` (``steps``, ``tol``, ``maxiter``,
        ``min_step``, ``adaptive``, ``predictor``, ``line_search``,
        ``verbose``, ``reuse``), or its fields as keywords (they replace
        the record's).

    Returns
    -------
    Solution
        ``(x, history)``, a named record that unpacks as a pair.
        ``x``: all unknowns (``model.N``; the displacements are
        ``x[:model.n_u]``).  ``history`` is a list of dicts per converged
        step (load factor, residual norms per iteration, the increments'
        energies ``|Δx·r|``, minimum J, the criterion's note in
        ``reason``, seconds; with ``reuse``: ``tangents``, the fresh
        tangents of the step, and ``undone``, the increments from kept
        factors that were taken back).

    Examples
    --------
    Modified Newton on a 2-D block (the factorization of a tangent kept
    while it contracts the residual): the same answer as full Newton.

    >>> import numpy as np, skfem as fem, skfem_pg as pg
    >>> from skfem_pg.formulations import Hyperelastic
    >>> from skfem_pg.materials import NeoHooke
    >>> mesh = fem.MeshQuad.init_tensor(np.linspace(0, 4, 9),
    ...                                  np.linspace(0, 1, 3))
    >>> basis = pg.FamilyBasis(pg.Particles.from_mesh(mesh), dim=2)
    >>> model = Hyperelastic(basis, NeoHooke(lam=10.0, mu=4.0))
    >>> D = basis.get_dofs(lambda x: x[0] == 0).all()
    >>> f = np.zeros(basis.N)
    >>> f[basis.get_dofs(lambda x: x[0] == 4).nodal["u^2"]] = -0.02
    >>> u, hist = pg.solvers.newton(model, f, D=D, verbose=False)
    >>> v, kept = pg.solvers.newton(model, f, D=D, verbose=False, reuse=True)
    >>> bool(np.abs(u - v).max() < 1e-8 * np.abs(u).max())
    True

    """
    opts = NewtonControls.of(controls, **kw)
    check_controls(load0=load0)
    problem = Problem.of(model, "newton", f_ext=f_ext, D=D, u_D=u_D)
    model, f_ext, D, u_D = problem.model, problem.f_ext, problem.D, \
        problem.u_D
    basis, N, n_u = model.basis, model.N, model.n_u
    Dd = as_dofs(D, n_u, "Dirichlet (displacement) dofs")
    check_sliding(basis, Dd)
    I = np.setdiff1d(np.arange(N), Dd)
    f_ext = external_load(f_ext, n_u, N)
    if callable(u_D):
        values = u_D

        def prescribed(t):
            return padded_vector(values(t), n_u, N, "u_D(t)")
    else:
        u_D1 = padded_vector(u_D, n_u, N, "u_D")

        def prescribed(t):
            return t * u_D1
    x0 = model.initial() if hasattr(model, "initial") else np.zeros(N)
    u = x0 if u0 is None else padded_vector(u0, n_u, N, "u0", x0)
    lin = solver if callable(solver) else condensed_solver(
        solver, basis, I, extra_fields=N > n_u,
        symmetric=False if f_ext.followers else None)
    stats = getattr(getattr(lin, "amg", None), "stats", {"iterations": []})
    lam = float(load0)
    dlam = (1.0 - lam) / opts.steps if lam < 1.0 else 1.0
    prev = None  # (load, u) of the converged step before the last
    if resume is not None:
        if u0 is not None or load0:
            raise ValueError("resume= starts from its checkpoint: give "
                             "neither u0 nor load0 with it")
        u, lam, saved = load_checkpoint(resume, model, state=True,
                                        kind="static")
        if not 0.0 <= lam <= 1.0:
            raise ValueError(
                "checkpoint {} holds load factor {!r}; a static run resumes "
                "from a load factor in [0, 1]".format(resume, lam))
        dlam = float(saved.get("step", dlam))
        if "prev_x" in saved:
            prev = (float(saved["prev_load"]), saved["prev_x"])

    kept = KeptTangent() if opts.reuse else None

    def step(start, target):
        n_krylov = len(stats["iterations"])
        n_tangents = 0 if kept is None else kept.stats["tangents"]
        out = newton_step(model, start, target, f_ext, Dd,
                          prescribed(target)[Dd], I, lin, opts.tol,
                          opts.maxiter, opts.line_search, kept)
        out[2]["krylov"] = stats["iterations"][n_krylov:]
        if kept is not None:
            out[2]["tangents"] = kept.stats["tangents"] - n_tangents
        return out

    try:
        return Solution(*load_stepping(
            model, step, SERIAL, u, lam, dlam, opts, prev=prev,
            callback=callback, every=Every.of(checkpoint)))
    finally:
        if kept is not None:
            kept.free()


def load_stepping(model, step, algebra, u, lam, dlam, options, prev=None,
                  callback=None, every=None, echo=None):
    r"""The load-stepping loop of :func:`newton` and of the distributed
    :func:`skfem_pg.distributed.newton`: from the converged ``u`` at load
    factor ``lam`` to :math:`\lambda = 1`, first step ``dlam``.

    ``step(start, target)`` runs Newton at load factor ``target`` from
    ``start`` and returns ``(ok, x, info, state)``
    (:func:`newton_iterations`); ``algebra`` is the vector arithmetic of
    the unknowns (:data:`SERIAL`, or a partition's PETSc vectors):
    ``extrapolate`` (the predictor), ``release``, ``serial`` (the unknowns
    in scikit-fem's serial numbering).  A converged step is committed
    (``model.commit``), checkpointed (``every``), passed to ``callback``
    and recorded; a failed one is halved, and :class:`ConvergenceError`
    is raised below ``options.min_step``, for fixed steps, or after
    :data:`MAX_LOAD_STEPS` (or 4 ``steps``) attempts.  ``prev`` is the
    predictor's ``(load, x)`` of the step before; ``echo`` prints the
    progress lines (default: :class:`~skfem_pg.progress.Echo` of
    ``options.verbose``).  Returns ``(x, history)``, ``x`` serial."""
    echo = Echo(options.verbose) if echo is None else echo
    history = []
    attempts, max_attempts = 0, max(MAX_LOAD_STEPS, 4 * options.steps)
    while lam < 1.0 - 1e-14:
        attempts += 1
        if attempts > max_attempts:
            raise ConvergenceError(
                "Newton stopped after {} load steps at load factor {:.6g} "
                "(skfem_pg.solvers.static.MAX_LOAD_STEPS)".format(
                    max_attempts, lam), load=lam, u=algebra.serial(u),
                history=history)
        target = min(1.0, lam + dlam)
        t0 = time.perf_counter()
        start = u
        if options.predictor and prev is not None:
            start = algebra.extrapolate(
                u, prev[1], (target - lam) / (lam - prev[0]))
        ok, uk, info, state = step(start, target)
        info.update(load=target, seconds=time.perf_counter() - t0)
        echo(step_line(info, target, target - lam, ok))
        f_int = info.pop("f_int", None)
        if ok:
            if hasattr(model, "commit"):  # history of a converged step
                model.commit(state)
            if prev is not None:
                algebra.release(prev[1])
            prev = (lam, u)
            u, lam = uk, target
            history.append(info)
            if options.adaptive and (
                    info["tangents"] <= 2 if "tangents" in info
                    else len(info["residuals"]) <= 5):
                dlam = min(2 * dlam, 1.0)
            if every is not None:  # before the callback, which may fail
                every.save(len(history), model, u, lam, kind="static",
                           step=dlam,
                           **({} if prev is None else
                              {"prev_load": prev[0], "prev_x": prev[1]}))
            if callback is not None:
                callback(u, lam, f_int)
            continue
        algebra.release(uk)
        dlam = (target - lam) / 2  # the step tried (clipped at 1), halved
        if dlam < options.min_step or not options.adaptive:
            why = ("fixed steps of {:.3g}".format(2 * dlam)
                   if not options.adaptive
                   else "the step fell below min_step = {:.3g}".format(
                       options.min_step))
            raise ConvergenceError(
                "Newton failed at load factor {:.6g} ({}); {} after "
                "reaching load {:.6g}".format(target, info["reason"], why,
                                              lam),
                load=lam, u=algebra.serial(u), history=history)
    return algebra.serial(u), history


def step_line(info, load, step, ok):
    """The progress line of a load step."""
    return ("  load {:.4f} (step {:.4f}): {} in {} it, |r| {}, min J {:.3g}"
            "{}".format(
                load, step, "converged" if ok else "FAILED ({})".format(
                    info["reason"]),
                len(info["residuals"]) - 1,
                " ".join("{:.1e}".format(r) for r in info["residuals"]),
                info["min_J"], ", Krylov {}".format(info["krylov"])
                if info.get("krylov") else ""))


#: most load steps (converged and failed) one :func:`newton` call takes
#: (or 4 ``steps``): no input makes the load loop run forever
MAX_LOAD_STEPS = 10_000


def padded_vector(v, n_u, N, what, rest=None):
    """A vector of one entry per displacement dof (the extra fields'
    entries from ``rest``, default zeros, appended) or per unknown;
    ``None`` gives zeros."""
    if v is None:
        return np.zeros(N)
    v = np.asarray(v, dtype=float).ravel()
    if v.shape == (n_u,) and N > n_u:
        return np.concatenate([v, np.zeros(N - n_u) if rest is None
                               else rest[n_u:]])
    if v.shape != (N,):
        raise ValueError("{} must have one entry per displacement dof ({}){}"
                         ", got {}".format(what, n_u, "" if N == n_u else
                                           " or per unknown ({})".format(N),
                                           v.shape[0]))
    bad = np.nonzero(~np.isfinite(v))[0]
    if len(bad):
        raise ValueError("{} has {} non-finite entries (first: dof {} = {})"
                         .format(what, len(bad), bad[0], v[bad[0]]))
    return v.copy()


#: a residual that stops decreasing is at its round-off floor (e.g. K·eps
#: of a nearly incompressible material: 5e-8 on the Cook membrane with
#: K = 2e7 mu, whatever the load) once the last increment did less than
#: ``ROUNDOFF_ENERGY * tol`` of the step's first increment's work
ROUNDOFF_ENERGY = 1e-3
#: ... or once it is flat (three iterations, each within a factor 1.25 of
#: the one before) below ``STALL_RESIDUAL`` of the reference norm, the
#: last increment doing less than ``ROUNDOFF_ENERGY`` of the first
#: increment's work: the rows of a stiff dilatation (U2P1C, Unl+P1C) floor
#: at K·eps·V, which in a Newmark step near steady state is above ``tol``
#: of the load (Poiseuille flow of water, K = 2.08 GPa, g = 2e-4 m/s²:
#: the residual is flat at 1e-6 of the load, the last increment's work at
#: 1e-8 of the first's)
STALL_RESIDUAL = 1e-5


def _small_increment(model, du, u):
    """Every field's Newton increment below 1e-10 of its magnitude."""
    blocks = getattr(model, "blocks", [("u", slice(None))])
    return all(np.abs(du[b]).max(initial=0.0)
               <= 1e-10 * np.abs(u[b]).max(initial=0.0) for _, b in blocks)


def verdict(res, energy, ref, tol, small=False):
    """The convergence criteria of :func:`newton` (its ``tol``) after a
    residual norm ``res[-1]``: ``res`` the step's norms, ``energy`` its
    increments' :math:`|\\Delta x\\cdot r|`, ``ref`` the reference norm,
    ``small`` an increment below 1e-10 of the unknowns.  Returns ``(True,
    "")`` converged, ``(True, "round-off floor")`` converged where the
    residual stalls, ``(False, "diverging")``, or ``(None, "")`` go on."""
    rn = res[-1]
    if rn <= tol * ref or small or (
            len(energy) > 1 and energy[-1] <= tol ** 2 * energy[0]):
        return True, ""
    if len(res) >= 3 and rn > 0.5 * res[-2] and len(energy) > 1 \
            and energy[-1] <= ROUNDOFF_ENERGY * tol * energy[0]:
        return True, "round-off floor"
    if len(res) >= 4 and all(0.8 < res[-i] / res[-i - 1] < 1.25
                             for i in (1, 2, 3)) \
            and rn <= STALL_RESIDUAL * ref and len(energy) > 1 \
            and energy[-1] <= ROUNDOFF_ENERGY * energy[0]:
        return True, "round-off floor"
    if len(res) >= 4 and rn > res[-2] > res[-3] and rn > 1e3 * tol * ref:
        return False, "diverging"
    return None, ""


#: halvings of a Newton increment at most (``line_search``)
LINE_SEARCH_HALVINGS = 4


class LinearSolveFailed(RuntimeError):
    """A linear solve of a Newton iteration failed in a way that a shorter
    load step may avoid (e.g. a Krylov solve diverging on an indefinite
    tangent); its message is the iteration's ``reason``."""


class ExternalLoad:
    """The external force of a static run at load factor 1: a dead vector
    ``(N,)`` and deformation-dependent loads (``force(u)``,
    ``stiffness(u)`` on the displacement dofs, e.g.
    :class:`~skfem_pg.discretization.follower.FollowerPressure`)."""

    def __init__(self, dead, followers, n_u=None):
        self.dead, self.followers = dead, tuple(followers)
        self.n_u = len(dead) if n_u is None else n_u
        self.norm = float(np.linalg.norm(self.vector(np.zeros(len(dead)))))

    def vector(self, u):
        """The force at the unknowns ``u``."""
        if not self.followers:
            return self.dead
        f = self.dead.copy()
        for load in self.followers:
            f[:self.n_u] += load.force(u[:self.n_u])
        return f

    def tangent(self, K, u, lam):
        """``K - lam * df/du``: the loads' share of Newton's tangent."""
        for load in self.followers:
            Kf = load.stiffness(u[:self.n_u])  # (n_u, n_u) of (N, N)
            Kf.resize(K.shape)
            K = K - lam * Kf
        return K


def external_load(f_ext, n_u, N):
    """:class:`ExternalLoad` of a driver's ``f_ext``: a vector, a load
    with ``force`` / ``stiffness``, or a list of both."""
    dead, followers = split_loads(f_ext)
    for load in followers:
        if load.N != n_u:
            raise ValueError(
                "{} acts on {} dofs, the model has {} displacement dofs: "
                "build it on the model's basis".format(
                    type(load).__name__, load.N, n_u))
    return ExternalLoad(padded_vector(dead, n_u, N, "f_ext"), followers,
                        n_u)


class SerialAlgebra:
    """The linear algebra of :func:`newton_iterations` on one process:
    NumPy vectors of all unknowns in scikit-fem's numbering, residuals and
    solves on the free dofs ``I`` (prescribed ``Dd``) by the condensed
    solver ``lin``.  The distributed counterpart is
    :class:`skfem_pg.distributed.solve.PetscAlgebra`."""

    def __init__(self, model=None, f_ext=None, Dd=None, I=None, lin=None,
                 kept=None):
        if f_ext is not None and not isinstance(f_ext, ExternalLoad):
            f_ext = ExternalLoad(np.asarray(f_ext, dtype=float), ())
        self.model, self.f_ext, self.Dd, self.I, self.lin = (
            model, f_ext, Dd, I, lin)
        self.kept = kept  # a KeptTangent (modified Newton) or None
        self.reused = False  # the last increment came from a kept factor

    def expire(self):
        """The next solve assembles and factorizes a fresh tangent."""
        if self.kept is not None:
            self.kept.fresh = True

    # vector arithmetic (load_stepping and the line search)
    @staticmethod
    def copy(u):
        return u.copy()

    @staticmethod
    def add(u, du, s=1.0):
        """``u + s du`` (``u`` may be overwritten)."""
        if s == 1.0:
            u += du
            return u
        return u + s * du

    @staticmethod
    def extrapolate(u, prev, c):
        return u + c * (u - prev)

    @staticmethod
    def release(u):
        pass

    @staticmethod
    def serial(u):
        return u

    # the Newton iteration
    def increment_at_dirichlet(self, u, values):
        """Prescribed values minus the current ones at the Dirichlet dofs,
        and whether any is non-zero."""
        du_D = values - u[self.Dd]
        return du_D, bool(np.any(du_D != 0))

    def state(self, u):
        return self.model.state(u)

    def min_J(self, state):
        return self.model.min_J(state)

    def residual(self, state, lam, u):
        """``(r, |r_free|, f_int)`` at load factor ``lam`` and unknowns
        ``u``."""
        f_int = self.model.internal_force(state)
        r = f_int - lam * self.f_ext.vector(u)
        return r, float(np.linalg.norm(r[self.I])), f_int

    def load_norm(self, lam):
        return lam * self.f_ext.norm

    def solve(self, state, u, r, du_D, first, lam=1.0):
        """The Newton increment (with the prescribed increment ``du_D``,
        or ``None``) and its energy :math:`|\\Delta x\\cdot r|`; returns
        ``(du, energy, t_assemble, t_linear)``."""
        I, Dd, kept = self.I, self.Dd, self.kept
        t0 = time.perf_counter()
        self.reused = kept is not None and kept.usable()
        K = kept.K if self.reused else self.f_ext.tangent(
            self.model.tangent(state).tocsr(), u, lam)
        t1 = time.perf_counter()
        du = np.zeros_like(u)
        rhs = -r[I]
        if du_D is not None:
            du[Dd] = du_D
            rhs = rhs - (K @ du)[I]
        if self.reused:
            kept.stats["reused"] += 1
            du[I] = kept.solve(rhs)
        else:
            if kept is not None:
                kept.stats["tangents"] += 1
            KII = submatrix(K, I)
            factor = None if kept is None else kept.factorize(self.lin, KII)
            if factor is None:
                du[I] = self.lin(KII, rhs)
            else:
                kept.keep(K, factor)
                du[I] = kept.solve(rhs)
        return (du, abs(float(np.dot(du[I], rhs))), t1 - t0,
                time.perf_counter() - t1)

    def impose(self, u, values):
        return u  # the increment carried the prescribed values

    def small_increment(self, du, u):
        return _small_increment(self.model, du, u)


#: the vector arithmetic of serial unknowns (:func:`load_stepping`)
SERIAL = SerialAlgebra()


def newton_step(model, u, lam, f_ext, Dd, u_DD, I, lin, tol, maxiter,
                line_search=False, kept=None):
    """:func:`newton_iterations` on one process: ``f_ext`` the external
    force at load factor 1, ``Dd`` the prescribed dofs and ``u_DD`` their
    values at this load, ``I`` the free dofs, ``lin`` the condensed
    solver, ``kept`` a :class:`KeptTangent` (modified Newton) or
    ``None``."""
    return newton_iterations(
        model, SerialAlgebra(model, f_ext, Dd, I, lin, kept), u, lam, u_DD,
        tol, maxiter, line_search)


#: modified Newton (``NewtonControls.reuse``): an increment from a kept
#: factorization is accepted where it cuts the residual norm at least by
#: this factor; one that does not (or fails: J <= 0, a return map) is
#: undone and the next increment assembles and factorizes a fresh
#: tangent, as does the one after a fresh increment that contracted less.
#: Accepting slower increments that still decreased the residual cost 2-6x
#: on the 3-D Cook (Newton led astray to J <= 0 and cut steps); 0.1, 0.25
#: and 0.5 were within 10 % of each other (benchmarks/README.md,
#: ``factor_reuse``)
REUSE_CONTRACTION = 0.25


class KeptTangent:
    """Modified Newton's kept tangent ``K`` and the factorization of its
    free block, shared by the iterations and load steps of one
    :func:`newton` call (``NewtonControls.reuse``): each increment solves
    with the kept factors until one of them contracts the residual by
    less than :data:`REUSE_CONTRACTION`; then the next increment takes a
    fresh tangent.  ``stats``: fresh tangents (each factorized, unless the
    linear solver has no kept factorization: AMG, a user's callable) and
    increments solved with kept factors."""

    def __init__(self):
        self.K = self.factor = None
        self.fresh = True
        self.stats = {"tangents": 0, "reused": 0}

    def usable(self):
        return self.factor is not None and not self.fresh

    @staticmethod
    def factorize(lin, A):
        """The linear solver's kept factorization of ``A``, or ``None``
        where it has none (a user's callable, AMG)."""
        factorize = getattr(lin, "factorize", None)
        return None if factorize is None else factorize(A)

    def keep(self, K, factor):
        self.free()
        self.K, self.factor, self.fresh = K, factor, False

    def solve(self, b):
        return self.factor.solve(b)

    def free(self):
        if self.factor is not None:
            self.factor.free()
        self.K = self.factor = None


def _iterate(algebra, u, lam, info):
    r"""``(fail, state, r, rn, f_int)`` of the iterate ``u`` at load factor
    ``lam``: ``fail`` names why it cannot be used (a return map that
    cannot return, :math:`J \le 0`, a non-finite residual), else
    ``None``; ``info`` gets the minimum J and the seconds."""
    t0 = time.perf_counter()
    fail, state, r, rn, f_int = None, None, None, np.nan, None
    try:
        state = algebra.state(u)
    except ReturnMapError as err:  # a plastic point that cannot return
        fail = "return map: {}".format(err)
    if fail is None:
        info["min_J"] = algebra.min_J(state)
        if not info["min_J"] > 0:
            fail = "J <= 0"
    if fail is None:
        r, rn, f_int = algebra.residual(state, lam, u)
        if not np.isfinite(rn):
            fail = "non-finite residual"
    info["t_assemble"] += time.perf_counter() - t0
    return fail, state, r, rn, f_int


def newton_iterations(model, algebra, u, lam, prescribed, tol, maxiter,
                      line_search=False):
    r"""Newton iterations at load factor ``lam`` from the converged ``u``
    (not changed); ``prescribed`` are the values at the Dirichlet dofs at
    this load, ``algebra`` the linear algebra (:class:`SerialAlgebra`, or
    a partition's :class:`~skfem_pg.distributed.solve.PetscAlgebra`).
    Returns ``(ok, x, info, state)``.

    The increment of the prescribed displacements enters the first linear
    solve (``K_II du_I = -r_I - K_ID du_D``), so it is spread through the
    body instead of distorting the boundary layer.

    ``line_search``: an increment whose iterate fails (:math:`J \le 0`, a
    return map that cannot return, a non-finite residual), or any but the
    first increment of the step when it raises the residual norm, is
    halved, at most :data:`LINE_SEARCH_HALVINGS` times, before the
    failure counts; an increment that still raises the residual is then
    taken at its shortest.  Not an increment that carries prescribed
    displacements, nor one below the round-off floor.  (The first
    increment may raise the residual, far from the root; a later rise is
    a cycle or divergence: plastic points switching between elastic and
    plastic made full increments cycle between two states on the Taylor
    rod's first Newmark step with Unl+P1C, residuals 0.40, 0.083, 0.38,
    0.085, ....)
    """
    u = algebra.copy(u)
    du_D, pending = algebra.increment_at_dirichlet(u, prescribed)
    res = []
    energy = []  # |du · rhs| of each solve
    info = {"residuals": res, "energies": energy, "min_J": np.nan,
            "reason": "", "t_assemble": 0.0, "t_linear": 0.0,
            "backtracks": 0, "undone": 0}
    ref = None
    small = False
    back = None  # (iterate, increment, length) while it may be halved
    undo = None  # the iterate before an increment from kept factors
    fresh = False  # the last increment came from a fresh kept tangent
    it = 0
    while True:
        fail, state, r, rn, f_int = _iterate(algebra, u, lam, info)
        redo = False
        if undo is not None:  # the increment came from kept factors
            if fail is not None or not rn <= REUSE_CONTRACTION * res[-1]:
                # too slow (a slow increment can lead Newton astray) or
                # failed: undo it, and solve again at the iterate before
                # with a fresh tangent
                u, state, r, rn, f_int, pending = undo
                energy.pop()
                fail, small, redo = None, False, True
                info["undone"] += 1
                algebra.expire()
            undo = None
        elif fresh and not rn <= REUSE_CONTRACTION * res[-1]:
            # Newton is not yet contracting fast even with a fresh
            # tangent: the next increment takes a fresh one too
            algebra.expire()
        fresh = False
        if back is not None and back[2] > 0.5 ** LINE_SEARCH_HALVINGS \
                and (fail is not None or (len(res) >= 2 and rn > res[-1])):
            u0, du0, s = back
            back = (u0, du0, 0.5 * s)
            u = algebra.add(algebra.copy(u0), du0, 0.5 * s)
            info["backtracks"] += 1
            continue
        if fail is not None:
            info["reason"] = fail
            return False, u, info, None
        back = None
        info["f_int"] = f_int
        if not redo:
            res.append(rn)
        if not pending and not redo:
            if ref is None:
                ref = max(algebra.load_norm(lam), rn, 1e-300)
            done, info["reason"] = verdict(res, energy, ref, tol, small)
            if done is not None:
                return done, u, info, state if done else None
        if it == maxiter:
            info["reason"] = "maxiter"
            return False, u, info, None
        try:
            du, e, t_asm, t_lin = algebra.solve(
                state, u, r, du_D if pending else None, it == 0, lam)
        except LinearSolveFailed as err:
            info["reason"] = str(err)
            return False, u, info, None
        energy.append(e)
        info["t_assemble"] += t_asm
        info["t_linear"] += t_lin
        if getattr(algebra, "reused", False):  # undone if it fails
            undo = (algebra.copy(u), state, r, rn, f_int, pending)
        else:
            fresh = getattr(algebra, "kept", None) is not None
            if line_search and not pending and \
                    energy[-1] > ROUNDOFF_ENERGY * tol * energy[0]:
                back = (algebra.copy(u), du, 1.0)
        u = algebra.impose(algebra.add(u, du), prescribed)
        small = algebra.small_increment(du, u)
        pending = False
        it += 1
