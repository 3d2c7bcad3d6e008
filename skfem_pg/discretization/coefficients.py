r"""Piecewise coefficients on a family basis: a value per cell of the
collocation mesh (two materials, a heterogeneous conductivity) evaluated at
the family members.

A particle on a material interface belongs to both sides: a value per
particle gives it one side's value, and the result then depends on which
(scikit-fem's two-material example: −8.1 % or +0.4 % with the interface
particles given the one or the other).  :func:`cell_values_at_members`
evaluates the coefficient of the bond instead: member :math:`j` of family
:math:`k` gets the value of the cell that contains the bond midpoint
:math:`(X^k + X^j)/2`, and the master itself the volume-weighted mean of
the cells around it.  A family on the interface thus sees both sides, each
in proportion to its bonds.  With ``family_quadrature="moments"``
(:mod:`~skfem_pg.discretization.moment_quadrature`) the quadrature points
are not members: each gets the value of the cell that contains it.

The cells are found by :func:`cell_average` (vectorized): a point on a
face or edge shared by cells (a bond along a material interface) takes
their mean, a bond midpoint on the mesh's boundary (where scikit-fem's
element finder saw round-off and said "outside of the mesh") its cell's
value, and a point outside every cell (a bond across a concave boundary
or a hole) the value of the cell it is closest to.
"""
import numpy as np
import skfem as fem

from .layout import is_family_basis
from .particles import linear_elements


def cell_values_at_members(basis, values):
    """``values`` (one per cell of the basis' collocation mesh) at the
    family members, ``(nf, m)`` padded (zero in padded slots): a form
    coefficient, ``form.assemble(basis, k=cell_values_at_members(basis,
    k_cells))``.

    Raises ``ValueError`` for a basis without a collocation mesh or a
    ``values`` of another length."""
    if not is_family_basis(basis) or basis.mesh is None:
        raise ValueError("cell_values_at_members needs a FamilyBasis "
                         "collocated from a mesh's vertices")
    mesh = basis.mesh
    values = np.asarray(values, dtype=float)
    if values.shape != (mesh.nelements,):
        raise ValueError("one value per cell of the collocation mesh ({}), "
                         "got shape {}".format(mesh.nelements, values.shape))
    x = basis.particles.x
    mem, mask = basis.families.padded()
    masters = mem[:, 0]
    mid = 0.5 * (x[:, masters][:, :, None] + x[:, mem])  # (d, nf, m)
    out = cell_average(mesh, mid.reshape(mid.shape[0], -1),
                       values).reshape(mem.shape)
    # the master: the volume-weighted mean of the cells around it
    e1, _ = linear_elements(mesh)
    volume = fem.Functional(lambda w: 1.0 + 0.0 * w.x[0]).elemental(
        fem.Basis(mesh, e1))
    weight = np.zeros(mesh.nvertices)
    total = np.zeros(mesh.nvertices)
    np.add.at(weight, mesh.t.ravel(),
              np.broadcast_to(volume, mesh.t.shape).ravel())
    np.add.at(total, mesh.t.ravel(),
              np.broadcast_to(volume * values, mesh.t.shape).ravel())
    out[:, 0] = total[masters] / weight[masters]
    points = getattr(basis, "points", None)
    if points is not None:  # family_quadrature="moments": its own points
        out = _at_points(mesh, values, points, basis.dx > 0, out[:, :1])
    return np.where(mask, out, 0.0)


def _at_points(mesh, values, points, used, master_mean):
    """``values`` of the cells that contain the quadrature points
    ``points`` ``(nf, m, d)`` where ``used`` (:func:`cell_average`: a point
    outside the node set's polygon, beside a curved boundary, takes its
    closest cell's), else the masters' mean."""
    out = np.broadcast_to(master_mean, used.shape).copy()
    P = points[used]  # (n, d)
    vals = out[used]
    if len(P):
        vals[:] = cell_average(mesh, P.T, values)
    out[used] = vals
    return out


#: linear cells split into simplices on their own vertices (local vertex
#: numbers, scikit-fem's orderings; the hexahedron's six tetrahedra are
#: scikit-fem's ``MeshHex1.to_meshtet``)
_SIMPLICES = {fem.MeshQuad1: ([0, 1, 2], [0, 2, 3]),
              fem.MeshHex1: ([0, 1, 3, 4], [0, 3, 2, 4], [2, 3, 4, 6],
                             [3, 4, 6, 7], [3, 4, 5, 7], [1, 3, 4, 5])}

