"""Time integration against closed-form answers: the clamped-free bar's
first period 4L/c, energy conservation (Newmark exact for a linear
problem, central differences without drift), the arrival time of a wave,
a bar bouncing off a rigid wall (contact 2L/c, rebound, release)."""
import numpy as np
import pytest
import skfem as fem

import skfem_pg as pg
from skfem_pg.formulations import Hyperelastic, model_for
from skfem_pg.materials import J2Plasticity, LinearElastic, NeoHookeIsoVol
from skfem_pg.solvers import (DynamicsError, RigidWall, central_difference,
                              lumped_mass, max_frequency, newmark,
                              stable_time_step)

E, RHO = 100.0, 1.0
C = np.sqrt(E / RHO)  # nu = 0: the bar's wave speed in plane strain
ELASTIC = LinearElastic(lam=0.0, mu=E / 2)


def bar(L=10.0, nx=20, ny=2, H=1.0):
    return fem.MeshQuad.init_tensor(
        np.linspace(0, L, nx + 1), np.linspace(0, H, ny + 1)
    ).with_boundaries({"left": lambda x: np.isclose(x[0], 0.0)})


def basis_of(mesh, kind):
    if kind == "PG":
        return pg.FamilyBasis(pg.Particles.from_mesh(mesh), dim=2)
    return fem.Basis(mesh, fem.ElementVector(fem.ElementQuad1()),
                     intorder=2)


def first_mode(basis, L, amplitude=1e-3):
    X = basis.doflocs
    u0 = np.zeros(basis.N)
    u0[0::2] = amplitude * np.sin(0.5 * np.pi * X[0, 0::2] / L)
    return u0


def period(ts, us):
    """Twice the mean spacing of the zero crossings."""
    ts, us = np.asarray(ts), np.asarray(us)
    i = np.flatnonzero(np.sign(us[1:]) != np.sign(us[:-1]))
    tz = ts[i] - us[i] * (ts[i + 1] - ts[i]) / (us[i + 1] - us[i])
    return 2 * np.mean(np.diff(tz))


@pytest.mark.parametrize("kind", ["PG", "Q1"])
def test_lumped_mass_is_rho_times_volume(kind):
    basis = basis_of(bar(), kind)
    m = lumped_mass(basis, 2.5)
    assert m.shape == (basis.N,)
    assert np.isclose(m[0::2].sum(), 2.5 * 10.0) and np.allclose(
        m[0::2], m[1::2])


def test_lumped_mass_refuses_what_it_cannot_lump():
    mesh = fem.MeshTri.init_tensor(np.linspace(0, 1, 3), np.linspace(0, 1, 3))
    with pytest.raises(ValueError, match="T2/O2"):
        lumped_mass(fem.Basis(mesh, fem.ElementVector(fem.ElementTriP2())),
                    1.0)
    with pytest.raises(ValueError, match="rho must be positive"):
        lumped_mass(basis_of(bar(), "PG"), -1.0)


@pytest.mark.parametrize("kind", ["PG", "Q1"])
def test_explicit_bar_period_and_energy_drift(kind):
    """First longitudinal period within 1 % of 4L/c; the energy balance
    drifts by less than 0.5 % over 10 periods."""
    L = 10.0
    basis = basis_of(bar(L), kind)
    model = Hyperelastic(basis, ELASTIC)
    m = lumped_mass(basis, RHO)
    tip = np.flatnonzero(np.isclose(basis.doflocs[0], L)
                         & (np.arange(basis.N) % 2 == 0))
    ts, us = [], []
    T = 4 * L / C
    tr = central_difference(
        model, m, 10 * T, D=basis.get_dofs("left").flatten(),
        u0=first_mode(basis, L), output_every=1, verbose=False,
        callback=lambda t, x, v, r: (ts.append(t), us.append(x[tip].mean())))
    assert abs(period(ts, us) / T - 1) < 0.01
    err = np.abs(tr.series("relative_error"))
    assert err.max() < 5e-3
    # the balance closes: kinetic + stored = the initial stored energy
    h = tr.history[-1]
    assert np.isclose(h["kinetic"] + h["stored"],
                      tr.history[0]["stored"], rtol=5e-3)


