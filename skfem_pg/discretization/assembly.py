r"""Batched assembly of scikit-fem forms on family bases and FE cell bases.

scikit-fem's generic assembly calls the form once per pair of local basis
functions: ``(c·m)²`` calls (324 for a 2-D quad family, 6561 for a 3-D hex
family), each over all elements.  A bilinear form is linear in the value and
gradient of ``u`` and of ``v``, so it is fully described by its coefficients

.. math::

    a(u, v) = \sum_{p,q} C_{pq}(x)\; \hat u_p \, \hat v_q, \qquad
    \hat u = (u_a, \partial_b u_a),

which :func:`assemble` obtains by calling the form with unit *probe* fields
(``(c(d+1))²`` calls: 36 in 2-D, 144 in 3-D; constant-coefficient forms give
scalars).  The local matrices

.. math::

    K^k_{(l c),(i a)} = \sum_j w_{kj} \sum_{\beta\gamma}
        C_{(a\beta)(c\gamma)}^{kj}\, \hat G^{kji}_\beta \hat G^{kjl}_\gamma,
    \qquad \hat G^{kji} = (N^{kji}, G^{kji}),

(a form may instead provide them as ``form.coefficients(w, c, d + 1)``,
shape ``(ne, nq, c(d+1), c(d+1))``, or as a pair ``(C, channels)`` with
``C`` of shape ``(ne, nq, c, nb, c, nb)`` on the ``nb`` channels listed)
are batched matrix products, one batch per block of equal local size (for
family bases the size groups of :mod:`skfem_pg.discretization.layout`: no
padding), scattered into a block sparsity pattern that is computed once per
basis. For a family basis ``k`` is a family, ``j`` a member (quadrature point)
and ``i`` a member (basis function) with :math:`N^{kji} = \delta_{ij}`;
for a scikit-fem cell basis ``k`` is an
element, ``j`` a quadrature point and ``i`` a scalar shape function — the
same code assembles FE comparators.  Forms that use more than values and
gradients (``hess`` ...) raise; use ``form.assemble(basis)`` for those.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import skfem as fem
from skfem.assembly import BilinearForm, LinearForm
from skfem.assembly.form.form import FormExtraParams
from skfem.assembly.basis import AbstractBasis
from skfem.element import DiscreteField, ElementVector

from .basis import FamilyBasis, form_roles
from ..errors import NO_SECOND_DERIVATIVES
from .shape.common import chunks
from ..threads import kernel


class _Block:
    """Elements of equal local size: ``conn`` ``(ne_b, nloc)`` node
    indices, ``dx`` ``(ne_b, nq)`` weights, ``ext_grad(sl, channels)``
    the values/derivatives ``Ĝ[k, j, i, β]`` of elements ``sl``, ``take``
    the restriction of a quadrature-point array (point axes first) to the
    block; ``index`` its elements (families) in the basis, ``G`` and
    ``group`` (family blocks) its unpadded derivatives and size group."""

    def __init__(self, conn, dx, ext_grad, take, index, G=None, group=None,
                 grad_t=None):
        self.conn, self.dx, self.ext_grad, self.take = conn, dx, ext_grad, \
            take
        self.index, self.G, self.group = index, G, group
        self.grad_t = grad_t  # gradients as (ne, nq·d, nloc), or None
        self.ne, self.nloc = conn.shape
        self.nq = dx.shape[1]


class _FamilyView:
    """Local arrays of a :class:`FamilyBasis`, one block per family size
    (:mod:`skfem_pg.discretization.layout`): no padding."""

    def __init__(self, basis):
        self.basis = basis
        self.layout = L = basis.layout
        self.dim = basis.particles.dim
        self.scalar = basis.ncomp is None
        self.nc = 1 if self.scalar else basis.ncomp
        self.n_nodes = basis.particles.n
        self.shape = (L.n_families, L.m_max)
        values = basis.grouped_values() or [None] * len(L)
        self.blocks = [
            _Block(g.members, dx, self._ext_grad(G, N),
                   (lambda C, g=g: L.take(C, g, axis=0)), g.families, G, g,
                   grad_t=lambda sl, b=b: basis.grouped_gradients_t()[b][sl])
            for b, (g, G, dx, N) in enumerate(zip(
                L, basis.grouped_gradients(), basis.grouped_weights(),
                values))]

    @staticmethod
    def _ext_grad(G, N=None):
        m = G.shape[1]

        def ext_grad(sl, channels):
            r"""``Ĝ[k, j, i, β]`` for families ``sl``; β over
            ``channels`` (β = 0: the values, :math:`\delta_{ij}` where
            the members are the quadrature points, else ``N``)."""
            Gs = G[sl]
            if list(channels) == list(range(1, Gs.shape[-1] + 1)):
                return Gs  # the gradients alone: no copy
            parts = [(np.broadcast_to(np.eye(m), Gs.shape[:3]) if N is None
                      else N[sl]) if beta == 0
                     else Gs[..., beta - 1] for beta in channels]
            return np.stack(parts, axis=-1)
        return ext_grad

    def coefficient_shape(self, shapes):
        """Quadrature axes of the form's values: padded ``(nf, m_max)`` or
        flat ``(1, N_q)``."""
        for sh in shapes:
            if len(sh) >= 2 and self.layout.is_flat(sh[-2:]):
                return (1, self.layout.n_points)
        return self.shape


class _CellView:
    """Local arrays of a scikit-fem ``CellBasis`` (scalar element or
    ``ElementVector`` of one): elements, quadrature points and the scalar
    shape functions, whose dof ``s`` carries vector dofs ``c·s + a``; one
    block."""

    def __init__(self, basis):
        elem = basis.elem
        vector = isinstance(elem, ElementVector)
        self.basis = basis
        self.scalar = not vector
        self.nc = elem.dim if vector else 1
        sb = getattr(basis, "_pg_scalar_basis", None)
        if sb is None:
            sb = basis if not vector else fem.Basis(
                basis.mesh, elem.elem, mapping=basis.mapping,
                quadrature=basis.quadrature, elements=basis.tind)
            basis._pg_scalar_basis = sb
        self.sb = sb
        conn = sb.element_dofs.T
        self.dim = basis.mesh.dim()
        self.n_nodes = sb.N
        self.shape = basis.dx.shape
        self.blocks = [_Block(conn, basis.dx, self._ext_grad,
                              lambda C: C, np.arange(len(conn)))]
        expected = (self.nc * conn[:, :, None]
                    + np.arange(self.nc)).reshape(len(conn), -1).T
        if vector and not np.array_equal(expected, basis.element_dofs):
            raise NotImplementedError("unexpected vector dof numbering")

    def _ext_grad(self, sl, channels):
        nloc = self.blocks[0].nloc
        parts = []
        for beta in channels:
            if beta == 0:
                v = [np.asarray(self.sb.basis[i][0])[sl]
                     for i in range(nloc)]
            else:
                v = [self.sb.basis[i][0].grad[beta - 1][sl]
                     for i in range(nloc)]
            parts.append(np.stack(v, axis=-1))  # (k, q, i)
        return np.stack(parts, axis=-1)

    def coefficient_shape(self, shapes):
        return self.shape


def supports(basis):
    """Whether :func:`assemble` has a batched path for ``basis``."""
    return isinstance(basis, FamilyBasis) or hasattr(
        basis, "batched_view") or (
        isinstance(basis, fem.CellBasis)
        and not isinstance(basis.elem, fem.ElementComposite))


def _generic(form, *bases, **kwargs):
    """scikit-fem's own ``assemble`` of the form's scikit-fem class (also
    for the subclasses of :mod:`skfem_pg.discretization.forms`, without
    recursion)."""
    for cls in (BilinearForm, LinearForm, fem.Functional):
        if isinstance(form, cls):
            return cls.assemble(form, *bases, **kwargs)
    return form.assemble(*bases, **kwargs)


def batched_view(basis):
    if not supports(basis):
        return None
    if hasattr(basis, "batched_view"):  # e.g. the blended PG2 basis
        return basis.batched_view()
    return (_FamilyView if isinstance(basis, FamilyBasis)
            else _CellView)(basis)


def _probes(view):
    """Unit probe fields: list of ``(component, channel, DiscreteField)``;
    channel 0 is the value, channel ``1 + b`` the derivative ``∂_b``.  A
    particle basis' fields (family, PG2) refuse second derivatives by
    name; an FE view's fall back to scikit-fem's generic assembly, which
    has them."""
    d, nc = view.dim, view.nc
    hess = None if isinstance(view, _CellView) else NO_SECOND_DERIVATIVES
    out = []
    for a in range(nc):
        for beta in range(d + 1):
            val = np.zeros((nc, 1, 1))
            grad = np.zeros((nc, d, 1, 1))
            if beta == 0:
                val[a] = 1.0
            else:
                grad[a, beta - 1] = 1.0
            if view.scalar:
                val, grad = val[0], grad[0]
            out.append((a, beta, DiscreteField(val, grad, hess=hess)))
    return out


def _coefficients(values, view):
    """Stack form values; constant coefficients stay ``(P, Q)``, others
    get the view's quadrature axes first: padded / cell ``(ne, nq)`` or
    flat ``(1, N_q)``."""
    arrs = [[np.asarray(v, dtype=float) for v in row] for row in values]
    if all(a.size == 1 for row in arrs for a in row):
        return np.array([[float(a.ravel()[0]) for a in row]
                         for row in arrs]), True
    shape = view.coefficient_shape([a.shape for row in arrs for a in row])
    out = np.empty(shape + (len(arrs), len(arrs[0])))
    for p, row in enumerate(arrs):
        for q, a in enumerate(row):
            out[..., p, q] = np.broadcast_to(a, shape)
    return out, False


def _used_channels(C, nc, nch):
    """Channels (value/derivatives) with a non-zero coefficient."""
    nz = np.asarray(C != 0).reshape(-1, nc, nch, nc, nch)
    used = np.flatnonzero(nz.any(axis=(0, 1, 3, 4))
                          | nz.any(axis=(0, 1, 2, 3)))
    return [int(b) for b in used] or [1]


def check_coefficients(basis, kwargs):
    """Named errors for form coefficients a family basis cannot use:
    arrays at another basis' quadrature points (an FE basis' ``(cells,
    points)``: PG integrates at the family members, ``(nf, m)``) and dof
    vectors of another length (a field of another element)."""
    nf, m = basis.families.padded()[0].shape
    for k, v in kwargs.items():
        if isinstance(v, DiscreteField) or (isinstance(v, np.ndarray)
                                            and v.ndim > 1):
            shape = np.asarray(v).shape
            if shape[-2:] not in ((nf, m), (1, basis.layout.n_points)):
                raise ValueError(
                    "form coefficient {!r} has its values at {} points "
                    "(shape {}); a FamilyBasis integrates at its family "
                    "members, ({}, {}) points.  Data from an FE basis' "
                    "quadrature cannot be used here: pass a callable of "
                    "the position and evaluate it in the form at w.x, a "
                    "dof vector of this basis (length {}), "
                    "basis.interpolate(u) of this basis, or for a value "
                    "per cell (a P0 field) skfem_pg.discretization."
                    "coefficients.cell_values_at_members(basis, values)"
                    .format(k, shape[-2:], shape, nf, m, basis.N))
        elif isinstance(v, np.ndarray) and v.ndim == 1 \
                and basis.mesh is not None \
                and v.shape[0] == basis.mesh.nelements != basis.N:
            raise ValueError(
                "form coefficient {!r} has one value per cell ({}); a "
                "FamilyBasis integrates at its family members: evaluate it "
                "there with skfem_pg.discretization.coefficients."
                "cell_values_at_members(basis, {}) (an interface family "
                "then sees both sides)".format(k, v.shape[0], k))
        elif isinstance(v, np.ndarray) and v.ndim == 1 \
                and v.shape[0] != basis.N:
            raise ValueError(
                "form coefficient {!r} has {} entries, this FamilyBasis {} "
                "dofs: a field of another basis (another element) must "
                "first be sampled at the particles, e.g. "
                "fe_basis.probes(basis.particles.x) @ u_fe per component"
                .format(k, v.shape[0], basis.N))


def _setup(form, basis, view, kwargs):
    """``w`` and probes shared by the bilinear and linear paths."""
    if isinstance(basis, FamilyBasis):
        check_coefficients(basis, kwargs)
    w = FormExtraParams({**basis.default_parameters(),
                         **form._normalize_asm_kwargs(kwargs, basis)})
    return w, _probes(view)


class ProbeError(TypeError):
    """The form needs more than unit value/gradient probes (Hessians,
    shapes, ...): only scikit-fem's generic assembly can evaluate it."""


