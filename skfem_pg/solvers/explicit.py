r"""Explicit central differences (thesis 4.4.1, (4.38)–(4.40)).

With the particle discretization's diagonal mass the equations of motion
decouple: a step is one internal-force evaluation and no global solve.
The scheme is written in its velocity (Verlet) form, which for a constant
step is (4.38)–(4.40) exactly and also admits a changing step:

.. math::

    v_{n+1/2} = v_n + \tfrac{\Delta t}2 a_n,\quad
    u_{n+1} = u_n + \Delta t\, v_{n+1/2},\quad
    a_{n+1} = M^{-1}\big(f_{ext}(t_{n+1}) - f_{int}(u_{n+1})\big),\quad
    v_{n+1} = v_{n+1/2} + \tfrac{\Delta t}2 a_{n+1}.

A material's history is committed after every step (4.4.2).  The
formulations whose mixed fields are continuous (U2P1C, Unl+P1C) and the
incompressible ones (IUnlP0) carry global unknowns beyond the
displacements and need a global solve every step (6.2.3): they are
refused here and run with :func:`~skfem_pg.solvers.newmark`.

Stable step (not in the thesis, which cites the CFL condition):
:math:`\Delta t = s \cdot 2/\omega_{max}`, :math:`\omega_{max}^2 =
\lambda_{max}(M^{-1}K)` of the tangent in the current configuration with
the material held elastic (:meth:`History.elastic_predictor
<skfem_pg.formulations.history.History.elastic_predictor>`: the plastic
tangent is softer than elastic unloading, which sets the limit),
by Lanczos iterations (:func:`lanczos_max`, from a start vector fixed by
the serial dof numbers) on :math:`M^{-1/2} K M^{-1/2}`.  As the
configuration changes the step is
divided by :func:`compression_since` the last estimate (how much the most
compressed point shrank since), and estimated again every
``estimate_every`` steps or as soon as that factor exceeds
:data:`REESTIMATE`.  A run whose energy balance error exceeds
``max_energy_error`` stops with :class:`DynamicsError` — the signature of
an unstable step — instead of returning garbage.
"""
from __future__ import annotations

import contextlib
from typing import Callable
import time

import numpy as np
from numpy.typing import ArrayLike

from ..formulations.protocol import Model
from ..materials import ReturnMapError
from ..materials.hyperelastic import inverse_and_det
from .contact import hold_initial
from .checkpoint import Every
from .exchange import SerialExchange
from .controls import ExplicitControls
from .dynamics import (DynamicsError, EnergyBalance, MAX_STEPS, Progress,
                       Recorder, STARTUP_STEPS, Timings, Trajectory,
                       bind_problem, bind_walls, book_rebuild, check_run,
                       closure_energy, commit, resume_run, save_run,
                       stored_energy)
from .problem import Problem
from ..discretization.particles import inverted_cells


#: a stable-step estimate is repeated at once when a point has been
#: compressed by more than this factor since the last one
REESTIMATE = 1.25


def _gradients(state):
    """The deformation gradients of a model's state (``F``, or the
    masters' ``F1`` of U1SIG), or ``None`` (a view: a new state holds
    new arrays, so the one kept at an estimate stays as it was)."""
    for key in ("F", "F1"):
        if key in state:
            return state[key]
    return None


def compression_since(F_est, F):
    r"""An upper bound of how much more any point is compressed than at
    the last step estimate: :math:`\max_p 1 + \|F_{est} F^{-1} -
    I\|_F` (:math:`\ge \|F_{est}F^{-1}\|_2`, the factor by which the
    shortest material line shrank); the highest frequency of an elastic
    body grows at most by it, so the estimated step is divided by it
    until the next estimate."""
    if F_est is None or F is None:
        return 1.0
    if F_est.shape != F.shape:
        # the model's points changed (crack-aware families rebuilt): the
        # step must be estimated again
        return np.inf
    d = F.shape[0]
    Fi, _ = inverse_and_det(F.reshape(d, d, -1))
    R = np.einsum("ikp,kjp->ijp", F_est.reshape(d, d, -1), Fi)
    R -= np.eye(d)[:, :, None]
    return float(1.0 + np.sqrt((R * R).sum(axis=(0, 1))).max(initial=0.0))


