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
from .threads import kernel


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


def supports(basis):
    """Whether :func:`assemble` has a batched path for ``basis``."""
    return isinstance(basis, FamilyBasis) or (
        isinstance(basis, fem.CellBasis)
        and not isinstance(basis.elem, fem.ElementComposite))


def _generic(form, *bases, **kwargs):
    """scikit-fem's own ``assemble`` of the form's scikit-fem class (also
    for the subclasses of :mod:`skfem_pg.forms`, without recursion)."""
    for cls in (BilinearForm, LinearForm, fem.Functional):
        if isinstance(form, cls):
            return cls.assemble(form, *bases, **kwargs)
    return form.assemble(*bases, **kwargs)


def _view(basis):
    if not supports(basis):
        return None
    return (_FamilyView if isinstance(basis, FamilyBasis)
            else _CellView)(basis)


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
    nz = np.asarray(C != 0).reshape(-1, nc, nch, nc, nch)
    used = np.flatnonzero(nz.any(axis=(0, 1, 3, 4))
                          | nz.any(axis=(0, 1, 2, 3)))
    return [int(b) for b in used] or [1]


def _setup(form, basis, view, kwargs):
    """``w`` and probes shared by the bilinear and linear paths."""
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


def _assemble_bilinear(form, basis, view, vview, kwargs):
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
        Gh = view.ext_grad(sl, ch)  # trial (k, j, i, β)
        Gv = Gh if vview is view else vview.ext_grad(sl, ch)  # test
        nfc = Gh.shape[0]
        # GT[k, i, (j, β)] = w_kj Ĝ[k, j, i, β]
        GT = (Gh * view.dx[sl][:, :, None, None]).transpose(0, 2, 1, 3) \
            .reshape(nfc, 1, m, nq * nb)
        # Ca[k, a, j, (β, c), γ] = C[k, j, (a, β), (c, γ)]
        if const:
            Ca = C.reshape(1, nc, 1, nb * nc, nb)
        else:
            Ca = C[sl].reshape(nfc, nq, nc, nb * nc, nb).transpose(
                0, 2, 1, 3, 4)
        # Y[k, a, (j, β), (c, l)]
        #     = sum_γ Ca[k, a, j, (β, c), γ] Ĝv[k, j, l, γ]  (test)
        Y = np.empty((nfc, nc, nq, nb * nc, m))  # matmul's own output
        np.matmul(Ca, np.swapaxes(Gv, -1, -2)[:, None], out=Y)  # may be
        Y = Y.reshape(nfc, nc, nq * nb, nc * m)  # strided: reshape copies
        # K[k, a, i, c, l]
        #     = sum_{j, β} GT[k, i, (j, β)] Y[k, a, (j, β), (c, l)]
        return np.matmul(GT, Y).reshape(nfc, nc, m, nc, m)

    return assemble_local(basis, local_matrices, view, transposed=True)


@kernel
def assemble_local(basis, local_matrices, view=None, transposed=False):
    """Sparse matrix from local element/family matrices.

    ``local_matrices(sl)`` returns, for the elements ``sl``, an array of
    shape ``(ne, m, m, c, c)``: block ``[k, l, i]`` couples row node ``l``
    (test) with column node ``i`` (trial), components ``[c_l, c_i]``.
    With ``transposed=True`` it returns the component-major transpose
    ``(ne, c, m, c, m)`` indexed ``[k, c_i, i, c_l, l]`` instead (what a
    batched product yields without a strided copy).  Blocks are summed
    into the cached :func:`block_pattern`.
    """
    view = _view(basis) if view is None else view
    nc = view.nc
    indptr, indices, pieces = block_pattern(basis, view)
    data = np.zeros((len(indices), nc, nc))
    for sl, u, inv in pieces:
        K = local_matrices(sl)
        if transposed:
            m = K.shape[2]
            inv = inv.reshape(-1, m, m).transpose(0, 2, 1).ravel()
        for c in range(nc):
            for a in range(nc):
                Kca = K[:, a, :, c, :] if transposed else K[..., c, a]
                data[u, c, a] += np.bincount(inv, weights=Kca.ravel(),
                                             minlength=len(u))
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


@kernel
def assemble(form, basis, vbasis=None, **kwargs):
    """Assemble ``form`` on ``basis`` with batched local matrices.

    Works for :class:`FamilyBasis` and scikit-fem cell bases (scalar or
    ``ElementVector``); the result equals ``form.assemble(basis, **kwargs)``
    (``tests/test_assembly.py``).  The test basis is ``vbasis``, by default
    ``basis`` itself or, for a Petrov–Galerkin family basis, ``basis.test``
    (also for linear forms: PPG internal forces).  Other combinations are
    passed on to ``form.assemble``.
    """
    if vbasis is None:
        test = getattr(basis, "test", None)
        vbasis = basis if test is None else test
    view = _view(basis)
    if vbasis is basis:
        vview = view
    elif (isinstance(basis, FamilyBasis) and isinstance(vbasis, FamilyBasis)
          and vbasis.families is basis.families):
        vview = _FamilyView(vbasis)
    else:
        vview = None
    if view is not None and vview is not None:
        if isinstance(form, BilinearForm):
            return _assemble_bilinear(form, basis, view, vview, kwargs)
        if isinstance(form, LinearForm):
            return _assemble_linear(form, basis, vview, kwargs)
    if isinstance(form, LinearForm):
        return _generic(form, vbasis, **kwargs)
    if vbasis is basis:
        return _generic(form, basis, **kwargs)
    return _generic(form, basis, vbasis, **kwargs)
