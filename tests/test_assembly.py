"""The batched assembly equals scikit-fem's generic assembly."""
import numpy as np
import pytest
import scipy.sparse as sp
import skfem as fem
from skfem.helpers import dot, grad, ddot, sym_grad, transpose, mul

import skfem_pg as pg
from skfem_pg.materials import lame
from skfem_pg.formulations import linear_elasticity
from conftest import square, cube


def rel(a, b):
    a = a.toarray() if hasattr(a, "toarray") else a
    b = b.toarray() if hasattr(b, "toarray") else b
    return np.abs(a - b).max() / np.abs(b).max()


@pytest.mark.parametrize("mesh", [square(5, 0.3), cube(2, 0.3)])
def test_elasticity_fast_equals_generic(mesh):
    d = mesh.dim()
    b = pg.FamilyBasis(pg.Particles.from_mesh(mesh), dim=d)
    form = linear_elasticity(*lame(10.0, 0.3))
    assert rel(pg.assemble(form, b), form.assemble(b)) < 1e-13
    # a point-wise tangent (the gradients-only path through the basis'
    # cached transposed gradients, weights folded into the coefficients)
    from skfem_pg.materials import NeoHooke
    from skfem_pg.formulations import material_tangent
    F = b.interpolate(0.05 * np.random.default_rng(2).standard_normal(
        b.N)).grad + np.eye(d)[:, :, None, None]
    A = NeoHooke(lam=3.0, mu=1.0).tangent(F)
    assert rel(pg.assemble(material_tangent, b, A=A),
               material_tangent.assemble(b, A=A)) < 1e-13


def test_scalar_and_value_terms():
    b = pg.FamilyBasis(pg.Particles.from_mesh(square(5, 0.3)))

    @fem.BilinearForm
    def helmholtz(u, v, w):
        return dot(grad(u), grad(v)) + (1 + w.x[0] ** 2) * u * v \
            + w.x[1] * u * grad(v)[0]

    @fem.LinearForm
    def load(v, w):
        return np.sin(w.x[0]) * v + w.x[1] * grad(v)[1]

    assert rel(pg.assemble(helmholtz, b), helmholtz.assemble(b)) < 1e-13
    assert rel(pg.assemble(load, b), load.assemble(b)) < 1e-13


def test_nonlinear_tangent_with_field_parameter():
    mesh = square(4, 0.3)
    b = pg.FamilyBasis(pg.Particles.from_mesh(mesh), dim=2)
    rng = np.random.default_rng(0)
    u0 = 0.05 * rng.normal(size=b.N)
    F = b.interpolate(u0).grad + np.eye(2)[:, :, None, None]

    @fem.BilinearForm
    def tangent(du, v, w):  # St. Venant-Kirchhoff-like geometric part
        S = mul(transpose(w.F), w.F)
        return ddot(mul(grad(du), S), grad(v)) + \
            ddot(mul(transpose(w.F), grad(du)), sym_grad(v))

    @fem.LinearForm
    def residual(v, w):
        return ddot(w.F, grad(v))

    assert rel(pg.assemble(tangent, b, F=F), tangent.assemble(b, F=F)) \
        < 1e-13
    assert rel(pg.assemble(residual, b, F=F), residual.assemble(b, F=F)) \
        < 1e-13


def test_interpolate_reproduces_linear_fields():
    mesh = square(5, 0.3)
    b = pg.FamilyBasis(pg.Particles.from_mesh(mesh), dim=2)
    A = np.array([[0.1, -0.2], [0.3, 0.05]])
    u = (A @ mesh.p).T.ravel()
    f = b.interpolate(u)
    mem, mask = b.families.padded()
    assert np.abs((f.grad - A[:, :, None, None]) * mask).max() < 1e-12
    assert np.allclose(np.asarray(f)[:, mask], (A @ mesh.p)[:, mem[mask]])


def test_forms_needing_hessians_are_refused_by_fast_path():
    b = pg.FamilyBasis(pg.Particles.from_mesh(square(3)))

    @fem.BilinearForm
    def biharmonic(u, v, w):
        return ddot(u.hess, v.hess)

    # a family basis has no second derivatives: named, on either route
    # (it used to point to form.assemble, where numpy's einsum failed)
    with pytest.raises(pg.SecondDerivativeError, match="first derivatives"):
        pg.assemble(biharmonic, b)
    # an FE basis that has them: pg.assemble points to scikit-fem's
    # generic route, which the package's forms take by themselves
    morley = fem.Basis(square(3, kind="tri"), fem.ElementTriMorley())
    with pytest.raises(TypeError, match="form.assemble"):
        pg.assemble(biharmonic, morley)
    assert rel(pg.BilinearForm(biharmonic.form).assemble(morley),
               biharmonic.assemble(morley)) < 1e-14