def _elastic(model):
    h = getattr(model, "history", None)
    return h.elastic_predictor() if h is not None else \
        contextlib.nullcontext()


def max_frequency(model, m, x, free=None, tol=1e-3, exchange=None,
                  matrix_free=None):
    r""":math:`\omega_{max} = \sqrt{\lambda_{max}(M^{-1}K)}` of the
    tangent at ``x`` on the ``free`` displacement dofs (default all with
    mass), the material held elastic; the symmetric part of a
    Petrov–Galerkin tangent.  Lanczos iterations (:func:`lanczos_max`,
    Ritz residual ``tol`` relative) on :math:`M^{-1/2} K M^{-1/2}`;
    ``exchange`` (default serial) sums the products over MPI ranks and
    gives the start vector (a function of the serial dof numbers).

    ``matrix_free`` forms each product :math:`K y` from two internal
    forces, :math:`(f(x + \epsilon y) - f(x - \epsilon y)) / 2\epsilon`
    (:func:`tangent_product`), instead of assembling :math:`K`: an
    estimate then costs about two force evaluations per Lanczos
    iteration, which is cheaper where a force is much cheaper than a
    tangent (U1SUnl, U1SIG: their material at the masters).  Default:
    the model's ``matrix_free_estimate`` attribute, for a symmetric
    tangent (not Petrov–Galerkin)."""
    exchange = SerialExchange(m.shape[0]) if exchange is None else exchange
    n_u = m.shape[0]
    free = m > 0 if free is None else free & (m > 0)
    s = np.where(free, 1.0 / np.sqrt(np.where(m > 0, m, 1.0)), 0.0)
    if matrix_free is None:
        matrix_free = bool(getattr(model, "matrix_free_estimate", False))
    if matrix_free and not symmetric_tangent(model):
        raise ValueError("matrix_free estimates take a symmetric tangent; "
                         "{} is Petrov–Galerkin".format(type(model).__name__))
    with _elastic(model):
        if matrix_free:
            product = tangent_product(model, x, n_u, exchange)
        else:
            K = model.tangent(model.state(x)).tocsr()[:n_u, :n_u]
            KT = K.T.tocsr()

            def product(y):
                return 0.5 * (K @ y + KT @ y)

        def matvec(y):
            return s * exchange.complete(product(s * y))

        lam = lanczos_max(matvec, np.where(free, exchange.start_vector(),
                                           0.0), exchange, tol)[0]
    return float(np.sqrt(max(lam, 0.0)))


def symmetric_tangent(model):
    """Whether ``model``'s tangent is symmetric (not Petrov–Galerkin)."""
    return getattr(getattr(model, "basis", None), "test", None) is None


#: the central-difference perturbation of :func:`tangent_product`: the
#: largest displacement it adds, relative to the mean particle spacing.
#: The truncation error goes with its square (on a randomly deformed
#: Taylor rod, U1SIG: omega_max 1.6e-4 off the assembled tangent's at
#: 1e-3, 1.6e-6 at 1e-4); the round-off of the force differences grows as
#: it shrinks and decides how closely a run on MPI ranks repeats the
#: serial one (at 1e-6 of the body's extent: 6e-11 in x after 100 steps;
#: at 1e-4 of the spacing: 4e-15)
PRODUCT_STEP = 1e-4


def tangent_product(model, x, n_u, exchange=None):
    r"""``f(y)`` :math:`= K(x)\,y` on the displacement dofs by central
    differences of the model's internal force (unassembled: a rank's own
    contributions), the perturbation's largest displacement
    :data:`PRODUCT_STEP` times the mean spacing of the whole body
    (``exchange`` reduces it over ranks, so that every rank and the serial
    run perturb alike)."""
    ex = SerialExchange(n_u) if exchange is None else exchange
    x = np.asarray(x, dtype=float)
    X = np.asarray(model.basis.doflocs, dtype=float)[:, :n_u]
    d = X.shape[0]
    extent = max(ex.max(X[a].max(initial=-np.inf))
                 - ex.min(X[a].min(initial=np.inf)) for a in range(d))
    one = np.ones(n_u)
    spacing = extent / max(ex.dot(one, one) / d, 1.0) ** (1.0 / d)

    def product(y):
        big = ex.max(np.abs(y).max(initial=0.0))
        if not big > 0:
            return np.zeros(n_u)
        eps = PRODUCT_STEP * spacing / big
        xp, xm = x.copy(), x.copy()
        xp[:n_u] += eps * y
        xm[:n_u] -= eps * y
        fp = model.internal_force(model.state(xp))[:n_u]
        fm = model.internal_force(model.state(xm))[:n_u]
        return (fp - fm) / (2.0 * eps)
    return product


