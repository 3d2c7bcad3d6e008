r"""Particles collocated from scikit-fem meshes.

A particle ``p`` carries a reference position :math:`X^p` and a volume
:math:`V^p > 0`.  Two collocations are offered:

* ``kind="vertices"`` (default): positions are the mesh vertices and the
  volumes are lumped, :math:`V^p = \int_\Omega N_p \,d\Omega` (row sum of the
  consistent P1/Q1 mass matrix).  Particle ``p`` is mesh vertex ``p``, so the
  degrees of freedom coincide with scikit-fem's nodal numbering and FE and PG
  matrices can be added.
* ``kind="centroids"``: positions are element barycentres and volumes are the
  element volumes; no particle lies on the surface.

Surface area vectors :math:`A^i = \int_{\partial\Omega} N_i \, n \,d\Gamma`
(thesis (5.18); FE consistent with the linear boundary facets) are what the
variationally consistent (VC) correction needs on the surface.
"""

import numpy as np
from scipy.spatial import cKDTree
import skfem as fem

from ..errors import ParticleError, UnsupportedMeshError, describe_particle
from .shape import mls1_values

# nodal (P1/Q1) and constant (P0) element of each supported linear mesh
_LINEAR_ELEMENTS = {
    fem.ElementTriP1: (fem.ElementTriP1, fem.ElementTriP0),
    fem.ElementQuad1: (fem.ElementQuad1, fem.ElementQuad0),
    fem.ElementTetP1: (fem.ElementTetP1, fem.ElementTetP0),
    fem.ElementHex1: (fem.ElementHex1, fem.ElementHex0),
}


def linear_elements(mesh):
    """Return ``(nodal_element, constant_element)`` instances for ``mesh``.

    Raises :class:`UnsupportedMeshError` for anything but MeshTri1, MeshQuad1,
    MeshTet1 and MeshHex1.
    """
    if not isinstance(mesh, fem.Mesh):
        raise UnsupportedMeshError(
            "expected a scikit-fem Mesh, got {}".format(type(mesh).__name__))
    pair = _LINEAR_ELEMENTS.get(mesh.elem)
    if pair is None:
        raise UnsupportedMeshError(
            "{} is not supported: particles are collocated from linear "
            "triangle, quadrilateral, tetrahedron or hexahedron meshes "
            "(MeshTri1, MeshQuad1, MeshTet1, MeshHex1)"
            .format(type(mesh).__name__))
    return pair[0](), pair[1]()


def _check_elements(mesh, elements):
    """Reject degenerate and inverted (self-overlapping) elements."""
    e1, _ = linear_elements(mesh)
    X, _ = fem.quadrature.get_quadrature(mesh.refdom, 2)
    det = mesh._mapping().detDF(X, tind=elements)
    scale = np.median(np.abs(det))
    bad = np.min(np.abs(det), axis=1) <= 1e-12 * scale
    if not isinstance(e1, (fem.ElementTriP1, fem.ElementTetP1)):
        # multilinear elements: the Jacobian must not change sign inside
        bad |= (np.min(det, axis=1) * np.max(det, axis=1)) <= 0
    if np.any(bad):
        e = elements[np.nonzero(bad)[0][0]]
        c = mesh.p[:, mesh.t[:, e]].mean(axis=1)
        raise ParticleError(
            "mesh element {} (centre {}) is degenerate or inverted "
            "(det J = {:.3g} .. {:.3g}); its particles would get a "
            "non-positive volume".format(
                e, tuple(float(v) for v in np.round(c, 6)),
                det[bad][0].min(), det[bad][0].max()))
    folded = folded_facets(mesh, elements)
    if len(folded):
        f = folded[0]
        e = mesh.f2t[:, f]
        c = mesh.p[:, mesh.facets[:, f]].mean(axis=1)
        raise ParticleError(
            "mesh elements {} and {} lie on the same side of their shared "
            "facet {} (centre {}): the mesh is folded (a vertex pushed "
            "through a neighbour; {} such facets), so its lumped volumes "
            "overlap".format(e[0], e[1], f,
                             tuple(float(v) for v in np.round(c, 6)),
                             len(folded)))