def test_newmark_conserves_a_linear_problems_energy_exactly():
    """Average acceleration: T + U constant to round-off (the trapezoidal
    works are exact); the period within 1 %."""
    L = 10.0
    basis = basis_of(bar(L), "PG")
    model = Hyperelastic(basis, ELASTIC)
    m = lumped_mass(basis, RHO)
    tip = np.flatnonzero(np.isclose(basis.doflocs[0], L)
                         & (np.arange(basis.N) % 2 == 0))
    ts, us, tot = [], [], []
    T = 4 * L / C

    def cb(t, x, v, r):
        ts.append(t)
        us.append(x[tip].mean())
        tot.append(r["kinetic"] + r["stored"])
    tr = newmark(model, m, 2 * T, T / 100, D=basis.get_dofs("left").flatten(),
                 u0=first_mode(basis, L), callback=cb, verbose=False)
    assert abs(period(ts, us) / T - 1) < 0.01
    tot = np.array(tot)
    assert np.abs(tot / tot[0] - 1).max() < 1e-10
    assert np.abs(tr.series("relative_error")).max() < 1e-10


@pytest.mark.study
@pytest.mark.parametrize("method", ["explicit", "newmark"])
def test_wave_arrival_time(method):
    """A velocity prescribed at one end of a long bar: the particle
    velocity at the middle reaches half of it at L/(2c), within 3 %."""
    L = 40.0
    basis = basis_of(bar(L, nx=160, ny=1), "PG")
    model = Hyperelastic(basis, ELASTIC)
    m = lumped_mass(basis, RHO)
    D = basis.get_dofs("left").nodal["u^1"]
    V = 1e-3 * C
    even = np.arange(basis.N) % 2 == 0
    probe = np.flatnonzero(np.isclose(basis.doflocs[0], L / 2) & even)
    rec = []
    t_end = 0.75 * L / C
    kw = dict(D=D, u_D=lambda t: np.where(even, V * t, 0.0), verbose=False,
              callback=lambda t, x, v, r: rec.append((t, v[probe].mean())))
    if method == "explicit":
        central_difference(model, m, t_end, output_every=1, **kw)
    else:
        newmark(model, m, t_end, t_end / 400, **kw)
    t, vp = np.array(rec).T
    i = np.flatnonzero(vp >= 0.5 * V)[0]
    ta = t[i - 1] + (0.5 * V - vp[i - 1]) * (t[i] - t[i - 1]) / (
        vp[i] - vp[i - 1])
    assert abs(ta / (0.5 * L / C) - 1) < 0.03
    assert vp[0] == 0 and abs(vp[-1] / V - 1) < 0.1


@pytest.mark.parametrize("far_wall", [False, True])
@pytest.mark.parametrize("method", ["explicit", "newmark"])
def test_bar_bounces_off_a_rigid_wall(method, far_wall):
    """Elastic impact: the wall holds the bar for 2L/c (within 3 %),
    releases every dof (no tensile reaction) and the bar leaves with
    nearly its impact speed; the wall took the first column's kinetic
    energy (its share of the mass, 1/(2 nx)).  A second wall on the same
    axis far away changes nothing (it used to put the dofs held by the
    first one onto itself)."""
    L, nx = 10.0, 40
    basis = basis_of(bar(L, nx), "PG")
    model = Hyperelastic(basis, ELASTIC)
    m = lumped_mass(basis, RHO)
    V = 0.01 * C
    v0 = np.where(np.arange(basis.N) % 2 == 0, -V, 0.0)
    rec = []
    t_end = 3 * L / C
    walls = [RigidWall(0, 0.0)] + ([RigidWall(0, 3 * L, side=-1)]
                                   if far_wall else [])
    kw = dict(v0=v0, wall=walls, verbose=False,
              callback=lambda t, x, v, r: rec.append(
                  (t, r["active"], np.dot(m[0::2], v[0::2]) / m[0::2].sum())))
    if method == "explicit":
        tr = central_difference(model, m, t_end, output_every=1, **kw)
    else:
        tr = newmark(model, m, t_end, L / C / 100, **kw)
    t, active, vx = np.array(rec).T
    t_off = t[np.flatnonzero(active > 0)[-1] + 1]
    assert abs(t_off / (2 * L / C) - 1) < 0.03
    assert active[-1] == 0 and active[0] > 0
    assert 0.95 < vx[-1] / V <= 1.0
    loss = tr.history[-1]["contact_loss"] / (0.5 * m[0::2].sum() * V ** 2)
    assert abs(loss - 1 / (2 * nx)) < 0.2 / (2 * nx)
    assert np.abs(tr.series("relative_error")).max() < 1e-2


