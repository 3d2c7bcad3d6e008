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


def _mirrored(x, axis, centre):
    y = x.copy()
    y[axis] = 2 * centre - y[axis]
    return y


@pytest.mark.parametrize("dim, k", [(2, 6), (2, 1), (3, 10), (3, 18)])
def test_nearest_with_ties_keeps_a_grids_symmetry(dim, k):
    """Equidistant neighbours join together (issue 45): on a regular grid
    the family of a particle's mirror image is the mirror image of its
    family; without ties the KD-tree's order breaks the symmetry."""
    from scipy.spatial import cKDTree
    mesh = (fem.MeshQuad.init_tensor(*(2 * [np.linspace(0, 1, 7)]))
            if dim == 2 else
            fem.MeshHex.init_tensor(*(3 * [np.linspace(0, 1, 5)])))
    p = pg.Particles.from_mesh(mesh)
    tree = cKDTree(p.x.T)

    def symmetric(fam):
        A = fam.adjacency()
        for axis in range(dim):
            _, image = tree.query(_mirrored(p.x, axis, 0.5).T)
            if (A[image][:, image] != A).nnz:
                return False
        return True

    assert symmetric(pg.families.nearest(p, k))
    if k in (6, 10):  # the tie breaks inside a ring of equal distance
        assert not symmetric(pg.families.nearest(p, k, ties=False))
    plain = pg.families.nearest(p, k, ties=False, pairwise=False)
    assert np.all(plain.sizes >= k + 1)


def test_nearest_tie_rule_families_pass_the_patch_test():
    """The 4 equidistant neighbours of k = 1 on a distorted-free grid: a
    cross stencil, enough for VC PBG Unl (without ties the same k fails,
    tests/test_robustness.py)."""
    from skfem_pg.analysis.verification import linear_patch_test
    mesh = fem.MeshQuad.init_tensor(*(2 * [np.linspace(-1, 1, 9)]))
    p = pg.Particles.from_mesh(mesh)
    fam = pg.families.nearest(p, 1)
    assert fam.sizes.min() >= 4 and np.median(fam.sizes) == 5
    r = linear_patch_test(mesh, lambda x: x[1] == 1.0, particles=p,
                          families=fam)
    assert r["max_error"] < 1e-10


@pytest.mark.parametrize("tol", [-1.0, np.nan, "x"])
def test_nearest_tie_tolerance_is_checked(tol):
    p = pg.Particles.from_mesh(square(3))
    with pytest.raises(pg.FamilyError, match="tie tolerance"):
        pg.families.nearest(p, 3, tie_tolerance=tol)
