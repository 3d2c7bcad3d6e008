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
                       Timings, Trajectory, bind_problem, book_rebuild,
                       check_run, commit, resume_run, save_run,
                       stored_energy)
from .controls import NewmarkControls
from .problem import Problem
from .rates import (bind_newmark_rate, bind_velocity_rate,
                    start_newmark_rate, unbind_rate)
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
            controls: NewmarkControls | None = None,
            gravity: ArrayLike | None = None, **kw) -> Trajectory:
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
    gravity
        An acceleration vector ``(d,)``: the weight :math:`m g` of the
        lumped mass at each displacement dof, added to ``f_ext``.  A model
        whose commit rebuilds its discretization and offers ``mass()``
        (:class:`~skfem_pg.formulations.UpdatedLagrangeFluid`) gets that
        mass after each rebuild, the weight follows it, and the velocities
        of the moving dofs are given to it with their momentum and their
        kinetic plus potential energy (:func:`remap_velocity`).
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
    N, n_u = model.N, model.n_u
    c = NewmarkControls.of(controls, **kw)
    m = check_run(n_u, N, problem.require_mass("newmark"), t_end, dt, u0,
                  v0, dt_required=True)
    if c.dt_min is not None and not (np.isfinite(c.dt_min)
                                     and 0 < c.dt_min <= dt):
        raise ValueError("dt_min must lie in (0, dt], got {!r}".format(
            c.dt_min))
    run = with_weight(bind_problem(problem, m), gravity)
    check_sliding(model.basis, run.D)
    x = (model.initial() if hasattr(model, "initial")
         else np.zeros(N)).copy()
    if u0 is not None:  # displacements, or all unknowns (check_run)
        u0 = np.asarray(u0, dtype=float)
        x[:u0.shape[0]] = u0
    x[run.D] = run.uD_of(0.0)[run.D]
    v = np.zeros(n_u) if v0 is None else np.asarray(v0, float).copy()
    if resume is None:
        check_conditional_stability(model, m, x, run.free, dt, c.beta,
                                    c.gamma, N == n_u)
    stepper = _Newmark(run, c, t_end, dt, solver, callback)
    try:
        start_newmark_rate(model, x, v, dt, c.beta, c.gamma)
        stepper.start(x, v, resume)
        every = Every.of(checkpoint)
        while stepper.t < t_end * (1 - 1e-12):
            if stepper.advance() and every is not None:
                stepper.save(every)
    except BaseException:
        unbind_rate(model)  # a viscous material's rate is this run's
        raise
    bind_velocity_rate(model, stepper.v, stepper.step, c.beta, c.gamma)
    stepper.times["total"] = sum(stepper.times.values())
    return Trajectory(stepper.x, stepper.v, stepper.a, stepper.t,
                      stepper.hist, stepper.steps, dict(stepper.times))


def with_weight(run, gravity):
    """The bound problem ``run`` with the weight of its lumped mass under
    ``gravity`` (``None``: unchanged) added to its loads."""
    if gravity is None:
        return run
    basis = run.model.basis
    d = basis.doflocs.shape[0]
    g = np.asarray(gravity, dtype=float)
    if g.shape != (d,) or not np.all(np.isfinite(g)):
        raise ValueError("gravity must be a finite vector of {} components, "
                         "got {!r}".format(d, gravity))
    weight = (run.f_of, g, dof_components(basis, run.model.n_u))
    return _weighted(run, weight, run.m)


def with_mass(run, m):
    """``run`` with the lumped mass ``m``; its weight
    (:func:`with_weight`) follows."""
    m = np.asarray(m, dtype=float)
    weight = getattr(run.f_of, "weight", None)
    if weight is None:
        return run._replace(m=m)
    return _weighted(run, weight, m)


def weight_potential(run, basis, u, comp):
    r"""Per displacement dof, the potential of the weight per unit mass,
    :math:`-g\cdot x` at the displaced dofs ``u`` of ``basis`` (``None``
    if the run has no ``gravity=``)."""
    weight = getattr(run.f_of, "weight", None)
    if weight is None:
        return None
    g, n = weight[1], len(comp)
    return -g[comp] * (basis.doflocs[comp, np.arange(n)] + u[:n])


