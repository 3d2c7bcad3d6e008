r"""Particle families :math:`H^k` — the "elements" of a PG method.

A family is an ordered list of particle indices, **master first**.
:class:`Families` stores them ragged (CSR-like ``offsets``/``members``)
and hands out a padded ``(nf, m)`` view with a mask
for the batched shape-function kernels and the unpadded size groups of
:mod:`skfem_pg.discretization.layout` for the hot paths.

Builders
--------
:func:`from_mesh`
    FE connectivity: all vertices of the elements adjacent to the master
    (for centroid particles: all elements sharing a vertex).
:func:`horizon`
    All particles with :math:`|X^i - X^k| \le \delta`, ``delta`` a multiple
    of the mean spacing (KD-tree).
:func:`nearest`
    The ``n`` nearest particles, with pairwise completion (``j`` joins
    :math:`H^k` whenever ``k`` is in :math:`H^j`).

:data:`RULES` names them for :class:`~skfem_pg.FamilyBasis`
(``families="nearest"``) and :mod:`~skfem_pg.discretization.recipes`.

Every builder enlarges families that are too small, or whose non-master
members do not span the space (collinear in 2-D, coplanar in 3-D), by the
next ring of neighbours: MLS1 at the master, needed by the VC correction,
requires ``dim + 1`` non-master members in general position.
"""
import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree
from ..errors import FamilyError, ParticleError, describe_particle
from .layout import SizeGroups
from .particles import Particles


class Families:
    """Ragged family storage.

    Parameters
    ----------
    offsets
        ``(nf + 1,)`` start of each family in ``members``.
    members
        Concatenated member indices; the first member of each family is its
        master.
    n_particles
        Size of the particle set the indices refer to.

    Examples
    --------
    The mesh rule's families on a 3 x 3 grid of particles: a corner's family
    holds its cell's four vertices, the centre's all nine:

    >>> import skfem as fem, skfem_pg as pg
    >>> p = pg.Particles.from_mesh(fem.MeshQuad().refined(1))
    >>> fam = from_mesh(p)
    >>> len(fam), int(fam.sizes.min()), int(fam.sizes.max())
    (9, 4, 9)

    """

    def __init__(self, offsets, members, n_particles):
        self.offsets = np.asarray(offsets, dtype=np.int64)
        self.members = np.asarray(members, dtype=np.int64)
        self.n_particles = int(n_particles)
        if self.offsets[0] != 0 or self.offsets[-1] != len(self.members) \
                or np.any(np.diff(self.offsets) < 1):
            raise FamilyError("inconsistent family offsets")
        if len(self.members) and (self.members.min() < 0 or
                                  self.members.max() >= self.n_particles):
            raise FamilyError("family members refer to particles outside "
                              "0..{}".format(self.n_particles - 1))
        if len(np.unique(self.masters)) != len(self):
            raise FamilyError("two families have the same master")
        self._padded = None
        self._groups = None

    def __len__(self):
        return len(self.offsets) - 1

    @property
    def masters(self):
        """Master particle of each family."""
        return self.members[self.offsets[:-1]]

    def require_every_master(self, x, what):
        """Raise :class:`ParticleError` naming the first particle that
        masters no family (``x`` the particle positions) — for
        formulations with an unknown at every particle (``what``)."""
        missing = np.setdiff1d(np.arange(self.n_particles), self.masters)
        if len(missing):
            i = int(missing[0])
            raise ParticleError(
                "{} masters no family: {} need(s) a family at every "
                "particle ({} without one)".format(
                    describe_particle(i, x[:, i]), what, len(missing)))

    @property
    def sizes(self):
        """Number of members ``n_k`` (master included)."""
        return np.diff(self.offsets)

    def padded(self):
        """``(members, mask)`` as ``(nf, m)`` arrays, ``m = max n_k``.

        Padding slots repeat the master index and have ``mask == False``.
        """
        if self._padded is None:
            sizes = self.sizes
            m = int(sizes.max())
            local = np.arange(m)
            mask = local[None, :] < sizes[:, None]
            mem = np.repeat(self.masters[:, None], m, axis=1)
            mem[mask] = self.members
            self._padded = (mem, mask)
        return self._padded

    def groups(self):
        """The unpadded layout:
        :class:`~skfem_pg.discretization.layout.SizeGroups` of the families
        (cached)."""
        if self._groups is None:
            self._groups = SizeGroups(self)
        return self._groups

    def __repr__(self):
        s = self.sizes
        return ("<skfem_pg Families: {} families, size min/mean/max "
                "{}/{:.1f}/{}>".format(len(self), s.min(), s.mean(), s.max()))

    @classmethod
    def from_adjacency(cls, adjacency, masters):
        """Families from a sparse particle adjacency.

        Row ``k`` of ``adjacency`` (``n_particles`` square) lists the members
        of the family of master ``k``; only the rows in ``masters`` are used.
        The master is put first, the others keep ascending order.
        """
        A = sp.csr_matrix(adjacency)
        A = (A[masters] + sp.csr_matrix(
            (np.ones(len(masters)), (np.arange(len(masters)), masters)),
            shape=(len(masters), A.shape[1]))).tocsr()
        A.sum_duplicates()
        A.sort_indices()
        rows = np.repeat(np.arange(len(masters)), np.diff(A.indptr))
        cols = A.indices.astype(np.int64)
        order = np.lexsort((cols, cols != masters[rows], rows))
        return cls(A.indptr, cols[order], A.shape[1])

    def adjacency(self):
        """Sparse ``(n_particles, n_particles)`` boolean adjacency (rows =
        masters)."""
        rows = np.repeat(self.masters, self.sizes)
        return sp.csr_matrix((np.ones(len(self.members), dtype=bool),
                              (rows, self.members)),
                             shape=(self.n_particles, self.n_particles))