def test_explicit_step_above_the_limit_is_refused():
    """A step 10 % above 2/omega_max grows without bound: it is refused
    where it enters, with the stable step named (issue 47: a fixed step
    far above it ran until an "inverted point"); the run whose energy
    balance breaks stops with DynamicsError instead of returning
    garbage."""
    L = 10.0
    basis = basis_of(bar(L), "PG")
    model = Hyperelastic(basis, ELASTIC)
    m = lumped_mass(basis, RHO)
    dt = stable_time_step(model, m, safety=1.0)
    assert np.isclose(dt, 2 / max_frequency(model, m, model.initial()))
    D = basis.get_dofs("left").flatten()
    with pytest.raises(ValueError, match=r"dt = .* is above the stable "
                                         r"step 2/omega_max = "):
        central_difference(model, m, 400 * dt, D=D, dt=1.1 * dt,
                           u0=first_mode(basis, L), verbose=False)
    with pytest.raises(DynamicsError, match="energy balance error"):
        central_difference(model, m, 400 * dt, D=D, u0=first_mode(basis, L),
                           verbose=False, safety=1.0, max_energy_error=1e-9)
    central_difference(model, m, 400 * dt, D=D, dt=0.99 * dt,
                       u0=first_mode(basis, L), verbose=False)


def test_conditionally_stable_newmark_refuses_a_step_above_its_limit():
    """Issue 47: Newmark with beta < gamma/2 (linear acceleration, beta =
    1/6) is stable for omega_max dt <= 1/sqrt(gamma/2 - beta) = 3.46; at
    3 x 2/omega_max it returned a run whose own energy record was 147 %
    off, without a word.  Refused now where dt enters, with the limit
    named; below the limit it runs with its energy balanced."""
    L = 10.0
    basis = basis_of(bar(L), "PG")
    model = Hyperelastic(basis, ELASTIC)
    m = lumped_mass(basis, RHO)
    D = basis.get_dofs("left").flatten()
    w = max_frequency(model, m, model.initial())
    limit = np.sqrt(12.0) / w
    u0 = first_mode(basis, L)
    with pytest.raises(ValueError, match=r"above the stability limit .* "
                                         r"beta = 0.1667 < gamma/2"):
        newmark(model, m, 40 * limit, 1.05 * limit, D=D, u0=u0,
                beta=1 / 6, verbose=False)
    tr = newmark(model, m, 40 * limit, 0.95 * limit, D=D, u0=u0,
                 beta=1 / 6, verbose=False)
    assert np.abs(tr.series("relative_error")).max() < 1e-2
    newmark(model, m, 4 * limit, 5 * limit, D=D, u0=u0, verbose=False)


def test_explicit_refuses_global_mixed_fields():
    mesh = bar()
    basis = pg.FamilyBasis(pg.Particles.from_mesh(mesh), dim=2,
                           shape="WTE2")
    model = model_for("U2P1C", basis, NeoHookeIsoVol(mu=40.0, K=100.0))
    with pytest.raises(ValueError, match="newmark"):
        central_difference(model, lumped_mass(basis, 1.0), 1.0,
                           verbose=False)


@pytest.mark.parametrize("method", ["explicit", "newmark"])
def test_plastic_impact_dissipates_and_commits(method):
    """A J2 bar hitting the wall hard: plastic strain accumulates (the
    history is committed per step), the dissipation is positive and the
    balance still closes."""
    L = 10.0
    basis = basis_of(bar(L, nx=20), "PG")
    material = J2Plasticity.from_young(E, 0.3, sigma_y0=0.5, H=1.0)
    model = Hyperelastic(basis, material)
    m = lumped_mass(basis, RHO)
    V = 0.05 * C
    v0 = np.where(np.arange(basis.N) % 2 == 0, -V, 0.0)
    kw = dict(v0=v0, wall=RigidWall(0, 0.0), verbose=False)
    if method == "explicit":
        tr = central_difference(model, m, L / C, **kw)
    else:
        tr = newmark(model, m, L / C, L / C / 40, **kw)
    ep = model.plastic_strain()
    assert ep[1] > 1e-3
    last = tr.history[-1]
    assert last["dissipation"] > 0.01 * last["kinetic"]
    assert abs(last["relative_error"]) < 1e-2


def test_compression_since_bounds_the_shortening():
    """A point compressed to 0.8 of its length since the estimate: the
    bound is at least 1/0.8 (the factor the highest frequency can grow
    by); an unchanged configuration gives 1."""
    from skfem_pg.solvers.explicit import compression_since
    F0 = np.broadcast_to(np.eye(3)[:, :, None, None], (3, 3, 1, 5)).copy()
    assert compression_since(F0, F0) == 1.0
    F1 = F0.copy()
    F1[0, 0, 0, 2] = 0.8
    r = compression_since(F0, F1)
    assert 1.25 - 1e-12 <= r <= 1.25 + 1e-12
    assert compression_since(None, F1) == 1.0


