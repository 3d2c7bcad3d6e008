r"""Hyperelastic materials as functions of the deformation gradient.

Each material maps ``F`` of shape ``(d, d, ...)`` (any trailing axes, e.g.
families × members or elements × quadrature points) to the first
Piola–Kirchhoff stress :math:`P = \partial W/\partial F` (2.41), shape
``(d, d, ...)``, and the consistent tangent
:math:`\mathbb A_{iJkL} = \partial P_{iJ}/\partial F_{kL}`, shape
``(d, d, d, d, ...)``.  In 2-D the models are plane strain (the third
stretch is 1) except :class:`LinearElastic` with ``plane_stress=True``.

Tangents are verified against central finite differences in
``tests/test_materials.py``.
"""
import inspect

import numpy as np

from .constants import check_moduli


def det(F):
    """Determinant of ``(d, d, ...)`` arrays; ``d = 2, 3`` written out
    (no batched LAPACK call: every explicit step checks every point's
    J), other ``d`` by ``numpy.linalg``."""
    d = F.shape[0]
    if d == 2:
        return F[0, 0] * F[1, 1] - F[0, 1] * F[1, 0]
    if d == 3:
        return (F[0, 0] * (F[1, 1] * F[2, 2] - F[1, 2] * F[2, 1])
                - F[0, 1] * (F[1, 0] * F[2, 2] - F[1, 2] * F[2, 0])
                + F[0, 2] * (F[1, 0] * F[2, 1] - F[1, 1] * F[2, 0]))
    return np.linalg.det(np.moveaxis(F, (0, 1), (-2, -1)))


def inverse_and_det(F):
    """Inverse and determinant of ``(d, d, ...)`` arrays; ``d = 2, 3`` by
    cofactors (contiguous, no batched LAPACK call), other ``d`` by
    ``numpy.linalg``."""
    d = F.shape[0]
    if d == 2:
        J = det(F)
        inv = np.array([[F[1, 1], -F[0, 1]], [-F[1, 0], F[0, 0]]]) / J
        return inv, J
    if d == 3:
        cof = np.empty_like(F, dtype=float)  # cof[i, j] = C_ji (adjugate)
        for i in range(3):
            i1, i2 = (i + 1) % 3, (i + 2) % 3
            for j in range(3):
                j1, j2 = (j + 1) % 3, (j + 2) % 3
                cof[j, i] = F[i1, j1] * F[i2, j2] - F[i1, j2] * F[i2, j1]
        J = F[0, 0] * cof[0, 0] + F[0, 1] * cof[1, 0] + F[0, 2] * cof[2, 0]
        cof /= J
        return cof, J
    Fm = np.moveaxis(F, (0, 1), (-2, -1))
    return np.moveaxis(np.linalg.inv(Fm), (-2, -1), (0, 1)), np.linalg.det(Fm)


def _eye(F):
    d = F.shape[0]
    return np.eye(d).reshape((d, d) + (1,) * (F.ndim - 2))


def dyad(A, B):
    """:math:`(A\\otimes B)_{iJkL} = A_{iJ} B_{kL}`."""
    return A[:, :, None, None] * B[None, None]


def _inv_t_derivative(Finv):
    r""":math:`\partial F^{-T}_{iJ}/\partial F_{kL} = -F^{-1}_{Jk}F^{-1}_{Li}`."""
    return -np.einsum("Jk...,Li...->iJkL...", Finv, Finv)


def _identity4(F):
    """:math:`\\delta_{ik}\\delta_{JL}`."""
    d = F.shape[0]
    eye = np.eye(d)
    return np.einsum("ik,JL->iJkL", eye, eye).reshape((d,) * 4
                                                      + (1,) * (F.ndim - 2))


class Material:
    """Base class: ``stress(F)``, ``tangent(F)``, ``energy(F)``.

    ``small_strain`` is true for a law whose ``stress`` is the small-strain
    stress itself (output reports it as the Cauchy stress, without the push
    forward :math:`PF^T/J` of a finite-strain law).

    The package's laws take their moduli by name (``NeoHooke(lam=...,
    mu=...)``, ``NeoHookeIsoVol(mu=..., K=...)``): two plain floats in
    the order of another law's constructor were accepted silently.  A
    positional call raises ``TypeError`` naming the keywords."""

    small_strain = False

    def __new__(cls, *args, **kwargs):
        if args:  # a law whose constructor takes names only
            params = list(inspect.signature(cls.__init__).parameters.values())
            names = [p.name for p in params if p.kind is p.KEYWORD_ONLY]
            if any(p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD,
                              p.VAR_POSITIONAL) for p in params[1:]):
                return super().__new__(cls)
            raise TypeError(
                "{0} takes its moduli by name: {0}({1}) (got {2} positional "
                "argument(s))".format(cls.__name__, ", ".join(
                    "{}=...".format(n) for n in names[:3]), len(args)))
        return super().__new__(cls)

    def stress(self, F):
        raise NotImplementedError

    def tangent(self, F):
        raise NotImplementedError

    def energy(self, F):
        raise NotImplementedError

    def __repr__(self):
        args = ", ".join("{}={:.6g}".format(k, v) for k, v in vars(self)
                         .items() if isinstance(v, (int, float)))
        return "{}({})".format(type(self).__name__, args)


