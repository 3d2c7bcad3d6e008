r"""Second-order weighted Taylor expansion (WTE2, formulation U2).

Basis without the constant term (the expansion is about the master, which
the derivatives reproduce exactly):

.. math::

    p(\Delta X) = (\Delta X_a;\ \Delta X_a\Delta X_b,\ a\le b)
    \quad\text{(2-D: 5 terms, 3-D: 9)},

moment matrix and derivatives (weights (5.41))

.. math::

    M^k = \sum_{i\ne k}\omega^{ki}V^i\, p(\Delta X^{ki})\otimes
          p(\Delta X^{ki}),\qquad
    G^{kji} = \omega^{ki}V^i \Big(\frac{\partial p}{\partial X}
          \Big|_{\Delta X^{kj}}\Big)^T (M^k)^{-1} p(\Delta X^{ki}),

:math:`i\ne k`; the master column by :math:`G^{kjk} = -\sum_{i\ne k}
G^{kji}`.  :math:`F^{kj}` is then exact for quadratic displacement fields at
every member ``j``.  Needs at least 5 (2-D) / 9 (3-D) non-master members in
general position — larger families than FE connectivity gives at corners
(use a horizon of about 2h or more).
"""
import numpy as np

from .common import FamilyGeometry, chunks, weights, inverse_spd
from .taylor import check_singular


def quadratic_terms(d):
    """Index pairs ``(a, b)``, ``a <= b``, of the quadratic monomials."""
    return [(a, b) for a in range(d) for b in range(a, d)]


def taylor2_basis(D):
    """:math:`p(D)`, shape ``D.shape[:-1] + (q,)``."""
    d = D.shape[-1]
    quad = [D[..., a] * D[..., b] for a, b in quadratic_terms(d)]
    return np.concatenate([D, np.stack(quad, axis=-1)], axis=-1)


def taylor2_derivatives(D):
    """:math:`\\partial p/\\partial X` at ``D``, shape
    ``D.shape[:-1] + (q, d)``."""
    d = D.shape[-1]
    lin = np.broadcast_to(np.eye(d), D.shape[:-1] + (d, d))
    rows = []
    for a, b in quadratic_terms(d):
        r = np.zeros(D.shape[:-1] + (d,))
        r[..., a] += D[..., b]
        r[..., b] += D[..., a]
        rows.append(r)
    return np.concatenate([lin, np.stack(rows, axis=-2)], axis=-2)


def wte2_coefficients(geo, n=1):
    r"""The WTE2 fit of the families of ``geo`` (a :class:`FamilyGeometry`)
    with weights :math:`|\Delta X|^{-2n}` (5.41): ``(c, singular)``, the
    monomial coefficients per member ``c[k, i, q]`` (offsets scaled by
    ``geo.h``; the master's column unused) and which families' moment
    matrices are singular."""
    D = geo.D0
    W = weights((D ** 2).sum(-1), n, floor=True) * geo.V  # master: r2 = 0
    p = taylor2_basis(D)  # (k, i, q)
    Wp = W[..., None] * p
    Minv, singular = inverse_spd(np.swapaxes(Wp, -1, -2) @ p)
    return Wp @ Minv, singular  # M symmetric


def wte2_gradients(x, volumes, fam, n=1):
    """WTE2 derivatives, shape ``(nf, m, m, d)`` (U2)."""
    return wte2_at(x, volumes, fam, n=n)


def wte2_at(x, volumes, fam, points=None, n=1):
    r"""The WTE2 fit of each family differentiated at ``points``:
    ``G[k, j, i]``, the derivative of the shape function of member ``i``
    at point ``j`` of family ``k``, shape ``(nf, P, m, d)``; ``points``
    ``(nf, P, d)`` absolute positions (default: the members, ``P = m``).
    Exact for quadratic fields."""
    mem_all, mask_all = fam.padded()
    nf, m = mem_all.shape
    d = x.shape[0]
    q = d + d * (d + 1) // 2
    P = m if points is None else points.shape[1]
    G = np.zeros((nf, P, m, d))
    for sl in chunks(nf, max(m, P) * m * q):
        geo = FamilyGeometry(x, volumes, mem_all[sl], mask_all[sl])
        c, singular = wte2_coefficients(geo, n)  # (k, i, q)
        check_singular(x, fam, sl, geo, singular, "WTE2", False)
        if points is None:
            Y, at = geo.D0, geo.mask
        else:
            Y = (points[sl] - x.T[mem_all[sl, :1]]) / geo.h[:, None, None]
            at = np.ones(Y.shape[:2], dtype=bool)
        dp = taylor2_derivatives(Y) * at[..., None, None]  # (k, j, q, d)
        # G[k, j, i, :] = c[k, i, :] @ dp[k, j]
        g = np.einsum("kiq,kjqd->kjid", c, dp)
        g[:, :, 0] = -g[:, :, 1:].sum(axis=2)
        g /= geo.h[:, None, None, None]
        G[sl] = g * geo.mask[:, None, :, None]
    return G
