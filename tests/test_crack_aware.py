"""Crack-aware families (issue 31, item 2): the VC correction of a body in
pieces, the linear patch test of a cracked body, the update's bookkeeping,
a checkpoint across an update, and the notched strip against the thesis'
variant (connectivity kept)."""
import numpy as np
import pytest
import skfem as fem
from scipy.optimize import brentq

import skfem_pg as pg
from skfem_pg.errors import FamilyError
from skfem_pg.formulations import (CrackAware, CrackAwareU1SIG,
                                   CrackAwareUnlP0)
from skfem_pg.discretization.cracks import pieces, separate
from skfem_pg.materials import J2Plasticity, NeoHooke
from skfem_pg.solvers.checkpoint import Every

from test_fracture import STEEL, pull, strip


def shifted_grid(nx, ny, seed=0, amount=0.3, nz=None):
    """A unit-square quad grid (unit-cube hex grid with ``nz``) whose
    vertices are shifted in x only (the layers of constant y stay
    straight), the boundary's x kept."""
    lines = [np.linspace(0, 1, n + 1) for n in (nx, ny, nz) if n]
    m = (fem.MeshQuad if nz is None else fem.MeshHex).init_tensor(*lines)
    p = m.p.copy()
    inner = (p[0] > 1e-9) & (p[0] < 1 - 1e-9)
    p[0, inner] += amount / nx * np.random.default_rng(seed).uniform(
        -1, 1, inner.sum())
    return type(m)(p, m.t)


def row_of_cells(mesh, y):
    """The cells whose centre lies at height ``y`` (second coordinate)."""
    c = mesh.p[:, mesh.t].mean(axis=1)
    return np.abs(c[1] - y) < 1e-9


def vc_gradients(basis, particles):
    """Per particle: its family's VC-corrected derivatives, sorted by
    member (to compare bases whose numbering of members differs)."""
    fam = basis.families
    out = {}
    for g, G in zip(basis.layout, basis.grouped_gradients()):
        for r, f in enumerate(g.families):
            mem = np.asarray(g.members[r])
            o = np.argsort(mem)
            out[particles[fam.masters[f]]] = (mem[o], G[r][:, o])
    return out


@pytest.mark.parametrize("vc", ["V3", "V5"])
def test_vc_of_two_separate_bodies_is_each_body_alone(vc):
    """The VC system of a particle set in two pieces that no family
    connects is block diagonal; its minimum-norm solution is each piece's
    own.  The pinned LU pins each piece (before, it pinned one, and the
    other piece's derivatives grew up to 130x through the unpinned null
    space while the constraint residual stayed at round-off)."""
    a = pg.meshing.distort(fem.MeshTri.init_tensor(
        np.linspace(0, 1, 7), np.linspace(0, 1, 6)), 0.2, seed=1)
    b = pg.meshing.distort(fem.MeshTri.init_tensor(
        np.linspace(2, 3, 6), np.linspace(0, 1.5, 8)), 0.2, seed=2)
    both = fem.MeshTri(np.hstack([a.p, b.p]),
                       np.hstack([a.t, b.t + a.p.shape[1]]))
    Gab = vc_gradients(pg.FamilyBasis(both, dim=2, vc=vc),
                       np.arange(both.p.shape[1]))
    n = 0
    for m, off in ((a, 0), (b, a.p.shape[1])):
        alone = vc_gradients(pg.FamilyBasis(m, dim=2, vc=vc),
                             np.arange(m.p.shape[1]) + off)
        for k, (mem, G) in alone.items():
            mem_ab, G_ab = Gab[k]
            assert np.array_equal(mem_ab, mem + off)
            assert np.abs(G_ab - G).max() <= 1e-10 * np.abs(G).max()
            n += 1
    assert n == both.p.shape[1]


def uniaxial(material, stretch, dim):
    """``F = diag(stretch, s[, s])`` with :math:`P_{22} (= P_{33}) = 0`
    (no traction on faces normal to y; plane strain in 2-D)."""
    def P22(s):
        F = np.diag([stretch] + [s] * (dim - 1)).reshape(dim, dim, 1, 1)
        return material.stress(F)[1, 1, 0, 0]
    s = brentq(P22, 0.99, 1.0, xtol=1e-15)
    return np.diag([stretch] + [s] * (dim - 1))