def _call(form, *args):
    try:
        out = form.form(*args)
    except (TypeError, AttributeError, ValueError) as err:
        raise ProbeError(
            "skfem_pg.assemble probes '{}' with value/gradient fields only "
            "and the form needs more ({}); assemble it with "
            "form.assemble(basis) instead".format(form.form.__name__, err)) \
            from err
    nd = np.ndim(out)
    if nd not in (0, 2):
        field = args[0]
        scalar = np.ndim(field) == 2
        raise ValueError(
            "form '{}' returned an array of shape {} for one pair of {} "
            "basis functions, where one value per (element, quadrature "
            "point) is expected: the form is written for {} fields. {}"
            .format(form.form.__name__, np.shape(out),
                    "scalar" if scalar else "vector",
                    "vector" if scalar else "scalar (or other-dimensional)",
                    "Build the basis with dim= the number of components "
                    "(e.g. FamilyBasis(..., dim=2) for 2-D displacements)"
                    if scalar else "Check the basis' dim against the form"))
    return out


def block_pattern(basis, view=None):
    """Node-level sparsity pattern of the basis, computed once and cached
    on it: CSR ``indptr`` and ``indices``, and per block and chunk of its
    elements ``(block, slice, u, inv)``: the distinct block indices ``u``
    the chunk touches and, per local pair ``(row node l, column node i)``,
    its index ``inv`` into ``u``."""
    if getattr(basis, "_pattern", None) is None:
        view = batched_view(basis) if view is None else view
        n = view.n_nodes
        rows_e, cols_n = [], []
        start = 0
        for blk in view.blocks:
            rows_e.append(np.repeat(np.arange(start, start + blk.ne),
                                    blk.nloc))
            cols_n.append(blk.conn.ravel())
            start += blk.ne
        E = sp.csr_matrix((np.ones(sum(len(r) for r in rows_e)),
                           (np.concatenate(rows_e), np.concatenate(cols_n))),
                          shape=(start, n))
        S = (E.T @ E).tocsr()
        S.sort_indices()
        rows = np.repeat(np.arange(n, dtype=np.int64), np.diff(S.indptr))
        keys = rows * n + S.indices
        pieces = []
        for bi, blk in enumerate(view.blocks):
            conn, m = blk.conn, blk.nloc
            for sl in chunks(blk.ne, blk.nq * m * view.nc ** 2
                             * (view.dim + 1), budget=2 ** 24):
                loc = (conn[sl, :, None].astype(np.int64) * n
                       + conn[sl, None, :]).ravel()
                u, inv = np.unique(np.searchsorted(keys, loc),
                                   return_inverse=True)
                pieces.append((bi, sl, u, inv.astype(
                    np.int32 if len(u) < 2 ** 31 else np.int64)))
        basis._pattern = (S.indptr.copy(), S.indices.copy(), pieces)
    return basis._pattern


