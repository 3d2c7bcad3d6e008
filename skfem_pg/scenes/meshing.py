"""Node sets for tests and benchmarks: distorted meshes, Cook's membrane,
gmsh geometries.

gmsh is used through its Python API; ``.geo`` sources ship as package data
in the repository's ``meshes/`` (:func:`geo_path`).
"""
import dataclasses
import importlib.util
import logging
import os
import tempfile

import numpy as np
import scipy.sparse as sp
import meshio
import skfem as fem
from skfem.io.meshio import from_meshio

#: Cook's membrane corners (thesis 7.1)
COOK_CORNERS = np.array([[0.0, 0.0], [48.0, 44.0], [48.0, 60.0], [0.0, 44.0]])


def _jacobians(mesh):
    """``det J`` per element at its corners and Gauss points."""
    X, _ = fem.quadrature.get_quadrature(mesh.refdom, 2)
    X = np.concatenate([X, type(mesh).init_refdom().p], axis=1)
    return mesh._mapping().detDF(X)


def distort(mesh, amount=0.3, seed=0):
    """Perturb the interior vertices by up to ``amount·h`` in each
    coordinate (uniform random), ``h`` the shortest edge at the vertex.

    Boundary vertices stay put, so the domain is unchanged (the ±0.3 h
    irregular node sets of the thesis).  Where a perturbation would invert
    an element (possible on skewed meshes), the perturbation of that
    element's vertices is halved until every element is valid.
    """
    rng = np.random.default_rng(seed)
    e = mesh.edges if mesh.dim() == 3 else mesh.facets
    L = np.linalg.norm(mesh.p[:, e[0]] - mesh.p[:, e[1]], axis=0)
    h = np.full(mesh.nvertices, np.inf)
    np.minimum.at(h, e[0], L)
    np.minimum.at(h, e[1], L)
    interior = np.setdiff1d(np.arange(mesh.nvertices), mesh.boundary_nodes())
    delta = np.zeros_like(mesh.p)
    delta[:, interior] = (rng.uniform(-amount, amount,
                                      (mesh.dim(), len(interior)))
                          * h[interior])
    sign = np.sign(_jacobians(mesh).mean(axis=1))
    for _ in range(30):
        out = type(mesh)(mesh.p + delta, mesh.t)
        det = _jacobians(out) * sign[:, None]
        bad = np.min(det, axis=1) <= 1e-3 * np.abs(det).mean()
        if not np.any(bad):
            return out
        delta[:, np.unique(mesh.t[:, bad])] *= 0.5
    return type(mesh)(mesh.p, mesh.t)


def _bilinear_map(xi, eta, corners):
    c = corners
    return ((1 - xi) * (1 - eta) * c[0][:, None]
            + xi * (1 - eta) * c[1][:, None]
            + xi * eta * c[2][:, None] + (1 - xi) * eta * c[3][:, None])


def point_index(points, point, what="vertex", tol=1e-9):
    """The index of the column of ``points`` ``(d, n)`` at ``point``
    (within ``tol`` times ``max(1, |point|)``); ``ValueError`` naming the
    point and the nearest ``what`` if there is none."""
    point = np.asarray(point, dtype=float)
    dist = np.linalg.norm(points - point[:, None], axis=0)
    k = int(np.argmin(dist))
    if dist[k] > tol * max(1.0, np.abs(point).max()):
        raise ValueError("no {} at {}: the nearest, {}, is at {} (distance "
                         "{:.3g})".format(what, tuple(point.tolist()), k,
                                          tuple(points[:, k].tolist()),
                                          dist[k]))
    return k


def vertex_at(mesh, point):
    """The index of the vertex of ``mesh`` at ``point``
    (:func:`point_index`)."""
    return point_index(mesh.p, point)


