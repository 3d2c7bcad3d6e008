"""Johnson–Cook hardening and ductile damage at single points (issue 31,
thesis 8.1): the hardening law in the return map, damage against its
closed form at fixed triaxiality, failure at Dc, the damage-free limit and
what a failed point carries."""
import numpy as np
import pytest

from skfem_pg.materials import (J2Plasticity, JohnsonCookDamage,
                                JohnsonCookHardening)

#: thesis 8.1 (Broumand & Khoei 2015), N, mm
E, NU = 200e3, 0.29
JC = JohnsonCookHardening(792.0, 510.0, 0.26)
JC_DAMAGE = JohnsonCookDamage(0.05, 3.44, -2.12, 0.3)


def stretch(lam, J=1.0):
    """Uniaxial isochoric stretch ``lam`` at volume ratio ``J``, one point
    ``(3, 3, 1)``."""
    s = np.cbrt(J)
    return np.diag([s * lam, s / np.sqrt(lam), s / np.sqrt(lam)])[:, :, None]


def walk(material, Fs):
    """Responses along the path ``Fs``, committing every step."""
    h = material.initial_history((1,))
    out = []
    for F in Fs:
        r = material.update(F, h)
        h = r.history
        out.append(r)
    return out


def fd_tangent(material, F, h, eps=1e-7):
    """Central differences of the stress update from the history ``h``
    at ``F`` ``(3, 3, 1)``."""
    A = np.zeros((3, 3, 3, 3, 1))
    for k in range(3):
        for L in range(3):
            dF = np.zeros_like(F)
            dF[k, L] = eps
            A[:, :, k, L] = (material.update(F + dF, h).P
                             - material.update(F - dF, h).P) / (2 * eps)
    return A


def von_mises(P, F):
    """σ_vM of the Kirchhoff stress P F^T at one point."""
    tau = P[:, :, 0] @ F[:, :, 0].T
    dev = tau - np.trace(tau) / 3 * np.eye(3)
    return np.sqrt(1.5 * np.sum(dev * dev))


def test_johnson_cook_flow_stress_in_the_return_map():
    """On a uniaxial path the von Mises stress after the return equals
    A + B ē_p^n (to the local Newton's tolerance), and the algorithmic
    tangent is the derivative of the stress update."""
    steel = J2Plasticity.from_young(E, NU, hardening=JC)
    Fs = [stretch(lam) for lam in np.linspace(1.002, 1.2, 12)]
    for F, r in zip(Fs, walk(steel, Fs)):
        a = r.history["alpha"][0]
        if a > 0:
            assert abs(von_mises(r.P, F) / JC.stress(a) - 1) < 1e-10
    assert walk(steel, Fs)[-1].history["alpha"][0] > 0.15
    # tangent by central differences of the update from a plastic state
    h = walk(steel, Fs[:6])[-1].history
    rng = np.random.default_rng(0)
    F = Fs[6] + 0.01 * rng.uniform(-1, 1, (3, 3, 1))
    A = steel.update(F, h).tangent()
    assert np.abs(A - fd_tangent(steel, F, h)).max() <= 1e-6 * np.abs(A).max()


def test_damage_at_fixed_triaxiality_is_the_closed_form():
    """Perfect plasticity (B = 0) stretched isochorically at a fixed
    volume ratio J: σ_vM = A and the pressure K(J² - 1)/2 stay fixed, so
    the triaxiality σ* = K(J² - 1)/(2A) is constant and the damage is
    exactly ē_p / ε_f(σ*) step after step; the point fails in the step
    where that reaches Dc, releases the energy it stored less half the
    work of its stress over that step (the drivers' trapezoid books
    only the step's start, where it still carried stress: issue 51; on
    these large plastic steps that half is 71 % of the stored energy),
    and carries nothing from then on (J > 1: no tension)."""
    A = 792.0
    plastic = J2Plasticity.from_young(E, NU, hardening=JohnsonCookHardening(
        A, 0.0, 1.0), damage=JC_DAMAGE)
    J = 1.003
    triax = plastic.K * (J ** 2 - 1) / (2 * A)
    ef = JC_DAMAGE.failure_strain(triax)
    assert 0.5 < triax < 1.5 and 0.3 < ef < 1.5
    Fs = [stretch(lam, J) for lam in np.linspace(1.0, 1.5, 101)]
    rs = walk(plastic, Fs)
    alpha = np.array([r.history["alpha"][0] for r in rs])
    D = np.array([r.history["damage"][0] for r in rs])
    failed = np.array([r.failed[0] for r in rs])
    assert failed.any() and not failed[0]
    first = np.argmax(failed)
    ok = slice(0, first + 1)
    assert np.abs(D[ok] - alpha[ok] / ef).max() <= 1e-12
    assert D[first - 1] < JC_DAMAGE.Dc <= D[first]
    # the energy it released is what it would have stored intact (the
    # plain law's, the same path up to there)
    intact = J2Plasticity.from_young(E, NU, hardening=plastic.hardening)
    end = walk(intact, Fs[:first + 1])[-1]
    W = end.energy()[0]
    half_work = 0.5 * np.sum(end.P[..., 0] * (Fs[first] - Fs[first - 1])[
        ..., 0])
    released = [r.history["released"][0] for r in rs]
    assert released[first - 1] == 0 and W > half_work > 0
    assert abs(released[first] / (W - half_work) - 1) < 1e-12
    assert np.all(np.array(released[first:]) == released[first])
    # after failure: no plastic flow, no stress in tension
    assert np.all(alpha[first:] == alpha[first])
    assert all(np.all(r.P == 0) for r in rs[first:])
    assert all(r.energy()[0] == 0 for r in rs[first:])


