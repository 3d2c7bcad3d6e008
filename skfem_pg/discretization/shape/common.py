r"""Shared pieces of the batched shape-function kernels.

All kernels work on the padded family view ``(nf, m)`` of
:meth:`Families.padded` and process families in chunks, so memory stays
bounded and there is no Python loop per family.  Geometry is normalised per
family (offsets by the family radius :math:`h_k`, volumes by their family
mean); the derivatives are scaled back by :math:`1/h_k`.  This keeps the
moment matrices well conditioned and the singularity test scale invariant.
"""
import numpy as np

from ...errors import FamilyError, describe_particle

#: a normalised moment matrix with determinant below this is singular
SINGULAR_TOL = 1e-10
#: for larger (quadratic) moment matrices, whose normalised determinant is
#: tiny even when they are well conditioned (their eigenvalues scale with
#: different powers of h): reciprocal condition number below this
SINGULAR_RCOND = 1e-12


class FamilyGeometry:
    r"""Normalised member positions and volumes of a chunk of families.

    Attributes
    ----------
    mem, mask
        ``(nf, m)`` member indices and validity.
    D0
        ``(nf, m, d)`` offsets :math:`(X^i - X^k)/h_k` from the master.
    V
        ``(nf, m)`` member volumes divided by the family mean (0 if padded).
    h
        ``(nf,)`` family radius :math:`h_k = \max_i |X^i - X^k|`.

    """

    def __init__(self, x, volumes, mem, mask):
        self.mem, self.mask = mem, mask
        P = x.T[mem]
        D0 = (P - P[:, :1, :]) * mask[..., None]
        h = np.sqrt((D0 ** 2).sum(axis=-1).max(axis=1))
        self.h = np.where(h > 0, h, 1.0)
        self.D0 = D0 / self.h[:, None, None]
        V = volumes[mem] * mask
        self.V = V / (V.sum(axis=1, keepdims=True) / mask.sum(axis=1,
                                                              keepdims=True))


