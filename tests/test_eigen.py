"""Eigenmodes of the free, unloaded block (thesis Fig. 7.6)."""
import numpy as np
import pytest
import scipy.linalg
import skfem as fem

import skfem_pg as pg
from skfem_pg.materials import lame
from skfem_pg.formulations import linear_elasticity


@pytest.fixture(scope="module")
def block():
    mesh = fem.MeshQuad.init_tensor(np.linspace(0, 2, 21),
                                    np.linspace(0, 1, 11))
    form = linear_elasticity(*lame(1.0, 0.4))
    K = form.assemble(fem.Basis(mesh, fem.ElementVector(fem.ElementQuad1())))
    ev = scipy.linalg.eigvalsh(K.toarray())
    return mesh, form, ev[3] / ev[-1]  # lowest physical mode of Q1


def spectrum(mesh, form, families=None, **kw):
    p = pg.Particles.from_mesh(mesh)
    K = pg.assemble(form, pg.FamilyBasis(p, families, dim=2, **kw))
    ev = scipy.linalg.eigvalsh(K.toarray())
    return ev / ev[-1]


def test_vc_pbg_unl_has_exactly_three_zero_modes(block):
    mesh, form, q1_lowest = block
    rel = spectrum(mesh, form)
    assert np.sum(np.abs(rel) < 1e-10) == 3
    # no spurious soft mode: the first deformation mode is physical
    assert rel[3] > 0.5 * q1_lowest


def test_u1_has_spurious_soft_modes(block):
    mesh, form, q1_lowest = block
    rel = spectrum(mesh, form, shape="WTE1")
    spurious = np.sum(rel[3:] < 0.5 * q1_lowest)
    assert spurious >= 5
    p = pg.Particles.from_mesh(mesh)
    rel3 = spectrum(mesh, form, pg.families.horizon(p, factor=3.01),
                    shape="WTE1")
    assert np.sum(rel3[3:] < 0.5 * q1_lowest) >= 5


def test_spectrum_tool_and_ppg_stability(block):
    """Free-block spectra with :mod:`skfem_pg.analysis.spectrum` (lumped mass):
    default VC PPG Unl (with bond correction) is stable like VC PBG Unl;
    without bond correction its non-symmetric tangent has eigenvalues with
    negative real part (measured: 6, the lowest -18.9)."""
    from skfem_pg.analysis.spectrum import classify, free_modes
    mesh, form, _ = block
    p = pg.Particles.from_mesh(mesh)
    M = np.repeat(p.volumes, 2)
    q1 = fem.Basis(mesh, fem.ElementVector(fem.ElementQuad1()), intorder=2)
    ref = free_modes(pg.assemble(form, q1), M)["eigenvalues"][3]
    out = {}
    for name, kw in {"PBG": {}, "PPG": dict(method="PPG1"),
                     "PPG no BC": dict(method="PPG1", bond=False),
                     "U1": dict(shape="WTE1")}.items():
        s = free_modes(pg.assemble(form, pg.FamilyBasis(p, dim=2, **kw)), M)
        out[name] = (s["eigenvalues"], classify(s["eigenvalues"], s["scale"],
                                                3, ref))
    for name in ("PBG", "PPG"):
        lam, c = out[name]
        assert c["zero"] == 3 and c["soft"] == 0 and lam[0] > -1e-10
    assert out["U1"][1]["soft"] >= 5
    assert np.sum(out["PPG no BC"][0] < -1e-8) >= 1


def test_random_centroid_patch_u1_soft_unl_stable():
    """Seed 002's patch: ~450 centroids of irregular gmsh quads, 12
    nearest neighbours.  Measured: U1 137 soft modes, VC PBG Unl none."""
    from skfem_pg.analysis.spectrum import free_modes
    mesh = pg.meshing.from_geo(pg.meshing.geo_path("square.geo"), size=0.11,
                               recombine=True)
    p = pg.Particles.from_mesh(mesh, kind="centroids")
    fam = pg.families.nearest(p, 12, pairwise=True)
    form = linear_elasticity(*lame(1.0, 0.3))
    M = np.repeat(p.volumes, 2)
    lam = {name: free_modes(pg.assemble(form, pg.FamilyBasis(
        p, fam, dim=2, **kw)), M)["eigenvalues"]
        for name, kw in {"U1": dict(shape="WTE1"), "Unl": {}}.items()}
    ref = lam["Unl"][3]
    for name, ev in lam.items():
        assert np.sum(np.abs(ev) < 1e-10 * ev[-1]) == 3
    assert np.sum(lam["Unl"][3:] < 0.5 * ref) == 0
    assert np.sum(lam["U1"][3:] < 0.5 * ref) >= 50
