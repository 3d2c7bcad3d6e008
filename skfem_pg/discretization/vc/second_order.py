r"""Second-order variationally consistent (VC2) correction for PBG with a
quadratic trial basis (U2), thesis (5.19)–(5.26).

The quadratic patch test holds when the discrete divergence theorem holds
for the test derivatives times constant *and linear* fields: for every
particle ``i``

.. math::

    r_1^i = \sum_k\sum_{j\in H^k} w_{kj} G^{kji} - A^i = 0, \\
    r_2^i = \sum_k\sum_{j\in H^k} w_{kj}\,(X^j - X^i)\otimes G^{kji}
            - \big(A_2^i - X^i\otimes A^i\big) + V^i\,I = 0

(:math:`A_2^i = \int_\Gamma N_i\, x\otimes n`, FE-consistent; the second
line is (5.26) with its surface term).  Ansatz, per family ``k`` and test
component ``B``:

.. math::

    G^{kji}_B \leftarrow G^{kji}_B + \varphi^{ki}\big(\alpha^k_B
        + \beta^k_{Bc}\,\Delta X^{kj}_c\big),
    \qquad \varphi^{ki} = N_{WLS2}^{kki} - \delta_{ki}\ \text{(V4)},

which keeps the quadratic consistency of :math:`G` (:math:`\varphi` is
orthogonal to quadratics), so the trial deformation gradient stays exact
for quadratic displacements.  The unknowns decouple per component ``B``
into one scalar system of ``(1 + d)·np`` equations in ``(1 + d)·nf``
unknowns with blocks :math:`\varphi^{ki} M^{ki}`,

.. math::

    M^{ki} = \begin{pmatrix} V^k & m_1^k \\
        m_1^k + V^k(X^k - X^i) & m_2^k + (X^k - X^i)\otimes m_1^k
    \end{pmatrix},\quad m_1^k = \sum_j w_{kj}\Delta X^{kj},\
    m_2^k = \sum_j w_{kj}\Delta X^{kj}\otimes\Delta X^{kj},

solved for its minimum-norm least-squares solution (LSQR; lengths scaled
by the mean spacing), or, with the thesis' boundary variant ``s``
(:mod:`skfem_pg.discretization.vc.boundary`), with all correction factors of
surface particles fixed to zero and their constraints released: a square
system, one sparse LU.  The surface particles' discrete :math:`A^i` and
:math:`A_2^i` then differ from FE's (``VCReport.area_correction``,
``area2_correction``).  Vertex particles of a mesh only (FE-consistent
:math:`A^i`, :math:`A_2^i`).
"""
import time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spl

from . import boundary as vc_boundary
from ...errors import VCSolveError
from .first_order import VCReport, constraint_residual


def _first_moments(G, dx, fam, X):
    """``S2[i, c, B] = Σ_k Σ_j w_kj X^j_c G^{kji}_B`` (bincount over the
    members ``i``)."""
    mem, _ = fam.padded()
    d = G.shape[-1]
    S2 = np.einsum("kjc,kj,kjiB->kicB", X.T[mem], dx, G)
    out = np.zeros((X.shape[1], d, d))
    for c in range(d):
        for b in range(d):
            out[:, c, b] = np.bincount(mem.ravel(),
                                       weights=S2[..., c, b].ravel(),
                                       minlength=X.shape[1])
    return out


def vc2_residuals(G, dx, fam, X, V, A, A2):
    """``(r1, r2)``: shapes ``(n, d)`` and ``(n, d, d)`` (``[i, c, B]``);
    ``X`` are positions relative to the origin of ``A2``."""
    r1 = constraint_residual(G, dx, fam, A)  # (5.18)
    S1 = r1 + A.T
    S2 = _first_moments(G, dx, fam, X)
    d = X.shape[0]
    r2 = (S2 - X.T[:, :, None] * S1[:, None, :]
          - (np.moveaxis(A2, -1, 0) - X.T[:, :, None] * A.T[:, None, :])
          + V[:, None, None] * np.eye(d))
    return r1, r2


def _system(phi, dx, fam, X, h):
    """Scalar matrix of the (scaled) VC2 system, rows ``(i, r)``, columns
    ``(k, s)``, ``r, s`` in ``0..d`` (0: first order / α)."""
    mem, mask = fam.padded()
    nf, m = mem.shape
    d = X.shape[0]
    Xs = X / h
    P = Xs.T[mem]  # (k, j, c)
    dX = (P - P[:, :1]) * mask[..., None]
    Vk = dx.sum(axis=1)
    m1 = np.einsum("kj,kjc->kc", dx, dX)
    m2 = np.einsum("kj,kjc,kje->kce", dx, dX, dX)
    rel = (P[:, :1] - P)  # X^k - X^i for member i, (k, i, c)
    M = np.zeros((nf, m, d + 1, d + 1))
    M[..., 0, 0] = Vk[:, None]
    M[..., 0, 1:] = m1[:, None, :]
    M[..., 1:, 0] = m1[:, None, :] + Vk[:, None, None] * rel
    M[..., 1:, 1:] = m2[:, None] + rel[..., :, None] * m1[:, None, None, :]
    return _blocks_to_csr(phi[..., None, None] * M, fam, d)


