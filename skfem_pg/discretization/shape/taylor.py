r"""Weighted and moving Taylor expansion shape-function derivatives.

``G[k, j, i, :]`` is the derivative of the shape function of member ``i`` of
family ``k``, evaluated at member ``j`` (thesis (4.8)–(4.12)), in the
*plain-sum* form :math:`F^{kj} = I + \sum_i u^i \otimes G^{kji}` with
:math:`\sum_i G^{kji} = 0` (the thesis' difference form (4.11), folded).
Padded slots are zero.

WTE1 (static Taylor expansion around the master; formulation U1)
    :math:`M^k = \sum_{i\ne k} \omega^{ki} V^i \Delta X^{ki}\otimes\Delta X^{ki}`,
    :math:`G^{kji} = \omega^{ki} V^i (M^k)^{-1} \Delta X^{ki}` for every
    ``j`` — the classical correspondence / corrected SPH gradient, constant
    in the family (4.3)–(4.6).
MTE1 (moving Taylor expansion, (5.48)–(5.52); formulation Unl)
    for each evaluation member ``j``,
    :math:`M^{kj} = \sum_{i\ne j} \omega^{ji} V^i \Delta X^{ji}\otimes\Delta X^{ji}`,
    :math:`G^{kji} = \omega^{ji} V^i (M^{kj})^{-1}\Delta X^{ji}` (i ≠ j),
    :math:`G^{kjj} = -\sum_{i\ne j} G^{kji}`.

Weights :math:`\omega = 1/|\Delta X|^{2n}` (5.41)–(5.42).
"""
import numpy as np

from .common import (FamilyGeometry, chunks, weights, inverse_spd,
                     raise_singular)


def check_singular(x, fam, sl, geo, singular, what, per_member):
    if np.any(singular):
        idx = np.argwhere(singular)[0]
        k = idx[0]
        j = idx[1] if per_member else None
        raise_singular(x, fam.masters[sl], fam.sizes[sl], geo.mem, k, j, what)


def wte1_gradients(x, volumes, fam, n=1):
    """WTE1 derivatives, shape ``(nf, m, m, d)`` (identical for every
    evaluation member ``j``)."""
    mem_all, mask_all = fam.padded()
    nf, m = mem_all.shape
    d = x.shape[0]
    G = np.zeros((nf, m, m, d))
    for sl in chunks(nf, m * m):
        geo = FamilyGeometry(x, volumes, mem_all[sl], mask_all[sl])
        D = geo.D0
        # the master has r2 = 0
        W = weights((D ** 2).sum(-1), n, floor=True) * geo.V
        WD = W[..., None] * D
        M = np.swapaxes(WD, -1, -2) @ D
        Minv, singular = inverse_spd(M)
        check_singular(x, fam, sl, geo, singular, "WTE1", False)
        g = WD @ np.swapaxes(Minv, -1, -2)
        g[:, 0] = -g[:, 1:].sum(axis=1)
        g /= geo.h[:, None, None]
        G[sl] = g[:, None, :, :] * geo.mask[:, :, None, None]
    return G


def mte1_gradients(x, volumes, fam, n=1):
    """MTE1 derivatives, shape ``(nf, m, m, d)``; the default shape
    functions of PBG Unl (5.52)."""
    mem_all, mask_all = fam.padded()
    nf, m = mem_all.shape
    d = x.shape[0]
    G = np.zeros((nf, m, m, d))
    eye_m = np.eye(m, dtype=bool)
    for sl in chunks(nf, m * m):
        geo = FamilyGeometry(x, volumes, mem_all[sl], mask_all[sl])
        P = geo.D0
        D = P[:, None, :, :] - P[:, :, None, :]  # D[k,j,i] = X^i - X^j
        pair = geo.mask[:, :, None] & geo.mask[:, None, :] & ~eye_m
        W = np.where(pair, weights((D ** 2).sum(-1), n, floor=True)
                     * geo.V[:, None, :], 0.0)
        WD = W[..., None] * D
        M = np.swapaxes(WD, -1, -2) @ D
        Minv, singular = inverse_spd(M)
        check_singular(x, fam, sl, geo, singular & geo.mask, "MTE1", True)
        g = WD @ np.swapaxes(Minv, -1, -2)  # G = W M^-1 D
        diag = g.sum(axis=2)  # G[k,j,j] = -sum_{i != j} G[k,j,i]
        g[:, np.arange(m), np.arange(m)] = -diag
        g /= geo.h[:, None, None, None]
        G[sl] = g * geo.mask[:, :, None, None]
    return G