def _assemble_bilinear(form, basis, view, vview, kwargs, local_extra=None):
    w, probes = _setup(form, basis, view, kwargs)
    nc = view.nc
    nch = view.dim + 1
    # C[p, q]: p = trial probe (a, β), q = test probe (c, γ)
    ch = None
    if hasattr(form, "coefficients"):  # the form knows them: no probing
        C = form.coefficients(w, view.nc, nch)
        if isinstance(C, tuple):  # already restricted to its channels
            C, ch = C
        const = False
    else:
        values = [[_call(form, pu, pv, w) for (_, _, pv) in probes]
                  for (_, _, pu) in probes]
        C, const = _coefficients(values, view)
    if ch is None:
        ch = _used_channels(C, nc, nch)
        sel = [a * nch + b for a in range(nc) for b in ch]
        C = C[..., sel, :][..., :, sel]
    nb = len(ch)
    gradients_only = ch == list(range(1, nch))
    Cb = {}  # weighted coefficients per block

    def weighted(Cq, dx):
        """``w_kj C[k, j]`` as ``(ne, nq, c·nb, c·nb)``, a new array."""
        Cq = np.asarray(Cq)
        Cq = Cq.reshape(Cq.shape[:2] + (nc * nb, nc * nb))
        w = dx[:, :, None, None]
        if np.may_share_memory(Cq, C) or Cq.shape[:2] != dx.shape:
            return Cq * w
        Cq *= w  # the block's own gather: weighted in place
        return Cq

    def local_matrices(bi, blk, sl):
        Gh = blk.ext_grad(sl, ch)  # trial (k, j, i, β)
        Gv = Gh if vview is view else vview.blocks[bi].ext_grad(sl, ch)
        nfc, nq, m = Gh.shape[:3]
        # GT[k, i, (j, β)] = Ĝ[k, j, i, β]: a view of the basis' cached
        # transposed gradients where the form uses the gradients only
        if gradients_only and blk.grad_t is not None:
            GT = np.swapaxes(blk.grad_t(sl), -1, -2)[:, None]
        else:
            GT = Gh.transpose(0, 2, 1, 3).reshape(nfc, 1, m, nq * nb)
        # Ca[k, a, j, (β, c), γ] = w_kj C[k, j, (a, β), (c, γ)]
        if const:
            Cw = weighted(C.reshape(1, 1, -1), blk.dx[sl])
        else:
            if bi not in Cb:
                Cb.clear()
                Cb[bi] = weighted(blk.take(C), blk.dx)  # one gather
            Cw = Cb[bi][sl]
        Ca = Cw.reshape(nfc, nq, nc, nb * nc, nb).transpose(0, 2, 1, 3, 4)
        # Y[k, a, (j, β), (c, l)]
        #     = sum_γ Ca[k, a, j, (β, c), γ] Ĝv[k, j, l, γ]  (test)
        # (written C-ordered: numpy would follow Ca's strides and the
        # reshape below would copy)
        Y = np.matmul(Ca, np.swapaxes(Gv, -1, -2)[:, None],
                      out=np.empty((nfc, nc, nq, nb * nc, m)))
        Y = Y.reshape(nfc, nc, nq * nb, nc * m)
        # K[k, a, i, c, l]
        #     = sum_{j, β} GT[k, i, (j, β)] Y[k, a, (j, β), (c, l)]
        K = np.matmul(GT, Y).reshape(nfc, nc, m, nc, m)
        if local_extra is not None:
            K += local_extra(bi, blk, sl)
        return K

    return assemble_local(basis, local_matrices, view, transposed=True)