def test_damage_under_hardening_converges_to_the_integral():
    """With hardening the triaxiality falls as σ_y grows; the damage the
    steps sum (each with its end-of-step triaxiality) converges at first
    order to ∫ dē_p / ε_f(p / σ_y(ē_p))."""
    steel = J2Plasticity.from_young(
        E, NU, hardening=JC, damage=JohnsonCookDamage(0.05, 3.44, -2.12, 1.0))
    J, lam = 1.002, 1.1
    p = steel.K * (J ** 2 - 1) / 2
    errors = []
    for steps in (20, 40, 80):
        r = walk(steel, [stretch(x, J) for x in
                         np.linspace(1.0, lam, steps + 1)])[-1]
        a_end, D = r.history["alpha"][0], r.history["damage"][0]
        # the exact integral up to the same plastic strain
        a = np.linspace(0, a_end, 20001)[1:]
        g = 1 / JC_DAMAGE.failure_strain(p / JC.stress(a))
        exact = np.sum(0.5 * (g[1:] + g[:-1]) * np.diff(a)) + a[0] * g[0]
        errors.append(abs(D / exact - 1))
    assert errors[0] < 0.05
    assert errors[1] < 0.6 * errors[0] and errors[2] < 0.6 * errors[1]


def test_the_damage_free_limit_is_the_plain_law():
    """A damage law that does not fail the point (Dc = 1 with a large
    failure strain) changes nothing: stresses, tangents and history equal
    the plain J2 law's bitwise."""
    plain = J2Plasticity.from_young(E, NU, hardening=JC)
    damaged = J2Plasticity.from_young(E, NU, hardening=JC,
                                      damage=JohnsonCookDamage(1e6, 0, 0, 1))
    rng = np.random.default_rng(1)
    F = np.eye(3)[:, :, None] + 0.05 * rng.uniform(-1, 1, (3, 3, 40))
    hp, hd = plain.initial_history((40,)), damaged.initial_history((40,))
    for step in range(1, 4):
        rp, rd = plain.update(step * (F - np.eye(3)[:, :, None]) / 3
                              + np.eye(3)[:, :, None], hp), \
            damaged.update(step * (F - np.eye(3)[:, :, None]) / 3
                           + np.eye(3)[:, :, None], hd)
        assert rp.plastic.any()
        assert np.array_equal(rp.P, rd.P)
        assert np.array_equal(rp.tangent(), rd.tangent())
        assert np.array_equal(rp.energy(), rd.energy())
        for k in rp.history:
            assert np.array_equal(rp.history[k], rd.history[k])
        assert not rd.history["released"].any()
        hp, hd = rp.history, rd.history
        assert np.all(rd.history["damage"] < 1e-5) and not rd.failed.any()


