r"""Second order on the vertices: the families' quadratic fits blended by
the mesh's hat functions (``PG2``).

Every particle :math:`k` fits a quadratic polynomial to its family's
values (the static Taylor expansion WTE2 of the moment quadrature's
default families: the mesh's 1-ring, enlarged until the fit is
determined),

.. math::

    u_k(x) = u^k + \sum_{i \in H^k} \sum_\alpha c^k_{i\alpha}\,
        p_\alpha\!\Big(\frac{x - X^k}{h_k}\Big)\,(u^i - u^k),

with :math:`p` the linear and quadratic monomials, and the collocation
mesh's linear hat functions :math:`N_k` blend the fits into one
conforming field,

.. math::

    u_h(x) = \sum_k N_k(x)\, u_k(x), \qquad
    \psi_i(x) = \sum_k N_k(x)\, \phi_{k,i}(x).

The shape functions :math:`\psi_i` reproduce quadratic polynomials (each
fit does and the hat functions are a partition of unity), are
Kronecker at the vertices (each fit interpolates its master) and are
continuous, so scikit-fem's forms assemble a Galerkin method on the
mesh's cells with a Gauss rule (degree 4 by default: exact for the
energy of a quadratic field on affine simplices).  An element of this
basis is a mesh cell; its local dofs are the union of its vertices'
families.  It is a partition-of-unity method (Melenk and Babuška 1996)
whose local approximations are the peridynamic families' WTE2 fits
(the thesis' (5.41)-(5.46) with :math:`n = 1` weights): second order with
the vertices' unknowns alone.

A fit of a particle near the boundary holds interior members, so the
field on a boundary facet depends on interior values: prescribing the
vertex values there (``condense``) fixes the field only at the vertices
and costs about one order in L2.  Prescribe Dirichlet conditions weakly
by Nitsche terms instead (:class:`skfem_pg.formulations.WeakDirichlet`,
what ``Scene.solve("PG2")`` does).  For the same reason the field's trace
on an interface is not an FE element's: adding this basis' matrices to
an FE basis' on shared vertices couples them non-conformingly (it fails
the patch test), unlike the first-order :class:`FamilyBasis`.
"""
from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

import numpy as np
import scipy.sparse as sp
import skfem as fem
from skfem.assembly.basis import AbstractBasis
from skfem.element import DiscreteField

from ..errors import (FamilyError, NO_SECOND_DERIVATIVES,
                      warn_slow_assembly)
from .particles import Particles, linear_elements
from .shape.common import FamilyGeometry, chunks
from .shape.quadratic import (taylor2_basis, taylor2_derivatives,
                              wte2_coefficients)


class QuadraticFits(NamedTuple):
    """The WTE2 fits of a particle set's families.

    Attributes
    ----------
    members, mask
        ``(nf, m)`` family members (the master first) and validity.
    coefficients
        ``(nf, m, q)``: :math:`c^k_{i\\alpha}`, the fit's monomial
        coefficients per member (the master's column is unused: its shape
        function is one minus the others').
    h
        ``(nf,)`` family radii (the fits' length scale).
    family
        ``(n,)`` the family of each particle (each particle is a master).
    """

    members: np.ndarray
    mask: np.ndarray
    coefficients: np.ndarray
    h: np.ndarray
    family: np.ndarray


#: a 3-D family whose equilibrated quadratic moment matrix has a larger
#: condition number takes its next nearest particle (:func:`families_3d`):
#: 100 left 118 of the 615 surface families of the gmsh-meshed 3-D Cook
#: plate (three layers thick) short of it after 64 more particles (mean
#: family 33 members); 300 gives 17.5 members there at 6 % more tip
#: error, 1000 15.9 members at 40 % more
FIT_CONDITION = 3e2
#: the nearest particles a 3-D family may take beyond its 1-ring
MAX_ADDED = 64


