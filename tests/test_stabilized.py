"""U1SUnl and U1SIG (thesis 6.3): the MLS1 second derivatives, the frozen
elastic energy, the moduli (6.20) and moment (6.27), the free-block
eigenmodes (U1's soft modes gone), the patch test, equivalence of elastic
U1SUnl with Unl, and tangents against differences of the forces with a
plastic history.  The homogeneous plastic checks are in
``tests/test_plasticity.py``."""
import numpy as np
import pytest
import skfem as fem

import skfem_pg as pg
from skfem_pg.analysis.spectrum import classify, free_modes
from skfem_pg.discretization.shape.least_squares import (
    _basis, mls1_hessian_at, mls1_master_hessians, weights)
from skfem_pg.formulations import Hyperelastic, U1SIG, U1SUnl
from skfem_pg.formulations.stabilized import (second_moment,
                                              stabilized_moduli,
                                              under_integrated)
from skfem_pg.materials import J2Plasticity, NeoHookeIsoVol, lame
from skfem_pg.materials.frozen import FrozenPlasticity
from conftest import cube, square

STEEL = J2Plasticity.from_young(206.9, 0.29, 0.45, H=0.13, sigma_yinf=1.165,
                                delta=16.93)


def mls1_values_at(D, V, fixed):
    W = np.where(fixed > 0, fixed, weights((D ** 2).sum(-1), 1) * V)
    p = _basis(D, 1)
    M = np.einsum("fl,flq,flr->fqr", W, p, p)
    a = np.linalg.solve(M, np.broadcast_to(np.eye(p.shape[-1])[0],
                                           M.shape[:2])[..., None])[..., 0]
    return W * np.einsum("flq,fq->fl", p, a)


@pytest.mark.parametrize("d", [2, 3])
def test_mls1_hessian_is_second_derivative_of_values(d):
    rng = np.random.default_rng(d)
    nf, m = 4, 12
    X = rng.uniform(-1, 1, (nf, m, d))
    X[:, 0] = 0.0
    V = rng.uniform(0.5, 1.5, (nf, m))
    fixed = np.zeros((nf, m))
    fixed[:, 0] = 1e-6 * V[:, 0]
    H, singular = mls1_hessian_at(X, V, 1, fixed)
    assert not singular.any()
    e = 1e-4  # truncation ~ e^2: 5e-5 at e = 1e-3, 3e-7 here
    Hf = np.zeros_like(H)
    for a in range(d):
        for b in range(d):
            ea, eb = np.eye(d)[a] * e, np.eye(d)[b] * e
            f = [mls1_values_at(X - s, V, fixed) for s in
                 (ea + eb, ea - eb, -ea + eb, -ea - eb)]
            Hf[..., a, b] = (f[0] - f[1] - f[2] + f[3]) / (4 * e * e)
    assert np.abs(H - Hf).max() < 2e-6 * np.abs(H).max()
    assert np.abs(H - np.swapaxes(H, -1, -2)).max() < 1e-12


@pytest.mark.parametrize("mesh", [square(4, 0.3, seed=2), cube(2, 0.2)])
def test_mls1_master_hessians_annihilate_linear_fields(mesh):
    p = pg.Particles.from_mesh(mesh)
    fam = pg.families.from_mesh(p)
    H = mls1_master_hessians(p.x, p.volumes, fam)
    mem, mask = fam.padded()
    X = p.x.T[mem] * mask[..., None]
    scale = np.abs(H).max()
    assert np.abs(H.sum(axis=1)).max() < 1e-11 * scale
    assert np.abs(np.einsum("kia,kibc->kabc", X, H)).max() < 1e-11 * scale
    # a quadratic field has a nonzero second derivative
    q = X[..., 0] ** 2
    assert np.abs(np.einsum("ki,kibc->kbc", q, H)).max() > 0.5


