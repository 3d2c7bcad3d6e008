"""A crack as a set of failed cells of the collocation mesh: pure
functions of the mesh and a mask of intact cells, which the crack-aware
models (:mod:`skfem_pg.formulations.crack_aware`) call.

* :func:`failure_counts` — per cell, the integration points
  :math:`(k, j)` it holds and how many of them have failed;
* :func:`pieces` — the pieces of the intact cells (connected through
  facets);
* :func:`separate` — the intact cells made clean: no two pieces touching
  at a vertex (a pinch a family would bridge), no flaps, no debris.

>>> import numpy as np, skfem as fem
>>> mesh = fem.MeshTri.init_tensor(np.linspace(0, 2, 5), np.linspace(0, 1, 3))
>>> left = mesh.p[0, mesh.t].mean(axis=0) < 1.0
>>> label, size = pieces(mesh, left | (mesh.p[0, mesh.t].mean(axis=0) > 1.5))
>>> size.tolist()
[8, 4]
"""
import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components


def failure_counts(keys, n, cells, failed):
    """``(failed, held)``: per cell, how many of the points ``keys``
    (:math:`k n + j`, particles numbered ``0..n-1`` as the vertices of
    ``cells``) it holds, and how many of them have ``failed`` (counts:
    on MPI ranks they are summed over the ranks)."""
    keys = np.asarray(keys)
    if keys.size == 0:  # a rank without points
        return (np.zeros(cells.shape[1], int),) * 2
    order = np.argsort(keys)
    sk = keys[order]
    q = (cells[:, None, :] * n + cells[None, :, :]).reshape(-1,
                                                          cells.shape[1])
    pos = np.minimum(np.searchsorted(sk, q), len(sk) - 1)
    hit = sk[pos] == q
    bad = hit & np.asarray(failed, bool).ravel()[order[pos]]
    return bad.sum(axis=0), hit.sum(axis=0)


def pieces(mesh, intact):
    """The pieces of the ``intact`` cells of ``mesh`` (cells sharing a
    facet are connected): ``(label per intact cell, cells per piece)``."""
    idx = np.flatnonzero(intact)
    if idx.size == 0:
        return np.zeros(0, int), np.zeros(0, int)
    a, b = mesh.f2t
    both = (b >= 0) & intact[a] & intact[np.maximum(b, 0)]
    local = np.full(intact.shape[0], -1)
    local[idx] = np.arange(idx.size)
    G = sp.csr_matrix((np.ones(both.sum()), (local[a[both]],
                                             local[b[both]])),
                      shape=(idx.size, idx.size))
    _, label = connected_components(G, directed=False)
    return label, np.bincount(label)


def separate(mesh, intact, min_piece):
    """The intact cells after the pieces are made clean: a vertex whose
    cells belong to more than one piece (two pieces touching at a vertex,
    a pinch that a family would bridge) keeps the cells of its largest
    piece only; a cell with two or more vertices that the crack has left
    with this cell alone (a flap, held by one facet or less) goes too;
    pieces with fewer than ``min_piece`` vertices go (debris).  Repeated
    until nothing changes (at most once per cell)."""
    intact = intact.copy()
    nv = mesh.p.shape[1]
    cells_at = np.bincount(mesh.t.ravel(), minlength=nv)
    for _ in range(intact.size + 1):
        idx = np.flatnonzero(intact)
        label, size = pieces(mesh, intact)
        t = mesh.t[:, idx]
        left = np.bincount(t.ravel(), minlength=nv)
        alone = (left == 1) & (cells_at > 1)  # the crack took the others
        # vertices per piece, and the pieces at each vertex
        at = sp.csr_matrix((np.ones(t.size, bool), (t.ravel(), np.tile(
            label, t.shape[0]))), shape=(nv, size.size))
        at.sum_duplicates()
        drop = alone[t].sum(axis=0) >= 2  # flaps
        verts = np.diff(at.tocsc().indptr)
        drop |= verts[label] < min_piece
        pinch = np.flatnonzero(np.diff(at.indptr) > 1)
        if pinch.size:
            # at each pinch the cells of all but its largest piece go
            rows = at[pinch].tocoo()
            best = np.zeros(pinch.size, int)
            key = size[rows.col] * (size.size + 1) + rows.col
            order = np.lexsort((key, rows.row))
            last = np.r_[np.diff(rows.row[order]) != 0, True]
            best[rows.row[order][last]] = rows.col[order][last]
            keep_piece = np.full(nv, -1)
            keep_piece[pinch] = best
            touches = keep_piece[t]  # (corners, cells)
            drop |= np.any((touches >= 0) & (touches != label[None]),
                           axis=0)
        if not drop.any():
            return intact
        intact[idx[drop]] = False
    return intact


__all__ = ["failure_counts", "pieces", "separate"]