def fit_condition(x, members, mask):
    """Condition numbers ``(nf,)`` of the families' equilibrated quadratic
    moment matrices (unit weights, offsets scaled by the family radius;
    ``inf`` where the members do not determine a quadratic)."""
    D0 = (x.T[members] - x.T[members[:, :1]]) * mask[..., None]
    h = np.maximum(np.sqrt((D0 ** 2).sum(-1)).max(1), 1e-300)
    p = taylor2_basis(D0 / h[:, None, None]) * mask[..., None]
    M = np.swapaxes(p, -1, -2) @ p
    dg = np.sqrt(np.maximum(np.einsum("fii->fi", M), 1e-300))
    ev = np.linalg.eigvalsh(M / dg[:, :, None] / dg[:, None, :])
    with np.errstate(divide="ignore"):
        return np.where(ev[:, 0] > 1e-14 * ev[:, -1], ev[:, -1] / ev[:, 0],
                        np.inf)


def families_3d(particles: Particles, condition: float = FIT_CONDITION):
    """The default families of :class:`BlendBasis` in 3-D: each
    particle's mesh 1-ring and, where its quadratic fit's condition
    number exceeds ``condition`` (surface particles, whose 1-ring has two
    layers across the surface), the nearest further particles one at a
    time until it does not — or, if it never does within
    :data:`MAX_ADDED` of them, as many as gave the best-conditioned fit.
    Where the moment quadrature's rings double a surface family, this
    keeps it near the 1-ring's size (``benchmarks/README.md``, "PG2 in
    the package": fewer non-zeros and less time at about the same
    accuracy on tetrahedra, less error on hexahedra).  A family whose
    members never determine a quadratic raises
    :class:`~skfem_pg.errors.FamilyError` naming the particle."""
    from scipy.spatial import cKDTree
    from .families import Families, from_mesh
    x = particles.x
    fam = from_mesh(particles)
    mem, mask = fam.padded()
    bad = np.flatnonzero(fit_condition(x, mem, mask) > condition)
    if not len(bad):
        return fam
    k = min(mask.shape[1] + MAX_ADDED, particles.n)
    _, near = cKDTree(x.T).query(x[:, fam.masters[bad]].T, k=k)
    # the candidates: the nearest particles that are not members yet
    new = ~((near[:, :, None] == mem[bad][:, None, :])
            & mask[bad][:, None, :]).any(-1)
    cand = np.take_along_axis(near, np.argsort(~new, axis=1,
                                                kind="stable"), 1)
    ncand = new.sum(1)
    bm, bk = mem[bad], mask[bad]
    best, best_r = np.full(len(bad), np.inf), np.zeros(len(bad), int)
    open_ = ncand > 0
    for r in range(min(MAX_ADDED, cand.shape[1])):  # rounds, not families
        rows = np.flatnonzero(open_)
        if not len(rows):
            break
        c = fit_condition(x, np.concatenate([bm[rows], cand[rows, :r + 1]],
                                            1),
                          np.concatenate([bk[rows], np.ones(
                              (len(rows), r + 1), dtype=bool)], 1))
        better = c < best[rows]
        best[rows[better]], best_r[rows[better]] = c[better], r
        open_[rows[c <= condition]] = False
        open_ &= r + 1 < ncand
    if np.isinf(best).any():
        i = int(fam.masters[bad[np.flatnonzero(np.isinf(best))[0]]])
        raise FamilyError(
            "the family of particle {} at {} does not determine a "
            "quadratic fit with its 1-ring and {} nearest particles "
            "({} such families; a quadratic needs members on three layers "
            "in every direction: a node set one element thick has two)"
            .format(i, np.round(x[:, i], 12).tolist(), MAX_ADDED,
                    int(np.isinf(best).sum())))
    take = np.arange(cand.shape[1]) <= best_r[:, None]
    rows = np.repeat(fam.masters[bad], take.sum(1))
    A = (fam.adjacency() + sp.csr_matrix(
        (np.ones(len(rows), dtype=bool), (rows, cand[take])),
        shape=(particles.n, particles.n))).astype(bool)
    return Families.from_adjacency(A, fam.masters)


def default_families(particles: Particles):
    """:class:`BlendBasis`' default families: in 2-D the moment
    quadrature's (:func:`~skfem_pg.discretization.moment_quadrature.
    default_families`, the 1-ring enlarged by rings until it determines
    a quadratic: 1.3-1.5 times less error than :func:`families_3d`'s
    rule on the Cook membrane at 2 % fewer non-zeros), in 3-D
    :func:`families_3d`."""
    if particles.dim == 3:
        return families_3d(particles)
    from .moment_quadrature import default_families as rings
    return rings(particles)


