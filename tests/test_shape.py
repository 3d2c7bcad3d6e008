"""Consistency of the shape-function derivatives on random families."""
import numpy as np
import pytest

import skfem_pg as pg
from skfem_pg.discretization.corrections import bond_correction
from conftest import square, cube


def random_particles(d, n=60, seed=0):
    rng = np.random.default_rng(seed)
    x = rng.uniform(0, 1, (d, n))
    return pg.Particles(x, rng.uniform(0.5, 1.5, n) / n)


def consistency(G, x, fam):
    mem, mask = fam.padded()
    X = x.T[mem]
    d = x.shape[0]
    zeroth = np.abs(G.sum(axis=2)).max()
    first = np.einsum("kia,kjib->kjab", X, G) - \
        np.eye(d) * mask[:, :, None, None]
    return zeroth, np.abs(first).max()


@pytest.mark.parametrize("d", [2, 3])
@pytest.mark.parametrize("shape", ["WTE1", "MTE1"])
@pytest.mark.parametrize("n", [1, 2])
def test_linear_consistency(d, shape, n):
    p = random_particles(d)
    fam = pg.families.nearest(p, 4 * d)
    G = pg.shape.GRADIENTS[shape](p.x, p.volumes, fam, n=n)
    z, f = consistency(G, p.x, fam)
    assert z < 1e-12 and f < 1e-10
    Gb = bond_correction(G, p.x, fam)
    z, f = consistency(Gb, p.x, fam)
    assert z < 1e-12 and f < 1e-10


@pytest.mark.parametrize("d", [2, 3])
def test_bond_mapping(d):
    p = random_particles(d, seed=3)
    fam = pg.families.nearest(p, 4 * d)
    G = bond_correction(pg.shape.mte1_gradients(p.x, p.volumes, fam),
                        p.x, fam)
    mem, mask = fam.padded()
    rng = np.random.default_rng(1)
    u = rng.normal(size=(p.n, d))
    F = np.eye(d) + np.einsum("kia,kjib->kjab", u[mem], G)
    dX = p.x.T[mem] - p.x.T[mem[:, :1]]
    dx = dX + u[mem] - u[mem[:, :1]]
    err = np.einsum("kjab,kjb->kja", F, dX) - dx
    assert np.abs(err[mask]).max() < 1e-12
    # without the correction the mapping of an arbitrary field is wrong
    G0 = pg.shape.mte1_gradients(p.x, p.volumes, fam)
    F0 = np.eye(d) + np.einsum("kia,kjib->kjab", u[mem], G0)
    err0 = np.einsum("kjab,kjb->kja", F0, dX) - dx
    assert np.abs(err0[:, 1:][mask[:, 1:]]).max() > 1e-3


def test_mls1_master_values_reproduce_linear_fields():
    p = random_particles(2, seed=5)
    fam = pg.families.nearest(p, 8)
    N = pg.shape.mls1_master_values(p.x, p.volumes, fam)
    mem, mask = fam.padded()
    assert np.allclose(N.sum(axis=1), 1.0)
    X = p.x.T[mem]
    assert np.allclose(np.einsum("ki,kia->ka", N, X), X[:, 0])
    assert np.all(N[:, 0] == 0) and np.all(N[~mask] == 0)


@pytest.mark.parametrize("d", [2, 3])
def test_vc_corrected_gradients_stay_consistent(d):
    from conftest import square, cube
    mesh = square(6, 0.3) if d == 2 else cube(3, 0.3)
    b = pg.FamilyBasis(pg.Particles.from_mesh(mesh), dim=d)
    z, f = consistency(b.G, b.particles.x, b.families)
    assert z < 1e-12 and f < 1e-10
    assert b.vc_report.residual_before > 1e-2
    assert b.vc_report.residual_after < 1e-12


