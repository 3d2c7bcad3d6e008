r"""Isotropic hardening laws :math:`\sigma_y(\alpha)` of the J2 material
(:class:`~skfem_pg.materials.J2Plasticity`), :math:`\alpha = \bar e_p` the
accumulated plastic strain.

* :class:`LinearSaturation`: the thesis' law (2.49),
  :math:`\sigma_y = \sigma_{y0} + H\alpha + (\sigma_{y\infty} -
  \sigma_{y0})(1 - e^{-\delta\alpha})`;
* :class:`JohnsonCookHardening`: the Johnson–Cook flow stress without its
  rate and temperature factors, :math:`\sigma_y = A + B\alpha^n` (thesis
  8.1, after Broumand & Khoei 2015).

A law is an object with ``stress(alpha)``, ``slope(alpha)``
(:math:`d\sigma_y/d\alpha`, finite everywhere the return map evaluates it)
and ``initial`` (:math:`\sigma_y(0) > 0`); the return map needs nothing
else, so a new law is a new class here.
"""
import numpy as np

from .constants import check_finite


class LinearSaturation:
    r"""Linear plus saturation hardening (2.49).

    Parameters
    ----------
    sigma_y0
        Initial yield stress (positive).
    H
        Linear hardening modulus (:math:`\ge 0`).
    sigma_yinf
        Saturation yield stress (default ``sigma_y0``: no saturation; not
        below ``sigma_y0``).
    delta
        Saturation exponent (:math:`\ge 0`).

    Examples
    --------
    >>> law = LinearSaturation(sigma_y0=5.0, H=10.0)
    >>> float(law.stress(0.1))
    6.0

    """

    def __init__(self, sigma_y0, H=0.0, sigma_yinf=None, delta=0.0):
        self.sigma_y0, self.H, self.sigma_yinf, self.delta = check_finite(
            "J2Plasticity", sigma_y0=sigma_y0, H=H,
            sigma_yinf=sigma_y0 if sigma_yinf is None else sigma_yinf,
            delta=delta)
        if not self.sigma_y0 > 0:
            raise ValueError("sigma_y0 must be positive, got {}".format(
                sigma_y0))
        if self.H < 0 or self.delta < 0:
            raise ValueError("H and delta must be >= 0 (softening is not "
                             "built), got H = {}, delta = {}".format(H, delta))
        if self.sigma_yinf < self.sigma_y0:
            raise ValueError("sigma_yinf ({}) below sigma_y0 ({}) would "
                             "soften".format(sigma_yinf, sigma_y0))

    def __repr__(self):
        return ("LinearSaturation(sigma_y0={:g}, H={:g}, sigma_yinf={:g}, "
                "delta={:g})".format(self.sigma_y0, self.H, self.sigma_yinf,
                                     self.delta))

    @property
    def initial(self):
        return self.sigma_y0

    def stress(self, alpha):
        """:math:`\\sigma_y(\\alpha)` (2.49)."""
        a = np.asarray(alpha, dtype=float)
        return (self.sigma_y0 + self.H * a + (self.sigma_yinf - self.sigma_y0)
                * (1.0 - np.exp(-self.delta * a)))

    def slope(self, alpha):
        """:math:`d\\sigma_y/d\\alpha`."""
        return self.H + (self.sigma_yinf - self.sigma_y0) * self.delta * \
            np.exp(-self.delta * np.asarray(alpha, dtype=float))


class JohnsonCookHardening:
    r"""Johnson–Cook (power-law) hardening without rate and temperature
    terms, :math:`\sigma_y = A + B\alpha^n` (thesis 8.1).

    For :math:`n < 1` the slope :math:`Bn\alpha^{n-1}` is infinite at
    :math:`\alpha = 0`; :meth:`slope` evaluates it at
    :math:`\max(\alpha, \alpha_0)`, ``alpha0 = 1e-300`` (finite for
    every ``n`` above 0.03).  The return map never evaluates it at zero:
    its bracketed start gives a positive increment, and the first yield
    of a point is an increment as small as :math:`((\sigma_{vM}^{tr} -
    A)/B)^{1/n}` (``2e-13`` for the thesis' steel a quarter of an MPa
    above A), where a slope floored any higher would be wrong and the
    local Newton would not converge.

    Parameters
    ----------
    A
        Initial yield stress (positive).
    B
        Hardening modulus (:math:`\ge 0`).
    n
        Hardening exponent, in [0.03, 1].

    Examples
    --------
    Broumand & Khoei's steel (thesis 8.1), in MPa:

    >>> float(JohnsonCookHardening(792.0, 510.0, 0.26).stress(0.1))
    ... # doctest: +ELLIPSIS
    1072.26...
    """

    alpha0 = 1e-300

    def __init__(self, A, B, n):
        self.A, self.B, self.n = check_finite("JohnsonCookHardening", A=A, B=B,
                                         n=n)
        if not self.A > 0:
            raise ValueError("JohnsonCookHardening: A (the initial yield "
                             "stress) must be positive, got {}".format(A))
        if self.B < 0:
            raise ValueError("JohnsonCookHardening: B must be >= 0 "
                             "(softening is not built), got {}".format(B))
        if not 0.03 <= self.n <= 1:
            raise ValueError("JohnsonCookHardening: the exponent n must lie "
                             "in [0.03, 1] (below, the return map's slope "
                             "at the first yield overflows), got {}"
                             .format(n))

    def __repr__(self):
        return "JohnsonCookHardening(A={:g}, B={:g}, n={:g})".format(
            self.A, self.B, self.n)

    @property
    def initial(self):
        return self.A

    def stress(self, alpha):
        """:math:`A + B\\alpha^n`."""
        a = np.maximum(np.asarray(alpha, dtype=float), 0.0)
        return self.A + self.B * a ** self.n

    def slope(self, alpha):
        """:math:`Bn\\max(\\alpha, \\alpha_0)^{n-1}`."""
        a = np.maximum(np.asarray(alpha, dtype=float), self.alpha0)
        return self.B * self.n * a ** (self.n - 1.0)