def entry_index(basis, view=None, transposed=False):
    """Where each local entry goes in the CSR data of the assembled matrix,
    computed once per layout and cached on the basis (beside
    :func:`block_pattern`): per chunk of :func:`block_pattern` ``(lo,
    idx)``, ``idx`` (int32 where it fits) the CSR data position minus
    ``lo`` of every entry of the chunk's local matrices in
    :func:`assemble_local`'s layout (``transposed``: ``[k, c_i, i, c_l,
    l]``, else ``[k, l, i, c_l, c_i]``), so a chunk is summed into the
    data by one ``bincount`` over ``[lo, lo + idx.max()]`` with no copy
    of its local matrices; and the CSR ``indptr`` / ``indices`` of the
    ``N × N`` matrix (component ``c`` of node ``n`` is dof ``nc·n + c``).

    The index holds one integer per local entry: about the memory of the
    assembled matrix itself (3 local entries per non-zero on 3-D kNN
    families)."""
    cache = getattr(basis, "_entry_index", None)
    if cache is None:
        cache = basis._entry_index = {}
    if transposed in cache:
        return cache[transposed]
    view = batched_view(basis) if view is None else view
    nc = view.nc
    indptr, indices, pieces = block_pattern(basis, view)
    n = len(indptr) - 1
    indptr = indptr.astype(np.int64)
    rowlen = np.diff(indptr)
    brow = np.repeat(np.arange(n), rowlen)
    # CSR position of component (0, 0) of node-level entry e and the
    # distance between the component rows of its node row
    base = nc * nc * indptr[brow] + (np.arange(len(indices))
                                     - indptr[brow]) * nc
    stride = nc * rowlen[brow]
    nnz = nc * nc * len(indices)
    dtype = np.int32 if nnz < 2 ** 31 else np.int64
    comp = np.arange(nc)
    out = []
    for bi, sl, u, inv in pieces:
        m = view.blocks[bi].nloc
        e = u[inv].reshape(-1, m, m)  # [k, l, i]
        if transposed:  # [k, c_i, i, c_l, l]
            e = e.transpose(0, 2, 1)[:, None, :, None, :]
            pos = base[e] + comp[:, None] * stride[e] \
                + comp[:, None, None, None]
        else:  # [k, l, i, c_l, c_i]
            e = e[..., None, None]
            pos = base[e] + comp[:, None] * stride[e] + comp
        lo = int(pos.min())
        out.append((lo, (pos - lo).astype(dtype).ravel()))
    csr_indptr = np.empty(nc * n + 1, dtype=dtype)
    csr_indptr[:-1] = (nc * nc * indptr[:-1, None]
                       + comp * nc * rowlen[:, None]).ravel()
    csr_indptr[-1] = nnz
    csr_indices = np.empty(nnz, dtype=indices.dtype)
    at = base[:, None, None] + comp[:, None] * stride[:, None, None] + comp
    csr_indices[at] = (nc * indices[:, None, None] + comp).astype(
        indices.dtype)
    cache[transposed] = (out, csr_indptr, csr_indices)
    return cache[transposed]


