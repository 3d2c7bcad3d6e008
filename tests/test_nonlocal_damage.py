"""The nonlocal brittle criterion (issue 51): the bell mean over a model's
points, the crack-tip calibration, the uniform-strain failure, a
crack-aware run that rebuilds the mean with its families."""
import types

import numpy as np
import pytest
import skfem as fem
from scipy.integrate import dblquad, quad

import skfem_pg as pg
from skfem_pg.discretization.nonlocal_mean import NonlocalAverage
from skfem_pg.formulations import CrackAware, Hyperelastic, model_for
from skfem_pg.materials import J2Plasticity, NonlocalStrainDamage
from skfem_pg.materials.damage import tip_average

from test_fracture import pull, strip


def _square(n=9, kind="tri"):
    x = np.linspace(0.0, 4.0, n)
    return (fem.MeshTri if kind == "tri" else fem.MeshQuad).init_tensor(x, x)


@pytest.mark.parametrize("basis_of", [
    lambda: pg.FamilyBasis(_square(), dim=2),
    lambda: fem.CellBasis(_square(kind="quad"), fem.ElementQuad1())],
    ids=["family", "Q1 Gauss points"])
def test_the_mean_keeps_constants_and_leaves_masked_points_out(basis_of):
    """A constant is its own mean at every point; points masked out do
    not count, however large their values; a point with no masked point
    within the radius gets 0."""
    basis = basis_of()
    average = NonlocalAverage(basis, radius=1.2)
    n = average.n_points
    x = (basis.particles.x[:, basis.families.members]
         if hasattr(basis, "families") else
         np.asarray(basis.global_coordinates()).reshape(2, -1))
    assert np.allclose(average(np.full(n, 3.0), np.ones(n, bool)), 3.0,
                       rtol=0, atol=1e-13)
    left = x[0] < 2.0
    v = np.where(left, 1e6, 3.0)
    mean = average(v, ~left)
    reached = x[0] > 2.0 - 1.2 + 1e-9  # a masked point within the radius
    assert np.allclose(mean[reached], 3.0, rtol=0, atol=1e-9)
    assert np.all(mean[~reached] == 0.0)
    with pytest.raises(ValueError, match="values and"):
        average(np.zeros(n + 1), np.ones(n + 1, bool))


def test_the_mean_is_refused_on_mpi_ranks():
    with pytest.raises(NotImplementedError, match="MPI ranks"):
        NonlocalAverage(types.SimpleNamespace(distributed=object()), 1.0)


def test_the_tip_average_against_an_independent_quadrature():
    """c_2 and c_3 of ``tip_average`` (midpoint sums, the ball's z
    integrated in closed form) against scipy's adaptive quadrature of
    the near-tip field (the ball's z numerically)."""
    nu = 0.3

    def e1(r, t):
        f = 1 / np.sqrt(2 * np.pi * r)
        c, s = np.cos(t / 2), np.sin(t / 2)
        sxx = f * c * (1 - s * np.sin(1.5 * t))
        syy = f * c * (1 + s * np.sin(1.5 * t))
        sxy = f * c * s * np.cos(1.5 * t)
        E = 1 - nu ** 2  # E' = 1
        exx = ((1 - nu ** 2) * sxx - nu * (1 + nu) * syy) / E
        eyy = ((1 - nu ** 2) * syy - nu * (1 + nu) * sxx) / E
        exy = (1 + nu) * sxy / E
        return max(0.5 * (exx + eyy) + np.sqrt(0.25 * (exx - eyy) ** 2
                                               + exy ** 2), 0.0)

    def mean(w):
        num = dblquad(lambda r, t: w(r) * r * e1(r, t), -np.pi, np.pi, 0, 1,
                      epsabs=1e-10)[0]
        den = dblquad(lambda r, t: w(r) * r, -np.pi, np.pi, 0, 1)[0]
        return num / den

    c2 = mean(lambda r: (1 - r * r) ** 2)
    c3 = mean(lambda r: quad(lambda z: max(1 - r * r - z * z, 0.0) ** 2,
                             0, np.sqrt(1 - r * r))[0])
    assert abs(tip_average(nu) - c2) < 2e-4 * c2
    assert abs(tip_average(nu, dim=3) - c3) < 2e-4 * c3


