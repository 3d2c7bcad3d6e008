"""Parallel VTU output: each rank writes its piece, rank 0 the ``.pvtu``
that ParaView opens as one data set."""
import os
from xml.sax.saxutils import quoteattr

import meshio
import numpy as np

from ..io import point_arrays


def write_pvtu(filename, part, **point_data):
    """Write ``filename`` (``.pvtu``) and one piece per rank
    (``<stem>_<rank>.vtu`` beside it): the collocation mesh's cells whose
    first vertex the rank owns, with their vertices and ``point_data``
    (serial-numbered arrays as :meth:`Partition.gather` returns them,
    converted as by :func:`skfem_pg.write_vtu`; the owner rank of each
    particle is added as ``rank``).  Collective: every rank calls it.
    Returns the piece this rank wrote."""
    from skfem.io.meshio import to_meshio
    if not filename.endswith(".pvtu"):
        raise ValueError("a parallel VTU file name ends in .pvtu, got "
                         "{!r}".format(filename))
    mesh, n = part.mesh, part.n
    data = point_arrays(n, dict(point_data, rank=part.owner.astype(float)))
    block = to_meshio(mesh, encode_cell_data=False).cells[0]
    cells = np.nonzero(part.owner[mesh.t[0]] == part.rank)[0]
    verts = np.unique(mesh.t[:, cells])
    index = np.full(n, -1, dtype=np.int64)
    index[verts] = np.arange(len(verts))
    pts = np.zeros((len(verts), 3))
    pts[:, :part.dim] = mesh.p[:, verts].T
    stem = filename[:-len(".pvtu")]
    piece = "{}_{}.vtu".format(stem, part.rank)
    meshio.write(piece, meshio.Mesh(
        pts, [(block.type, index[block.data[cells]])],
        point_data={k: v[verts] for k, v in data.items()}))
    part.comm.barrier()
    if part.rank == 0:
        arrays = "".join(
            '      <PDataArray type="Float64" Name={} '
            'NumberOfComponents="{}"/>\n'.format(
                quoteattr(k), 1 if v.ndim == 1 else v.shape[1])
            for k, v in data.items())
        pieces = "".join('    <Piece Source={}/>\n'.format(quoteattr(
            os.path.basename("{}_{}.vtu".format(stem, r))))
            for r in range(part.size))
        with open(filename, "w") as fh:
            fh.write(
                '<?xml version="1.0"?>\n'
                '<VTKFile type="PUnstructuredGrid" version="0.1" '
                'byte_order="LittleEndian">\n'
                '  <PUnstructuredGrid GhostLevel="0">\n'
                '    <PPoints>\n      <PDataArray type="Float64" '
                'NumberOfComponents="3"/>\n    </PPoints>\n'
                '    <PPointData>\n' + arrays + '    </PPointData>\n'
                + pieces + '  </PUnstructuredGrid>\n</VTKFile>\n')
    part.comm.barrier()
    return piece