def folded_facets(mesh, elements=None, p=None):
    """Interior facets (between two of ``elements``) whose two elements'
    centroids lie on the same side of the facet's line/plane: a folded or
    tangled mesh (vertex positions ``p``, default ``mesh.p``), which the
    element Jacobians of simplices cannot show.  Returns facet indices."""
    p = mesh.p if p is None else p
    f2t = mesh.f2t
    inner = np.nonzero(f2t[1] >= 0)[0]
    if elements is not None:
        keep = np.zeros(mesh.nelements, dtype=bool)
        keep[elements] = True
        inner = inner[keep[f2t[0, inner]] & keep[f2t[1, inner]]]
    F = p[:, mesh.facets[:, inner]]  # (d, nvf, nf)
    d = p.shape[0]
    if d == 2:
        e = F[:, 1] - F[:, 0]
        n = np.array([-e[1], e[0]])
    else:
        n = np.cross(F[:, 1] - F[:, 0], F[:, 2] - F[:, 0], axis=0)
    x0 = F.mean(axis=1)
    c = p[:, mesh.t].mean(axis=1)  # element centroids
    s0 = (n * (c[:, f2t[0, inner]] - x0)).sum(0)
    s1 = (n * (c[:, f2t[1, inner]] - x0)).sum(0)
    return inner[s0 * s1 >= 0]


def inverted_cells(particles, u):
    r"""Cells of the collocation mesh that the particle displacement ``u``
    (scikit-fem nodal numbering) turns inside out.

    PG checks :math:`J^{kj} > 0` at its own integration points only;
    particles can still cross each other.  Mapping ``u`` onto the mesh the
    particles were collocated from shows it: a cell is inverted where its
    Jacobian changes sign (at the corners of multilinear cells) or, for
    simplices, where it lies on the wrong side of a neighbour
    (:func:`folded_facets`).  Returns the indices of inverted cells.
    """
    if particles.kind != "vertices" or particles.mesh is None:
        raise ValueError("inverted_cells needs particles collocated from a "
                         "mesh's vertices (Particles.from_mesh)")
    mesh = particles.mesh
    d = mesh.dim()
    x = mesh.p + np.asarray(u, dtype=float).reshape(-1, d).T
    tind = (np.arange(mesh.nelements) if particles.elements is None
            else np.asarray(particles.elements))
    deformed = type(mesh)(x, mesh.t)
    if isinstance(mesh, (fem.MeshTri1, fem.MeshTet1)):  # constant det J
        X, _ = fem.quadrature.get_quadrature(mesh.refdom, 1)
    else:  # a multilinear Jacobian is extreme at the cell's corners
        X = type(mesh).init_refdom().p
    s0 = np.sign(mesh._mapping().detDF(X, tind=tind))
    s1 = deformed._mapping().detDF(X, tind=tind) * s0
    bad = np.zeros(mesh.nelements, dtype=bool)
    bad[tind[np.any(s1 <= 0, axis=1)]] = True
    folded = folded_facets(mesh, tind, p=x)
    bad[mesh.f2t[:, folded].ravel()] = True
    return np.nonzero(bad)[0]


