r"""FE comparators with a mean dilatation: Q1P0 / H1P0 (Simo–Taylor–Pister)
for the iso/vol split neo-Hooke (2.43), per element a constant dilatation
:math:`\Theta_e = \frac1{V_e}\int_e J` and pressure
:math:`p_e = U'(\Theta_e)`, condensed,

.. math:: \Pi = \sum_e \int_e W_{iso}(F) + V_e U(\Theta_e),\qquad
          U(\Theta) = \tfrac K4(\Theta^2 - 1 - 2\ln\Theta).

Its tangent has a rank-one term per element,
:math:`\frac{U''(\Theta_e)}{V_e}\, g_e\otimes g_e` with
:math:`g_e = \int_e J F^{-T}:\nabla\varphi`.
"""
import numpy as np
import scipy.sparse as sp

from ..materials import NeoHookeIsoVol, inverse_and_det
from ..discretization.assembly import assemble
from ..threads import kernel
from .displacement import Hyperelastic, internal_force, material_tangent, _det


class MeanDilatation(Hyperelastic):
    """Q1P0 / H1P0 mean dilatation on a scikit-fem vector basis (see the
    module docstring) for the iso/vol neo-Hooke with shear modulus ``mu``
    and bulk modulus ``K``."""

    def __init__(self, basis, mu, K):
        if hasattr(basis, "G"):
            raise ValueError("MeanDilatation is the FE comparator; for "
                             "particles use the UnlP0 formulation")
        super().__init__(basis, NeoHookeIsoVol.isochoric(mu))
        self.K = float(K)
        self.material_full = NeoHookeIsoVol(mu, K)
        self._V = basis.dx.sum(axis=1)

    @kernel
    def state(self, u):
        s = super().state(u)
        J = _det(s["F"])
        s["J"] = J
        s["Theta"] = (J * self.basis.dx).sum(axis=1) / self._V
        return s

    def _pressure(self, Theta):
        return 0.5 * self.K * (Theta - 1.0 / Theta)

    @kernel
    def stress(self, state):
        F, J = state["F"], state["J"]
        FinvT = np.swapaxes(inverse_and_det(F)[0], 0, 1)
        p = self._pressure(state["Theta"])[:, None]
        return self.material.stress(F) + p * J * FinvT

    @kernel
    def tangent(self, state):
        F, J, Theta = state["F"], state["J"], state["Theta"]
        Finv = inverse_and_det(F)[0]
        FinvT = np.swapaxes(Finv, 0, 1)
        p = self._pressure(Theta)[:, None]
        # d(J F^-T)/dF = J (F^-T (x) F^-T - F^-1_Jk F^-1_Li)
        dJFinvT = J * (FinvT[:, :, None, None] * FinvT[None, None]
                       - np.einsum("Jk...,Li...->iJkL...", Finv, Finv))
        A = self.material.tangent(F) + p * dJFinvT
        K = assemble(material_tangent, self.basis, A=A)
        # rank-one volumetric term per element
        g = internal_force.elemental(self.basis, P=J * FinvT).tolocal()
        Upp = 0.5 * self.K * (1.0 + 1.0 / Theta ** 2)
        loc = (Upp / self._V)[:, None, None] * g[:, :, None] * g[:, None, :]
        ed = self.basis.element_dofs  # (Nbfun, nel)
        rows = np.broadcast_to(ed.T[:, :, None], loc.shape)
        cols = np.broadcast_to(ed.T[:, None, :], loc.shape)
        Kvol = sp.coo_matrix((loc.ravel(), (rows.ravel(), cols.ravel())),
                             shape=K.shape).tocsr()
        return K + Kvol