class LinearElastic(Material):
    r"""Small-strain linear elasticity as a function of ``F``:
    :math:`\varepsilon = \mathrm{sym}(F - I)`,
    :math:`P = \lambda\,\mathrm{tr}\varepsilon\, I + 2\mu\varepsilon`.

    Examples
    --------
    >>> import numpy as np
    >>> m = LinearElastic(lam=60.0, mu=40.0)
    >>> F = np.eye(2)[:, :, None] + np.array([[1e-3, 0], [0, 0]])[:, :, None]
    >>> m.stress(F)[:, :, 0].round(6).tolist()
    [[0.14, 0.0], [0.0, 0.06]]

    """

    small_strain = True

    def __init__(self, *, lam, mu, plane_stress=False):
        lam, mu = check_moduli(lam=lam, mu=mu)
        self.plane_stress = bool(plane_stress)
        if plane_stress:
            lam = 2 * lam * mu / (lam + 2 * mu)
        self.lam, self.mu = float(lam), float(mu)

    def stress(self, F):
        H = F - _eye(F)
        eps = 0.5 * (H + np.swapaxes(H, 0, 1))
        return self.lam * np.trace(eps) * _eye(F) + 2 * self.mu * eps

    def tangent(self, F):
        d = F.shape[0]
        eye = np.eye(d)
        A = (self.lam * np.einsum("iJ,kL->iJkL", eye, eye)
             + self.mu * (np.einsum("ik,JL->iJkL", eye, eye)
                          + np.einsum("iL,Jk->iJkL", eye, eye)))
        return np.broadcast_to(A.reshape(A.shape + (1,) * (F.ndim - 2)),
                               A.shape + F.shape[2:])

    def energy(self, F):
        H = F - _eye(F)
        eps = 0.5 * (H + np.swapaxes(H, 0, 1))
        return 0.5 * self.lam * np.trace(eps) ** 2 + self.mu * np.einsum(
            "ij...,ij...->...", eps, eps)


class StVenantKirchhoff(Material):
    r"""St. Venant–Kirchhoff (2.45): :math:`S = \lambda\,\mathrm{tr}E\,I +
    2\mu E`, :math:`P = FS`.

    Examples
    --------
    >>> import numpy as np
    >>> m = StVenantKirchhoff(lam=60.0, mu=40.0)
    >>> float(m.energy(np.eye(3)[:, :, None])[0])
    0.0

    """

    def __init__(self, *, lam, mu):
        self.lam, self.mu = check_moduli(lam=lam, mu=mu)

    def _S(self, F):
        E = 0.5 * (np.einsum("kI...,kJ...->IJ...", F, F) - _eye(F))
        return self.lam * np.trace(E) * _eye(F) + 2 * self.mu * E, E

    def stress(self, F):
        S, _ = self._S(F)
        return np.einsum("iK...,KJ...->iJ...", F, S)

    def tangent(self, F):
        S, _ = self._S(F)
        d = F.shape[0]
        eye = np.eye(d)
        # delta_ik S_JL + F_iM C_MJNL F_kN
        A = np.einsum("ik,JL...->iJkL...", eye, S)
        A = A + self.lam * np.einsum("iJ...,kL...->iJkL...", F, F)
        A = A + self.mu * (np.einsum("iN...,kN...,JL->iJkL...", F, F, eye)
                           + np.einsum("iL...,kJ...->iJkL...", F, F))
        return A

    def energy(self, F):
        _, E = self._S(F)
        return 0.5 * self.lam * np.trace(E) ** 2 + self.mu * np.einsum(
            "ij...,ij...->...", E, E)


class NeoHooke(Material):
    r"""Compressible neo-Hooke (2.42):
    :math:`W = \frac\mu2(\mathrm{tr}C - 3 - 2\ln J)
    + \frac\lambda4(J^2 - 1 - 2\ln J)`,
    :math:`P = \mu(F - F^{-T}) + \frac\lambda2(J^2 - 1)F^{-T}`.

    Examples
    --------
    The arguments are Lamé's constants, ``lam`` first; at ``F = I`` the
    stress vanishes and the tangent is the linear one:

    >>> import numpy as np
    >>> m = NeoHooke(lam=60.0, mu=40.0)
    >>> F = np.eye(3)[:, :, None]
    >>> float(np.abs(m.stress(F)).max()), float(m.tangent(F)[0, 0, 0, 0, 0])
    (0.0, 140.0)

    """

    def __init__(self, *, lam, mu):
        self.lam, self.mu = check_moduli(lam=lam, mu=mu)

    def stress(self, F):
        Finv, J = inverse_and_det(F)
        FinvT = np.swapaxes(Finv, 0, 1)
        return self.mu * F + (0.5 * self.lam * (J ** 2 - 1) - self.mu) * FinvT

    def tangent(self, F):
        Finv, J = inverse_and_det(F)
        FinvT = np.swapaxes(Finv, 0, 1)
        c = 0.5 * self.lam * (J ** 2 - 1) - self.mu
        return (self.mu * _identity4(F)
                + self.lam * J ** 2 * dyad(FinvT, FinvT)
                + c * _inv_t_derivative(Finv))

    def energy(self, F):
        _, J = inverse_and_det(F)
        d = F.shape[0]
        trC = np.einsum("kI...,kI...->...", F, F) + (3 - d)
        lnJ = np.log(J)
        return (0.5 * self.mu * (trC - 3 - 2 * lnJ)
                + 0.25 * self.lam * (J ** 2 - 1 - 2 * lnJ))


