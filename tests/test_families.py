import numpy as np
import pytest
import skfem as fem

import skfem_pg as pg
from conftest import square


def test_mesh_families_master_first_and_sizes():
    mesh = square(4)
    fam = pg.families.from_mesh(mesh)
    assert len(fam) == mesh.nvertices
    assert np.array_equal(fam.masters, np.arange(mesh.nvertices))
    counts = np.bincount(fam.sizes)
    assert counts[9] == 9 and counts[6] == 12 and counts[4] == 4
    mem, mask = fam.padded()
    assert np.all(mem[:, 0] == fam.masters)


def test_corner_families_of_triangles_are_enlarged():
    # a corner vertex touching one triangle has 3 members: too few for MLS1
    mesh = fem.MeshTri.init_tensor(*[np.linspace(0, 1, 4)] * 2)
    touching = np.bincount(mesh.t.ravel(), minlength=mesh.nvertices)
    lonely = np.nonzero(touching == 1)[0]
    assert len(lonely) == 2
    fam = pg.families.from_mesh(mesh)
    assert fam.sizes.min() >= 4
    assert np.all(fam.sizes[lonely] > 3)


def test_horizon_and_nearest():
    p = pg.Particles.from_mesh(square(6))
    fam = pg.families.horizon(p, factor=1.51)
    assert fam.sizes.max() == 9  # 3 x 3 stencil on a regular grid
    fam3 = pg.families.horizon(p, factor=3.01)
    assert fam3.sizes.max() == 29
    near = pg.families.nearest(p, 4)
    A = near.adjacency()
    assert (A != A.T).nnz == 0  # pairwise


def test_too_small_family_is_named():
    x = np.array([[0.0, 1.0, 0.0, 1.0], [0.0, 0.0, 1.0, 1.0]])
    p = pg.Particles(x, np.ones(4))
    fam = pg.Families([0, 4, 8, 10, 14], [0, 1, 2, 3, 1, 0, 2, 3, 2, 3,
                                          3, 0, 1, 2], 4)
    with pytest.raises(pg.FamilyError, match=r"particle 2 at \(0, 1\) has 2 "
                                            r"members.*needs at least 3"):
        pg.FamilyBasis(p, fam, dim=2, vc=None)


def test_collinear_family_is_named():
    x = np.array([[0.0, 1.0, 2.0, 3.0, 0.0, 1.0, 2.0, 3.0],
                  [0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0]])
    p = pg.Particles(x, np.ones(8))
    # family of particle 0 = the collinear bottom row only
    members = [0, 1, 2, 3]
    for i in range(1, 8):
        members += [i, (i + 1) % 8, (i + 4) % 8, (i + 5) % 8]
    fam = pg.Families(np.arange(0, 33, 4), members, 8)
    with pytest.raises(pg.FamilyError, match="particle 0 at .*collinear"):
        pg.FamilyBasis(p, fam, dim=2, bond=False, vc=None)