def quadratic_fits(particles: Particles, families=None,
                   needed=None) -> QuadraticFits:
    """The WTE2 fits of ``families`` (default: :func:`default_families`)
    with weights :math:`|\\Delta X|^{-2}` (the
    thesis' (5.41), :math:`n = 1`).

    A family whose members do not determine a quadratic, and a particle
    of ``needed`` (default all) without a family, raise
    :class:`~skfem_pg.errors.FamilyError` naming the particle.
    """
    fam = default_families(particles) if families is None else families
    mem, mask = fam.padded()
    family = np.full(particles.n, -1, dtype=np.int64)
    family[fam.masters] = np.arange(len(fam))
    needed = np.arange(particles.n) if needed is None else needed
    if (family[needed] < 0).any():
        i = int(needed[np.flatnonzero(family[needed] < 0)[0]])
        raise FamilyError(
            "particle {} at {} has no family: the blended quadratic basis "
            "needs one per particle".format(
                i, np.round(particles.x[:, i], 12).tolist()))
    if not np.array_equal(mem[:, 0], fam.masters):
        raise FamilyError("the families must list their master first")
    geo = FamilyGeometry(particles.x, particles.volumes, mem, mask)
    c, singular = wte2_coefficients(geo, n=1)
    if singular.any():
        k = int(np.flatnonzero(singular)[0])
        raise FamilyError(
            "the family of particle {} at {} ({} members) does not "
            "determine a quadratic fit ({} such families; a quadratic "
            "needs members on three layers in every direction: a node set "
            "one element thick has two)".format(
                int(fam.masters[k]),
                np.round(particles.x[:, fam.masters[k]], 12).tolist(),
                int(mask[k].sum()), int(singular.sum())))
    return QuadraticFits(mem, mask, c, geo.h, family)


def _raw(mesh, fits, base, cells, part=slice(None)):
    """Values and gradients of the blended shape functions at ``base``'s
    points (a cell or facet basis of the mesh's linear element on
    ``cells``; its elements ``part``), one slot per (cell vertex,
    member): ``(ne, nq, R, 1 + d)``, the slots' particles ``(ne, R)`` and
    validity."""
    mem, mask, c, hk, family = fits
    X = np.asarray(base.global_coordinates())[:, part]  # (d, ne, nq)
    cells = cells[part]
    d, nv, m = mesh.dim(), mesh.t.shape[0], mem.shape[1]
    ne, nq = X.shape[1:]
    out = np.zeros((ne, nq, nv, m, 1 + d))
    Xt = np.moveaxis(X, 0, -1)  # (ne, nq, d)
    for a in range(nv):  # the cell's vertices: a constant, not particles
        hat = base.basis[a][0]
        hat_value, hat_grad = np.asarray(hat)[part], hat.grad[:, part]
        k = family[mesh.t[a, cells]]
        Y = (Xt - mesh.p.T[mesh.t[a, cells]][:, None, :]) \
            / hk[k][:, None, None]
        ck = np.swapaxes(c[k], -1, -2)[:, None]  # (ne, 1, q, m)
        val = (taylor2_basis(Y)[:, :, None] @ ck)[:, :, 0]  # (ne, nq, m)
        grad = np.swapaxes(np.swapaxes(taylor2_derivatives(Y), -1, -2)
                           @ ck, -1, -2) / hk[k][:, None, None, None]
        val[..., 0] = 1.0 - val[..., 1:].sum(-1)  # the master's
        grad[..., 0, :] = -grad[..., 1:, :].sum(-2)
        val *= mask[k][:, None, :]
        grad *= mask[k][:, None, :, None]
        hv = hat_value[:, :, None]  # (ne, nq, 1)
        out[:, :, a, :, 0] = hv * val
        out[:, :, a, :, 1:] = hv[..., None] * grad \
            + np.moveaxis(hat_grad, 0, -1)[:, :, None, :] * val[..., None]
    k = family[mesh.t[:, cells]].T  # (ne, nv)
    return (out.reshape(ne, nq, nv * m, 1 + d),
            mem[k].reshape(ne, -1), mask[k].reshape(ne, -1))


