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
shape ``(ne, nq, c(d+1), c(d+1))``) are batched matrix products, scattered
into a block sparsity pattern that is
computed once per basis.  For a family basis ``k`` is a family, ``j`` a
member (quadrature point) and ``i`` a member (basis function) with
:math:`N^{kji} = \delta_{ij}`; for a scikit-fem cell basis ``k`` is an
element, ``j`` a quadrature point and ``i`` a scalar shape function — the
same code assembles FE comparators.  Forms that use more than values and
gradients (``hess`` ...) raise; use ``form.assemble(basis)`` for those.
"""
import numpy as np
import scipy.sparse as sp
import skfem as fem
from skfem.assembly import BilinearForm, LinearForm
from skfem.assembly.form.form import FormExtraParams
from skfem.element import DiscreteField, ElementVector

from .basis import FamilyBasis
from .shape.common import chunks


class _FamilyView:
    """Local arrays of a :class:`FamilyBasis`."""

    def __init__(self, basis):
        self.basis = basis
        self.conn, self.mask = basis.families.padded()
        self.nq = self.nloc = self.conn.shape[1]
        self.dim = basis.particles.dim
        self.scalar = basis.ncomp is None
        self.nc = 1 if self.scalar else basis.ncomp
        self.n_nodes = basis.particles.n
        self.dx = basis.dx

    def ext_grad(self, sl, channels):
        """``Ĝ[k, j, i, β]`` for families ``sl``; β over ``channels``."""
        G = self.basis.G[sl]
        nfc, m = G.shape[:2]
        parts = []
        for beta in channels:
            if beta == 0:
                parts.append(np.broadcast_to(
                    np.eye(m) * self.mask[sl][:, None, :], (nfc, m, m)))
            else:
                parts.append(G[..., beta - 1])
        return np.stack(parts, axis=-1)


class _CellView:
    """Local arrays of a scikit-fem ``CellBasis`` (scalar element or
    ``ElementVector`` of one): elements, quadrature points and the scalar
    shape functions, whose dof ``s`` carries vector dofs ``c·s + a``."""

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
        self.conn = sb.element_dofs.T
        self.mask = np.ones(self.conn.shape, dtype=bool)
        self.nloc = self.conn.shape[1]
        self.nq = basis.dx.shape[1]
        self.dim = basis.mesh.dim()
        self.n_nodes = sb.N
        self.dx = basis.dx
        expected = (self.nc * self.conn[:, :, None]
                    + np.arange(self.nc)).reshape(len(self.conn), -1).T
        if vector and not np.array_equal(expected, basis.element_dofs):
            raise NotImplementedError("unexpected vector dof numbering")

    def ext_grad(self, sl, channels):
        parts = []
        for beta in channels:
            if beta == 0:
                v = [np.asarray(self.sb.basis[i][0])[sl]
                     for i in range(self.nloc)]
            else:
                v = [self.sb.basis[i][0].grad[beta - 1][sl]
                     for i in range(self.nloc)]
            parts.append(np.stack(v, axis=-1))  # (k, q, i)
        return np.stack(parts, axis=-1)


def _view(basis):
    if isinstance(basis, FamilyBasis):
        return _FamilyView(basis)
    if isinstance(basis, fem.CellBasis) and not isinstance(
            basis.elem, fem.ElementComposite):
        return _CellView(basis)
    return None


def _probes(view):
    """Unit probe fields: list of ``(component, channel, DiscreteField)``;
    channel 0 is the value, channel ``1 + b`` the derivative ``∂_b``."""
    d, nc = view.dim, view.nc
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
            out.append((a, beta, DiscreteField(val, grad)))
    return out


def _coefficients(values, shape):
    """Stack form values; constant coefficients stay ``(P, Q)``."""
    arrs = [[np.asarray(v, dtype=float) for v in row] for row in values]
    if all(a.size == 1 for row in arrs for a in row):
        return np.array([[float(a.ravel()[0]) for a in row] for row in arrs]), \
            True
    out = np.empty(shape + (len(arrs), len(arrs[0])))
    for p, row in enumerate(arrs):
        for q, a in enumerate(row):
            out[..., p, q] = np.broadcast_to(a, shape)
    return out, False


def _used_channels(C, nc, nch):
    """Channels (value/derivatives) with a non-zero coefficient."""
    used = []
    for beta in range(nch):
        idx = [a * nch + beta for a in range(nc)]
        sub = np.concatenate([np.take(C, idx, axis=-2).ravel(),
                              np.take(C, idx, axis=-1).ravel()])
        if np.any(sub != 0):
            used.append(beta)
    return used or [1]


def _setup(form, basis, view, kwargs):
    """``w`` and probes shared by the bilinear and linear paths."""
    w = FormExtraParams({**basis.default_parameters(),
                         **form._normalize_asm_kwargs(kwargs, basis)})
    return w, _probes(view)


def _call(form, *args):
    try:
        return form.form(*args)
    except (TypeError, AttributeError, ValueError) as err:
        raise TypeError(
            "skfem_pg.assemble probes '{}' with value/gradient fields only "
            "and the form needs more ({}); assemble it with "
            "form.assemble(basis) instead".format(form.form.__name__, err)) \
            from err


def block_pattern(basis, view=None):
    """Node-level sparsity pattern of the basis, computed once and cached
    on it: CSR ``indptr`` and ``indices``, and for each chunk of elements
    the distinct block indices ``u`` it touches and, per local pair
    ``(row node l, column node i)``, its index ``inv`` into ``u``."""
    if getattr(basis, "_pattern", None) is None:
        view = _view(basis) if view is None else view
        conn, mask = view.conn, view.mask
        ne, m = conn.shape
        n = view.n_nodes
        E = sp.csr_matrix((np.ones(mask.sum()),
                           (np.broadcast_to(np.arange(ne)[:, None],
                                            conn.shape)[mask], conn[mask])),
                          shape=(ne, n))
        S = (E.T @ E).tocsr()
        S.sort_indices()
        rows = np.repeat(np.arange(n, dtype=np.int64), np.diff(S.indptr))
        keys = rows * n + S.indices
        pieces = []
        for sl in chunks(ne, view.nq * m * view.nc ** 2 * (view.dim + 1),
                         budget=2 ** 24):
            loc = (conn[sl, :, None].astype(np.int64) * n
                   + conn[sl, None, :]).ravel()
            u, inv = np.unique(np.searchsorted(keys, loc),
                               return_inverse=True)
            pieces.append((sl, u, inv.astype(np.int64)))
        basis._pattern = (S.indptr.copy(), S.indices.copy(), pieces)
    return basis._pattern


def _assemble_bilinear(form, basis, view, kwargs):
    w, probes = _setup(form, basis, view, kwargs)
    ne, nq, m, nc = len(view.conn), view.nq, view.nloc, view.nc
    nch = view.dim + 1
    # C[p, q]: p = trial probe (a, β), q = test probe (c, γ)
    if hasattr(form, "coefficients"):  # the form knows them: no probing
        C, const = form.coefficients(w, view.nc, nch), False
    else:
        values = [[_call(form, pu, pv, w) for (_, _, pv) in probes]
                  for (_, _, pu) in probes]
        C, const = _coefficients(values, (ne, nq))
    ch = _used_channels(C, nc, nch)
    sel = [a * nch + b for a in range(nc) for b in ch]
    C = C[..., sel, :][..., :, sel]
    nb = len(ch)

    def local_matrices(sl):
        Gh = view.ext_grad(sl, ch)  # (k, j, i, β)
        X = Gh * view.dx[sl][:, :, None, None]
        nfc = X.shape[0]
        if const:
            # T[k, j, i, a, c, γ] = sum_β X[k, j, i, β] C[a, β, c, γ]
            T = np.tensordot(X, C.reshape(nc, nb, nc, nb), axes=([3], [1]))
        else:
            Ck = C[sl].reshape((nfc, nq, nc, nb, nc, nb))
            Ck = Ck.transpose(0, 1, 3, 2, 4, 5).reshape(nfc, nq, nb, -1)
            T = np.matmul(X, Ck).reshape(nfc, nq, m, nc, nc, nb)
        # K[k, i, a, c, l] = sum_{j, γ} T[k, j, i, a, c, γ] Ĝ[k, j, l, γ]
        Tm = T.transpose(0, 2, 3, 4, 1, 5).reshape(nfc, m * nc * nc,
                                                   nq * nb)
        Gm = Gh.transpose(0, 1, 3, 2).reshape(nfc, nq * nb, m)
        K = np.matmul(Tm, Gm).reshape(nfc, m, nc, nc, m)
        # block (row l, col i) holds K[(l, c), (i, a)] as [c, a]
        return K.transpose(0, 4, 1, 3, 2)

    return assemble_local(basis, local_matrices, view)


def assemble_local(basis, local_matrices, view=None):
    """Sparse matrix from local element/family matrices.

    ``local_matrices(sl)`` returns, for the elements ``sl``, an array of
    shape ``(ne, m, m, c, c)``: block ``[k, l, i]`` couples row node ``l``
    (test) with column node ``i`` (trial), components ``[c_l, c_i]``.
    Blocks are summed into the cached :func:`block_pattern`.
    """
    view = _view(basis) if view is None else view
    nc = view.nc
    indptr, indices, pieces = block_pattern(basis, view)
    data = np.zeros((len(indices), nc, nc))
    for sl, u, inv in pieces:
        K = local_matrices(sl).reshape(-1, nc * nc)
        acc = np.stack([np.bincount(inv, weights=K[:, q], minlength=len(u))
                        for q in range(nc * nc)], axis=-1)
        data[u] += acc.reshape(len(u), nc, nc)
    N = basis.N
    if nc == 1:
        return sp.csr_matrix((data[:, 0, 0], indices, indptr), shape=(N, N))
    return sp.bsr_matrix((data, indices, indptr), shape=(N, N)).tocsr()


def _assemble_linear(form, basis, view, kwargs):
    w, probes = _setup(form, basis, view, kwargs)
    ne, nq, m, nc = len(view.conn), view.nq, view.nloc, view.nc
    nch = view.dim + 1
    values = [[_call(form, pv, w) for (_, _, pv) in probes]]
    C, const = _coefficients(values, (ne, nq))
    C = C[..., 0, :]  # (P,) or (ne, nq, P)
    b = np.zeros(basis.N)
    for sl in chunks(ne, nq * m * nc * nch, budget=2 ** 24):
        Gh = view.ext_grad(sl, range(nch))
        dx = view.dx[sl]
        Cs = C if const else C[sl]
        Cs = np.broadcast_to(Cs, dx.shape + (nc * nch,)) \
            .reshape(dx.shape + (nc, nch))
        # f[k, l, c] = sum_j dx sum_γ C[k, j, c, γ] Ĝ[k, j, l, γ]
        nfc = dx.shape[0]
        X = (dx[..., None, None] * Cs).transpose(0, 2, 1, 3) \
            .reshape(nfc, nc, nq * nch)
        Gm = Gh.transpose(0, 1, 3, 2).reshape(nfc, nq * nch, m)
        f = np.swapaxes(X @ Gm, -1, -2)
        dofs = nc * view.conn[sl][:, :, None] + np.arange(nc)
        b += np.bincount(dofs.ravel(), weights=f.ravel(), minlength=basis.N)
    return b


def assemble(form, basis, vbasis=None, **kwargs):
    """Assemble ``form`` on ``basis`` with batched local matrices.

    Works for :class:`FamilyBasis` and scikit-fem cell bases (scalar or
    ``ElementVector``) when no different test basis is given; anything else
    is passed on to ``form.assemble``.  The result equals
    ``form.assemble(basis, **kwargs)`` (``tests/test_assembly.py``).
    """
    view = _view(basis) if (vbasis is None or vbasis is basis) else None
    if view is not None:
        if isinstance(form, BilinearForm):
            return _assemble_bilinear(form, basis, view, kwargs)
        if isinstance(form, LinearForm):
            return _assemble_linear(form, basis, view, kwargs)
    if vbasis is None:
        return form.assemble(basis, **kwargs)
    return form.assemble(basis, vbasis, **kwargs)
