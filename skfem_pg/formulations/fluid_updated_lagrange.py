r"""A fluid on PBG UnlP0 in the updated Lagrangian frame with
re-neighbouring (thesis 8.2: "updated Lagrangian where total Lagrangian
breaks down"): the flows whose particles travel far from their first
neighbours, as the dam break.  [The thesis does not build it; every
choice below is made here and measured in ``benchmarks/flow.py``.]

**When it rebuilds.**  In the total Lagrangian frame the families are
those of the particles' first positions; a surge shears them until a
family inverts (``J <= 0``; the dam break stops at T = 2.4-2.9).  Here,
after a converged step, the particles' current positions are
triangulated again — the Delaunay triangulation trimmed by an alpha
shape, as the particle finite element method does
(:func:`~skfem_pg.discretization.retriangulation.alpha_shape`) — when a
cell of the last rebuild has left the alpha shape or worn out (its radius
ratio below ``quality`` times its ratio at the rebuild and below 0.1), or
a point's :math:`\det\Delta F` is off 1 by more than ``distortion``.  The
particles are collocated from the kept cells (a particle in none is
*free*: no volume, no internal force, it flies under its loads until a
rebuild takes it in again) and the families, derivatives and VC
corrections are built there with the options of the first basis.  The
displacement unknowns keep their numbering.

**The frame** between rebuilds is that of :class:`UpdatedLagrange`
(2.18): :math:`F = \Delta F\,F_c`, :math:`\Delta F = I + \nabla_c(u -
u_c)`.  A fluid has no shear memory, so at a rebuild

.. math::

    F_c = \Theta_k^{1/d} I \quad\text{at every point of family } k,

and the viscous history (the committed :math:`F_n` of
:class:`~skfem_pg.materials.NewtonianFluid`) restarts at :math:`F_c`.
With :math:`F_c` constant over a family the reference weights are
:math:`w_c/J_c`, the mean dilatation of :class:`~skfem_pg.formulations.
MeanDilatation` is :math:`\Theta = J_c \sum_j w_{c,j}\det\Delta F^j /
\sum_j w_{c,j}`, the internal force :math:`\sum w_c\, P F_c^T/J_c :
\nabla_c\delta u`, and both tangent parts scale by :math:`J_c^{2/d-1}`,
which is 1 in 2-D: the tangent is :class:`~skfem_pg.formulations.
MeanDilatation`'s on the current basis.

**The pressure carried.**  A family's mean dilatation stands for the
field at its centroid, not at its particle.  The new family of particle
``k`` takes the old families' field at its own centroid: a least-squares
linear field through the old centroids (:func:`dilatation_field`), moved
to the new centroid and kept within the old family's range
(:func:`theta_at`).  A hydrostatic pressure is linear, so it carries over
exactly; with the value carried unmoved the dam break gains energy at
each rebuild and blows up (measured).

**The mass** follows the cells, as in the particle finite element
method: with the local VC correction the pressure force on a particle is
the P1 one, :math:`-V^k\nabla p` with the lumped volume :math:`V^k` of
the current cells, and a fluid at rest needs its weight to match it —
with the first basis' masses kept, a column whose cells change flows at
about g/3 (measured).  So after a rebuild the mass is
:math:`\rho_0 V^k/\Theta_k`, scaled to keep the total (:meth:`mass`; a
free particle keeps its own), and :func:`skfem_pg.newmark` takes it (with
``gravity=``, the weight too).  Mass moved between particles whose
velocities are kept changes the kinetic energy and the weight's
potential energy (mass moved onto fast or high particles creates it: the
8 x 16 dam break gained 2 % of weight x height this way and stopped on
the energy check at T = 2.4, measured), so :func:`skfem_pg.newmark`
gives the velocities to the new masses with the same momentum and the
same kinetic plus potential energy
(:func:`~skfem_pg.solvers.newmark.remap_velocity`).
"""
import numpy as np

from ..discretization.basis import FamilyBasis
from ..discretization.elementwise import Elements
from ..discretization.retriangulation import (alpha_shape, circumradii,
                                              collocate, free_particles,
                                              radius_ratios)
from ..discretization.assembly import assemble
from ..threads import kernel
from .dilatation import MeanDilatation, compressible_moduli
from .displacement import internal_force
from .history import History


def _per_particle(a, n, name):
    a = np.broadcast_to(np.asarray(a, dtype=float), (n,)).copy()
    if not np.all(np.isfinite(a)):
        raise ValueError("{}: finite values per particle".format(name))
    return a