def _needs_enlargement(x, fam, min_size, order=1):
    """Families with too few members or with non-master members that do not
    span the space affinely (``order=2``: whose offsets from the master do
    not determine a quadratic fit, e.g. two layers of a grid)."""
    mem, mask = fam.padded()
    small = fam.sizes < min_size
    # centred non-master member positions, scaled per family
    others = mask.copy()
    others[:, 0] = False
    P = x.T[mem]  # (nf, m, d)
    cnt = np.maximum(others.sum(axis=1), 1)
    c = (P * others[..., None]).sum(axis=1) / cnt[:, None]
    D = (P - c[:, None, :]) * others[..., None]
    h = np.maximum(np.abs(D).max(axis=(1, 2)), 1e-300)
    D = D / h[:, None, None]
    S = np.swapaxes(D, -1, -2) @ D
    ev = np.linalg.eigvalsh(S)
    flat = ev[:, 0] <= 1e-8 * np.maximum(ev[:, -1], 1e-300)
    if order == 2:
        from .shape.quadratic import taylor2_basis
        D0 = (P - P[:, :1]) * mask[..., None]
        D0 = D0 / np.maximum(np.abs(D0).max(axis=(1, 2)), 1e-300)[:, None,
                                                                   None]
        p = taylor2_basis(D0) * others[..., None]
        eq = np.linalg.eigvalsh(np.swapaxes(p, -1, -2) @ p)
        flat |= eq[:, 0] <= 1e-8 * np.maximum(eq[:, -1], 1e-300)
    return small | flat


def _complete(x, A, masters, min_size, max_rings=3, order=1):
    """Build families from ``A`` and enlarge the deficient ones ring by
    ring; families the rings cannot fix (isolated clusters, or neighbours
    all on one line of a strongly anisotropic node set) get their nearest
    neighbours among the masters, ``min_size + dim`` first and then twice
    as many per round until their members span the space."""
    fam = Families.from_adjacency(A, masters)
    A = A.tocsr().astype(bool)
    k = min(min_size + x.shape[0], len(masters))
    for ring in range(max_rings + 64):
        need = _needs_enlargement(x, fam, min_size, order)
        if not np.any(need):
            break
        rows = masters[need]
        if ring < max_rings:
            R = sp.csr_matrix((np.ones(len(rows), dtype=bool),
                               (rows, rows)), shape=A.shape)
            A = (A + R @ A @ A).astype(bool)
        else:
            if ring > max_rings:
                if k == len(masters):
                    break  # cannot grow further: the shape kernels raise
                k = min(2 * k, len(masters))
            _, nb = cKDTree(x[:, masters].T).query(x[:, rows].T, k=k)
            nb = nb.reshape(len(rows), k)
            A = (A + sp.csr_matrix(
                (np.ones(nb.size, dtype=bool),
                 (np.repeat(rows, k), masters[nb.ravel()])),
                shape=A.shape)).astype(bool)
        fam = Families.from_adjacency(A, masters)
    return fam