#: most Lanczos iterations of one estimate (it keeps that many vectors)
LANCZOS_MAXITER = 150


def lanczos_max(matvec, v0, exchange, tol=1e-3, maxiter=LANCZOS_MAXITER):
    r"""The largest eigenvalue of the symmetric operator ``matvec`` by
    Lanczos iterations from ``v0`` with full reorthogonalization, stopped
    when the Ritz residual :math:`\beta_j |s_j|` is at most ``tol``
    times the Ritz value (ARPACK's criterion).  Sums over dofs go through
    ``exchange.dot`` (all ranks).  Returns ``(theta, ritz_vector,
    iterations)``; raises ``RuntimeError`` if ``maxiter`` iterations do
    not converge (a non-symmetric or non-finite operator)."""
    beta0 = np.sqrt(exchange.dot(v0, v0))
    if not beta0 > 0:
        raise ValueError("no free dof with mass: no frequency to estimate")
    V = [v0 / beta0]
    alpha, beta = [], []
    theta, s = 0.0, np.ones(1)
    for j in range(maxiter):
        w = matvec(V[-1])
        a = exchange.dot(V[-1], w)
        alpha.append(a)
        # full reorthogonalization, twice (classical Gram–Schmidt)
        for _ in range(2):
            for q, ci in zip(V, exchange.dots(V, w)):
                w -= ci * q
        b = np.sqrt(exchange.dot(w, w))
        T = np.diag(alpha) + np.diag(beta, 1) + np.diag(beta, -1)
        ev, evec = np.linalg.eigh(T)
        theta, s = ev[-1], evec[:, -1]
        if not np.isfinite(theta):
            raise RuntimeError("Lanczos: a non-finite Ritz value at "
                               "iteration {}".format(j + 1))
        if b * abs(s[-1]) <= tol * abs(theta) or b <= 1e-14 * abs(theta):
            break
        beta.append(b)
        V.append(w / b)
    else:
        raise RuntimeError("Lanczos: the largest eigenvalue did not "
                           "converge in {} iterations (residual {:.3g} of "
                           "{:.3g})".format(maxiter, b * abs(s[-1]), theta))
    ritz = sum(si * q for si, q in zip(s, V))
    return float(theta), ritz, j + 1


def stable_time_step(model, m, x=None, free=None, safety=0.8,
                     exchange=None):
    r"""The central-difference step :math:`s \cdot 2/\omega_{max}`
    (:func:`max_frequency`) at ``x`` (default the initial unknowns)."""
    x = model.initial() if x is None else x
    w = max_frequency(model, m, x, free, exchange=exchange)
    if not w > 0:
        raise ValueError("no stiffness on the free dofs (omega_max = {}): "
                         "no stable step".format(w))
    return safety * 2.0 / w


