r"""Pressure and dilatation as polynomials per element, condensed: FE Q1P0 /
H1P0 (Simo–Taylor–Pister mean dilatation), PBG UnlP0 (thesis 6.2.1) and
U2P1 (6.2.2).

The iso/vol neo-Hooke (2.43) with the volumetric part on a dilatation
:math:`\Theta` and a pressure :math:`p` that are polynomials of degree
``order`` on each element — an FE element, or a family :math:`H^k` with the
PBG weights :math:`w_{kj} = V^kV^j/V_H^k` (4.30) as its quadrature; (6.3):

.. math::

    \Pi = \sum_e \sum_j w_{ej}\Big[W_{iso}(F^{ej}) + U(\Theta^{ej})
          + p^{ej}\big(J^{ej} - \Theta^{ej}\big)\Big],
    \qquad U(\Theta) = \tfrac K4(\Theta^2 - 1 - 2\ln\Theta),

with :math:`p^{ej} = \sum_a \Phi_a^{ej} p_a^e` (same for :math:`\Theta`):
order 0, :math:`\Phi = 1`, one p and one Θ per element — UnlP0 (6.9),
Q1P0, H1P0; order 1, :math:`\Phi = (1, (X^j - X_c^e)/h_e)`, linear p and Θ
per family — U2P1 (6.10), ``2(d + 1)`` local unknowns.  Stationarity in the
local unknowns is the static condensation (6.6) in closed form:

.. math::

    \Theta = \Pi_e J, \qquad p = \Pi_e U'(\Theta), \qquad
    \Pi_e = \Phi M_e^{-1}\Phi^T W_e,\quad M_e = \Phi^T W_e \Phi,

the weighted :math:`L^2` projection onto the element's polynomials (for
order 0 the mean :math:`\Theta_e = \sum_j w_{ej}J^{ej}/V_e`).  The residual
is :math:`\sum_j w_{ej}(P_{iso} + p^{ej} J F^{-T}) : \nabla\delta u` (the
volumetric force (6.8), :math:`P_{vol} = J p F^{-T}`) and the tangent

.. math::

    K = \sum_{ej} w_{ej}\,\nabla\delta u : (\mathbb A_{iso}
        + p^{ej}\partial_F(JF^{-T})) : \nabla du
        + \sum_e C_e^T M_e^{-1} (\Phi^T W_e U''(\Theta)\Phi) M_e^{-1} C_e,
    \qquad C_e = \Phi^T W_e (JF^{-T} : \nabla N),

a term of rank ``q`` (1 or d + 1) per element
(:class:`~skfem_pg.discretization.elementwise.Elements`, batched over size
groups).  PPG UnlP0 (the master evaluation :math:`\Theta^k = J^{kk}`) is
:mod:`.master_dilatation`.

With a damage law (:mod:`~skfem_pg.materials.damage`) the isochoric law
at the points takes :math:`\tau_m = J p` as its mean stress for the
triaxiality — under a homogeneous deformation the law's own
:math:`\tfrac K2(J^2 - 1)`, so the damage is the displacement
formulation's — and a failed point's no-tension rule acts on the
element [choice made here]: where :math:`\Theta \ge 1` the volumetric
energy is :math:`(1 - \phi_e)\,U(\Theta)`, :math:`\phi_e` the weighted
share of the element's points failed in the committed history (frozen
during a step; :math:`U'(1) = 0` keeps the pressure continuous at
:math:`\Theta = 1`); in compression the element keeps all of it.
"""
import numpy as np

from ..discretization.assembly import assemble
from ..discretization.elementwise import Elements
from ..materials import (J2Plasticity, NeoHookeIsoVol, NewtonianFluid,
                         check_moduli, inverse_and_det)
from ..threads import kernel
from .displacement import Hyperelastic, material_tangent
from .history import History


def d_JFinvT(J, Finv):
    r""":math:`\partial(JF^{-T})_{iJ}/\partial F_{kL} = J(F^{-T}_{iJ}
    F^{-T}_{kL} - F^{-1}_{Jk}F^{-1}_{Li})`."""
    FinvT = np.swapaxes(Finv, 0, 1)
    return J * (FinvT[:, :, None, None] * FinvT[None, None]
                - np.einsum("Jk...,Li...->iJkL...", Finv, Finv))


def compressible_moduli(material, formulation):
    """``(mu, K)`` of an iso/vol neo-Hooke material with a finite bulk
    modulus, which the condensed and nodal mixed formulations need;
    anything else raises naming ``formulation``."""
    if not isinstance(material, (NeoHookeIsoVol, J2Plasticity,
                                 NewtonianFluid)) \
            or not np.isfinite(material.K):
        raise ValueError("{} needs the iso/vol neo-Hooke material "
                         "(NeoHookeIsoVol), J2Plasticity or a "
                         "NewtonianFluid with a finite bulk modulus, got {!r}"
                         .format(formulation, material))
    return material.mu, material.K


