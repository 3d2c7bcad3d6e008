r"""Bond-based peridynamics with critical-stretch bond breaking: the
prototype microelastic brittle (PMB) material of Silling & Askari (2005),
the model every peridynamic code ships — here as a comparator on the same
particles and the same explicit driver as the PG formulations.

Every pair of particles closer than the horizon :math:`\delta` is a bond
:math:`\xi = X_j - X_i`; with :math:`y = \xi + u_j - u_i` its stretch is
:math:`s = |y|/|\xi| - 1` and its energy :math:`\frac c2 s^2 |\xi| V_i
V_j`, so that the internal force is

.. math:: f_i = -\sum_j \mu_{ij}\, c\, s_{ij} V_i V_j \frac{y_{ij}}
          {|y_{ij}|}, \qquad
          \mu_{ij} = \begin{cases} 1 & s_{ij} < s_0 \text{ at every
          step so far} \\ 0 & \text{else (broken for good)}\end{cases}

(no Python loop: the bonds are arrays and forces are summed with
``bincount``).  Bonds break when a step is committed.  The micromodulus
:math:`c` and the critical stretch :math:`s_0` follow from Young's modulus
and the fracture energy :math:`G_0` by matching the strain energy density
and the energy to break all bonds across a crack (Silling & Askari 2005 in
3-D; Ha & Bobaru 2010 in 2-D, per unit thickness):

=============  ===============================  ===============================
               :math:`c`                        :math:`s_0`
=============  ===============================  ===============================
3-D            :math:`18K/(\pi\delta^4)`,        :math:`\sqrt{5G_0/(9K\delta)}`
               :math:`K = E/(3(1-2\nu))`
plane strain   :math:`48E/(5\pi\delta^3)`       :math:`\sqrt{5\pi G_0/(12E\delta)}`
plane stress   :math:`9E/(\pi\delta^3)`         :math:`\sqrt{4\pi G_0/(9E\delta)}`
=============  ===============================  ===============================

A bond-based material has a fixed Poisson ratio: :math:`\nu = 1/4` in 3-D
and plane strain, :math:`1/3` in plane stress.  Near a free surface a
particle has fewer bonds and is softer (the *surface effect*; no
correction here), which is what the peer codes do by default as well.
"""
import contextlib
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

#: the Poisson ratio a bond-based material has
POISSON = {"3d": 0.25, "strain": 0.25, "stress": 1.0 / 3.0}


def bonds_within(x, horizon):
    """The pairs ``(i, j)``, ``i < j``, of points ``x`` ``(d, n)`` closer
    than ``horizon`` (a number or one per point: the pair's larger one)."""
    h = np.broadcast_to(np.asarray(horizon, float), (x.shape[1],))
    tree = cKDTree(x.T)
    pairs = tree.query_pairs(float(h.max()), output_type="ndarray")
    if pairs.size == 0:
        return np.zeros((0, 2), dtype=np.int64)
    r = np.linalg.norm(x[:, pairs[:, 1]] - x[:, pairs[:, 0]], axis=0)
    return pairs[r < np.maximum(h[pairs[:, 0]], h[pairs[:, 1]])]


@dataclass(frozen=True)
class PMBMaterial:
    """The parameters of a :class:`BondBased` model (what a checkpoint's
    fingerprint compares): Young's modulus, fracture energy, horizon (a
    length), the 2-D assumption (``"3d"``, ``"strain"``, ``"stress"``)."""
    E: float
    G0: float | None
    horizon: float
    plane: str


class BondState:
    """The committed state of a :class:`BondBased` model — which bonds
    are intact, and the energy the broken ones took — with the interface
    the checkpoints and the explicit driver use of a history
    (:class:`~skfem_pg.formulations.history.History`)."""

    stateful = True

    def __init__(self, n_bonds, dim):
        self.committed = self.virgin(n_bonds, dim)

    @staticmethod
    def virgin(n_bonds, dim):
        """All bonds intact, nothing released, no bond broken in the last
        step (``last_force``, ``last_y``: the force and the deformed
        vector of the bonds that broke at the last commit, zero
        elsewhere)."""
        return {"intact": np.ones(n_bonds), "broken_energy": np.zeros(()),
                "last_force": np.zeros((dim, n_bonds)),
                "last_y": np.zeros((dim, n_bonds))}

    @property
    def intact(self):
        return self.committed["intact"] > 0.5

    def save(self):
        return {k: np.array(v) for k, v in self.committed.items()}

    def restore(self, saved):
        virgin = self.virgin(*self.committed["last_y"].shape[::-1])
        # a checkpoint of an older version has no last-step arrays
        self.committed = {k: np.array(v, dtype=float) for k, v in {
            **virgin, **(saved or {})}.items()}

    def elastic_predictor(self):
        """Bonds have no plastic part: the model as it is."""
        return contextlib.nullcontext(self)


