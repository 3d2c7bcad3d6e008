"""The updated Lagrangian frame: an identity update reproduces TL to
round-off, a homogeneous deformation is carried exactly through a rebuild
(VC keeps the forces of constant stress exact), the history survives the
rebuild, and a dynamic run in UL follows TL."""
import numpy as np
import pytest
import skfem as fem

import skfem_pg as pg
from skfem_pg.formulations import Hyperelastic, UpdatedLagrange
from skfem_pg.formulations.updated_lagrange import remap_points
from skfem_pg.materials import J2Plasticity, NeoHooke
from skfem_pg.naming import frame_of
from skfem_pg.solvers import lumped_mass, newmark

MATERIALS = {"neo-Hooke": NeoHooke(lam=100.0, mu=40.0),
             "J2": J2Plasticity.from_young(100.0, 0.3, 0.5, H=1.0)}


def mesh():
    return pg.meshing.distort(fem.MeshQuad.init_tensor(
        np.linspace(0, 2, 9), np.linspace(0, 1, 5)), 0.2)


def affine(basis, F):
    """Nodal displacements of the homogeneous deformation ``F``."""
    X = basis.doflocs
    d = X.shape[0]
    comp = np.arange(basis.N) % d
    return np.einsum("ij,jn->in", F - np.eye(d), X)[comp, np.arange(basis.N)]


@pytest.mark.parametrize("name", MATERIALS)
def test_identity_update_reproduces_tl(name):
    b = pg.FamilyBasis(pg.Particles.from_mesh(mesh()), dim=2)
    tl, ul = Hyperelastic(b, MATERIALS[name]), UpdatedLagrange(
        b, MATERIALS[name])
    ul.rebuild(np.zeros(b.N))
    u = np.random.default_rng(0).normal(size=b.N) * 1e-2
    st, su = tl.state(u), ul.state(u)
    ft, fu = tl.internal_force(st), ul.internal_force(su)
    Kt, Ku = tl.tangent(st).toarray(), ul.tangent(su).toarray()
    assert ul.updates == 1 and ul.current is not b
    assert np.abs(fu - ft).max() <= 1e-12 * np.abs(ft).max()
    assert np.abs(Ku - Kt).max() <= 1e-12 * np.abs(Kt).max()


@pytest.mark.parametrize("name", MATERIALS)
def test_rebuild_carries_a_homogeneous_state_and_the_history(name):
    """Commit a homogeneous (for J2: plastic) state, rebuild at it, load
    further: the forces equal TL's to round-off and the plastic strain
    carried over."""
    b = pg.FamilyBasis(pg.Particles.from_mesh(mesh()), dim=2)
    tl, ul = Hyperelastic(b, MATERIALS[name]), UpdatedLagrange(
        b, MATERIALS[name])
    F0 = np.array([[1.02, 0.01], [0.005, 0.99]])
    u0 = affine(b, F0)
    for m in (tl, ul):
        m.commit(m.state(u0))
    assert ul.updates == 1  # every = 1: rebuilt at u0
    assert not np.allclose(ul.current.G, b.G)
    u1 = affine(b, np.array([[1.05, 0.02], [0.0, 0.97]]) @ F0)
    ft = tl.internal_force(tl.state(u1))
    fu = ul.internal_force(ul.state(u1))
    assert np.abs(fu - ft).max() <= 1e-12 * np.abs(ft).max()
    if name == "J2":
        ep_t, ep_u = tl.plastic_strain()[1], ul.plastic_strain()[1]
        assert ep_t > 1e-3 and abs(ep_u - ep_t) <= 1e-14