def _merge(values, conn, mask, n):
    """Sum the slots of one particle in each element: ``(values (ne, nq,
    L, c), conn (ne, L), valid (ne, L))`` with ``L`` the largest number
    of distinct particles of an element (padded slots: zero values, the
    element's first particle)."""
    ne, nq, R, nch = values.shape
    key = np.where(mask, conn, n)
    order = np.argsort(key, axis=1, kind="stable")
    sk = np.take_along_axis(key, order, axis=1)
    new = np.ones(sk.shape, dtype=bool)
    new[:, 1:] = sk[:, 1:] != sk[:, :-1]
    real = new & (sk < n)
    L = int(real.sum(1).max())
    slot_sorted = np.cumsum(new, axis=1) - 1
    slot = np.empty_like(slot_sorted)
    np.put_along_axis(slot, order, slot_sorted, axis=1)
    slot = np.where(mask, slot, L)  # padding: a dump slot
    rows = (np.arange(ne)[:, None] * (L + 1) + slot).ravel()
    S = sp.csr_matrix((np.ones(ne * R), (rows, np.arange(ne * R))),
                      shape=(ne * (L + 1), ne * R))
    flat = np.moveaxis(values, 1, 2).reshape(ne * R, nq * nch)
    merged = (S @ flat).reshape(ne, L + 1, nq, nch)[:, :L]
    out_conn = np.zeros((ne, L), dtype=np.int64)
    valid = np.zeros((ne, L), dtype=bool)
    e, s = np.nonzero(real)
    out_conn[e, slot_sorted[e, s]] = sk[e, s]
    valid[e, slot_sorted[e, s]] = True
    out_conn = np.where(valid, out_conn, out_conn[:, :1])
    return np.ascontiguousarray(np.moveaxis(merged, 1, 2)), out_conn, valid


class _LazyFunctions(Sequence):
    """``basis.basis`` of a :class:`BlendBasis`: the ``Nbfun`` local
    basis functions as scikit-fem ``DiscreteField`` tuples, made when
    asked for (scikit-fem's generic assembly; :func:`skfem_pg.assemble`
    uses the batched arrays instead)."""

    def __init__(self, basis):
        self.b = basis

    def __len__(self):
        return self.b.Nbfun

    def __getitem__(self, i):
        b = self.b
        if not 0 <= i < len(self):
            raise IndexError(i)
        nc = 1 if b.ncomp is None else b.ncomp
        s, a = divmod(i, nc)
        Gh = b.values[:, :, s]  # (ne, nq, 1 + d)
        value, grad = Gh[..., 0], np.moveaxis(Gh[..., 1:], -1, 0)
        if b.ncomp is None:
            return (DiscreteField(value, grad,
                                  hess=NO_SECOND_DERIVATIVES),)
        d = grad.shape[0]
        V = np.zeros((nc,) + value.shape)
        G = np.zeros((nc, d) + value.shape)
        V[a], G[a] = value, grad
        return (DiscreteField(V, G, hess=NO_SECOND_DERIVATIVES),)


