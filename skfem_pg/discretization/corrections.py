r"""Bond correction and first-order variationally consistent (VC) correction.

Bond correction (BC), thesis (5.53)–(5.55), linear bases only
    For a neighbour ``j`` of master ``k``,
    :math:`e = \Delta X^{kj}/|\Delta X^{kj}|`,
    :math:`Q^{kj} = I - e\otimes e` and

    .. math:: \tilde G^{kji} = Q^{kj}\hat G^{kji}
              + \delta_{ij}\,\Delta X^{kj}/|\Delta X^{kj}|^2 \quad (i \ne k),

    the master column by :math:`G^{kjk} = -\sum_{i\ne k} G^{kji}`.  Then
    :math:`F^{kj}\Delta X^{kj} = \Delta x^{kj}` exactly (bond mapping) and
    linear consistency is kept.  :math:`Q^{kk} = I`.

The variationally consistent (VC) corrections are
:mod:`skfem_pg.discretization.vc`; :func:`check_correction` checks the
result of any of them.
"""
import warnings

import numpy as np

from ..errors import CorrectionError, describe_particle


def bond_directions(x, fam):
    """Unit bonds ``e[k, j]`` master → member ``j`` and squared lengths
    ``L2[k, j]``; ``e = 0`` at the master and in padded slots."""
    mem, mask = fam.padded()
    P = x.T[mem]
    D0 = (P - P[:, :1, :]) * mask[..., None]
    L2 = (D0 ** 2).sum(-1)
    ok = L2 > 0
    e = D0 / np.sqrt(np.where(ok, L2, 1.0))[..., None]
    return e, L2


def bond_projectors(x, fam):
    r"""``Q[k, j] = I - e⊗e`` with ``e`` the unit bond master→member ``j``;
    identity at the master and in padded slots.  Shape ``(nf, m, d, d)``."""
    e, _ = bond_directions(x, fam)
    return np.eye(x.shape[0]) - e[..., :, None] * e[..., None, :]


def bond_correction(G, x, fam):
    """Bond-corrected derivatives (5.55), shape of ``G``."""
    mem, mask = fam.padded()
    m = mem.shape[1]
    e, L2 = bond_directions(x, fam)
    # Q G = G - (G·e) e, e = 0 on the master row (Q^{kk} = I)
    Gt = G - (G * e[:, :, None, :]).sum(-1)[..., None] * e[:, :, None, :]
    idx = np.arange(1, m)
    Gt[:, idx, idx, :] += e[:, 1:] / np.sqrt(np.where(L2[:, 1:] > 0,
                                                      L2[:, 1:],
                                                      1.0))[..., None]
    Gt[:, 1:, 0] = -Gt[:, 1:, 1:].sum(axis=2)
    Gt *= mask[:, :, None, None] & mask[:, None, :, None]
    return Gt


#: largest accepted ``|G^{kji}|·h_k`` of corrected derivatives: beyond it the
#: correction cancels more than six digits (the largest seen in a correct
#: basis: 2.2e3, boundary variant p on the 3-D Cook tets; ``|ΔG|·h`` of the
#: WTE2 s-variant at 9×9 particles, which loses the patch test to 1e-6:
#: 1e5)
GRADIENT_LIMIT = 1e6


def family_radii(x, fam):
    """``(nf,)`` largest master-member distance :math:`h_k`."""
    mem, mask = fam.padded()
    P = x.T[mem]
    return np.sqrt((((P - P[:, :1]) ** 2).sum(-1) * mask).max(axis=1))


def check_correction(G, x, fam, report, tolerance=1e-8, what="VC"):
    r"""Refuse a corrected basis that would give wrong answers.

    Raises :class:`~skfem_pg.errors.CorrectionError`, naming the worst
    particles, when the derivatives ``G`` (``(nf, m, m, d)`` or the
    master derivatives ``(nf, m, d)``; or lists of them per size group,
    ``fam`` then the groups' families) are not finite, when
    :math:`\max |G^{kji}|\,h_k` exceeds :data:`GRADIENT_LIMIT`, or when the
    constraint residual left by the correction (``report``) is above
    ``tolerance`` (relative to :math:`h^{d-1}`; ``report=None``: no
    correction, derivatives only).  ``tolerance=None``
    accepts any residual with a warning (for studies of inexact
    corrections).
    """
    if isinstance(G, (list, tuple)):  # per size group, fam the subsets
        Gl, fl = G, fam
    else:
        Gl, fl = [G], [fam]
    masters = np.concatenate([f.masters for f in fl])
    sizes = np.concatenate([f.sizes for f in fl])
    bad = np.concatenate([~np.all(np.isfinite(g), axis=tuple(
        range(1, g.ndim))) for g in Gl])
    if np.any(bad):
        k = np.nonzero(bad)[0]
        raise CorrectionError(
            "{} gave non-finite derivatives in {} families, first the "
            "family of {} ({} members): its moment matrix is singular. "
            "Use larger families (a larger horizon or more neighbours)."
            .format(what, len(k), describe_particle(masters[k[0]],
                                                    x[:, masters[k[0]]]),
                    sizes[k[0]]))
    gh = np.concatenate([np.abs(g).max(axis=tuple(range(1, g.ndim)))
                         * family_radii(x, f) for g, f in zip(Gl, fl)])
    if gh.max() > GRADIENT_LIMIT:
        worst = np.argsort(gh)[::-1][:3]
        why = ("their moment matrices are near-singular" if report is None
               else "the correction system is near-singular for them "
               "(residual {:.2e} -> {:.2e})".format(report.residual_before,
                                                    report.residual_after))
        raise CorrectionError(
            "{} blew the derivatives up: |G|·h = {} in the families of {} "
            "(limit {:.0e}); {}. Use larger or better-shaped families{}."
            .format(what, ", ".join("{:.2e}".format(gh[k]) for k in worst),
                    "; ".join(describe_particle(masters[k], x[:, masters[k]])
                              for k in worst), GRADIENT_LIMIT, why,
                    "" if report is None else ", or vc=None"))
    if report is None:
        return
    res = report.residual_after
    if res <= (1e-8 if tolerance is None else tolerance):
        return
    r = report.particle_residuals
    where = ""
    if r is not None:
        worst = np.argsort(r)[::-1][:3]
        where = " Worst particles: {}.".format("; ".join(
            "{} ({:.1e})".format(describe_particle(i, x[:, i]), r[i])
            for i in worst))
    msg = ("{} left a constraint residual of {:.2e} (relative to h^(d-1); "
           "before the correction {:.2e}), so the patch test does not hold."
           "{} {}".format(what, res, report.residual_before, where,
                          " ".join(report.notes)))
    if tolerance is None:
        warnings.warn(msg + " Kept because vc_tolerance=None.")
        return
    raise CorrectionError(
        msg + " Use larger or better-shaped families; vc_tolerance=None "
        "keeps the basis anyway.")
