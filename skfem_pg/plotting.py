"""3-D plots of PG and FE fields through PyVista (an optional extra).

:func:`to_pyvista` turns a :class:`~skfem_pg.FamilyBasis` (its particles:
with the collocation mesh's cells where they are a mesh's vertices, else
as points) or a scikit-fem basis (its mesh) into a
``pyvista.UnstructuredGrid`` carrying the given fields as point data —
the displacement ``u`` (warped by ``scale``) and any per-particle or
per-vertex array, e.g. particle stresses; :func:`plot` shows one of them.
ParaView users keep :func:`skfem_pg.write_vtu`: the same arrays, in a
file.

``pip install skfem-pg[plot]`` installs PyVista (and VTK, about 180 MB
of wheels); without it these functions raise ``ImportError`` saying so.
Off screen (no display, e.g. CI) pass ``off_screen=True`` and a
``screenshot`` path to :func:`plot`.
"""
from __future__ import annotations

import numpy as np

from .io import point_arrays

__all__ = ["to_pyvista", "plot"]


def _pyvista():
    try:
        import pyvista
    except ImportError as err:
        raise ImportError("skfem_pg.plotting needs PyVista: pip install "
                          "skfem-pg[plot] (or pyvista)") from err
    return pyvista


def _fe_vertex_values(basis, u):
    """``(n_vertices, ncomp)`` of an FE dof vector at the mesh vertices
    (the vertex dofs; a quadratic element's other dofs are left out)."""
    nodal = basis.nodal_dofs  # (ncomp, n_vertices)
    return np.asarray(u)[nodal].T


def to_pyvista(basis, u=None, scale: float = 1.0, **point_data):
    """A ``pyvista.UnstructuredGrid`` of ``basis`` with its fields.

    Parameters
    ----------
    basis : FamilyBasis or skfem.CellBasis
        Particles (with the collocation mesh's cells for vertex
        particles, else as VTK vertices) or an FE basis' mesh.
    u : array_like, optional
        A displacement dof vector of ``basis``: stored as ``"u"`` (3
        components) and the points moved by ``scale * u``.
    scale : float
        The warp factor (``0``: the reference configuration).
    **point_data
        Arrays with one row per particle or mesh vertex (``(n,)``,
        ``(n, k)``, ``(n, d, d)``) or dof vectors of length ``k n``, as
        :func:`skfem_pg.write_vtu` takes them.

    Examples
    --------
    >>> import numpy as np, skfem as fem, skfem_pg as pg
    >>> from skfem_pg.plotting import to_pyvista
    >>> basis = pg.FamilyBasis(fem.MeshHex().refined(1), dim=3)
    >>> u = np.zeros(basis.N); u[2::3] = 0.1        # lift everything
    >>> grid = to_pyvista(basis, u=u)                # doctest: +SKIP
    >>> grid.n_points, float(grid.points[:, 2].min())  # doctest: +SKIP
    (27, 0.1)
    """
    pv = _pyvista()
    import meshio
    particles = getattr(basis, "particles", None)
    if particles is not None:
        from .io import _cells
        n, d = particles.n, particles.dim
        coordinates = particles.x
        cells = _cells(particles)
        values = None if u is None else np.asarray(u).reshape(n, -1)
        fields = {"volume": particles.volumes}
    else:
        from skfem.io.meshio import to_meshio
        mesh = basis.mesh
        n, d = mesh.nvertices, mesh.dim()
        coordinates = mesh.p
        cells = [(b.type, b.data) for b in to_meshio(
            mesh, encode_cell_data=False).cells]
        values = None if u is None else _fe_vertex_values(basis, u)
        fields = {}
    pts = np.zeros((n, 3))
    pts[:, :d] = coordinates.T
    if values is not None:
        if values.shape != (n, d):
            raise ValueError("u has {} values per point; a displacement "
                             "has {}".format(values.shape[1], d))
        fields["u"] = values
        pts[:, :d] += scale * values
    fields.update(point_data)
    grid = pv.from_meshio(meshio.Mesh(pts, cells))
    for name, val in point_arrays(n, fields).items():
        grid.point_data[name] = val
    return grid


def plot(basis, u=None, scalars: str | None = None, scale: float = 1.0,
         plotter=None, screenshot: str | None = None,
         off_screen: bool | None = None, **point_data):
    """Show a field of ``basis`` in 3-D (:func:`to_pyvista`): ``scalars``
    names the point array to colour by (default ``"u"``'s magnitude if
    given), ``plotter`` an existing ``pyvista.Plotter`` to draw into;
    ``screenshot`` writes a PNG (with ``off_screen=True`` no window
    opens).  Returns the plotter."""
    pv = _pyvista()
    grid = to_pyvista(basis, u=u, scale=scale, **point_data)
    if scalars is None and "u" in grid.point_data:
        scalars = "u"
    if scalars is not None and scalars not in grid.point_data:
        raise ValueError("no point array {!r}; the grid has {}".format(
            scalars, sorted(grid.point_data)))
    if plotter is None:
        plotter = pv.Plotter(off_screen=bool(off_screen))
    points = grid.n_cells and all(
        c == pv.CellType.VERTEX for c in np.unique(grid.celltypes))
    plotter.add_mesh(grid, scalars=scalars, show_edges=not points,
                     render_points_as_spheres=bool(points),
                     point_size=8 if points else 5)
    if screenshot is not None:
        plotter.screenshot(screenshot)
    return plotter
