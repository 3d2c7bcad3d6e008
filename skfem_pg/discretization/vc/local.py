r"""Local variationally consistent (VC) correction: the PBG integration
constraint met family by family, without a global solve (the outlook of
the thesis, 8.2, (8.1)–(8.3); ``vc_solver="local"``).

The global constraint (5.18) sums the families' integrals of the test
gradients,

.. math:: r^i = \sum_k s_h^{ki} - A^i = 0, \qquad
          s_h^{ki} = \sum_{j\in H^k} w_{kj} G^{kji},

and couples the families through the particles they share.  It holds if
every family meets its own share,

.. math:: s_h^{ki} = s^{ki} \quad (i \in H^k), \qquad
          \sum_k s^{ki} = A^i .                                   \tag{L1}

The shares must respect what the derivatives already satisfy (5.1.1):
zeroth- and first-order consistency give
:math:`\sum_i s_h^{ki} = 0` and
:math:`\sum_i s_h^{ki}\otimes X^i = (\sum_j w_{kj}) I = V^k I`, so

.. math:: \sum_i s^{ki} = 0, \qquad \sum_i s^{ki}\otimes X^i = V^k I. \tag{L2}

The thesis' (8.2)/(8.3) (as far as the extraction shows them) set the
interior shares to zero; that contradicts (L2)'s second condition, which
no correction keeping linear consistency can violate.  The shares here
come from the collocation mesh's linear functions :math:`N` (P1, Q1, P1
tetrahedra, Q1 hexahedra) on the particles' elements:

.. math:: s^{ki} = \int_\Omega N_k\,\nabla N_i \,d\Omega .

They satisfy (L1) with the FE-consistent area vectors
(:math:`\sum_k N_k = 1`, :math:`\int_\Omega \nabla N_i = \oint N_i n =
A^i`) and (L2) with the lumped volumes :math:`V^k = \int N_k`
(:math:`\sum_i N_i = 1`, :math:`\sum_i X^i N_i = X`) — the particles'
own volumes.  A family must contain every particle that shares an
element with its master (the mesh families do).

The correction :math:`C^{kji} = Q^{kj}\beta^{ki}` — one vector per family
and shape function, :math:`Q^{kj}` the bond projector for V5 (the bond
mapping is kept) and :math:`I` for V3 — gives per family the
:math:`d\times d` systems

.. math:: M^k \beta^{ki} = s^{ki} - s_h^{ki}, \qquad
          M^k = \sum_j w_{kj} Q^{kj},

with :math:`M^k` positive definite (the master's :math:`Q^{kk} = I`).
Because the right-hand sides satisfy (L2) minus the same conditions of
:math:`s_h`, :math:`\sum_i \beta^{ki} = 0` and
:math:`\sum_i \beta^{ki}\otimes X^i = 0`: linear consistency is kept, and
the linear patch test holds to round-off.  On a U1 basis (the master's
derivatives at every member, no bond) the corrected derivatives are the
node-based smoothed gradients :math:`s^{ki}/V^k`.
"""
import functools
import time

import numpy as np
import scipy.sparse as sp
import skfem as fem

from ...errors import CorrectionError, describe_particle
from .first_order import VCReport, vc_parts, vc_residual
from ..particles import linear_elements


