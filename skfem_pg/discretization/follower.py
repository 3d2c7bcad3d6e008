r"""Follower pressure: a surface load that turns with the surface.

A pressure :math:`p` on the boundary facets of the mesh the particles were
collocated from (or of an FE basis' mesh) acts on the *current* surface,

.. math::

    f^a(x) = -\int_{\Gamma} p\, N_a\, n\, da
           = -\int_{\square} p\, N_a(\xi)\, \nu(\xi)\, d\xi,
    \qquad
    \nu = \begin{cases} R\, \partial_\xi x & \text{2-D (per unit
    thickness)}, \\ \partial_{\xi_1} x \times \partial_{\xi_2} x
    & \text{3-D,} \end{cases}

integrated with the facets' linear shape functions :math:`N_a` (the same
FE-consistent facets as :func:`~skfem_pg.discretization.loads.traction`),
:math:`x = X + u` at the facet's vertices and :math:`R` the rotation by
-90°.  A positive ``p`` pushes against the outward normal (compression).
:meth:`FollowerPressure.stiffness` is :math:`\partial f / \partial u`,
the load's share of Newton's tangent (not symmetric in general); both are
exact for segments, triangles (one point) and bilinear quadrilaterals
(2 × 2 Gauss points).

:func:`skfem_pg.solvers.newton` takes such a load in ``f_ext`` (alone or
in a list beside dead load vectors) and scales it by the load factor like
a dead load.
"""
from __future__ import annotations

from typing import Callable

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike

__all__ = ["FollowerPressure", "split_loads"]

# facet reference rules: shape functions N (q, a), derivatives dN (r, q, a),
# weights w (q,)
_G = 1.0 / np.sqrt(3.0)


def _segment():
    N = np.array([[0.5, 0.5]])
    dN = np.array([[[-1.0, 1.0]]])
    return N, dN, np.array([1.0])


def _triangle():
    N = np.full((1, 3), 1.0 / 3.0)
    dN = np.array([[[-1.0, 1.0, 0.0]], [[-1.0, 0.0, 1.0]]])
    return N, dN, np.array([0.5])


def _quadrilateral():
    xi = np.array([-_G, _G, _G, -_G])
    eta = np.array([-_G, -_G, _G, _G])
    sx = np.array([-1.0, 1.0, 1.0, -1.0])  # cyclic vertex order
    sy = np.array([-1.0, -1.0, 1.0, 1.0])
    N = 0.25 * (1 + sx * xi[:, None]) * (1 + sy * eta[:, None])
    dN = np.stack([0.25 * sx * (1 + sy * eta[:, None]),
                   0.25 * sy * (1 + sx * xi[:, None])])
    return N, dN, np.ones(4)


_RULES = {(2, 2): _segment, (3, 3): _triangle, (3, 4): _quadrilateral}
# the rotation of a 2-D facet tangent to its normal
_R = np.array([[0.0, 1.0], [-1.0, 0.0]])


def _skew(v):
    """``(3, 3, ...)`` matrices with ``skew(v) @ w = v × w``."""
    z = np.zeros_like(v[0])
    return np.array([[z, -v[2], v[1]], [v[2], z, -v[0]],
                     [-v[1], v[0], z]])


def _mesh_and_dofs(basis):
    """The mesh whose facets carry the load and the ``(nc, nverts)`` dofs
    of its vertices in ``basis``."""
    particles = getattr(basis, "particles", None)
    if particles is not None:  # a FamilyBasis
        mesh = particles.mesh
        if mesh is None or particles.n != mesh.p.shape[1] or not np.allclose(
                particles.x, mesh.p):
            raise ValueError(
                "FollowerPressure needs particles at a mesh's vertices (the "
                "facets carry the load): these {} particles are not the "
                "vertices of a mesh".format(particles.kind))
        nc = basis.ncomp
        if nc != mesh.dim():
            raise ValueError("FollowerPressure acts on displacements: build "
                             "the basis with dim={}".format(mesh.dim()))
        return mesh, basis.nodal_dofs  # scikit-fem's, of the vertex particles
    mesh = basis.mesh
    elem = getattr(basis, "elem", None)
    nodal = getattr(basis, "nodal_dofs", None)
    if (nodal is None or nodal.shape[0] != mesh.dim()
            or basis.Nbfun != mesh.dim() * mesh.t.shape[0]):
        raise NotImplementedError(
            "FollowerPressure takes linear vector elements (T1, Q1, O1, H1 "
            "as ElementVector), got {}: a higher-order element's facet "
            "nodes are not the mesh vertices".format(type(elem).__name__))
    return mesh, nodal


