"""FElupe's material library on family and FE bases (FElupeMaterial), and
the package's own laws taking their moduli by name."""
import warnings

import numpy as np
import pytest
import skfem as fem

import skfem_pg as pg
from skfem_pg import loadcase
from skfem_pg.formulations import Hyperelastic
from skfem_pg.materials import (J2Plasticity, NeoHooke, NeoHookeIsoVol,
                                FElupeMaterial)

felupe = pytest.importorskip("felupe")
pytest.importorskip("tensortrax")


def _laws():
    return {"ogden": felupe.Hyperelastic(felupe.ogden, mu=[1.0, 0.2],
                                         alpha=[1.7, -1.5]),
            "yeoh": felupe.Hyperelastic(felupe.yeoh, C10=0.5, C20=-0.1,
                                        C30=0.02),
            "mooney_rivlin": felupe.Hyperelastic(felupe.mooney_rivlin,
                                                 C10=0.3, C01=0.2),
            "extended_tube": felupe.Hyperelastic(
                felupe.extended_tube, Gc=0.18, Ge=0.17, beta=0.2,
                delta=0.09),
            "NeoHooke": felupe.NeoHooke(mu=1.0, bulk=5.0)}


@pytest.mark.parametrize("name", sorted(_laws()))
@pytest.mark.parametrize("d", [2, 3])
def test_tangent_is_the_derivative_of_the_stress(name, d):
    law = FElupeMaterial(_laws()[name])
    rng = np.random.default_rng(3)
    F = np.eye(d)[:, :, None, None] + 0.1 * rng.standard_normal(
        (d, d, 4, 5))
    dF = rng.standard_normal(F.shape)
    eps = 1e-6
    fd = (law.stress(F + eps * dF) - law.stress(F - eps * dF)) / (2 * eps)
    A = law.tangent(F)
    assert A.shape == (d,) * 4 + (4, 5)
    an = np.einsum("iJkL...,kL...->iJ...", A, dF)
    assert np.abs(an - fd).max() < 1e-6 * np.abs(fd).max()


def _cube():
    return fem.MeshHex.init_tensor(*(np.linspace(0, 1, 4),) * 3)


def test_felupe_getting_started_cube_h1_equals_felupe():
    """FElupe's getting-started cube (NeoHooke(mu=1, bulk=5), uniaxial,
    clamped, moved by -0.3) posed with the package's load case and H1 on
    the same nodes and Gauss points: FElupe's own solution to 1e-10."""
    fmesh = felupe.Cube(n=4)
    field = felupe.FieldContainer([felupe.Field(
        felupe.RegionHexahedron(fmesh), dim=3)])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        boundaries = felupe.dof.uniaxial(field, clamped=True, move=-0.3)[0]
    solid = felupe.SolidBody(felupe.NeoHooke(mu=1, bulk=5), field)
    step = felupe.Step(items=[solid], ramp={
        boundaries["move"]: felupe.math.linsteps([0, -0.3], num=5)},
        boundaries=boundaries)
    felupe.Job(steps=[step]).evaluate(verbose=0, tol=1e-12)
    mesh = _cube()
    index = {tuple(x): i for i, x in enumerate(
        np.round(fmesh.points, 9).tolist())}
    order = [index[tuple(x)] for x in np.round(mesh.p.T, 9).tolist()]
    u_felupe = field[0].values[order]
    basis = fem.Basis(mesh, fem.ElementVector(fem.ElementHex1()),
                      intorder=3)  # FElupe's 2 x 2 x 2 Gauss points
    model = Hyperelastic(basis, FElupeMaterial(felupe.NeoHooke(mu=1,
                                                               bulk=5)))
    case = loadcase.uniaxial(basis, move=-0.3, clamped=True)
    x, _ = pg.solvers.newton(case.problem(model), verbose=False, tol=1e-12,
                             steps=5)
    u = np.stack([x[basis.nodal_dofs[c]] for c in range(3)], axis=1)
    assert np.abs(u - u_felupe).max() < 1e-10


@pytest.mark.parametrize("d", [2, 3])
def test_homogeneous_stretch_pg_equals_fe(d):
    """An Ogden law (tensortrax; isochoric, so with FElupe's volumetric
    part beside it: alone, free lateral faces let it dilate at no stress)
    in uniaxial tension: the state is homogeneous, so PG (VC) and linear
    FE both reproduce it and their reactions agree to round-off."""
    mesh = fem.MeshTri.init_symmetric().refined(2) if d == 2 else _cube()
    law = FElupeMaterial(_laws()["ogden"] & felupe.Volumetric(bulk=5.0))
    forces = []
    for basis in (pg.FamilyBasis(mesh, dim=d),
                  fem.Basis(mesh, fem.ElementVector(type(mesh.elem())()))):
        model = Hyperelastic(basis, law)
        case = loadcase.uniaxial(basis, move=0.25)
        x, _ = pg.solvers.newton(case.problem(model), verbose=False,
                                 tol=1e-12)
        forces.append(case.reaction(model, x))
    assert forces[0] > 0
    assert forces[0] == pytest.approx(forces[1], rel=1e-9)


def test_refusals_and_moduli_by_name():
    with pytest.raises(TypeError, match="gradient and hessian"):
        FElupeMaterial(object())
    with pytest.raises(NotImplementedError, match="state variable"):
        FElupeMaterial(felupe.LinearElasticPlasticIsotropicHardening(
            E=1.0, nu=0.3, sy=1.0, K=0.1))
    with pytest.raises(ValueError, match="shape"):
        FElupeMaterial(_laws()["yeoh"]).stress(np.ones((1, 1, 3)))
    with pytest.raises(NotImplementedError, match="strain energy"):
        FElupeMaterial(_laws()["yeoh"]).energy(np.eye(3)[:, :, None])
    for call, names in ((lambda: NeoHooke(60.0, 40.0), "lam=..., mu=..."),
                        (lambda: NeoHookeIsoVol(40.0, 100.0),
                         "mu=..., K=..."),
                        (lambda: J2Plasticity(1.0, 2.0, 0.1),
                         "mu=..., K=..., sigma_y0=...")):
        with pytest.raises(TypeError, match="by name.*" + names.replace(
                ".", r"\.")):
            call()
    assert NeoHookeIsoVol(mu=40.0, K=100.0).K == 100.0