def central_difference(model: Model | Problem, m: ArrayLike | None = None,
                       t_end: float | None = None,
                       f_ext: ArrayLike | Callable | None = None, D=None,
                       u_D: ArrayLike | Callable | None = None,
                       u0: ArrayLike | None = None,
                       v0: ArrayLike | None = None,
                       dt: float | None = None, wall=None,
                       callback: Callable | None = None, checkpoint=None,
                       resume: str | None = None,
                       controls: ExplicitControls | None = None,
                       exchange=None, **kw) -> Trajectory:
    r"""Integrate :math:`M\ddot u + f_{int}(u) = f_{ext}(t)` from 0 to
    ``t_end`` by central differences.

    Parameters
    ----------
    model
        A :class:`~skfem_pg.solvers.problem.Problem` (its model, loads,
        Dirichlet data, walls and mass; then give ``t_end`` by keyword),
        or a displacement-only model (Unl, UnlP0, U1SUnl, U1SIG, FE; no
        global extra fields) with the keywords below.
    m
        Diagonal mass per displacement dof (:func:`lumped_mass`).
    t_end
        The end time.
    f_ext, u_D
        External forces and prescribed displacements: vectors (constant)
        or callables of the time; ``D`` the prescribed dofs.
    u0, v0
        Initial displacements and velocities (default zero).
    dt
        Fixed step; default ``safety · 2/ω_max`` (:func:`stable_time_step`),
        scaled down as points are compressed (:func:`compression_since`)
        and estimated again every ``estimate_every`` steps or when that
        scaling passes :data:`REESTIMATE`.
    wall
        A :class:`~skfem_pg.solvers.RigidWall` (or a list of them).
    callback
        ``callback(t, x, v, record)`` at the start, every
        ``output_every`` steps (default: about 20 outputs, guessed from
        the first step) and at the end; ``record``: the energies.
    exchange
        The communication between the parts of a model on MPI ranks
        (the vectors are then a rank's local ones); default serial
        (:mod:`skfem_pg.solvers.exchange` states what it provides).
    controls, **kw
        :class:`~skfem_pg.solvers.ExplicitControls` (``safety``,
        ``estimate_every``, ``output_every``, ``max_energy_error`` (checked
        from step :data:`STARTUP_STEPS` on), ``verbose``), or its fields as
        keywords (they replace the record's).
    checkpoint, resume
        A path or :class:`~skfem_pg.solvers.checkpoint.Every` (e.g.
        ``Every("taylor.npz", seconds=600)``) to write the run's state to
        (time, displacements, velocities, accelerations, internal force,
        held dofs, the step estimate and the deformation it was made at,
        energy accounts, records, the model's history; atomically); a path
        to resume such a run from: it then ends where the uninterrupted
        run ends, to round-off.

    Returns
    -------
    Trajectory
        The final state, the energies per output and the seconds spent in
        force evaluation (``force``), history commits (``commit``), step
        estimates (``estimate``), contact (``contact``) and output
        (``output``).
    """
    c = ExplicitControls.of(controls, **kw)
    problem = Problem.of(model, "central_difference", f_ext=f_ext, D=D,
                         u_D=u_D, wall=wall, m=m)
    model = problem.model
    n_u = model.n_u
    if model.N != n_u:
        raise ValueError(
            "{} has global unknowns beyond the displacements ({} of {}): "
            "explicit steps would need a global solve (6.2.3); integrate "
            "it with newmark".format(type(model).__name__,
                                     model.N - n_u, model.N))
    ex = SerialExchange(n_u) if exchange is None else exchange
    m = check_run(n_u, n_u, problem.require_mass("central_difference"),
                  t_end, dt, u0, v0)
    run = bind_problem(problem, m, bind=lambda *args: _collective(
        ex, bind_walls, *args))
    u = model.initial() if u0 is None else np.asarray(u0, float).copy()
    v = np.zeros(n_u) if v0 is None else np.asarray(v0, float).copy()
    if u.shape != (n_u,) or v.shape != (n_u,):
        raise ValueError("u0 and v0 need {} entries".format(n_u))
    u[run.D] = run.uD_of(0.0)[run.D]
    stepper = _CentralDifference(run, c, ex, t_end, dt, callback)
    stepper.start(u, v, resume)
    every = Every.of(checkpoint)
    while stepper.t < t_end * (1 - 1e-12):
        stepper.advance()
        if every is not None:
            stepper.save(every)
    return stepper.trajectory()


