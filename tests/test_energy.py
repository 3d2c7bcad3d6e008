"""Discrete strain energy and energy capture (analysis.energy_capture)."""
import numpy as np
import pytest
import skfem as fem

import skfem_pg as pg
from skfem_pg import materials as mat
from skfem_pg.analysis import (discrete_energy, energy_capture,
                               nodal_interpolant)
from skfem_pg.discretization.assembly import assemble
from skfem_pg.formulations import linear_elasticity
from conftest import cube

LAM, MU = 100.0, 40.0
GRAD = np.array([[0.1, 0.3, -0.2], [0.2, 0.4, 0.1], [-0.1, 0.05, 0.3]])


def _bases(mesh):
    fe = fem.Basis(mesh, fem.ElementVector(fem.ElementTetP1()), intorder=1)
    return {"O1": fe, "VC PBG Unl": pg.FamilyBasis(mesh, dim=3),
            "PBG Unl": pg.FamilyBasis(mesh, dim=3, vc=None)}


@pytest.mark.parametrize("name", ["O1", "VC PBG Unl", "PBG Unl"])
def test_linear_field_energy_is_captured_exactly(name):
    mesh = cube(4, 0.3, seed=2, kind="tet")
    b = _bases(mesh)[name]
    m = mat.LinearElastic(lam=LAM, mu=MU)
    exact = m.energy(np.eye(3) + GRAD) * 1.0  # unit cube
    r = energy_capture(b, lambda x: np.tensordot(GRAD, x, 1), m, exact)
    assert abs(r - 1) < 1e-12


@pytest.mark.parametrize("name", ["O1", "VC PBG Unl"])
def test_discrete_energy_is_half_u_K_u(name):
    """The same quadrature and gradients as the assembled stiffness."""
    mesh = cube(3, 0.25, seed=3, kind="tet")
    b = _bases(mesh)[name]
    u = nodal_interpolant(b, lambda x: np.array(
        [np.sin(x[0] + x[2]), x[1] ** 2, np.cos(2 * x[0]) * x[1]]) * 1e-2)
    K = assemble(linear_elasticity(LAM, MU), b)
    E = discrete_energy(b, u, mat.LinearElastic(lam=LAM, mu=MU))
    assert E == pytest.approx(0.5 * u @ K @ u, rel=1e-12)
    assert E > 0


def test_bending_capture_separates_soft_and_stiff():
    """Pure bending of a unit cube: O1 locks (captures more than the
    exact energy), the interpolant on a fine regular set converges."""
    m = mat.LinearElastic(lam=LAM, mu=MU)
    k = 1e-2

    def bend(x):
        return np.array([-k * x[0] * (x[2] - 0.5), 0 * x[0],
                         0.5 * k * x[0] ** 2])

    exact = 0.5 * (LAM + 2 * MU) * k ** 2 / 12.0
    coarse = _bases(cube(2, kind="tet"))
    fine = _bases(cube(8, kind="tet"))
    assert energy_capture(coarse["O1"], bend, m, exact) > 1.2
    for name in ("O1", "VC PBG Unl"):
        e2 = abs(energy_capture(coarse[name], bend, m, exact) - 1)
        e8 = abs(energy_capture(fine[name], bend, m, exact) - 1)
        assert e8 < 0.5 * e2, name


def test_nodal_interpolant_checks_the_field_shape():
    mesh = cube(2, kind="tet")
    for b in _bases(mesh).values():
        with pytest.raises(ValueError, match=r"shape \(3, 27\)"):
            nodal_interpolant(b, lambda x: x[:2])
    p2 = fem.Basis(mesh, fem.ElementVector(fem.ElementTetP2()))
    with pytest.raises(ValueError, match="vertex-only"):
        nodal_interpolant(p2, lambda x: x)