def affine(basis, F):
    X = basis.doflocs
    d = X.shape[0]
    comp = np.arange(basis.N) % d
    return np.einsum("ij,jn->in", F - np.eye(d), X)[comp, np.arange(basis.N)]


@pytest.mark.parametrize("dim, vc, kind", [(2, "V5", "Unl"),
                                           (2, None, "Unl"),
                                           (3, "V5", "Unl"),
                                           (2, "V3", "U1SIG"),
                                           (2, "V5 local", "Unl"),
                                           (3, "V5 local", "Unl"),
                                           (2, "V3 local", "U1SIG")])
def test_a_cut_body_passes_the_linear_patch_test(dim, vc, kind):
    """Cells failed across a body (the crack: a layer of cells): after the
    update the families stop at the crack and the crack faces enter the
    VC correction.  A homogeneous deformation with no traction on the
    crack faces (uniaxial stress along the crack, J2 in its elastic range
    with the damage law) is the discrete solution with the outer boundary
    prescribed: the residual at the free particles — those on the crack
    faces among them — is round-off with VC (measured 1.2e-13 relative,
    2-D on 8 x 8 quads and 3-D on 4 x 4 x 4 hexahedra; U1SIG on its
    WTE1 V3 basis also 1.2e-13) and not without (0.13, 2-D); the local
    correction (``vc_solver="local"``) redone on the cut body too."""
    n = 8 if dim == 2 else 4
    mesh = shifted_grid(n, n, amount=0.5, nz=None if dim == 2 else n)
    kw = {}
    if vc is not None and vc.endswith(" local"):
        vc, kw = vc.split()[0], {"vc_solver": "local"}
    if kind == "U1SIG":
        basis = pg.FamilyBasis(mesh, dim=dim, shape="WTE1", bond=False,
                               vc=vc, **kw)
        model = CrackAwareU1SIG(basis, STEEL)
    else:
        basis = pg.FamilyBasis(mesh, dim=dim, vc=vc, **kw)
        model = CrackAware(basis, STEEL)
    crack = row_of_cells(mesh, (n // 2 + 0.5) / n)
    zero = np.zeros(basis.N)
    model.update(zero, model.state(zero)[model._gradient_key], crack)
    assert model.updates == 1 and (~model.intact).sum() == n ** (dim - 1)
    fam = model.point_basis.families
    above = mesh.p[1] > 0.5 + 1e-9
    k = np.repeat(fam.masters, fam.sizes)
    assert not np.any(above[k] != above[np.asarray(fam.members)])
    F = uniaxial(STEEL, 1.001, dim)
    u = affine(basis, F)
    f = model.internal_force(model.state(u))
    outer = basis.get_dofs().all()  # the mesh's boundary (no crack faces)
    free = np.setdiff1d(np.arange(basis.N), outer)
    active = np.repeat(model.point_basis.particles.active, dim)
    free = free[active[free]]
    scale = np.abs(f).max()
    err = np.abs(f[free]).max() / scale
    if vc is None:
        assert err > 1e-2
        return
    assert err <= 1e-10
    # and Newton from the undeformed interior finds the homogeneous field
    x, _ = pg.newton(model, D=outer, u_D=u, verbose=False)
    assert np.abs(x - u).max() <= 1e-10 * np.abs(u).max()


def test_the_update_carries_the_history_and_books_the_energy():
    """An update keeps the deformation continuous (semi-TL: F = F_c +
    G(u - u_c)), the committed history follows the surviving points, and
    the energy the removed points had stored is booked as released."""
    mesh = shifted_grid(6, 6)
    basis = pg.FamilyBasis(mesh, dim=2)
    model = CrackAware(basis, STEEL)
    u = 1e-5 * np.random.default_rng(3).normal(size=basis.N)  # elastic
    st = model.state(u)
    model.commit(st)
    stored = model.energy(st)
    model.update(u, np.array(st["F"]), row_of_cells(mesh, 2.5 / 6))
    after = model.state(u)
    # the surviving points keep their gradient exactly
    from skfem_pg.formulations.updated_lagrange import point_keys
    k_old, k_new = point_keys(basis), point_keys(model.current)
    common, i_old, i_new = np.intersect1d(k_old, k_new, return_indices=True)
    assert len(common) < len(k_old)
    F_old = np.asarray(st["F"]).reshape(4, -1)[:, i_old]
    F_new = np.asarray(after["F"]).reshape(4, -1)[:, i_new]
    assert np.abs(F_new - F_old).max() <= 1e-14
    a_old = model.history.committed["alpha"].ravel()
    assert a_old.shape == (len(k_new),)
    # stored before = stored after + released by the update
    assert model.released_at_updates > 0
    assert abs(stored - model.energy(after) - model.released_at_updates) \
        <= 1e-12 * stored
    assert model.fracture_energy() == pytest.approx(
        model.released_at_updates, rel=1e-12)


def test_pieces_are_cleaned_of_debris_and_pinches():
    """``separate``: a piece with fewer than ``min_piece`` vertices goes;
    of two pieces touching at a vertex one keeps its cells there; a cell
    held by one facet goes."""
    mesh = shifted_grid(4, 4, amount=0.0)
    c = mesh.p[:, mesh.t].mean(axis=1)
    all_cells = np.ones(mesh.t.shape[1], bool)
    cut = all_cells & ~row_of_cells(mesh, 1.5 / 4)
    # the bottom row (10 vertices) is debris below 11, kept at 10
    assert np.array_equal(separate(mesh, cut, 11), cut & (c[1] > 0.5))
    assert np.array_equal(separate(mesh, cut, 10), cut)
    # a pinch: the failed cells leave the lower-left block and the
    # upper-right one touching at the vertex (0.5, 0.5) only; one block
    # keeps its four cells, no vertex is left in two pieces
    lower_left, upper_right = (c[0] < 0.5) & (c[1] < 0.5), \
        (c[0] > 0.5) & (c[1] > 0.5)
    kept = separate(mesh, lower_left | upper_right, 4)
    assert kept[lower_left].all() or kept[upper_right].all()
    label, _ = pieces(mesh, kept)
    piece_of = np.full(mesh.t.shape[1], -1)
    piece_of[kept] = label
    for v in range(mesh.p.shape[1]):
        around = piece_of[(mesh.t == v).any(axis=0) & kept]
        assert len(set(around.tolist())) <= 1
    # a flap: one cell on top of the lower half, its upper vertices in no
    # other cell any more, held by its lower facet alone: it goes
    lower = c[1] < 0.5
    flap = (c[1] > 0.5) & (c[1] < 0.75) & (c[0] < 0.25)
    assert np.array_equal(separate(mesh, lower | flap, 4), lower)


def test_an_update_makes_debris_inactive_and_a_full_failure_is_an_error():
    """The particles of failed debris become inactive; failing every cell
    raises a named error."""
    mesh = shifted_grid(4, 4)
    basis = pg.FamilyBasis(mesh, dim=2)
    model = CrackAware(basis, STEEL, min_piece=11)
    c = mesh.p[:, mesh.t].mean(axis=1)
    n = model.intact.sum()
    assert not model.cells_to_fail(
        np.zeros(model.current.flat_weights().shape, bool)).any()
    model.update(np.zeros(basis.N), model.state(np.zeros(basis.N))["F"],
                 row_of_cells(mesh, 1.5 / 4) | (c[1] < 0.25))
    assert model.intact.sum() == n - 8
    assert not model.current.particles.active[mesh.p[1] < 0.2].any()
    with pytest.raises(FamilyError, match="every cell"):
        model.update(np.zeros(basis.N),
                     model.state(np.zeros(basis.N))["F"], model.intact)


def test_the_history_follows_its_pairs_when_debris_leaves_no_family():
    """The debris of the bottom row (the lowest particle numbers) masters
    no family after the update: every surviving point keeps the history
    of its own (master, member) pair.  Before, points were keyed by the
    family's index, which shifts past the first inactive particle: the
    history went to other pairs."""
    mesh = shifted_grid(4, 4)
    basis = pg.FamilyBasis(mesh, dim=2)
    model = CrackAware(basis, STEEL, min_piece=11)
    from skfem_pg.formulations.updated_lagrange import point_keys
    n = basis.particles.n
    keys = point_keys(basis).astype(float)
    st = model.state(np.zeros(basis.N))
    model.commit(st)
    h = model.history.committed
    h["alpha"] = 1e-9 * keys.reshape(h["alpha"].shape)  # tagged points
    c = mesh.p[:, mesh.t].mean(axis=1)
    model.update(np.zeros(basis.N), st["F"],
                 row_of_cells(mesh, 1.5 / 4) | (c[1] < 0.25))
    fam = model.current.families
    assert fam.masters[0] > 0  # particle 0 masters no family any more
    k_new = point_keys(model.current)
    assert np.array_equal(k_new, np.repeat(fam.masters, fam.sizes) * n
                          + np.asarray(fam.members))
    tags = model.history.committed["alpha"].ravel()
    assert np.array_equal(tags, 1e-9 * k_new.astype(float))


def test_a_new_pair_takes_the_state_at_its_particle():
    """Triangles cut along a slanted band: some families take members
    they did not have (15 new pairs).  A new point (k, j) takes the
    history and F_c of the point at its particle, (j, j), not its family
    master's, (k, k): a failure and a tracked crack's line belong to the
    material at j (with the master's, a tracked crack's lines reached
    sites three spacings beside them on Kalthoff–Winkler)."""
    mesh = fem.MeshTri.init_tensor(*(np.linspace(0, 1, 9),) * 2)
    basis = pg.FamilyBasis(mesh, dim=2)
    model = CrackAware(basis, STEEL)
    from skfem_pg.formulations.updated_lagrange import point_keys
    n = basis.particles.n
    keys = point_keys(basis)
    st = model.state(np.zeros(basis.N))
    model.commit(st)
    h = model.history.committed
    for name in ("alpha", "damage"):  # tagged points
        h[name] = 1e-9 * keys.astype(float).reshape(h[name].shape)
    F = np.array(st["F"])
    F[0, 0] += 1e-9 * keys.reshape(F.shape[2:])
    c = mesh.p[:, mesh.t].mean(axis=1)
    model.update(np.zeros(basis.N), F,
                 np.abs(c[1] - 0.7 * c[0] - 0.1) < 0.08)
    k_new = point_keys(model.current)
    new = ~np.isin(k_new, keys)
    assert new.sum() == 15
    want = 1e-9 * np.where(new, (k_new % n) * (n + 1), k_new).astype(float)
    h = model.history.committed
    for name in ("alpha", "damage"):
        assert np.array_equal(h[name].ravel(), want)
    F_c = np.asarray(model.state(np.zeros(basis.N))["F"])[0, 0].ravel()
    assert np.allclose(F_c - 1.0, want, rtol=0, atol=1e-15)


def test_cells_fail_from_their_failed_points():
    """A cell fails when the failed share of its points reaches
    ``fraction``; then a piece smaller than ``min_piece`` goes with it."""
    mesh = shifted_grid(4, 4)
    basis = pg.FamilyBasis(mesh, dim=2)
    model = CrackAware(basis, STEEL)
    from skfem_pg.formulations.updated_lagrange import point_keys
    keys = point_keys(basis)
    n = basis.particles.n
    cell = 5
    v = mesh.t[:, cell]
    in_cell = np.isin(keys // n, v) & np.isin(keys % n, v)
    failed = in_cell.copy()
    assert model.cells_to_fail(failed)[cell]
    # half of the cell's points, rounded down: not enough at 0.5 + 1
    half = np.flatnonzero(in_cell)[:in_cell.sum() // 2 - 1]
    failed = np.zeros_like(in_cell)
    failed[half] = True
    assert not model.cells_to_fail(failed)[cell]


def test_crack_aware_refuses_what_it_cannot_do():
    mesh = shifted_grid(4, 4)
    with pytest.raises(ValueError, match="'nearest' family rule"):
        CrackAware(pg.FamilyBasis(mesh, dim=2, families="horizon"), STEEL)
    with pytest.raises(ValueError, match="no damage law"):
        CrackAware(pg.FamilyBasis(mesh, dim=2), NeoHooke(lam=1.0, mu=2.0))
    with pytest.raises(ValueError, match="no damage law"):
        CrackAware(pg.FamilyBasis(mesh, dim=2),
                   J2Plasticity.from_young(1.0, 0.3, 0.01))
    with pytest.raises(ValueError, match="PBG"):
        CrackAware(pg.FamilyBasis(mesh, dim=2, method="PPG1"), STEEL)
    with pytest.raises(ValueError, match="fraction"):
        CrackAware(pg.FamilyBasis(mesh, dim=2), STEEL, fraction=0.0)
    with pytest.raises(ValueError, match="vertices"):
        CrackAware(pg.FamilyBasis(pg.Particles.from_mesh(
            mesh, kind="centroids"), dim=2), STEEL)
    with pytest.raises(ValueError, match="vc must be"):
        CrackAware(pg.FamilyBasis(mesh, dim=2), STEEL, vc="global")


def test_crack_aware_takes_the_local_vc_from_the_start():
    """Issue 51: the families on the intact cells are corrected by the
    local VC (min-norm boundary) from the start, whatever the basis' own;
    vc="basis" keeps the basis' global 'sn' correction; a basis without
    VC stays without.  The dofs (model.basis) are the user's basis'."""
    mesh = shifted_grid(4, 4)
    basis = pg.FamilyBasis.from_name(mesh, "VCBCPBG V5sn Unl", dim=2)
    local = CrackAware(basis, STEEL)
    assert local.basis is basis and local.current is not basis
    assert local.current.vc_report.solver == "local"
    assert local.current.options["vc_boundary"] == "min-norm"
    kept = CrackAware(basis, STEEL, vc="basis")
    assert kept.current is basis and basis.options["vc_boundary"] == "sn"
    plain = pg.FamilyBasis.from_name(mesh, "BCPBG Unl", dim=2)
    assert CrackAware(plain, STEEL).current is plain
    # the linear patch test on the local basis, to round-off
    X = local.current.doflocs
    u = (0.01 * X[0] + 0.02 * X[1]) * (np.arange(basis.N) % 2 == 0)
    F = local.state(u)["F"]
    assert np.abs(F[0, 0] - 1.01).max() <= 1e-12
    assert np.abs(F[0, 1] - 0.02).max() <= 1e-12


@pytest.mark.parametrize("vc", ["local", "basis"])
def test_crack_aware_strip_separates_where_the_thesis_variant_holds(vc):
    """The notched strip of ``test_fracture`` (VC PBG Unl, Johnson–Cook
    damage, 6 x 12 cells): crack-aware families fail the notch row's four
    cells right of the root and the strip comes apart — no family spans
    the crack, the lower piece stays, the upper one goes with the grip —
    with the energy balance within 1e-3.  Measured: 4 updates of one cell
    each; with the local VC (the default) 2450 steps, balance 3.4e-4;
    with the basis' global VC 2957 steps, 0.03 s per update, balance
    -8.3e-4.  The thesis' variant on the same strip: 8156 steps (its
    stable step shrinks with the stretched families across the failed
    band), stored energy ~450 N mm after the break against ~200 here; the
    bottom force oscillates around zero in both (mean over the last half
    -57 N and +5 N, peak 8495 N)."""
    n = 6
    mesh, y_notch = strip(n, notch_cells=True)
    basis = pg.FamilyBasis(mesh, dim=2)
    model = CrackAware(basis, STEEL, vc=vc)
    tr, first = pull(model, basis, 0.02, 2000.0, grip=0.0)
    _assert_separated(model, basis, mesh, y_notch, tr)
    last = tr.history[-1]
    assert 0 < last["fracture"] < last["dissipation"]
    assert (model.current.vc_report.solver == "local") == (vc == "local")


def test_nearest_families_stay_on_their_side_of_removed_cells():
    """Particles of a subset of the cells (a crack-aware rebuild): the
    nearest-neighbour families are taken among the particles the cells
    connect, so none reaches across a removed row, while the Euclidean
    neighbours of the same particles do; away from the gap a family
    before the pairing is the Euclidean one (the 3 x 3 stencil)."""
    mesh = fem.MeshQuad.init_tensor(np.linspace(0, 6, 7), np.linspace(0, 7, 8))
    c = mesh.p[:, mesh.t].mean(axis=1)
    kept = np.flatnonzero(np.abs(c[1] - 3.5) > 0.1)  # the row y in (3, 4)
    p = pg.Particles.from_mesh(mesh, elements=kept)
    fam = pg.families.nearest(p, 6)
    k = np.repeat(fam.masters, fam.sizes)
    below = mesh.p[1] < 3.5
    assert not np.any(below[k] != below[fam.members])
    euclid = pg.families.nearest(pg.Particles(p.x, p.volumes), 6)
    k = np.repeat(euclid.masters, euclid.sizes)
    assert np.any(below[k] != below[euclid.members])
    inner = int(np.argmin(np.hypot(p.x[0] - 3, p.x[1] - 1)))
    own, near = (pg.families.nearest(q, 6, pairwise=False) for q in (
        p, pg.Particles(p.x, p.volumes)))
    assert sorted(own.members[own.offsets[inner]:own.offsets[inner + 1]]) \
        == sorted(near.members[near.offsets[inner]:near.offsets[inner + 1]])
    assert own.sizes[own.masters == inner][0] == 9


def test_nearest_families_of_cells_hold_their_cell_neighbours():
    """On triangles the nearest neighbours miss some particles that share
    a cell; on a subset of the cells those join, so the crack-aware
    kNN basis takes the local VC (which needs them) from the start."""
    mesh = shifted_grid(6, 6).to_meshtri()
    p = pg.Particles.from_mesh(mesh, elements=np.arange(mesh.t.shape[1]))
    fam = pg.families.nearest(p, 6)
    k = np.repeat(fam.masters, fam.sizes)
    have = set(zip(k.tolist(), fam.members.tolist()))
    t = mesh.t
    pairs = {(int(a), int(b)) for c in t.T for a in c for b in c}
    assert pairs <= have
    euclid = pg.families.nearest(pg.Particles(p.x, p.volumes), 6)
    k = np.repeat(euclid.masters, euclid.sizes)
    assert not pairs <= set(zip(k.tolist(), euclid.members.tolist()))
    model = CrackAware(pg.FamilyBasis(mesh, dim=2, families="nearest"),
                       STEEL)
    assert model.current.vc_report.solver == "local"


def test_crack_aware_strip_separates_with_nearest_neighbour_families():
    """The notched strip with the kNN families (``families="nearest"``):
    rebuilt among the intact cells' particles, no family spans the crack
    and the strip comes apart as with the mesh rule."""
    mesh, y_notch = strip(6, notch_cells=True)
    basis = pg.FamilyBasis(mesh, dim=2, families="nearest")
    model = CrackAware(basis, STEEL)
    tr, first = pull(model, basis, 0.02, 2000.0, grip=0.0)
    _assert_separated(model, basis, mesh, y_notch, tr)


def _assert_separated(model, basis, mesh, y_notch, tr):
    """The notch row's four cells right of the root failed, no family
    spans them, the strip is in two pieces, the balance within 1e-3."""
    c = mesh.p[:, mesh.t].mean(axis=1)
    gone = ~model.intact
    assert np.allclose(c[1, gone], y_notch)
    assert np.allclose(np.sort(c[0, gone]), [25 / 6, 35 / 6, 7.5, 55 / 6])
    assert model.updates >= 1 and len(model.update_log) == model.updates
    fam = model.current.families
    above = mesh.p[1] > y_notch
    k = np.repeat(fam.masters, fam.sizes)
    assert not np.any(above[k] != above[np.asarray(fam.members)])
    assert abs(tr.history[-1]["relative_error"]) < 1e-3
    # apart: the lower piece stays below, the upper one has gone with the
    # grip (38 mm up at the end)
    uy = tr.x[1::2]
    y = basis.particles.x[1]
    assert np.abs(uy[y < y_notch]).max() < 1.0
    assert uy[y > y_notch].min() > 30.0


def test_crack_aware_unlp0_strip_separates():
    """Issue 51: PBG UnlP0 with crack-aware families on the same strip —
    the same four cells fail (4 updates), the strip comes apart, the
    balance holds (measured 3.0e-4, 2255 steps).  What the updates
    release is not positive here: measured -87 N mm over the run (10,370
    N mm dissipated, most of it plastic).  A family whose failed points
    leave it keeps the volumetric energy of its intact share only while
    they are in it (MeanDilatation's tension share); rebuilt without
    them, its whole volumetric energy returns."""
    mesh, y_notch = strip(6, notch_cells=True)
    basis = pg.FamilyBasis(mesh, dim=2)
    model = CrackAwareUnlP0(basis, STEEL)
    tr, first = pull(model, basis, 0.02, 2000.0, grip=0.0)
    _assert_separated(model, basis, mesh, y_notch, tr)
    assert model.current.vc_report.solver == "local"
    assert model.elements.n == model.current.layout.n_families


@pytest.mark.parametrize("kind", ["Unl", "U1SIG"])
def test_a_run_resumed_after_an_update_ends_where_it_would_have(tmp_path,
                                                                 kind):
    """A checkpoint written after the crack has formed holds the intact
    cells, the update's u_c and F_c and the released energy; a fresh
    model resumed from it rebuilds its families and ends where the
    uninterrupted run ends, to round-off."""
    mesh, _ = strip(4, notch_cells=True)
    path = tmp_path / "crack.npz"

    def run(**kw):
        if kind == "U1SIG":
            basis = pg.FamilyBasis.from_name(mesh, "VCPBG V3m U1SIG", dim=2)
            model = CrackAwareU1SIG(basis, STEEL)
        else:
            basis = pg.FamilyBasis(mesh, dim=2)
            model = CrackAware(basis, STEEL)
        tr, _ = pull(model, basis, 0.003, 2000.0, grip=0.0, **kw)
        return model, tr
    whole, tr = run(checkpoint=Every(path, steps=150))
    assert whole.updates >= 1
    with np.load(path) as f:
        saved_intact = f["history_crack_intact"] > 0.5
        at = float(f["load"])
    assert not saved_intact.all() and at < tr.t
    resumed, tr2 = run(resume=str(path))
    assert np.array_equal(resumed.intact, whole.intact)
    assert np.abs(tr2.x - tr.x).max() <= 1e-10 * np.abs(tr.x).max()
    assert resumed.fracture_energy() == pytest.approx(
        whole.fracture_energy(), rel=1e-10)


@pytest.mark.slow
def test_crack_aware_u1sig_on_the_notched_strip():
    """U1SIG with crack-aware families on the notched strip, 8 x 16 cells
    (the thesis' formulation; its history at the masters, a cell fails
    when half of its vertices' masters have).  Measured: the first master
    to fail is the clamped grip's corner (10, 20) — as in U1SIG with its
    connectivity kept — and the failed cells then run along the top row
    (the strip tears off the grip) and around the notch; 10 updates,
    2933 steps in 7 s, energy balance 7.6e-4 (2.3e-4 with the former
    stabilization on u - u_c and no closure).  Checked: the updates
    happen, no family spans a failed cell, the energy balance holds to
    1e-3."""
    mesh, _ = strip(8, notch_cells=True)
    basis = pg.FamilyBasis.from_name(mesh, "VCPBG V3m U1SIG", dim=2)
    model = CrackAwareU1SIG(basis, STEEL)
    tr, _ = pull(model, basis, 0.02, 2000.0, grip=0.0)
    assert model.updates >= 1 and not model.intact.all()
    label, _ = pieces(mesh, model.intact)
    piece = np.full(mesh.p.shape[1], -1)
    piece[mesh.t[:, model.intact].ravel()] = np.repeat(
        label[None], mesh.t.shape[0], axis=0).ravel()
    fam = model.point_basis.families
    k = np.repeat(fam.masters, fam.sizes)
    assert np.array_equal(piece[k], piece[np.asarray(fam.members)])
    assert abs(tr.history[-1]["relative_error"]) < 1e-3


def test_crack_aware_u1sig_is_objective_after_an_update():
    """A rigid rotation of a bent body after an update leaves the stored
    energy of CrackAwareU1SIG unchanged: its implicit-gradient
    stabilization acts on the total displacement, whose second
    derivatives rotate with the committed tangent.  On u - u_c (before
    issue 51's fix) the energy grew with the angle (+7e-5 at 0.1 rad,
    +6.7e-3 at 1 rad here), and on the two-hole plate at 1002 particles
    the flying pieces gained 1,400 N mm of released energy after they had
    come apart (benchmarks/README.md)."""
    mesh = shifted_grid(6, 6)
    basis = pg.FamilyBasis.from_name(mesh, "VCPBG V3m U1SIG", dim=2)
    model = CrackAwareU1SIG(basis, STEEL)
    P = basis.doflocs[:, ::2]
    U = np.vstack([-2e-4 * P[0] * P[1], 1e-4 * P[0] ** 2])  # elastic
    u0 = U.T.ravel()
    st = model.state(u0)
    model.commit(st)
    model.update(u0, np.array(st["F1"]), np.zeros_like(model.intact))
    assert model.updates == 1
    st0 = model.state(u0)
    model.commit(st0)
    E0 = model.energy(st0)
    for angle in (0.1, 1.0):
        c, s = np.cos(angle), np.sin(angle)
        u = ((np.array([[c, -s], [s, c]]) @ (P + U)) - P).T.ravel()
        st = model.state(u)
        model.commit(st)  # the stabilization's tangent rotates with F
        assert model.energy(st) == pytest.approx(E0, rel=1e-8)
    # the bending is the stabilization's: it holds 0.8 % of the energy
    model.commit(st0)
    assert 0.5 * u0 @ model.stabilization_force(u0) > 1e-3 * E0


def test_a_crack_checkpoint_is_refused_on_another_triangulation(tmp_path):
    """Issue 47: a crack-aware checkpoint loaded into a model on another
    triangulation of the same vertices (same cell count) applied its
    crack mask to other cells; the fingerprint hashes the cells now."""
    from skfem_pg.solvers import checkpoint
    quads = fem.MeshQuad.init_tensor(*(np.linspace(0, 1, 7),) * 2)
    q = quads.t
    a = fem.MeshTri(quads.p, np.hstack([q[[0, 1, 2]], q[[0, 2, 3]]]))
    b = fem.MeshTri(quads.p, np.hstack([q[[0, 1, 3]], q[[1, 2, 3]]]))
    model = CrackAware(pg.FamilyBasis(a, dim=2, families="mesh"), STEEL)
    u = np.zeros(model.N)
    st = model.state(u)
    model.commit(st)
    c = a.p[:, a.t].mean(axis=1)
    one = np.zeros(a.nelements, dtype=bool)
    one[np.argmin(np.hypot(c[0] - 0.5, c[1] - 0.5))] = True
    model.update(u, np.array(st["F"]), one)
    path = checkpoint.save(tmp_path / "crack", model, u, 0.5)
    other = CrackAware(pg.FamilyBasis(b, dim=2, families="mesh"), STEEL)
    with pytest.raises(ValueError, match="cells"):
        checkpoint.load(path, other)
    same = CrackAware(pg.FamilyBasis(a, dim=2, families="mesh"), STEEL)
    checkpoint.load(path, same)
    assert np.array_equal(same.intact, model.intact)
