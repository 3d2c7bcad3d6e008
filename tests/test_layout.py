"""The unpadded size-group layout (skfem_pg.discretization.layout) gives
what the padded arrays give: interpolation, material evaluation, internal
forces and tangents to round-off (≤ 1e-12 relative), on family sets of
many sizes."""
import numpy as np
import pytest

import skfem_pg as pg
from skfem_pg import materials as mat
from skfem_pg.discretization.assembly import assemble
from skfem_pg.formulations import (Hyperelastic, internal_force,
                                   material_tangent)
from skfem_pg.formulations.tangents import fd_tangent
from conftest import cube, square


def rel(a, b):
    a = a.toarray() if hasattr(a, "toarray") else np.asarray(a)
    b = b.toarray() if hasattr(b, "toarray") else np.asarray(b)
    return np.abs(a - b).max() / np.abs(b).max()


def bases():
    """Family sets with several sizes: tetrahedra (mesh families) and a
    horizon on distorted quads, PBG and PPG1."""
    tets = pg.Particles.from_mesh(cube(3, 0.3, kind="tet"))
    quads = pg.Particles.from_mesh(square(6, 0.3))
    return [pg.FamilyBasis(tets, dim=3),
            pg.FamilyBasis(quads, pg.families.horizon(quads, factor=2.2),
                           dim=2),
            pg.FamilyBasis(quads, dim=2, method="PPG1")]


@pytest.fixture(scope="module", params=range(3), ids=["tet", "horizon",
                                                       "ppg"])
def basis(request):
    return bases()[request.param]


def test_groups_partition_the_families(basis):
    L = basis.layout
    assert len(L) > 1  # several sizes: the test means something
    fams = np.concatenate([g.families for g in L])
    assert np.array_equal(np.sort(fams), np.arange(len(basis.families)))
    for g in L:
        assert np.all(basis.families.sizes[g.families] == g.m)
        assert np.array_equal(g.members[:, 0], basis.families.masters[
            g.families])
    # padded <-> flat round trip; the padding is filled
    a = np.random.default_rng(0).normal(size=(2, L.n_families, L.m_max))
    mem, mask = basis.families.padded()
    back = L.flat_to_padded(L.padded_to_flat(a), fill=np.nan)
    assert np.array_equal(back[:, mask], a[:, mask])
    assert np.all(np.isnan(back[:, ~mask]))


def test_flat_interpolation_equals_padded(basis):
    u = np.random.default_rng(1).normal(size=basis.N)
    pad = basis.interpolate(u)
    flat = basis.interpolate(u, flat=True)
    L = basis.layout
    assert flat.grad.shape[-2:] == (1, L.n_points)
    mem, mask = basis.families.padded()
    assert np.array_equal(L.flat_to_padded(flat.grad[..., 0, :])[..., mask],
                          pad.grad[..., mask])
    # the old padded formula, directly on basis.G
    U = u.reshape(-1, basis.ncomp)[mem]
    ref = (np.swapaxes(basis.G, -1, -2) @ U[:, None]).transpose(3, 2, 0, 1)
    assert rel(pad.grad, ref) < 1e-14
    assert np.all(pad.grad[..., ~mask] == 0)


def test_flat_coefficients_assemble_like_padded(basis):
    """Forms fed flat fields (the models' hot path) and padded fields (what
    scikit-fem's generic assembly sees) give the same vectors and
    matrices."""
    d = basis.particles.dim
    material = mat.NeoHookeIsoVol(mu=1.0, K=10.0)
    u = 0.02 * np.random.default_rng(2).normal(size=basis.N)
    eye = np.eye(d).reshape(d, d, 1, 1)
    Fp = basis.interpolate(u).grad + eye
    Ff = basis.interpolate(u, flat=True).grad + eye
    mem, mask = basis.families.padded()
    Fp[..., ~mask] = eye[..., 0]  # padded slots: any valid F
    fp = assemble(internal_force, basis, P=material.stress(Fp))
    ff = assemble(internal_force, basis, P=material.stress(Ff))
    assert rel(ff, fp) < 1e-12
    Kp = assemble(material_tangent, basis, A=material.tangent(Fp))
    Kf = assemble(material_tangent, basis, A=material.tangent(Ff))
    assert rel(Kf, Kp) < 1e-12
    if not basis.is_petrov:  # scikit-fem's own generic path, padded
        with pytest.warns(pg.errors.SlowAssemblyWarning):
            Kg = material_tangent.assemble(basis, A=material.tangent(Fp))
        assert rel(Kf, Kg) < 1e-12
    model = Hyperelastic(basis, material)
    s = model.state(u)
    assert s["F"].shape[-2:] == (1, basis.layout.n_points)
    assert rel(model.tangent(s), Kp) < 1e-12
    assert rel(model.internal_force(s), fp) < 1e-12


