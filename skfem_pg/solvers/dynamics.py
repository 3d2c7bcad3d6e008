r"""What the time integrators share: loads and prescribed motion as
functions of time, the energy balance, progress lines and the result.

Energy bookkeeping (printed as a run goes and stored per output):

* kinetic :math:`T = \tfrac12 v\cdot M v` (free dofs; prescribed dofs and
  dofs held by a wall are massless while constrained);
* internal work :math:`W_{int} = \sum \tfrac12 (f_{int}^n +
  f_{int}^{n+1})\cdot\Delta u` (trapezoidal, over all dofs): the stored
  energy plus the plastic dissipation;
* stored energy :math:`\Pi = \sum w\, W(F)` where the model offers it
  (``model.energy``), and the dissipation :math:`W_{int} - \Pi`;
* where the model fractures (``model.fracture_energy``): the energy the
  failed points, broken bonds and crack updates released, :math:`R`,
  booked as the integrator books the work of the step in which they fail
  (a point's :meth:`~skfem_pg.materials.J2Plasticity.update`, a bond's
  ``BondBased.commit``, a crack update's :func:`book_rebuild`), the
  energy the steps lost where failed points close and open
  (``closure`` :math:`C`, ``model.closure_energy``: a failed point's
  pressure in compression has a kink at :math:`J = 1`, across which the
  trapezoid books more work than the energy stored, second order in the
  step; :meth:`~skfem_pg.materials.plasticity.Response.closure_step`),
  and the rest of the dissipation,
  ``other_dissipation`` :math:`= W_{int} - \Pi - R - C`: the plastic
  dissipation, zero to :math:`O(\Delta t^2)` for an elastic material
  with a brittle criterion (the independent check of the booking);
* external work :math:`W_{ext}` of the loads (trapezoidal), work of the
  reactions at prescribed dofs :math:`W_D` (:math:`R = f_{int} -
  f_{ext}` there), and the energy the wall took at impacts
  :math:`D_c` (the work of the contact forces on the dofs they hold, with
  the sign turned: a rigid wall stops what hits it);
* the balance error :math:`T + W_{int} - C + D_c - W_{ext} - W_D -
  T_0`, relative to the largest energy of the run so far (the initial
  stored energy included).  The closure :math:`C` comes off because it
  is no energy the run has: the trapezoid books it on top of what the
  failed points store (issue 51: on the mode-I plate with the nonlocal
  criterion the balance is 6.7e-4 and 1.2e-3 at h = 2 and 1 mm with it
  off, 1.1e-2 and 1.2e-2 with it).

For Newmark's average acceleration (β = 1/4, γ = 1/2) the trapezoidal
works make the balance exact for a linear problem; for central
differences it holds to :math:`O(\Delta t^2)` with no drift.
"""
import contextlib
import copy
import json
import sys
import time
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from ..dofs import as_dofs
from ..errors import FamilyError, ParticleError
from ..progress import Echo
from .checkpoint import load as load_checkpoint
from .exchange import SerialExchange
from ..discretization.follower import split_loads
from .static import padded_vector


def time_functions(model, f_ext, u_D):
    """``f(t)`` and ``u_D(t)`` as full-length vectors (one entry per
    unknown) from a vector, a callable of the time or ``None``."""
    N, n_u = model.N, model.n_u
    if split_loads(f_ext)[1]:
        raise NotImplementedError(
            "follower loads (FollowerPressure) in the time integrators: "
            "newton takes them; newmark and central_difference take dead "
            "load vectors or callables of the time")

    def wrap(v, what):
        if callable(v):
            return lambda t: padded_vector(v(t), n_u, N, what + "(t)")
        c = padded_vector(v, n_u, N, what)
        return lambda t: c
    return wrap(f_ext, "f_ext"), wrap(u_D, "u_D")


#: most steps one time integration may take: a run whose steps would
#: exceed it (t_end / dt, or a stable step that collapses) stops with a
#: named error instead of running for days
MAX_STEPS = 100_000_000


