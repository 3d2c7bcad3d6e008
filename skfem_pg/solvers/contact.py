r"""A rigid frictionless plane wall: the thesis' simplified contact (7.3.7).

The wall is the plane :math:`x_a = c` normal to a coordinate axis ``a``;
the body lies on the side ``side`` (``+1``: :math:`x_a \ge c`).  It acts
on the normal displacement dof of each node (particle) alone — no friction,
the tangential motion stays free — and only by pressure:

* explicit (:func:`~skfem_pg.solvers.central_difference`): a dof whose
  predicted position lies behind the wall is put on it; a dof on the wall
  is *held* (zero normal velocity and acceleration) while the free
  acceleration pushes it into the wall, i.e. while the reaction is
  compressive, and released as soon as it would pull;
* implicit (:func:`~skfem_pg.solvers.newmark`): an active set, solved as
  Dirichlet dofs; after a converged step the dofs with a tensile reaction
  are released and the free ones behind the wall are activated, and the
  step is repeated until the set no longer changes.

A held dof is massless while held (its inertia is part of the reaction);
the kinetic energy an impact destroys is reported as the contact loss
(:mod:`~skfem_pg.solvers.dynamics`).
"""
import numpy as np

from .exchange import SerialExchange


class RigidWall:
    """The plane ``x[axis] = position``, the body on ``side`` of it.

    ``tol``: the penetration (a length) below which a dof counts as on the
    wall; default 1e-9 of the body's extent along ``axis``.
    ``release=False``: a dof once held stays on the wall (it slides along
    it, never lifts off) — a wall that a fluid wets, which no tension
    draws the fluid off (:class:`~skfem_pg.formulations.
    UpdatedLagrangeFluid`); implicit runs only.

    Examples
    --------
    The plane ``y = 0`` with the body above it (``side=1``); a driver binds a
    copy of it to each run (``Problem(..., walls=wall)``):

    >>> wall = RigidWall(axis=1, position=0.0, side=1)
    >>> wall
    RigidWall(axis=1, position=0.0, side=+1)

    """

    def __init__(self, axis, position=0.0, side=1, tol=None,
                 release=True):
        if side not in (1, -1):
            raise ValueError("side must be +1 or -1, got {!r}".format(side))
        if isinstance(axis, bool) or not isinstance(axis, (int, np.integer)):
            raise ValueError("axis must be an integer (0: x, 1: y, 2: z), "
                             "got {!r}".format(axis))
        if not np.isfinite(position):
            raise ValueError("the wall's position must be finite, got {!r}"
                             .format(position))
        if tol is not None and not (np.isfinite(tol) and tol >= 0):
            raise ValueError("tol must be a non-negative length, got {!r}"
                             .format(tol))
        self.axis, self.position, self.side = int(axis), float(position), side
        self.tol = tol
        self.release = bool(release)

    def __repr__(self):
        return "RigidWall(axis={}, position={}, side={:+d}{})".format(
            self.axis, self.position, self.side,
            "" if self.release else ", release=False")

    def bind(self, basis, n_u, D):
        """The candidate dofs (component ``axis`` of every node, except
        prescribed ones) and their reference coordinates; checks that the
        body starts on its side."""
        locs = basis.doflocs
        d = locs.shape[0]
        if not 0 <= self.axis < d:
            raise ValueError("{!r}: axis {} of a {}-D body".format(
                self, self.axis, d))
        dofs = np.setdiff1d(np.arange(self.axis, n_u, d), D)
        self.dofs = dofs
        self.X = locs[self.axis, dofs]
        if self.tol is None:
            self.tol = self.default_tol(locs)
        behind = self.side * (self.X - self.position) < -self.tol
        if behind.any():
            i = np.flatnonzero(behind)[0]
            raise ValueError(
                "{!r}: {} node(s) start behind the wall, first dof {} at "
                "{} = {}".format(self, behind.sum(), dofs[i], "xyz"[self.axis],
                                 self.X[i]))
        return dofs

    def default_tol(self, x):
        """1e-9 of the extent along the axis of the points ``x``
        ``(d, n)``: the ``tol`` of a wall not given one."""
        ext = np.ptp(x[self.axis]) if x.shape[1] else 1.0
        return 1e-9 * max(ext, 1e-300)

    def touching(self, x):
        """Mask of the points ``x`` ``(d, n)`` (positions, not bound
        dofs) on or behind the wall, within ``tol`` (:meth:`default_tol`
        of ``x`` for a wall not given one)."""
        tol = self.default_tol(x) if self.tol is None else self.tol
        return self.side * (x[self.axis] - self.position) <= tol

    def gap(self, u):
        """Signed distances of the candidates to the wall (negative:
        behind it)."""
        return self.side * (self.X + u[self.dofs] - self.position)

    def wall_values(self):
        """The displacements that put each candidate on the wall."""
        return self.position - self.X

    def penetrating(self, u):
        """Mask of the candidates behind the wall by more than ``tol``."""
        return self.gap(u) < -self.tol

    def on_wall(self, u):
        """Mask of the candidates on (or behind) the wall."""
        return self.gap(u) <= self.tol

    def compressive(self, force):
        """Mask of the candidates whose wall force (``force``: the force
        the wall must exert on each candidate dof to hold it) pushes the
        body away from the wall (all of them for a wall that does not
        release)."""
        if not self.release:
            return np.ones(np.shape(force), dtype=bool)
        return self.side * force > 0


def hold_initial(walls, candidates, u, v, a, m, held,
                 dot=SerialExchange.dot):
    """Hold the candidates that start on a wall moving or pushed into it
    (zero normal velocity and acceleration); returns the kinetic energy
    the walls took (``dot``: the sum over dofs, of all ranks on MPI).
    A body that starts behind a wall (displaced there by
    ``u0``) is refused by name."""
    lost = 0.0
    for w, c in zip(walls, candidates):
        behind = w.penetrating(u)
        if behind.any():
            i = np.flatnonzero(behind)[0]
            raise ValueError(
                "{!r}: the initial displacements put {} node(s) behind the "
                "wall, first dof {} at {} = {:.6g}".format(
                    w, int(behind.sum()), c[i], "xyz"[w.axis],
                    w.X[i] + u[c[i]]))
        on = w.on_wall(u)
        into = w.side * (v[c] + a[c]) < 0
        h = c[on & into]
        held[h] = True
        lost += 0.5 * dot(m, v * v, h)
        v[h], a[h] = 0.0, 0.0
    return lost
