r"""The elastic energy of :class:`~skfem_pg.materials.J2Plasticity` at a
fixed plastic state: what the stabilizations of thesis 6.3 evaluate.

With the plastic metric :math:`C_p^{-1}` held fixed (isochoric,
:math:`\det C_p^{-1} = 1`), (2.46) is a hyperelastic energy of :math:`F`:

.. math::

    W(F) = \frac\mu2\left(J^{-2/3} c - 3\right)
         + \frac K4\left(J^2 - 1 - 2\ln J\right), \qquad
    c = \mathrm{tr}(F C_p^{-1} F^T) = F : (F C_p^{-1}),

.. math::

    P = \mu J^{-2/3}\left(F C_p^{-1} - \tfrac c3 F^{-T}\right)
        + \tfrac K2 (J^2 - 1) F^{-T},

and the tangent is that of :class:`~.hyperelastic.NeoHookeIsoVol` with
:math:`F C_p^{-1}` in place of :math:`F` in its rank-one terms and
:math:`\delta_{ik} (C_p^{-1})_{LJ}` in place of :math:`\delta_{ik}
\delta_{JL}`.  In 2-D (plane strain) the in-plane block of :math:`C_p^{-1}`
enters the products and its out-of-plane component adds to :math:`c`.

``mu`` and ``K`` may vary per point (the modified :math:`\tilde E,
\tilde\nu` of (6.20) differ per family) and vanish at some (a failed
point's stabilization, :mod:`~skfem_pg.materials.damage`).
"""
import numpy as np

from .hyperelastic import Material, dyad, inverse_and_det


class FrozenPlasticity(Material):
    """Neo-Hooke (2.46) of the elastic part at the fixed plastic metric
    ``Cp_inv`` ``(3, 3, *points)``; ``mu``, ``K`` scalars or arrays of the
    points' shape.  ``stress``/``tangent``/``energy`` take ``F`` of shape
    ``(d, d, *points)``, ``d`` = 2 (plane strain) or 3."""

    def __init__(self, mu, K, Cp_inv):
        self.mu, self.K = np.asarray(mu, float), np.asarray(K, float)
        if np.any(self.mu < 0) or np.any(self.K < 0) or \
                not np.all(np.isfinite(self.K)) or not np.any(self.mu > 0):
            raise ValueError("FrozenPlasticity needs mu >= 0 (positive "
                             "somewhere) and a finite K >= 0")
        self.Cp_inv = np.asarray(Cp_inv, float)
        if self.Cp_inv.shape[:2] != (3, 3):
            raise ValueError("Cp_inv must have shape (3, 3, ...), got {}"
                             .format(self.Cp_inv.shape))

    def __repr__(self):
        return "FrozenPlasticity(at {} points)".format(
            int(np.prod(self.Cp_inv.shape[2:])))

    def _parts(self, F):
        d = F.shape[0]
        if d not in (2, 3) or F.shape[2:] != self.Cp_inv.shape[2:]:
            raise ValueError("F of shape {} for a plastic state at points {}"
                             .format(F.shape, self.Cp_inv.shape[2:]))
        C = self.Cp_inv[:d, :d]
        FC = np.einsum("iK...,KJ...->iJ...", F, C)
        c = np.einsum("iJ...,iJ...->...", F, FC)
        if d == 2:
            c = c + self.Cp_inv[2, 2]
        Finv, J = inverse_and_det(F)
        return C, FC, c, Finv, J

    def stress(self, F):
        _, FC, c, Finv, J = self._parts(F)
        FinvT = np.swapaxes(Finv, 0, 1)
        mua = self.mu * J ** (-2.0 / 3.0)
        return mua * (FC - c / 3.0 * FinvT) + 0.5 * self.K * (J ** 2 - 1) \
            * FinvT

    def tangent(self, F):
        C, FC, c, Finv, J = self._parts(F)
        FinvT = np.ascontiguousarray(np.swapaxes(Finv, 0, 1))
        d = F.shape[0]
        mua = self.mu * J ** (-2.0 / 3.0)
        J2 = J ** 2
        U = -2.0 / 3.0 * mua * (FC - c / 3.0 * FinvT) + self.K * J2 * FinvT
        A = dyad(U, FinvT)
        A += dyad(FinvT, -2.0 / 3.0 * mua * FC)
        e = 0.5 * self.K * (J2 - 1) - c / 3.0 * mua
        A -= np.einsum("Jk...,Li...->iJkL...", e * Finv, Finv)
        for i in range(d):
            A[i, :, i, :] += mua * np.swapaxes(C, 0, 1)
        return A

    def energy(self, F):
        _, _, c, _, J = self._parts(F)
        return (0.5 * self.mu * (J ** (-2.0 / 3.0) * c - 3)
                + 0.25 * self.K * (J ** 2 - 1 - 2 * np.log(J)))

    def von_mises(self, F):
        r"""Cauchy von Mises stress :math:`\sigma_{vM} = \sqrt{3/2}\,
        |\mathrm{dev}\,\tau|/J` at ``F`` (the 3-D state, plane strain
        in 2-D)."""
        d = F.shape[0]
        F3 = np.zeros((3, 3) + F.shape[2:])
        F3[:d, :d] = F
        if d == 2:
            F3[2, 2] = 1.0
        be = np.einsum("iK...,KL...,jL...->ij...", F3, self.Cp_inv, F3)
        _, J = inverse_and_det(F3)
        tr = np.einsum("ii...->...", be)
        s = be - tr / 3.0 * np.eye(3).reshape((3, 3) + (1,) * (F.ndim - 2))
        s = self.mu * J ** (-2.0 / 3.0) * s
        return np.sqrt(1.5 * np.einsum("ij...,ij...->...", s, s)) / J