def segment_cut(a, b):
    """A 2-D pre-crack along the segment from ``a`` to ``b``: the ``cut``
    of :class:`BondBased` that is true for the bonds whose segment crosses
    it (strictly: a bond ending on the line is not cut)."""
    a, b = np.asarray(a, float), np.asarray(b, float)

    def cross(u, v):
        return u[0] * v[1] - u[1] * v[0]

    def cut(Xi, Xj):
        r, s = (b - a)[:, None], Xj - Xi
        denom = cross(r, s)
        q = Xi - a[:, None]
        with np.errstate(divide="ignore", invalid="ignore"):
            t, w = cross(q, s) / denom, cross(q, r) / denom
        return (denom != 0) & (t >= 0) & (t <= 1) & (w > 0) & (w < 1)
    return cut


def _horizon(p, horizon, absolute):
    """The horizon length of the particles ``p``: ``horizon`` itself
    (``absolute``) or times the median particle spacing, checked."""
    spacing = float(np.median(p.volumes ** (1.0 / p.dim)))
    try:
        delta = float(horizon) * (1.0 if absolute else spacing)
    except (TypeError, ValueError):
        raise ValueError("BondBased: the horizon must be a number, got "
                         "{!r}".format(horizon)) from None
    if not (np.isfinite(delta) and delta > 0):
        raise ValueError("BondBased: the horizon must be a positive "
                         "finite {}, got {!r}".format(
                             "length" if absolute else
                             "multiple of the particle spacing", horizon))
    size = float(np.linalg.norm(np.ptp(p.x, axis=1)))
    if delta >= size:
        raise ValueError(
            "BondBased: the horizon {:g} spans the whole body (its "
            "diameter is {:g}): every particle bonds with every other "
            "and the micromodulus (~1/horizon^{}) vanishes; give a "
            "horizon of a few particle spacings (the spacing is {:g}; "
            "the default is 3 spacings)".format(delta, size, p.dim + 1,
                                                spacing))
    return delta


def _micromodulus(key, E, nu, delta, G0):
    """``(c, s0)``: the PMB micromodulus and critical stretch (``None``
    without a fracture energy ``G0``) in 3-D, plane strain or stress."""
    if key == "3d":
        K = E / (3 * (1 - 2 * nu))
        return 18 * K / (np.pi * delta ** 4), None if G0 is None else \
            np.sqrt(5 * G0 / (9 * K * delta))
    if key == "strain":
        return 48 * E / (5 * np.pi * delta ** 3), None if G0 is None else \
            np.sqrt(5 * np.pi * G0 / (12 * E * delta))
    return 9 * E / (np.pi * delta ** 3), None if G0 is None else \
        np.sqrt(4 * np.pi * G0 / (9 * E * delta))