def remap_velocity(v, m_old, m_new, moving, comp, potential=None,
                   max_scale=1.1):
    r"""The velocities ``v`` of the lumped mass ``m_old`` given to the
    lumped mass ``m_new`` (a rebuild moved mass between the particles,
    :class:`~skfem_pg.formulations.UpdatedLagrangeFluid`), keeping the
    momentum per component and the energy over the ``moving`` dofs
    (``comp``: each dof's component).

    Velocities kept as they are change the kinetic energy by
    :math:`\frac12\sum (m' - m)\,v^2` and the potential energy of the
    weight (``potential``: per dof, per unit mass) by :math:`\sum (m' -
    m)\,\phi`: mass moved onto fast or high particles creates energy.
    Here :math:`v' = \bar v + s\,(v + \delta - \bar v)`: the shift
    :math:`\delta` per component restores the momentum, :math:`\bar v`
    is the mean velocity, and the factor :math:`s` on the fluctuation
    makes the kinetic energy what the old one was less the potential
    energy gained.  The factor is at most ``max_scale``: energy that
    would take the fluctuation faster than that is lost, not made (a
    fluid at rest whose mass moves down stays at rest), and :math:`s = 0`
    when the potential energy gained exceeds the kinetic.  [A global
    correction, chosen here: on the dam break the factor stays within
    0.98-1.01, ``benchmarks/flow.py``.]

    >>> import numpy as np
    >>> v = np.array([1.0, 0.0, -1.0, 0.0])
    >>> m_old, m_new = np.ones(4), np.array([1.2, 1.0, 0.8, 1.0])
    >>> moving, comp = np.ones(4, bool), np.arange(4) % 2
    >>> w = remap_velocity(v, m_old, m_new, moving, comp)
    >>> abs(float(m_new @ w)) < 1e-15, round(float(m_new @ w ** 2), 12)
    (True, 2.0)
    """
    v = np.array(v, dtype=float)
    n = len(m_old)
    idx = np.flatnonzero(np.asarray(moving)[:n])
    if idx.size == 0:
        return v
    vi, mo, mn, c = v[idx], m_old[idx], m_new[idx], np.asarray(comp)[idx]
    d = int(c.max()) + 1
    M = np.bincount(c, mn, minlength=d)
    p_old = np.bincount(c, mo * vi, minlength=d)
    p_new = np.bincount(c, mn * vi, minlength=d)
    M_safe = np.where(M > 0, M, 1.0)
    mean = p_old / M_safe
    fluct = vi + ((p_old - p_new) / M_safe)[c] - mean[c]
    target = 0.5 * np.sum(mo * vi * vi) - 0.5 * np.sum(M * mean * mean)
    if potential is not None:
        target -= np.sum((mn - mo) * np.asarray(potential)[idx])
    have = 0.5 * np.sum(mn * fluct * fluct)
    s = min(np.sqrt(max(target, 0.0) / have), max_scale) if have > 0 \
        else 1.0
    v[idx] = mean[c] + s * fluct
    return v


def _weighted(run, weight, m):
    """``run`` with the mass ``m`` and the loads ``weight[0]`` plus the
    weight of ``m`` under ``weight[1]`` (components ``weight[2]``)."""
    loads, g, comp = weight
    w = g[comp] * m

    def f_of(t):
        f = np.array(loads(t), dtype=float)
        f[:w.size] += w
        return f
    f_of.weight = weight
    return run._replace(m=m, f_of=f_of)


def dof_components(basis, n_u):
    """The component (0 … d-1) of each displacement dof of ``basis``: a
    family basis' dofs interleave them; a scikit-fem vector basis names
    them per node (``nodal_dofs``) — other dofs raise naming the basis."""
    d = basis.doflocs.shape[0]
    if getattr(basis, "families", None) is not None:
        return np.arange(n_u) % d
    comp = np.full(n_u, -1)
    nodal = np.asarray(basis.nodal_dofs)
    for i in range(min(d, nodal.shape[0])):
        comp[nodal[i]] = i
    if (comp < 0).any():
        raise ValueError("gravity needs the component of each dof: {} has "
                         "dofs that are not nodal components (give the "
                         "weight as f_ext)".format(type(basis).__name__))
    return comp