class _CentralDifference:
    """One central-difference run (:func:`central_difference`): its state
    (``t``, ``u``, ``v``, ``a``, the forces, the dofs the walls hold), the
    step controller, and the phases of a step, each a method — the step
    size (:meth:`step_size`), the walls before and after the force
    (:func:`_onto_walls`, :func:`_hold_on_walls`), the force with the
    model's rebuild (:meth:`force`), the energy account and its check
    (:meth:`account`), output and checkpoints (:meth:`report`,
    :meth:`save`); ``times`` holds the seconds of each
    (:class:`~skfem_pg.solvers.dynamics.Timings`)."""

    def __init__(self, run, controls, exchange, t_end, dt, callback):
        self.run, self.c, self.ex = run, controls, exchange
        self.model, self.t_end, self.dt = run.model, t_end, dt
        self.inv_m = np.where(run.free, 1.0 / run.m, 0.0)
        self.times = Timings(("force", "commit", "estimate", "contact",
                              "output"))
        self.callback = callback
        self.t, self.steps, self.step = 0.0, 0, dt
        self.F_est = None  # the deformation at the last estimate
        self.rebuilt = False  # the model's basis changed since
        self.output_every = controls.output_every

    # -- the start ------------------------------------------------------
    def start(self, u, v, resume):
        """The state at ``t = 0`` (or of the checkpoint ``resume``), the
        energy account, the first step size and the first output."""
        run, ex, times = self.run, self.ex, self.times
        self.t_start = time.perf_counter()
        with times("force"):
            self.state = _evaluate(self.model, u, 0.0, None, v, exchange=ex)
            self.fi = ex.complete(self.model.internal_force(self.state))
        self.fe = run.f_of(0.0)
        self.u, self.v = u, v
        self.a = self.inv_m * (self.fe - self.fi)
        self.held = np.zeros(len(u), dtype=bool)  # dofs a wall holds
        self.energy = EnergyBalance(run.m, v, run.free, ex.sum(
            stored_energy(self.model, self.state)), dot=ex.dot)
        self.energy.D_c += _collective(
            ex, hold_initial, run.walls, run.candidates, u, v, self.a, run.m,
            self.held, ex.dot)
        progress = Progress(self.t_end, self.c.verbose if ex.root else False)
        self.out = Recorder(self.model, self.energy, run.free, progress,
                            self.callback, self.times, total=ex.sum,
                            max_dissipation_drop=self.c.max_energy_error)
        self.hist = self.out.hist
        self.first_step(resume)
        if resume is None:
            self.output()
            return
        self.u, self.t, self.v, self.a, self.fi, self.held, saved = \
            resume_run(resume, self.model, self.energy, self.hist,
                       "explicit", controller=("steps", "step", "base",
                                               "output_every"))
        self.steps, self.step, self.base = int(saved["steps"]), float(
            saved["step"]), float(saved["base"])
        self.output_every = int(saved["output_every"])
        self.F_est = saved.get("F_est")
        self.rebuilt = bool(saved.get("rebuilt", False))
        self.state = _evaluate(self.model, self.u, self.t, self.hist,
                               self.v, exchange=ex)
        self.fe = run.f_of(self.t)

    def estimate(self, safety):
        # always from the same start vector: a warm start from the last
        # Ritz vector converged to a lower Ritz value after a crack-aware
        # rebuild (energy balance error 2.4e-3 against 7.7e-4 cold)
        return stable_time_step(self.model, self.run.m, self.u,
                                self.run.free, safety, exchange=self.ex)

    def first_step(self, resume):
        """The estimated step (``dt=None``), or ``dt`` checked against the
        stable step."""
        safety = self.c.safety
        if self.step is None:
            with self.times("estimate"):
                self.step = self.estimate(safety)
                self.F_est = _gradients(self.state)
        elif resume is None:
            # a fixed step above 2/omega_max grows without bound and died
            # later as an "inverted point" (issue 47); the Ritz value is a
            # lower bound of omega_max, so no stable step is refused
            with self.times("estimate"):
                limit = self.estimate(1.0)
            if self.step > limit:
                raise ValueError(
                    "dt = {:.4g} is above the stable step 2/omega_max = "
                    "{:.4g} of central differences at the start: the run "
                    "would diverge.  Give dt <= {:.4g} or leave dt=None "
                    "(the estimated step times safety = {})".format(
                        self.step, limit, limit, safety))
        self.base = self.step  # the estimate's, before the scaling
        if self.output_every is None:
            self.output_every = max(1, int(round(
                self.t_end / self.step / 20)))

    # -- a step ---------------------------------------------------------
    def step_size(self):
        """The step: the estimate scaled down by the compression since it
        was made, estimated again every ``estimate_every`` steps, when
        that scaling passes :data:`REESTIMATE` or after the model rebuilt
        its basis (``dt=None``)."""
        if self.dt is None and self.steps:
            with self.times("estimate"):
                ratio = self.ex.max(compression_since(
                    self.F_est, _gradients(self.state)))
                if self.steps % self.c.estimate_every == 0 \
                        or ratio > REESTIMATE or self.rebuilt:
                    self.base = self.estimate(self.c.safety)
                    self.F_est, ratio = _gradients(self.state), 1.0
                    self.rebuilt = False
                self.step = self.base / ratio
        step, t = self.step, self.t
        if not (np.isfinite(step) and step > 0) \
                or self.steps + (self.t_end - t) / step > MAX_STEPS:
            raise DynamicsError(
                "central differences: the stable step collapsed to {:.3g} "
                "at t = {:.6g} (step {}): {:.3g} more steps to t_end"
                .format(step, t, self.steps, (self.t_end - t) / step if step
                        else np.inf), t=t, x=self.u, v=self.v,
                history=self.hist)
        return min(step, self.t_end - t)

    def force(self, un, t):
        """The state and the internal force at ``un``; after a rebuild
        of the model's basis (a commit that returns ``True``) those of the
        new basis."""
        ex, model = self.ex, self.model
        with self.times("force"):
            state = _evaluate(model, un, t, self.hist, self.v, self.u,
                              exchange=ex)
            fi_n = ex.complete(model.internal_force(state))
        with self.times("commit"):
            if _collective(ex, commit, model, state, t, self.u, self.v,
                           self.hist):
                state = _evaluate(model, un, t, self.hist, self.v, self.u,
                                  exchange=ex)
                fi_before = fi_n
                fi_n = ex.complete(model.internal_force(state))
                # a new basis has its own highest frequency (a crack's
                # families raise it): estimate it before the next step,
                # also where the points' count (compression_since's
                # signal) happens to stay the same
                self.rebuilt = True
                book_rebuild(model, ex.dot, fi_before, fi_n,
                             (un - self.u)[:model.n_u], ex.root)
        return state, fi_n

    def advance(self):
        """One step from ``t`` to ``t + h``."""
        run, Dd = self.run, self.run.D
        u, v, a, h = self.u, self.v, self.a, self.step_size()
        vh = v + 0.5 * h * a
        un = u + h * vh
        un[Dd] = run.uD_of(self.t + h)[Dd]
        vh[Dd] = (un[Dd] - u[Dd]) / h
        with self.times("contact"):
            was_held = self.held.copy()
            _onto_walls(run.walls, run.candidates, self.held, u, un, vh, h)
        self.state, fi_n = self.force(un, self.t + h)
        fe_n = run.f_of(self.t + h)
        a_n = self.inv_m * (fe_n - fi_n)
        vn = vh + 0.5 * h * a_n
        vn[Dd] = vh[Dd]
        with self.times("contact"):
            _hold_on_walls(run.walls, run.candidates, self.held, un, vn,
                           a_n, h)
            touched = np.flatnonzero(self.held | was_held)
        self.energy.step(un - u, self.fi, fi_n, self.fe, fe_n, Dd, touched,
                         v, vn, run.free & ~was_held, run.free & ~self.held)
        self.u, self.v, self.a, self.fi, self.fe = un, vn, a_n, fi_n, fe_n
        self.t += h
        self.steps += 1
        self.report(h, self.account(h))

    def account(self, h):
        """The step's energy record; an error above
        ``max_energy_error`` after :data:`STARTUP_STEPS` stops the run."""
        rec = self.energy.record(self.t, self.v, self.run.free & ~self.held,
                                 closure=closure_energy(self.model,
                                                        self.ex.sum))
        if abs(rec["relative_error"]) > self.c.max_energy_error and \
                self.steps > STARTUP_STEPS:
            raise DynamicsError(
                "central differences: energy balance error {:.3g} > "
                "{:.3g} at t = {:.6g} (step {}, dt {:.3g}): the step is "
                "unstable (increase safety margin: safety < {})".format(
                    rec["relative_error"], self.c.max_energy_error, self.t,
                    self.steps, h, self.c.safety), t=self.t, x=self.u,
                v=self.v, history=self.hist)
        return rec

    # -- output ---------------------------------------------------------
    def output(self, force_progress=False):
        self.out(self.t, self.u, self.v, self.state, self.held,
                 force_progress, dt=self.step, steps=self.steps,
                 active=int(self.held.sum()))

    def report(self, h, rec):
        """An output every ``output_every`` steps and at the end, else a
        progress line."""
        final = self.t >= self.t_end * (1 - 1e-12)
        if self.steps % self.output_every == 0 or final:
            self.output(force_progress=final)
        else:
            self.out.progress(self.t, h, self.steps, rec)

    def save(self, every):
        """A checkpoint, if ``every`` says it is due."""
        save_run(every, self.steps, self.model, self.u, self.t, self.v,
                 self.a, self.fi, self.held, self.energy, self.hist,
                 "explicit", steps=self.steps, step=self.step,
                 base=self.base, output_every=self.output_every,
                 rebuilt=float(self.rebuilt),
                 **({} if self.F_est is None else {"F_est": self.F_est}))

    def trajectory(self):
        self.times["total"] = time.perf_counter() - self.t_start
        return Trajectory(self.u, self.v, self.a, self.t, self.hist,
                          self.steps, dict(self.times))