def check_run(n_u, N, m, t_end, dt=None, u0=None, v0=None,
              dt_required=False):
    """Named errors for a time integration's inputs: the lumped mass
    (one finite positive entry per displacement dof), ``t_end`` (finite,
    positive), ``dt`` (finite, positive; at most :data:`MAX_STEPS` steps
    to ``t_end``), ``u0`` (``n_u`` or ``N`` entries) and ``v0`` (``n_u``),
    all finite.  Returns the mass as an array."""
    m = np.asarray(m, dtype=float)
    if m.shape != (n_u,):
        raise ValueError("the mass needs one entry per displacement dof "
                         "({}), got shape {}".format(n_u, m.shape))
    bad = np.flatnonzero(~(np.isfinite(m) & (m > 0)))
    if bad.size:
        raise ValueError("the mass must be finite and positive at every "
                         "dof: {} entries are not (first: dof {} = {})"
                         .format(bad.size, bad[0], m[bad[0]]))
    if t_end is None or not (np.isfinite(t_end) and t_end > 0):
        raise ValueError("t_end must be a positive time, got {!r}"
                         .format(t_end))
    if dt is None:
        if dt_required:
            raise ValueError("dt is required")
    elif not (np.isfinite(dt) and dt > 0):
        raise ValueError("dt must be a positive time step, got {!r}"
                         .format(dt))
    elif t_end / dt > MAX_STEPS:
        raise ValueError("t_end / dt = {:.3g} steps: more than MAX_STEPS "
                         "= {:.3g} (skfem_pg.solvers.dynamics)".format(
                             t_end / dt, MAX_STEPS))
    for name, v, sizes in (("u0", u0, (n_u, N)), ("v0", v0, (n_u,))):
        if v is None:
            continue
        v = np.asarray(v, dtype=float)
        if v.ndim != 1 or v.shape[0] not in sizes:
            raise ValueError("{} needs {} entries, got shape {}".format(
                name, " or ".join(str(k) for k in sorted(set(sizes))),
                v.shape))
        bad = np.flatnonzero(~np.isfinite(v))
        if bad.size:
            raise ValueError("{} has {} non-finite entries (first: dof {})"
                             .format(name, bad.size, bad[0]))
    return m


#: steps before the energy checks start: an impulsive start (a velocity
#: prescribed from rest) errs by several per cent of the tiny energies of
#: the first steps (8 % at step 1, 0.4 % at step 10 in the wave-arrival
#: test) and then settles; an unstable step grows without bound
STARTUP_STEPS = 10