@pytest.mark.parametrize("d", [2, 3])
def test_frozen_plasticity_is_the_elastic_law_at_a_plastic_state(d):
    rng = np.random.default_rng(d)
    n = 5
    F0 = np.eye(d)[:, :, None] + 0.05 * rng.uniform(-1, 1, (d, d, n))
    h = STEEL.update(F0, STEEL.initial_history((n,))).history
    assert h["alpha"].min() > 0
    F = F0 + 1e-4 * rng.uniform(-1, 1, (d, d, n))
    frozen = FrozenPlasticity(STEEL.mu, STEEL.K, h["Cp_inv"])
    elastic = J2Plasticity(mu=STEEL.mu, K=STEEL.K, sigma_y0=1e9).update(F, h)
    assert np.abs(frozen.stress(F) - elastic.P).max() < 1e-12
    assert np.abs(frozen.tangent(F) - elastic.tangent()).max() < 1e-9
    assert np.abs(frozen.energy(F) - elastic.energy()).max() < 1e-12
    eps = 1e-6
    for k in range(d):
        for L in range(d):
            dF = np.zeros_like(F)
            dF[k, L] = eps
            dP = (frozen.stress(F + dF) - frozen.stress(F - dF)) / (2 * eps)
            assert np.abs(dP - frozen.tangent(F)[:, :, k, L]).max() \
                < 1e-6 * np.abs(frozen.tangent(F)).max()
            dW = (frozen.energy(F + dF) - frozen.energy(F - dF)) / (2 * eps)
            assert np.abs(dW - frozen.stress(F)[k, L]).max() < 1e-6
    # the Cauchy von Mises stress of the plastic state is the yield stress
    vm = FrozenPlasticity(STEEL.mu, STEEL.K, h["Cp_inv"]).von_mises(F0)
    J = np.linalg.det(np.moveaxis(F0, -1, 0))
    assert np.allclose(vm * J, STEEL.yield_stress(h["alpha"]), rtol=1e-8)


def test_stabilized_moduli_and_particle_moment():
    mu, K = 1.0, 100.0  # nu = 0.495
    E = 9 * K * mu / (3 * K + mu)
    mt, Kt = stabilized_moduli(mu, K, np.array([1.0, 1.0, 1.0]),
                               np.array([0.0, 1e-6, 10.0]))
    Et = 9 * Kt * mt / (3 * Kt + mt)
    nut = (3 * Kt - 2 * mt) / (2 * (3 * Kt + mt))
    assert np.allclose(nut, 0.49)
    assert np.allclose(Et, [E, E, max(1e-3 * E, 0.1)])
    # 3-D: the sphere of (6.27); 2-D: a disk of the same area
    assert np.isclose(second_moment(1.0, 3), 0.0769669, rtol=1e-6)
    R = 0.7
    A = np.pi * R ** 2
    assert np.isclose(second_moment(A, 2), np.pi * R ** 4 / 4, rtol=1e-14)
    with pytest.raises(ValueError, match="dim"):
        second_moment(1.0, 1)


def test_free_block_eigenmodes():
    """The free 20 x 10 block of demos/eigenmodes.py, nu = 0.4: U1 at the
    masters has soft modes; both stabilizations leave exactly the three
    rigid modes and no soft one."""
    mesh = fem.MeshQuad.init_tensor(np.linspace(0, 2, 21),
                                    np.linspace(0, 1, 11))
    p = pg.Particles.from_mesh(mesh)
    lam, mu = lame(1.0, 0.4)
    m = NeoHookeIsoVol.from_lame(lam, mu)
    M = np.repeat(p.volumes, 2)
    q1 = fem.Basis(mesh, fem.ElementVector(fem.ElementQuad1()), intorder=2)
    ref = free_modes(Hyperelastic(q1, m).tangent(
        Hyperelastic(q1, m).state(np.zeros(q1.N))), M)["eigenvalues"][3]
    unl = pg.FamilyBasis.from_name(p, "VCPBG V5m Unl", dim=2)
    counts = {}
    for name, model in [("U1", Hyperelastic(under_integrated(unl), m)),
                        ("U1SUnl", U1SUnl(unl, m)),
                        ("U1SIG", U1SIG(unl, m))]:
        K = model.tangent(model.state(model.initial()))
        s = free_modes(K, M)
        counts[name] = classify(s["eigenvalues"], s["scale"], 3, ref)
    assert counts["U1"]["soft"] >= 20
    for name in ("U1SUnl", "U1SIG"):
        assert counts[name]["zero"] == 3 and counts[name]["soft"] == 0
        assert counts[name]["first_deformation"] > 0.5 * ref


