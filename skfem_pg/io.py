"""VTU output of particle fields for ParaView (via meshio)."""
import numpy as np
import meshio


def write_vtu(filename, particles, **point_data):
    """Write particles as VTK vertices with nodal fields.

    ``point_data`` values are arrays with one row per particle (``(n,)``,
    ``(n, k)``) or scikit-fem dof vectors of length ``k·n`` (interleaved
    components), which are reshaped to ``(n, k)``.  2-D vectors are padded
    to 3 components as ParaView expects.
    """
    n = particles.n
    pts = np.zeros((n, 3))
    pts[:, :particles.dim] = particles.x.T
    data = {"volume": particles.volumes}
    for name, val in point_data.items():
        val = np.asarray(val, dtype=float)
        if val.ndim == 1 and val.shape[0] != n and val.shape[0] % n == 0:
            val = val.reshape(n, -1)
        if val.ndim == 2 and val.shape[1] == 2:
            val = np.column_stack([val, np.zeros(n)])
        data[name] = val
    cells = [("vertex", np.arange(n).reshape(-1, 1))]
    meshio.write(filename, meshio.Mesh(pts, cells, point_data=data))