@kernel
def assemble_local(basis, local_matrices, view=None, transposed=False):
    """Sparse matrix from local element/family matrices.

    ``local_matrices(b, block, sl)`` returns, for the elements ``sl`` of
    block ``b`` (``block.conn``: their nodes; a :class:`FamilyBasis` has a
    block per family size, ``block.G`` its unpadded derivatives and
    ``block.group`` its :class:`~skfem_pg.discretization.layout.Group`), an
    array of shape ``(ne, m, m, c, c)``: entry ``[k, l, i]`` couples row node
    ``l`` (test) with column node ``i`` (trial), components
    ``[c_l, c_i]``.  With ``transposed=True`` it returns the
    component-major transpose ``(ne, c, m, c, m)`` indexed
    ``[k, c_i, i, c_l, l]`` instead (what a batched product yields
    without a strided copy).  Each chunk's entries are summed into the
    CSR data by one ``bincount`` through the cached :func:`entry_index`
    (no copy of the local matrices).
    """
    view = batched_view(basis) if view is None else view
    pieces = block_pattern(basis, view)[2]
    index, indptr, indices = entry_index(basis, view, transposed)
    data = np.zeros(int(indptr[-1]))
    for (bi, sl, _, _), (lo, idx) in zip(pieces, index):
        K = local_matrices(bi, view.blocks[bi], sl)
        part = np.bincount(idx, weights=K.ravel())
        data[lo:lo + len(part)] += part
    N = basis.N
    return sp.csr_matrix((data, indices.copy(), indptr.copy()),
                         shape=(N, N))


