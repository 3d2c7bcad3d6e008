"""The energy a fracture releases, booked as the integrator books the work
of the step in which a point fails or a bond breaks (issue 51): a bond
breaking in one step (exact), a point failing in one step (to third order
in the step), a failed point closing across the kink of its pressure,
and the mode-I plate on unstructured triangles, where every joule the
internal forces did is stored, released or lost at the failed points'
closure (the material is elastic, its criterion brittle)."""
import numpy as np
import pytest
import skfem as fem

import skfem_pg as pg
from skfem_pg.formulations import CrackAware, model_for
from skfem_pg.formulations.bond_based import BondBased
from skfem_pg.solvers import DynamicsError
from skfem_pg.materials import (CriticalStrainDamage, J2Plasticity,
                                NonlocalStrainDamage)

#: N, mm, s: Kalthoff–Winkler's maraging steel (demos/kalthoff_winkler.py)
E, NU, G0, RHO = 190e3, 0.3, 22.17, 8e-9


def test_a_bond_breaking_in_a_step_releases_the_work_booked_on_it():
    """Bonds along a uniform stretch that grows linearly in time (the
    x-dofs prescribed, the bonds straight: their force is linear in the
    step, so the trapezoidal work is exact) break in one step: the
    internal work equals the released energy to round-off.  The bond
    energy at the step's end (the booking until this issue) left
    0.12 N mm of 44.5 unaccounted (2.7e-3)."""
    mesh = fem.MeshQuad.init_tensor(*(np.linspace(0, 1, 7),) * 2)
    basis = pg.FamilyBasis(mesh, dim=2)
    model = BondBased(basis, 200e3, G0=10.0, horizon=1.2)  # no diagonals
    x = basis.doflocs[0]
    rate = model.s0 / 0.73e-5  # the bonds break at t = 0.73e-5

    def u_D(t):
        u = np.zeros(basis.N)
        u[0::2] = rate * t * x[0::2]
        return u
    tr = pg.central_difference(model, pg.lumped_mass(basis, RHO), 1e-5,
                               D=np.arange(0, basis.N, 2), u_D=u_D, dt=2e-8,
                               verbose=False)
    last = tr.history[-1]
    horizontal = np.abs(model.xi[1]) < 1e-12
    assert not model.intact[horizontal].any() and model.intact[
        ~horizontal].all()
    assert last["stored"] == 0.0 and last["fracture"] > 40.0
    assert abs(last["other_dissipation"]) <= 1e-13 * last["internal_work"]


def test_a_point_failing_in_a_step_releases_the_work_booked_on_it():
    """A point stretched across the brittle criterion in one step of size
    δ: the energy it releases equals its energy at the step's start plus
    the trapezoid's half of its work over the step (what the driver
    books: the failed point carries no stress at the step's end), to
    third order in δ (measured: 2.0e-3, 2.5e-4, 3.1e-5, 3.9e-6 N/mm² for
    δ = 4, 2, 1, 0.5e-3 of a 13-14 N/mm² release).  The intact energy at
    the step's end (the booking until this issue) is half a step's work
    off, first order in δ."""
    steel = J2Plasticity.from_young(E, NU, 1e9,
                                    damage=CriticalStrainDamage(0.01))
    s_c = np.exp(0.01) - 1  # the stretch at which it fails

    def F(s):
        return np.array([[1 + s, 0.0], [0.0, 1.0]])[:, :, None]
    misses, half_steps = [], []
    for delta in (4e-3, 2e-3, 1e-3, 5e-4):
        s0 = s_c - 0.3 * delta
        r0 = steel.update(F(s0), steel.initial_history((1,)))
        r1 = steel.update(F(s0 + delta), r0.history)
        assert r1.failed.all() and not r0.failed.any()
        work = 0.5 * np.sum(r0.P[..., 0] * (F(s0 + delta) - F(s0))[..., 0])
        booked = r0.energy()[0] + work
        misses.append(r1.history["released"][0] - booked)
        half_steps.append(work)
    misses = np.abs(misses)
    assert np.all(misses[:-1] / misses[1:] > 7.0)  # third order
    assert np.all(misses < 1e-3 * np.array(half_steps))