class EnergyBalance:
    """The energies of a run (module docstring), updated per step.

    Examples
    --------
    At rest with nothing stored, the balance starts at zero:

    >>> import numpy as np
    >>> m, v = np.ones(4), np.zeros(4)
    >>> eb = EnergyBalance(m, v, np.ones(4, dtype=bool), 0.0)
    >>> eb.record(0.0, v, np.ones(4, dtype=bool))["relative_error"]
    0.0

    """

    def __init__(self, m, v0, free, stored0=None, dot=None):
        self.m = m
        # sums over dofs: the serial dot product, or one over the owned
        # dofs of all ranks (HaloExchange.dot)
        self.dot = SerialExchange.dot if dot is None else dot
        self.T0 = self.kinetic(v0, free)
        self.W_int = self.W_ext = self.W_D = self.D_c = 0.0
        # the energy scale of the relative error: the largest energy met
        # so far (the initial stored one included)
        self.scale = max(self.T0, abs(stored0 or 0.0), 1e-300)

    def kinetic(self, v, free):
        n = self.m.shape[0]
        vf = np.where(free, v[:n], 0.0)
        return 0.5 * self.dot(self.m, vf * vf)

    def step(self, du, fi0, fi1, fe0, fe1, D, held=None, v0=None, v1=None,
             free0=None, free1=None):
        """Add a step: displacement increment ``du`` (all unknowns),
        internal and external forces before and after, prescribed dofs
        ``D``; ``held``: the dofs a wall constrained during the step
        (their velocities ``v0``, ``v1`` and whether they were free)."""
        n = self.m.shape[0]
        du = du[:n]
        fi, fe = 0.5 * (fi0[:n] + fi1[:n]), 0.5 * (fe0[:n] + fe1[:n])
        self.W_int += self.dot(fi, du)
        self.W_ext += self.dot(fe, du)
        self.W_D += self.dot(fi - fe, du, D)
        if held is not None:  # on every rank: the sums are collective
            k0 = np.where(free0, v0[:n] ** 2, 0.0)
            k1 = np.where(free1, v1[:n] ** 2, 0.0)
            # work of the contact force on the held dofs = their kinetic
            # change + their internal minus external work
            w = 0.5 * self.dot(self.m, k1 - k0, held) + self.dot(
                fi - fe, du, held)
            self.D_c -= float(w)

    #: the accounts a checkpoint keeps
    ACCOUNTS = ("T0", "W_int", "W_ext", "W_D", "D_c", "scale")

    def accounts(self):
        """The running accounts, for a checkpoint."""
        return {"energy_" + k: getattr(self, k) for k in self.ACCOUNTS}

    def restore(self, saved):
        """Set the accounts from :meth:`accounts` (a resumed run)."""
        for k in self.ACCOUNTS:
            setattr(self, k, float(saved["energy_" + k]))

    def record(self, t, v, free, stored=None, closure=None):
        """The energies at time ``t`` as a dict (with the balance
        error, absolute and relative); ``closure``: the model's closure
        energy (:func:`closure_energy`), which the balance takes off the
        internal work."""
        T = self.kinetic(v, free)
        err = T + self.W_int - (closure or 0.0) + self.D_c - self.W_ext \
            - self.W_D - self.T0
        self.scale = scale = max(self.scale, T, abs(self.W_int),
                                 abs(self.W_ext), abs(self.W_D),
                                 abs(self.D_c), abs(stored or 0.0))
        out = {"t": float(t), "kinetic": T, "internal_work": self.W_int,
               "external_work": self.W_ext, "prescribed_work": self.W_D,
               "contact_loss": self.D_c, "error": err,
               "relative_error": err / scale}
        if closure is not None:
            out["closure"] = closure
        if stored is not None:
            out["stored"] = stored
            out["dissipation"] = self.W_int - stored
        return out


class DynamicsError(RuntimeError):
    """A time integration could not continue (no convergence at the
    smallest step, an inverted point, a failed return map, an explicit
    run going unstable).  ``t``, ``x``, ``v`` and ``history`` hold the
    last good state."""

    def __init__(self, message, t=0.0, x=None, v=None, history=None):
        super().__init__(message)
        self.t, self.x, self.v = t, x, v
        self.history = history or []


def history_text(hist):
    """The records of a run as JSON text (a checkpoint keeps them)."""
    return json.dumps(hist, default=float)


def history_of(text):
    """The records of :func:`history_text`."""
    return json.loads(str(text))


def commit(model, state, t, x, v, hist):
    """``model.commit(state)`` after a step to ``t``; a model that cannot
    go on from there (an updated-Lagrangian rebuild on an inverted
    collocation mesh) stops the run with :class:`DynamicsError` at
    ``t``.  Returns whether the model's discretization changed (a model
    whose ``commit`` returns ``True``: crack-aware families rebuilt), so
    that the integrator evaluates the internal force again."""
    if not hasattr(model, "commit"):
        return False
    try:
        return bool(model.commit(state))
    except (ParticleError, FamilyError) as err:
        raise DynamicsError("the model could not be committed at t = "
                            "{:.6g}: {}".format(t, err), t=t, x=x, v=v,
                            history=hist) from None