def _assemble_linear(form, basis, view, kwargs):
    w, probes = _setup(form, basis, view, kwargs)
    nc = view.nc
    nch = view.dim + 1
    values = [[_call(form, pv, w) for (_, _, pv) in probes]]
    C, const = _coefficients(values, view)
    C = C[..., 0, :]  # (P,) or (points..., P)
    # the channels the form uses (an internal force: the gradients only)
    used = np.asarray(C != 0).reshape(-1, nc, nch).any(axis=(0, 1))
    ch = [beta for beta in range(nch) if used[beta]] or [0]
    sel = [a * nch + beta for a in range(nc) for beta in ch]
    C = C[..., sel]
    nu = len(ch)
    b = np.zeros(basis.N)
    for blk in view.blocks:
        Cblk = C if const else blk.take(C)
        m, nq = blk.nloc, blk.nq
        for sl in chunks(blk.ne, nq * m * nc * nu, budget=2 ** 24):
            dx = blk.dx[sl]
            nfc = dx.shape[0]
            Cs = np.broadcast_to(Cblk if const else Cblk[sl],
                                 dx.shape + (nc * nu,)) \
                .reshape(dx.shape + (nc, nu))
            # f[k, l, c] = sum_j dx sum_γ C[k, j, c, γ] Ĝ[k, j, l, γ]
            X = (dx[..., None, None] * Cs).transpose(0, 2, 1, 3) \
                .reshape(nfc, nc, nq * nu)
            if blk.grad_t is not None and ch == list(range(1, nch)):
                Gm = blk.grad_t(sl)
            else:
                Gm = blk.ext_grad(sl, ch).transpose(0, 1, 3, 2).reshape(
                    nfc, nq * nu, m)
            f = np.swapaxes(X @ Gm, -1, -2)
            dofs = nc * blk.conn[sl][:, :, None] + np.arange(nc)
            b += np.bincount(dofs.ravel(), weights=f.ravel(),
                             minlength=basis.N)
    return b


