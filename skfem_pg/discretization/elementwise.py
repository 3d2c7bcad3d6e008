r"""Per-element reductions on any basis the batched assembly supports: a
scikit-fem cell basis (elements × Gauss points) or a
:class:`~skfem_pg.FamilyBasis` (families × members, in size groups).

What the mixed formulations need beyond a form:

* :meth:`Elements.sum` — :math:`\sum_j w_{ej}\, a_{ej}` per element
  (a family's PBG weights :math:`w_{kj} = V^k V^j/V_H^k` (4.30) sum to
  :math:`V^k`, an FE element's Gauss weights to its volume);
* :meth:`Elements.spread` — a per-element value at every point;
* :meth:`Elements.gradient_vectors` — local vectors
  :math:`g_e[i, c] = \sum_j w_{ej}\, Q_{c\beta}^{ej} \partial_\beta
  N_i^{ej}`, the discrete :math:`\int_e Q : \nabla\delta u` (e.g.
  :math:`Q = J F^{-T}` for the pressure coupling of (6.3)/(6.5));
* :meth:`Elements.outer` — the sparse :math:`\sum_e c_e\, g_e\otimes g_e`
  (the condensed volumetric tangent (6.6));
* :meth:`Elements.coupling` — the sparse :math:`(N_u \times n_e)` matrix
  with columns :math:`g_e` (the :math:`K_{up}` block of (6.5)).

Point data use the layout of the basis' ``interpolate``: FE ``(nel, nq)``,
family bases the flat ``(1, N_q)`` of :mod:`skfem_pg.discretization.layout`.
All loops run over size groups, never over elements.
"""
import numpy as np
import scipy.sparse as sp

from .assembly import _view, assemble_local


class Elements:
    """The elements (FE cells or families) of ``basis`` with their
    quadrature weights; ``n`` elements, ``volumes`` :math:`\\sum_j w_{ej}`."""

    def __init__(self, basis):
        self.basis = basis
        self.view = _view(basis)
        if self.view is None:
            raise TypeError("per-element reductions need a FamilyBasis or a "
                            "scikit-fem cell basis, got {}".format(
                                type(basis).__name__))
        self.family = hasattr(basis, "layout")
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

    def gradient_vectors(self, Q):
        r"""Per block ``(ne_b, nloc, nc)`` local vectors
        :math:`g_e[i, c] = \sum_j w_{ej} Q_{c\beta}^{ej} \partial_\beta
        N_i^{ej}` of point tensors ``Q`` ``(d, d, *point_shape)``; a list
        in the order of the view's blocks."""
        d = self.view.dim
        out = []
        for blk in self.view.blocks:
            Gh = blk.ext_grad(slice(None), range(1, d + 1))  # (k, j, i, b)
            Qb = self._take(Q, blk)  # (c, b, k, j)
            Qw = Qb * blk.dx
            out.append(np.einsum("cbkj,kjib->kic", Qw, Gh))
        return out

    def _take(self, a, blk):
        """Point data ``(..., *point_shape)`` of the block's elements,
        ``(..., ne_b, nq)``."""
        return self.basis.layout.take(a, blk.group) if self.family else a

    def _dofs(self, blk):
        nc = self.view.nc
        return nc * blk.conn[:, :, None] + np.arange(nc)  # (ne_b, nloc, nc)

    def outer(self, g, c):
        r"""Sparse :math:`\sum_e c_e\, g_e\otimes g_e` (``N × N``) for the
        local vectors ``g`` of :meth:`gradient_vectors` and per-element
        coefficients ``c`` ``(n,)``."""
        cb = [np.asarray(c)[blk.index] for blk in self.view.blocks]

        def local_matrices(bi, blk, sl):
            gb = g[bi][sl]  # (k, l, c)
            return (cb[bi][sl, None, None, None, None]
                    * gb[:, :, None, :, None] * gb[:, None, :, None, :])
        return assemble_local(self.basis, local_matrices, self.view)

    def coupling(self, g):
        r"""Sparse ``(N, n)`` matrix whose column ``e`` is :math:`g_e`
        scattered to the global dofs."""
        rows, cols, vals = [], [], []
        for blk, gb in zip(self.view.blocks, g):
            dofs = self._dofs(blk)
            rows.append(dofs.ravel())
            cols.append(np.broadcast_to(blk.index[:, None, None],
                                        dofs.shape).ravel())
            vals.append(gb.ravel())
        return sp.coo_matrix((np.concatenate(vals), (np.concatenate(rows),
                                                     np.concatenate(cols))),
                             shape=(self.basis.N, self.n)).tocsr()
