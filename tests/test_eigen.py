"""Eigenmodes of the free, unloaded block (thesis Fig. 7.6)."""
import numpy as np
import pytest
import scipy.linalg
import skfem as fem

import skfem_pg as pg
from skfem_pg.models import lame, linear_elasticity


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