def _flat_pairs(basis):
    """Per flat point of ``basis``: its family's master and its member
    particle, and its weight."""
    fam = basis.families
    k = np.repeat(np.asarray(fam.masters), np.diff(fam.offsets))
    return k, np.asarray(fam.members), basis.flat_weights().ravel()


def family_centroids(basis, x):
    """Per particle, the weighted centroid of its family's members at
    the positions ``x`` ``(d, n)`` (``nan`` where it masters none)."""
    k, j, w = _flat_pairs(basis)
    n = x.shape[1]
    V = np.bincount(k, w, minlength=n)
    c = np.array([np.bincount(k, w * xi[j], minlength=n) for xi in x])
    with np.errstate(invalid="ignore", divide="ignore"):
        return c / V


def dilatation_field(basis, x, theta):
    r"""A linear field through the families' dilatations ``theta`` (per
    particle, its family's :math:`\Theta`): per particle ``(centroid,
    gradient, (low, high))`` — its family's centroid at the positions
    ``x``, the least-squares gradient over the members' centroids (zero
    where they do not span the space) and the range of the members'
    values.  A family's mean dilatation stands for the field at its
    centroid, not at its particle; a new family takes the field at its
    own centroid (:func:`theta_at`), so a hydrostatic (linear) pressure
    carries over exactly."""
    k, j, w = _flat_pairs(basis)
    d, n = x.shape
    c = family_centroids(basis, x)
    ok = np.isfinite(c[0])
    sel = ok[k] & ok[j] & (k != j)
    k, j = k[sel], j[sel]
    dc = c[:, j] - c[:, k]
    dt = theta[j] - theta[k]
    A = np.zeros((n, d, d))
    b = np.zeros((n, d))
    for a in range(d):
        b[:, a] = np.bincount(k, dc[a] * dt, minlength=n)
        for e in range(d):
            A[:, a, e] = np.bincount(k, dc[a] * dc[e], minlength=n)
    scale = np.trace(A, axis1=1, axis2=2)
    good = np.abs(np.linalg.det(A)) > 1e-8 * np.maximum(scale, 1e-300) ** d
    g = np.zeros((n, d))
    g[good] = np.linalg.solve(A[good], b[good][..., None])[..., 0]
    # the range of the family's values bounds the moved value (a slope
    # limiter: no new extremum where the field is not linear)
    lo, hi = theta.copy(), theta.copy()
    np.minimum.at(lo, k, theta[j])
    np.maximum.at(hi, k, theta[j])
    return c, g.T, (lo, hi)


def theta_at(basis, x, theta, field):
    """The dilatation per particle for the families of ``basis`` at the
    positions ``x``: ``theta`` moved along the ``field`` of
    :func:`dilatation_field` to the new families' centroids, within the
    range of the old family's values (unchanged where either centroid is
    missing)."""
    centroids, gradients, (lo, hi) = field
    c = family_centroids(basis, x)
    shift = np.einsum("ap,ap->p", gradients, c - centroids)
    moved = np.clip(theta + shift, lo, hi)
    return np.where(np.isfinite(shift), moved, theta)


class _FluidHistory(History):
    """The viscous history of :class:`UpdatedLagrangeFluid`, which a
    checkpoint cannot hold: the rebuilt cells, dilatations and masses of
    the model are not saved, so saving and restoring refuse by name."""

    def save(self):
        raise NotImplementedError(
            "checkpoints of an UpdatedLagrangeFluid run are not built (its "
            "rebuilt cells, dilatations and masses are not saved): run it "
            "without checkpoint= / resume=")

    restore = save