class BlendBasis(AbstractBasis):
    """The blended quadratic basis on a mesh's vertices (module docstring).

    Parameters
    ----------
    particles
        :class:`~skfem_pg.Particles` collocated from a mesh's vertices,
        or the mesh (triangles, quadrilaterals, tetrahedra, hexahedra).
    dim
        Number of field components (``None``: a scalar field).
    families
        :class:`~skfem_pg.discretization.families.Families` whose WTE2
        fits are blended; default :func:`default_families`.
    intorder
        Degree of the cell (and facet) Gauss rule, default 4.
    facets
        Build the basis on these boundary facets' points instead of the
        cells (:meth:`boundary`: loads, Nitsche terms).

    Attributes
    ----------
    values
        ``(ne, nq, L, 1 + d)``: value and gradient of the ``L`` local
        shape functions of each cell at its quadrature points (padded
        slots zero).
    conn
        ``(ne, L)`` the particles of the local shape functions.
    fits
        The :class:`QuadraticFits` blended.

    Examples
    --------
    >>> import skfem as fem, skfem_pg as pg
    >>> from skfem.helpers import dot, grad
    >>> mesh = fem.MeshTri.init_sqsymmetric().refined(2)
    >>> basis = pg.FamilyBasis(mesh, order=2)
    >>> type(basis).__name__, basis.N   # one unknown per vertex
    ('BlendBasis', 81)
    >>> @fem.BilinearForm
    ... def laplace(u, v, w):
    ...     return dot(grad(u), grad(v))
    >>> K = pg.assemble(laplace, basis)
    >>> x, y = mesh.p
    >>> u = x ** 2 + x * y   # a quadratic is reproduced: its energy is exact
    >>> print("{:.12f}".format(u @ K @ u))  # int |grad u|^2 over [0, 1]^2
    3.000000000000
    """

    name = "PG2"

    def __init__(self, particles, dim: int | None = None, families=None,
                 intorder: int = 4, facets=None, _fits=None):
        if isinstance(particles, fem.Mesh):
            particles = Particles.from_mesh(particles)
        if particles.kind != "vertices" or particles.mesh is None:
            raise ValueError(
                "the blended quadratic basis blends with the collocation "
                "mesh's hat functions: it needs particles collocated from a "
                "mesh's vertices (Particles.from_mesh), got {}".format(
                    particles.kind))
        if dim is not None and dim != particles.dim:
            raise ValueError("dim must be None (a scalar field) or the "
                             "spatial dimension {}, got {!r}".format(
                                 particles.dim, dim))
        if int(intorder) != intorder or intorder < 2:
            raise ValueError("intorder must be an integer >= 2 (the "
                             "degree of the Gauss rule), got {!r}".format(
                                 intorder))
        mesh = particles.mesh
        self.particles, self.mesh, self.ncomp = particles, mesh, dim
        self.intorder = int(intorder)
        e1, _ = linear_elements(mesh)
        nc = 1 if dim is None else dim
        self.elem = e1 if dim is None else fem.ElementVector(e1, dim=nc)
        self.dofs = fem.assembly.Dofs(mesh, self.elem)
        self.doflocs = np.repeat(mesh.p, nc, axis=1)
        self.mapping = mesh._mapping()
        if facets is None:
            kw = {} if particles.elements is None else {
                "elements": particles.elements}
            base = fem.Basis(mesh, e1, intorder=self.intorder, **kw)
            cells = base.tind if base.tind is not None \
                else np.arange(mesh.nelements)
            self.normals = None
        else:
            base = fem.FacetBasis(mesh, e1, facets=np.asarray(facets),
                                  intorder=self.intorder)
            cells = base.tind
            self.normals = base.normals
        self.fits = _fits if _fits is not None else quadratic_fits(
            particles, families, np.unique(mesh.t[:, cells]))
        self.facets = None if facets is None else base.find
        self._base = base
        self.tind = cells
        self.X, self.W = base.X, base.W
        self.dx = base.dx
        self.nelems = len(cells)
        self.values, self.conn, self.valid = self._merged(base, cells)
        self.Nbfun = nc * self.conn.shape[1]
        self._x = np.asarray(base.global_coordinates())
        self._pattern = None

    def _merged(self, base, cells):
        """:func:`_raw` and :func:`_merge` per chunk of cells, padded to
        one local size."""
        mem = self.fits.members
        nv, nq = self.mesh.t.shape[0], len(base.W)
        pieces = [_merge(*_raw(self.mesh, self.fits, base, cells, sl),
                         self.particles.n)
                  for sl in chunks(len(cells), nq * nv * mem.shape[1]
                                   * (2 + self.mesh.dim()), budget=2 ** 24)]
        L = max(p[1].shape[1] for p in pieces)
        values = np.zeros((len(cells), nq, L, 1 + self.mesh.dim()))
        conn = np.zeros((len(cells), L), dtype=np.int64)
        valid = np.zeros((len(cells), L), dtype=bool)
        start = 0
        for v, c, ok in pieces:
            n, l = c.shape
            values[start:start + n, :, :l] = v
            conn[start:start + n] = c[:, :1]
            conn[start:start + n, :l] = c
            valid[start:start + n, :l] = ok
            start += n
        return values, conn, valid

    # --- what scikit-fem reads ----------------------------------------
    @property
    def N(self):
        return (1 if self.ncomp is None else self.ncomp) * self.particles.n

    @property
    def element_dofs(self):
        nc = 1 if self.ncomp is None else self.ncomp
        return (nc * self.conn[:, :, None] + np.arange(nc)).reshape(
            self.nelems, -1).T

    @property
    def basis(self):
        """The local basis functions for scikit-fem's generic assembly
        (made when asked for); a bilinear form there costs ``Nbfun**2``
        form calls, which :func:`skfem_pg.assemble` avoids."""
        if self.Nbfun ** 2 > 4000:
            warn_slow_assembly("BlendBasis", self.Nbfun)
        return _LazyFunctions(self)

    def default_parameters(self):
        out = {"x": self.global_coordinates(),
               "h": DiscreteField(np.broadcast_to(
                   self._cell_size()[:, None], self.dx.shape))}
        if self.normals is not None:
            out["n"] = self.normals
        return out

    def _cell_size(self):
        if self.facets is not None:
            v = self.mesh.p[:, self.mesh.facets[:, self.facets]]
            if self.mesh.dim() == 2:
                return np.linalg.norm(v[:, 1] - v[:, 0], axis=0)
            return np.sqrt(np.linalg.norm(np.cross(
                (v[:, 1] - v[:, 0]).T, (v[:, 2] - v[:, 0]).T), axis=1))
        return self.mesh.param() * np.ones(self.nelems)

    def global_coordinates(self):
        return DiscreteField(self._x)

    def interpolate(self, w):
        """The field of the dof vector ``w`` at the quadrature points:
        ``DiscreteField`` with values ``(ne, nq)`` (scalar) or ``(d, ne,
        nq)`` and gradients ``(d, ne, nq)`` / ``(d, d, ne, nq)``."""
        w = np.asarray(w)
        if w.shape != (self.N,):
            raise ValueError(
                "interpolate: a dof vector of this basis has {} entries, "
                "got shape {}".format(self.N, w.shape))
        Gh = self.values
        if self.ncomp is None:
            uu = w[self.conn]  # (ne, L)
            out = np.einsum("eqlc,el->ceq", Gh, uu)
            return DiscreteField(out[0], out[1:],
                                 hess=NO_SECOND_DERIVATIVES)
        uu = w.reshape(-1, self.ncomp)[self.conn]  # (ne, L, nc)
        out = np.einsum("eqlc,ela->aceq", Gh, uu)
        return DiscreteField(out[:, 0], out[:, 1:],
                             hess=NO_SECOND_DERIVATIVES)

    def boundary(self, facets=None):
        """The same shape functions at the Gauss points of boundary
        ``facets`` (default all): a basis for tractions and Nitsche
        terms (``w.n`` the outward normals, ``w.h`` the facet sizes)."""
        if facets is None:
            facets = self.mesh.boundary_facets()
        elif isinstance(facets, str):
            facets = self.mesh.boundaries[facets]
        return BlendBasis(self.particles, self.ncomp, intorder=self.intorder,
                          facets=facets, _fits=self.fits)

    def batched_view(self):
        """The arrays :func:`skfem_pg.assemble` batches over."""
        return _BlendView(self)

    def __repr__(self):
        return "<BlendBasis (PG2) of {} particles, {} {}, {} local " \
            "functions>".format(self.particles.n, self.nelems,
                                "cells" if self.facets is None
                                else "facets", self.Nbfun)


class _BlendView:
    """:func:`skfem_pg.discretization.assembly.batched_view` of a
    :class:`BlendBasis`: one block, the cells."""

    def __init__(self, basis):
        from .assembly import _Block
        self.basis = basis
        self.scalar = basis.ncomp is None
        self.nc = 1 if self.scalar else basis.ncomp
        self.dim = basis.mesh.dim()
        self.n_nodes = basis.particles.n
        self.shape = basis.dx.shape
        V = basis.values

        def ext_grad(sl, channels):
            return V[sl][..., list(channels)]
        self.blocks = [_Block(basis.conn, basis.dx, ext_grad, lambda C: C,
                              np.arange(basis.nelems))]

    def coefficient_shape(self, shapes):
        return self.shape
