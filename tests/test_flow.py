"""Flow (thesis 8.2): the Newtonian fluid, its rate from Newmark, and
Poiseuille's start-up against the analytic series (issue 51)."""
import numpy as np
import pytest
import skfem as fem

import skfem_pg as pg
from skfem_pg.formulations import model_for
from skfem_pg.materials import NeoHookeIsoVol, NewtonianFluid, NoRateError
from skfem_pg.solvers import checkpoint, newmark
from skfem_pg.solvers.static import verdict

RHO, K, ETA, G, H = 1e3, 2.08e9, 1e-3, 2e-4, 1e-3  # water (thesis 8.2)
NU = ETA / RHO
V_MAX = G * H ** 2 / (8 * NU)


@pytest.mark.parametrize("d", [2, 3])
def test_fluid_tangent_is_the_derivative_of_its_stress(d):
    """Rate part, geometric part and volumetric part against central
    differences at random F, F_n and rate offset."""
    rng = np.random.default_rng(d)
    fluid = NewtonianFluid(K=3.0, eta=0.7)
    F = np.eye(d)[:, :, None] + 0.2 * rng.standard_normal((d, d, 4))
    history = {"alpha": np.zeros(4),
               "F": np.eye(d)[:, :, None] + 0.2 * rng.standard_normal(
                   (d, d, 4))}
    fluid.bind_rate(2.5, 0.3 * rng.standard_normal((d, d, 4)))
    A = fluid.update(F, history).tangent()
    e = 1e-6
    for k in range(d):
        for L in range(d):
            Fp, Fm = F.copy(), F.copy()
            Fp[k, L] += e
            Fm[k, L] -= e
            fd = (fluid.update(Fp, history).P
                  - fluid.update(Fm, history).P) / (2 * e)
            assert np.abs(A[:, :, k, L] - fd).max() <= 1e-8 * np.abs(A).max()


def test_fluid_shear_stress_is_viscous_and_stores_nothing():
    """Simple shear at the rate 0.4/s: sigma_xy = eta 0.4, no normal
    stress (J = 1), no stored energy."""
    fluid = NewtonianFluid(K=2.0, eta=0.5)
    F = np.eye(2)[:, :, None] + np.array([[0, 0.1], [0, 0]])[:, :, None]
    fluid.bind_rate(0.0, np.array([[0, 0.4], [0, 0]])[:, :, None])
    r = fluid.update(F, fluid.initial_history((1,)))
    sigma = r.P[:, :, 0] @ F[:, :, 0].T  # J = 1
    assert sigma[0, 1] == pytest.approx(0.5 * 0.4, rel=1e-14)
    assert sigma[1, 0] == pytest.approx(0.5 * 0.4, rel=1e-14)
    assert abs(sigma[0, 0]) <= 1e-15 and abs(sigma[1, 1]) <= 1e-15
    assert abs(r.energy()[0]) <= 1e-16


def test_fluid_parameters_and_refusals():
    with pytest.raises(ValueError, match="eta"):
        NewtonianFluid(K=1.0, eta=-1.0)
    with pytest.raises(ValueError, match="bulk modulus"):
        NewtonianFluid(K=0.0, eta=1.0)
    with pytest.raises(ValueError, match="shear modulus"):
        NeoHookeIsoVol.isochoric(-1.0)
    fluid = NewtonianFluid(K=1.0, eta=1.0)
    with pytest.raises(NoRateError, match="newmark"):
        fluid.update(np.eye(2)[:, :, None], fluid.initial_history((1,)))
    with pytest.raises(NoRateError, match="stateful"):
        fluid.stress(np.eye(2)[:, :, None])