class _Newmark:
    """One Newmark run (:func:`newmark`): its state, the step controller
    (a failed step is halved down to ``dt_min``, a step that converges in
    a few iterations doubles back towards ``dt``) and the phases of a
    step as methods; ``times`` holds the seconds of each
    (:class:`~skfem_pg.solvers.dynamics.Timings`)."""

    def __init__(self, run, controls, t_end, dt, solver, callback):
        self.run, self.c, self.model = run, controls, run.model
        self.t_end, self.dt, self.solver = t_end, float(dt), solver
        self.dt_min = dt / 1024 if controls.dt_min is None \
            else controls.dt_min
        self.callback = callback
        self.times = Timings(("assemble", "linear", "output", "contact"))
        self.solvers = {}  # the condensed solver of the active set
        self.t, self.steps, self.step, self.cuts = 0.0, 0, float(dt), 0

    def start(self, x, v, resume):
        """The state at ``t = 0`` (or of the checkpoint ``resume``), the
        energy account and the first output."""
        run, model, n_u = self.run, self.model, self.model.n_u
        self.held = np.zeros(n_u, dtype=bool)
        self.state = model.state(x)
        self.fi = np.asarray(model.internal_force(self.state), dtype=float)
        self.fe = run.f_of(0.0)
        self.x, self.v = x, v
        self.a = np.where(run.free, (self.fe[:n_u] - self.fi[:n_u])
                          / run.m, 0.0)
        self.energy = EnergyBalance(run.m, v, run.free,
                                    stored_energy(model, self.state))
        self.energy.D_c += hold_initial(run.walls, run.candidates, x, v,
                                        self.a, run.m, self.held)
        self.progress = Progress(self.t_end, self.c.verbose)
        self.out = Recorder(model, self.energy, run.free, self.progress,
                            self.callback, self.times)
        self.hist = self.out.hist
        if resume is None:
            self.output()
            return
        self.x, self.t, self.v, self.a, self.fi, self.held, saved = \
            resume_run(resume, model, self.energy, self.hist, "newmark",
                       controller=("step", "steps", "cuts"))
        self.step, self.steps, self.cuts = float(saved["step"]), int(
            saved["steps"]), int(saved["cuts"])
        self.state = model.state(self.x)
        self.fe = run.f_of(self.t)

    def output(self, info=None, final=False):
        self.out(self.t, self.x, self.v, self.state, self.held, final,
                 dt=self.step, steps=self.steps, cuts=self.cuts,
                 active=int(self.held.sum()), iterations=0 if info is None
                 else len(info["residuals"]) - 1)

    def advance(self):
        """Try one step; ``False`` if it failed and was halved."""
        t, h = self.t, min(self.step, self.t_end - self.t)
        bind_newmark_rate(self.model, h, self.c.beta, self.c.gamma, self.v,
                          self.a)
        ok, res = _step(self.run, self.c, (self.x, self.v, self.a,
                                            self.held), t, h, self.solver,
                        self.solvers, self.times)
        if not ok:
            self.cut(h, res)
            return False
        self.accept(h, *res)
        return True

    def cut(self, h, reason):
        """Halve the step after a failed one, down to ``dt_min``."""
        self.cuts += 1
        self.step = h / 2
        self.progress.echo("  t {:.6g}: step {:.3g} failed ({}); halved"
                           .format(self.t + h, h, reason))
        if self.step < self.dt_min:
            raise DynamicsError(
                "Newmark: no convergence at t = {:.6g} with the step "
                "{:.3g} < dt_min = {:.3g} ({})".format(
                    self.t + h, self.step, self.dt_min, reason),
                t=self.t, x=self.x, v=self.v, history=self.hist)

    def accept(self, h, xn, vn, an, fi_n, state, held_n, info):
        """Commit the history (a rebuild of the model's basis: the force
        and acceleration of the new basis), book the energy, move on."""
        run, model, n_u, t = self.run, self.model, self.model.n_u, self.t
        fe_n = run.f_of(t + h)
        if commit(model, state, t + h, self.x, self.v, self.hist):
            # the families were rebuilt: the force and the acceleration
            # of the new basis (lumped mass, the model's new one if it
            # has one), a viscous stress with the step's final velocity
            # gradient on it
            if hasattr(model, "mass"):
                m_new = np.asarray(model.mass(), dtype=float)
                comp = dof_components(model.basis, n_u)
                vn = remap_velocity(vn, run.m, m_new, run.free & ~held_n,
                                    comp, weight_potential(run, model.basis,
                                                           xn, comp))
                self.run = run = with_mass(run, m_new)
                self.energy.m = run.m
                fe_n = run.f_of(t + h)
            bind_velocity_rate(model, vn, h, self.c.beta, self.c.gamma)
            state = model.state(xn)
            fi_before = fi_n
            fi_n = np.asarray(model.internal_force(state), dtype=float)
            book_rebuild(model, self.energy.dot, fi_before, fi_n,
                         (xn - self.x)[:n_u])
            an, moving = np.array(an), run.free & ~held_n
            an[moving] = (fe_n[:n_u] - fi_n[:n_u])[moving] / run.m[moving]
        touched = np.flatnonzero(self.held | held_n)
        self.energy.step(xn - self.x, self.fi, fi_n, self.fe, fe_n, run.D,
                         touched, self.v, vn, run.free & ~self.held,
                         run.free & ~held_n)
        self.x, self.v, self.a, self.fi, self.fe, self.held = \
            xn, vn, an, fi_n, fe_n, held_n
        self.state = state
        self.t += h
        self.steps += 1
        if len(info["residuals"]) <= 5 and self.step < self.dt:
            self.step = min(2 * self.step, self.dt)
        final = self.t >= self.t_end * (1 - 1e-12)
        if self.steps % self.c.output_every == 0 or final:
            self.output(info, final)

    def save(self, every):
        """A checkpoint, if ``every`` says it is due."""
        save_run(every, self.steps, self.model, self.x, self.t, self.v,
                 self.a, self.fi, self.held, self.energy, self.hist,
                 "newmark", step=self.step, steps=self.steps,
                 cuts=self.cuts)


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
    start = x.copy()  # the last unknowns (NewmarkControls.predictor)
    if controls.predictor == "acceleration":
        start[:n_u] = u_tilde + beta * h * h * a  # constant acceleration
    uD = uD_of(t + h)
    held = held.copy()
    for _ in range(max_passes):
        C = np.union1d(Dd, np.flatnonzero(held))
        values = np.zeros(N)
        values[Dd] = uD[Dd]
        for w, cw in zip(walls, cand):
            # a held dof is on its own wall (two walls may share an axis)
            own = w.on_wall(start)
            values[cw[own]] = w.wall_values()[own]
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
                # only this wall's held dofs (two walls may share an axis)
                release = hw & w.on_wall(xn) & ~w.compressive(R[cw])
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
