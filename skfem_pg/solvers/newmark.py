r"""Implicit Newmark-β time integration with Newton's method per step and
adaptive steps (thesis 4.4.1, (4.36)–(4.37)).

With :math:`\tilde u = u_n + \Delta t\, v_n + \Delta t^2 (\tfrac12 -
\beta) a_n`,

.. math::

    a_{n+1} = \frac{u_{n+1} - \tilde u}{\beta \Delta t^2},\qquad
    v_{n+1} = v_n + \Delta t\big((1-\gamma) a_n + \gamma a_{n+1}\big),

which is (4.36) with :math:`\gamma/(\beta\Delta t)` (the thesis prints
:math:`\Delta t^2`, a misprint) and (4.37).  Each step solves
:math:`r(u) = f_{int}(u) + M a_{n+1}(u) - f_{ext}(t_{n+1}) = 0` by Newton's
method with the effective tangent :math:`K + M/(\beta\Delta t^2)` (4.53),
for any model: mixed fields without mass are algebraic unknowns of the
same system.  β = 1/4, γ = 1/2 (average acceleration) conserves the
energy of a linear problem exactly and is unconditionally stable.

Adaptive steps: a step whose Newton iteration fails (divergence,
``maxiter``, :math:`J \le 0`, a failed return map) is halved; after a step
that converged in at most 4 iterations the step doubles again, up to the
initial ``dt``.  Below ``dt_min`` the run stops with
:class:`~skfem_pg.solvers.dynamics.DynamicsError` and the time it reached
(the failure angle of a twisted prism, thesis 7.3.6).  The history of a
plastic material is committed after each converged step.
"""
from __future__ import annotations

import time
from typing import Callable

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike

from ..formulations.protocol import Model
from ..dofs import check_sliding
from .contact import hold_initial
from .checkpoint import Every
from .dynamics import (DynamicsError, EnergyBalance, Progress, Recorder,
                       Trajectory, bind_problem, check_run, commit,
                       resume_run, save_run, stored_energy)
from .controls import NewmarkControls
from .problem import Problem
from .static import condensed_solver, newton_step


class _Inertial:
    """The model plus the inertia of a Newmark step:
    :math:`f + M (u - \\tilde u) c`, tangent :math:`K + cM`,
    :math:`c = 1/(\\beta\\Delta t^2)` (``m`` zero on constrained dofs)."""

    def __init__(self, model, m, c, u_tilde):
        self.model, self.m, self.c, self.u_tilde = model, m, c, u_tilde
        self.basis, self.N, self.n_u = model.basis, model.N, model.n_u
        self.blocks = getattr(model, "blocks", [("u", slice(None))])

    def state(self, x):
        return (self.model.state(x), x)

    def min_J(self, s):
        return self.model.min_J(s[0])

    def internal_force(self, s):
        f = np.array(self.model.internal_force(s[0]), dtype=float)
        n = self.n_u
        f[:n] += self.c * self.m * (s[1][:n] - self.u_tilde[:n])
        return f

    def model_force(self, f, x):
        """The model's own internal force from the step's ``f`` at
        ``x``."""
        f = np.array(f, dtype=float)
        n = self.n_u
        f[:n] -= self.c * self.m * (x[:n] - self.u_tilde[:n])
        return f

    def tangent(self, s):
        K = self.model.tangent(s[0]).tocsr()
        diag = np.zeros(self.N)
        diag[:self.n_u] = self.c * self.m
        return K + sp.diags(diag)


