r"""Numerical inf-sup test (Chapelle & Bathe 1993; thesis 7.2.5,
(7.10)–(7.15); Quak 2011, (3.52)–(3.60)).

For the displacement space :math:`U_h` and the pressure space :math:`P_h` a
formulation induces, the inf-sup value is :math:`\tilde\beta =
\sqrt{\lambda_k}`, :math:`\lambda_k` the smallest non-zero eigenvalue of

.. math:: T_h U = \lambda\, S_h U \qquad (7.11)

:math:`S_h` the :math:`H^1` seminorm matrix (:math:`\int\nabla u:\nabla v`,
(7.12)) and :math:`T_h` the pressure projection of the divergence (7.13):
the tangent with bulk modulus 1 and shear modulus 0 —
:math:`\int \mathrm{div}\,u\,\mathrm{div}\,v` for displacement formulations
(pressure at every quadrature point), :math:`B^T M_p^{-1} B` for a discrete
pressure space (:math:`B = \int q\,\mathrm{div}\,u`,
:math:`M_p = \int p\,q`; Q1P0, MINI ...).
With ``k - 1`` zero eigenvalues, the number of spurious pressure modes is

.. math:: k_{pm} = k - (n_u - n_p + 1) \qquad (7.15)

A formulation passes when :math:`\tilde\beta` stays bounded under refinement
and :math:`k_{pm} = 0`; a decreasing :math:`\tilde\beta` predicts locking.
The same functions accept scikit-fem bases and family bases.
"""
import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import skfem as fem
from skfem.helpers import ddot, div, grad

from ..discretization.assembly import assemble
from ..formulations import IncompressibleP0, MeanDilatation, NodalPressure


@fem.BilinearForm
def div_div(u, v, w):
    r""":math:`\int \mathrm{div}\,u\;\mathrm{div}\,v` (K = 1, μ = 0)."""
    return div(u) * div(v)


@fem.BilinearForm
def grad_grad(u, v, w):
    r""":math:`\int \nabla u : \nabla v` (the :math:`H^1` seminorm)."""
    return ddot(grad(u), grad(v))


def infsup(T, S, free, n_pressure, zero_tol=1e-8):
    """Solve (7.11) on the ``free`` dofs (dense; for the small model
    problems of the test) and return a dict with ``beta`` (7.14), the
    number of zero eigenvalues ``zeros`` (``k - 1``), the spurious pressure
    modes ``kpm`` (7.15) and the ``eigenvalues``.  Eigenvalues below
    ``zero_tol`` times the largest count as zero."""
    T = sp.csr_matrix(T)[free][:, free].toarray()
    S = sp.csr_matrix(S)[free][:, free].toarray()
    lam = sla.eigh(0.5 * (T + T.T), 0.5 * (S + S.T), eigvals_only=True)
    zero = lam < zero_tol * lam.max()
    k = int(zero.sum()) + 1
    n_u = len(free)
    return {"beta": float(np.sqrt(lam[~zero].min())), "zeros": k - 1,
            "kpm": k - (n_u - n_pressure + 1), "n_u": n_u,
            "n_p": int(n_pressure), "eigenvalues": lam}


@fem.BilinearForm
def pressure_divergence(u, q, w):
    r""":math:`\int q\,\mathrm{div}\,u`."""
    return q * div(u)


@fem.BilinearForm
def pressure_mass(p, q, w):
    r""":math:`\int p\,q`."""
    return p * q


def infsup_fe(basis, free, pbasis=None, **kw):
    """Inf-sup test of a scikit-fem vector basis: displacement-based
    (pressure at the quadrature points) or, with a pressure basis
    ``pbasis`` on the same mesh and quadrature (e.g. ``ElementQuad0`` for
    Q1P0, ``ElementTriP1`` with ``ElementTriMini`` displacements),
    :math:`T = B^T M_p^{-1} B`."""
    S = assemble(grad_grad, basis)
    if pbasis is None:
        return infsup(assemble(div_div, basis), S, free, basis.dx.size,
                      **kw)
    B = pressure_divergence.assemble(basis, pbasis).toarray()
    Mp = pressure_mass.assemble(pbasis).toarray()
    T = B.T @ np.linalg.solve(Mp, B)
    return infsup(T, S, free, pbasis.N, **kw)


def infsup_pg(basis, free, **kw):
    """Inf-sup test of a PBG family basis (displacement formulation):
    pressure at every member of every family (Unl), or one per family when
    the gradient is constant in the family (WTE1: U1)."""
    if basis.test is not None:
        raise ValueError("the inf-sup test needs a symmetric (PBG) family "
                         "basis, got {}".format(basis.method))
    T = assemble(div_div, basis)
    S = assemble(grad_grad, basis)
    n_p = len(basis.families) if basis.shape == "WTE1" \
        else int(basis.families.sizes.sum())
    return infsup(T, S, free, n_p, **kw)


