r"""Free-surface flow on particles that re-neighbour and merge: the driver
of :class:`~skfem_pg.formulations.UpdatedLagrangeFluid` for flows whose
particles crowd, as at the stagnation corner of a dam break.

A Lagrangian particle set follows the fluid: where the flow stagnates
against a wall the particles along it close in on each other, the
dilatation of one family (one pressure per particle) does not see a pair
inside it closing, and the pair meets — a family then has two members at
one place and its derivatives blow up (measured on the dam break at
T ≈ 2.1, every resolution and particle set).  The particle finite element
method removes such nodes (Idelsohn, Oñate & Del Pin 2004); here they are
merged [choice made here]: :func:`free_surface_flow` runs
:func:`~skfem_pg.newmark` and, whenever two particles come closer than
``merge`` times their mean spacing, stops, replaces each such pair by one
particle with the pair's mass, momentum and volume (:func:`merge_close`),
and goes on from the current positions with a new basis and model (a
*segment*).  From segment to segment the particles keep their masses,
the new families take the dilatation :math:`\Theta = \rho_0/\rho` of
the old families' linear field at their centroids, as at a rebuild
(:func:`~skfem_pg.formulations.fluid_updated_lagrange.theta_at`; each
particle's own family value carried instead jolted the pressure, and the
8 x 16 dam break blew up right after its sixth merge at T = 2.25,
measured), and the velocities are given to the masses lumped on the new
cells with the same momentum and energy
(:func:`~skfem_pg.solvers.newmark.remap_velocity`).
"""
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial import cKDTree

from ..discretization.basis import FamilyBasis
from ..discretization.retriangulation import alpha_shape, collocate
from ..formulations.fluid_updated_lagrange import dilatation_field, theta_at
from .controls import NewmarkControls
from .dynamics import DynamicsError
from .newmark import newmark, remap_velocity


#: Newmark's rule of :func:`free_surface_flow`: gamma = 0.55, beta =
#: (gamma + 1/2)^2 / 4, which damps what the step does not resolve (the
#: pressure waves of a stiff fluid, the jolts of rebuilds and merges).
#: With the trapezoidal rule (gamma = 1/2) the dam break's energy rises
#: after T = 2 and the runs stop on the energy check at T = 2.2-4.0 (five
#: particle sets); with gamma = 0.55 six sets reach T = 4, losing 3.8-6.3 %
#: of weight x height (``benchmarks/flow.py``).
FLOW_CONTROLS = NewmarkControls(beta=0.275625, gamma=0.55)


@dataclass
class FlowResult:
    """The end of a :func:`free_surface_flow` run: time ``t``, particle
    positions ``x`` and velocities ``v`` ``(d, n)``, masses ``m``,
    dilatations ``theta`` and spacings ``spacing`` ``(n,)`` (``n`` after
    the merges), the ``segments`` run, the ``merged`` pairs (as indices
    of the particles of their segment, with the time), the Newmark
    ``steps`` and the model's ``rebuilds``, summed over the segments."""
    t: float
    x: np.ndarray
    v: np.ndarray
    m: np.ndarray
    theta: np.ndarray
    spacing: np.ndarray
    segments: int = 1
    merged: list = field(default_factory=list)
    steps: int = 0
    rebuilds: int = 0
    outputs: int = 0


def close_pairs(x, spacing, merge):
    """Pairs ``(i, j)`` of particles closer than ``merge`` times their
    mean ``spacing``, closest first."""
    r = merge * float(np.max(spacing))
    pairs = np.array(sorted(cKDTree(x.T).query_pairs(r)), dtype=int)
    if len(pairs) == 0:
        return pairs.reshape(0, 2)
    i, j = pairs.T
    dist = np.linalg.norm(x[:, i] - x[:, j], axis=0)
    close = dist < merge * 0.5 * (spacing[i] + spacing[j])
    return pairs[close][np.argsort(dist[close])]


