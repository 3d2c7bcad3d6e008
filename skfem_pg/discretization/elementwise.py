r"""Per-element reductions on any basis the batched assembly supports: a
scikit-fem cell basis (elements × Gauss points) or a
:class:`~skfem_pg.FamilyBasis` (families × members, in size groups).

What the mixed formulations need beyond a form:

* :meth:`Elements.sum` — :math:`\sum_j w_{ej}\, a_{ej}` per element
  (a family's PBG weights :math:`w_{kj} = V^k V^j/V_H^k` (4.30) sum to
  :math:`V^k`, an FE element's Gauss weights to its volume);
* :meth:`Elements.spread` — a per-element value at every point;
* :meth:`Elements.polynomials` — constant and linear functions per
  element (the p, Theta spaces of UnlP0 (6.9) and U2P1 (6.10));
* :meth:`Elements.gram` — their weighted Gram matrices;
* :meth:`Elements.moments` — local moments
  :math:`C_e[i, c, a] = \sum_j w_{ej}\, \Phi_a^{ej} Q_{c\beta}^{ej}
  \partial_\beta N_i^{ej}` (order 0: the discrete
  :math:`\int_e Q : \nabla\delta u`, e.g. :math:`Q = J F^{-T}` for the
  pressure coupling of (6.3)/(6.5));
* :meth:`Elements.quadratic` — the sparse :math:`\sum_e C_e^T S_e C_e`
  (the condensed volumetric tangent (6.6));
* :meth:`Elements.coupling` — the sparse :math:`(N_u \times n_e q)`
  matrix with the moments as columns (the :math:`K_{up}` block of (6.5)).

Point data use the layout of the basis' ``interpolate``: FE ``(nel, nq)``,
family bases the flat ``(1, N_q)`` of :mod:`skfem_pg.discretization.layout`.
All loops run over size groups, never over elements.
"""
import numpy as np
import scipy.sparse as sp

from .assembly import batched_view, assemble_local
from .layout import is_family_basis


