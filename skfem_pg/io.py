"""VTU output of particle fields for ParaView (via meshio), and time
series of them (``.pvd`` collections)."""
from __future__ import annotations

import os
import tempfile

import numpy as np
import meshio

from .discretization.layout import is_family_basis


def write_vtu(filename: str, particles, **point_data) -> None:
    """Write particles (a :class:`~skfem_pg.Particles` or a
    :class:`~skfem_pg.FamilyBasis`) and their fields for ParaView.

    Particles collocated from a mesh's vertices are written with the
    collocation mesh's cells (those of the PG subdomain for an element
    subset), so ParaView shows a surface or volume; other particle sets
    (centroids, point clouds) as VTK vertices.  ``point_data`` values are
    arrays with one row per particle (``(n,)``, ``(n, k)``, ``(n, d, d)``)
    or scikit-fem dof vectors of length ``k·n`` (interleaved components),
    reshaped to ``(n, k)``.  2-D vectors are padded to 3 components and
    ``(n, d, d)`` tensors written as ``(n, 9)`` (3×3, zero-padded), as
    ParaView expects.
    """
    if is_family_basis(particles):  # a basis: its particles
        particles = particles.particles
    if not hasattr(particles, "kind"):
        raise TypeError("write_vtu takes a skfem_pg.Particles or a "
                        "FamilyBasis, got {}; for a scikit-fem basis use "
                        "its mesh's meshio export (mesh.save)".format(
                            type(particles).__name__))
    n = particles.n
    pts = np.zeros((n, 3))
    pts[:, :particles.dim] = particles.x.T
    data = {"volume": particles.volumes}
    data.update(point_arrays(n, point_data))
    meshio.write(filename, meshio.Mesh(pts, _cells(particles),
                                       point_data=data))


def point_arrays(n, point_data):
    """``point_data`` as ParaView point arrays of ``n`` points (the
    conversions of :func:`write_vtu`)."""
    data = {}
    for name, val in point_data.items():
        val = np.asarray(val, dtype=float)
        if val.ndim == 1 and val.shape[0] != n and val.shape[0] % n == 0:
            val = val.reshape(n, -1)
        if val.shape[0] != n:
            raise ValueError("field {!r} has {} rows, the particle set {} "
                             "particles".format(name, val.shape[0], n))
        if val.ndim == 3:  # (n, d, d) tensors -> 3x3
            t = np.zeros((n, 3, 3))
            t[:, :val.shape[1], :val.shape[2]] = val
            val = t.reshape(n, 9)
        if val.ndim == 2 and val.shape[1] == 2:
            val = np.column_stack([val, np.zeros(n)])
        data[name] = val
    return data


def _cells(particles):
    """The collocation mesh's cells (meshio's vertex order, via
    scikit-fem), or VTK vertices."""
    mesh = particles.mesh
    if particles.kind == "vertices" and mesh is not None:
        from skfem.io.meshio import to_meshio
        block = to_meshio(mesh, encode_cell_data=False).cells[0]
        t = block.data
        if particles.elements is not None:
            t = t[np.asarray(particles.elements)]
        return [(block.type, t)]
    return [("vertex", np.arange(particles.n).reshape(-1, 1))]


def step_writer(basis, **fields):
    """``write(filename)`` of one output of a run, for
    :class:`VTUSeries`: on a family basis the particles with ``fields``
    (:func:`write_vtu`); on a scikit-fem basis its mesh, with dof vectors
    (length ``basis.N``) and per-vertex arrays as point data and
    per-element arrays as cell data."""
    if is_family_basis(basis):
        return lambda fn: write_vtu(fn, basis.particles, **fields)

    def write(fn):
        from skfem.io.meshio import to_meshio
        mesh = basis.mesh
        m = to_meshio(mesh, encode_cell_data=False)
        d = mesh.dim()
        if m.points.shape[1] == 2:  # VTU points are 3-D
            m.points = np.column_stack([m.points,
                                        np.zeros(m.points.shape[0])])
        points, cells = {}, {}
        for name, val in fields.items():
            val = np.asarray(val, dtype=float)
            if val.shape[0] == basis.N:
                val = val.reshape(-1, d)[:mesh.nvertices]
                points[name] = np.column_stack(
                    [val, np.zeros((val.shape[0], 3 - d))]) if d == 2 \
                    else val
            elif val.shape[0] == mesh.nelements:
                cells[name] = [val]
            elif val.shape[0] == mesh.nvertices:
                points[name] = val
            else:
                raise ValueError("field {!r} of length {}: neither dofs "
                                 "({}), vertices nor elements".format(
                                     name, val.shape[0], basis.N))
        m.point_data, m.cell_data = points, cells
        meshio.write(fn, m)
    return write


class VTUSeries:
    """A time series for ParaView: ``folder/step_NNN.vtu`` per step and
    the collection ``folder + ".pvd"`` that lists them with their times,
    rewritten after each step (an interrupted run leaves a readable
    series).  ``add(t, write)`` calls ``write(filename)`` — e.g.
    :func:`write_vtu` of the particles, or meshio for an FE mesh — and
    returns the file's name.

    A run on MPI ranks writes ``suffix="pvtu"`` files
    (:func:`skfem_pg.distributed.write_pvtu`, called by every rank) and
    the collection on one rank only (``collection=rank == 0``)."""

    def __init__(self, folder, suffix="vtu", collection=True):
        if suffix not in ("vtu", "pvtu"):
            raise ValueError("a VTU series holds .vtu or .pvtu files, got "
                             "suffix={!r}".format(suffix))
        name = os.path.basename(os.path.normpath(os.fspath(folder))) \
            if isinstance(folder, (str, os.PathLike)) else None
        if not name or name in (".", "..", os.sep):
            raise ValueError(
                "VTUSeries needs a folder with a name for its steps, got "
                "{!r}: the collection is written beside it as NAME.pvd "
                "(e.g. VTUSeries('out/run') writes out/run/step_000.vtu and "
                "out/run.pvd)".format(folder))
        folder = os.fspath(folder)
        self.folder, self.entries = folder, []
        self.suffix, self.collection = suffix, collection
        os.makedirs(folder, exist_ok=True)

    def add(self, t, write):
        fn = os.path.join(self.folder, "step_{:03d}.{}".format(
            len(self.entries), self.suffix))
        write(fn)
        self.entries.append((float(t), os.path.basename(fn)))
        if not self.collection:
            return fn
        sub = os.path.basename(os.path.normpath(self.folder))
        text = ['<?xml version="1.0"?>\n<VTKFile type="Collection">\n'
                '<Collection>\n']
        text += ['<DataSet timestep="{:.9g}" file="{}/{}"/>\n'.format(
            time, sub, name) for time, name in self.entries]
        text.append('</Collection>\n</VTKFile>\n')
        # atomically: a kill during the write keeps the previous collection
        atomic_write(os.path.normpath(self.folder) + ".pvd",
                     lambda f: f.write("".join(text).encode()))
        return fn


def atomic_write(path, write):
    """Write ``path`` atomically: ``write(f)`` fills a binary temporary
    file in the same folder, which is flushed to disk and then renamed
    over ``path`` (``os.replace``); a kill or an error during the write
    leaves the previous file as it was.  Checkpoints, the overkill cache
    and VTU collections are written this way.  Returns ``path``."""
    path = os.fspath(path)
    d = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(dir=d, prefix=".tmp-",
                               suffix=os.path.splitext(path)[1])
    try:
        with os.fdopen(fd, "wb") as f:
            write(f)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return path