def merge_close(x, v, m, theta, spacing, pairs, walls=()):
    """Merge each pair of ``pairs`` (disjoint pairs first come, first
    served): one particle at the pair's centre of mass, with its momentum,
    its mass, its current volume (:math:`m\\Theta/\\rho_0` summed, so
    :math:`\\Theta` is mass-averaged) and the spacing of that volume; on a
    wall (a :class:`~skfem_pg.solvers.RigidWall`) if either was, with no
    velocity into it.  Returns the new ``(x, v, m, theta, spacing)`` and
    the pairs merged."""
    d = x.shape[0]
    taken = np.zeros(x.shape[1], dtype=bool)
    done = []
    for i, j in pairs:
        if taken[i] or taken[j]:
            continue
        taken[i] = taken[j] = True
        done.append((int(i), int(j)))
    keep = np.ones(x.shape[1], dtype=bool)
    touching = [w.touching(x) for w in walls]
    x, v, m = x.copy(), v.copy(), m.copy()
    theta, spacing = theta.copy(), spacing.copy()
    for i, j in done:
        M = m[i] + m[j]
        xi = (m[i] * x[:, i] + m[j] * x[:, j]) / M
        vi = (m[i] * v[:, i] + m[j] * v[:, j]) / M
        for w, on in zip(walls, touching):
            if on[i] or on[j]:
                xi[w.axis] = w.position
                vi[w.axis] = max(0.0, w.side * vi[w.axis]) * w.side
        theta[i] = (m[i] * theta[i] + m[j] * theta[j]) / M
        spacing[i] = (spacing[i] ** d + spacing[j] ** d) ** (1.0 / d)
        x[:, i], v[:, i], m[i] = xi, vi, M
        keep[j] = False
    return (x[:, keep], v[:, keep], m[keep], theta[keep], spacing[keep],
            done)


def _on_walls(x, walls):
    """``(d, n)``: whether a particle's coordinate is held by a wall."""
    on = np.zeros(x.shape, dtype=bool)
    for w in walls:
        on[w.axis] |= w.touching(x)
    return on


class _Restart(Exception):
    def __init__(self, t, x, v):
        super().__init__("restart")
        self.t, self.x, self.v = t, x, v


class _Watch:
    """The callback of a segment's :func:`~skfem_pg.newmark`: the user's
    outputs, the energy check, the merges (:func:`free_surface_flow`)."""

    def __init__(self, run, model, t0, X):
        self.run, self.model, self.t0, self.X = run, model, t0, X
        self.steps = 0

    def __call__(self, ts, u, vs, record):
        run, model = self.run, self.model
        d = self.X.shape[0]
        self.steps = int(record.get("steps", 0))
        x = self.X + u[:model.n_u].reshape(-1, d).T
        v = vs.reshape(-1, d).T
        out = run.out
        out.outputs += 1
        final = self.t0 + ts >= run.t_end * (1 - 1e-12)
        if run.callback is not None and (
                (out.outputs - 1) % run.output_every == 0 or final):
            run.callback(self.t0 + ts, x, v, model.mass()[::d])
        gain = (run.energy(x, v, model.mass()[::d]) - run.E0) / run.scale
        if gain > run.max_energy_gain:
            raise DynamicsError(
                "free_surface_flow: the particles gained {:.3g} of the "
                "energy scale (weight x height, {:.4g}) by t = {:.6g}, "
                "more than max_energy_gain = {:g}: the re-neighbouring "
                "creates energy here (UpdatedLagrangeFluid)".format(
                    gain, run.scale, self.t0 + ts, run.max_energy_gain),
                t=self.t0 + ts)
        if ts > 0 and len(close_pairs(x, model.spacing, run.merge)):
            raise _Restart(ts, x, v)