def _identity(E):
    d = E.view.dim
    return np.broadcast_to(np.eye(d).reshape((d, d) + (1,) * len(
        E.point_shape)), (d, d) + E.point_shape)


def infsup_mixed(model, free, **kw):
    r"""Inf-sup test of a mixed formulation's displacement–pressure pair,
    :math:`T = B^T M_p^{-1} B` with :math:`B = \sum q\,\mathrm{div}\,u`
    and :math:`M_p = \sum p\,q` summed with the formulation's weights:

    * :class:`~skfem_pg.formulations.MeanDilatation` and
      :class:`~skfem_pg.formulations.IncompressibleP0` — p constant (Q1P0,
      H1P0, UnlP0, IUnlP0) or linear (U2P1) per element or family;
    * :class:`~skfem_pg.formulations.NodalPressure` — nodal p extrapolated
      with the gradients at the master (U2P1C, (6.11)); with the bubble
      (Unl+P1C) the displacement space holds the bubbles too, ``d`` more
      unknowns per family, all free (their rows of ``S`` are
      :math:`\sum_j w_{kj} (X^j - X_c^k)\cdot\ldots`, (6.15)).

    ``free`` are the free displacement dofs (scikit-fem numbering)."""
    basis = model.basis
    S = assemble(grad_grad, basis)
    if isinstance(model, (MeanDilatation, IncompressibleP0)):
        E = model.elements
        Phi = E.polynomials(getattr(model, "order", 0))
        Bt = E.coupling(E.moments(_identity(E), Phi))
        Minv = np.linalg.inv(E.gram(Phi))
        T = Bt @ sp.block_diag(list(Minv), format="csr") @ Bt.T
        return infsup(T, S, free, Bt.shape[1], **kw)
    if not isinstance(model, NodalPressure):
        raise TypeError("infsup_mixed takes a MeanDilatation, "
                        "IncompressibleP0 or NodalPressure model, got "
                        "{}".format(type(model).__name__))
    K = model.tangent(model.state(model.initial()))
    n_u, n = model.n_u, model.n
    Bt = K[:n_u, n_u:n_u + n]  # sum w div(N) Np at the reference
    M = -K[n_u:n_u + n, n_u + n:].toarray()
    if not model.bubble:
        T = Bt @ sp.csr_matrix(np.linalg.solve(M, Bt.T.toarray()))
        return infsup(T, S, free, n, **kw)
    d, nf = basis.particles.dim, basis.layout.n_families
    Sub, Sbb, Bbt = ([], [], []), np.zeros(nf * d), np.zeros((nf * d, n))
    for gr in model.groups:
        # grad of the bubble e_c (x) b^kj: S_ub = sum_j w G^kji . b^kj,
        # S_bb = sum_j w |b^kj|^2, the same for every component c
        v = np.einsum("kj,kjib,kjb->ki", gr.dx, gr.G, gr.b)
        bb = np.einsum("kj,kjb,kjb->k", gr.dx, gr.b, gr.b)
        fam = np.broadcast_to(gr.families[:, None], gr.members.shape)
        for c in range(d):
            Sub[0].append((d * gr.members + c).ravel())
            Sub[1].append((d * fam + c).ravel())
            Sub[2].append(v.ravel())
            Sbb[d * gr.families + c] = bb
        # div of the bubble: b^kj_c; against Np^kji
        r = np.einsum("kj,kjc,kji->kci", gr.dx, gr.b, gr.Np)
        rows = d * gr.families[:, None, None] + np.arange(d)[:, None]
        np.add.at(Bbt, (np.broadcast_to(rows, r.shape),
                        np.broadcast_to(gr.members[:, None, :], r.shape)),
                  r)
    Sub = sp.coo_matrix((np.concatenate(Sub[2]), (
        np.concatenate(Sub[0]), np.concatenate(Sub[1]))),
        shape=(n_u, nf * d))
    S = sp.bmat([[S, Sub], [Sub.T, sp.diags(Sbb)]], format="csr")
    Bt = sp.vstack([Bt, sp.csr_matrix(Bbt)]).tocsr()
    T = Bt @ sp.csr_matrix(np.linalg.solve(M, Bt.T.toarray()))
    free = np.concatenate([np.asarray(free), n_u + np.arange(nf * d)])
    return infsup(T, S, free, n, **kw)