@pytest.mark.parametrize("formulation", ["U1SUnl", "U1SIG"])
def test_patch_test(formulation):
    mesh = square(5, 0.3, seed=3)
    p = pg.Particles.from_mesh(mesh)
    b = pg.FamilyBasis.from_name(p, "VCPBG V5m Unl", dim=2)
    model = {"U1SUnl": U1SUnl, "U1SIG": U1SIG}[formulation](
        b, NeoHookeIsoVol(mu=1.0, K=5.0))
    B = np.array([[0.02, 0.01], [-0.03, 0.015]])
    u = (B @ p.x).T.ravel()
    f = model.internal_force(model.state(u)).reshape(-1, 2)
    inner = np.setdiff1d(np.arange(p.n), mesh.boundary_nodes())
    assert np.abs(f[inner]).max() < 1e-12
    # the boundary forces are the exact tractions: P . A^i
    F = np.eye(2) + B
    P = NeoHookeIsoVol(mu=1.0, K=5.0).stress(F[:, :, None])[:, :, 0]
    A = p.area_vectors()
    assert np.abs(f - (P @ A).T).max() < 1e-12


def test_elastic_u1sunl_is_unl():
    """nu <= 0.49 and no plasticity: the stabilization is the whole Unl
    energy, the WTE1 parts cancel."""
    mesh = square(4, 0.3, seed=5)
    b = pg.FamilyBasis.from_name(pg.Particles.from_mesh(mesh),
                                 "VCPBG V5m Unl", dim=2)
    m = NeoHookeIsoVol(mu=1.0, K=3.0)
    u = 0.05 * np.random.default_rng(0).uniform(-1, 1, b.N)
    s, unl = U1SUnl(b, m), Hyperelastic(b, m)
    f1, f2 = s.internal_force(s.state(u)), unl.internal_force(unl.state(u))
    assert np.abs(f1 - f2).max() < 1e-13 * np.abs(f2).max()
    K1, K2 = s.tangent(s.state(u)), unl.tangent(unl.state(u))
    assert abs(K1 - K2).max() < 1e-12 * abs(K2).max()
    assert abs(s.energy(s.state(u)) - unl.energy(unl.state(u))) < 1e-13


@pytest.mark.parametrize("formulation", ["U1SUnl", "U1SIG"])
@pytest.mark.parametrize("plastic", [False, True])
def test_tangent_is_derivative_of_force(formulation, plastic):
    """Central differences of the forces (and, elastic, of the energy)
    after a committed step; plastic: the master history and the reduced
    moduli (6.20) of that step."""
    mesh = square(4, 0.2, seed=6)
    b = pg.FamilyBasis.from_name(pg.Particles.from_mesh(mesh),
                                 "VCPBG V5m Unl", dim=2)
    material = STEEL if plastic else NeoHookeIsoVol(mu=80.0, K=160.0)
    model = {"U1SUnl": U1SUnl, "U1SIG": U1SIG}[formulation](b, material)
    rng = np.random.default_rng(1)
    u0 = 0.02 * rng.uniform(-1, 1, b.N)
    model.commit(model.state(u0))  # a committed (plastic) master state
    if plastic:
        a = model.history.alpha()
        assert a.shape == (len(b.families.masters),) and a.max() > 0
        assert model.frozen()[0].min() < STEEL.mu  # (6.20) reduced some
    u = u0 + 0.01 * rng.uniform(-1, 1, b.N)
    K = model.tangent(model.state(u)).toarray()
    du = rng.uniform(-1, 1, b.N)
    eps = 1e-7
    df = (model.internal_force(model.state(u + eps * du))
          - model.internal_force(model.state(u - eps * du))) / (2 * eps)
    assert np.abs(K @ du - df).max() < 1e-6 * np.abs(df).max()
    if plastic:  # the stored energy is no potential of a plastic step
        return
    dE = (model.energy(model.state(u + eps * du))
          - model.energy(model.state(u - eps * du))) / (2 * eps)
    f = model.internal_force(model.state(u))
    assert abs(dE - f @ du) < 1e-6 * abs(f @ du)


def test_names_and_refusals():
    p = pg.Particles.from_mesh(square(3))
    sig = pg.FamilyBasis.from_name(p, "VCPBG U1SIG", dim=2)
    assert sig.shape == "WTE1" and not sig.bond and sig.vc == "V3"
    assert under_integrated(sig) is sig
    unl = pg.FamilyBasis.from_name(p, "VCPBG U1SUnl", dim=2)
    assert unl.shape == "MTE1" and unl.bond and unl.vc == "V5"
    with pytest.raises(ValueError, match="bond"):
        pg.FamilyBasis.from_name(p, "VCBCPBG U1SIG", dim=2)
    with pytest.raises(ValueError, match="MTE1"):
        U1SUnl(sig, NeoHookeIsoVol(mu=1.0, K=3.0))
    with pytest.raises(ValueError, match="finite bulk"):
        U1SIG(sig, NeoHookeIsoVol.incompressible(1.0))
    ppg = pg.FamilyBasis.from_name(p, "VCPPG Unl", dim=2)
    with pytest.raises(ValueError, match="PBG"):
        U1SIG(ppg, NeoHookeIsoVol(mu=1.0, K=3.0))