def test_a_failed_point_closing_loses_what_the_trapezoid_books_more():
    """A failed point carries pressure in compression only: its stress
    has a kink at J = 1.  A step from J = 1 + a to 1 - b books K b (a + b)
    / 2 of work (the trapezoid) and stores K b^2 / 2: the closure energy
    is K a b / 2 to first order (measured here 1.7e-3 and 2.7e-4 off);
    a step in tension loses nothing, one in compression to third order
    in the step."""
    steel = J2Plasticity.from_young(E, NU, 1e9,
                                    damage=CriticalStrainDamage(0.01))
    K = steel.K

    def F(J):
        return np.array([[J, 0.0], [0.0, 1.0]])[:, :, None]
    failed = steel.update(F(1.05), steel.initial_history((1,)))
    assert failed.failed.all()

    def closure(J0, J1):
        r0 = steel.update(F(J0), failed.history)
        r1 = steel.update(F(J1), r0.history)
        return r1.history["closure"][0] - r0.history["closure"][0]
    for a, b in ((1e-3, 2e-3), (2e-3, 5e-4)):
        assert closure(1 + a, 1 - b) == pytest.approx(0.5 * K * a * b,
                                                      rel=3e-3)
    assert closure(1.002, 1.001) == 0.0
    small = [closure(0.99, 0.99 - d) for d in (2e-3, 1e-3)]
    assert 7.0 < small[0] / small[1] < 9.0  # third order


def slotted_plate(h):
    """The mode-I plate of ``meshes/plate_slot.geo`` on gmsh triangles of
    size ``h`` mm."""
    return pg.meshing.from_geo(pg.meshing.geo_path("plate_slot.geo"),
                               size=h)


def pull_apart(model, basis, t_end, grip=0.0, speed=5000.0):
    """Central differences with the stable step: the plate's grips (its
    top and bottom edges, or layers ``grip`` deep: a nonlocal model is
    held by a layer, not a row) pulled apart at ``speed`` mm/s each
    (5 m/s), sideways free."""
    X = basis.doflocs
    y = np.arange(basis.N) % 2 == 1
    top = np.flatnonzero(y & (X[1] > 40 - grip - 1e-9))
    bottom = np.flatnonzero(y & (X[1] < grip + 1e-9))

    def u_D(t):
        u = np.zeros(basis.N)
        u[top], u[bottom] = speed * t, -speed * t
        return u
    return pg.central_difference(
        model, pg.lumped_mass(basis, RHO), t_end,
        D=np.concatenate([top, bottom]), u_D=u_D, verbose=False)


@pytest.mark.parametrize("kind", ["kept", "crack-aware", "PMB"])
def test_the_mode_one_plate_on_triangles_books_every_joule(kind):
    """The 40 x 40 mm plate with a 12 mm slot on unstructured triangles
    (h = 4 mm, 194 particles), its grips pulled apart at 5 m/s for 60 µs:
    PG Unl (``VCBCPBG V5sn Unl``, elastic with the crack-band brittle
    criterion) with its connectivity kept and with crack-aware families,
    and the bond-based comparator (held by layers one horizon deep).  The
    cracks run; the internal work is the stored plus the released
    energy plus the closure (PG): measured (W_int − stored − released −
    closure) / W_int +2.8e-5 / +5.2e-5 / +1.1e-4, the closure 9.3e-4 and
    1.1e-3 of W_int (PG), the released energy 85, 75 and 94 % of W_int,
    the drivers' own balance 1.9e-3 / 4.0e-3 / 6.7e-3 (until this issue
    the first ratio was −0.14 for kept and +0.10 for PMB held by its edge
    rows, at h = 2 mm)."""
    h = 4.0
    mesh = slotted_plate(h)
    if kind == "PMB":
        basis = pg.FamilyBasis(mesh, dim=2)
        model = BondBased(basis, E, G0=G0, plane="strain")
    else:
        law = CriticalStrainDamage.from_fracture_energy(
            G0, E / (1 - NU ** 2), h)
        steel = J2Plasticity.from_young(E, NU, 1e9, damage=law)
        basis = pg.FamilyBasis.from_name(mesh, "VCBCPBG V5sn Unl", dim=2)
        model = CrackAware(basis, steel) if kind == "crack-aware" else \
            model_for("Unl", basis, steel)
    tr = pull_apart(model, basis, 6e-5, grip=getattr(model, "horizon", 0))
    last = tr.history[-1]
    assert last["fracture"] > 0.5 * last["internal_work"]  # it broke
    assert abs(last["other_dissipation"]) <= 1e-3 * last["internal_work"]
    assert abs(last["relative_error"]) <= 2e-2