def cook_membrane(n, kind="quad"):
    """Cook's membrane with ``n`` elements per side.

    ``kind``: ``"quad"`` (MeshQuad), ``"tri"`` (the same nodes, each quad
    split in two triangles).  Boundaries ``left`` (clamped in the benchmark)
    and ``right`` (loaded) are named.
    """
    m = fem.MeshQuad.init_tensor(np.linspace(0, 1, n + 1),
                                 np.linspace(0, 1, n + 1))
    p = _bilinear_map(m.p[0], m.p[1], COOK_CORNERS)
    mesh = fem.MeshQuad(p, m.t)
    if kind == "tri":
        mesh = mesh.to_meshtri()
    elif kind != "quad":
        raise ValueError("kind must be 'quad' or 'tri'")
    return mesh.with_boundaries({
        "left": lambda x: np.isclose(x[0], 0.0),
        "right": lambda x: np.isclose(x[0], 48.0),
    })


def cook_membrane_3d(n, nz, thickness=10.0, distortion=0.0, seed=0):
    """The 3-D Cook's membrane as a hexahedral grid: the 2-D outline of
    :func:`cook_membrane` (``n`` × ``n`` cells) extruded by ``thickness``
    in z (``nz`` cells), interior nodes optionally distorted by
    ``±distortion·h`` (:func:`distort`); boundaries ``left`` and
    ``right`` named."""
    m = fem.MeshHex.init_tensor(np.linspace(0, 1, n + 1),
                                np.linspace(0, 1, n + 1),
                                np.linspace(0, 1, nz + 1))
    p = np.vstack([_bilinear_map(m.p[0], m.p[1], COOK_CORNERS),
                   thickness * m.p[2]])
    mesh = fem.MeshHex(p, m.t)
    if distortion:
        mesh = distort(mesh, distortion, seed)
    return mesh.with_boundaries({
        "left": lambda x: np.isclose(x[0], 0.0),
        "right": lambda x: np.isclose(x[0], 48.0),
    })


def annulus(n, a=1.0, b=2.0):
    """Quarter annulus :math:`a \\le r \\le b` of quadrilaterals, ``n``
    elements radially and ``2n`` around, with the boundaries ``inner``,
    ``xaxis`` and ``yaxis`` (Lamé's and the thick-walled cylinder's
    domain)."""
    m0 = fem.MeshQuad.init_tensor(np.linspace(a, b, n + 1),
                                  np.linspace(0, np.pi / 2, 2 * n + 1))
    mesh = fem.MeshQuad(np.array([m0.p[0] * np.cos(m0.p[1]),
                                  m0.p[0] * np.sin(m0.p[1])]), m0.t)
    return mesh.with_boundaries({
        "inner": lambda x: np.hypot(x[0], x[1]) < a + 0.5 * (b - a) / n,
        "xaxis": lambda x: np.isclose(x[1], 0),
        "yaxis": lambda x: np.isclose(x[0], 0)})


#: the necking bar of thesis 7.3.5 (Simo's bar): length, radius [mm] and
#: the centre's radius relative to the ends'
NECKING_BAR = dict(length=53.334, radius=6.413, reduction=0.99)


def _join(meshes, tol):
    """One mesh of ``meshes`` (same type), nodes closer than ``tol``
    merged.  (scikit-fem's ``+`` rounds to 8 decimals, which splits nodes
    that differ by an ulp across a rounding boundary, e.g. cos and sin of
    pi/4 on a shared edge of mapped blocks.)"""
    from scipy.spatial import cKDTree
    p = np.hstack([m.p for m in meshes])
    offsets = np.cumsum([0] + [m.p.shape[1] for m in meshes])
    t = np.hstack([m.t + o for m, o in zip(meshes, offsets)])
    pairs = cKDTree(p.T).query_pairs(tol, output_type="ndarray")
    rep = np.arange(p.shape[1])
    for _ in range(3):  # a node on up to four blocks: chains of pairs
        lo = np.minimum(rep[pairs[:, 0]], rep[pairs[:, 1]])
        np.minimum.at(rep, pairs[:, 0], lo)
        np.minimum.at(rep, pairs[:, 1], lo)
    keep, inverse = np.unique(rep, return_inverse=True)
    return type(meshes[0])(p[:, keep], inverse[t])