#: a point within this fraction (in barycentric coordinates) outside a
#: simplex counts as on it (round-off on shared faces and the boundary)
INSIDE = 1e-10


def _search(mesh, x, k=12):
    """Candidate cells of the points ``x`` (``(d, n)``): the cells split
    into simplices on their vertices, the ``k`` simplices with the
    nearest centroids (``4 k`` for the points none of them holds) and
    their smallest barycentric coordinates; returns ``(cells (n, kk),
    scores (n, kk))`` (a score >= ``-INSIDE``: the point is in the
    cell)."""
    from scipy.spatial import cKDTree
    x = np.asarray(x, dtype=float)
    t = mesh.t
    blocks = next((b for cls, b in _SIMPLICES.items()
                   if isinstance(mesh, cls)), None)
    if blocks is None:  # triangles, tetrahedra (their corner rows)
        ts = t[:mesh.p.shape[0] + 1]
        parent = np.arange(t.shape[1])
    else:
        ts = np.hstack([t[list(b)] for b in blocks])
        parent = np.tile(np.arange(t.shape[1]), len(blocks))
    X = mesh.p[:, ts]  # (d, d + 1, ns)
    ns = X.shape[2]
    E = np.moveaxis(X[:, 1:] - X[:, :1], -1, 0)  # (ns, d, d): edges
    Einv = np.linalg.inv(E)
    tree = cKDTree(X.mean(axis=1).T)

    def scores(points, kk):
        kk = min(kk, ns)
        _, cand = tree.query(points.T, k=kk)
        cand = cand.reshape(points.shape[1], kk)
        r = points.T[:, None, :] - np.moveaxis(X[:, 0, cand], 0, -1)
        lam = np.einsum("nkij,nkj->nki", Einv[cand], r)  # (n, kk, d)
        return cand, np.minimum(1.0 - lam.sum(-1), lam.min(-1))

    cand, score = scores(x, k)
    far = np.flatnonzero(score.max(axis=1) < -INSIDE)
    if len(far) and ns > k:  # not among the nearest: look wider
        c2, s2 = scores(x[:, far], 4 * k)
        wide = c2.shape[1] - cand.shape[1]  # columns that never win
        cand = np.pad(cand, ((0, 0), (0, wide)), mode="edge")
        score = np.pad(score, ((0, 0), (0, wide)), constant_values=-np.inf)
        cand[far], score[far] = c2, s2  # the wider search holds the nearer
    return parent[cand], score


def locate(mesh, x, k=12):
    """The cell of ``mesh`` that contains each point of ``x`` (``(d,
    n)``), vectorized (:func:`_search`): a point on a face shared by
    cells goes to one of them; a point outside every cell to the cell it
    is closest to (the simplex whose smallest barycentric coordinate is
    the largest).  :func:`cell_average` averages over the cells sharing
    the point instead.

    >>> import numpy as np, skfem as fem
    >>> mesh = fem.MeshTri.init_circle(2)
    >>> c = locate(mesh, np.array([[0.0, 1.0, 0.1], [0.0, 0.0, 0.0]]))
    >>> len(c), bool(np.all((c >= 0) & (c < mesh.nelements)))
    (3, True)
    """
    cells, score = _search(mesh, x, k)
    return cells[np.arange(len(cells)), np.argmax(score, axis=1)]


def cell_average(mesh, x, values, k=12):
    """``values`` (one per cell) at the points ``x`` (``(d, n)``): the
    value of the cell that contains a point, the mean over the cells
    whose common face or edge holds it (a bond along a material
    interface is half on either side), the closest cell's outside
    every cell."""
    cells, score = _search(mesh, x, k)
    n = len(cells)
    inside = score >= -INSIDE
    best = np.argmax(score, axis=1)
    inside[np.arange(n), best] = True  # the closest where none holds it
    rows = np.repeat(np.arange(n), inside.sum(axis=1))
    pairs = np.unique(np.stack([rows, cells[inside]]), axis=1)
    count = np.bincount(pairs[0], minlength=n)
    total = np.bincount(pairs[0], weights=np.asarray(values)[pairs[1]],
                        minlength=n)
    return total / count


__all__ = ["cell_values_at_members", "cell_average", "locate"]
