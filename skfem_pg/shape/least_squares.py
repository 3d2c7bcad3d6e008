r"""Weighted / moving least-squares shape functions.

MLS1 *values at the master*, with the master's own weight excluded
(:math:`\omega^{kk} = 0`; formulas.md section 3):

.. math::

    N_{MLS1}^{kki} = \omega^{ki} V^i \, p^{ki} \cdot (M^{kk})^{-1} \cdot e_0,
    \qquad p^{ki} = (1, \Delta X^{ki}),
    \qquad M^{kk} = \sum_{i\ne k} \omega^{ki} V^i p^{ki}\otimes p^{ki}.

They reproduce linear fields, :math:`\sum_i N = 1` and
:math:`\sum_i N\,\Delta X^{ki} = 0`, and build the VC correction functions V3
and V5 (5.62), (5.64).  Needs ``dim + 1`` non-master members in general
position.
"""
import numpy as np

from .common import (FamilyGeometry, chunks, weights, inverse_spd,
                     raise_singular)


def _basis(D, order):
    """``(1, D)`` (order 1) or ``(1, D, quadratic terms)`` (order 2)."""
    one = np.ones(D.shape[:-1] + (1,))
    if order == 1:
        return np.concatenate([one, D], axis=-1)
    from .quadratic import taylor2_basis
    return np.concatenate([one, taylor2_basis(D)], axis=-1)


def ls_values(D, V, n=1, order=1):
    r"""Least-squares shape-function values (MLS1 for ``order=1``, WLS2
    for ``order=2``) from offsets ``D = (X^i - x)/h`` (``(..., k, d)``) and
    volumes ``V`` (``(..., k)``; 0 for unused slots) of the support
    particles of evaluation points ``x``: :math:`N^i = \omega^i V^i
    p^i\cdot M^{-1} e_0`.  Offsets of length 0 get weight 0.  Returns
    ``(N, singular)``."""
    W = weights((D ** 2).sum(-1), n) * V
    p = _basis(D, order)
    M = np.swapaxes(W[..., None] * p, -1, -2) @ p
    Minv, singular = inverse_spd(M)
    return W * (p @ Minv[..., :, :1])[..., 0], singular


def mls1_values(D, V, n=1):
    """MLS1 values, :func:`ls_values` with ``order=1``."""
    return ls_values(D, V, n, 1)


def _master_values(x, volumes, fam, n, order):
    mem_all, mask_all = fam.padded()
    nf, m = mem_all.shape
    d = x.shape[0]
    need = d + 1 if order == 1 else 1 + d + d * (d + 1) // 2
    N = np.zeros((nf, m))
    for sl in chunks(nf, m * m):
        geo = FamilyGeometry(x, volumes, mem_all[sl], mask_all[sl])
        N[sl], singular = ls_values(geo.D0, geo.V, n, order)
        if np.any(singular):
            k = np.nonzero(singular)[0][0]
            raise_singular(x, fam.masters[sl], fam.sizes[sl], geo.mem, k,
                           None, "{} (master excluded, needs {} members "
                           "besides the master in general position)"
                           .format("MLS1" if order == 1 else "WLS2", need))
    return N


def mls1_master_values(x, volumes, fam, n=1):
    """:math:`N_{MLS1}^{kki}`, shape ``(nf, m)`` (zero in padded slots and
    at the master itself)."""
    return _master_values(x, volumes, fam, n, 1)


def wls2_master_values(x, volumes, fam, n=1):
    r""":math:`N_{WLS2}^{kki}` (quadratic basis with constant term, master
    weight excluded), shape ``(nf, m)``: they reproduce quadratic fields at
    the master, so :math:`\varphi^{ki} = N^{kki} - \delta_{ki}` (correction
    function V4) is orthogonal to all quadratics.  Needs ``d + d(d+1)/2 + 1``
    non-master members in general position."""
    return _master_values(x, volumes, fam, n, 2)


def wls1_master_gradients(x, volumes, fam, n=1):
    r"""WLS1 derivatives at the masters, ``(nf, m, d)``: the gradient of
    the weighted linear least-squares fit with a constant term,
    :math:`\nabla N^i = \omega^{ki}V^i\,(M^{-1} p^{ki})_{1..d}`,
    :math:`p^{ki} = (1, \Delta X^{ki})`, master weight excluded.  Unlike
    WTE1 the fit need not pass through the master's value.  A PPG test
    function option."""
    mem_all, mask_all = fam.padded()
    nf, m = mem_all.shape
    d = x.shape[0]
    g = np.zeros((nf, m, d))
    for sl in chunks(nf, m * m):
        geo = FamilyGeometry(x, volumes, mem_all[sl], mask_all[sl])
        W = weights((geo.D0 ** 2).sum(-1), n) * geo.V
        p = _basis(geo.D0, 1)
        M = np.swapaxes(W[..., None] * p, -1, -2) @ p
        Minv, singular = inverse_spd(M)
        if np.any(singular):
            k = np.nonzero(singular)[0][0]
            raise_singular(x, fam.masters[sl], fam.sizes[sl], geo.mem, k,
                           None, "WLS1 (master excluded, needs {} members "
                           "besides the master in general position)"
                           .format(d + 1))
        g[sl] = W[..., None] * (p @ Minv)[..., 1:] / geo.h[:, None, None]
    return g
