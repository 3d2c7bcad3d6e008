import numpy as np
import pytest
import skfem as fem

import skfem_pg as pg
from conftest import square, cube


@pytest.mark.parametrize("mesh", [square(6, 0.3), square(6, 0.3, kind="tri"),
                                  cube(3, 0.3), cube(3, 0.3, kind="tet")])
def test_lumped_volumes_and_area_vectors(mesh):
    p = pg.Particles.from_mesh(mesh)
    vol = fem.Functional(lambda w: 1.0 + 0 * w.x[0]).assemble(
        fem.Basis(mesh, pg.particles.linear_elements(mesh)[0]))
    assert p.volumes.sum() == pytest.approx(vol, rel=1e-12)
    A = p.area_vectors()
    # closed surface: sum A = 0, sum X (x) A = V I (divergence theorem)
    assert np.abs(A.sum(axis=1)).max() < 1e-12
    assert np.allclose(p.x @ A.T, vol * np.eye(mesh.dim()), atol=1e-12)
    interior = np.setdiff1d(np.arange(mesh.nvertices), mesh.boundary_nodes())
    assert np.abs(A[:, interior]).max() == 0.0


def test_centroid_particles():
    mesh = square(8, 0.2)
    p = pg.Particles.from_mesh(mesh, kind="centroids")
    assert p.n == mesh.nelements
    assert p.volumes.sum() == pytest.approx(4.0)
    A = p.area_vectors()
    # MLS1 area vectors: divergence identities, zero away from the surface
    assert np.abs(A.sum(axis=1)).max() < 1e-12
    assert np.allclose(p.x @ A.T, 4.0 * np.eye(2), atol=1e-12)
    far = np.max(np.abs(p.x), axis=0) < 0.5 - 1e-9
    assert far.any() and np.all(A[:, far] == 0)


def test_subset_particles_keep_global_numbering():
    mesh = square(4)
    right = mesh.elements_satisfying(lambda x: x[0] > 0)
    p = pg.Particles.from_mesh(mesh, elements=right)
    assert p.n == mesh.nvertices
    assert p.volumes.sum() == pytest.approx(2.0)
    assert not p.active[np.nonzero(mesh.p[0] < -0.1)[0]].any()
    # area vectors of the subdomain include the interface x = 0 (normal -x)
    A = p.area_vectors()
    iface = np.nonzero(np.isclose(mesh.p[0], 0) &
                       (np.abs(mesh.p[1]) < 0.99))[0]
    assert np.all(A[0, iface] < 0)


def test_negative_volume_is_rejected():
    with pytest.raises(pg.ParticleError, match=r"particle 1 at \(1, 0\)"):
        pg.Particles(np.array([[0.0, 1.0], [0.0, 0.0]]), [1.0, -1.0])


def test_zero_volume_is_rejected():
    with pytest.raises(pg.ParticleError, match="volume 0"):
        pg.Particles(np.array([[0.0, 1.0], [0.0, 0.0]]), [1.0, 0.0])


def test_duplicates_are_rejected():
    x = np.array([[0.0, 1.0, 1.0], [0.0, 0.0, 0.0]])
    with pytest.raises(pg.ParticleError, match="particle 1 .* duplicates"):
        pg.Particles(x, [1.0, 1.0, 1.0])


def test_unsupported_meshes_are_rejected():
    with pytest.raises(pg.UnsupportedMeshError, match="MeshTri2"):
        pg.Particles.from_mesh(fem.MeshTri2.init_symmetric())
    with pytest.raises(pg.UnsupportedMeshError, match="MeshLine1"):
        pg.Particles.from_mesh(fem.MeshLine(np.linspace(0, 1, 5)))


@pytest.mark.filterwarnings("ignore::RuntimeWarning")
def test_degenerate_element_is_rejected():
    p = np.array([[0.0, 1.0, 2.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
    t = np.array([[0, 1, 0], [1, 2, 1], [2, 3, 3]])  # first is flat
    with pytest.raises(pg.ParticleError, match="element 0 .* degenerate"):
        pg.Particles.from_mesh(fem.MeshTri(p, t))


def test_gmsh_file(tmp_path, capfd, caplog):
    mesh = pg.meshing.from_geo(pg.meshing.geo_path("square.geo"))
    # meshing prints nothing (meshio's reader guess printed a blank line
    # per mesh, issue 50)
    out, err = capfd.readouterr()
    assert out == "" and "C_CONTIGUOUS" not in err
    # a .geo with a physical surface and no physical curves: scikit-fem
    # warned "Failure to parse tags" looking for the facets' tags
    geo = tmp_path / "tagged.geo"
    geo.write_text("Point(1) = {0, 0, 0, 1}; Point(2) = {1, 0, 0, 1};\n"
                   "Point(3) = {1, 1, 0, 1}; Point(4) = {0, 1, 0, 1};\n"
                   "Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4};\n"
                   "Line(4) = {4, 1}; Curve Loop(1) = {1, 2, 3, 4};\n"
                   "Plane Surface(1) = {1};\n"
                   "Physical Surface(\"plate\") = {1};\n")
    tagged = pg.meshing.from_geo(str(geo), size=0.5)
    out, err = capfd.readouterr()
    assert out == "" and err == ""
    assert [r.getMessage() for r in caplog.records] == []
    assert len(tagged.subdomains["plate"]) == tagged.nelements
    fn = str(tmp_path / "square.msh")
    mesh.save(fn)
    p = pg.Particles.from_file(fn)
    assert p.n == mesh.nvertices
    assert p.volumes.sum() == pytest.approx(4.0)