@pytest.mark.parametrize("d", [2, 3])
def test_wte2_reproduces_quadratic_gradients(d):
    from skfem_pg.discretization.shape import wte2_gradients
    if d == 2:
        mesh = square(8, 0.3, seed=1)
    else:
        mesh = cube(4, 0.3, seed=1)
    p = pg.Particles.from_mesh(mesh)
    fam = pg.families.horizon(p, factor=2.51,
                              min_size=2 + d + d * (d + 1) // 2)
    G = wte2_gradients(p.x, p.volumes, fam)
    rng = np.random.default_rng(0)
    A = rng.normal(size=(d, d))
    H = rng.normal(size=(d, d, d))
    H = H + H.transpose(0, 2, 1)
    u = A @ p.x + 0.5 * np.einsum("abc,bn,cn->an", H, p.x, p.x)
    mem, mask = fam.padded()
    F = np.einsum("kjid,kia->kjad", G, u.T[mem])
    F_exact = A + np.einsum("abc,kjc->kjab", H, p.x.T[mem])
    err = np.abs((F - F_exact) * mask[..., None, None])
    # ill-conditioned 7-member boundary families reach 7e-10
    assert err.max() < 1e-8
    assert np.abs(G.sum(axis=2)).max() < 1e-10


@pytest.mark.parametrize("d", [2, 3])
def test_least_squares_master_derivatives(d):
    """WLS1/MLS1 gradients reproduce linear fields, WLS2 gradients and
    Hessians (the V2 correction functions) quadratic ones; MLS1 against
    finite differences of the moving fit."""
    from skfem_pg.discretization.shape import least_squares as ls
    p = random_particles(d, n=80, seed=7)
    fam = pg.families.nearest(p, 14 if d == 2 else 24)
    mem, mask = fam.padded()
    X = p.x.T[mem] * mask[..., None]
    A = np.arange(1.0, 1.0 + d * d).reshape(d, d) / d ** 2
    u = np.einsum("ak,ab,bk->k", p.x, A, p.x)  # X·A·X
    for fn in (ls.wls1_master_gradients, ls.mls1_master_gradients,
               ls.wls2_master_gradients):
        g = fn(p.x, p.volumes, fam)
        assert np.abs(g.sum(1)).max() < 1e-9
        assert np.abs(np.einsum("kia,kib->kab", X, g) - np.eye(d)).max() \
            < 1e-9
    g2 = ls.wls2_master_gradients(p.x, p.volumes, fam)
    exact = ((A + A.T) @ p.x[:, fam.masters]).T
    assert np.abs(np.einsum("ki,kia->ka", u[mem] * mask, g2) - exact).max() \
        < 1e-8
    H = ls.wls2_master_hessians(p.x, p.volumes, fam)
    assert np.abs(H.sum(1)).max() < 1e-8
    assert np.abs(np.einsum("kia,kibc->kabc", X, H)).max() < 1e-8
    assert np.abs(np.einsum("ki,kiab->kab", u[mem] * mask, H)
                  - (A + A.T)).max() < 1e-8
    # MLS1: the derivative of the moving fit (master excluded)
    g = ls.mls1_master_gradients(p.x, p.volumes, fam)
    assert np.abs(g - ls.wls1_master_gradients(p.x, p.volumes, fam)).max() \
        > 1e-3  # it is not the static one
    k, eps = 5, 1e-6
    others = mem[k][mask[k]][1:]
    xk = p.x[:, fam.masters[k]]
    # ls_values takes offsets in units of the family radius
    h = np.linalg.norm(p.x[:, others].T - xk, axis=1).max()

    def values(pt):
        N, _ = ls.ls_values(((p.x[:, others].T - pt) / h)[None],
                            p.volumes[others][None])
        return N[0]
    fd = np.array([(values(xk + eps * e) - values(xk - eps * e)) / (2 * eps)
                   for e in np.eye(d)]).T
    assert np.abs(fd - g[k, 1:len(others) + 1]).max() < 1e-6 * np.abs(
        fd).max()