def check_conditional_stability(model, m, x, free, dt, beta, gamma,
                                 displacement_only=True):
    r"""Refuses a step above Newmark's stability limit when ``beta <
    gamma/2`` (conditionally stable: linear acceleration, Fox–Goodwin):
    :math:`\omega_{max}\,\Delta t \le \Omega_{crit} = 1/\sqrt{\gamma/2 -
    \beta}` (undamped; Hughes 1987, 9.1).  Above it the run grows without
    bound and its own energy record shows errors above 100 % without a
    word (issue 47).  ``omega_max`` is the Lanczos Ritz value at the
    start, a lower bound: no stable step is refused."""
    if beta >= gamma / 2:
        return  # unconditionally stable
    if not displacement_only:
        raise ValueError(
            "beta = {:.4g} < gamma/2 = {:.4g} is only conditionally stable "
            "and the step limit can be checked for displacement-only "
            "models only: use beta >= gamma/2 (default 1/4)".format(
                beta, gamma / 2))
    from .explicit import max_frequency
    limit = 1.0 / np.sqrt(gamma / 2 - beta) / max_frequency(model, m, x,
                                                            free)
    if dt > limit:
        raise ValueError(
            "dt = {:.4g} is above the stability limit {:.4g} of Newmark's "
            "method with beta = {:.4g} < gamma/2 (conditionally stable: "
            "omega_max dt <= 1/sqrt(gamma/2 - beta) = {:.3g}): use dt <= "
            "{:.4g} or beta >= gamma/2 (default 1/4, unconditionally "
            "stable)".format(dt, limit, beta, 1 / np.sqrt(gamma / 2 - beta),
                             limit))