def _facet_indices(mesh, facets):
    if callable(facets):
        facets = mesh.facets_satisfying(facets)
    elif isinstance(facets, str):
        if mesh.boundaries is None or facets not in mesh.boundaries:
            raise ValueError("the mesh has no boundary named {!r}{}".format(
                facets, "" if not mesh.boundaries else
                " (it has {})".format(sorted(mesh.boundaries))))
        facets = mesh.boundaries[facets]
    facets = np.asarray(facets, dtype=np.int64).ravel()
    if len(facets) == 0:
        raise ValueError("FollowerPressure on no facets: the selection is "
                         "empty")
    if facets.min() < 0 or facets.max() >= mesh.facets.shape[1]:
        raise ValueError("facet index out of range [0, {})".format(
            mesh.facets.shape[1]))
    inner = facets[mesh.f2t[1, facets] >= 0]
    if len(inner):
        x = mesh.p[:, mesh.facets[:, inner[0]]].mean(axis=1)
        raise ValueError(
            "facet {} at {} is inside the mesh: a pressure acts on "
            "boundary facets".format(inner[0], np.round(x, 12).tolist()))
    return facets


class FollowerPressure:
    r"""A pressure on boundary facets that follows the deformed surface
    (module docstring).

    Parameters
    ----------
    basis : FamilyBasis or skfem.CellBasis
        A displacement basis: a :class:`~skfem_pg.FamilyBasis` of a mesh's
        vertices (``dim=`` the space dimension) or a scikit-fem basis of a
        linear vector element (T1, Q1, O1, H1).
    facets : array_like, str or callable
        Boundary facets of the mesh: indices, a boundary name, or a
        callable of facet midpoints ``x`` (``mesh.facets_satisfying``).
    pressure : float, array_like or callable
        The pressure at load factor 1: a number, one value per facet, or a
        callable of the facets' reference midpoints ``(dim, n_facets)``.
        Positive pushes against the outward normal.

    Examples
    --------
    A unit square's right edge under p = 2, undeformed: the load is
    ``-p`` times the edge's length, along its outward normal.

    >>> import numpy as np, skfem as fem, skfem_pg as pg
    >>> mesh = fem.MeshQuad().refined(2)
    >>> basis = pg.FamilyBasis(mesh, dim=2)
    >>> load = FollowerPressure(basis, lambda x: x[0] == 1.0, 2.0)
    >>> f = load.force(np.zeros(basis.N))
    >>> float(f[0::2].sum()), float(f[1::2].sum())
    (-2.0, 0.0)
    >>> load.stiffness(np.zeros(basis.N)).shape == (basis.N, basis.N)
    True
    """

    def __init__(self, basis, facets, pressure: float | ArrayLike |
                 Callable = 1.0):
        mesh, nodal = _mesh_and_dofs(basis)
        self.N = basis.N
        facets = _facet_indices(mesh, facets)
        nodes = mesh.facets[:, facets]
        d, nv = mesh.dim(), nodes.shape[0]
        if (d, nv) not in _RULES:
            raise NotImplementedError(
                "FollowerPressure on {}-D facets with {} vertices".format(
                    d, nv))
        self._N, self._dN, self._w = _RULES[(d, nv)]()
        # outward orientation: the reference normal points away from the
        # centroid of the facet's cell
        X = mesh.p[:, nodes]  # (d, nv, nf)
        nu = self._normal(X).mean(axis=1)
        cell = mesh.p[:, mesh.t[:, mesh.f2t[0, facets]]].mean(axis=1)
        out = np.einsum("in,in->n", nu, X.mean(axis=1) - cell) < 0
        nodes[:, out] = nodes[::-1][:, out]  # the other orientation
        self.facets = facets
        self.X = mesh.p[:, nodes]
        self.dofs = nodal[:, nodes]  # (d, nv, nf)
        if callable(pressure):
            pressure = pressure(self.X.mean(axis=1))
        pressure = np.asarray(pressure, dtype=float)
        if pressure.ndim > 1 or pressure.size not in (1, len(facets)):
            raise ValueError(
                "FollowerPressure: the pressure has shape {}; give a number "
                "or one value per facet ({})".format(pressure.shape,
                                                     len(facets)))
        self.pressure = np.broadcast_to(pressure, (len(facets),)).copy()
        bad = np.flatnonzero(~np.isfinite(self.pressure))
        if len(bad):
            raise ValueError(
                "FollowerPressure: pressure {} on facet {} at {}".format(
                    self.pressure[bad[0]], facets[bad[0]], np.round(
                        self.X[:, :, bad[0]].mean(axis=1), 12).tolist()))
        rows = np.broadcast_to(self.dofs[:, :, None, None], (d, nv, d, nv)
                               + (len(facets),))
        cols = np.broadcast_to(self.dofs[None, None], rows.shape)
        self._rows, self._cols = rows.ravel(), cols.ravel()

    def _tangents(self, x):
        """``(r, d, q, nf)``: :math:`\\partial_{\\xi_r} x` at the points."""
        return np.einsum("rqa,iaf->riqf", self._dN, x)

    def _normal(self, x):
        """``(d, q, nf)``: the area-weighted normal :math:`\\nu`."""
        g = self._tangents(x)
        if x.shape[0] == 2:
            return np.einsum("ij,jqf->iqf", _R, g[0])
        return np.cross(g[0], g[1], axis=0)

    def _current(self, u):
        u = np.asarray(u, dtype=float)
        if u.shape[0] < self.N:
            raise ValueError("FollowerPressure: {} unknowns, the basis has "
                             "{} dofs".format(u.shape[0], self.N))
        return self.X + u[self.dofs]

    def force(self, u: ArrayLike) -> np.ndarray:
        """The load vector ``(N,)`` at the displacements ``u``."""
        nu = self._normal(self._current(u))  # (d, q, nf)
        fa = -np.einsum("q,qa,iqf,f->iaf", self._w, self._N, nu,
                        self.pressure)
        return np.bincount(self.dofs.ravel(), weights=fa.ravel(),
                           minlength=self.N)

    def stiffness(self, u: ArrayLike) -> sp.csr_matrix:
        r""":math:`\partial f / \partial u`, sparse ``(N, N)``."""
        x = self._current(u)
        d = x.shape[0]
        if d == 2:  # dnu_i/dx_cj = R_ij dN_c
            dnu = np.einsum("ij,qc,f->ijqcf", _R, self._dN[0, :, :],
                            np.ones(x.shape[-1]))
        else:  # dnu/dx_c = -skew(g2) dN1_c + skew(g1) dN2_c
            g = self._tangents(x)
            dnu = (-np.einsum("ijqf,qc->ijqcf", _skew(g[1]), self._dN[0])
                   + np.einsum("ijqf,qc->ijqcf", _skew(g[0]), self._dN[1]))
        k = -np.einsum("q,qa,ijqcf,f->iajcf", self._w, self._N, dnu,
                       self.pressure)
        return sp.coo_matrix((k.ravel(), (self._rows, self._cols)),
                             shape=(self.N, self.N)).tocsr()


def split_loads(f_ext):
    """``(dead, followers)``: the dead load (``f_ext`` itself when it holds
    no deformation-dependent load: a vector, a callable of the time or
    ``None``; the sum of the vectors of a list) and the
    deformation-dependent loads (objects with ``force(u)`` and
    ``stiffness(u)``) of ``f_ext`` — one such load or a list of both."""
    if _follows(f_ext):
        return None, [f_ext]
    if not (isinstance(f_ext, (list, tuple))
            and any(_follows(f) for f in f_ext)):
        return f_ext, []
    dead, followers = None, []
    for f in f_ext:
        if _follows(f):
            followers.append(f)
        elif f is not None:
            dead = np.asarray(f, dtype=float) if dead is None \
                else dead + np.asarray(f, dtype=float)
    return dead, followers


def _follows(f):
    return hasattr(f, "force") and hasattr(f, "stiffness")
