r"""A collocation mesh built again from particles that have moved: the
Delaunay triangulation of their positions trimmed by an alpha shape, as
the particle finite element method does (Idelsohn, Oñate & Del Pin 2004)
— the re-neighbouring of a flow in the updated Lagrangian frame
(:class:`~skfem_pg.formulations.UpdatedLagrangeFluid`).

A simplex of the Delaunay triangulation is kept when its circumradius
:math:`R` is below :math:`\alpha\,h`, :math:`h` the mean of its vertices'
spacings (the particles' initial :math:`V^{1/d}`): the free surface keeps
its concavities, and particles that part by more than about
:math:`2\alpha h` are no longer neighbours.  On a square grid the
triangles have :math:`R = h/\sqrt2`, equilateral ones :math:`h/\sqrt3`.

A particle left in no kept simplex (a drop that flew off, the thin tip of
a surge) has no volume to integrate: a free particle, which the fluid
model lets fly under its loads alone until it meets the others again (as
the particle finite element method does); :func:`alpha_triangulation`,
which returns a mesh of the kept cells alone, refuses it by name.
"""
import numpy as np
import skfem as fem
from scipy.spatial import Delaunay

from ..errors import ParticleError, describe_particle


def circumradii(x, t):
    """Circumradius of each simplex ``t`` ``(d + 1, n)`` of the points
    ``x`` ``(d, N)`` (``inf`` for a degenerate one)."""
    d = x.shape[0]
    v = x[:, t]  # (d, d + 1, n)
    e = v[:, 1:] - v[:, :1]  # edges from the first vertex, (d, d, n)
    # the centre c (relative to vertex 0) solves 2 e_i . c = |e_i|^2
    A = 2.0 * np.moveaxis(e, -1, 0).transpose(0, 2, 1)  # (n, d, d) rows e_i
    b = np.einsum("aip,aip->pi", e, e)  # (n, d)
    det = np.linalg.det(A)
    scale = np.einsum("nij,nij->n", A, A) ** (d / 2)
    ok = np.abs(det) > 1e-12 * scale
    R = np.full(t.shape[1], np.inf)
    if ok.any():
        c = np.linalg.solve(A[ok], b[ok][..., None])[..., 0]
        R[ok] = np.linalg.norm(c, axis=1)
    return R


def radius_ratios(x, t):
    """The radius ratio :math:`d\\,r/R` of each simplex ``t`` of the
    points ``x`` (1 for a regular simplex, 0 for a flat one; negative
    where it turned over): inradius :math:`r = dV/\\sum_f A_f`,
    circumradius :math:`R` (:func:`circumradii`)."""
    from math import factorial
    d = x.shape[0]
    v = x[:, t]
    e = v[:, 1:] - v[:, :1]
    V = np.linalg.det(np.moveaxis(e, -1, 0).transpose(0, 2, 1)) / factorial(
        d)
    area = np.zeros(t.shape[1])
    for i in range(d + 1):  # the facet opposite vertex i
        f = np.delete(v, i, axis=1)
        g = f[:, 1:] - f[:, :1]  # (d, d - 1, n)
        G = np.einsum("aip,ajp->pij", g, g)
        area += np.sqrt(np.maximum(np.linalg.det(G), 0.0)) / factorial(d - 1)
    r = d * np.abs(V) / area
    return np.sign(V) * d * r / circumradii(x, t)