def newmark(model: Model | Problem, m: ArrayLike | None = None,
            t_end: float | None = None, dt: float | None = None,
            f_ext: ArrayLike | Callable | None = None, D=None,
            u_D: ArrayLike | Callable | None = None,
            u0: ArrayLike | None = None, v0: ArrayLike | None = None,
            solver: str | Callable = "auto", wall=None,
            callback: Callable | None = None, checkpoint=None,
            resume: str | None = None,
            controls: NewmarkControls | None = None, **kw) -> Trajectory:
    r"""Integrate :math:`M\ddot u + f_{int}(u) = f_{ext}(t)` from 0 to
    ``t_end`` by Newmark's method (module docstring).

    Parameters
    ----------
    model
        A :class:`~skfem_pg.solvers.problem.Problem` (its model, loads,
        Dirichlet data, walls and mass; then give ``t_end`` and ``dt``
        by keyword), or any model of :mod:`skfem_pg.formulations` (FE or
        PG, mixed too) with the keywords below.
    m
        Diagonal mass per displacement dof (:func:`lumped_mass`).
    t_end
        The end time.
    dt
        Initial (and largest) step.
    f_ext, D, u_D
        Loads and prescribed displacements: vectors (constant) or
        callables of the time; ``D`` the prescribed dofs.
    u0, v0
        Initial displacements (or all unknowns) and velocities.
    solver
        The linear solver of Newton's method per step
        (:func:`~skfem_pg.solvers.newton`).
    wall
        A :class:`~skfem_pg.solvers.RigidWall` (or a list): an active set
        of held dofs, repeated per step until it settles (at most
        ``max_contact_passes`` solves).
    callback
        ``callback(t, x, v, record)`` at the start and every
        ``output_every`` converged steps, and at the end.
    controls, **kw
        :class:`~skfem_pg.solvers.NewmarkControls` (``beta``, ``gamma``,
        ``dt_min``, ``tol``, ``maxiter``, ``line_search``,
        ``max_contact_passes``, ``output_every``, ``verbose``), or its
        fields as keywords (they replace the record's).
    checkpoint, resume
        A path or :class:`~skfem_pg.solvers.checkpoint.Every` (e.g.
        ``Every("run.npz", seconds=600)``) to write the run's state to
        after converged steps (time, unknowns, velocities, accelerations,
        internal force, step size, held dofs, energy accounts, records,
        the model's history; atomically); a path to resume such a run
        from: it then ends where the uninterrupted run ends, to round-off.

    Returns
    -------
    Trajectory
        Final unknowns, velocities and accelerations, energies and step
        data (``dt``, Newton ``iterations``, ``cuts``) per output, the
        seconds of assembly, linear solves and output.
    """
    problem = Problem.of(model, "newmark", f_ext=f_ext, D=D, u_D=u_D,
                         wall=wall, m=m)
    model = problem.model
    basis, N, n_u = model.basis, model.N, model.n_u
    c = NewmarkControls.of(controls, **kw)
    beta, gamma, dt_min, verbose = c.beta, c.gamma, c.dt_min, c.verbose
    m = check_run(n_u, N, problem.require_mass("newmark"), t_end, dt, u0,
                  v0, dt_required=True)
    if dt_min is not None and not (np.isfinite(dt_min)
                                   and 0 < dt_min <= dt):
        raise ValueError("dt_min must lie in (0, dt], got {!r}".format(
            dt_min))
    run = bind_problem(problem, m)
    Dd, free, f_of, uD_of = run.D, run.free, run.f_of, run.uD_of
    walls, cand = run.walls, run.candidates
    check_sliding(basis, Dd)
    dt_min = dt / 1024 if dt_min is None else dt_min
    x0 = model.initial() if hasattr(model, "initial") else np.zeros(N)
    x = x0.copy()
    if u0 is not None:  # displacements, or all unknowns (check_run)
        u0 = np.asarray(u0, dtype=float)
        x[:u0.shape[0]] = u0
    x[Dd] = uD_of(0.0)[Dd]
    v = np.zeros(n_u) if v0 is None else np.asarray(v0, float).copy()
    held = np.zeros(n_u, dtype=bool)
    times = dict.fromkeys(("assemble", "linear", "output", "contact"), 0.0)
    if resume is None:
        check_conditional_stability(model, m, x, free, dt, beta, gamma,
                                    N == n_u)
    state = model.state(x)
    fi = np.asarray(model.internal_force(state), dtype=float)
    fe = f_of(0.0)
    a = np.where(free, (fe[:n_u] - fi[:n_u]) / m, 0.0)
    energy = EnergyBalance(m, v, free, stored_energy(model, state))
    energy.D_c += hold_initial(walls, cand, x, v, a, m, held)
    progress = Progress(t_end, verbose)
    out = Recorder(model, energy, free, progress, callback,
                   times)
    hist = out.hist
    t, steps, step, cuts = 0.0, 0, float(dt), 0
    if resume is not None:
        x, t, v, a, fi, held, saved = resume_run(
            resume, model, energy, hist, "newmark",
            controller=("step", "steps", "cuts"))
        step, steps, cuts = float(saved["step"]), int(saved["steps"]), \
            int(saved["cuts"])
        state = model.state(x)
        fe = f_of(t)
    solvers = {}
    every = Every.of(checkpoint)

    def output(info=None, final=False):
        out(t, x, v, state, held, final, dt=step, steps=steps, cuts=cuts,
            active=int(held.sum()), iterations=0 if info is None else
            len(info["residuals"]) - 1)

    if resume is None:
        output()
    while t < t_end * (1 - 1e-12):
        h = min(step, t_end - t)
        ok, res = _step(run, c, (x, v, a, held), t, h, solver, solvers,
                        times)
        if not ok:
            cuts += 1
            step = h / 2
            progress.echo("  t {:.6g}: step {:.3g} failed ({}); halved"
                          .format(t + h, h, res))
            if step < dt_min:
                raise DynamicsError(
                    "Newmark: no convergence at t = {:.6g} with the step "
                    "{:.3g} < dt_min = {:.3g} ({})".format(
                        t + h, step, dt_min, res),
                    t=t, x=x, v=v, history=hist)
            continue
        xn, vn, an, fi_n, state, held_n, info = res
        fe_n = f_of(t + h)
        if commit(model, state, t + h, x, v, hist):
            # the families were rebuilt: the force and the acceleration
            # of the new basis (lumped mass)
            state = model.state(xn)
            fi_n = np.asarray(model.internal_force(state), dtype=float)
            an, moving = np.array(an), free & ~held_n
            an[moving] = (fe_n[:n_u] - fi_n[:n_u])[moving] / m[moving]
        touched = np.flatnonzero(held | held_n)
        energy.step(xn - x, fi, fi_n, fe, fe_n, Dd, touched, v, vn,
                    free & ~held, free & ~held_n)
        x, v, a, fi, fe, held = xn, vn, an, fi_n, fe_n, held_n
        t += h
        steps += 1
        if len(info["residuals"]) <= 5 and step < dt:
            step = min(2 * step, dt)
        final = t >= t_end * (1 - 1e-12)
        if steps % c.output_every == 0 or final:
            output(info, final)
        if every is not None:
            save_run(every, steps, model, x, t, v, a, fi, held, energy, hist,
                     "newmark", step=step, steps=steps, cuts=cuts)
    times["total"] = sum(times.values())
    return Trajectory(x, v, a, t, hist, steps, times)


