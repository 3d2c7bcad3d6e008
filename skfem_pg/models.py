"""Forms for linear elasticity that assemble on FE and family bases alike.

Plain scikit-fem forms (``skfem.helpers``), dimension agnostic.
"""
import skfem as fem
from skfem.helpers import ddot, sym_grad, trace, eye


def lame(E, nu, plane_stress=False):
    r"""Lamé parameters :math:`(\lambda, \mu)`; with ``plane_stress`` the
    effective :math:`\lambda^* = 2\lambda\mu/(\lambda + 2\mu)`."""
    lam = E * nu / ((1 + nu) * (1 - 2 * nu))
    mu = E / (2 * (1 + nu))
    if plane_stress:
        lam = 2 * lam * mu / (lam + 2 * mu)
    return lam, mu


def linear_elasticity(lam, mu):
    r""":math:`a(u, v) = \int (2\mu\,\varepsilon(u) + \lambda\,\mathrm{tr}
    \varepsilon(u) I) : \varepsilon(v)`."""
    @fem.BilinearForm
    def linear_elasticity(u, v, w):
        e = sym_grad(u)
        return ddot(2.0 * mu * e + lam * eye(trace(e), e.shape[0]),
                    sym_grad(v))
    return linear_elasticity