def chunks(nf, per_family, budget=2 ** 22):
    """Slices over ``nf`` families such that ``chunk * per_family`` stays
    near ``budget`` (array entries)."""
    step = max(1, budget // max(1, per_family))
    return [slice(a, min(a + step, nf)) for a in range(0, nf, step)]


#: Smallest squared bond length, in units of the family radius squared,
#: that :func:`weights` uses with ``floor=True``: a bond shorter than
#: ``sqrt(BOND_FLOOR)`` = 0.032 family radii weighs as one of that length.
#: Near-coincident particles (two particles 1e-3 mesh spacings apart in a
#: jittered triangulation) otherwise get :math:`\omega` ~1e6 times their
#: neighbours', gradient coefficients ``~1/|ΔX|`` and a stiffness matrix whose
#: round-off alone breaks the linear patch test (max nodal error 1.5e-10
#: V5m, 3.2e-10 V5p; with the floor ≤ 5.6e-11 on every variant,
#: tests/test_adversarial.py).  Any positive weights reproduce linear
#: fields, so the floor keeps the patch test; the shortest bond on the
#: package's gmsh meshes and ±0.3h grids is 0.07–0.6 family radii, where
#: the floor does nothing.
BOND_FLOOR = 1e-3


def weights(r2, n, floor=False):
    r"""Weights :math:`\omega = 1/|\Delta X|^{2n}` from squared distances
    (5.41); zero where ``r2 == 0``.  ``floor=True`` (``r2`` in units of
    the family radius squared): ``r2`` below :data:`BOND_FLOOR` counts as
    :data:`BOND_FLOOR`."""
    r2 = np.asarray(r2)
    safe = np.where(r2 > 0, np.maximum(r2, BOND_FLOOR) if floor else r2,
                    1.0)
    return np.where(r2 > 0, safe ** (-float(n)), 0.0)


def _det(M):
    q = M.shape[-1]
    if q == 1:
        return M[..., 0, 0]
    if q == 2:
        return M[..., 0, 0] * M[..., 1, 1] - M[..., 0, 1] * M[..., 1, 0]
    if q == 3:
        return (M[..., 0, 0] * (M[..., 1, 1] * M[..., 2, 2]
                                - M[..., 1, 2] * M[..., 2, 1])
                - M[..., 0, 1] * (M[..., 1, 0] * M[..., 2, 2]
                                  - M[..., 1, 2] * M[..., 2, 0])
                + M[..., 0, 2] * (M[..., 1, 0] * M[..., 2, 1]
                                  - M[..., 1, 1] * M[..., 2, 0]))
    return np.linalg.det(M)


def _inv_closed(M, det):
    q = M.shape[-1]
    out = np.empty_like(M)
    if q == 1:
        out[..., 0, 0] = 1.0
    elif q == 2:
        out[..., 0, 0] = M[..., 1, 1]
        out[..., 1, 1] = M[..., 0, 0]
        out[..., 0, 1] = -M[..., 0, 1]
        out[..., 1, 0] = -M[..., 1, 0]
    else:  # q == 3, adjugate
        for a in range(3):
            for b in range(3):
                r = [i for i in range(3) if i != b]
                c = [i for i in range(3) if i != a]
                minor = (M[..., r[0], c[0]] * M[..., r[1], c[1]]
                         - M[..., r[0], c[1]] * M[..., r[1], c[0]])
                out[..., a, b] = (-1) ** (a + b) * minor
    return out / det[..., None, None]


def inverse_spd(M):
    r"""Batched inverse of symmetric positive semi-definite matrices.

    The matrices are equilibrated first, :math:`\hat M = D^{-1/2} M
    D^{-1/2}` with :math:`D = \mathrm{diag}\,M` (unit diagonal), so the
    test is blind to scale: a weighted moment matrix with a constant term
    whose members lie at 1e-3 and 1 family radii (1000:1 graded node sets)
    has entries from 1e6 to 1, yet a well-conditioned :math:`\hat M`.
    One step of iterative refinement follows the inversion.  Returns
    ``(inverse, singular)``; singular matrices (determinant of
    :math:`\hat M` below :data:`SINGULAR_TOL` for ``q <= 3``, reciprocal
    condition number below :data:`SINGULAR_RCOND` for larger ones) are
    replaced by the identity so the caller can report them and carry on
    with finite numbers.
    """
    q = M.shape[-1]
    dg = np.diagonal(M, axis1=-2, axis2=-1)
    s = 1.0 / np.sqrt(np.where(dg > 0, dg, 1.0))
    Mn = M * s[..., :, None] * s[..., None, :]
    if q <= 3:
        det = _det(Mn)
        singular = ~(det > SINGULAR_TOL) | np.any(~(dg > 0), axis=-1)
    else:
        lam = np.linalg.eigvalsh(Mn)
        singular = ~(lam[..., 0] > SINGULAR_RCOND * lam[..., -1])
    eye = np.eye(q)
    Mn = np.where(singular[..., None, None], eye, Mn)
    if q <= 3:
        inv = _inv_closed(Mn, np.where(singular, 1.0, det))
    else:
        inv = np.linalg.inv(Mn)
    # one step of iterative refinement: the reproduction conditions
    # (partition of unity, linear fields) that the VC system's null space
    # relies on hold to round-off even for condition numbers of 1e6
    inv = inv + inv @ (eye - Mn @ inv)
    return inv * s[..., :, None] * s[..., None, :], singular


def raise_singular(x, fam_masters, fam_sizes, mem, k, j, what):
    """Raise :class:`FamilyError` for family ``k`` (chunk-local index) and
    evaluation member ``j`` (``None``: the master)."""
    p = fam_masters[k]
    msg = "family of {} ({} members): {} moment matrix".format(
        describe_particle(p, x[:, p]), fam_sizes[k], what)
    if j is not None and j > 0:
        q = mem[k, j]
        msg += " at member {}".format(describe_particle(q, x[:, q]))
    msg += (" is singular: the members are too few or collinear/coplanar."
            " Enlarge the family (larger horizon, more neighbours, or "
            "families.from_mesh with a larger min_size).")
    raise FamilyError(msg)
