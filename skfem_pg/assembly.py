r"""Batched assembly of scikit-fem forms on a :class:`FamilyBasis`.

scikit-fem's generic assembly calls the form once per pair of local basis
functions: ``(c·m)²`` calls (324 for a 2-D quad family, 6561 for a 3-D hex
family), each over all families.  A bilinear form is linear in the value and
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
    \qquad \hat G^{kji} = (\delta_{ij}, G^{kji}),

are then batched matrix products over families, scattered into a block
sparsity pattern computed once per basis.  Forms that use more than values
and gradients (``hess``...) raise; use ``form.assemble(basis)`` for those.
"""
import numpy as np
import scipy.sparse as sp
from skfem.assembly import BilinearForm, LinearForm
from skfem.assembly.form.form import FormExtraParams
from skfem.element import DiscreteField

from .basis import FamilyBasis
from .shape.common import chunks


def _probes(basis):
    """Unit probe fields: list of ``(component, channel, DiscreteField)``;
    channel 0 is the value, channel ``1 + b`` the derivative ``∂_b``."""
    d = basis.particles.dim
    nc = 1 if basis.ncomp is None else basis.ncomp
    out = []
    for a in range(nc):
        for beta in range(d + 1):
            val = np.zeros((nc, 1, 1))
            grad = np.zeros((nc, d, 1, 1))
            if beta == 0:
                val[a] = 1.0
            else:
                grad[a, beta - 1] = 1.0
            if basis.ncomp is None:
                val, grad = val[0], grad[0]
            out.append((a, beta, DiscreteField(val, grad)))
    return out


def _extended_gradients(basis, sl, channels):
    """``Ĝ[k, j, i, β]`` for families ``sl``; β over ``channels``."""
    mem, mask = basis.families.padded()
    G = basis.G[sl]
    nfc, m = G.shape[:2]
    parts = []
    for beta in channels:
        if beta == 0:
            parts.append(np.broadcast_to(np.eye(m) * mask[sl][:, None, :],
                                         (nfc, m, m)))
        else:
            parts.append(G[..., beta - 1])
    return np.stack(parts, axis=-1)


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


def _used_channels(C, nc, nch, axis_is_pair=True):
    """Channels (value/derivatives) with a non-zero coefficient."""
    used = []
    for beta in range(nch):
        idx = [a * nch + beta for a in range(nc)]
        if axis_is_pair:
            sub = np.concatenate([np.take(C, idx, axis=-2).ravel(),
                                  np.take(C, idx, axis=-1).ravel()])
        else:
            sub = np.take(C, idx, axis=-1).ravel()
        if np.any(sub != 0):
            used.append(beta)
    return used or [1]


def _setup(form, basis, kwargs):
    """``w``, probes and sizes shared by the bilinear and linear paths."""
    w = FormExtraParams({**basis.default_parameters(),
                         **form._normalize_asm_kwargs(kwargs, basis)})
    nf, m = basis.families.padded()[0].shape
    nc = 1 if basis.ncomp is None else basis.ncomp
    return w, _probes(basis), nf, m, nc, basis.particles.dim + 1


def _call(form, *args):
    try:
        return form.form(*args)
    except (TypeError, AttributeError, ValueError) as err:
        raise TypeError(
            "skfem_pg.assemble probes '{}' with value/gradient fields only "
            "and the form needs more ({}); assemble it with "
            "form.assemble(basis) instead".format(form.form.__name__, err)) \
            from err


def block_pattern(basis):
    """Node-level sparsity pattern of the basis, computed once and cached:
    CSR ``indptr`` and ``indices``, and for each chunk of families the
    distinct block indices ``u`` it touches and, per local pair
    ``(row member l, column member i)``, its index ``inv`` into ``u``."""
    if basis._pattern is None:
        mem, mask = basis.families.padded()
        nf, m = mem.shape
        n = basis.particles.n
        nc = 1 if basis.ncomp is None else basis.ncomp
        E = sp.csr_matrix((np.ones(mask.sum()),
                           (np.broadcast_to(np.arange(nf)[:, None],
                                            mem.shape)[mask], mem[mask])),
                          shape=(nf, n))
        S = (E.T @ E).tocsr()
        S.sort_indices()
        rows = np.repeat(np.arange(n, dtype=np.int64), np.diff(S.indptr))
        keys = rows * n + S.indices
        pieces = []
        for sl in chunks(nf, m * m * nc * nc * (basis.particles.dim + 1),
                         budget=2 ** 24):
            loc = (mem[sl, :, None].astype(np.int64) * n
                   + mem[sl, None, :]).ravel()
            u, inv = np.unique(np.searchsorted(keys, loc),
                               return_inverse=True)
            pieces.append((sl, u, inv.astype(np.int64)))
        basis._pattern = (S.indptr.copy(), S.indices.copy(), pieces)
    return basis._pattern