def test_a_failed_point_carries_pressure_in_compression_only():
    """A failed point under compression (J < 1) carries the volumetric
    Kirchhoff stress K(J² - 1)/2 I and nothing deviatoric; its tangent is
    the derivative of that; under tension it carries nothing."""
    steel = J2Plasticity.from_young(E, NU, hardening=JC, damage=JC_DAMAGE)
    h = steel.initial_history((1,))
    h["damage"][:] = JC_DAMAGE.Dc  # failed
    F = stretch(1.05, 0.98) + 0.01 * np.array(
        [[0, 1, 0], [0, 0, 0.5], [0.2, 0, 0]])[:, :, None]
    r = steel.update(F, h)
    Jn = np.linalg.det(F[:, :, 0])
    tau = r.P[:, :, 0] @ F[:, :, 0].T
    assert Jn < 1 and r.failed[0]
    assert np.abs(tau - steel.K / 2 * (Jn ** 2 - 1) * np.eye(3)).max() \
        <= 1e-9 * steel.K * (1 - Jn)
    A = r.tangent()
    assert np.abs(A - fd_tangent(steel, F, h)).max() <= 1e-6 * np.abs(A).max()
    tension = steel.update(stretch(1.05, 1.01), h)
    assert np.all(tension.P == 0) and np.all(tension.tangent() == 0)


def test_laws_refuse_what_they_cannot_do():
    """Named errors: a JC exponent outside [0.03, 1], Dc outside (0, 1],
    both hardening descriptions at once, damage on the mixed
    formulations' isochoric part."""
    with pytest.raises(ValueError, match="exponent n"):
        JohnsonCookHardening(792.0, 510.0, 1.5)
    with pytest.raises(ValueError, match="Dc"):
        JohnsonCookDamage(0.05, 3.44, -2.12, 0.0)
    with pytest.raises(TypeError, match="either"):
        J2Plasticity(mu=1.0, K=1.0, sigma_y0=0.5, hardening=JC)
    with pytest.raises(TypeError, match="not a damage law"):
        J2Plasticity(mu=1.0, K=1.0, sigma_y0=0.5, damage=JC)
    with pytest.raises(NotImplementedError, match="UnlP0"):
        J2Plasticity(mu=1.0, K=1.0, sigma_y0=0.5, damage=JC_DAMAGE).isochoric()


def test_the_docstring_examples_run():
    """The examples in the laws' docstrings are what the code gives."""
    import doctest

    from skfem_pg.materials import damage, hardening, plasticity
    for module in (damage, hardening, plasticity):
        result = doctest.testmod(module, optionflags=doctest.ELLIPSIS)
        assert result.attempted > 0 and result.failed == 0, module


def test_first_yield_under_power_law_hardening_converges():
    """The first yield of a point under A + B ē_p^n is an increment of
    ((σ_vM - A)/B)^(1/n): 2e-13 for the thesis' steel a quarter MPa above
    A.  The return map converges there (its slope is not floored above
    such increments) and on 2000 random trial states from the
    virgin state."""
    steel = J2Plasticity.from_young(E, NU, hardening=JC)
    x, da, *_ = steel.return_map(np.array([[-0.00049402, 0., 0.00994686]]),
                                 np.zeros(1))
    assert 1e-13 < da[0] < 1e-12
    rng = np.random.default_rng(2)
    F = np.eye(3)[:, :, None] + 0.0025 * rng.normal(size=(3, 3, 2000))
    r = steel.update(F, steel.initial_history((2000,)))
    a = r.history["alpha"]
    assert r.plastic.sum() > 500 and a[r.plastic].min() < 1e-9
    tau = np.einsum("ijn,kjn->nik", r.P, F)
    dev = tau - np.einsum("nii->n", tau)[:, None, None] / 3 * np.eye(3)
    vm = np.sqrt(1.5 * np.sum(dev * dev, axis=(1, 2)))
    assert np.abs(vm[r.plastic] / JC.stress(a[r.plastic]) - 1).max() < 1e-9


def test_formulations_carry_damage_and_the_mixed_ones_refuse_it():
    """Unl keeps damage at every family member and reports the failed
    ones; U1SIG at the masters, and a failed master loses its
    stabilization too (its moduli are zero, the others' untouched); PPG
    UnlP0 and IUnlP0, which carry the pressure at the master or as an
    unknown, refuse a damage law by name."""
    import skfem as fem

    import skfem_pg as pg
    from skfem_pg.formulations import model_for
    mesh = fem.MeshQuad.init_tensor(*(np.linspace(0, 1, 5),) * 2)
    basis = pg.FamilyBasis(mesh, dim=2)
    steel = J2Plasticity.from_young(E, NU, hardening=JC, damage=JC_DAMAGE)
    unl = model_for("Unl", basis, steel)
    unl.internal_force(unl.state(np.zeros(basis.N)))
    failed = unl.failed()
    assert failed.shape == unl.history.committed["alpha"].shape
    assert not failed.any() and unl.fracture_energy() == 0.0
    u1sig = model_for("U1SIG", basis, steel)
    u1sig.internal_force(u1sig.state(np.zeros(basis.N)))
    mu, K = u1sig.frozen()[:2]
    u1sig.history.committed = dict(u1sig.history.committed)
    u1sig.history.committed["damage"] = np.where(
        np.arange(mu.size) == 3, JC_DAMAGE.Dc, 0.0)
    mu_f, K_f = u1sig.frozen()[:2]
    assert mu_f[3] == 0 and K_f[3] == 0
    assert np.array_equal(np.delete(mu_f, 3), np.delete(mu, 3))
    # the mixed formulations that carry the pressure elsewhere refuse
    ppg = pg.FamilyBasis(mesh, dim=2, method="PPG1")
    with pytest.raises(NotImplementedError, match="MeanDilatation"):
        model_for("UnlP0", ppg, steel)
    incompressible = J2Plasticity(mu=steel.mu, K=np.inf, hardening=JC,
                                  damage=JC_DAMAGE)
    with pytest.raises(NotImplementedError, match="MeanDilatation"):
        model_for("IUnlP0", basis, incompressible)


