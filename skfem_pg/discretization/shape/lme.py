r"""Local maximum-entropy (LME) shape-function derivatives at the masters
(Arroyo & Ortiz; Quak 2011, (2.26)–(2.30)), a test-function option of PPG.

At the master :math:`x = X^k` of family ``k`` with members ``a``:

.. math::

    \varphi_a = \frac{\exp(-\beta|x - X^a|^2 + \lambda\cdot(x - X^a))}{Z},
    \qquad \beta = \mu / h^2 ,

with :math:`\lambda` from Newton's method on the dual problem,
:math:`r(\lambda) = \sum_a \varphi_a (x - X^a) = 0`,
:math:`J = \sum_a \varphi_a (x - X^a)\otimes(x - X^a) - r\otimes r`; then
:math:`\nabla\varphi_a = -\varphi_a J^{-1}(x - X^a)`.  The values sum to
one and reproduce linear fields; the gradients sum to zero and satisfy
:math:`\sum_a X^a\otimes\nabla\varphi_a = I`.  ``h`` is the family's
nearest-neighbour distance; ``mu`` controls locality (large: nearly
interpolating, small: smooth).  Batched over families (Newton iterations
for all at once).
"""
import numpy as np


def lme_master_gradients(x, fam, mu=1.8, tol=1e-12, maxiter=60):
    r"""LME derivatives at the masters, ``(nf, m, d)`` (member ``a`` of
    family ``k`` at :math:`X^k`; zero in padded slots), and a boolean
    ``(nf,)`` array ``ok``.  A master on the convex hull of its family (a
    surface particle) has no finite :math:`\lambda` — LME degenerates
    there — and gets ``ok = False``: callers substitute another test
    function for those families."""
    mem, mask = fam.padded()
    nf, m = mem.shape
    d = x.shape[0]
    P = x.T[mem]
    D = (P[:, :1] - P) * mask[..., None]  # x - X^a, (k, a, d)
    r2 = (D ** 2).sum(-1)
    h = np.sqrt(np.where(mask & (r2 > 0), r2, np.inf).min(axis=1))
    Dn = D / h[:, None, None]  # normalised: beta = mu in these units
    base = -mu * (Dn ** 2).sum(-1)
    lam = np.zeros((nf, d))
    eye = np.eye(d)
    for _ in range(maxiter):
        expo = np.where(mask, base + (Dn @ lam[..., None])[..., 0], -np.inf)
        expo -= expo.max(axis=1, keepdims=True)
        phi = np.exp(expo)
        phi /= phi.sum(axis=1, keepdims=True)
        r = (phi[..., None] * Dn).sum(1)
        J = (np.swapaxes(phi[..., None] * Dn, 1, 2) @ Dn
             - r[:, :, None] * r[:, None, :])
        done = np.abs(r).max(axis=1) < tol
        if done.all():
            break
        J_safe = np.where(done[:, None, None], eye, J + 1e-14 * eye)
        step = np.linalg.solve(J_safe, r[..., None])[..., 0]
        lam -= np.where(done[:, None], 0.0, np.clip(step, -10.0, 10.0))
    J_safe = np.where(done[:, None, None], J, eye)
    g = -phi[..., None] * np.linalg.solve(J_safe, np.swapaxes(Dn, 1, 2)) \
        .swapaxes(1, 2)
    g = g / h[:, None, None] * mask[..., None]
    lin = np.einsum("kad,kab->kbd", g, P) - eye
    zero = np.abs(g.sum(axis=1)).max(axis=1) * h
    ok = done & (np.abs(lin).max(axis=(1, 2)) < 1e-8) & (zero < 1e-8)
    g[~ok] = 0.0
    return g, ok
