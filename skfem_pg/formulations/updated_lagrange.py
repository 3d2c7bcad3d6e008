r"""The updated Lagrangian frame (thesis 7.2.4, (2.18)) of the displacement
formulation.

In the total Lagrangian frame (TL) families, shape-function derivatives and
the bond and VC corrections are computed once, in the reference
configuration.  In the updated frame they are rebuilt in the current
configuration every ``every`` converged steps (``every = 1``: every step,
as the thesis' test): the particles move to :math:`x_c = X + u_c`, the
family rule of the basis (mesh neighbours, or the horizon search of WTE2)
is applied there, and the derivatives :math:`G_c` and corrections are
recomputed with the same options.  Between updates

.. math::

    \Delta F = I + \sum_i (u^i - u_c^i) \otimes G_c^{kji},\qquad
    F = \Delta F\, F_c \quad (2.18),

:math:`F_c` the committed deformation gradient at the update, per
integration point.  The internal force is the TL one written on the
current basis, :math:`\sum w_c\, P_c : \nabla_{x_c} \delta u` with
:math:`P_c = P(F)\, F_c^T / J_c` (:math:`J_c = \det F_c`), which equals
:math:`\sum w_0\, P : \nabla_X \delta u` when the current weights are
:math:`J_c w_0`; the tangent is :math:`\mathbb A_{iMkN} F_{c,JM} F_{c,LN} /
J_c`.

Volumes and surface area vectors [not specified by the thesis; chosen
here]: the collocation mesh moves with the particles, and the current
particles are collocated from it (:meth:`Particles.from_mesh
<skfem_pg.Particles.from_mesh>`): volumes are the deformed cells' volumes
lumped to their vertices, area vectors those of the deformed boundary
facets — exact for the deformed cells, and identical to TL's at zero
displacement.

History: the committed :math:`F` and the internal variables of a plastic
material live at the integration points :math:`(k, j)`.  When the rebuilt
families keep their members (mesh families always do) they carry over
unchanged; a new pair :math:`(k, j)` takes the master's :math:`(k, k)`
values [interpretation; kNN families re-neighbour, and the member's
:math:`(j, j)`, which crack-aware families take, moved the results by
2e-4 to 3e-4: ``benchmarks/README.md``].
"""
import numpy as np

from ..discretization.assembly import assemble
from ..discretization.basis import FamilyBasis
from ..discretization.particles import Particles
from ..threads import kernel
from ..materials.hyperelastic import det
from .displacement import Hyperelastic, internal_force, material_tangent


def point_keys(basis):
    """``k * n + j`` for each flat point (master particle ``k`` of its
    family, member particle ``j``): the same pair has the same key in
    every basis on the particles, whichever particles master no family."""
    fam = basis.families
    k = np.repeat(np.asarray(fam.masters), np.diff(fam.offsets))
    return k * basis.particles.n + np.asarray(fam.members)


def remap_points(old, new, arrays, donor="master"):
    """Point arrays (last axis flat over the points of ``old``) on the
    points of ``new``: the same (family, member) pair where it exists,
    else the family's master (``donor="master"``: the family's state) or
    the member's own master, the point at the same particle
    (``donor="member"``: the material's state there; the family's master
    where the member has no family)."""
    if donor not in ("master", "member"):
        raise ValueError("donor must be 'master' or 'member', got {!r}"
                         .format(donor))
    ko, kn = point_keys(old), point_keys(new)
    if ko.shape == kn.shape and np.array_equal(ko, kn):
        return arrays
    n = new.particles.n
    order = np.argsort(ko)
    sk = ko[order]

    def find(keys):
        pos = np.minimum(np.searchsorted(sk, keys), len(ko) - 1)
        return order[pos], sk[pos] == keys

    src, hit = find(kn)
    k, j = kn // n, kn % n
    at_master, _ = find(k * n + k)
    if donor == "member":
        at_member, has = find(j * n + j)
        at_master = np.where(has, at_member, at_master)
    src = np.where(hit, src, at_master)
    return [a[..., src] for a in arrays]


def carry_points(history, old, new, F, donor="master"):
    """Carry the point data of basis ``old`` to the points of ``new``
    (:func:`remap_points`, a new point's from ``donor``): the committed
    arrays of ``history`` (a :class:`~skfem_pg.formulations.history.
    History` or ``None``), in place, and the deformation gradients ``F``
    ``(d, d, 1, N_q)``, whose remapped copy is returned."""
    d = F.shape[0]
    c = None if history is None else history.committed
    names = sorted(c) if c is not None else []
    arrays = remap_points(old, new, [np.asarray(F).reshape(d * d, -1)] + [
        c[k].reshape(-1, c[k].shape[-1]) for k in names], donor=donor)
    if c is not None:
        history.committed = {k: a.reshape(c[k].shape[:-1] + (-1,))
                             for k, a in zip(names, arrays[1:])}
        history._last = None
    return arrays[0].reshape(d, d, 1, -1)