class Elements:
    """The elements (FE cells or families) of ``basis`` with their
    quadrature weights; ``n`` elements, ``volumes`` :math:`\\sum_j w_{ej}`."""

    def __init__(self, basis):
        self.basis = basis
        self.view = batched_view(basis)
        if self.view is None:
            raise TypeError("per-element reductions need a FamilyBasis or a "
                            "scikit-fem cell basis, got {}".format(
                                type(basis).__name__))
        self.family = is_family_basis(basis)
        self.n = (basis.layout.n_families if self.family
                  else basis.dx.shape[0])
        self.point_shape = ((1, basis.layout.n_points) if self.family
                            else basis.dx.shape)
        self.dx = (basis.flat_weights() if self.family else basis.dx)
        self.volumes = self.sum(np.ones(self.point_shape))

    def sum(self, a):
        r""":math:`\sum_j w_{ej} a_{ej}` per element, ``(..., n)``, of point
        data ``a`` ``(..., *point_shape)``."""
        a = np.asarray(a) * self.dx
        if not self.family:
            return a.sum(axis=-1)
        out = np.empty(a.shape[:-2] + (self.n,))
        for g in self.basis.layout:
            out[..., g.families] = a[..., 0, g.flat].sum(axis=-1)
        return out

    def spread(self, e):
        """Per-element values ``(..., n)`` at every point of the element,
        ``(..., *point_shape)``."""
        e = np.asarray(e)
        if not self.family:
            return e[..., None]
        out = np.empty(e.shape[:-1] + (self.basis.layout.n_points,))
        for g in self.basis.layout:
            out[..., g.flat] = e[..., g.families, None]
        return out[..., None, :]

    def positions(self):
        """Reference coordinates of the points, ``(d, *point_shape)``:
        Gauss points, or family members (the particles), or the points of
        ``family_quadrature="moments"``."""
        if self.family:
            L = self.basis.layout
            x = self.basis.particles.x
            points = getattr(self.basis, "points", None)
            flat = np.empty((x.shape[0], L.n_points))
            for g in L:
                flat[:, g.flat] = x[:, g.members] if points is None else \
                    np.moveaxis(points[g.families, :g.m], -1, 0)
            return flat[:, None, :]
        return np.asarray(self.basis.global_coordinates().value)

    def polynomials(self, order):
        r"""Per-element polynomial basis at the points,
        ``(q, *point_shape)``: ``order=0`` the constant (q = 1),
        ``order=1`` also :math:`(X - X_c^e)/h_e` (q = 1 + d), centred on
        the weighted centroid :math:`X_c^e = \sum_j w_{ej} X^{ej} / V_e`
        (for a family the volume barycentre (6.16)) and scaled by
        :math:`h_e = V_e^{1/d}`."""
        ones = np.ones((1,) + self.point_shape)
        if order == 0:
            return ones
        if order != 1:
            raise ValueError("polynomial order 0 or 1, got {!r}".format(
                order))
        X = self.positions()
        d = X.shape[0]
        Xc = self.sum(X) / self.volumes
        h = self.volumes ** (1.0 / d)
        return np.concatenate([ones, (X - self.spread(Xc))
                               / self.spread(h)])

    def gram(self, Phi, D=1.0):
        r""":math:`\sum_j w_{ej} D_{ej} \Phi_a^{ej}\Phi_b^{ej}`,
        ``(n, q, q)``."""
        PP = Phi[:, None] * Phi[None] * D
        return np.moveaxis(self.sum(PP), -1, 0)

    def moments(self, Q, Phi):
        r"""Per block ``(ne_b, nloc, nc, q)`` local moments
        :math:`C_e[i, c, a] = \sum_j w_{ej}\, \Phi_a^{ej}\, Q_{c\beta}^{ej}
        \partial_\beta N_i^{ej}` of point tensors ``Q``
        ``(d, d, *point_shape)`` against the polynomials ``Phi`` (order 0:
        the discrete :math:`\int_e Q : \nabla\delta u`); a list in the
        order of the view's blocks."""
        d = self.view.dim
        out = []
        for blk in self.view.blocks:
            Gh = blk.ext_grad(slice(None), range(1, d + 1))  # (k, j, i, b)
            ne, nq, nloc = Gh.shape[:3]
            Qw = self._take(Q, blk) * blk.dx  # (c, b, k, j)
            Pb = self._take(Phi, blk)  # (a, k, j)
            # batched matrix products over (j, b): (k, i, jb) @ (k, jb, c)
            Gt = np.ascontiguousarray(np.swapaxes(Gh, 1, 2)).reshape(
                ne, nloc, nq * d)
            QP = np.einsum("cbkj,akj->akjbc", Qw, Pb).reshape(
                len(Pb), ne, nq * d, -1)
            out.append(np.stack([Gt @ QPa for QPa in QP], axis=-1))
        return out

    def quadratic(self, C, S):
        r"""Sparse :math:`\sum_e C_e^T S_e C_e` (``N × N``) for the local
        moments ``C`` of :meth:`moments` and per-element symmetric ``S``
        ``(n, q, q)``."""
        return assemble_local(self.basis, self.quadratic_local(C, S),
                              self.view, transposed=True)

    def quadratic_local(self, C, S):
        """The local matrices of :meth:`quadratic` as a function for
        :func:`~.assembly.assemble_local` with ``transposed=True`` (or for
        ``assemble(..., local_extra=)``, which adds them to a form's in
        one scatter): ``[k, c_i, i, c_l, l]``."""
        Sb = [np.asarray(S)[blk.index] for blk in self.view.blocks]

        def local_matrices(bi, blk, sl):
            Cb = C[bi][sl]  # (k, l, c, a)
            k, m, nc, q = Cb.shape
            Ct = np.ascontiguousarray(Cb.transpose(0, 2, 1, 3)).reshape(
                k, nc * m, q)  # [k, (c, l), a]
            SC = Ct @ Sb[bi][sl]  # S symmetric: [k, (d, i), a]
            return (SC @ np.swapaxes(Ct, 1, 2)).reshape(k, nc, m, nc, m)
        return local_matrices

    def _take(self, a, blk):
        """Point data ``(..., *point_shape)`` of the block's elements,
        ``(..., ne_b, nq)``."""
        return self.basis.layout.take(a, blk.group) if self.family else a

    def _dofs(self, blk):
        nc = self.view.nc
        return nc * blk.conn[:, :, None] + np.arange(nc)  # (ne_b, nloc, nc)

    def coupling(self, C):
        r"""Sparse ``(N, n q)`` matrix whose column ``e q + a`` is the
        moment :math:`C_e[:, :, a]` of :meth:`moments` scattered to the
        global dofs (order 0: column ``e`` is the discrete
        :math:`\int_e Q : \nabla N`)."""
        rows, cols, vals = [], [], []
        q = C[0].shape[-1]
        for blk, Cb in zip(self.view.blocks, C):
            dofs = self._dofs(blk)[..., None]
            col = q * blk.index[:, None, None, None] + np.arange(q)
            rows.append(np.broadcast_to(dofs, Cb.shape).ravel())
            cols.append(np.broadcast_to(col, Cb.shape).ravel())
            vals.append(Cb.ravel())
        return sp.coo_matrix((np.concatenate(vals), (np.concatenate(rows),
                                                     np.concatenate(cols))),
                             shape=(self.basis.N, self.n * q)).tocsr()
