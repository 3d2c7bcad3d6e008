"""Numerical inf-sup test (Chapelle & Bathe; thesis 7.2.5) on the clamped
unit square: known FE behaviour first, then the PG displacement spaces."""
import numpy as np
import pytest
import skfem as fem

import skfem_pg as pg
from skfem_pg.analysis.infsup import infsup_fe, infsup_pg


def square(N, distortion=0.0):
    m = fem.MeshQuad.init_tensor(np.linspace(0, 1, N + 1),
                                 np.linspace(0, 1, N + 1))
    return pg.meshing.distort(m, distortion, seed=N) if distortion else m


def q1p0(N, distortion=0.0):
    m = square(N, distortion)
    b = fem.Basis(m, fem.ElementVector(fem.ElementQuad1()), intorder=2)
    free = b.complement_dofs(b.get_dofs())
    return infsup_fe(b, free, fem.Basis(m, fem.ElementQuad0(), intorder=2))


def mini(N):
    m = square(N).to_meshtri()
    b = fem.Basis(m, fem.ElementVector(fem.ElementTriMini()))
    free = b.complement_dofs(b.get_dofs())
    return infsup_fe(b, free, fem.Basis(m, fem.ElementTriP1(),
                                        quadrature=b.quadrature))


@pytest.fixture(scope="module")
def fe_series():
    return {N: (q1p0(N), mini(N), q1p0(N, 0.2)) for N in (4, 8, 16)}


def test_q1p0_counts_the_checkerboard_and_fails(fe_series):
    for N, (reg, _, dist) in fe_series.items():
        # (7.15): the constant pressure and, on regular meshes, the
        # checkerboard; distortion removes the exact checkerboard
        assert reg["kpm"] == 2 and dist["kpm"] == 1
    b = [fe_series[N][0]["beta"] for N in (4, 8, 16)]
    # measured 0.368, 0.216, 0.115: beta ~ h (Chapelle & Bathe: the 4/1
    # element fails the test)
    assert b[2] < 0.6 * b[1] < 0.6 * 0.6 * b[0]


def test_mini_passes(fe_series):
    b = [fe_series[N][1]["beta"] for N in (4, 8, 16)]
    assert all(v["kpm"] == 1 for v in (fe_series[N][1] for N in (4, 8, 16)))
    assert min(b) > 0.3 and b[2] > 0.95 * b[1]  # measured 0.318 .. 0.314


def test_full_integration_locks_on_fe_and_pg():
    beta_q1, beta_unl = [], []
    for N in (4, 8, 16):
        m = square(N)
        b = fem.Basis(m, fem.ElementVector(fem.ElementQuad1()), intorder=2)
        free = b.complement_dofs(b.get_dofs())
        beta_q1.append(infsup_fe(b, free)["beta"])
        p = pg.Particles.from_mesh(m)
        fam = pg.families.horizon(p, factor=2.51)
        pb = pg.FamilyBasis(p, fam, dim=2, vc=None)  # thesis: no VC here
        beta_unl.append(infsup_pg(pb, free)["beta"])
    # measured Q1 0.221, 0.109, 0.054; PBG Unl 0.347, 0.140, 0.049
    for beta in (beta_q1, beta_unl):
        assert beta[2] < 0.6 * beta[1] < 0.6 * 0.6 * beta[0]


def test_inf_sup_refuses_ppg():
    m = square(4)
    pb = pg.FamilyBasis(m, dim=2, method="PPG1")
    with pytest.raises(ValueError, match="PPG1"):
        infsup_pg(pb, np.arange(pb.N))


def family_basis(m, shape="MTE1"):
    """The thesis' inf-sup setting: horizon 2.51 spacings, no VC."""
    p = pg.Particles.from_mesh(m)
    return pg.FamilyBasis(p, pg.families.horizon(p, factor=2.51), dim=2,
                          vc=None, shape=shape)


def test_mixed_inf_sup_of_q1p0_is_the_fe_one():
    from skfem_pg.analysis.infsup import infsup_mixed
    from skfem_pg.formulations import MeanDilatation
    m = square(4, 0.2)
    b = fem.Basis(m, fem.ElementVector(fem.ElementQuad1()), intorder=2)
    free = b.complement_dofs(b.get_dofs())
    fe = infsup_fe(b, free, fem.Basis(m, fem.ElementQuad0(), intorder=2))
    mixed = infsup_mixed(MeanDilatation(b, 1.0, 10.0), free)
    assert abs(mixed["beta"] - fe["beta"]) <= 1e-10 * fe["beta"]
    assert mixed["kpm"] == fe["kpm"]


def test_mixed_pg_pairs():
    """Measured on the clamped square (benchmarks/infsup_mixed.py):
    Unl+P1C has no spurious pressure mode and the largest beta of the PBG
    pairs (±0.3h, N = 4, 8: 0.31, 0.16); UnlP0 and U2P1C lie an order of
    magnitude below (0.023 / 0.016, 0.035 / 0.023); U2P1's beta falls like
    U2's (regular: 0.17, 0.043), its linear p, Theta reproduce the linear
    divergence of a WTE2 family exactly (the thesis: U2P1 locks)."""
    from skfem_pg.analysis.infsup import infsup_mixed
    from skfem_pg.formulations import MeanDilatation, NodalPressure
    beta = {}
    for N in (4, 8):
        for dist in (0.0, 0.3):
            m = square(N, dist)
            b = fem.Basis(m, fem.ElementVector(fem.ElementQuad1()))
            free = b.complement_dofs(b.get_dofs())
            mte, wte = family_basis(m), family_basis(m, "WTE2")
            r = {"Unl+P1C": infsup_mixed(NodalPressure(mte, 1.0, 10.0),
                                         free),
                 "UnlP0": infsup_mixed(MeanDilatation(mte, 1.0, 10.0), free),
                 "U2P1C": infsup_mixed(NodalPressure(wte, 1.0, 10.0,
                                                     bubble=False), free),
                 "U2P1": infsup_mixed(MeanDilatation(wte, 1.0, 10.0,
                                                     order=1), free)}
            assert r["Unl+P1C"]["kpm"] == 0
            for k, v in r.items():
                beta[k, N, dist] = v["beta"]
    for N in (4, 8):
        assert beta["Unl+P1C", N, 0.3] > 5 * beta["UnlP0", N, 0.3]
        assert beta["Unl+P1C", N, 0.3] > 3 * beta["U2P1C", N, 0.3]
    assert beta["U2P1", 8, 0.0] < 0.35 * beta["U2P1", 4, 0.0]
