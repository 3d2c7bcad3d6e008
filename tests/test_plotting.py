"""3-D plots through PyVista (the ``plot`` extra): PG particles with the
collocation mesh's cells or as points, FE meshes, fields as point data,
the warp, an off-screen screenshot."""
import numpy as np
import pytest
import skfem as fem

import skfem_pg as pg
from skfem_pg.plotting import plot, to_pyvista

pv = pytest.importorskip("pyvista")


def test_particles_and_fe_meshes_as_grids():
    mesh = fem.MeshHex().refined(1)
    basis = pg.FamilyBasis(mesh, dim=3)
    u = np.zeros(basis.N)
    u[2::3] = 0.1 * basis.particles.x[0]  # a shear: lift grows with x
    sigma = np.ones((basis.particles.n, 3, 3))
    grid = to_pyvista(basis, u=u, scale=2.0, sigma=sigma)
    assert grid.n_points == basis.particles.n == 27
    assert grid.n_cells == mesh.nelements
    assert np.allclose(grid.points[:, 2],
                       basis.particles.x[2] + 0.2 * basis.particles.x[0])
    assert grid.point_data["u"].shape == (27, 3)
    assert grid.point_data["sigma"].shape == (27, 9)
    fe = fem.Basis(mesh, fem.ElementVector(fem.ElementHex2()))
    v = fe.zeros()
    v[fe.nodal_dofs[0]] = 0.5
    g = to_pyvista(fe, u=v)
    assert g.n_points == mesh.nvertices and g.n_cells == mesh.nelements
    assert np.allclose(g.points[:, 0], mesh.p[0] + 0.5)
    # particles that are not a mesh's vertices: points
    centroids = pg.Particles.from_mesh(fem.MeshQuad().refined(2),
                                       kind="centroids")
    cloud = to_pyvista(pg.FamilyBasis(centroids, dim=2, vc=None))
    assert cloud.n_cells == cloud.n_points == centroids.n
    assert set(np.unique(cloud.celltypes)) == {pv.CellType.VERTEX}
    with pytest.raises(ValueError, match="displacement has 3"):
        to_pyvista(basis, u=np.zeros(2 * basis.particles.n))


def test_off_screen_plot_writes_a_screenshot(tmp_path):
    basis = pg.FamilyBasis(fem.MeshTet().refined(1), dim=3)
    u = np.zeros(basis.N)
    u[0::3] = 0.1
    path = tmp_path / "u.png"
    plotter = plot(basis, u=u, off_screen=True, screenshot=str(path))
    assert path.stat().st_size > 1000
    plotter.close()
    with pytest.raises(ValueError, match="no point array 'p'"):
        plot(basis, u=u, scalars="p", off_screen=True)