class MeanDilatation(Hyperelastic):
    """Condensed polynomial pressure and dilatation per element (see the
    module docstring): ``order=0`` is Q1P0 / H1P0 on a scikit-fem vector
    basis and UnlP0 on a PBG :class:`~skfem_pg.FamilyBasis`; ``order=1`` on
    a WTE2 family basis is U2P1.  Iso/vol neo-Hooke with shear modulus
    ``mu`` and bulk modulus ``K``.

    ``fields(u)`` gives, per element (family), the pressure ``p`` and
    dilatation ``Theta`` at the centroid (order 1 also their gradients
    ``p_grad``, ``Theta_grad``, ``(n, d)``).

    Examples
    --------
    >>> import numpy as np, skfem as fem, skfem_pg as pg
    >>> basis = pg.FamilyBasis(fem.MeshQuad().refined(2), dim=2)
    >>> model = MeanDilatation(basis, mu=40.0, K=100.0)
    >>> state = model.state(np.zeros(model.N))
    >>> model.N == basis.N, float(np.abs(model.internal_force(state)).max())
    (True, 0.0)

    """

    def __init__(self, basis, mu, K, order=0):
        if getattr(basis, "is_petrov", False):
            raise NotImplementedError(
                "MeanDilatation integrates over the family (PBG); PPG UnlP0 "
                "(the dilatation at the master, Theta^k = J^kk) is "
                "MasterDilatation")
        super().__init__(basis, NeoHookeIsoVol.isochoric(mu))
        (self.K,) = check_moduli(K=K)
        self.order = int(order)
        E = self.elements = Elements(basis)
        self.Phi = E.polynomials(self.order)
        self._Minv = np.linalg.inv(E.gram(self.Phi))

    @classmethod
    def of(cls, basis, material, order=0):
        """From a :class:`~skfem_pg.materials.NeoHookeIsoVol`."""
        mu, K = compressible_moduli(
            material, "a mean-dilatation formulation (Q1P0, H1P0, UnlP0, "
            "U2P1)")
        return cls(basis, mu, K, order=order).with_material(material)

    def with_material(self, material):
        """Bind the isochoric part of ``material`` (the volumetric part is
        this formulation's); a damage law comes along: the points get the
        element pressure for their triaxiality, and the element's
        volumetric energy loses its failed share in tension (module
        docstring)."""
        if getattr(material, "stateful", False):
            self.material = History(material.isochoric(with_damage=True),
                                    lambda: self.point_basis)
        return self

    def tension_share(self):
        """Per element, the share of its points (by weight) that have not
        failed in the committed history, spread to the points; ``None``
        without a damage law."""
        h = self.history
        if h is None or getattr(h.material, "damage", None) is None:
            return None
        failed = h.failed()
        if failed is None:  # before the first evaluation: all intact
            return 1.0
        E = self.elements
        return E.spread(1.0 - E.sum(failed.astype(float)) / E.volumes)

    def project(self, a):
        """Coefficients ``(n, q)`` of the weighted L2 projection of point
        data ``a`` onto each element's polynomials."""
        rhs = np.moveaxis(self.elements.sum(self.Phi * a), 0, -1)
        return np.einsum("nab,nb->na", self._Minv, rhs)

    def evaluate(self, c):
        """Point values of per-element coefficients ``c`` ``(n, q)``."""
        return (self.Phi * self.elements.spread(c.T)).sum(axis=0)

    def pressure(self, Theta):
        """:math:`U'(\\Theta)`."""
        return 0.5 * self.K * (Theta - 1.0 / Theta)

    @kernel
    def state(self, u):
        s = super().state(u)
        Finv, J = inverse_and_det(s["F"])
        c_Theta = self.project(J)
        Theta = self.evaluate(c_Theta)
        share = self.tension_share()
        # failed points carry no tension: in expansion the element keeps
        # the volumetric energy of its intact share (U'(1) = 0: continuous)
        scale = 1.0 if share is None else np.where(Theta >= 1.0, share,
                                                    1.0)
        c_p = self.project(scale * self.pressure(Theta))
        s.update(Finv=Finv, J=J, Theta=Theta, c_Theta=c_Theta, c_p=c_p,
                 p=self.evaluate(c_p), scale=scale)
        if share is not None:  # the points' triaxiality: tau_m = J p
            self.history.bind_mean_stress(s["F"], s["J"] * s["p"])
        return s

    def min_J(self, state):
        return float(min(state["J"].min(), state["Theta"].min()))

    def energy(self, state):
        Th = state["Theta"]
        U = 0.25 * self.K * (Th ** 2 - 1 - 2 * np.log(Th)) * state["scale"]
        return super().energy(state) + float(np.sum(self.elements.sum(U)))

    def fields(self, x):
        s = self.state(x)
        out = {"p": s["c_p"][:, 0], "Theta": s["c_Theta"][:, 0]}
        if self.order == 1:
            h = self.elements.volumes ** (1.0 / self.elements.view.dim)
            out["p_grad"] = s["c_p"][:, 1:] / h[:, None]
            out["Theta_grad"] = s["c_Theta"][:, 1:] / h[:, None]
        return out

    @kernel
    def stress(self, state):
        FinvT = np.swapaxes(state["Finv"], 0, 1)
        return (self.material.stress(state["F"])
                + state["p"] * state["J"] * FinvT)

    def _volumetric_tangent(self, state):
        """The local matrices of :math:`\\sum_e C_e^T M^{-1}(\\Phi^T W
        U''\\Phi) M^{-1} C_e`."""
        E = self.elements
        Th = state["Theta"]
        Upp = 0.5 * self.K * (1.0 + 1.0 / Th ** 2) * state["scale"]
        S = self._Minv @ E.gram(self.Phi, Upp) @ self._Minv
        C = E.moments(state["J"] * np.swapaxes(state["Finv"], 0, 1),
                      self.Phi)
        return E.quadratic_local(C, S)

    @kernel
    def tangent(self, state):
        A = self.material.tangent(state["F"]) + state["p"] * d_JFinvT(
            state["J"], state["Finv"])
        # one scatter for the pointwise and the condensed volumetric part
        return assemble(material_tangent, self.point_basis, A=A,
                        local_extra=self._volumetric_tangent(state))