def necking_bar(n=1, length=NECKING_BAR["length"],
                radius=NECKING_BAR["radius"],
                reduction=NECKING_BAR["reduction"], full=False, axial=None):
    r"""The necking bar of thesis 7.3.5 in hexahedra: a square core (side
    the radius) and mapped blocks out to the circle, ``2n`` elements
    radially, elements of about ``R/(4n)`` along the axis (nearly cubic:
    the WTE2 horizon families need it).  The radius varies linearly from
    ``reduction * radius`` at the centre ``x = 0`` to ``radius`` at the
    ends [interpretation: the thesis states only the centre's 0.99 d;
    Simo's bar uses such a linear taper].  Exact circles at the nodes (the
    faceted volume is below the cylinder's by the chords).

    ``full=False``: one eighth, :math:`0 \le x \le L/2`, :math:`y, z \ge
    0` (``192 n^3`` elements), boundaries ``center`` (x = 0), ``end``
    (x = L/2), ``ysym`` (y = 0), ``zsym`` (z = 0).  ``full=True``: the
    whole bar, :math:`|x| \le L/2` (``8 x`` as many), boundaries ``left``
    and ``right``.  ``axial``: the number of elements along the modelled
    length (default ``16n``, ``32n`` with ``full``)."""
    half, c = 0.5 * length, 0.5
    if full:
        xs = np.linspace(-half, half, (axial or 32 * n) + 1)
        core_u, ring_u = np.linspace(-1, 1, 4 * n + 1), \
            np.linspace(0, 1, 4 * n + 1)
    else:
        xs = np.linspace(0.0, half, (axial or 16 * n) + 1)
        core_u = ring_u = np.linspace(0.0, 1.0, 2 * n + 1)
    radial = np.linspace(0.0, 1.0, 2 * n + 1)

    def block(f, a_nodes, b_nodes):
        m = fem.MeshHex.init_tensor(xs, a_nodes, b_nodes)
        x, a, b = m.p
        y, z = f(a, b)
        rho = radius * (reduction + (1 - reduction) * np.abs(x) / half)
        return fem.MeshHex(np.array([x, rho * y, rho * z]), m.t)

    def ring(s, t, lo):  # s radial from the core's side y = c to the arc
        th = 0.25 * np.pi * (t if lo == 0 else 2 * t - 1)
        zc = c * (t if lo == 0 else 2 * t - 1)
        return (1 - s) * c + s * np.cos(th), (1 - s) * zc + s * np.sin(th)

    def rotated(f, k):
        cs, sn = np.cos(0.5 * np.pi * k), np.sin(0.5 * np.pi * k)

        def g(a, b):
            y, z = f(a, b)
            return cs * y - sn * z, sn * y + cs * z
        return g

    core = block(lambda a, b: (c * a, c * b), core_u, core_u)
    if full:
        mesh = _join([core] + [block(rotated(lambda s, t: ring(s, t, -1), k),
                                     radial, ring_u) for k in range(4)],
                     1e-9 * radius)
        return mesh.with_boundaries({
            "left": lambda x: np.isclose(x[0], -half),
            "right": lambda x: np.isclose(x[0], half)})
    # the second eighth-block mirrors the first: swap the parameters and
    # the coordinates (two reflections keep the orientation)
    mesh = _join([core, block(lambda s, t: ring(s, t, 0), radial, ring_u),
                  block(lambda a, b: ring(b, a, 0)[::-1], ring_u, radial)],
                 1e-9 * radius)
    return mesh.with_boundaries({
        "center": lambda x: np.isclose(x[0], 0.0),
        "end": lambda x: np.isclose(x[0], half),
        "ysym": lambda x: np.isclose(x[1], 0.0),
        "zsym": lambda x: np.isclose(x[2], 0.0)})


#: the Taylor anvil's copper rod (thesis 7.3.7, after Kamoulakis 1990;
#: the dimensions are only in the thesis' Fig. 7.27, these are the
#: benchmark's standard values)
TAYLOR_ROD = dict(length=32.4, radius=3.2)


