r"""Explicit central differences on MPI ranks: the serial time-stepping
skeleton (:func:`skfem_pg.solvers.central_difference`) on each rank's
local vectors, with the communication of
:class:`~skfem_pg.distributed.halo.HaloExchange` injected.

Per step a rank evaluates the internal force of the families (or FE
cells) it owns on its local particles (owned + halo), and one exchange
sums the contributions at each particle to its owner and copies the total
back to the ranks that hold the particle as halo.  The rank then
integrates all its local dofs; its halo copies stay equal to their owners'
values because every operand is.  Lumped masses, loads and prescribed
motions are per particle and need no exchange.  Energies, the minimum J
and the stable-step estimate (Lanczos iterations with distributed
products, :func:`~skfem_pg.solvers.explicit.lanczos_max`) are reduced
over the ranks.  History lives with the points of a rank's families.

Inputs are given as in a serial run, in scikit-fem's serial numbering and
the same on every rank; the result comes back in the serial numbering on
every rank.

Checkpoints: every rank writes its own piece (``<stem>.rank<r>.step<k>
.npz``, atomically), then rank 0 writes the manifest ``<stem>.npz``
naming the step; the previous pieces are removed only after that.  A run
killed at any moment leaves a manifest whose pieces are complete.  Resume
on the same number of ranks and the same partition (the pieces carry the
fingerprint of each rank's model: positions of the local particles).
"""
import copy
import os

import numpy as np

from ..solvers import explicit as serial
from ..solvers.checkpoint import Every, atomic_savez, npz_path
from ..solvers.dynamics import Trajectory
from ..solvers.problem import Problem
from .halo import HaloExchange


class RankCheckpoints(Every):
    """A :class:`~skfem_pg.solvers.checkpoint.Every` for a run on ranks:
    rank 0 decides when (its clock), every rank writes its piece, rank 0
    the manifest (module docstring)."""

    def __init__(self, every, part):
        super().__init__(every.path, every.steps, every.seconds)
        self.part = part
        self._piece = None

    def piece(self, count, rank=None):
        stem = self.path[:-len(".npz")]
        return "{}.rank{}.step{}.npz".format(
            stem, self.part.rank if rank is None else rank, count)

    def due(self, count):
        return self.part.comm.bcast(super().due(count), root=0)

    def write(self, count, model, x, load, **state):
        from ..solvers.checkpoint import save
        comm = self.part.comm
        piece = save(self.piece(count), model, x, load, **state)
        comm.barrier()  # every piece of step `count` is on disk
        if self.part.rank == 0:
            atomic_savez(self.path, ranks=self.part.size, step=count)
        comm.barrier()
        if self._piece is not None and self._piece != piece and \
                os.path.exists(self._piece):
            os.unlink(self._piece)
        self._piece = piece


def resume_piece(path, part):
    """The piece of this rank named by the manifest ``path`` of
    :class:`RankCheckpoints`."""
    path = npz_path(path)
    try:
        with np.load(path) as f:
            ranks, step = int(f["ranks"]), int(f["step"])
    except (OSError, KeyError, ValueError) as err:
        raise ValueError("{} is not the manifest of a checkpoint on ranks "
                         "({}: {})".format(path, type(err).__name__, err)) \
            from None
    if ranks != part.size:
        raise ValueError("checkpoint {} was written on {} ranks, this run "
                         "has {}: resume on as many ranks".format(
                             path, ranks, part.size))
    stem = path[:-len(".npz")]
    return "{}.rank{}.step{}.npz".format(stem, part.rank, step)