def test_the_critical_strain_criterion_fails_at_its_strain():
    """CriticalStrainDamage on an elastic J2 point (a yield stress the
    path does not reach): a uniaxial stretch just below exp(e_c) leaves
    the point intact, just above fails it, for good; compression does
    not; the crack-band strain sqrt(2 G0 / (E h))."""
    from skfem_pg.materials import CriticalStrainDamage
    law = CriticalStrainDamage(0.01)
    m = J2Plasticity.from_young(E, NU, 1e9, damage=law)
    F = lambda lam: np.diag([lam, 1.0, 1.0])[:, :, None]  # noqa: E731
    lam_c = np.exp(0.01)
    below = walk(m, [F(1 + 0.5 * (lam_c - 1)), F(lam_c * (1 - 1e-9))])
    assert not below[-1].failed.any()
    assert below[-1].history["damage"][0] == pytest.approx(1.0, abs=1e-7)
    after = walk(m, [F(lam_c * (1 + 1e-9)), F(1.0)])
    assert after[0].failed.all() and after[1].failed.all()
    assert np.abs(after[1].P).max() == 0.0  # failed, unloaded
    assert not walk(m, [F(0.97)])[0].failed.any()
    assert CriticalStrainDamage.from_fracture_energy(
        22.17, 190e3, 1.0).critical_strain == pytest.approx(
            np.sqrt(2 * 22.17 / 190e3))
    with pytest.raises(ValueError, match="positive"):
        CriticalStrainDamage(0.0)


def test_the_critical_stress_criterion_fails_at_its_stress():
    """CriticalStressDamage on an elastic J2 point: a uniaxial stretch
    whose largest Cauchy stress is just below the strength leaves the
    point intact (damage 1 to round-off), just above fails it; a
    compression across a free direction, whose Poisson strain fails the
    strain criterion of the same uniaxial strength, leaves it intact; a
    mixed formulation's mean stress is the one it takes; the crack-band
    strength sqrt(2 G0 E / h)."""
    from skfem_pg.materials import CriticalStrainDamage, CriticalStressDamage
    f_t = 1000.0
    law = CriticalStressDamage(f_t)
    m = J2Plasticity.from_young(E, NU, 1e9, damage=law)
    plain = J2Plasticity.from_young(E, NU, 1e9)
    F = lambda a, b=1.0: np.diag([a, b, 1.0])[:, :, None]  # noqa: E731

    def cauchy_xx(a):  # (P F^T / J)_xx = P_xx for F = diag(a, 1, 1)
        return plain.stress(F(a))[0, 0, 0]
    lo, hi = 1.0, 1.02  # the stretch at the strength, by bisection
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if cauchy_xx(mid) < f_t else (lo, mid)
    below = walk(m, [F(1 + 0.5 * (lo - 1)), F(lo * (1 - 1e-9))])
    assert not below[-1].failed.any()
    assert below[-1].history["damage"][0] == pytest.approx(1.0, abs=1e-6)
    after = walk(m, [F(hi * (1 + 1e-9)), F(1.0)])
    assert after[0].failed.all() and after[1].failed.all()
    # compressed along y, free along x: a tensile strain, no tensile stress
    a = 1.0
    for _ in range(60):  # the stretch along x at which sigma_xx = 0
        a -= plain.stress(F(a, 0.98))[0, 0, 0] / (E / (1 - NU ** 2))
    assert abs(plain.stress(F(a, 0.98))[0, 0, 0]) < 1e-6
    strain_law = CriticalStrainDamage(f_t / (E / (1 - NU ** 2)))
    by_strain = J2Plasticity.from_young(E, NU, 1e9, damage=strain_law)
    assert walk(by_strain, [F(a, 0.98)])[0].failed.all()
    assert not walk(m, [F(a, 0.98)])[0].failed.any()
    # a mixed formulation's mean stress (Kirchhoff) decides instead
    h0 = m.initial_history((1,))
    r = m.update(F(1.0), h0, mean_stress=np.array([1.01 * f_t]))
    assert r.failed.all()
    assert CriticalStressDamage.from_fracture_energy(
        22.17, 190e3, 1.0).strength == pytest.approx(
            np.sqrt(2 * 22.17 * 190e3))
    with pytest.raises(ValueError, match="positive"):
        CriticalStressDamage(-1.0)


