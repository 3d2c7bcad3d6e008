r"""Weighted / moving least-squares shape functions.

MLS1 *values at the master*, with the master's own weight excluded
(:math:`\omega^{kk} = 0`; weights (5.41)):

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

from .common import (BOND_FLOOR, FamilyGeometry, chunks, weights,
                     inverse_spd, raise_singular)
from .quadratic import quadratic_terms, taylor2_basis


def _basis(D, order):
    """``(1, D)`` (order 1) or ``(1, D, quadratic terms)`` (order 2)."""
    one = np.ones(D.shape[:-1] + (1,))
    if order == 1:
        return np.concatenate([one, D], axis=-1)
    return np.concatenate([one, taylor2_basis(D)], axis=-1)


def ls_values(D, V, n=1, order=1):
    r"""Least-squares shape-function values (MLS1 for ``order=1``, WLS2
    for ``order=2``) from offsets ``D = (X^i - x)/h`` (``(..., k, d)``) and
    volumes ``V`` (``(..., k)``; 0 for unused slots) of the support
    particles of evaluation points ``x``: :math:`N^i = \omega^i V^i
    p^i\cdot M^{-1} e_0`.  Offsets of length 0 get weight 0.  Returns
    ``(N, singular)``."""
    W = weights((D ** 2).sum(-1), n, floor=True) * V
    p = _basis(D, order)
    M = np.swapaxes(W[..., None] * p, -1, -2) @ p
    Minv, singular = inverse_spd(M)
    c = _reproducing(W[..., None] * (p @ Minv[..., :, :1]), p)
    return c[..., 0], singular


def _reproducing(c, p, steps=2):
    r"""Refine least-squares coefficients ``c`` (``(..., k, r)``: the
    first ``r`` columns of :math:`W p M^{-1}`) until they reproduce the
    basis, :math:`\sum_i p^i_a c^i_b = \delta_{ab}` — partition of unity
    and linear (quadratic) reproduction, which the VC system's null space
    needs to round-off.  With member weights 1e6 apart (1000:1 graded
    node sets) :math:`M` has condition numbers of 1e12 and the plain
    product reproduces only to 1e-10; each step :math:`c \leftarrow c +
    c\,(I - p^T c)` (on the ``r`` reproduced columns) squares the error.
    """
    r = c.shape[-1]
    for _ in range(steps):
        E = -np.swapaxes(p[..., :r], -1, -2) @ c
        E[..., np.arange(r), np.arange(r)] += 1.0
        c = c + c @ E
    return c


def mls1_values(D, V, n=1):
    """MLS1 values, :func:`ls_values` with ``order=1``."""
    return ls_values(D, V, n, 1)


def master_fits(x, volumes, fam, n=1, order=1, moving=False):
    r"""Weighted least-squares fits about the masters, master weight
    excluded: coefficients :math:`c^{ki} = \omega^{ki}V^i (M^k)^{-1}p^{ki}`
    (``(nf, m, 1 + d)`` for order 1, ``(nf, m, 1 + d + q)`` for order 2,
    in the scaled offsets :math:`D = \Delta X/h_k`) and the family radii
    ``h`` (``(nf,)``).  :math:`N^{ki}(X) = p((X - X^k)/h_k)\cdot c^{ki}`
    is the static (WLS) shape function; its value at the master is
    ``c[..., 0]``, its gradient ``c[..., 1:1+d] / h`` and, for order 2, its
    constant Hessian from the quadratic coefficients.

    With ``moving=True`` (order 1 only) also the MLS1 derivatives at the
    master, ``(nf, m, d)``, which include the derivatives of the weights
    and of the moment matrix with respect to the evaluation point
    (:math:`D^i = (X^i - x)/h`, :math:`\partial p^i/\partial x_a =
    -E_a/h`, :math:`\partial W^i/\partial x_a = 2n W^i D^i_a/(|D^i|^2 h)`):

    .. math:: \partial_a N^i = \partial_a W^i\, p^i\cdot M^{-1}e_0
        + W^i\,\partial_a p^i\cdot M^{-1}e_0
        - W^i p^i\cdot M^{-1}(\partial_a M) M^{-1}e_0 .
    """
    mem_all, mask_all = fam.padded()
    nf, m = mem_all.shape
    d = x.shape[0]
    need = d + 1 if order == 1 else 1 + d + d * (d + 1) // 2
    c = np.zeros((nf, m, need))
    h = np.ones(nf)
    grad = np.zeros((nf, m, d)) if moving else None
    for sl in chunks(nf, m * m):
        geo = FamilyGeometry(x, volumes, mem_all[sl], mask_all[sl])
        r2 = (geo.D0 ** 2).sum(-1)
        W = weights(r2, n, floor=True) * geo.V
        p = _basis(geo.D0, order)
        M = np.swapaxes(W[..., None] * p, -1, -2) @ p
        Minv, singular = inverse_spd(M)
        if np.any(singular):
            k = np.nonzero(singular)[0][0]
            raise_singular(x, fam.masters[sl], fam.sizes[sl], geo.mem, k,
                           None, "{} (master excluded, needs {} members "
                           "besides the master in general position)"
                           .format("WLS{}".format(order), need))
        c[sl] = _reproducing(W[..., None] * (p @ Minv), p)
        h[sl] = geo.h
        if moving:
            grad[sl] = _mls1_master_gradients(geo.D0, r2, W, p, Minv, n) \
                / geo.h[:, None, None]
    return (c, h, grad) if moving else (c, h)


def _mls1_master_gradients(D, r2, W, p, Minv, n):
    """MLS1 derivatives at the master in scaled coordinates (times h);
    offsets ``D = (X^i - X^k)/h`` (so the evaluation point is the master)."""
    d = D.shape[-1]
    a0 = Minv[..., :, 0]  # M^{-1} e0, (nf, q)
    pa = (p * a0[:, None, :]).sum(-1)  # p^i·M^{-1}e0, (nf, m)
    # a weight held at the bond floor does not move with the point
    safe = np.where(r2 > 0, r2, 1.0)
    dW = np.where(r2 > BOND_FLOOR, 2.0 * n * W / safe, 0.0)[..., None] * D
    g = np.empty(D.shape)
    for a in range(d):
        Ea = np.zeros(p.shape[-1])
        Ea[1 + a] = 1.0
        dp = -np.broadcast_to(Ea, p.shape) * (W > 0)[..., None]  # -E_a
        # dM = Σ_l dW_l p p^T + W_l (dp p^T + p dp^T)
        dM = np.einsum("fl,flq,flr->fqr", dW[..., a], p, p) + np.einsum(
            "fl,flq,flr->fqr", W, dp, p)
        dM = dM + np.swapaxes(dM - np.einsum("fl,flq,flr->fqr", dW[..., a],
                                             p, p), -1, -2)
        b = (Minv @ (dM @ a0[..., None]))[..., 0]  # M^-1 dM M^-1 e0
        g[..., a] = (dW[..., a] * pa + W * (dp * a0[:, None, :]).sum(-1)
                     - W * (p * b[:, None, :]).sum(-1))
    return g


def _master_values(x, volumes, fam, n, order):
    return master_fits(x, volumes, fam, n, order)[0][..., 0]


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
    c, h = master_fits(x, volumes, fam, n, 1)
    d = x.shape[0]
    return c[..., 1:1 + d] / h[:, None, None]


def wls2_master_gradients(x, volumes, fam, n=1):
    r"""WLS2 derivatives at the masters, ``(nf, m, d)``: the gradient at
    :math:`X^k` of the weighted quadratic least-squares fit (constant
    term included, master weight excluded); exact for quadratic fields.
    A PPG test function option."""
    c, h = master_fits(x, volumes, fam, n, 2)
    d = x.shape[0]
    return c[..., 1:1 + d] / h[:, None, None]


def wls2_master_hessians(x, volumes, fam, n=1):
    r"""Second derivatives of the WLS2 shape functions, constant over the
    family, ``(nf, m, d, d)``: :math:`\partial^2 N^{ki}_{WLS2}`, the
    correction function V2 (5.61).  They annihilate constant and linear
    fields: :math:`\sum_i \partial^2 N^{ki} = 0`,
    :math:`\sum_i \Delta X^{ki}\otimes\partial^2 N^{ki} = 0`."""
    c, h = master_fits(x, volumes, fam, n, 2)
    d = x.shape[0]
    H = np.zeros(c.shape[:2] + (d, d))
    for t, (a, b) in enumerate(quadratic_terms(d)):
        coef = c[..., 1 + d + t]
        H[..., a, b] += coef
        H[..., b, a] += coef
    return H / (h ** 2)[:, None, None, None]


def mls1_master_gradients(x, volumes, fam, n=1):
    r"""MLS1 derivatives at the masters, ``(nf, m, d)``: the moving
    least-squares derivative (weights and moment matrix differentiated
    with the evaluation point, :func:`master_fits`), master weight
    excluded.  Linearly consistent; a PPG test function option."""
    return master_fits(x, volumes, fam, n, 1, moving=True)[2]


#: the master's own weight in the MLS1 Hessian of U1SIG (6.28): the
#: "exception" of (5.42), :math:`\omega^{kk} = 1/(1000\,h)^{2n}` (``h`` the
#: family radius) instead of an infinite one; constant near the master
MASTER_WEIGHT_DISTANCE = 1000.0


def mls1_hessian_at(D, V, n=1, fixed=None):
    r"""Second derivatives of the MLS1 shape functions (moving weights,
    linear basis) at the evaluation point ``x``, in the scaled offsets
    ``D = (X^i - x)/h`` ``(nf, m, d)`` with volumes ``V`` ``(nf, m)``;
    ``fixed`` ``(nf, m)`` (optional) weights that do not move with ``x``
    (the master's exception).  Returns ``(H, singular)``, ``H``
    ``(nf, m, d, d)`` in units of ``1/h^2``.

    With :math:`N^i = W^i p^i\cdot a`, :math:`a = M^{-1}e_0`,
    :math:`M = \sum_l W^l p^l\otimes p^l`, :math:`p^i = (1, D^i)`,
    :math:`\partial_a p = -e_{1+a}`, :math:`W = V|D|^{-2n}`,
    :math:`\partial_a W = 2nW D_a/|D|^2`,
    :math:`\partial_{ab} W = \frac{2nW}{|D|^2}\big(2(n+1)\frac{D_aD_b}
    {|D|^2} - \delta_{ab}\big)`:

    .. math::

        \partial_{ab}N = \partial_{ab}W\,p\cdot a
        + \partial_a W(\partial_b p\cdot a + p\cdot\partial_b a)
        + \partial_b W(\partial_a p\cdot a + p\cdot\partial_a a)
        + W(\partial_a p\cdot\partial_b a + \partial_b p\cdot\partial_a a
        + p\cdot\partial_{ab} a),

    :math:`\partial_a a = -M^{-1}\partial_a M\,a`,
    :math:`\partial_{ab} a = -M^{-1}(\partial_{ab}M\,a + \partial_a M\,
    \partial_b a + \partial_b M\,\partial_a a)`.
    """
    nf, m, d = D.shape
    q = d + 1
    r2 = (D ** 2).sum(-1)
    W = weights(r2, n, floor=True) * V
    moving = np.ones_like(W) if fixed is None else (fixed == 0)
    W = np.where(moving, W, 0.0) + (0.0 if fixed is None else fixed)
    safe = np.where(r2 > 0, r2, 1.0)
    # (nf, m); a weight held at the bond floor does not move with the point
    g = np.where((r2 > BOND_FLOOR) & moving, 2.0 * n * W / safe, 0.0)
    dW = g[..., None] * D
    ddW = g[..., None, None] * (
        2.0 * (n + 1) * D[..., :, None] * D[..., None, :]
        / safe[..., None, None] - np.eye(d))
    p = _basis(D, 1)
    M = np.einsum("fl,flq,flr->fqr", W, p, p)
    Minv, singular = inverse_spd(M)
    a = Minv[..., :, 0]  # (nf, q)
    dp = -np.eye(q)[1:]  # dp[b] = -e_{1+b}, (d, q)
    s = np.einsum("fl,flq->fq", W, p)  # Σ W p
    t = np.einsum("fla,flq->faq", dW, p)  # Σ ∂_a W p
    sw = W.sum(axis=1)
    dM = (np.einsum("fla,flq,flr->faqr", dW, p, p)
          + np.einsum("bq,fr->fbqr", dp, s) + np.einsum("fq,br->fbqr", s,
                                                        dp))
    da = -np.einsum("fqr,fbrs,fs->fbq", Minv, dM, a)  # (nf, d, q)
    ddM = np.einsum("flab,flq,flr->fabqr", ddW, p, p)
    dpt = np.einsum("bq,far->fbaqr", dp, t)  # ∂_b p ⊗ t_a
    ddM += dpt + np.swapaxes(dpt, -1, -2)
    ddM += np.swapaxes(dpt, 1, 2) + np.swapaxes(np.swapaxes(dpt, 1, 2), -1,
                                                -2)
    pp = np.einsum("aq,br->abqr", dp, dp)
    ddM += sw[:, None, None, None, None] * (pp + np.swapaxes(pp, 0, 1))
    rhs = (np.einsum("fabqr,fr->fabq", ddM, a)
           + np.einsum("faqr,fbr->fabq", dM, da)
           + np.einsum("fbqr,far->fabq", dM, da))
    dda = -np.einsum("fqr,fabr->fabq", Minv, rhs)
    pa = np.einsum("flq,fq->fl", p, a)
    pda = np.einsum("flq,fbq->flb", p, da)  # p·∂_b a
    dpa = np.einsum("bq,fq->fb", dp, a)  # ∂_b p·a (same for every l)
    dpda = np.einsum("aq,fbq->fab", dp, da)  # ∂_a p·∂_b a
    H = ddW * pa[..., None, None]
    X = dW[..., :, None] * (dpa[:, None, None, :] + pda[..., None, :])
    H += X + np.swapaxes(X, -1, -2)
    H += W[..., None, None] * ((dpda + np.swapaxes(dpda, 1, 2))[:, None]
                               + np.einsum("flq,fabq->flab", p, dda))
    return H, singular


def mls1_master_hessians(x, volumes, fam, n=1):
    r"""Second derivatives of the MLS1 shape functions at the masters,
    ``(nf, m, d, d)`` (zero in padded slots): :math:`\partial^2
    N^{kki}_{MLS1}/\partial X^2` of U1SIG (6.28), moving weights, the
    master's weight the constant exception
    :math:`1/(1000\,h_k)^{2n}` (:data:`MASTER_WEIGHT_DISTANCE`).  They
    annihilate constant and linear fields to round-off,
    :math:`\sum_i \partial^2 N^{kki} = 0`, :math:`\sum_i X^i\otimes
    \partial^2 N^{kki} = 0`."""
    mem_all, mask_all = fam.padded()
    nf, m = mem_all.shape
    d = x.shape[0]
    H = np.zeros((nf, m, d, d))
    for sl in chunks(nf, m * (d + 1) ** 2 * d * d):
        geo = FamilyGeometry(x, volumes, mem_all[sl], mask_all[sl])
        fixed = np.zeros(geo.V.shape)
        fixed[:, 0] = geo.V[:, 0] * MASTER_WEIGHT_DISTANCE ** (-2.0 * n)
        Hs, singular = mls1_hessian_at(geo.D0, geo.V, n, fixed)
        if np.any(singular):
            k = np.nonzero(singular)[0][0]
            raise_singular(x, fam.masters[sl], fam.sizes[sl], geo.mem, k,
                           None, "MLS1 (needs {} members besides the master "
                           "in general position)".format(d + 1))
        H[sl] = Hs * geo.mask[..., None, None] \
            / (geo.h ** 2)[:, None, None, None]
    return H