def ppg1_second_order_functions(phi, fam, X, h):
    r"""``(nf, m, d)`` functions :math:`\psi^{ki} = \varphi^{ki}\Delta
    X^{ki} - \delta_{ki}\sum_l\varphi^{kl}\Delta X^{kl}` (lengths scaled
    by ``h``) that carry the second-order unknowns of PPG1: they sum to
    zero over ``i``, so the corrected test derivatives keep
    :math:`\sum_i G_t^{ki} = 0`, without which the element view of PPG1
    (bond pairs, :func:`skfem_pg.discretization.petrov.element_test_gradients`)
    would not
    have the constraints (5.16), (5.24) of the master view."""
    mem, mask = fam.padded()
    P = (X / h).T[mem]
    psi = phi[..., None] * (P - P[:, :1]) * mask[..., None]
    psi[:, 0] -= psi.sum(axis=1)
    return psi


def _system_ppg1(phi, Vk, fam, X, h):
    r"""Scalar matrix of the PPG1 VC2 system (5.24): test derivatives at
    the masters only, :math:`G_t^{ki}_B \mathrel{+}= \varphi^{ki}\alpha^k_B
    + \psi^{ki}_e\beta^k_{eB}` (:func:`ppg1_second_order_functions`);
    block :math:`V^k\,(1, -\Delta X^{ki})\otimes(\varphi^{ki},
    \psi^{ki})` (rows ``(i, r)``, columns ``(k, s)``, lengths scaled by
    ``h``)."""
    mem, mask = fam.padded()
    nf, m = mem.shape
    d = X.shape[0]
    P = (X / h).T[mem]
    dX = (P - P[:, :1]) * mask[..., None]  # ΔX^{ki}, (k, i, c)
    left = np.concatenate([np.ones((nf, m, 1)), -dX], axis=-1)
    right = np.concatenate([phi[..., None],
                            ppg1_second_order_functions(phi, fam, X, h)],
                           axis=-1)
    M = Vk[:, None, None, None] * left[..., :, None] * right[..., None, :]
    return _blocks_to_csr(M * mask[..., None, None], fam, d)


def _blocks_to_csr(M, fam, d):
    """``(nf, m, d+1, d+1)`` blocks ``(k, i)`` → sparse rows ``(i, r)``,
    columns ``(k, s)``."""
    mem, mask = fam.padded()
    nf, m = mem.shape
    k = np.broadcast_to(np.arange(nf)[:, None], (nf, m))[mask]
    i = mem[mask]
    vals = M[mask]
    r = np.arange(d + 1)
    rows = (d + 1) * i[:, None, None] + r[None, :, None]
    cols = (d + 1) * k[:, None, None] + r[None, None, :]
    rows, cols = np.broadcast_arrays(rows, cols)
    return sp.csr_matrix((vals.ravel(), (rows.ravel(), cols.ravel())),
                         shape=((d + 1) * fam.n_particles, (d + 1) * nf))


def _corrected(G, alpha, phi, fam, x, h, method):
    """The derivatives ``G`` plus the VC2 correction of the unknowns
    ``alpha`` ``(nf, d + 1, d)``: PBG's at every member, PPG1's at the
    masters (functions of the test member)."""
    mem, mask = fam.padded()
    if method == "PBG":
        P = (x / h).T[mem]
        dX = (P - P[:, :1]) * mask[..., None]  # (k, j, c) scaled
        # correction c[k, j, B] = α[k, 0, B] + Σ_c β[k, c, B] ΔX[k, j, c]
        corr = alpha[:, None, 0, :] + np.einsum("kjc,kcB->kjB", dX,
                                                alpha[:, 1:, :])
        return G + phi[:, None, :, None] * (corr * mask[..., None])[
            :, :, None, :]
    psi = ppg1_second_order_functions(phi, fam, x, h)
    Gc = G.copy()
    Gc[:, 0] += (phi[..., None] * alpha[:, None, 0, :]
                 + np.einsum("kie,keB->kiB", psi, alpha[:, 1:, :])) \
        * mask[..., None]
    return Gc