@pytest.mark.parametrize("element", ["Q1P0", "UnlP0"])
def test_mean_dilatation_carries_damage_as_the_displacement_law(element):
    """Q1P0 (and PBG UnlP0) under a homogeneous stretch in plane strain:
    the element pressure K/2 (Theta - 1/Theta) times J is the law's own
    mean stress, so the damage and the failure step are the displacement
    formulation's (Q1 / Unl) to round-off; once every point has failed,
    the element carries no tension (its volumetric stress vanishes in
    expansion) and keeps its pressure in compression."""
    import skfem as fem

    import skfem_pg as pg
    from skfem_pg.formulations import model_for
    mesh = fem.MeshQuad.init_tensor(*(np.linspace(0, 1, 3),) * 2)
    if element == "Q1P0":
        basis = fem.Basis(mesh, fem.ElementVector(fem.ElementQuad1()))
        plain = "Q1"
    else:
        basis = pg.FamilyBasis(mesh, dim=2)
        plain = "Unl"
    steel = J2Plasticity.from_young(E, NU, hardening=JC, damage=JC_DAMAGE)
    mixed, disp = model_for(element, basis, steel), model_for(plain, basis,
                                                               steel)
    X = basis.doflocs
    comp = np.arange(basis.N) % 2

    def affine(F):
        return np.einsum("ij,jn->in", F - np.eye(2), X)[comp,
                                                       np.arange(basis.N)]
    fail_step = {}
    for step, lam in enumerate(np.linspace(1.01, 1.6, 40)):
        u = affine(np.diag([lam, 1.0 / lam ** 0.3]))
        sm, sd = mixed.state(u), disp.state(u)
        Dm = mixed.history.response(sm["F"]).history["damage"]
        Dd = disp.history.response(sd["F"]).history["damage"]
        assert np.abs(Dm - Dd).max() <= 1e-10 * max(1.0, Dd.max())
        for name, m, s_ in (("mixed", mixed, sm), ("disp", disp, sd)):
            m.commit(s_)
            if m.failed().all() and name not in fail_step:
                fail_step[name] = step
    assert fail_step["mixed"] == fail_step["disp"]
    # failed everywhere: no stress in expansion, pressure in compression
    for F, carries in ((np.diag([1.65, 0.9]), False),
                       (np.diag([0.95, 0.95]), True)):
        P = mixed.stress(mixed.state(affine(F)))
        assert (np.abs(P).max() > 1.0) == carries


def test_johnson_cook_failure_strain_is_never_nan_or_everywhere_zero():
    """Issue 47: D2 = 0 with a steep D3 gave 0 * inf = NaN failure strains
    in compression (the points failed at their first plastic step); D1 <=
    0 with D2 = 0 failed every yielding point at once.  A steep D3 with
    D2 > 0 saturates (no failure in deep compression)."""
    from skfem_pg.materials import JohnsonCookDamage
    t = np.array([-5.0, -1.0, 0.0, 1.0 / 3.0, 2.0])
    flat = JohnsonCookDamage(0.3, 0.0, -300.0, 1.0)
    assert np.array_equal(flat.failure_strain(t), np.full(5, 0.3))
    assert np.all(np.isfinite(flat.increment(np.full(5, 0.01), t)))
    steep = JohnsonCookDamage(0.05, 3.44, -300.0, 1.0)
    ef = steep.failure_strain(t)
    assert not np.any(np.isnan(ef)) and ef[0] == np.inf
    assert steep.increment(np.full(5, 0.01), t)[0] == 0.0
    with pytest.raises(ValueError, match="D2 = 0 .* D1 <= 0"):
        JohnsonCookDamage(-0.1, 0.0, -2.0, 1.0)
    JohnsonCookDamage(-0.09, 0.27, 0.48, 1.0)  # D1 < 0 with D2 > 0 fits