class _Run:
    """The state of a :func:`free_surface_flow` run between segments."""

    def __init__(self, g, callback, output_every, merge, max_energy_gain,
                 t_end):
        self.g, self.callback, self.output_every = g, callback, output_every
        self.t_end = t_end
        self.merge, self.max_energy_gain = merge, max_energy_gain
        self.E0 = self.scale = None
        self.out = None

    def energy(self, x, v, m):
        """Kinetic plus potential energy of the particles."""
        return float(0.5 * np.sum(m * (v * v).sum(axis=0))
                     - np.sum(m * (self.g @ x)))

    def start(self, x, v, m):
        self.E0 = self.energy(x, v, m)
        height = np.ptp(self.g @ x) / max(np.linalg.norm(self.g), 1e-300)
        self.scale = max(float(m.sum() * np.linalg.norm(self.g) * height
                               + 0.5 * np.sum(m * (v * v).sum(axis=0))),
                         1e-300)


def free_surface_flow(mesh, fluid, rho, t_end, dt, gravity, walls=(),
                      method="VCBCPBG V5m UnlP0", alpha=1.2, merge=0.25,
                      distortion=0.1, quality=0.3, callback=None,
                      output_every=1, max_energy_gain=0.05,
                      max_segments=1000, controls=FLOW_CONTROLS,
                      **newmark_kw):
    r"""Run a free-surface flow of ``fluid`` (a
    :class:`~skfem_pg.materials.NewtonianFluid`, density ``rho``) that
    fills ``mesh`` (2-D) at rest, under ``gravity`` (a vector), from 0 to
    ``t_end`` with Newmark steps of at most ``dt``, on
    :class:`~skfem_pg.formulations.UpdatedLagrangeFluid` (``method``
    with the local VC correction, ``alpha``, ``distortion``,
    ``quality``), merging particles closer than ``merge`` spacings
    (module docstring).

    ``walls``: :class:`~skfem_pg.solvers.RigidWall` planes, best with
    ``release=False`` (a wetted wall).  ``callback(t, x, v, m)`` every
    ``output_every`` steps (and at each segment's start and end):
    positions and velocities ``(d, n)`` and masses of the particles of
    the segment.  ``controls``: Newmark's, by default
    :data:`FLOW_CONTROLS` (gamma = 0.55, dissipative); other keywords go
    to :func:`~skfem_pg.newmark`, which outputs every step: the merges
    and the energy are checked there.

    Raises
    ------
    DynamicsError
        The particles' kinetic plus potential energy rose above its start
        by more than ``max_energy_gain`` times the total weight times the
        height span (the re-neighbouring does not conserve energy exactly:
        a run that creates it is stopped, not returned); a segment stopped
        for another reason than a merge (its time is the run's); more
        than ``max_segments`` segments.  Its ``result`` is the
        :class:`FlowResult` of the run so far (its merges, steps,
        rebuilds; the state is the error's).

    Examples
    --------
    A column of water at rest on a floor stays there:

    >>> import numpy as np, skfem as fem
    >>> from skfem_pg.materials import NewtonianFluid
    >>> from skfem_pg.solvers import RigidWall
    >>> mesh = fem.MeshQuad.init_tensor(*[np.linspace(0, 0.1, 5)] * 2)
    >>> walls = [RigidWall(1, release=False), RigidWall(0, release=False),
    ...          RigidWall(0, 0.1, side=-1, release=False)]
    >>> r = free_surface_flow(mesh, NewtonianFluid(K=2.08e9, eta=1e-3),
    ...                       1e3, 0.02, 0.005, [0.0, -9.81], walls=walls,
    ...                       verbose=False)
    >>> bool(np.abs(r.v).max() < 1e-3), r.segments
    (True, 1)

    """
    from ..formulations.fluid_updated_lagrange import UpdatedLagrangeFluid
    from .mass import lumped_mass
    if not (np.isfinite(merge) and 0 < merge < 1):
        raise ValueError("merge must lie in (0, 1) spacings, got {!r}"
                         .format(merge))
    if not (np.isfinite(max_energy_gain) and max_energy_gain > 0):
        raise ValueError("max_energy_gain must be a positive number, got "
                         "{!r}".format(max_energy_gain))
    walls = list(walls)
    first = FamilyBasis.from_name(mesh, method, dim=mesh.dim(),
                                  vc_solver="local")
    d = first.particles.dim
    g = np.asarray(gravity, dtype=float).reshape(d)
    m = lumped_mass(first, rho)[::d]  # per particle
    x = first.particles.x.copy()
    v = np.zeros_like(x)
    theta = np.ones(x.shape[1])
    spacing = first.particles.volumes ** (1.0 / d)
    run = _Run(g, callback, int(output_every), merge, max_energy_gain,
               t_end)
    run.start(x, v, m)
    out = run.out = FlowResult(0.0, x, v, m, theta, spacing, segments=0)
    basis, t, restart = first, 0.0, False
    while t < t_end * (1 - 1e-12):
        if out.segments >= max_segments:
            err = DynamicsError("free_surface_flow: more than {} segments "
                                "by t = {:.6g}".format(max_segments, t),
                                t=t)
            err.result = out
            raise err
        out.segments += 1
        model = UpdatedLagrangeFluid(basis, fluid, rho, alpha=alpha,
                                     distortion=distortion, quality=quality,
                                     theta=theta, spacing=spacing, masses=m)
        watch = _Watch(run, model, t, x)
        if restart:  # the mass lumped on the new cells: the same energy
            m_old, m_new = np.repeat(m, d), model.mass()
            v = remap_velocity(v.T.ravel(), m_old, m_new,
                               ~_on_walls(x, walls).T.ravel(),
                               np.arange(m_new.size) % d,
                               -(g[:, None] * x).T.ravel()).reshape(-1, d).T
        try:
            tr = newmark(model, model.mass(), t_end - t, dt, gravity=g,
                         wall=walls or None, v0=v.T.ravel(), callback=watch,
                         controls=controls, output_every=1, **newmark_kw)
        except _Restart as stop:
            theta, m = _dilatation(model, stop.x, watch.X), model.mass()[::d]
            field = dilatation_field(model.current, stop.x, theta)
            x, v, m, theta, spacing, done = merge_close(
                stop.x, stop.v, m, theta, spacing,
                close_pairs(stop.x, spacing, merge), walls)
            out.merged += [(t + stop.t, i, j) for i, j in done]
            out.steps += watch.steps
            out.rebuilds += model.rebuilds
            t += stop.t
            basis = FamilyBasis(collocate(*alpha_shape(x, spacing, alpha)),
                                **first.options)
            keep = np.ones(stop.x.shape[1], dtype=bool)
            keep[[j for _, j in done]] = False
            c, grad, (lo, hi) = field
            theta = theta_at(basis, x, theta, (c[:, keep], grad[:, keep],
                                                (lo[keep], hi[keep])))
            restart = True
            continue
        except DynamicsError as err:
            out.steps += watch.steps
            out.rebuilds += model.rebuilds
            if not str(err).startswith("free_surface_flow"):
                err = DynamicsError(
                    "free_surface_flow, segment {} (from t = {:.6g}): {}"
                    .format(out.segments, t, err), t=t + err.t)
            err.result = out  # the run so far: merges, steps, rebuilds
            raise err from None
        out.steps += tr.steps
        out.rebuilds += model.rebuilds
        x = watch.X + tr.x[:model.n_u].reshape(-1, d).T
        v = tr.v.reshape(-1, d).T
        theta, m = _dilatation(model, x, watch.X), model.mass()[::d]
        t += tr.t
    out.t, out.x, out.v, out.m, out.theta, out.spacing = (
        t, x, v, m, theta, spacing)
    return out


def _dilatation(model, x, X):
    """Per particle, the dilatation of its family at the positions ``x``
    (the last one carried for a free particle)."""
    u = (x - X).T.ravel()
    theta = model.theta.copy()
    s = model.state(u)
    theta[np.asarray(model.current.families.masters)] = s["c_Theta"][:, 0]
    return theta