class NeoHookeIsoVol(Material):
    r"""Neo-Hooke with isochoric/volumetric split (2.43), (2.44):
    :math:`W = \frac\mu2(\mathrm{tr}\,b_{iso} - 3)
    + \frac K4(J^2 - 1 - 2\ln J)`, :math:`b_{iso} = J^{-2/3} b`,
    :math:`K = \lambda + \frac23\mu`.  In 2-D: plane strain,
    :math:`\mathrm{tr}\,b = \mathrm{tr}\,b_{2D} + 1`.

    Examples
    --------
    Shear and bulk modulus, ``mu`` first (:meth:`from_lame` takes Lamé's
    constants):

    >>> m = NeoHookeIsoVol(mu=40.0, K=100.0)
    >>> n = NeoHookeIsoVol.from_lame(60.0, 40.0)
    >>> round(n.K, 6), n.mu
    (86.666667, 40.0)

    """

    def __init__(self, *, mu, K):
        self.mu, self.K = check_moduli(mu=mu, K=K)

    @classmethod
    def from_lame(cls, lam, mu):
        return cls(mu=mu, K=lam + 2.0 * mu / 3.0)

    @classmethod
    def isochoric(cls, mu):
        """The isochoric part alone (``K = 0``), e.g. for a mean-dilatation
        model that adds the volumetric part per element; ``mu = 0`` is a
        fluid's (:class:`~skfem_pg.materials.NewtonianFluid`, whose
        viscous part the model then binds)."""
        if mu == 0:
            m = cls(mu=1.0, K=1.0)
            m.mu = 0.0
        else:
            m = cls(mu=mu, K=1.0)
        m.K = 0.0
        return m

    @classmethod
    def incompressible(cls, mu):
        r"""The incompressible limit (:math:`\nu = 0.5`, ``K = inf``): only
        the formulations with a pressure unknown (IUnlP0,
        :class:`~skfem_pg.formulations.IncompressibleP0`) accept it."""
        m = cls(mu=mu, K=1.0)
        m.K = np.inf
        return m

    def stress(self, F):
        Finv, J = inverse_and_det(F)
        FinvT = np.swapaxes(Finv, 0, 1)
        d = F.shape[0]
        c = np.einsum("kI...,kI...->...", F, F) + (3 - d)  # tr C (3-D)
        a = J ** (-2.0 / 3.0)
        return (self.mu * a * (F - c / 3.0 * FinvT)
                + 0.5 * self.K * (J ** 2 - 1) * FinvT)

    def tangent(self, F):
        r"""Written with four full-size temporaries:
        :math:`\mathbb A = \mu a\, \delta_{ik}\delta_{JL}
        + U\otimes F^{-T} + F^{-T}\otimes V - e\,F^{-1}_{Jk}F^{-1}_{Li}`,
        :math:`a = J^{-2/3}`, :math:`U = -\frac23\mu a(F - \frac c3
        F^{-T}) + KJ^2F^{-T}`, :math:`V = -\frac23\mu a F`,
        :math:`e = \frac K2(J^2 - 1) - \frac c3\mu a`, :math:`c =
        \mathrm{tr}\,C`."""
        Finv, J = inverse_and_det(F)
        FinvT = np.ascontiguousarray(np.swapaxes(Finv, 0, 1))
        d = F.shape[0]
        c = np.einsum("kI...,kI...->...", F, F) + (3 - d)
        mua = self.mu * J ** (-2.0 / 3.0)
        J2 = J ** 2
        U = -2.0 / 3.0 * mua * (F - c / 3.0 * FinvT) + self.K * J2 * FinvT
        A = dyad(U, FinvT)
        A += dyad(FinvT, -2.0 / 3.0 * mua * F)
        e = 0.5 * self.K * (J2 - 1) - c / 3.0 * mua
        A -= np.einsum("Jk...,Li...->iJkL...", e * Finv, Finv)
        for i in range(d):
            for k in range(d):
                A[i, k, i, k] += mua
        return A

    def energy(self, F):
        _, J = inverse_and_det(F)
        d = F.shape[0]
        trb = np.einsum("kI...,kI...->...", F, F) + (3 - d)
        return (0.5 * self.mu * (J ** (-2.0 / 3.0) * trb - 3)
                + 0.25 * self.K * (J ** 2 - 1 - 2 * np.log(J)))