def test_necking_bar_mesh():
    """The eighth and the whole bar: positive volumes, eight eighths make
    the whole, the centre radius 0.99 R, and the faceted volume just below
    the tapered cylinder's."""
    eighth = pg.meshing.necking_bar(1)
    whole = pg.meshing.necking_bar(1, full=True)
    vol = [fem.Basis(m, fem.ElementHex1()).dx.sum(axis=1)
           for m in (eighth, whole)]
    assert vol[0].min() > 0 and vol[1].min() > 0
    assert np.isclose(8 * vol[0].sum(), vol[1].sum(), rtol=1e-9)
    L, R = 53.334, 6.413
    exact = np.pi * R ** 2 * L * (0.99 ** 2 + 0.99 + 1) / 3  # mean rho^2
    assert 0.95 < vol[1].sum() / exact < 1.0
    p = eighth.p
    r = np.hypot(p[1], p[2])
    assert np.isclose(r[np.isclose(p[0], 0)].max(), 0.99 * R)
    assert np.isclose(r[np.isclose(p[0], L / 2)].max(), R)
    assert set(eighth.boundaries) == {"center", "end", "ysym", "zsym"}
    assert set(whole.boundaries) == {"left", "right"}


def test_tetrahedra_split_keeps_nodes_and_boundaries():
    """``meshing.tetrahedra``: the same nodes, the same volume, and every
    named boundary covered by twice as many triangles on the same
    vertices; anything but hexahedra is refused."""
    hexes = pg.meshing.necking_bar(1)
    tets = pg.meshing.tetrahedra(hexes)
    assert isinstance(tets, fem.MeshTet) and np.array_equal(tets.p, hexes.p)
    vol = [fem.Basis(m, e).dx.sum() for m, e in (
        (hexes, fem.ElementHex1()), (tets, fem.ElementTetP1()))]
    assert np.isclose(vol[0], vol[1], rtol=1e-12)
    assert set(tets.boundaries) == set(hexes.boundaries)
    for name, facets in hexes.boundaries.items():
        assert len(tets.boundaries[name]) == 2 * len(facets)
        assert np.array_equal(np.unique(tets.facets[:, tets.boundaries[name]]),
                              np.unique(hexes.facets[:, facets]))
    with pytest.raises(TypeError, match="MeshHex"):
        pg.meshing.tetrahedra(tets)


def test_ppg_unlp0_refused_where_unstable():
    """PPG UnlP0 in 3-D with the min-norm (or p) VC: its tangent at rest
    has eigenvalues with negative real part (here measured again), so
    the model refuses it; with 'sn' it is stable."""
    from skfem_pg.formulations.master_dilatation import MasterDilatation
    from skfem_pg.scenes import Scene
    mesh = cube(4).with_boundaries({"a": lambda x: x[0] < 1e-9,
                                    "b": lambda x: x[0] > 1 - 1e-9})
    sc = Scene("x", mesh, NeoHookeIsoVol(mu=1.0, K=2.0), clamped=["a", "b"])
    with pytest.raises(ValueError, match="unstable"):
        sc.setup("VCBCPPG V3m UnlP0")
    for name, unstable in (("VCBCPPG V3m UnlP0", True),
                           ("VCBCPPG V3sn UnlP0", False)):
        if unstable:  # build it as it was before the check
            saved = MasterDilatation.unstable_3d
            MasterDilatation.unstable_3d = ()
            try:
                _, model, _, D, _, _ = sc.setup(name)
            finally:
                MasterDilatation.unstable_3d = saved
        else:
            _, model, _, D, _, _ = sc.setup(name)
        K = model.tangent(model.state(model.initial()))
        free = np.setdiff1d(np.arange(model.N), D)
        ev = np.linalg.eigvals(K[free][:, free].toarray()).real
        assert (ev < -1e-9 * np.abs(ev).max()).any() == unstable