def test_the_plate_with_the_nonlocal_criterion_books_the_closure():
    """The mode-I plate (h = 4 mm) pulled at 1 m/s for 300 µs, PG Unl with
    its connectivity kept and the nonlocal criterion (radius 4 mm): the
    failed band, several spacings wide, closes and opens, and the steps
    lose energy at the failed points' kink (``closure``).  Measured: the
    closure 5.2e-3 of W_int, and (W_int − stored − released − closure) /
    W_int 2.2e-5 (at h = 2 mm 1.2e-2 and 5.6e-5; the closure 3.8e-3 and
    9.2e-4 with the step halved and quartered, second order).  The
    drivers' balance takes the closure off the internal work: 3.2e-3,
    7.7e-3 with it (at h = 2 mm 6.7e-4 and 1.1e-2)."""
    h = 4.0
    mesh = slotted_plate(h)
    law = NonlocalStrainDamage.from_fracture_energy(G0, E, NU, 4.0)
    steel = J2Plasticity.from_young(E, NU, 1e9, damage=law)
    basis = pg.FamilyBasis.from_name(mesh, "VCBCPBG V5sn Unl", dim=2)
    model = model_for("Unl", basis, steel)
    tr = pull_apart(model, basis, 3e-4, speed=1000.0)
    last = tr.history[-1]
    w = last["internal_work"]
    assert last["fracture"] > 0.5 * w
    assert last["closure"] == pytest.approx(model.closure_energy())
    assert last["closure"] > 2e-3 * w
    assert abs(last["other_dissipation"]) <= 2e-4 * w
    scale = last["error"] / last["relative_error"]
    assert abs(last["relative_error"]) < 5e-3 < (
        last["error"] + last["closure"]) / scale


def test_a_fracture_run_whose_model_makes_energy_stops():
    """A model whose force is not the gradient of the energy it reports
    (here the energy reported 1.5 times too large) makes its other
    dissipation fall as it loads: the run stops with a DynamicsError
    naming it, instead of booking the difference as negative plastic
    dissipation (CrackAwareU1SIG's former stabilization on the two-hole
    plate: a fall of 17 % of the energy scale)."""
    mesh = slotted_plate(4.0)
    law = CriticalStrainDamage.from_fracture_energy(G0, E / (1 - NU ** 2),
                                                    4.0)
    steel = J2Plasticity.from_young(E, NU, 1e9, damage=law)
    basis = pg.FamilyBasis.from_name(mesh, "VCBCPBG V5sn Unl", dim=2)
    model = model_for("Unl", basis, steel)
    energy = model.energy
    model.energy = lambda state: 1.5 * energy(state)
    with pytest.raises(DynamicsError, match="makes energy") as err:
        pull_apart(model, basis, 6e-5)
    assert err.value.t < 6e-5 and err.value.history


def test_a_rebuild_is_followed_by_a_new_step_estimate(monkeypatch):
    """A model whose commit reports a changed discretization (crack-aware
    families rebuilt) gets its stable step estimated again before the
    next step, also where its points' count stays the same (the
    compression check's signal), and its released energy corrected by
    the driver (book_rebuild)."""
    from skfem_pg.formulations import Hyperelastic
    from skfem_pg.materials import NeoHookeIsoVol
    from skfem_pg.solvers import explicit
    basis = pg.FamilyBasis(fem.MeshQuad().refined(2), dim=2)

    class Rebuilt(Hyperelastic):
        commits, booked = 0, []

        def commit(self, state):
            self.commits += 1
            return self.commits == 3  # "rebuilt" once, same points

        def book_removed_work(self, work):
            self.booked.append(work)

    model = Rebuilt(basis, NeoHookeIsoVol(mu=1.0, K=5.0))
    estimates = []
    original = explicit.stable_time_step

    def counting(*args, **kw):
        estimates.append(1)
        return original(*args, **kw)
    monkeypatch.setattr(explicit, "stable_time_step", counting)
    left = basis.get_dofs(lambda x: x[0] == 0).all()

    def u_D(t):
        u = np.zeros(basis.N)
        u[left] = 0.01 * t
        return u
    tr = pg.central_difference(model, pg.lumped_mass(basis, 1.0), 1.0,
                               D=left, u_D=u_D, estimate_every=10 ** 6,
                               verbose=False)
    assert tr.steps > 5
    assert len(estimates) == 2  # the start and after the rebuild
    assert len(model.booked) == 1 and model.booked[0] == 0.0  # same force