def _step(run, controls, start_state, t, h, solver, solvers, times):
    """One Newmark step of the :class:`~skfem_pg.solvers.dynamics.
    BoundProblem` ``run`` with the ``controls`` from ``t`` to ``t + h``
    and the state ``(x, v, a, held)``, repeated while the wall's active
    set changes: ``(True, (x, v, a, f_int, state, held, info))`` or
    ``(False, reason)``."""
    model, m, free, Dd = run.model, run.m, run.free, run.D
    f_of, uD_of, walls, cand = run.f_of, run.uD_of, run.walls, \
        run.candidates
    x, v, a, held = start_state
    beta, gamma = controls.beta, controls.gamma
    max_passes = controls.max_contact_passes
    n_u = m.shape[0]
    N = x.shape[0]
    c = 1.0 / (beta * h * h)
    u_tilde = x[:n_u] + h * v + h * h * (0.5 - beta) * a
    start = x.copy()
    start[:n_u] = u_tilde + beta * h * h * a  # constant acceleration
    uD = uD_of(t + h)
    held = held.copy()
    for _ in range(max_passes):
        C = np.union1d(Dd, np.flatnonzero(held))
        values = np.zeros(N)
        values[Dd] = uD[Dd]
        for w, cw in zip(walls, cand):
            values[cw] = w.wall_values()
        I = np.setdiff1d(np.arange(N), C)
        key = I.tobytes()
        if key not in solvers:
            solvers.clear()  # one active set at a time
            solvers[key] = solver if callable(solver) else \
                condensed_solver(solver, model.basis, I,
                                  extra_fields=N > n_u)
        mm = np.where(free & ~held, m, 0.0)
        inert = _Inertial(model, mm, c, u_tilde)
        ok, xn, info, state = newton_step(inert, start, 1.0, f_of(t + h),
                                           C, values[C], I, solvers[key],
                                           controls.tol, controls.maxiter,
                                           controls.line_search)
        times["assemble"] += info["t_assemble"]
        times["linear"] += info["t_linear"]
        if not ok:
            return False, info["reason"]
        t1 = time.perf_counter()
        fi = inert.model_force(info.pop("f_int"), xn)
        changed = False
        if walls:
            R = fi[:n_u] - f_of(t + h)[:n_u]  # what the wall must push
            for w, cw in zip(walls, cand):
                hw = held[cw]
                release = hw & ~w.compressive(R[cw])
                enter = ~hw & w.penetrating(xn)
                if release.any() or enter.any():
                    changed = True
                    held[cw[release]] = False
                    held[cw[enter]] = True
        times["contact"] += time.perf_counter() - t1
        if not changed:
            an = np.where(free & ~held, c * (xn[:n_u] - u_tilde), 0.0)
            vn = v + h * ((1 - gamma) * a + gamma * an)
            vn[held] = 0.0
            return True, (xn, vn, an, fi, state[0], held, info)
        start = xn
    return False, "the wall's active set did not settle in {} " \
        "passes".format(max_passes)