def _onto_walls(walls, cand, held, u, un, vh, h):
    """Predicted positions behind a wall (or held on it) go onto it, with
    the half-step velocity that gets them there (in place)."""
    for w, c in zip(walls, cand):
        # the held dofs on this wall (two walls may share an axis)
        pen = w.penetrating(un) | (held[c] & w.on_wall(u))
        un[c[pen]] = w.wall_values()[pen]
        vh[c[pen]] = (un[c[pen]] - u[c[pen]]) / h


def _hold_on_walls(walls, cand, held, un, vn, a_n, h):
    """``held``: the dofs on a wall that the step would push into it;
    their velocity and acceleration are zeroed (in place)."""
    held[:] = False
    for w, c in zip(walls, cand):
        on = w.on_wall(un)
        into = w.side * (vn[c] + 0.5 * h * a_n[c]) < 0
        hc = c[on & into]
        held[hc] = True
        vn[hc], a_n[hc] = 0.0, 0.0


def _evaluate(model, u, t, hist, v, u_last=None, exchange=None):
    """``model.state(u)`` with the checks of a step: a return map that
    fails or an inverted point stops the run with the time (on every rank
    when one rank fails: one reduction of the minimum J)."""
    ex = SerialExchange(len(u)) if exchange is None else exchange
    state, failed = None, None
    try:
        state = model.state(u)
        J = model.min_J(state)
    except ReturnMapError as err:
        failed, J = "return map failed at t = {:.6g}: {}".format(t, err), \
            -np.inf
    except Exception as err:  # noqa: BLE001 - re-raised below
        if exchange is None:
            raise
        failed, J = "{}: {}".format(type(err).__name__, err), -np.inf
    J = ex.min(J if np.isfinite(J) else -np.inf)
    if not J > 0:
        message = ex.first(failed)
        if message is None:
            message = "an inverted point (min J = {:.3g}) at t = {:.6g}{}" \
                .format(J, t, ex.first(inversion_note(model, u) or None)
                        or "")
        raise DynamicsError(message, t=t, x=u_last, v=v, history=hist)
    return state


