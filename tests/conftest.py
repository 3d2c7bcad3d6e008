import numpy as np
import pytest
import skfem as fem

import skfem_pg as pg


def square(n=10, distortion=0.0, seed=0, kind="quad"):
    """[-1, 1]^2 with n x n elements, optionally distorted by ±distortion·h."""
    m = fem.MeshQuad.init_tensor(*[np.linspace(-1, 1, n + 1)] * 2)
    if distortion:
        m = pg.meshing.distort(m, distortion, seed)
    return m.to_meshtri() if kind == "tri" else m


def cube(n=5, distortion=0.0, seed=0, kind="hex"):
    mesh_cls = fem.MeshHex if kind == "hex" else fem.MeshTet
    m = mesh_cls.init_tensor(*[np.linspace(0, 1, n + 1)] * 3)
    return pg.meshing.distort(m, distortion, seed) if distortion else m


@pytest.fixture
def distorted_quads():
    return square(10, 0.3, seed=1)