class UpdatedLagrangeFluid(MeanDilatation):
    """A :class:`~skfem_pg.materials.NewtonianFluid` of density ``rho``
    on PBG UnlP0 (``basis``: a :class:`~skfem_pg.FamilyBasis` collocated
    from a mesh's vertices, with ``vc_solver="local"``), its families
    rebuilt on the alpha shape (``alpha``) of the current positions when
    its cells wear out (``quality``) or a family distorts
    (``distortion``) (module docstring).  Run it with
    :func:`skfem_pg.newmark` and ``gravity=``, or with
    :func:`~skfem_pg.solvers.free_surface_flow`, which merges particles
    that crowd.

    ``theta`` (:math:`\\rho_0/\\rho`), ``spacing`` (default
    :math:`V^{1/d}`) and ``masses`` (default :math:`\\rho_0 V/\\Theta`)
    per particle: the state a run goes on from.  ``model.basis`` stays the
    first basis (dofs, Dirichlet boundaries); ``model.current`` is that of
    the last rebuild, ``model.rebuilds`` counts them, ``model.free`` lists
    the free particles and :meth:`mass` gives the current lumped mass.

    Examples
    --------
    >>> import skfem as fem, skfem_pg as pg
    >>> from skfem_pg.materials import NewtonianFluid
    >>> mesh = fem.MeshTri().refined(2)
    >>> basis = pg.FamilyBasis.from_name(mesh, "VCBCPBG V5m UnlP0", dim=2,
    ...                                  vc_solver="local")
    >>> model = UpdatedLagrangeFluid(basis, NewtonianFluid(K=2e9, eta=1e-3),
    ...                              rho=1e3)
    >>> model.N == basis.N, model.rebuilds, float(model.mass().sum())
    (True, 0, 2000.0)

    """

    def __init__(self, basis, material, rho, alpha=1.2, distortion=0.1,
                 quality=0.3, theta=None, spacing=None, masses=None):
        if not isinstance(basis, FamilyBasis):
            raise ValueError("UpdatedLagrangeFluid is built for PBG family "
                             "bases, got {}".format(type(basis).__name__))
        p = basis.particles
        if p.dim != 2:
            raise NotImplementedError(
                "UpdatedLagrangeFluid is built and measured in 2-D: on "
                "tetrahedra the Delaunay triangulation of a grid has "
                "slivers, and a column of water at rest reached 0.68 "
                "sqrt(gH) in 0.05 s (4^3 cells)")
        if p.kind != "vertices" or p.mesh is None:
            raise ValueError("UpdatedLagrangeFluid triangulates the "
                             "particles again: they must come from "
                             "Particles.from_mesh (vertices)")
        if getattr(material, "mu", None) != 0.0 or not hasattr(
                material, "bind_rate"):
            raise ValueError(
                "UpdatedLagrangeFluid restarts the reference at each "
                "rebuild, keeping only the density: it carries a fluid "
                "(NewtonianFluid), not {!r}, whose shear strain it would "
                "lose".format(material))
        mu, K = compressible_moduli(material, "UpdatedLagrangeFluid")
        super().__init__(basis, mu, K, order=0)
        self.material = _FluidHistory(material.isochoric(),
                                      lambda: self.point_basis)
        if not (np.isfinite(rho) and rho > 0):
            raise ValueError("UpdatedLagrangeFluid: the density rho must be "
                             "a positive number, got {!r}".format(rho))
        self.rho = float(rho)
        if not (np.isfinite(alpha) and alpha > 0):
            raise ValueError("alpha must be a positive number, got {!r}"
                             .format(alpha))
        if not (np.isfinite(distortion) and 0 < distortion < 1):
            raise ValueError("distortion must lie in (0, 1), got {!r}"
                             .format(distortion))
        if not (np.isfinite(quality) and 0 < quality < 1):
            raise ValueError("quality (a radius ratio) must lie in (0, 1), "
                             "got {!r}".format(quality))
        self.alpha, self.distortion = float(alpha), float(distortion)
        self.quality = float(quality)
        self.spacing = (p.volumes ** (1.0 / p.dim) if spacing is None
                        else _per_particle(spacing, p.n, "spacing"))
        if not np.all(self.spacing > 0):
            i = int(np.flatnonzero(~(self.spacing > 0))[0])
            raise ValueError("UpdatedLagrangeFluid: particle {} has no "
                             "spacing (no volume): give spacing=".format(i))
        self.current = basis
        self.u_c = np.zeros(basis.N)
        self._cells = None  # the kept cells of the last rebuild
        # per particle, at the last rebuild
        self.theta = (np.ones(p.n) if theta is None
                      else _per_particle(theta, p.n, "theta"))
        if not np.all(self.theta > 0):
            raise ValueError("theta (rho_0 / rho per particle) must be "
                             "positive")
        self.free = np.zeros(0, dtype=int)
        self.rebuilds = 0
        self._start_from(basis)
        on = p.volumes > 0
        if masses is None:
            if not on.all():
                raise ValueError("UpdatedLagrangeFluid: particle {} has no "
                                 "volume: give the particles' masses".format(
                                     int(np.flatnonzero(~on)[0])))
            masses = self.rho * p.volumes / self.theta
        masses = _per_particle(masses, p.n, "masses")
        if not np.all(masses > 0):
            raise ValueError("masses must be positive")
        self.total_mass = float(masses.sum())
        self._m = self._consistent_mass(basis, masses)

    @property
    def point_basis(self):
        """The basis of the last rebuild: its points carry the history."""
        return self.current

    # -- the frame -----------------------------------------------------
    def _scale(self, power):
        """:math:`J_c^{power}` at the points (1 before the first
        rebuild)."""
        return 1.0 if self._Jc_points is None else self._Jc_points ** power

    def deformation_gradient(self, u):
        u = np.asarray(u, dtype=float)[:self.n_u]
        dF = self.current.interpolate(u - self.u_c, flat=True).grad \
            + self._eye
        return dF * self._scale(1.0 / self._dim)

    def rate_gradient(self, w):
        r""":math:`\nabla_X w = \nabla_c w\, F_c`."""
        w = np.asarray(w, dtype=float)[:self.n_u]
        return self.current.interpolate(w, flat=True).grad * self._scale(
            1.0 / self._dim)

    @property
    def _dim(self):
        return self.basis.particles.dim

    def energy(self, state):
        w = self.current.flat_weights() * self._scale(-1.0)
        Th = state["Theta"]
        U = 0.25 * self.K * (Th ** 2 - 1 - 2 * np.log(Th))
        return float(np.sum(w * (self.material.energy(state["F"]) + U)))

    @kernel
    def internal_force(self, state):
        P = self.stress(state) * self._scale(1.0 / self._dim - 1.0)
        return assemble(internal_force, self.current, P=P)

    # -- re-neighbouring -----------------------------------------------
    def commit(self, state):
        """Commit the step; rebuild on the alpha shape of the current
        positions when the cells wore out or a family distorted (module
        docstring).  Returns whether it rebuilt (the driver then takes the
        new mass and evaluates the force of the new basis)."""
        super().commit(state)
        u = np.asarray(state["u"], dtype=float)[:self.n_u]
        x = self.basis.particles.x + u.reshape(-1, self._dim).T
        dJ = state["J"] * self._scale(-1.0)  # det(Delta F)
        if self._cells is not None and np.abs(dJ - 1.0).max() <= \
                self.distortion and self._cells_hold(x):
            return False
        mesh, kept = alpha_shape(x, self.spacing, self.alpha)
        self.rebuild(mesh, kept, u, state["c_Theta"][:, 0])
        return True

    def _cells_hold(self, x):
        """Whether the cells of the last rebuild, at the positions ``x``,
        are still in the alpha shape and not worn out (module
        docstring)."""
        t = self._cells
        h = self.spacing[t].mean(axis=0)
        # the mesh's cells have either orientation (scikit-fem sorts them)
        q = radius_ratios(x, t) * np.sign(self._q0)
        worn = q < np.minimum(self.quality * np.abs(self._q0), 0.1)
        return not (np.any(worn) or np.any(circumradii(x, t)
                                           >= self.alpha * h))

    def rebuild(self, mesh, kept, u, Theta):
        """The basis on the cells ``kept`` of ``mesh`` (the particles at
        ``X + u``), each new family starting from its particle's
        dilatation (``Theta``: per family of the current basis); the
        particles in no kept cell fly free."""
        d = self._dim
        self.theta[np.asarray(self.current.families.masters)] = Theta
        field = dilatation_field(self.current, mesh.p, self.theta)
        self.free = free_particles(mesh, kept)
        new = FamilyBasis(collocate(mesh, kept), **self.basis.options)
        self.theta = theta_at(new, mesh.p, self.theta, field)
        self._start_from(new)
        self._m = self._consistent_mass(new, self._m)
        self.u_c = np.array(u, dtype=float)
        self._cells = np.array(mesh.t[:, kept])
        self._q0 = radius_ratios(mesh.p, self._cells)
        h = self.history
        h.committed = {"alpha": np.zeros(self._Jc_points.shape),
                       "F": self._eye * self._scale(1.0 / d)}
        h._last = h._mean = None
        self.rebuilds += 1
        return new

    def mass(self):
        """The lumped mass per displacement dof of the current basis
        (module docstring): :math:`\\rho_0 V^k/\\Theta_k`, scaled to the
        particles' total mass (a free particle keeps its own)."""
        return np.repeat(self._m, self._dim)

    def _consistent_mass(self, basis, previous):
        """Per particle: the mass of its current volume and density, the
        connected particles scaled so that the total is kept."""
        V = basis.particles.volumes
        on = V > 0
        m = np.array(previous, dtype=float)
        m[on] = self.rho * V[on] / self.theta[on]
        m[on] *= (self.total_mass - m[~on].sum()) / m[on].sum()
        return m

    def _start_from(self, basis):
        """Make ``basis`` the current one, its families starting from
        their particles' dilatation ``theta``."""
        E = Elements(basis)
        self.current, self.elements = basis, E
        self.Phi = E.polynomials(self.order)
        self._Minv = np.linalg.inv(E.gram(self.Phi))
        self.J_c = self.theta[np.asarray(basis.families.masters)]
        self._Jc_points = (None if np.all(self.J_c == 1.0)
                           else E.spread(self.J_c))

    def state(self, u):
        s = super().state(u)
        s["u"] = u
        return s