def book_rebuild(model, dot, f_before, f_after, du, root=True):
    r"""After a commit that changed the model's discretization at the end
    of a step (crack-aware families rebuilt): the driver
    books the step's work with the force of the new discretization, so
    the energy the model released at the step's end
    (``model.fracture_energy``) is corrected by
    :math:`-\tfrac12 (f_{before} - f_{after})\cdot\Delta u`, the half of
    the removed forces' work the trapezoid no longer counts
    (``model.book_removed_work``; exact to third order in the step).
    ``dot``: the sum over the dofs (over all ranks on MPI: collective);
    ``root``: whether this part books it (a model's released energy is
    summed over the ranks, so one rank books the whole sum)."""
    book = getattr(model, "book_removed_work", None)
    if book is not None:
        n = len(du)
        work = -0.5 * dot(np.asarray(f_before)[:n] - np.asarray(f_after)[:n],
                          du)
        book(work if root else 0.0)


@dataclass
class Trajectory:
    """A time integration's result: the unknowns ``x`` (displacements
    first), velocities ``v`` and accelerations ``a`` at the final time
    ``t``; ``history``: the energies (:class:`EnergyBalance`) and step
    data per output; ``steps``; ``times``: wall seconds by part.

    Examples
    --------
    >>> import numpy as np, skfem as fem, skfem_pg as pg
    >>> basis = pg.FamilyBasis(fem.MeshQuad().refined(2), dim=2)
    >>> from skfem_pg.formulations import Hyperelastic
    >>> from skfem_pg.materials import NeoHooke
    >>> problem = pg.Problem(Hyperelastic(basis, NeoHooke(lam=60.0, mu=40.0)),
    ...                      mass=pg.lumped_mass(basis, 1.0))
    >>> v0 = np.tile([0.1, 0.0], basis.N // 2)  # a rigid translation
    >>> tr = pg.central_difference(problem, t_end=0.01, v0=v0, verbose=False)
    >>> bool(np.allclose(tr.x[0::2], 0.001)), tr.t
    (True, 0.01)

    """
    x: np.ndarray
    v: np.ndarray
    a: np.ndarray
    t: float
    history: list = field(default_factory=list)
    steps: int = 0
    times: dict = field(default_factory=dict)

    def series(self, key):
        """One recorded quantity over the outputs, as an array."""
        return np.array([h[key] for h in self.history])


class Progress:
    """A progress line at every tenth (``parts``) of the simulated time:
    time, step size, steps per second, energies and the balance
    error."""

    def __init__(self, t_end, verbose, parts=10, stream=None):
        self.t_end, self.parts = t_end, parts
        self.echo = Echo(verbose, stream)
        self.next, self.t0 = 0, self.echo.t0

    def __call__(self, t, dt, steps, energies, force=False):
        if not self.echo.on:
            return
        frac = t / self.t_end if self.t_end > 0 else 1.0
        if not force and frac < self.next / self.parts - 1e-12:
            return
        while self.next / self.parts <= frac + 1e-12:
            self.next += 1
        wall = time.perf_counter() - self.t0
        e = energies
        print("  t {:.4g} ({:3.0f} %)  dt {:.3g}  {} steps, {:.3g}/s  "
              "T {:.4g}  W_int {:.4g}  W_ext {:.4g}  D_c {:.3g}  "
              "energy error {:.2e}".format(
                  t, 100 * frac, dt, steps, steps / max(wall, 1e-9),
                  e["kinetic"], e["internal_work"],
                  e["external_work"] + e["prescribed_work"],
                  e["contact_loss"], e["relative_error"]),
              file=self.echo.stream or sys.stdout, flush=True)


def resume_run(path, model, energy, hist, kind, controller=()):
    """The state a time-stepping checkpoint holds (:func:`save_run`):
    ``(x, t, v, a, f_int, held, saved)``; the energy accounts and the
    records are restored into ``energy`` and ``hist``, the model's
    history by :func:`~skfem_pg.solvers.checkpoint.load`.  ``saved``
    holds the integrator's own entries (its step controller: the names
    ``controller``).  A checkpoint of another ``kind`` of run
    (``"newmark"``, ``"explicit"``; a static one) or without these
    entries raises ``ValueError``."""
    needs = ("v", "a", "f_int", "held", "records") \
        + tuple(energy.accounts()) + tuple(controller)
    x, t, saved = load_checkpoint(path, model, state=True, kind=kind,
                                  needs=needs)
    energy.restore(saved)
    hist[:] = history_of(saved["records"])
    return (x, t, saved["v"], saved["a"], saved["f_int"],
            saved["held"].astype(bool), saved)