def test_fd_tangent_on_flat_and_padded_state():
    basis = bases()[0]
    material = mat.NeoHookeIsoVol(mu=1.0, K=10.0)
    u = 0.02 * np.random.default_rng(3).normal(size=basis.N)
    eye = np.eye(3).reshape(3, 3, 1, 1)
    Kf = fd_tangent(basis, material, basis.interpolate(u, flat=True).grad
                    + eye)
    Kp = fd_tangent(basis, material, basis.interpolate(u).grad + eye)
    K = assemble(material_tangent, basis, A=material.tangent(
        basis.interpolate(u, flat=True).grad + eye))
    assert rel(Kf, Kp) < 1e-12
    assert rel(Kf, K) < 1e-6  # central differences


@pytest.mark.parametrize("boundary", ["min-norm", "p"])
@pytest.mark.parametrize("families", [None, "mesh"])  # kNN, thesis
def test_unpadded_pipeline_equals_padded(boundary, families):
    """The default PBG pipeline (MTE1, bond, V5) runs per size group; the
    same kernels on the padded arrays give the same derivatives."""
    from skfem_pg.discretization.corrections import bond_correction
    from skfem_pg.discretization.vc import (VCSystem, correction_functions,
                                            vc_correction)
    from skfem_pg.discretization.quadrature import weight_rule
    from skfem_pg.discretization.shape import GRADIENTS
    p = pg.Particles.from_mesh(cube(3, 0.3, kind="tet"))
    b = pg.FamilyBasis(p, dim=3, vc_boundary=boundary, families=families)
    assert b._G is None and len(b.layout) > 1  # built without padding
    fam, x, V, n = b.families, p.x, p.volumes, b.weight_exponent
    G = bond_correction(GRADIENTS["MTE1"](x, V, fam, n=n), x, fam)
    dx = weight_rule(b.weights)(V, fam)
    Gc, rep = vc_correction(
        VCSystem(G, dx, x, V, fam, p.area_vectors(),
                 correction_functions("V5", x, V, fam, n=n),
                 p.surface_area_vectors()), boundary=boundary)
    assert rel(b.dx, dx) < 1e-15
    assert rel(b.G, Gc) < 1e-12
    assert abs(rep.residual_after - b.vc_report.residual_after) < 1e-12


def test_renumber_keeps_boundaries_and_reduces_bandwidth():
    m0 = pg.meshing.from_geo(pg.meshing.geo_path("cook.geo"), size=4,
                             reorder=False)
    m1 = pg.meshing.renumber(m0)
    assert set(m1.boundaries) == set(m0.boundaries)
    for name, facets in m0.boundaries.items():
        a = np.sort(m0.p[:, m0.facets[:, facets]].reshape(2, -1), axis=1)
        b = np.sort(m1.p[:, m1.facets[:, m1.boundaries[name]]]
                    .reshape(2, -1), axis=1)
        assert np.array_equal(a, b)
    bw = [np.abs(m.t[:, None] - m.t[None]).max() for m in (m0, m1)]
    assert bw[1] < bw[0] / 3
    # the same elements, vertices permuted
    assert np.allclose(np.sort(m0.p[:, m0.t].mean(axis=1), axis=1),
                       np.sort(m1.p[:, m1.t].mean(axis=1), axis=1))