def test_explicit_updated_lagrange_follows_total_lagrange():
    """The clamped-free bar in UL (rebuilt every 20 steps) swings like
    TL: the tip history agrees to 2e-4 of its amplitude (measured
    1.7e-5)."""
    from skfem_pg.formulations import UpdatedLagrange
    L = 10.0
    basis = basis_of(bar(L), "PG")
    m = lumped_mass(basis, RHO)
    D = basis.get_dofs("left").flatten()
    u0 = first_mode(basis, L, amplitude=0.05)
    tip = np.flatnonzero(np.isclose(basis.doflocs[0], L)
                         & (np.arange(basis.N) % 2 == 0))
    out = {}
    for name, model in (("TL", Hyperelastic(basis, ELASTIC)),
                        ("UL", UpdatedLagrange(basis, ELASTIC, every=20))):
        us = []
        central_difference(model, m, 4 * L / C, D=D, u0=u0, dt=0.015,
                           output_every=10, verbose=False,
                           callback=lambda t, x, v, r: us.append(x[tip]
                                                                 .mean()))
        out[name] = np.array(us)
    assert model.updates > 5
    assert np.abs(out["UL"] - out["TL"]).max() < 2e-4 * 0.05  # 1.7e-5


def test_lanczos_estimate_equals_the_dense_eigenvalue():
    """The stable-step estimate (Lanczos, full reorthogonalization) against
    the dense largest eigenvalue of M^-1/2 K M^-1/2, cold and warm
    started (from a Ritz vector, as central_difference does)."""
    from skfem_pg.solvers.explicit import lanczos_max
    from skfem_pg.solvers.exchange import SerialExchange
    rng = np.random.default_rng(3)
    A = rng.standard_normal((300, 300))
    A = A @ A.T + np.diag(np.linspace(0, 50, 300))
    lam = np.linalg.eigvalsh(A)[-1]
    ex = SerialExchange(300)
    th, ritz, its = lanczos_max(lambda x: A @ x, ex.start_vector(), ex,
                                tol=1e-6)
    assert abs(th - lam) <= 1e-9 * lam
    th2, _, its2 = lanczos_max(lambda x: A @ x, ritz + 0.1 * ex.start_vector()
                               / 17.3, ex, tol=1e-6)
    assert abs(th2 - lam) <= 1e-9 * lam and its2 < its
    with pytest.raises(RuntimeError, match="did not converge"):
        lanczos_max(lambda x: A @ x, ex.start_vector(), ex, tol=1e-14,
                    maxiter=3)


@pytest.mark.parametrize("formulation", ["Unl", "U1SIG"])
def test_matrix_free_estimate_equals_the_assembled_one(formulation):
    """The stable-step estimate from internal-force differences against
    the one of the assembled elastic tangent, on a deformed and plastic
    plate (measured 8e-8 Unl, 1.9e-7 U1SIG relative); U1SIG takes it by
    default (its force is the cheap one); a Petrov–Galerkin model refuses
    it."""
    from skfem_pg.formulations import model_for
    from skfem_pg.materials import J2Plasticity
    from skfem_pg.solvers.explicit import max_frequency
    mesh = pg.meshing.distort(fem.MeshQuad.init_tensor(
        np.linspace(0, 1, 9), np.linspace(0, 2, 17)), 0.2, seed=5)
    basis = pg.FamilyBasis(mesh, dim=2)
    model = model_for(formulation, basis, J2Plasticity.from_young(
                                                       1e3, 0.3, 5.0))
    x = 0.003 * np.random.default_rng(1).standard_normal(basis.N)
    x += 0.1 * basis.doflocs[1] * (np.arange(basis.N) % 2)  # 10 % stretch
    model.commit(model.state(x))  # plastic history
    assert model.plastic_strain()[1] > 0
    m = pg.lumped_mass(basis, 1.0)
    w_k = max_frequency(model, m, x, matrix_free=False)
    w_f = max_frequency(model, m, x, matrix_free=True)
    assert abs(w_f - w_k) <= 1e-5 * w_k
    assert getattr(model, "matrix_free_estimate", False) == (
        formulation == "U1SIG")
    ppg = Hyperelastic(pg.FamilyBasis(mesh, dim=2, method="PPG1"),
                       J2Plasticity.from_young(1e3, 0.3, 5.0))
    with pytest.raises(ValueError, match="Petrov"):
        max_frequency(ppg, m, np.zeros(basis.N), matrix_free=True)