def _mesh_of(obj):
    if isinstance(obj, Particles):
        return obj.mesh, obj.kind, obj.elements, obj.x
    return obj, "vertices", None, obj.p


def from_mesh(mesh_or_particles, elements=None, min_size=None, order=1):
    """Families from mesh connectivity (the default builder).

    Parameters
    ----------
    mesh_or_particles
        A scikit-fem mesh (vertex particles) or a :class:`Particles` built by
        ``Particles.from_mesh`` (its kind and element subset are used).
    elements
        Optional element subset (vertex particles only); families are built
        for the vertices of these elements from these elements alone.
    min_size
        Minimum family size, master included (default ``dim + 2``).
        Smaller families, and families whose non-master members are
        collinear/coplanar, get the next ring of neighbours.
    order
        2: also families whose members do not determine a quadratic
        Taylor fit (WTE2) get the next ring (the edge and corner nodes of
        a hexahedral grid: two layers in a direction).

    """
    mesh, kind, pel, x = _mesh_of(mesh_or_particles)
    if mesh is None:
        raise FamilyError("these particles have no mesh; use "
                          "families.horizon or families.nearest")
    if elements is None:
        elements = pel
    d = mesh.dim()
    min_size = d + 2 if min_size is None else int(min_size)
    if kind == "centroids":
        tind = pel  # particle p is element tind[p]
        nv, ne = mesh.nvertices, len(tind)
        E = sp.csr_matrix((np.ones(mesh.t.shape[0] * ne, dtype=bool),
                           (mesh.t[:, tind].ravel(),
                            np.tile(np.arange(ne), mesh.t.shape[0]))),
                          shape=(nv, ne))
        A = (E.T @ E).astype(bool)
        return _complete(x, A, np.arange(ne), min_size, order=order)
    tind = (np.arange(mesh.nelements) if elements is None
            else np.asarray(mesh.normalize_elements(elements)))
    t = mesh.t[:, tind]
    A = _cell_adjacency(t, mesh.nvertices)
    masters = np.unique(t)
    return _complete(x, A, masters, min_size, order=order)


def _cell_adjacency(t, nv):
    """``(nv, nv)`` boolean: the vertices that share a cell of ``t``
    (``(corners, cells)``), each with itself."""
    E = sp.csr_matrix((np.ones(t.size, dtype=bool),
                       (t.ravel(), np.tile(np.arange(t.shape[1]),
                                           t.shape[0]))),
                      shape=(nv, t.shape[1]))
    return (E @ E.T).astype(bool).tocsr()


def _active_tree(particles):
    act = np.nonzero(particles.active)[0]
    return act, cKDTree(particles.x[:, act].T)


def horizon(particles, delta=None, factor=1.51, min_size=None):
    r"""Families of all particles within the horizon ``delta``.

    ``delta`` defaults to ``factor`` times the mean nearest-neighbour
    distance ``h`` (the grid spacing of a regular node set; thesis:
    1.51 h ... 3.01 h).  A non-finite or non-positive ``delta`` or
    ``factor``, or a ``delta`` below the median nearest-neighbour distance
    (most families would hold the master alone), raises
    :class:`FamilyError`; the few particles a valid horizon leaves without
    enough neighbours get the next ring (module docstring).
    """
    act, tree = _active_tree(particles)
    dist, _ = tree.query(particles.x[:, act].T, k=2)
    spacing = dist[:, 1]
    if delta is None:
        factor = _positive_number(factor, "horizon factor")
        delta = factor * float(np.mean(spacing))
    delta = _positive_number(delta, "horizon delta")
    if delta < np.median(spacing):  # most families would be the master
        lonely = np.nonzero(spacing > delta)[0]
        q = act[lonely[np.argmax(spacing[lonely])]]
        raise FamilyError(
            "the horizon delta = {:.6g} is below the median nearest-"
            "neighbour distance {:.6g}: {} of {} particles have no "
            "neighbour within it, e.g. {} (nearest at {:.6g}); use a delta "
            "of 1.51 ... 3.01 times the mean spacing {:.6g} (factor=)"
            .format(delta, np.median(spacing), len(lonely), len(act),
                    describe_particle(q, particles.x[:, q]),
                    spacing[lonely].max(), np.mean(spacing)))
    pairs = tree.query_pairs(r=delta, output_type="ndarray")
    i, j = act[pairs[:, 0]], act[pairs[:, 1]]
    n = particles.n
    A = sp.csr_matrix((np.ones(2 * len(i), dtype=bool),
                       (np.r_[i, j], np.r_[j, i])), shape=(n, n))
    d = particles.dim
    return _complete(particles.x, A, act,
                     d + 2 if min_size is None else min_size)