class BondBased:
    r"""The PMB bond-based model (module docstring) on the particles of a
    :class:`~skfem_pg.FamilyBasis` (its dof numbering, volumes and
    boundaries; not its families).

    Parameters
    ----------
    basis
        A vector :class:`~skfem_pg.FamilyBasis` (``dim=2`` or 3): the
        particles and the displacement numbering the drivers use.
    E
        Young's modulus.
    G0
        Fracture energy (energy per crack area); ``None``: bonds never
        break.
    horizon
        :math:`\delta` as a multiple of the particle spacing
        :math:`V^{1/d}` (the median over the particles; default 3, the
        peer codes' common choice), or ``absolute=True`` for a length.
    plane
        In 2-D: ``"strain"`` (default) or ``"stress"``.
    absolute
        ``horizon`` is a length, not a multiple of the spacing.
    cut
        Pre-cracks: bonds for which ``cut(X_i, X_j)`` (two ``(d, nb)``
        arrays of bond ends, returning ``nb`` booleans) is true are
        broken from the start, e.g. :func:`segment_cut` for a notch in
        2-D.

    Examples
    --------
    >>> import numpy as np, skfem as fem, skfem_pg as pg
    >>> basis = pg.FamilyBasis(fem.MeshQuad().refined(3), dim=2)
    >>> model = BondBased(basis, E=1000.0)
    >>> state = model.state(np.zeros(model.N))
    >>> float(np.abs(model.internal_force(state)).max())
    0.0

    """

    name = "PMB"
    fields_names = ()

    def __init__(self, basis, E, G0=None, horizon=3.0, plane="strain",
                 absolute=False, cut=None):
        p = basis.particles
        self.basis, self.dim = basis, p.dim
        if basis.N != p.n * p.dim:
            raise ValueError("BondBased needs a vector basis (dim={}) on its "
                             "particles: {} dofs for {} particles".format(
                                 p.dim, basis.N, p.n))
        E = float(E)
        if not (np.isfinite(E) and E > 0):
            raise ValueError("BondBased: Young's modulus E must be positive, "
                             "got {}".format(E))
        key = "3d" if p.dim == 3 else plane
        if key not in POISSON:
            raise ValueError("BondBased: plane must be 'strain' or 'stress', "
                             "got {!r}".format(plane))
        self.plane, self.nu = key, POISSON[key]
        empty = np.flatnonzero(~(p.volumes > 0))
        if len(empty):
            raise ValueError(
                "BondBased: {} of {} particles have no volume (first: "
                "particle {} at {}) — particles outside the elements they "
                "were collocated from carry neither mass nor bonds; "
                "collocate from the part itself (mesh.restrict(elements))"
                .format(len(empty), p.n, empty[0],
                        np.round(p.x[:, empty[0]], 12).tolist()))
        delta = _horizon(p, horizon, absolute)
        self.horizon = delta
        self.E, self.G0 = E, None if G0 is None else float(G0)
        if self.G0 is not None and not self.G0 > 0:
            raise ValueError("BondBased: the fracture energy G0 must be "
                             "positive, got {}".format(G0))
        self.c, s0 = _micromodulus(key, E, self.nu, delta, self.G0)
        self.s0 = np.inf if s0 is None else float(s0)
        self.x0 = p.x
        self.bonds = bonds_within(p.x, delta)
        if self.bonds.shape[0] == 0:
            raise ValueError("BondBased: no two particles closer than the "
                             "horizon {:g}".format(delta))
        i, j = self.bonds.T
        self.xi = p.x[:, j] - p.x[:, i]  # (d, nb)
        self.length = np.linalg.norm(self.xi, axis=0)
        self.VV = p.volumes[i] * p.volumes[j]
        self.history = BondState(self.bonds.shape[0], self.dim)
        if cut is not None:
            across = np.asarray(cut(p.x[:, i], p.x[:, j]), dtype=bool)
            if across.shape != i.shape:
                raise ValueError("BondBased: cut(X_i, X_j) must return one "
                                 "boolean per bond ({}), got shape {}"
                                 .format(i.size, across.shape))
            self.history.committed["intact"][across] = 0.0
        self.material = PMBMaterial(E, self.G0, delta, key)
        self.n_u = self.N = basis.N

    @property
    def intact(self):
        """``True`` for the bonds not broken (committed)."""
        return self.history.intact

    @property
    def broken_energy(self):
        """The stored energy the broken bonds had when they broke (what
        they dissipated), summed."""
        return float(self.history.committed["broken_energy"])

    def __repr__(self):
        return ("BondBased(E={:g}, G0={}, horizon={:g}, {} bonds, {} broken)"
                .format(self.E, self.G0, self.horizon, self.bonds.shape[0],
                        int((~self.intact).sum())))

    # -- the model protocol ----------------------------------------------
    def initial(self):
        return np.zeros(self.N)

    def state(self, x):
        d = self.dim
        U = np.asarray(x, dtype=float)[:self.n_u].reshape(-1, d).T
        i, j = self.bonds.T
        y = self.xi + U[:, j] - U[:, i]
        r = np.linalg.norm(y, axis=0)
        return {"u": x, "y": y, "r": r, "s": r / self.length - 1.0}

    def internal_force(self, state):
        """:math:`f_{int} = \\partial\\Pi/\\partial u` (module docstring)."""
        e = state["y"] / state["r"]
        t = np.where(self.intact, self.c * state["s"] * self.VV, 0.0) * e
        i, j = self.bonds.T
        n = self.x0.shape[1]
        f = np.zeros((n, self.dim))
        for a in range(self.dim):
            f[:, a] = (np.bincount(j, weights=t[a], minlength=n)
                       - np.bincount(i, weights=t[a], minlength=n))
        return f.ravel()

    def tangent(self, state):
        r""":math:`\partial f_{int}/\partial u`: per intact bond
        :math:`k = cV_iV_j[e\otimes e/|\xi| + s/|y|\,(I - e\otimes e)]`
        between the two particles (what the stable step is estimated
        from)."""
        d = self.dim
        e = state["y"] / state["r"]
        w = np.where(self.intact, self.c * self.VV, 0.0)
        ee = e[:, None, :] * e[None, :, :]  # (d, d, nb)
        k = w * (ee / self.length + state["s"] / state["r"]
                 * (np.eye(d)[:, :, None] - ee))
        i, j = self.bonds.T
        rows, cols, vals = [], [], []
        for a in range(d):
            for b in range(d):
                for (p, q, sign) in ((i, i, 1), (j, j, 1), (i, j, -1),
                                     (j, i, -1)):
                    rows.append(d * p + a)
                    cols.append(d * q + b)
                    vals.append(sign * k[a, b])
        return sp.coo_matrix((np.concatenate(vals), (np.concatenate(rows),
                             np.concatenate(cols))),
                             shape=(self.N, self.N)).tocsr()

    def energy(self, state):
        """The stored energy of the intact bonds."""
        return float(np.sum(np.where(self.intact, 0.5 * self.c
                                     * state["s"] ** 2 * self.length
                                     * self.VV, 0.0)))

    def min_J(self, state):
        """A bond model has no deformation gradient: 1.0 (a driver's
        inversion check never cuts its steps)."""
        return 1.0

    def commit(self, state):
        r"""Break, for good, the bonds stretched beyond :math:`s_0`; their
        stored energy is added to :attr:`broken_energy` (what the broken
        bonds dissipated).

        A bond that breaks at this commit still pulled with its force at
        this state, which the drivers' internal force of the step holds
        (the bond-based convention: it is gone from the next evaluation
        on), so the trapezoid of the next step books half of its work
        over that step; the next commit adds that half,
        :math:`\tfrac12 t\cdot\Delta y`, to :attr:`broken_energy`, which
        then equals the work the integrator booked on the bond (a broken
        bond stores nothing): exact where the trapezoid is."""
        c = self.history.committed
        last = np.flatnonzero(np.any(c["last_force"] != 0, axis=0))
        if last.size:  # the bonds of the last commit: their last half step
            dy = state["y"][:, last] - c["last_y"][:, last]
            c["broken_energy"] = c["broken_energy"] + 0.5 * np.sum(
                c["last_force"][:, last] * dy)
            c["last_force"][:, last] = 0.0
            c["last_y"][:, last] = 0.0
        breaking = np.flatnonzero(self.intact & (state["s"] > self.s0))
        if breaking.size:
            s = state["s"][breaking]
            c["broken_energy"] = c["broken_energy"] + np.sum(
                0.5 * self.c * s ** 2 * self.length[breaking]
                * self.VV[breaking])
            y = state["y"][:, breaking]
            c["last_force"][:, breaking] = (self.c * s * self.VV[breaking]
                                            / np.linalg.norm(y, axis=0) * y)
            c["last_y"][:, breaking] = y
            c["intact"][breaking] = 0.0

    def fields(self, x):
        return {}

    def fracture_energy(self):
        """What the broken bonds stored when they broke
        (:attr:`broken_energy`)."""
        return self.broken_energy

    # -- results -------------------------------------------------------
    def damage(self):
        r"""Per particle :math:`\varphi_i = 1 - \sum_j \mu_{ij}V_j /
        \sum_j V_j` over its bonds (0 intact, 1 all bonds broken)."""
        i, j = self.bonds.T
        p = self.basis.particles
        n = p.n
        Vj = np.concatenate([p.volumes[j], p.volumes[i]])
        who = np.concatenate([i, j])
        alive = np.concatenate([self.intact, self.intact])
        total = np.bincount(who, weights=Vj, minlength=n)
        kept = np.bincount(who, weights=Vj * alive, minlength=n)
        return 1.0 - kept / np.where(total > 0, total, 1.0)