def _collective(exchange, fn, *args):
    """``fn(*args)``, whose error on one rank is raised on every rank
    (serial: called as it is)."""
    if isinstance(exchange, SerialExchange):
        return fn(*args)
    failed, out = None, None
    try:
        out = fn(*args)
    except Exception as err:  # noqa: BLE001 - re-raised on every rank
        failed = err
    message = exchange.first(None if failed is None else "{}: {}".format(
        type(failed).__name__, failed))
    if message is not None:
        if failed is not None:
            raise failed
        raise DynamicsError(message)
    return out


def inversion_note(model, u):
    """The inversion diagnostic for an error message: how many cells of
    the collocation mesh the displacements ``u`` turn inside out
    (:func:`~skfem_pg.discretization.particles.inverted_cells`), where
    the particles came from a mesh's vertices."""
    p = getattr(model.basis, "particles", None)
    if p is None or p.kind != "vertices" or p.mesh is None:
        return ""
    bad = inverted_cells(p, u[:model.n_u])
    if not bad.size:
        return "; no cell of the collocation mesh is inverted"
    x = p.mesh.p[:, p.mesh.t[:, bad[0]]].mean(axis=1)
    return "; {} cell(s) of the collocation mesh inverted, first {} at " \
        "({})".format(bad.size, bad[0], ", ".join("{:.4g}".format(c)
                                                   for c in x))