def smoothed_gradients(mesh, elements=None, rows=None):
    r"""``(d,)`` sparse matrices :math:`S_c[k, i] = \int N_k\,\partial_c
    N_i` over ``elements`` of ``mesh`` (linear P1/Q1 functions of its
    vertices): the family shares :math:`s^{ki}`.  ``rows``: the masters
    whose rows are needed (only the elements around them are
    integrated)."""
    e1, _ = linear_elements(mesh)
    tind = (np.arange(mesh.nelements) if elements is None
            else np.asarray(elements, dtype=np.int64))
    if rows is not None:
        hit = np.zeros(mesh.nvertices, dtype=bool)
        hit[rows] = True
        tind = tind[hit[mesh.t[:, tind]].any(axis=0)]
    # N_k dN_i det J is a polynomial of degree 1 (simplices) or 3 per
    # direction (quads, hexes): exact with intorder 2 and 3 (then the
    # shares sum exactly to the area vectors and lumped volumes)
    simplex = mesh.t.shape[0] == mesh.dim() + 1
    basis = fem.CellBasis(mesh, e1, elements=tind,
                          intorder=2 if simplex else 3)
    phi = np.array([np.asarray(b[0]) for b in basis.basis])  # (nb, nel, nq)
    dphi = np.array([b[0].grad for b in basis.basis])  # (nb, d, nel, nq)
    t = mesh.t[:, tind]
    nb = t.shape[0]
    rows_ = np.repeat(t, nb, axis=0)  # k of entry (k, i)
    cols_ = np.tile(t, (nb, 1))
    out = []
    for c in range(mesh.dim()):
        # (nb_k, nb_i, nel): sum_q dx N_k d_c N_i
        E = np.einsum("keq,ieq,eq->kie", phi, dphi[:, c], basis.dx)
        out.append(sp.coo_matrix(
            (E.reshape(nb * nb, -1).ravel(), (rows_.ravel(),
                                              cols_.ravel())),
            shape=(mesh.nvertices, mesh.nvertices)).tocsr())
    return out


def family_shares(S, masters, mem, mask, x):
    """``(nf, m, d)`` shares :math:`s^{ki}` of the families (``masters``,
    padded members ``mem`` / ``mask``, all in the numbering of ``S``),
    read from the matrices of :func:`smoothed_gradients`; raises
    :class:`~skfem_pg.errors.CorrectionError` naming a master whose family
    lacks a particle it shares an element with (``x``: positions)."""
    nf, m = mem.shape
    d = len(S)
    out = np.zeros((nf, m, d))
    rows = np.broadcast_to(masters[:, None], mem.shape)
    for c in range(d):
        out[..., c][mask] = np.asarray(
            S[c][rows[mask], mem[mask]]).ravel()
    total = sum(abs(S[c][masters]) for c in range(d)).tocsr()
    lost = total.sum(axis=1).A1 - np.abs(out).sum(axis=(1, 2))
    bad = np.flatnonzero(lost > 1e-12 * total.sum(axis=1).A1)
    if bad.size:
        k = bad[0]
        missing = np.setdiff1d(total[k].indices[total[k].data > 0],
                               mem[k][mask[k]])
        raise CorrectionError(
            "local VC: the family of {} lacks {}, which shares an element "
            "with its master ({} such families); the local correction "
            "needs every element neighbour in the family (the mesh "
            "families, families='mesh'), or use the global solve "
            "(vc_solver='auto')".format(
                describe_particle(masters[k], x[:, masters[k]]),
                describe_particle(missing[0], x[:, missing[0]]), bad.size))
    return out


def local_vc_correction(system, variant="V5", boundary="min-norm",
                        shares=None, complete=None, together=None,
                        **ignored):
    r"""Correct ``G`` family by family so each family meets its share of
    the integration constraint (module docstring).

    The arguments are those of
    :func:`~skfem_pg.discretization.vc.first_order.vc_correction` (of the
    :class:`~skfem_pg.discretization.vc.first_order.VCSystem`, ``phi`` is
    not used: the local correction has one vector per family and shape
    function); ``shares`` is ``f(masters, mem, mask) -> (nf, m, d)`` (the
    caller's :func:`family_shares` on its mesh, in the numbering of
    ``x``).  Returns ``(G_corrected, VCReport)``; the report's residuals
    are those of the global constraint (5.18) with the FE-consistent
    ``area``; ``complete(sums)`` (default: ``sums - area.T`` and the
    active particles) turns this part's sums :math:`\sum_{kj} w_{kj}
    G^{kji}` into the residual of all parts (a partition sums its ranks');
    ``together(error)`` (on ranks:
    :func:`~skfem_pg.distributed.comm.raise_together`) raises an error of
    one part's families on every part before the residual is summed.
    """
    G, dx, x, volumes, fam, area, phi, _, index = system
    if variant not in ("V3", "V5"):
        raise ValueError("local VC corrects with V3 or V5 (the bond "
                         "projector), got vc={!r}".format(variant))
    if boundary != "min-norm":
        raise ValueError(
            "local VC meets every constraint with the FE-consistent area "
            "vectors (the boundary variants release constraints of the "
            "global system): use vc_boundary='min-norm', got {!r}"
            .format(boundary))
    t0 = time.perf_counter()
    grouped = isinstance(G, (list, tuple))
    parts, masters, B, Qs = vc_parts(G, dx, fam, phi, index, x, variant)
    d, n = x.shape
    active = volumes > 0
    area_scale = np.mean(volumes[active]) ** ((d - 1.0) / d)
    if complete is None:
        def complete(sums):
            return sums - area.T, volumes > 0
    r0, keep = complete(vc_residual(parts, [p[0] for p in parts], n))
    Gc, error = None, None
    try:  # an error of one part is raised on every part (ranks)
        Gc = _corrected(parts, Qs, B, shares, volumes, x)
    except Exception as err:  # noqa: BLE001 - raised below
        error = err
    if together is not None:
        together(error)
    elif error is not None:
        raise error
    r1, keep = complete(vc_residual(parts, Gc, n))
    pairs = int(sum(p[2].padded()[1].sum() for p in parts))  # (k, i)
    rep = VCReport(
        variant=variant, solver="local", unknowns=pairs * d,
        constraints=pairs * d,
        residual_before=float(np.abs(r0[keep]).max() / area_scale),
        residual_after=float(np.abs(r1[keep]).max() / area_scale),
        iterations=0, seconds=time.perf_counter() - t0,
        notes=["local: one d x d solve per family"], boundary=boundary,
        particle_residuals=np.abs(r1 * keep[:, None]).max(axis=1)
        / area_scale)
    return (Gc if grouped else Gc[0]), rep