class Particles:
    r"""Reference positions and volumes of a particle set.

    Parameters
    ----------
    x
        Positions, shape ``(dim, n)`` (scikit-fem's layout, like ``mesh.p``).
    volumes
        Volumes :math:`V^p`, shape ``(n,)``.  Particles with zero volume are
        *inactive*: they keep their index (and degrees of freedom) but belong
        to no family; this is how a PG subdomain keeps the global numbering
        of the whole mesh.  Negative volumes are an error.
    mesh, kind, elements
        Provenance, set by :meth:`from_mesh`.  ``mesh`` is needed for surface
        area vectors, boundary loads and ``get_dofs`` by facets.

    Examples
    --------
    Particles collocated from a scikit-fem mesh: its vertices, with their
    lumped volumes (the volumes add up to the domain's):

    >>> import skfem as fem
    >>> p = Particles.from_mesh(fem.MeshQuad().refined(2))
    >>> p.n, p.dim, round(float(p.volumes.sum()), 12)
    (25, 2, 1.0)

    """

    def __init__(self, x, volumes, mesh=None, kind="points", elements=None):
        x = np.atleast_2d(np.asarray(x, dtype=float))
        volumes = np.asarray(volumes, dtype=float).ravel()
        if x.shape[0] not in (1, 2, 3):
            raise ParticleError(
                "positions must have shape (dim, n) with dim 1, 2 or 3; "
                "got {}".format(x.shape))
        if volumes.shape[0] != x.shape[1]:
            raise ParticleError(
                "{} volumes given for {} particles".format(volumes.shape[0],
                                                           x.shape[1]))
        self.x = x
        self.volumes = volumes
        self.mesh = mesh
        self.kind = kind
        self.elements = elements
        self._area_vectors = None
        self._surface_area_vectors = None
        self._facet_mesh = None
        self._validate(allow_inactive=elements is not None)

    # -- construction ------------------------------------------------------
    @classmethod
    def from_mesh(cls, mesh, kind="vertices", elements=None):
        """Collocate particles from a linear scikit-fem mesh.

        Parameters
        ----------
        mesh
            MeshTri1, MeshQuad1, MeshTet1 or MeshHex1.
        kind
            ``"vertices"``: vertices with lumped volumes :math:`\\int N_p`;
            ``"centroids"``: element barycentres with element volumes.
        elements
            Optional subset of elements (anything ``mesh.normalize_elements``
            accepts, e.g. a callable or a subdomain name).  With vertex
            particles the volumes are lumped over this subset only and
            vertices outside it are inactive (zero volume): use this for the
            PG part of an FE–PG coupled model.

        """
        e1, e0 = linear_elements(mesh)
        dim = mesh.refdom.dim() if hasattr(mesh.refdom, "dim") else None
        if dim is not None and mesh.p.shape[0] != dim:
            raise ParticleError(
                "{} has {}-D elements but {} coordinates per vertex: give "
                "it (d, n) = ({}, n) points (drop the extra coordinate)"
                .format(type(mesh).__name__, dim, mesh.p.shape[0], dim))
        unused = np.setdiff1d(np.arange(mesh.p.shape[1]), mesh.t)
        if len(unused) and kind == "vertices":
            raise ParticleError(
                "{} vertex(es) belong to no element, first {}: remove them "
                "(e.g. mesh.remove_unused_nodes())".format(
                    len(unused), describe_particle(unused[0],
                                                   mesh.p[:, unused[0]])))
        subset = None if elements is None else \
            np.asarray(mesh.normalize_elements(elements), dtype=np.int64)
        tind = np.arange(mesh.nelements) if subset is None else subset
        if len(tind) == 0:
            raise ParticleError("the element subset is empty")
        _check_elements(mesh, tind)
        if kind == "vertices":
            basis = fem.Basis(mesh, e1, elements=subset)
            volumes = fem.LinearForm(lambda v, w: v).assemble(basis)
            if subset is not None:
                untouched = np.setdiff1d(np.arange(mesh.nvertices),
                                         np.unique(mesh.t[:, subset]))
                volumes[untouched] = 0.0
            return cls(mesh.p.copy(), volumes, mesh=mesh, kind="vertices",
                       elements=subset)
        if kind == "centroids":
            basis = fem.Basis(mesh, e0, elements=subset)
            dx = basis.dx
            xq = basis.global_coordinates()
            vol = dx.sum(axis=1)
            x = np.einsum("dkq,kq->dk", np.asarray(xq), dx) / vol
            # elements keeps the map particle -> element
            obj = cls(x, vol, mesh=mesh, kind="centroids", elements=None)
            obj.elements = tind
            return obj
        raise ValueError("kind must be 'vertices' or 'centroids', "
                         "got {!r}".format(kind))

    @classmethod
    def from_file(cls, filename, kind="vertices", **kwargs):
        """Read a mesh (e.g. a gmsh ``.msh`` file) with ``skfem.Mesh.load``
        and collocate particles from it.  Physical groups become
        ``mesh.boundaries`` / ``mesh.subdomains``."""
        mesh = fem.Mesh.load(filename, **kwargs)
        return cls.from_mesh(mesh, kind=kind)

    # -- properties --------------------------------------------------------
    @property
    def dim(self):
        """Spatial dimension."""
        return self.x.shape[0]

    @property
    def n(self):
        """Number of particles (active and inactive)."""
        return self.x.shape[1]

    def __len__(self):
        return self.n

    @property
    def active(self):
        """Boolean mask of particles with positive volume."""
        return self.volumes > 0

    @property
    def spacing(self):
        r"""Mean particle spacing :math:`h = \overline{V}^{1/d}`."""
        return float(np.mean(self.volumes[self.active]) ** (1.0 / self.dim))

    def __repr__(self):
        return ("<skfem_pg Particles: {} {} in {}-D, {} active, h={:.4g}>"
                ).format(
            self.n, self.kind, self.dim, int(self.active.sum()), self.spacing)

    # -- validation --------------------------------------------------------
    def _validate(self, allow_inactive):
        x, v = self.x, self.volumes
        if not np.all(np.isfinite(x)):
            p = np.nonzero(~np.all(np.isfinite(x), axis=0))[0][0]
            raise ParticleError("{} has a non-finite position".format(
                describe_particle(p, x[:, p])))
        bad = ~np.isfinite(v) | (v < 0) | ((v == 0) & (not allow_inactive))
        if np.any(bad):
            p = np.nonzero(bad)[0][0]
            raise ParticleError(
                "{} has volume {:.6g}; volumes must be positive ({} of {} "
                "particles are affected)".format(
                    describe_particle(p, x[:, p]), v[p], int(bad.sum()),
                    len(v)))
        act = np.nonzero(self.active)[0]
        if len(act) == 0:
            raise ParticleError("no particle has a positive volume")
        tree = cKDTree(x[:, act].T)
        h = np.mean(v[act]) ** (1.0 / self.dim)
        pairs = tree.query_pairs(r=1e-9 * h, output_type="ndarray")
        if len(pairs):
            a, b = act[pairs[0]]
            raise ParticleError(
                "{} and particle {} are duplicates (distance {:.3g}, mean "
                "spacing {:.3g}); {} duplicate pair(s) in total".format(
                    describe_particle(a, x[:, a]), b,
                    np.linalg.norm(x[:, a] - x[:, b]), h, len(pairs)))

    # -- surface -----------------------------------------------------------
    def boundary_facets(self):
        """Oriented boundary facets of the particles' mesh region."""
        self._need_mesh("boundary facets")
        elements = (np.arange(self.mesh.nelements) if self.elements is None
                    else self.elements)
        return self.mesh.facets_around(elements)

    def outer_facets(self):
        """Boundary facets of the particles' region that lie on the mesh's
        own boundary — not on an interface with the rest of the mesh (FE
        elements in an FE–PG coupled model)."""
        f = np.asarray(self.boundary_facets())  # one element each: no
        return f[self.mesh.f2t[1, f] < 0]        # orientation needed

    def surface_area_vectors(self):
        """Area vectors over :meth:`outer_facets` only, ``(dim, n)``: the
        true surface particles of a PG subdomain (what the VC boundary
        variants ``s``/``sn`` release); equal to :meth:`area_vectors` for a
        whole mesh and for centroid particles."""
        if self.kind != "vertices" or self.elements is None:
            return self.area_vectors()
        if self._surface_area_vectors is None:
            self._surface_area_vectors = self.area_vectors(
                self.outer_facets())
        return self._surface_area_vectors

    def area_vectors(self, facets=None):
        r"""FE-consistent nodal area vectors, shape ``(dim, n)``.

        .. math::  A^i = \int_{\Gamma} N_i \, n \, d\Gamma

        over the boundary of the particles' region (default; for a subdomain
        this includes the interface with the rest of the mesh, with normals
        pointing out of the subdomain) or over the given ``facets``.
        Vertex particles use the mesh's P1/Q1 functions :math:`N_i`; interior
        particles get :math:`A^i = 0`.  Centroid particles have no surface
        particles: :math:`N_i` are then MLS1 functions of the nearest
        ``3·dim`` particles at the facet quadrature points, which reproduce
        linear fields, so that :math:`\sum_i X^i\otimes A^i = V\,I` as the
        integration constraint requires.  Used as the right-hand side of the
        integration constraint (5.18) and for Neumann loads.
        """
        if facets is None and self._area_vectors is not None:
            return self._area_vectors
        self._need_mesh("area vectors")
        if self.kind == "centroids":
            out = self._mls_area_vectors(facets)
            if facets is None:
                self._area_vectors = out
            return out
        fb = self._facet_basis(facets)
        out = np.zeros((self.dim, fb.N))
        for c in range(self.dim):
            out[c] = fem.LinearForm(lambda v, w: v * w.n[c]).assemble(fb)
        # exact zeros off the facets (not round-off of the facet basis)
        on = np.zeros(fb.N, dtype=bool)
        on[self.mesh.facets[:, fb.find].ravel()] = True
        out[:, ~on] = 0.0
        if facets is None:
            self._area_vectors = out
        return out

    def area_moments(self, origin=None, facets=None):
        r"""FE-consistent first moments of the area vectors, shape
        ``(dim, dim, n)``:

        .. math:: A_2^{i}{}_{cB} = \int_\Gamma N_i\,(x - x_0)_c\, n_B
                  \,d\Gamma ,

        ``x_0 = origin`` (default 0): the boundary term of the second-order
        integration constraint (VC2, (5.26)).  Vertex particles only."""
        self._need_mesh("area moments")
        if self.kind != "vertices":
            raise NotImplementedError("area moments need vertex particles")
        x0 = np.zeros(self.dim) if origin is None else np.asarray(origin)
        x0 = x0 - self.facet_origin  # the facet basis is local
        fb = self._facet_basis(facets)
        out = np.zeros((self.dim, self.dim, fb.N))
        for c in range(self.dim):
            for b in range(self.dim):
                out[c, b] = fem.LinearForm(
                    lambda v, w: v * (w.x[c] - x0[c]) * w.n[b]).assemble(fb)
        on = np.zeros(fb.N, dtype=bool)
        on[self.mesh.facets[:, fb.find].ravel()] = True
        out[..., ~on] = 0.0
        return out

    def _mls_area_vectors(self, facets=None):
        e1, _ = linear_elements(self.mesh)
        elements = self.elements
        if facets is None:
            facets = self.mesh.facets_around(elements)
        else:
            facets = self.mesh.normalize_facets(facets)
        fb = fem.FacetBasis(self.facet_mesh(), e1, facets=facets, intorder=3)
        xq = (np.asarray(fb.global_coordinates()).reshape(self.dim, -1).T
              + self.facet_origin)
        ndg = (np.asarray(fb.normals) * fb.dx[None]).reshape(self.dim, -1)
        k = min(3 * self.dim, self.n)
        _, nb = cKDTree(self.x.T).query(xq, k=k)
        D = self.x.T[nb] - xq[:, None, :]
        h = np.sqrt((D ** 2).sum(-1).max(axis=1))
        N, singular = mls1_values(D / h[:, None, None], self.volumes[nb])
        if np.any(singular):
            q = np.nonzero(singular)[0][0]
            raise ParticleError("MLS1 at boundary point {} is singular: its "
                                "{} nearest particles are collinear/coplanar"
                                .format(tuple(np.round(xq[q], 6)), k))
        out = np.zeros((self.dim, self.n))
        for c in range(self.dim):
            out[c] = np.bincount(nb.ravel(), weights=(N * ndg[c][:, None])
                                 .ravel(), minlength=self.n)
        return out

    @property
    def facet_origin(self):
        """The corner of the mesh's bounding box, shape ``(dim,)``: facet
        integrals (area vectors, area moments, tractions) are computed on
        the mesh translated by ``-facet_origin`` — their values do not
        depend on where the body sits, but scikit-fem's quadrilateral and
        hexahedral facet mappings (an inverse-mapping Newton iteration
        with an absolute tolerance of 1e-12) fail on a mesh 1e3 away from
        the origin.  Facet points ``w.x`` of these integrals are local:
        add ``facet_origin`` for global positions."""
        self._need_mesh("facet integrals")
        return self.mesh.p.min(axis=1)

    def facet_mesh(self):
        """The mesh translated by ``-facet_origin`` (the mesh itself if
        that is zero); same elements, facets and facet numbers."""
        if self._facet_mesh is None:
            origin = self.facet_origin
            self._facet_mesh = (self.mesh if not origin.any()
                                else self.mesh.translated(-origin))
        return self._facet_mesh

    def _facet_basis(self, facets=None, vector=False):
        e1, e0 = linear_elements(self.mesh)
        elem = e1 if self.kind == "vertices" else e0
        if vector:
            elem = fem.ElementVector(elem)
        facets = (self.boundary_facets() if facets is None
                  else self.mesh.normalize_facets(facets))
        return fem.FacetBasis(self.facet_mesh(), elem, facets=facets,
                              intorder=3)

    def _need_mesh(self, what):
        if self.mesh is None:
            raise ParticleError(
                "{} need the mesh the particles were collocated from; "
                "build the particles with Particles.from_mesh".format(what))