def alpha_shape(x, spacing, alpha=1.2):
    """The Delaunay triangulation of the points ``x`` ``(d, N)`` as a
    :class:`skfem.MeshTri` or :class:`skfem.MeshTet` (counter-clockwise
    simplices, every point a vertex), and the indices of its cells whose
    circumradius is below ``alpha`` times their vertices' mean
    ``spacing`` (``(N,)`` or a number): the alpha shape.  Points in none
    of these cells are the free particles
    (:func:`free_particles`); ``Particles.from_mesh(mesh,
    elements=kept)`` collocates the others.

    Examples
    --------
    A square grid's Delaunay triangles all stay; a point far off is left
    free:

    >>> import numpy as np
    >>> X, Y = np.meshgrid(np.arange(4.0), np.arange(3.0))
    >>> x = np.c_[np.array([X.ravel(), Y.ravel()]), [9.0, 1.0]]
    >>> mesh, kept = alpha_shape(x, 1.0)
    >>> len(kept), free_particles(mesh, kept)
    (12, array([12]))

    """
    x = np.asarray(x, dtype=float)
    d, n = x.shape
    if d not in (2, 3):
        raise ParticleError("alpha_shape: points in 2 or 3 dimensions, "
                            "got {}".format(d))
    if not (np.isfinite(alpha) and alpha > 0):
        raise ParticleError("alpha must be a positive number, got {!r}"
                            .format(alpha))
    h = np.broadcast_to(np.asarray(spacing, dtype=float), (n,))
    tri = Delaunay(x.T)
    if len(tri.coplanar):  # a point the triangulation dropped: a twin
        i, _, j = tri.coplanar[0]
        raise ParticleError(
            "{} and particle {} coincide to round-off: no triangulation "
            "has both (merge them)".format(describe_particle(i, x[:, i]),
                                           int(j)))
    t = tri.simplices.T.copy()
    e = x[:, t[1:]] - x[:, t[:1]]  # (d, d, n)
    flip = np.linalg.det(np.moveaxis(e, -1, 0).transpose(0, 2, 1)) < 0
    t[:2, flip] = t[1::-1, flip]
    kept = np.flatnonzero(circumradii(x, t) < alpha * h[t].mean(axis=0))
    mesh = fem.MeshTri if d == 2 else fem.MeshTet
    return mesh(np.ascontiguousarray(x), np.ascontiguousarray(t)), kept


def free_particles(mesh, kept):
    """The vertices of ``mesh`` in none of the cells ``kept``."""
    return np.setdiff1d(np.arange(mesh.p.shape[1]), mesh.t[:, kept])


def attached(x, spacing, alpha=1.2):
    """Mask of the points ``x`` in a cell of their alpha shape
    (:func:`alpha_shape`): the body, without the free particles (a drop
    ahead of a surge)."""
    mesh, kept = alpha_shape(x, spacing, alpha)
    out = np.ones(np.shape(x)[1], dtype=bool)
    out[free_particles(mesh, kept)] = False
    return out


def collocate(mesh, kept):
    """The particles of the alpha shape ``(mesh, kept)``
    (:func:`alpha_shape`): collocated from the kept cells, the free
    particles inactive (no volume)."""
    from .particles import Particles
    if len(free_particles(mesh, kept)) == 0:
        return Particles.from_mesh(type(mesh)(
            mesh.p, np.ascontiguousarray(mesh.t[:, kept])))
    return Particles.from_mesh(mesh, elements=kept)


def alpha_triangulation(x, spacing, alpha=1.2):
    """The alpha shape of :func:`alpha_shape` as a mesh of its kept
    cells alone.

    Raises
    ------
    ParticleError
        A particle is left in no cell (named with its position).

    Examples
    --------
    >>> import numpy as np
    >>> X, Y = np.meshgrid(np.arange(4.0), np.arange(3.0))
    >>> mesh = alpha_triangulation(np.array([X.ravel(), Y.ravel()]), 1.0)
    >>> import skfem_pg as pg
    >>> mesh.t.shape[1], round(float(pg.Particles.from_mesh(mesh).volumes.sum()), 12)
    (12, 6.0)

    """
    mesh, kept = alpha_shape(x, spacing, alpha)
    lonely = free_particles(mesh, kept)
    if len(lonely):
        raise ParticleError(
            "{} particle(s) are in no simplex of the alpha shape (alpha = "
            "{:g}; they parted from the others by more than about 2 alpha "
            "spacings), first {}".format(len(lonely), alpha,
                                         describe_particle(
                                             lonely[0], mesh.p[:, lonely[0]])))
    return type(mesh)(mesh.p, np.ascontiguousarray(mesh.t[:, kept]))