def taylor_rod(n=1, length=TAYLOR_ROD["length"],
               radius=TAYLOR_ROD["radius"], full=True):
    r"""The Taylor anvil's rod in hexahedra, standing on the plane ``x =
    0`` (the wall) and reaching to ``x = L``; the cross section of
    :func:`necking_bar` (``2n`` elements across the radius) and nearly
    cubic elements of about ``R/(4n)`` along the axis.  Boundaries
    ``impact`` (x = 0) and ``top`` (x = L).

    ``full=False``: the quarter :math:`y, z \ge 0`, with the symmetry
    planes ``ysym`` and ``zsym``.  Its particles on the axis sit in a
    right-angled corner of two sliding planes and the impact face; there
    the minimum-norm VC solve makes derivatives ten times the median
    (measured: 82 against 11 at n = 1), and the explicit stable step
    drops ninefold (0.020 against 0.18 µs without VC), so the whole rod
    (``full=True``, default; stable step 0.11 µs with V5m) is the
    cheaper model for explicit runs."""
    axial = max(1, int(round(4 * n * length / radius)))
    if full:
        m = necking_bar(n, length=length, radius=radius, reduction=1.0,
                        full=True, axial=axial)
        mesh = fem.MeshHex(m.p + np.array([[0.5 * length], [0.0], [0.0]]),
                           m.t)
        names = {}
    else:
        m = necking_bar(n, length=2 * length, radius=radius, reduction=1.0,
                        axial=axial)
        mesh = fem.MeshHex(m.p, m.t)
        names = {"ysym": lambda x: np.isclose(x[1], 0.0),
                 "zsym": lambda x: np.isclose(x[2], 0.0)}
    return mesh.with_boundaries({
        "impact": lambda x: np.isclose(x[0], 0.0),
        "top": lambda x: np.isclose(x[0], length), **names})


def transfer_boundaries(old, new):
    """Named boundaries of ``old`` on ``new``, a split of ``old`` with the
    same vertices: a boundary facet of ``new`` belongs to a name when all
    its vertices lie on that name's facets."""
    if not old.boundaries:
        return new
    bfacets = new.boundary_facets()
    named = {}
    for name, facets in old.boundaries.items():
        on = np.zeros(old.nvertices, dtype=bool)
        on[old.facets[:, facets].ravel()] = True
        named[name] = bfacets[np.all(on[new.facets[:, bfacets]], axis=0)]
    return new.with_boundaries(named)


def tetrahedra(mesh):
    """The hexahedral ``mesh`` split into tetrahedra on the same nodes
    (scikit-fem's ``to_meshtet``), its named boundaries carried over: a
    boundary keeps the tetrahedral boundary facets whose vertices all lie
    on its own facets (planar boundaries, as those of
    :func:`necking_bar`, :func:`taylor_rod`, :func:`cook_membrane_3d`)."""
    if not isinstance(mesh, fem.MeshHex):
        raise TypeError("tetrahedra() splits a MeshHex, got {}".format(
            type(mesh).__name__))
    tets = mesh.to_meshtet()
    if not np.array_equal(tets.p, mesh.p):
        raise RuntimeError("to_meshtet moved or added nodes: the split "
                           "cannot carry the boundaries over")
    named = {}
    for name, facets in (mesh.boundaries or {}).items():
        on = np.zeros(mesh.nvertices, dtype=bool)
        on[mesh.facets[:, facets].ravel()] = True
        bf = tets.boundary_facets()
        named[name] = bf[on[tets.facets[:, bf]].all(axis=0)]
    return dataclasses.replace(tets, _boundaries=named or None)