def central_difference(model, part, m=None, t_end=None, f_ext=None, D=None,
                       u_D=None, u0=None, v0=None, dt=None, wall=None,
                       callback=None, checkpoint=None, resume=None,
                       controls=None, **kw):
    r"""Central differences (:func:`skfem_pg.solvers.central_difference`)
    for a model on this rank's local basis (:meth:`Partition.basis` or
    :meth:`Partition.fe_basis`), collectively on all ranks of ``part``.
    ``model``: the model, or a :class:`~skfem_pg.solvers.problem.Problem`
    of it (then ``t_end`` by keyword) whose vectors are serial and whose
    mass is local.

    ``m`` is the local lumped mass (:func:`lumped_mass`); ``f_ext``,
    ``u_D`` (vectors or callables of the time), ``u0``, ``v0`` and the
    prescribed dofs ``D`` are serial (scikit-fem numbering, the same on
    every rank); ``wall``, ``dt``, ``controls`` / ``kw`` as in the serial
    driver.  ``callback(t, x, v, record)`` receives serial vectors
    (gathered on every rank: collective).  ``checkpoint`` / ``resume``:
    the manifest path of :class:`RankCheckpoints`.

    Returns the serial :class:`~skfem_pg.solvers.dynamics.Trajectory` with
    ``x``, ``v``, ``a`` in the serial numbering on every rank; the
    energies are those of the whole body.
    """
    problem = Problem.of(model, "central_difference", f_ext=f_ext, D=D,
                         u_D=u_D, wall=wall, m=m)
    model, D = problem.model, problem.D
    n_u = model.n_u
    if model.N != n_u:
        raise NotImplementedError(
            "{} has global unknowns beyond the displacements: explicit "
            "steps on ranks take displacement models".format(
                type(model).__name__))
    nc = n_u // len(part.local) if len(part.local) else 0
    if nc * len(part.local) != n_u or nc < 1:
        raise ValueError("the model is not on this partition's local "
                         "particles ({} dofs, {} local particles)".format(
                             n_u, len(part.local)))
    ex = HaloExchange(part, nc)
    lsd = ex.serial_dofs()
    N = nc * part.n

    def local(v, what):
        if v is None:
            return None
        if callable(v):
            return lambda t: local(v(t), what + "(t)")
        v = np.asarray(v, dtype=float)
        if v.shape != (N,):
            raise ValueError("{} is a serial vector of {} entries, got "
                             "shape {}".format(what, N, v.shape))
        return v[lsd]

    if D is not None:
        from ..dofs import as_dofs
        mask = np.zeros(N, dtype=bool)
        mask[as_dofs(D, N, "Dirichlet dofs (serial numbering)")] = True
        D = np.flatnonzero(mask[lsd])
    walls = []
    for w in problem.walls:  # the serial default tolerance: of the whole
        w = copy.copy(w)     # body (on copies: the caller's walls stay)
        if w.tol is None:
            w.tol = 1e-9 * max(np.ptp(part.particles.x[w.axis]), 1e-300)
        walls.append(w)

    def gather(x):
        return gather_owned(part, x, nc)

    cb = None
    if callback is not None:
        def gathered(t, x, v, rec):
            callback(t, gather(x), gather(v), rec)
        cb = gathered
    every = Every.of(checkpoint)
    if every is not None:
        every = RankCheckpoints(every, part)
    if resume is not None:
        resume = resume_piece(resume, part)
    on_rank = Problem(model, f_ext=local(problem.f_ext, "f_ext"), D=D,
                      u_D=local(problem.u_D, "u_D"), walls=walls,
                      mass=problem.mass)
    traj = serial.central_difference(
        on_rank, t_end=t_end, u0=local(u0, "u0"), v0=local(v0, "v0"),
        dt=dt, callback=cb, checkpoint=every, resume=resume,
        controls=controls, exchange=ex, **kw)
    traj.times["messages"] = ex.messages
    return Trajectory(gather(traj.x), gather(traj.v), gather(traj.a),
                      traj.t, traj.history, traj.steps, traj.times)


def gather_owned(part, x, nc):
    """A local vector (``nc`` components per local particle, owned first)
    in the serial numbering on every rank."""
    own = np.asarray(x[:nc * len(part.owned)], dtype=float)
    parts = part.comm.allgather(own)
    owned = part.comm.allgather(part.owned)
    out = np.empty(nc * part.n)
    for o, p in zip(owned, parts):
        out.reshape(-1, nc)[o] = p.reshape(-1, nc)
    return out