def _channel(n, method="VCBCPBG V5m Unl+P1C"):
    """The Poiseuille channel of demos/poiseuille.py: ``(model, m, f, D,
    middle)``."""
    mesh = fem.MeshQuad.init_tensor(np.linspace(0, H, n + 1),
                                    np.linspace(0, H, n + 1))
    basis = pg.FamilyBasis.from_name(mesh, method, dim=2)
    model = model_for(method.split()[-1], basis,
                      NewtonianFluid(K=K, eta=ETA))
    m = pg.lumped_mass(basis, RHO)
    X = basis.doflocs
    along = np.arange(basis.N) % 2 == 0
    wall = np.isclose(X[1], 0) | np.isclose(X[1], H)
    end = np.isclose(X[0], 0) | np.isclose(X[0], H)
    D = np.flatnonzero(wall | (end & ~along))
    middle = np.flatnonzero(along & np.isclose(X[0], H / 2))
    return model, m, np.where(along, m * G, 0.0), D, middle


def _series(y, t):
    v = G / (2 * NU) * y * (H - y)
    for k in range(1, 400, 2):
        v -= (4 * G * H ** 2 / (NU * np.pi ** 3 * k ** 3)
              * np.sin(k * np.pi * y / H)
              * np.exp(-k ** 2 * np.pi ** 2 * NU * t / H ** 2))
    return v


def test_static_and_explicit_drivers_refuse_a_fluid():
    model, m, f, D, _ = _channel(4)
    with pytest.raises(ValueError, match="newton .*newmark"):
        pg.newton(model, f, D=D, verbose=False)
    with pytest.raises(ValueError, match="central_difference .*newmark"):
        pg.central_difference(model, m, 1e-3, f_ext=f, D=D, verbose=False)
    with pytest.raises(ValueError, match="U1SUnl"):  # material at masters
        model_for("U1SUnl", pg.FamilyBasis.from_name(
            fem.MeshQuad().refined(2), "VCPBG U1SUnl", dim=2),
            NewtonianFluid(K=1.0, eta=1.0))


def test_poiseuille_start_up_follows_the_series():
    """PG Unl+P1C on 17 x 17 particles, Newmark with numerical damping:
    the middle column's v_x within 1 % of v_max of the series at t = 0.1 s
    (measured 8.4e-3) and at 0.5 s (7.8e-3).  After the run its fields
    can be read, and the shear stress at the final state is the viscous
    one of the final velocities (eta dv/dy: at the wall 4 v_max eta/H)."""
    model, m, f, D, middle = _channel(16)
    y = model.basis.doflocs[1, middle]
    seen = {}

    final = {}

    def output(t, x, v, record):
        for s in (0.1, 0.5):
            if np.isclose(t, s):
                seen[s] = v[middle].copy()
        final.update(x=x.copy(), v=v.copy())
    newmark(model, m, 0.5, 0.02, f_ext=f, D=D, callback=output,
            verbose=False, gamma=0.6, beta=0.3025)
    assert sorted(seen) == [0.1, 0.5]
    for t, v in seen.items():
        assert np.abs(v - _series(y, t)).max() <= 1e-2 * V_MAX, t
    tr_x = model.initial()
    tr_x[:] = final["x"]
    fields = model.fields(tr_x)
    assert set(fields) >= {"p", "Theta"}
    state = model.state(tr_x)
    P = model.stress(state)
    L = model.rate_gradient(final["v"])
    # the shear stress is eta (dv_x/dy + dv_y/dx) of the final velocities
    # up to the bubble's share (measured 7.3 % of the largest)
    shear = P[0, 1] - ETA * (L[0, 1] + L[1, 0])
    assert np.abs(shear).max() <= 0.1 * ETA * np.abs(L[0, 1]).max()


def test_pbg_unl_locks_and_does_not_flow():
    """The thesis' finding (8.2): PBG Unl does not flow; at t = 0.1 s its
    centre moves at under 2 % of the series' velocity (measured -0.5 %)."""
    model, m, f, D, middle = _channel(8, "PBG Unl")
    tr = newmark(model, m, 0.1, 0.02, f_ext=f, D=D, verbose=False,
                 gamma=0.6, beta=0.3025)
    assert np.abs(tr.v[middle]).max() <= 0.02 * _series(H / 2, 0.1)