def plate_with_hole(a=1.0, L=5.0, n=8, m=None, ratio=6.0):
    r"""Quarter of a square plate :math:`[-L, L]^2` with a central hole of
    radius ``a``: the part :math:`x, y \ge 0`, structured quadrilaterals
    (two transfinite blocks split along the diagonal, ``n`` cells along
    each half of the hole's arc, ``m`` (default ``2n``) radially, graded
    geometrically so that the outer cells are ``ratio`` times the inner
    ones).  Boundaries ``hole``, ``left`` (x = 0), ``bottom`` (y = 0),
    ``right`` (x = L), ``top`` (y = L)."""
    m = 2 * n if m is None else m
    q = ratio ** (1.0 / max(m - 1, 1))
    eta = np.cumsum(np.r_[0.0, q ** np.arange(m)])
    eta /= eta[-1]
    xi = np.linspace(0.0, 1.0, n + 1)
    XI, ETA = np.meshgrid(xi, eta, indexing="ij")  # (n+1, m+1)
    blocks = []
    for lower in (True, False):
        th = XI * np.pi / 4 if lower else np.pi / 2 - XI * np.pi / 4
        inner = a * np.array([np.cos(th), np.sin(th)])
        outer = (np.array([np.full_like(XI, L), XI * L]) if lower
                 else np.array([XI * L, np.full_like(XI, L)]))
        P = (1 - ETA) * inner + ETA * outer
        idx = np.arange(P[0].size).reshape(P[0].shape)
        t = np.array([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:],
                      idx[:-1, 1:]]).reshape(4, -1)
        if not lower:  # keep the orientation counter-clockwise
            t = t[[0, 3, 2, 1]]
        blocks.append((P.reshape(2, -1), t))
    p = np.hstack([blocks[0][0], blocks[1][0]])
    t = np.hstack([blocks[0][1], blocks[1][1] + blocks[0][0].shape[1]])
    key = np.round(p.T * 1e9).astype(np.int64)
    _, first, inv = np.unique(key, axis=0, return_index=True,
                              return_inverse=True)
    mesh = fem.MeshQuad(p[:, first], inv.ravel()[t])
    tol = 1e-9 * L
    return mesh.with_boundaries({
        "hole": lambda x: np.hypot(x[0], x[1]) < a + tol,  # chords
        "left": lambda x: np.abs(x[0]) < tol,
        "bottom": lambda x: np.abs(x[1]) < tol,
        "right": lambda x: np.abs(x[0] - L) < tol,
        "top": lambda x: np.abs(x[1] - L) < tol,
    })


def renumber(mesh):
    """The same mesh with its vertices in reverse Cuthill–McKee order of
    the vertex graph (elements keep their order, named boundaries and
    subdomains are carried over).

    gmsh numbers vertices with bandwidth of the order of their count; in
    this order the sparse kernels stay in cache (PG assembly about twice
    as fast, benchmarks/README.md, "Measurements behind the defaults").
    Quadratic meshes are returned unchanged."""
    from scipy.sparse.csgraph import reverse_cuthill_mckee
    if mesh.doflocs.shape[1] != mesh.nvertices:
        return mesh  # higher order: vertices and nodes differ
    t = mesh.t
    n = mesh.nvertices
    k = t.shape[0]
    A = sp.csr_matrix((np.ones(k * k * t.shape[1]),
                       (np.repeat(t, k, axis=0).ravel(),
                        np.tile(t, (k, 1)).ravel())), shape=(n, n))
    perm = reverse_cuthill_mckee(A, symmetric_mode=True)
    inv = np.empty(n, dtype=np.int64)
    inv[perm] = np.arange(n)
    new = type(mesh)(np.ascontiguousarray(mesh.p[:, perm]),
                     np.ascontiguousarray(inv[t]))
    if mesh.boundaries:
        # facets by their sorted vertex tuples
        keys = np.sort(new.facets, axis=0)
        order = np.lexsort(keys[::-1])
        skeys = keys[:, order]
        named = {}
        for name, facets in mesh.boundaries.items():
            q = np.sort(inv[mesh.facets[:, facets]], axis=0)
            pos = _lexsearch(skeys, q)
            named[name] = order[pos]
        new = new.with_boundaries(named)
    if mesh.subdomains:
        new = new.with_subdomains(dict(mesh.subdomains))
    return new


def _lexsearch(sorted_cols, q):
    """Indices of the columns ``q`` in the lexicographically sorted columns
    ``sorted_cols`` (all present)."""
    base = sorted_cols.max() + 1
    code = np.zeros(sorted_cols.shape[1], dtype=np.int64)
    qc = np.zeros(q.shape[1], dtype=np.int64)
    for r in range(sorted_cols.shape[0]):
        code = code * base + sorted_cols[r]
        qc = qc * base + q[r]
    pos = np.searchsorted(code, qc)
    if not np.array_equal(code[np.minimum(pos, len(code) - 1)], qc):
        raise RuntimeError("renumber: a named facet was not found")
    return pos


