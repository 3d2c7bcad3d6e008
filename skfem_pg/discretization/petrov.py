r"""Peridynamic Petrov–Galerkin (PPG) test bases, thesis (4.21)–(4.22).

PPG evaluates the test-shape derivatives once per family, at the master:
:math:`G_t^{kki}` (here the WTE1 derivative at the master, which MTE1
shares).  Written over bonds ((4.21)),

.. math::

    \text{PPG1:}\quad \delta W = \sum_k V^k \sum_{j\in H^k}
        P(F^{jk}) : \big((\delta u^j - \delta u^k)\otimes G_t^{kkj}\big),

with :math:`F^{jk}` the trial deformation gradient at :math:`X^k` computed
in family :math:`j`.  As an element: family ``f``, quadrature point
``k ∈ H^f`` with weight :math:`V^k`, trial derivatives :math:`G^{fki}`, and
test derivatives

.. math::

    T^{fk f} = G_t^{kkf}, \qquad T^{fkk} = -G_t^{kkf}, \qquad
    T^{fki} = 0 \text{ otherwise};

PPG2 (4.22) swaps the roles, :math:`G_t^{kkf} \to -G_t^{ffk}`.  Families
must be pairwise (``k ∈ H^f`` exactly when ``f ∈ H^k``): :func:`pairwise`
completes them.

Integration constraint of PPG1 (5.16): for every particle ``i``

.. math:: \sum_{j\in H^i} V^j G_t^{jji} = A^i ,

the PBG constraint with the weights :math:`w_{kj}` of the master only, so
the VC correction of :mod:`~skfem_pg.discretization.corrections` (V3, one
:math:`\alpha^k` per family) applies unchanged.  PPG matrices are not
symmetric.
"""
import time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spl

from .vc.first_order import VCReport, constraint_residual
from .families import Families


def pairwise(fam):
    """Families completed to pairwise ones: ``j`` joins :math:`H^k`
    whenever ``k`` is in :math:`H^j`."""
    A = fam.adjacency().astype(float)
    masters = fam.masters
    if len(masters) != fam.n_particles:
        keep = np.zeros(fam.n_particles)
        keep[masters] = 1.0
        A = sp.diags(keep) @ A @ sp.diags(keep)
    S = A + A.T
    if S.nnz == A.nnz:
        return fam
    return Families.from_adjacency(S, masters)


def reverse_slots(fam):
    """``rev[f, q]``: the slot of master ``f`` in the family of its member
    ``mem[f, q]``; -1 in padded slots.  Needs pairwise families."""
    mem, mask = fam.padded()
    nf, m = mem.shape
    index = np.full(fam.n_particles, -1, dtype=np.int64)
    index[fam.masters] = np.arange(nf)
    owner = index[mem]  # family of each member
    # key (family, particle) -> slot, via sorting
    keys = np.arange(nf, dtype=np.int64)[:, None] * fam.n_particles + mem
    flat = np.where(mask, keys, -1).ravel()
    order = np.argsort(flat)
    wanted = (owner * fam.n_particles
              + fam.masters[:, None]).ravel()
    pos = np.searchsorted(flat[order], wanted)
    pos = np.minimum(pos, len(flat) - 1)
    found = (flat[order][pos] == wanted) & mask.ravel() & (owner.ravel()
                                                           >= 0)
    rev = np.where(found, order[pos] % m, -1).reshape(nf, m)
    if np.any(mask & (rev < 0)):
        f, q = np.argwhere(mask & (rev < 0))[0]
        raise ValueError(
            "families are not pairwise: particle {} is in the family of "
            "particle {} but not the other way round; complete them with "
            "skfem_pg.discretization.petrov.pairwise".format(
                mem[f, q], fam.masters[f]))
    return rev


def quadrature_weights(volumes, fam):
    """PPG weights ``dx[f, q] = V^{mem[f, q]}`` (0 in padded slots)."""
    mem, mask = fam.padded()
    return volumes[mem] * mask