def _affine_F(model, basis, strain):
    """The points' F of the displacement (strain x, 0)."""
    X = basis.doflocs
    u = np.where(np.arange(basis.N) % 2 == 0, strain * X[0], 0.0)
    return model.state(u)["F"]


@pytest.mark.parametrize("kind", ["PG Unl", "FE Q1"])
def test_a_uniform_strain_fails_every_point_at_the_critical_strain(kind):
    """A uniform strain: the nonlocal mean is the local strain, so every
    point fails together just above the critical log strain and none just
    below (PG: exact by the patch test; FE Q1: Gauss points)."""
    eps_c = 0.01
    law = NonlocalStrainDamage(eps_c, radius=1.5)
    steel = J2Plasticity.from_young(200e3, 0.3, 1e9, damage=law)
    if kind == "PG Unl":
        basis = pg.FamilyBasis.from_name(_square(), "VCBCPBG V5sn Unl",
                                         dim=2)
        model = model_for("Unl", basis, steel)
    else:
        basis = fem.CellBasis(_square(kind="quad"), fem.ElementVector(
            fem.ElementQuad1()))
        model = Hyperelastic(basis, steel)
    for factor, failed in ((0.999, False), (1.001, True)):
        r = model.history.response(_affine_F(model, basis,
                                             np.expm1(factor * eps_c)))
        assert np.all(r.failed == failed)
    assert model.history._average.basis is model.point_basis


def test_a_nonlocal_law_is_refused_outside_a_model_and_by_u1sig():
    steel = J2Plasticity.from_young(
        200e3, 0.3, 1e9, damage=NonlocalStrainDamage(0.01, radius=1.0))
    with pytest.raises(ValueError, match="nonlocal"):
        steel.stress(np.eye(2)[:, :, None] * np.ones(3))
    with pytest.raises(ValueError, match="radius must be positive"):
        NonlocalStrainDamage(0.01, radius=0.0)
    # U1SIG evaluates its material at the masters, not at the points
    basis = pg.FamilyBasis.from_name(_square(kind="quad"), "VCPBG V3m U1SIG",
                                     dim=2)
    model = model_for("U1SIG", basis, steel)
    with pytest.raises(ValueError, match="at the masters"):
        model.internal_force(model.state(np.zeros(model.N)))


def test_crack_aware_with_the_nonlocal_law_separates_the_strip():
    """An elastic–brittle notched strip (6 x 12 cells), crack-aware with
    the nonlocal criterion (radius 1.2 spacings): the strip comes apart
    at the notch (a band of three rows, the bell's width), and after each
    update the mean is over the rebuilt basis' points."""
    mesh, y_notch = strip(6, notch_cells=True)
    h = 10.0 / 6
    steel = J2Plasticity.from_young(
        200e3, 0.29, 1e9, damage=NonlocalStrainDamage(0.004,
                                                      radius=1.2 * h))
    basis = pg.FamilyBasis(mesh, dim=2)
    model = CrackAware(basis, steel)
    tr = pull(model, basis, 2e-3, 200.0, grip=0.0)[0]
    assert model.updates >= 1
    average = model.history._average
    assert average.basis is model.point_basis
    assert average.n_points == model._n_points()
    c = mesh.p[:, mesh.t].mean(axis=1)
    row = np.isclose(c[1], y_notch) & (c[0] > 3.0)  # the notch's row
    assert row.sum() == 4 and not model.intact[row].any()
    active = model.current.families.masters  # not the debris
    uy, y = tr.x[1::2][active], basis.particles.x[1, active]
    # apart: the lower piece rings within its elastic strain at failure
    # (0.004 x 9 mm), the upper one has gone with the grip (0.38 mm)
    assert np.abs(uy[y < y_notch - h]).max() < 0.05
    assert uy[y > y_notch + h].min() > 0.1
    assert abs(tr.history[-1]["relative_error"]) < 1e-2