def from_geo(path, size=None, order=1, algorithm=None, recombine=False,
             reorder=True):
    """Mesh a gmsh ``.geo`` file and load it as a scikit-fem mesh.

    ``size`` sets ``Mesh.MeshSizeMax`` (and scales ``MeshSizeMin``);
    ``recombine`` recombines 2-D triangles into quadrilaterals (an
    irregular quad mesh). Physical groups become
    ``mesh.boundaries``/``mesh.subdomains``.  ``reorder``: vertices in a
    bandwidth-reducing order (:func:`renumber`; linear meshes).
    """
    import gmsh
    try:  # no SIGINT handler of gmsh's own (gmsh >= 4.12)
        gmsh.initialize(interruptible=False)
    except TypeError:  # gmsh 4.11
        gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.open(str(path))
        if size is not None:
            gmsh.option.setNumber("Mesh.MeshSizeMax", size)
            gmsh.option.setNumber("Mesh.MeshSizeMin", 0.5 * size)
        if algorithm is not None:
            gmsh.option.setNumber("Mesh.Algorithm", algorithm)
        if recombine:
            gmsh.option.setNumber("Mesh.RecombineAll", 1)
            gmsh.option.setNumber("Mesh.RecombinationAlgorithm", 1)
        dim = gmsh.model.getDimension()
        gmsh.model.mesh.generate(dim)
        gmsh.model.mesh.setOrder(order)
        with tempfile.TemporaryDirectory() as tmp:
            fn = os.path.join(tmp, "mesh.msh")
            gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
            gmsh.write(fn)
            # scikit-fem's loader logs "Transforming over 1000 vertices to
            # C_CONTIGUOUS" for every mesh read (its own transpose, which
            # it copies at once): not a message for the user
            # the format named: meshio tries ANSYS first for .msh and
            # prints that reader's empty error message, a blank line
            # in the output of every script that meshes with gmsh
            m = meshio.read(fn, file_format="gmsh")
            quiet = [logging.getLogger("skfem.mesh.mesh")]
            if not any(c.dim == dim - 1 for c in m.cells):
                # no physical curves (surfaces) in the .geo: scikit-fem
                # warns "Failure to parse tags" looking for their facets,
                # and keeps the subdomains
                quiet.append(logging.getLogger("skfem.io.meshio"))
            levels = [log.level for log in quiet]
            for log in quiet:
                log.setLevel(logging.ERROR)
            try:
                mesh = from_meshio(m)
            finally:
                for log, level in zip(quiet, levels):
                    log.setLevel(level)
    finally:
        gmsh.finalize()
    return renumber(mesh) if reorder and order == 1 else mesh


def _meshes_dir():
    """The directory of the ``.geo`` sources: the installed data package
    ``skfem_pg.meshes`` (wheel, editable install), else the repository's
    top-level ``meshes/`` next to the package (a source checkout on
    ``PYTHONPATH``)."""
    spec = importlib.util.find_spec("skfem_pg.meshes")
    if spec is not None and spec.origin:
        return os.path.dirname(os.path.abspath(spec.origin))
    return os.path.join(os.path.dirname(os.path.abspath(__file__)),
                        os.pardir, os.pardir, "meshes")


def geo_path(name):
    """Path of a ``.geo`` file shipped with the package (the repository's
    ``meshes/``, installed as ``skfem_pg.meshes``: cook.geo, cook3d.geo,
    cube.geo, square.geo, beam3d.geo, plate_hole3d.geo,
    plate_two_holes.geo)."""
    here = os.path.normpath(_meshes_dir())
    fn = os.path.join(here, name)
    if not os.path.isfile(fn):
        raise FileNotFoundError("no mesh source {!r} in {} (available: {})"
                                .format(name, here, ", ".join(sorted(
                                    os.listdir(here)))))
    return fn