@kernel
def assemble(form: fem.assembly.form.Form, basis: AbstractBasis,
             vbasis: AbstractBasis | None = None,
             **kwargs) -> sp.csr_matrix | np.ndarray | float:
    """Assemble ``form`` on ``basis`` with batched local matrices.

    Works for :class:`FamilyBasis` and scikit-fem cell bases (scalar or
    ``ElementVector``); the result equals ``form.assemble(basis, **kwargs)``
    (``tests/test_assembly.py``).  The test basis is ``vbasis``, by default
    ``basis`` itself or, for a Petrov–Galerkin family basis, ``basis.test``
    (also for linear forms: PPG internal forces).  Other combinations are
    passed on to ``form.assemble``.

    ``local_extra(b, block, sl)`` (bilinear forms on the batched path):
    local matrices in :func:`assemble_local`'s transposed layout ``(ne, c,
    m, c, m)`` added to the form's before the one scatter — a term that is
    not a pointwise form, e.g. the condensed volumetric stiffness of a
    mixed formulation (:meth:`~.elementwise.Elements.quadratic_local`).
    """
    local_extra = kwargs.pop("local_extra", None)
    if vbasis is None:
        vbasis = test_basis(form, basis)
    with form_roles(form, basis, vbasis, kwargs):
        return _assemble(form, basis, vbasis, kwargs, local_extra)


def test_basis(form, basis):
    """The basis a form tests with when none is given: ``basis.test`` of
    a Petrov–Galerkin family basis (bilinear and linear forms: PPG
    internal forces), else ``basis`` itself."""
    test = getattr(basis, "test", None)
    if test is None or isinstance(form, fem.Functional):
        return basis
    return test


def _assemble(form, basis, vbasis, kwargs, local_extra):
    view = batched_view(basis)
    if vbasis is basis:
        vview = view
    elif (isinstance(basis, FamilyBasis) and isinstance(vbasis, FamilyBasis)
          and vbasis.families is basis.families):
        vview = _FamilyView(vbasis)
    else:
        vview = None
    if view is not None and vview is not None:
        if isinstance(form, BilinearForm):
            return _assemble_bilinear(form, basis, view, vview, kwargs,
                                      local_extra)
        if isinstance(form, LinearForm):
            return _assemble_linear(form, basis, vview, kwargs)
    if local_extra is not None:
        raise ValueError("local_extra needs a bilinear form on the batched "
                         "path (a FamilyBasis or a scikit-fem cell basis "
                         "tested with itself)")
    if isinstance(form, LinearForm):
        return _generic(form, vbasis, **kwargs)
    if vbasis is basis or isinstance(form, fem.Functional):
        return _generic(form, basis, **kwargs)
    return _generic(form, basis, vbasis, **kwargs)


class FixedPattern:
    """A fixed sparsity pattern of COO entries ``(rows, cols)`` (``N × N``):
    the CSR structure is found once, then :meth:`matrix` sums each new set
    of values into it by one ``bincount`` — for tangents whose local
    blocks do not fit a form (the global p / Theta blocks of
    :class:`~skfem_pg.formulations.NodalPressure`, the master-point
    volumetric term of PPG UnlP0)."""

    def __init__(self, rows, cols, N):
        A = sp.coo_matrix((np.arange(1, len(rows) + 1, dtype=float),
                           (rows, cols)), shape=(N, N)).tocsr()
        A.sum_duplicates()
        A.sort_indices()
        self.indptr, self.indices = A.indptr, A.indices
        # position of every COO entry in the CSR data
        key = rows.astype(np.int64) * N + cols
        csr_rows = np.repeat(np.arange(N), np.diff(A.indptr))
        csr_key = csr_rows.astype(np.int64) * N + A.indices
        self.pos = np.searchsorted(csr_key, key)
        self.N, self.nnz = N, len(A.indices)

    def matrix(self, values):
        data = np.bincount(self.pos, values, minlength=self.nnz)
        return sp.csr_matrix((data, self.indices, self.indptr),
                             shape=(self.N, self.N))