def test_remap_takes_the_master_or_the_member_for_new_pairs():
    """A new (family, member) pair takes the family master's point, or
    with ``donor="member"`` the point at its own particle."""
    p = pg.Particles.from_mesh(mesh())
    old = pg.FamilyBasis(p, dim=2)
    new = pg.FamilyBasis(p, dim=2, shape="WTE2", bond=False)
    keys_old = np.arange(old.layout.n_points, dtype=float)
    (out,) = remap_points(old, new, [keys_old[None]])
    fam = new.families
    n = p.n
    k = np.repeat(np.arange(len(fam.offsets) - 1), np.diff(fam.offsets))
    ko = np.repeat(np.arange(len(old.families.offsets) - 1),
                   np.diff(old.families.offsets)) * n + \
        np.asarray(old.families.members)
    kn = k * n + np.asarray(fam.members)
    lookup = dict(zip(ko.tolist(), keys_old.tolist()))
    want = [lookup.get(key, lookup[(key // n) * n + key // n])
            for key in kn.tolist()]
    assert np.array_equal(out[0], want)
    # donor="member" (a crack-aware carry): a new pair (k, j) takes the
    # point at its particle j, (j, j)
    (out,) = remap_points(old, new, [keys_old[None]], donor="member")
    want = [lookup.get(key, lookup[(key % n) * n + key % n])
            for key in kn.tolist()]
    assert not np.isin(kn, ko).all()  # there are new pairs
    assert np.array_equal(out[0], want)
    with pytest.raises(ValueError, match="donor"):
        remap_points(old, new, [keys_old[None]], donor="nearest")


def test_ul_by_name_and_dynamic_run_follows_tl():
    """A cantilever swinging under a tip load: UL (rebuilt every step)
    and TL agree to the discretization's difference (1 %) over a short
    Newmark run; UL through the thesis name."""
    assert frame_of("VCBCPBG V5m Unl UL") == "UL"
    assert frame_of("VCPBG Unl") == "TL" and frame_of("FEM Q1") == "TL"
    m = fem.MeshQuad.init_tensor(np.linspace(0, 10, 21),
                                 np.linspace(0, 1, 3)).with_boundaries(
        {"left": lambda x: np.isclose(x[0], 0.0),
         "right": lambda x: np.isclose(x[0], 10.0)})
    sc = pg.scenes.Scene("beam", m, NeoHooke(lam=100.0, mu=40.0),
                         clamped=["left"])
    tips = {}
    for frame in ("TL", "UL"):
        basis, model, _, D, _, _ = sc.setup("VCBCPBG V5m Unl " + frame)
        f = pg.traction(basis, "right", [0.0, -0.05])
        tip = basis.get_dofs("right").nodal["u^2"]
        tr = newmark(model, lumped_mass(basis, 1.0), 4.0, 0.2, f_ext=f,
                     D=D, verbose=False)
        tips[frame] = tr.x[tip].mean()
        if frame == "UL":
            assert isinstance(model, UpdatedLagrange)
            assert model.updates == tr.steps
    assert tips["TL"] < -0.05
    assert abs(tips["UL"] / tips["TL"] - 1) < 0.01


def test_a_rebuild_on_an_inverted_mesh_stops_the_run_with_its_time():
    """Cook's membrane hit hard (PBG UL): the collocation mesh inverts,
    the rebuild cannot collocate particles there, and Newmark stops with
    DynamicsError at that time (not a stray ParticleError)."""
    from skfem_pg.solvers import DynamicsError
    sc = pg.scenes.Scene("cook", pg.meshing.cook_membrane(4),
                         NeoHooke(lam=121.0, mu=80.8), clamped=["left"])
    basis, model, _, D, _, _ = sc.setup("PBG Unl UL noBC")
    f = pg.traction(basis, "right", [0.0, 1.0])
    with pytest.raises(DynamicsError, match="could not be committed") as e:
        newmark(model, lumped_mass(basis, 7.85), 20.0, 0.2,
                f_ext=lambda t: 200.0 * np.sin(np.pi * t / 10.0) * f, D=D,
                verbose=False, dt_min=0.05)
    assert 0 < e.value.t < 20.0 and model.updates > 0