def save_run(every, count, model, x, t, v, a, f_int, held, energy, hist,
             kind, **controller):
    """Write a time-stepping run's state (unknowns, velocities,
    accelerations, internal force, held dofs, energy accounts, records and
    the integrator's ``controller`` entries) through ``every``
    (:class:`~skfem_pg.solvers.checkpoint.Every`, atomically) at the
    ``count``-th step; ``kind`` the integrator (``"newmark"``,
    ``"explicit"``)."""
    every.save(count, model, x, t, kind=kind, v=v, a=a, f_int=f_int,
               held=held.astype(float), records=history_text(hist),
               **energy.accounts(), **controller)


def stored_energy(model, state):
    """``model.energy(state)`` where the model offers it, else
    ``None``."""
    f = getattr(model, "energy", None)
    if f is None:
        return None
    try:
        return float(f(state))
    except (NotImplementedError, TypeError):
        return None


def free_mask(n_u, Dd):
    """``True`` at the displacement dofs that are not prescribed."""
    free = np.ones(n_u, dtype=bool)
    free[Dd] = False
    return free


def bind_walls(wall, basis, n_u, Dd):
    """``(walls, candidates)``: copies of ``wall`` (a
    :class:`~skfem_pg.solvers.RigidWall`, a list of them or ``None``)
    bound to this run, and the dofs each may hold
    (:meth:`RigidWall.bind`).  The caller's walls are not changed: a wall
    without ``tol`` takes its default from each body it meets."""
    walls = [] if wall is None else (list(wall) if isinstance(
        wall, (list, tuple)) else [wall])
    walls = [copy.copy(w) for w in walls]
    return walls, [w.bind(basis, n_u, Dd) for w in walls]


class BoundProblem(NamedTuple):
    """A :class:`~skfem_pg.solvers.problem.Problem` as a time integration
    uses it: the model, the mass, the prescribed dofs ``D`` (an array),
    the ``free`` displacement dofs, ``f_of(t)`` / ``uD_of(t)`` (full
    vectors) and the walls bound to the run with their candidate dofs."""

    model: object
    m: np.ndarray
    D: np.ndarray
    free: np.ndarray
    f_of: object
    uD_of: object
    walls: list
    candidates: list


def bind_problem(problem, m, bind=bind_walls):
    """The :class:`BoundProblem` of ``problem`` with the checked mass
    ``m``; ``bind(walls, basis, n_u, D)`` binds the walls (a collective
    one on MPI ranks)."""
    model = problem.model
    n_u = model.n_u
    Dd = as_dofs(problem.D, n_u, "Dirichlet (displacement) dofs")
    f_of, uD_of = time_functions(model, problem.f_ext, problem.u_D)
    walls, cand = bind(list(problem.walls), model.basis, n_u, Dd)
    return BoundProblem(model, m, Dd, free_mask(n_u, Dd), f_of, uD_of,
                        walls, cand)


class Timings(dict):
    """Seconds per phase of a run, as a dict; ``with timings("force"):``
    adds the seconds of the block to its phase.

    >>> t = Timings(("force",))
    >>> with t("force"):
    ...     pass
    >>> sorted(t), t["force"] >= 0.0
    (['force'], True)
    """

    def __init__(self, phases=()):
        super().__init__(dict.fromkeys(phases, 0.0))

    @contextlib.contextmanager
    def __call__(self, phase):
        t0 = time.perf_counter()
        try:
            yield
        finally:
            self[phase] = self.get(phase, 0.0) + time.perf_counter() - t0


def closure_energy(model, total=None):
    """What the steps lost where the model's failed points close and open
    (``model.closure_energy()``, :meth:`~skfem_pg.materials.plasticity.
    Response.closure_step`), summed over the ranks by ``total``; ``None``
    for a model without it or without a damage law.  The trapezoid's
    internal work books it on top of the failed points' energy, so the
    drivers' balance takes it off (the module docstring)."""
    f = getattr(model, "closure_energy", None)
    c = None if f is None else f()
    if c is None:
        return None
    return c if total is None else total(c)