def nearest(particles, n, pairwise=True, min_size=None, ties=True,
            tie_tolerance=1e-6):
    """Families of the ``n`` nearest neighbours of each particle, made
    pairwise (``j`` in ``H^k`` whenever ``k`` in ``H^j``) by default.

    ``ties``: every particle as near as the ``n``-th nearest (within
    ``tie_tolerance`` times its distance) joins too, so that the families
    of a regular grid keep its symmetry (on a square grid ``n = 6``
    gives the 3 x 3 stencil, not 4 edge and 2 of the 4 corner
    neighbours picked by the KD-tree's internal order); ``ties=False``
    takes exactly ``n`` (the order among equidistant particles is then
    arbitrary).

    On particles of a subset of a mesh's cells
    (``Particles.from_mesh(mesh, elements=...)``: what a crack-aware
    update collocates) the neighbours are taken among the particles the
    cells connect within a few rings, and every particle that shares a
    cell joins (the local VC correction needs them), so that no family
    reaches across removed cells.

    >>> import numpy as np, skfem as fem, skfem_pg as pg
    >>> m = fem.MeshQuad.init_tensor(*(2 * [range(5)]))
    >>> p = pg.Particles.from_mesh(m)
    >>> f = pg.families.nearest(p, 6, pairwise=False)
    >>> centre = int(np.argmin(np.hypot(*(p.x - 2.0))))
    >>> int(f.sizes[f.masters == centre][0])  # the 3 x 3 stencil
    9
    """
    act, tree = _active_tree(particles)
    if isinstance(n, (bool, np.bool_)) or not isinstance(
            n, (int, np.integer)):
        raise FamilyError("the number of neighbours n must be an integer, "
                          "got {!r}".format(n))
    if n < 1 or n >= len(act):
        raise FamilyError("need 1 <= n < {} (active particles), got {}"
                          .format(len(act), n))
    tol = _positive_number(tie_tolerance, "tie tolerance") if ties else 0.0
    N = particles.n
    d = particles.dim
    if particles.elements is not None and particles.mesh is not None \
            and particles.kind == "vertices":
        # a body of a subset of the cells (a crack-aware rebuild): the
        # neighbours among the particles its cells connect
        A = _nearest_in_cells(particles, act, n, tol)
        if pairwise:
            A = (A + A.T).tocsr()
        return _complete(particles.x, A, act,
                         d + 2 if min_size is None else min_size)
    pts = particles.x[:, act].T
    k = n + 1
    while True:  # at most log2(#particles) rounds: k doubles
        kq = min(len(act), 2 * k if ties else k)
        dist, idx = tree.query(pts, k=kq)
        dist, idx = dist.reshape(len(act), kq), idx.reshape(len(act), kq)
        if not ties:
            keep = np.ones(dist.shape, dtype=bool)
            break
        keep = dist <= dist[:, n:n + 1] * (1.0 + tol)
        if kq == len(act) or not keep[:, -1].any():
            break  # every tie found: the last column is beyond them
        k = kq
    rows = np.repeat(act, keep.sum(axis=1))
    cols = act[idx[keep]]
    A = sp.csr_matrix((np.ones(len(rows), dtype=bool), (rows, cols)),
                      shape=(N, N))
    if pairwise:
        A = (A + A.T).tocsr()
    return _complete(particles.x, A, act,
                     d + 2 if min_size is None else min_size)