def test_a_flow_resumes_to_round_off(tmp_path):
    """The fluid's committed F is part of the checkpoint."""
    model, m, f, D, _ = _channel(4)

    def run(**kw):
        fresh = model_for("Unl+P1C", model.basis,
                          NewtonianFluid(K=K, eta=ETA))
        return newmark(fresh, m, 0.3, 0.05, f_ext=f, D=D, verbose=False,
                       gamma=0.6, beta=0.3025, **kw)
    full = run()

    class Stop(Exception):
        pass

    def stop(t, x, v, record):
        if t > 0.17:
            raise Stop
    with pytest.raises(Stop):
        run(checkpoint=checkpoint.Every(tmp_path / "flow", steps=1),
            callback=stop)
    resumed = run(resume=tmp_path / "flow")
    assert resumed.t == full.t
    assert np.abs(resumed.v - full.v).max() <= 1e-10 * np.abs(full.v).max()


def test_newton_accepts_a_flat_round_off_floor_only():
    """The stall rule (static.STALL_RESIDUAL): flat residuals far below
    the load with the increments' work gone are converged; a residual
    that still falls by 0.6 per iteration is not."""
    flat = [1.4e-10, 2.8e-14, 2.9e-14, 2.8e-14, 2.9e-14]
    work = [1e-21, 2e-28, 1.3e-29, 1.4e-29]
    assert verdict(flat, work, 1.2e-8, 1e-9) == (True, "round-off floor")
    falling = [1e-10 * 0.6 ** i for i in range(5)]
    assert verdict(falling, work, 1e-4, 1e-9)[0] is None
    assert verdict(flat, [1e-21, 1e-22, 1e-22, 1e-22], 1.2e-8,
                   1e-9)[0] is None  # the increments still do work


def _column(method, n=10, H_col=0.1):
    """A square column of water at rest in a box (slip walls at the sides
    and the bottom, a free top), gravity 9.81 m/s^2 down:
    ``(model, m, f, D)``."""
    mesh = fem.MeshQuad.init_tensor(np.linspace(0, H_col, n + 1),
                                    np.linspace(0, H_col, n + 1))
    fluid = NewtonianFluid(K=K, eta=ETA)
    if method.startswith("FEM"):
        basis = fem.Basis(mesh, fem.ElementVector(fem.ElementQuad1()))
        along = np.zeros(basis.N, dtype=bool)
        along[basis.nodal_dofs[0]] = True
    else:
        basis = pg.FamilyBasis.from_name(mesh, method, dim=2)
        along = np.arange(basis.N) % 2 == 0
    model = model_for(method.split()[-1], basis, fluid)
    m = pg.lumped_mass(basis, RHO)
    X = basis.doflocs
    D = np.flatnonzero((np.isclose(X[1], 0) & ~along)
                       | ((np.isclose(X[0], 0) | np.isclose(X[0], H_col))
                          & along))
    return model, m, np.where(~along, -m * 9.81, 0.0), D


@pytest.mark.parametrize("method", [
    "FEM Q1P0",
    pytest.param("VCBCPBG V5m Unl+P1C", marks=pytest.mark.xfail(
        strict=True, reason="issue 51: the pressure's integration is not "
        "exact for a linear pressure (VC covers constant fields only), "
        "and the wall particles slide down their slip walls at about g: "
        "0.21 sqrt(gH) after 0.02 s, J <= 0 at 0.026 s (UnlP0: 0.06, "
        "J <= 0 at 0.10 s); the thesis' diagnosis of its dam break "
        "(8.2)")),
])
def test_a_column_of_water_stays_at_rest(method):
    """Hydrostatics, the state every free-surface flow starts from: a
    0.1 m column at rest stays at rest — after 0.02 s no velocity above
    1 % of sqrt(gH) (FE Q1P0: measured 9.3e-4, the settling of its
    compressibility)."""
    model, m, f, D = _column(method)
    tr = newmark(model, m, 0.02, 0.005, f_ext=f, D=D, verbose=False,
                 gamma=0.6, beta=0.3025)
    assert np.abs(tr.v).max() <= 1e-2 * np.sqrt(9.81 * 0.1)