class Recorder:
    """The output of a time-stepping run, shared by Newmark and central
    differences: at each output an energy record (:class:`EnergyBalance`)
    with the step data, the progress line, the user's
    ``callback(t, x, v, record)`` and the seconds spent (``times
    ["output"]``).  ``hist`` holds the records.

    Where a model fractures, its dissipation other than the released
    energy and the closure (``other_dissipation``: plastic, or zero to
    second order in the step for an elastic material) cannot fall: one
    that falls by more than ``max_dissipation_drop`` of the run's energy
    scale below its largest value stops the run with
    :class:`DynamicsError` — the model's force is then not the gradient
    of the energy it reports, and the run makes energy (issue 51: the
    pieces of the two-hole plate flying apart with ``CrackAwareU1SIG``'s
    former stabilization; its other dissipation fell by 17 % of the
    scale).  The drivers pass their ``max_energy_error``; the check
    starts after :data:`STARTUP_STEPS` steps."""

    def __init__(self, model, energy, free, progress, callback, times,
                 total=None, max_dissipation_drop=0.05):
        self.model, self.energy, self.free = model, energy, free
        self.progress, self.callback, self.times = progress, callback, times
        # a model's energies summed over the ranks (HaloExchange.sum)
        self.total = (lambda x: x) if total is None else total
        self.max_dissipation_drop = float(max_dissipation_drop)
        self.hist = []
        # the largest other dissipation of hist[:_seen] (a resumed run's
        # records included), kept so that an output reads only its own
        self._seen, self._most = 0, -np.inf

    def __call__(self, t, x, v, state, held, final=False, **data):
        """Record the state at ``t``; ``data``: ``dt``, ``steps`` and what
        else the integrator reports (in the record's order)."""
        t1 = time.perf_counter()
        closure = closure_energy(self.model, self.total)
        rec = self.energy.record(t, v, self.free & ~held, self.total(
            stored_energy(self.model, state)), closure)
        fracture = getattr(self.model, "fracture_energy", None)
        fracture = None if fracture is None else self.total(fracture())
        if fracture is not None:
            # part of the dissipation: what failed points or broken bonds
            # had stored when they failed (and, apart, the closure)
            rec["fracture"] = fracture
            if "stored" in rec:
                rec["other_dissipation"] = (rec["dissipation"] - fracture
                                            - (closure or 0.0))
        rec.update(data)
        self.hist.append(rec)
        self.progress(t, data["dt"], data["steps"], rec, force=final)
        if self.callback is not None:
            self.callback(t, x, v, rec)
        self.times["output"] += time.perf_counter() - t1
        if data.get("steps", 0) > STARTUP_STEPS:
            self.check_dissipation(t, x, v)

    def check_dissipation(self, t, x, v):
        """Stop a run whose other dissipation fell (class docstring)."""
        if self._seen > len(self.hist):  # records replaced: read again
            self._seen, self._most = 0, -np.inf
        for r in self.hist[self._seen:]:
            self._most = max(self._most, r.get("other_dissipation", -np.inf))
        self._seen = len(self.hist)
        other = self.hist[-1].get("other_dissipation") if self.hist else None
        if other is None:
            return
        drop = self._most - other
        if drop > self.max_dissipation_drop * self.energy.scale:
            raise DynamicsError(
                "the dissipation other than the released energy (W_int - "
                "stored - released - closure) fell by {:.4g} ({:.3g} of "
                "the energy scale {:.4g}, more than {:g}) below its "
                "largest value at t = {:.6g}: the model's internal force is "
                "not the gradient of the energy it reports (the run makes "
                "energy, or books it wrong)".format(
                    drop, drop / self.energy.scale, self.energy.scale,
                    self.max_dissipation_drop, t),
                t=t, x=x, v=v, history=self.hist)