def vc2_correction(system, area2, exclude=None, tol=1e-15, maxiter=None,
                   boundary="min-norm", method="PBG"):
    """Second-order VC correction of the PBG derivatives ``G`` of
    ``system`` (a :class:`~skfem_pg.discretization.vc.first_order.VCSystem`;
    quadratic consistent, e.g. WTE2; padded, ``index`` unused); ``area``
    :math:`A^i` ``(d, n)``, ``area2`` :math:`A_2^i` ``(d, d, n)`` about
    the origin 0, ``phi`` the correction function ``(nf, m)`` (V4; for
    PPG1 also V1/V3); ``boundary``
    ``"min-norm"`` (LSQR) or ``"s"`` (sparse LU).  ``method="PPG1"``
    corrects PPG1 test derivatives instead (``G`` nonzero at ``j = 0``
    only, ``dx`` the master weights): constraint (5.24), ansatz of
    :func:`_system_ppg1`.  Returns ``(G_corrected, VCReport)``.
    """
    G, dx, x, volumes, fam, area, phi, surface, _ = system
    if method not in ("PBG", "PPG1"):
        raise ValueError("VC2 is implemented for PBG and PPG1, not {!r}"
                         .format(method))
    if boundary not in ("min-norm", "s"):
        raise ValueError("VC2 boundary variant {!r} is not available: "
                         "'min-norm' or 's'".format(boundary))
    if boundary == "s" and exclude is not None:
        raise ValueError("vc_exclude is for the minimum-norm solve; "
                         "boundary 's' releases all surface constraints")
    t0 = time.perf_counter()
    d, n = x.shape
    active = volumes > 0
    h = np.mean(volumes[active]) ** (1.0 / d)
    r1, r2 = vc2_residuals(G, dx, fam, x, volumes, area, area2)
    A = (_system(phi, dx, fam, x, h) if method == "PBG"
         else _system_ppg1(phi, dx[:, 0], fam, x, h))
    # right-hand sides per component B: rows (i, 0) r1, (i, c) r2 / h
    rhs = -np.concatenate([r1[:, None, :], r2 / h], axis=1)  # (n, 1+d, B)
    keep = active.copy()
    if exclude is not None:
        keep[np.asarray(exclude, dtype=np.int64)] = False
    alpha = np.zeros((len(fam), d + 1, d))
    if boundary == "s":
        surf, _, _ = vc_boundary.surface_frames(
            area if surface is None else surface)
        keep[surf] = False
        cols = np.nonzero(keep[fam.masters])[0]
        # select the kept equations and unknowns; one LU (vc_boundary)
        R = sp.eye((d + 1) * n, format="csr")[np.repeat(keep, d + 1)]
        T = sp.eye((d + 1) * len(fam), format="csc")[:, (
            (d + 1) * cols[:, None] + np.arange(d + 1)).ravel()]
        try:
            sol = vc_boundary.solve_reduced(A, rhs.reshape(-1, d), R, T)
        except RuntimeError as err:
            raise VCSolveError("VC2 with boundary variant 's': {}"
                               .format(err)) from None
        alpha = sol.reshape(len(fam), d + 1, d)
        its, solver = 2, "direct"
    else:
        A = A[np.repeat(keep, d + 1)]
        rhs = rhs[keep]
        its, solver = 0, "lsqr"
        for b in range(d):
            sol = spl.lsqr(A, rhs[:, :, b].ravel(), atol=tol, btol=tol,
                           conlim=1e12, iter_lim=maxiter or 50 * A.shape[1])
            alpha[:, :, b] = sol[0].reshape(-1, d + 1)
            its = max(its, sol[2])
    Gc = _corrected(G, alpha, phi, fam, x, h, method)
    s1, s2 = vc2_residuals(Gc, dx, fam, x, volumes, area, area2)
    scale = h ** (d - 1)
    before = max(np.abs(r1[keep]).max(), np.abs(r2[keep]).max() / h)
    after = max(np.abs(s1[keep]).max(), np.abs(s2[keep]).max() / h)
    rep = VCReport(variant="VC2" if method == "PBG" else "VC2 (PPG1)",
                   solver=solver,
                   unknowns=(d + 1) * d * (len(cols) if boundary == "s"
                                           else len(fam)),
                   constraints=(d + 1) * d * int(keep.sum()),
                   residual_before=float(before / scale),
                   residual_after=float(after / scale), iterations=int(its),
                   seconds=time.perf_counter() - t0, boundary=boundary,
                   particle_residuals=np.maximum(
                       np.abs(s1).max(axis=1),
                       np.abs(s2).reshape(len(s2), -1).max(axis=1) / h)
                   * keep / scale)
    if boundary == "s":
        rep.area_correction = s1.T.copy()
        # r2 = S2 - X⊗S1 - (A2 - X⊗A) + V I: discrete minus FE A2 is
        # r2 + X⊗r1, stored as (d, d, n) like A2
        rep.area2_correction = np.moveaxis(
            s2 + x.T[:, :, None] * s1[:, None, :], 0, -1).copy()
    if exclude is None and boundary != "s":
        rep.notes.append("the full second-order system is incompatible: "
                         "pass the Dirichlet particles as vc_exclude")
    return Gc, rep