def _assemble_bilinear(form, basis, kwargs):
    w, probes, nf, m, nc, nch = _setup(form, basis, kwargs)
    # C[p, q]: p = trial probe (a, β), q = test probe (c, γ)
    values = [[_call(form, pu, pv, w) for (_, _, pv) in probes]
              for (_, _, pu) in probes]
    C, const = _coefficients(values, (nf, m))
    ch = _used_channels(C, nc, nch)
    sel = [a * nch + b for a in range(nc) for b in ch]
    C = C[..., sel, :][..., :, sel]
    nb = len(ch)

    def local_matrices(sl):
        Gh = _extended_gradients(basis, sl, ch)  # (k, j, i, β)
        X = Gh * basis.dx[sl][:, :, None, None]
        nfc = X.shape[0]
        if const:
            # T[k, j, i, a, c, γ] = sum_β X[k, j, i, β] C[a, β, c, γ]
            T = np.tensordot(X, C.reshape(nc, nb, nc, nb), axes=([3], [1]))
        else:
            Ck = C[sl].reshape((nfc, m, nc, nb, nc, nb))
            Ck = Ck.transpose(0, 1, 3, 2, 4, 5).reshape(nfc, m, nb, -1)
            T = np.matmul(X, Ck).reshape(nfc, m, m, nc, nc, nb)
        # K[k, i, a, c, l] = sum_{j, γ} T[k, j, i, a, c, γ] Ĝ[k, j, l, γ]
        Tm = T.transpose(0, 2, 3, 4, 1, 5).reshape(nfc, m * nc * nc, m * nb)
        Gm = Gh.transpose(0, 1, 3, 2).reshape(nfc, m * nb, m)
        K = np.matmul(Tm, Gm).reshape(nfc, m, nc, nc, m)
        # block (row l, col i) holds K[(l, c), (i, a)] as [c, a]
        return K.transpose(0, 4, 1, 3, 2)

    return assemble_local(basis, local_matrices)


def assemble_local(basis, local_matrices):
    """Sparse matrix from local family matrices.

    ``local_matrices(sl)`` returns, for the families ``sl``, an array of
    shape ``(nfc, m, m, c, c)``: block ``[k, l, i]`` couples row member
    ``l`` (test) with column member ``i`` (trial), components ``[c_l, c_i]``.
    Blocks are summed into the cached :func:`block_pattern`.
    """
    nc = 1 if basis.ncomp is None else basis.ncomp
    indptr, indices, pieces = block_pattern(basis)
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


def _assemble_linear(form, basis, kwargs):
    w, probes, nf, m, nc, nch = _setup(form, basis, kwargs)
    mem = basis.families.padded()[0]
    values = [[_call(form, pv, w) for (_, _, pv) in probes]]
    C, const = _coefficients(values, (nf, m))
    C = C[..., 0, :]  # (P,) or (nf, m, P)
    b = np.zeros(basis.N)
    for sl in chunks(nf, m * m * nc * nch, budget=2 ** 24):
        Gh = _extended_gradients(basis, sl, range(nch))
        dx = basis.dx[sl]
        Cs = C if const else C[sl]
        Cs = np.broadcast_to(Cs, dx.shape + (nc * nch,)) \
            .reshape(dx.shape + (nc, nch))
        # f[k, l, c] = sum_j dx sum_γ C[k, j, c, γ] Ĝ[k, j, l, γ]
        nfc = dx.shape[0]
        X = (dx[..., None, None] * Cs).transpose(0, 2, 1, 3) \
            .reshape(nfc, nc, m * nch)
        Gm = Gh.transpose(0, 1, 3, 2).reshape(nfc, m * nch, m)
        f = np.swapaxes(X @ Gm, -1, -2)
        dofs = nc * mem[sl][:, :, None] + np.arange(nc)
        b += np.bincount(dofs.ravel(), weights=f.ravel(), minlength=basis.N)
    return b


def assemble(form, basis, vbasis=None, **kwargs):
    """Assemble ``form`` on ``basis`` — the fast path for family bases.

    For a :class:`FamilyBasis` (and no different test basis), bilinear and
    linear forms are assembled with batched local matrices; anything else
    is passed on to ``form.assemble``.  The result equals
    ``form.assemble(basis, **kwargs)`` (see ``tests/test_assembly.py``).
    """
    if isinstance(basis, FamilyBasis) and (vbasis is None or
                                           vbasis is basis):
        if isinstance(form, BilinearForm):
            return _assemble_bilinear(form, basis, kwargs)
        if isinstance(form, LinearForm):
            return _assemble_linear(form, basis, kwargs)
    if vbasis is None:
        return form.assemble(basis, **kwargs)
    return form.assemble(basis, vbasis, **kwargs)