@pytest.mark.parametrize("mesh_elem", [
    (square(4, 0.3), fem.ElementQuad1()),
    (square(4, 0.3), fem.ElementQuad2()),
    (square(4, 0.3, kind="tri"), fem.ElementTriP2()),
    (cube(2, 0.3), fem.ElementHex1()),
    (cube(2, 0.3, kind="tet"), fem.ElementTetP2()),
], ids=["Q1", "Q2", "T2", "H1", "O2"])
def test_fe_cell_bases_fast_equals_generic(mesh_elem):
    mesh, e = mesh_elem
    d = mesh.dim()
    vb = fem.Basis(mesh, fem.ElementVector(e))
    form = linear_elasticity(*lame(10.0, 0.3))
    assert rel(pg.assemble(form, vb), form.assemble(vb)) < 1e-13
    rng = np.random.default_rng(1)
    F = vb.interpolate(0.05 * rng.standard_normal(vb.N)).grad \
        + np.eye(d)[:, :, None, None]
    from skfem_pg.materials import NeoHooke
    from skfem_pg.formulations import material_tangent, internal_force
    A = NeoHooke(lam=3.0, mu=1.0).tangent(F)
    P = NeoHooke(lam=3.0, mu=1.0).stress(F)
    assert rel(pg.assemble(material_tangent, vb, A=A),
               material_tangent.assemble(vb, A=A)) < 1e-13
    assert rel(pg.assemble(internal_force, vb, P=P),
               internal_force.assemble(vb, P=P)) < 1e-13
    sb = fem.Basis(mesh, e)

    @fem.BilinearForm
    def mass_diffusion(u, v, w):
        return dot(grad(u), grad(v)) + (1 + w.x[0] ** 2) * u * v

    assert rel(pg.assemble(mass_diffusion, sb),
               mass_diffusion.assemble(sb)) < 1e-13


@pytest.mark.parametrize("transposed", [False, True])
@pytest.mark.parametrize("mesh,dim", [(square(5, 0.3), 2), (square(4, 0.3), None),
                                      (cube(2, 0.3), 3)])
def test_local_matrices_scatter_like_coo(mesh, dim, transposed):
    """:func:`assemble_local` through the cached entry index equals a COO
    sum of the same local matrices, in both layouts, on a basis with
    several family sizes; the returned matrix is canonical CSR and does
    not share the cached index arrays."""
    from skfem_pg.discretization.assembly import assemble_local, \
        batched_view
    b = pg.FamilyBasis(pg.Particles.from_mesh(mesh), dim=dim)
    view = batched_view(b)
    assert len(view.blocks) > 1  # several size groups: several chunks
    nc = view.nc
    rng = np.random.default_rng(3)
    local = [rng.standard_normal((blk.ne, nc, blk.nloc, nc, blk.nloc)
                                 if transposed else
                                 (blk.ne, blk.nloc, blk.nloc, nc, nc))
             for blk in view.blocks]

    def local_matrices(bi, blk, sl):
        return local[bi][sl]

    rows, cols, vals = [], [], []
    for blk, K in zip(view.blocks, local):
        if transposed:  # [k, c_i, i, c_l, l] -> [k, l, i, c_l, c_i]
            K = K.transpose(0, 4, 2, 3, 1)
        dof = nc * blk.conn[:, :, None] + np.arange(nc)  # (k, node, c)
        r = np.broadcast_to(dof[:, :, None, :, None], K.shape)
        c = np.broadcast_to(dof[:, None, :, None, :], K.shape)
        rows.append(r.ravel())
        cols.append(c.ravel())
        vals.append(K.ravel())
    ref = sp.coo_matrix((np.concatenate(vals), (np.concatenate(rows),
                                                np.concatenate(cols))),
                        shape=(b.N, b.N)).tocsr()
    for _ in range(2):  # the second call through the cached index
        A = assemble_local(b, local_matrices, view, transposed=transposed)
        assert A.has_canonical_format
        assert abs(A - ref).max() <= 1e-13 * abs(ref).max()
        A.indices[:] = 0  # the caller's copy: the cache is untouched
        A.indptr[:] = 0
