import numpy as np
import pytest
import skfem as fem

import skfem_pg as pg
from skfem_pg import materials as mat
from skfem_pg.analysis.postprocess import particle_fields


def test_homogeneous_stretch_gives_exact_fields(tmp_path):
    mesh = pg.meshing.distort(
        fem.MeshQuad.init_tensor(*[np.linspace(0, 1, 6)] * 2), 0.3, seed=2)
    b = pg.FamilyBasis(pg.Particles.from_mesh(mesh), dim=2)
    Fh = np.array([[1.2, 0.1], [0.0, 0.9]])
    u = ((Fh - np.eye(2)) @ mesh.p).T.ravel()
    m = mat.NeoHooke(100.0, 40.0)
    out = particle_fields(b, m, u)
    F3 = np.eye(3)
    F3[:2, :2] = Fh
    assert np.allclose(out["F"], F3.ravel(), atol=1e-12)  # 3x3 for ParaView
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
    assert back.point_data["F"].shape == (mesh.nvertices, 9)
    # the collocation mesh's cells: ParaView shows a surface
    assert back.cells[0].type == "quad"
    assert np.array_equal(back.cells[0].data, mesh.t.T)


@pytest.mark.parametrize("kind", ["hex", "tet"])
def test_vtu_cells_in_3d_and_subsets(tmp_path, kind):
    import meshio
    g = np.linspace(0, 1, 4)
    mesh = (fem.MeshHex if kind == "hex" else fem.MeshTet).init_tensor(
        g, g, g)
    p = pg.Particles.from_mesh(mesh, elements=lambda x: x[0] < 0.5)
    fn = str(tmp_path / "s.vtu")
    pg.write_vtu(fn, p, T=np.zeros((p.n, 3, 3)))
    back = meshio.read(fn)
    assert back.cells[0].type == ("hexahedron" if kind == "hex"
                                  else "tetra")
    assert len(back.cells[0].data) == len(p.elements)
    assert back.point_data["T"].shape == (p.n, 9)
    # scikit-fem reads the cells back as the PG subdomain's elements
    # (its own vertex order: hexahedra are permuted for VTK)
    from skfem.io.meshio import from_meshio
    assert np.array_equal(from_meshio(back).t, mesh.t[:, p.elements])
    centroids = pg.Particles.from_mesh(mesh, kind="centroids")
    pg.write_vtu(fn, centroids)
    assert meshio.read(fn).cells[0].type == "vertex"


def test_vtu_series_lists_its_steps(tmp_path):
    """A .pvd collection naming every step's VTU with its time, readable
    after each step; the files are the particles with their fields."""
    import re
    import meshio
    from skfem_pg.io import VTUSeries
    mesh = fem.MeshQuad.init_tensor(*[np.linspace(0, 1, 3)] * 2)
    p = pg.Particles.from_mesh(mesh)
    series = VTUSeries(str(tmp_path / "run"))
    for t in (0.25, 0.5, 1.0):
        series.add(t, lambda fn: pg.write_vtu(fn, p, a=np.full(p.n, t)))
        pvd = (tmp_path / "run.pvd").read_text()
        listed = re.findall(r'timestep="([^"]+)" file="([^"]+)"', pvd)
        assert [float(s) for s, _ in listed][-1] == t
    assert [f for _, f in listed] == ["run/step_{:03d}.vtu".format(k)
                                      for k in range(3)]
    last = meshio.read(str(tmp_path / listed[-1][1]))
    assert np.all(last.point_data["a"] == 1.0)
