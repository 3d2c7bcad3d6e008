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
