r"""One dilatation and one pressure per element, condensed: FE Q1P0 / H1P0
(Simo–Taylor–Pister mean dilatation) and PBG UnlP0 (thesis 6.2.1).

The iso/vol neo-Hooke (2.43) with the volumetric part on a per-element
dilatation :math:`\Theta_e` and pressure :math:`p_e` — an FE element, or a
family :math:`H^k` with the PBG weights :math:`w_{kj} = V^kV^j/V_H^k`
(4.30) as its quadrature, (6.3) with :math:`p^{kj} = p^k`,
:math:`\Theta^{kj} = \Theta^k` (6.9):

.. math::

    \Pi = \sum_e \Big[\sum_j w_{ej} W_{iso}(F^{ej})
          + V_e U(\Theta_e) + p_e\Big(\sum_j w_{ej} J^{ej}
          - V_e\Theta_e\Big)\Big],
    \qquad U(\Theta) = \tfrac K4(\Theta^2 - 1 - 2\ln\Theta),

:math:`V_e = \sum_j w_{ej}` (for a family :math:`V^k`).  Stationarity in
the local :math:`p_e, \Theta_e` gives the condensation (6.6) in closed form:

.. math::

    \Theta_e = \frac1{V_e}\sum_j w_{ej} J^{ej}, \qquad
    p_e = U'(\Theta_e) = \tfrac K2(\Theta_e - 1/\Theta_e),

the residual :math:`\sum_j w_{ej}(P_{iso} + p_e J F^{-T}) : \nabla\delta u`
(the volumetric force (6.8) with :math:`P_{vol} = J p F^{-T}`) and the
tangent

.. math::

    K = \sum_e\sum_j w_{ej}\,\nabla\delta u : (\mathbb A_{iso}
        + p_e\,\partial_F(JF^{-T})) : \nabla du
        + \sum_e \frac{U''(\Theta_e)}{V_e}\, g_e\otimes g_e, \qquad
    g_e = \sum_j w_{ej}\, J F^{-T} : \nabla N^{ej},

a rank-one term per element (:class:`~skfem_pg.discretization.elementwise.
Elements`, batched over size groups).  PPG UnlP0 (the master evaluation
:math:`\Theta^k = J^{kk}`) is not built.
"""
import numpy as np

from ..discretization.assembly import assemble
from ..discretization.elementwise import Elements
from ..materials import NeoHookeIsoVol, inverse_and_det
from ..threads import kernel
from .displacement import Hyperelastic, material_tangent


def _d_JFinvT(J, Finv):
    r""":math:`\partial(JF^{-T})_{iJ}/\partial F_{kL} = J(F^{-T}_{iJ}
    F^{-T}_{kL} - F^{-1}_{Jk}F^{-1}_{Li})`."""
    FinvT = np.swapaxes(Finv, 0, 1)
    return J * (FinvT[:, :, None, None] * FinvT[None, None]
                - np.einsum("Jk...,Li...->iJkL...", Finv, Finv))


class MeanDilatation(Hyperelastic):
    """Q1P0 / H1P0 on a scikit-fem vector basis, UnlP0 on a PBG
    :class:`~skfem_pg.FamilyBasis` (see the module docstring), for the
    iso/vol neo-Hooke with shear modulus ``mu`` and bulk modulus ``K``.

    ``fields(u)`` gives the per-element (per-family) pressure ``p`` and
    dilatation ``Theta``.
    """

    def __init__(self, basis, mu, K):
        if getattr(basis, "is_petrov", False):
            raise NotImplementedError(
                "UnlP0 on a Petrov–Galerkin basis (PPG UnlP0: the "
                "dilatation at the master, Theta^k = J^kk) is not built; "
                "use a PBG basis")
        super().__init__(basis, NeoHookeIsoVol.isochoric(mu))
        self.K = float(NeoHookeIsoVol(mu, K).K)  # checked
        self.elements = Elements(basis)

    @classmethod
    def of(cls, basis, material):
        """From a :class:`~skfem_pg.materials.NeoHookeIsoVol`."""
        if not isinstance(material, NeoHookeIsoVol):
            raise ValueError("a mean-dilatation formulation (Q1P0, H1P0, "
                             "UnlP0) needs the iso/vol neo-Hooke material "
                             "(NeoHookeIsoVol), got {!r}".format(material))
        return cls(basis, material.mu, material.K)

    def pressure(self, Theta):
        """:math:`U'(\\Theta)`."""
        return 0.5 * self.K * (Theta - 1.0 / Theta)

    def _stiffness(self, Theta):
        """:math:`U''(\\Theta)`."""
        return 0.5 * self.K * (1.0 + 1.0 / Theta ** 2)

    @kernel
    def state(self, u):
        s = super().state(u)
        Finv, J = inverse_and_det(s["F"])
        E = self.elements
        Theta = E.sum(J) / E.volumes
        s.update(Finv=Finv, J=J, Theta=Theta,
                 p=E.spread(self.pressure(Theta)))
        return s

    def min_J(self, state):
        return float(min(state["J"].min(), state["Theta"].min()))

    def energy(self, state):
        E = self.elements
        Th = state["Theta"]
        U = 0.25 * self.K * (Th ** 2 - 1 - 2 * np.log(Th))
        return super().energy(state) + float(np.sum(E.volumes * U))

    def fields(self, x):
        s = self.state(x)
        return {"p": self.pressure(s["Theta"]), "Theta": s["Theta"]}

    @kernel
    def stress(self, state):
        FinvT = np.swapaxes(state["Finv"], 0, 1)
        return (self.material.stress(state["F"])
                + state["p"] * state["J"] * FinvT)

    def _volumetric_tangent(self, state):
        """The rank-one terms :math:`U''/V_e\\, g_e\\otimes g_e`."""
        E = self.elements
        g = E.gradient_vectors(state["J"] * np.swapaxes(state["Finv"], 0, 1))
        return E.outer(g, self._stiffness(state["Theta"]) / E.volumes)

    @kernel
    def tangent(self, state):
        A = self.material.tangent(state["F"]) + state["p"] * _d_JFinvT(
            state["J"], state["Finv"])
        return (assemble(material_tangent, self.basis, A=A)
                + self._volumetric_tangent(state))

