import numpy as np
import pytest
import skfem as fem

import skfem_pg as pg
from skfem_pg import materials as mat
from skfem_pg.postprocess import particle_fields


def test_homogeneous_stretch_gives_exact_fields(tmp_path):
    mesh = pg.meshing.distort(
        fem.MeshQuad.init_tensor(*[np.linspace(0, 1, 6)] * 2), 0.3, seed=2)
    b = pg.FamilyBasis(pg.Particles.from_mesh(mesh), dim=2)
    Fh = np.array([[1.2, 0.1], [0.0, 0.9]])
    u = ((Fh - np.eye(2)) @ mesh.p).T.ravel()
    m = mat.NeoHooke(100.0, 40.0)
    out = particle_fields(b, m, u)
    assert np.allclose(out["F"], Fh.ravel(), atol=1e-12)
    F3 = np.eye(3)
    F3[:2, :2] = Fh
    P = m.stress(F3[:, :, None])[:, :, 0]
    sigma = P @ F3.T / np.linalg.det(F3)
    assert np.allclose(out["cauchy"], sigma.ravel(), atol=1e-10)
    s = sigma - np.trace(sigma) / 3 * np.eye(3)
    assert out["von_mises"] == pytest.approx(np.sqrt(1.5 * (s * s).sum()))
    fn = str(tmp_path / "p.vtu")
    pg.write_vtu(fn, b.particles, **out)
    import meshio
    back = meshio.read(fn)
    assert np.allclose(back.point_data["von_mises"], out["von_mises"])