def _corrected(parts, Qs, B, shares, volumes, x):
    r"""The corrected derivatives of each group of ``parts``
    (:func:`local_vc_correction`): per family one ``d x d`` solve for
    :math:`\beta^{ki}`, then :math:`C^{kji} = Q^{kj}\beta^{ki}`."""
    d = x.shape[0]
    Gc = []
    for (Gp, w, f, _, idx), Q in zip(parts, Qs):
        mem, mask = f.padded()
        Vk = volumes[f.masters]
        if np.any(np.abs(w.sum(axis=1) - Vk) > 1e-12 * Vk):
            k = int(np.argmax(np.abs(w.sum(axis=1) - Vk)))
            raise CorrectionError(
                "local VC: the weights of the family of {} sum to {:.6g}, "
                "its volume is {:.6g}; first-order consistency needs them "
                "equal".format(describe_particle(
                    f.masters[k], x[:, f.masters[k]]),
                    w[k].sum(), Vk[k]))
        nf, m = mem.shape
        sh = (w[:, None, :] @ Gp.reshape(nf, m, m * d)).reshape(nf, m, d)
        target = shares(f.masters, mem, mask)
        Bp = B if idx is None else B[idx]
        beta = np.linalg.solve(Bp[:, None], (target - sh)[..., None])[..., 0]
        beta *= mask[..., None]
        # C^{kji} = Q^{kj} beta^{ki} at the real members j
        C = np.matmul(Q, np.swapaxes(beta, 1, 2)[:, None])  # (k, j, a, i)
        Gc.append(Gp + np.swapaxes(C, 2, 3) * mask[:, :, None, None])
    return Gc


def local_solver(particles):
    """The ``vc_solve`` of a basis built with ``vc_solver="local"``:
    :func:`local_vc_correction` with the shares of ``particles``' mesh
    (vertex particles of a linear mesh).  A rank's basis takes its
    partition's (:meth:`skfem_pg.distributed.Partition.local_vc_solver`:
    the shares of its owned masters, no communication but the report's
    residual sum)."""
    mesh, x = particles.mesh, particles.x
    if mesh is None or particles.kind != "vertices":
        raise ValueError(
            "vc_solver='local' takes its family shares from the "
            "collocation mesh: vertex particles of a linear mesh "
            "(Particles.from_mesh), not {}".format(
                "particles without a mesh" if mesh is None else
                "{} particles".format(particles.kind)))
    S = []  # built at the first call: inside the correction's timing

    def shares(masters, mem, mask):
        if not S:
            S.extend(smoothed_gradients(mesh, particles.elements))
        return family_shares(S, masters, mem, mask, x)
    return functools.partial(local_vc_correction, shares=shares)