def element_test_gradients(Gt, fam, variant="PPG1", reverse=None):
    """Test derivatives ``T[f, q, i]`` (shape ``(nf, m, m, d)``) of the
    element view from the master derivatives ``Gt[k, i]`` (``(nf, m, d)``:
    derivative of member ``i`` of family ``k`` at its master).  PPG1 reads
    :math:`G_t^{kkf}` from the family of each member ``k``; ``reverse``
    gives them instead (``(nf, m, d)``, e.g. from other MPI ranks)."""
    mem, mask = fam.padded()
    nf, m, d = Gt.shape
    if variant == "PPG1" and reverse is not None:
        g = reverse * mask[..., None]
    elif variant == "PPG1":
        rev = reverse_slots(fam)
        index = np.full(fam.n_particles, -1, dtype=np.int64)
        index[fam.masters] = np.arange(nf)
        g = Gt[index[mem], np.maximum(rev, 0)] * mask[..., None]  # G_t^{kkf}
    elif variant == "PPG2":
        g = -Gt * mask[..., None]  # -G_t^{ffk}
    else:
        raise ValueError("variant must be 'PPG1' or 'PPG2'")
    g[:, 0] = 0.0  # q = master: the two contributions cancel
    T = np.zeros((nf, m, m, d))
    T[:, :, 0] = g
    q = np.arange(m)
    T[:, q, q] -= g
    return T


def ppg2_vc_correction(Gt, volumes, fam, area, phi, exclude=None, tol=1e-15,
                       maxiter=None):
    r"""VC correction of PPG2's master derivatives ``Gt`` (``(nf, m, d)``)
    so that its integration constraint (5.17) holds,

    .. math:: r^i = \sum_{f \ni i} V^i G_t^{ffi}
                    - \sum_{k\in H^i} V^k G_t^{iik} - A^i = 0 ,

    with :math:`G_t^{fk} \leftarrow G_t^{fk} + \varphi^{fk}\alpha^f`.  The
    map :math:`\alpha \to r` is one scalar sparse matrix for all
    components: column ``f`` holds :math:`V^i\varphi^{fi}` in the rows of
    its members ``i`` and :math:`-\sum_k V^k\varphi^{fk}` in the row of its
    master (zero for correction functions that sum to zero).  Solved for
    the minimum-norm least-squares solution with LSQR.  Returns
    ``(Gt_corrected, VCReport)``."""
    t0 = time.perf_counter()
    mem, mask = fam.padded()
    nf, m, d = Gt.shape
    n = fam.n_particles
    V = volumes
    Vm = V[mem] * mask
    dx = quadrature_weights(V, fam)

    def residual(G):  # the generic constraint of the element view
        return constraint_residual(element_test_gradients(G, fam, "PPG2"),
                                   dx, fam, area)

    f = np.broadcast_to(np.arange(nf)[:, None], (nf, m))
    rows = np.concatenate([mem[mask], fam.masters])
    cols = np.concatenate([f[mask], np.arange(nf)])
    vals = np.concatenate([(V[mem] * phi)[mask], -(Vm * phi).sum(1)])
    S = sp.csr_matrix((vals, (rows, cols)), shape=(n, nf))
    keep = V > 0
    if exclude is not None:
        keep[np.asarray(exclude, dtype=np.int64)] = False
    r0 = residual(Gt)
    alpha = np.zeros((nf, d))
    its = 0
    for a in range(d):
        out = spl.lsqr(S[keep], -r0[keep, a], atol=tol, btol=tol,
                       iter_lim=maxiter or 20 * nf)
        alpha[:, a] = out[0]
        its = max(its, int(out[2]))
    Gc = Gt + phi[..., None] * alpha[:, None, :]
    r1 = residual(Gc)
    h = np.mean(V[V > 0]) ** (1.0 / d)
    rep = VCReport(variant="V3 (PPG2)", solver="lsqr", unknowns=nf * d,
                   constraints=int(keep.sum()) * d,
                   residual_before=float(np.abs(r0[keep]).max()
                                         / h ** (d - 1)),
                   residual_after=float(np.abs(r1[keep]).max()
                                        / h ** (d - 1)),
                   iterations=its, seconds=time.perf_counter() - t0,
                   particle_residuals=np.abs(r1).max(axis=1) * keep
                   / h ** (d - 1))
    return Gc, rep