def _nearest_in_cells(particles, act, n, tol, max_rings=6):
    """The ``n`` nearest (with ties within ``tol``) of each active
    particle among those its element subset connects within a few rings
    of cells (grown ring by ring, at most ``max_rings``, until every
    particle has ``n`` candidates or its piece has no more), and every
    particle that shares a cell with it (what the local VC correction
    needs): no family reaches across a gap of removed cells, as the
    Euclidean nearest neighbours would."""
    mesh, N = particles.mesh, particles.n
    ring = _cell_adjacency(mesh.t[:, np.asarray(mesh.normalize_elements(
        particles.elements))], N)
    C = ring
    for _ in range(max_rings - 1):  # the next ring of the short rows
        short = act[C.getnnz(axis=1)[act] < n + 1]
        if not short.size:
            break
        S = sp.csr_matrix((np.ones(short.size, dtype=bool), (short, short)),
                          shape=(N, N))
        grown = (C + S @ C @ ring).astype(bool).tocsr()
        if grown.nnz == C.nnz:
            break  # their pieces are exhausted
        C = grown
    C = C[act].tocoo()
    i, j = act[C.row], C.col
    dist = np.linalg.norm(particles.x[:, i] - particles.x[:, j], axis=0)
    order = np.lexsort((dist, i))
    i, j, dist = i[order], j[order], dist[order]
    start = np.searchsorted(i, i, side="left")
    rank = np.arange(i.size) - start
    count = np.bincount(i, minlength=N)
    # the distance of the n-th neighbour (rank n: the particle itself is
    # rank 0), or of the last candidate of a smaller piece
    nth = dist[start + np.minimum(n, count[i] - 1)]
    keep = dist <= nth * (1.0 + tol) if tol > 0 else rank <= n
    A = sp.csr_matrix((np.ones(int(keep.sum()), dtype=bool),
                       (i[keep], j[keep])), shape=(N, N))
    rows = sp.csr_matrix((np.ones(act.size, dtype=bool), (act, act)),
                         shape=(N, N))
    return (A + rows @ ring).astype(bool).tocsr()


def _positive_number(value, what):
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise FamilyError("the {} must be a number, got {!r}".format(
            what, value)) from None
    if not np.isfinite(v) or v <= 0:
        raise FamilyError("the {} must be positive and finite, got {!r}"
                          .format(what, value))
    return v


def check_supports(particles, families, n_required, what):
    """Raise :class:`FamilyError` naming the first family with fewer than
    ``n_required`` members."""
    small = np.nonzero(families.sizes < n_required)[0]
    if len(small):
        k = small[0]
        p = families.masters[k]
        raise FamilyError(
            "family of {} has {} members; {} needs at least {} ({} families "
            "are too small). Use a larger horizon or more neighbours."
            .format(describe_particle(p, particles.x[:, p]),
                    families.sizes[k], what, n_required, len(small)))


#: neighbours of the ``"nearest"`` rule by spatial dimension (3-D: the
#: kNN recipe, :mod:`skfem_pg.discretization.recipes`)
NEAREST = {1: 2, 2: 6, 3: 10}


def _nearest_default(particles):
    return nearest(particles, NEAREST[particles.dim])


#: family rules by name: ``rule(particles) -> Families`` with the rule's
#: default parameters (``"nearest"``: :data:`NEAREST` neighbours,
#: pairwise)
RULES = {"mesh": from_mesh, "nearest": _nearest_default, "horizon": horizon}


def build(rule, particles):
    """The families of rule ``rule`` (a name of :data:`RULES`) on
    ``particles``; ``"mesh"`` on particles without a mesh raises
    :class:`FamilyError`."""
    try:
        f = RULES[rule]
    except (KeyError, TypeError):
        raise FamilyError("unknown family rule {!r}: one of {}, or a "
                          "Families object".format(
                              rule, ", ".join(map(repr, RULES)))) from None
    return f(particles)


__all__ = ["Families", "NEAREST", "RULES", "build", "from_mesh", "horizon",
           "nearest", "check_supports"]