class UpdatedLagrange(Hyperelastic):
    """The displacement formulation on ``basis`` (a PBG
    :class:`~skfem_pg.FamilyBasis` collocated from a mesh's vertices) in
    the updated Lagrangian frame, rebuilt every ``every`` converged steps
    (module docstring).

    ``model.basis`` stays the reference basis (dofs, loads, Dirichlet
    boundaries: the particle numbering does not change);
    ``model.current`` is the basis of the last update.

    Examples
    --------
    >>> import numpy as np, skfem as fem, skfem_pg as pg
    >>> basis = pg.FamilyBasis(fem.MeshQuad().refined(2), dim=2)
    >>> from skfem_pg.materials import NeoHooke
    >>> model = UpdatedLagrange(basis, NeoHooke(lam=60.0, mu=40.0), every=2)
    >>> model.N == basis.N, model.every
    (True, 2)

    """

    def __init__(self, basis, material, every=1):
        if not isinstance(basis, FamilyBasis):
            raise ValueError("the updated Lagrangian frame is built for PBG "
                             "family bases, got {}".format(
                                 type(basis).__name__))
        basis.spec.require("updated_lagrangian")  # PBG at the members
        p = basis.particles
        if p.kind != "vertices" or p.mesh is None:
            raise ValueError("UL moves the collocation mesh with the "
                             "particles (volumes, area vectors): the "
                             "particles must come from Particles.from_mesh")
        if int(every) < 1:
            raise ValueError("every must be >= 1, got {}".format(every))
        super().__init__(basis, material)
        self.every = int(every)
        self.current = basis
        self.u_c = np.zeros(basis.N)
        self.F_c = None  # identity until the first update
        self.J_c = None
        self.updates = 0
        self._commits = 0

    # -- the update ----------------------------------------------------
    def rebuild(self, u, F=None):
        """Rebuild the basis at the configuration ``X + u`` with ``F``
        (flat points of the current basis; default: the deformation
        gradient at ``u``) becoming :math:`F_c`; the committed history
        follows the points."""
        p0 = self.basis.particles
        mesh = p0.mesh
        d = p0.dim
        x = mesh.p + np.asarray(u[:self.n_u], float).reshape(-1, d).T
        moved = type(mesh)(x, mesh.t)
        particles = Particles.from_mesh(moved, elements=p0.elements)
        new = FamilyBasis(particles, **self.basis.options)
        F = self.state(u)["F"] if F is None else F
        Fn = carry_points(self.history, self.current, new, F)
        self.F_c, self.J_c = Fn, det(Fn)
        self.current = new
        self.u_c = np.array(u[:self.n_u], dtype=float)
        self.updates += 1
        return new

    def commit(self, state):
        """Commit the step (history, :math:`F`) and rebuild every
        ``every`` commits."""
        super().commit(state)
        self._commits += 1
        if self._commits % self.every == 0:
            self.rebuild(state["u"], np.array(state["F"]))

    # -- the model -----------------------------------------------------
    @kernel
    def state(self, u):
        dF = self.current.interpolate(u[:self.n_u] - self.u_c,
                                      flat=True).grad + self._eye
        F = dF if self.F_c is None else np.einsum("ikpq,kjpq->ijpq", dF,
                                                  self.F_c)
        return {"F": F, "dF": dF, "u": u}

    def rate_gradient(self, w):
        r""":math:`\nabla_X w = \nabla_c w\, F_c` at the current points
        (:meth:`Hyperelastic.rate_gradient`)."""
        g = super().rate_gradient(w)
        return g if self.F_c is None else np.einsum("ikpq,kjpq->ijpq", g,
                                                    self.F_c)

    def _to_current(self, P):
        if self.F_c is None:
            return P
        return np.einsum("iMpq,JMpq->iJpq", P, self.F_c) / self.J_c

    def energy(self, state):
        w = self.current.flat_weights()
        W = self.material.energy(state["F"])
        return float(np.sum(w * W / (1.0 if self.J_c is None
                                     else self.J_c)))

    @kernel
    def internal_force(self, state):
        return assemble(internal_force, self.current,
                        P=self._to_current(self.stress(state)))

    @kernel
    def tangent(self, state):
        A = self.material.tangent(state["F"])
        if self.F_c is not None:
            Fc = self.F_c
            A = np.einsum("iMkNpq,JMpq,LNpq->iJkLpq", A, Fc, Fc) / self.J_c
        return assemble(material_tangent, self.current, A=A)

    @property
    def point_basis(self):
        """The current basis: its points carry the history."""
        return self.current
