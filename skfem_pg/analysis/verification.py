r"""Verification tools (thesis chapter 7): discrete error norms, the linear
and the quadratic patch test.

Discrete norms (7.3), with particle volumes and family weights as
quadrature:

.. math::

    \varepsilon_{L2} = \Big(\sum_p V^p |u^p - u(X^p)|^2\Big)^{1/2}, \qquad
    \varepsilon_{H1} = \Big(\sum_k\sum_j w_{kj}
        |\nabla u_h^{kj} - \nabla u(X^j)|^2\Big)^{1/2}.
"""
import numpy as np
import skfem as fem

from ..discretization.basis import FamilyBasis, pbg_weights
from ..discretization.assembly import assemble
from ..discretization.loads import stress_load
from ..materials.constants import lame
from ..formulations.linear import linear_elasticity
from ..discretization.particles import Particles, linear_elements
from ..solvers.linear import direct, require_stiffness


def checked_solve(A, b):
    """scipy's ``spsolve`` (COLAMD, what ``fem.solve`` uses) with the
    residual check of :func:`~skfem_pg.solvers.direct`."""
    return direct(A, b, ordering="colamd")


def solve_held(basis, K, f, x, D):
    """``fem.solve(*fem.condense(K, f, x=x, D=D))`` that first checks the
    condensed system holds every rigid-body mode
    (:func:`~skfem_pg.solvers.linear.require_stiffness`): a patch test
    without enough Dirichlet conditions raises SingularSystemError instead
    of returning an arbitrary rigid-body part (max error 0.44, or 4.6e16)."""
    A, b, x, I = fem.condense(K, f, x=x, D=D)
    d = basis.doflocs.shape[0]
    require_stiffness(A, basis.doflocs[:, I], I % d)
    return fem.solve(A, b, x, I, solver=checked_solve)

#: displacement gradient of the thesis' linear patch test (7.1)
PATCH_GRADIENT_2D = np.array([[0.1, 0.3], [0.2, 0.4]])
#: a full 3-D analogue
PATCH_GRADIENT_3D = np.array([[0.1, 0.3, -0.2], [0.2, 0.4, 0.1],
                              [-0.1, 0.05, 0.3]])


def l2_error(basis, u, exact):
    """Discrete L2 error; ``exact(x)`` returns ``(ncomp, n)`` values at the
    particle positions ``x`` (``(dim, n)``)."""
    p = basis.particles
    nc = 1 if basis.ncomp is None else basis.ncomp
    e = u.reshape(-1, nc).T - np.reshape(exact(p.x), (nc, -1))
    return float(np.sqrt(np.sum(p.volumes * (e ** 2).sum(axis=0))))


def h1_error(basis, u, exact_grad):
    """Discrete H1 seminorm error; ``exact_grad(x)`` returns
    ``(ncomp, dim, ...)`` at the quadrature points ``x`` (``(dim, nf,
    m)``: the members, or the points of ``family_quadrature="moments"``).
    The quadrature is the basis' own for PBG, and the PBG one,
    :math:`w_{kj} = V^kV^j/V_H^k`, for PPG bases (their weights
    :math:`V^j` count each particle once per family it belongs to)."""
    g = basis.interpolate(u).grad
    x = basis.global_coordinates()
    ge = np.broadcast_to(exact_grad(np.asarray(x)), g.shape)
    err = ((g - ge) ** 2).reshape(-1, *g.shape[-2:]).sum(axis=0)
    w = (pbg_weights(basis.particles.volumes, basis.families)
         if basis.is_petrov else basis.dx)
    return float(np.sqrt(np.sum(w * err)))


def nodal_interpolant(basis, field):
    """Nodal vector of ``field(x)`` (``(ncomp, n)`` values at points ``x``
    of shape ``(dim, n)``) at the particles of a family basis or at the
    vertices of a scikit-fem P1/Q1 vector basis."""
    family = isinstance(basis, FamilyBasis)
    x = basis.particles.x if family else basis.mesh.p
    if family:
        nc = 1 if basis.ncomp is None else basis.ncomp
    else:
        nc = basis.nodal_dofs.shape[0]
        if nc * x.shape[1] != basis.N:
            raise ValueError("nodal_interpolant needs a vertex-only FE "
                             "basis (P1/Q1), this one has {} dofs for {} "
                             "vertices".format(basis.N, x.shape[1]))
    values = np.asarray(field(x), float)
    if values.shape != (nc, x.shape[1]) and not (
            nc == 1 and values.shape == (x.shape[1],)):
        raise ValueError("field(x) must return shape ({}, {}), got {}"
                         .format(nc, x.shape[1], values.shape))
    values = values.reshape(nc, -1)
    if family:
        return values.T.ravel()
    u = np.zeros(basis.N)
    u[basis.nodal_dofs] = values
    return u


def discrete_energy(basis, u, material):
    r"""Strain energy of the nodal vector ``u`` as the discretization
    integrates it, :math:`\sum_k\sum_j w_{kj} W(F^{kj})` for a family
    basis (PBG weights (4.30); PPG bases use their own ``dx``) and
    :math:`\sum_e\sum_q w_{eq} W(F)` for a scikit-fem vector basis."""
    d = basis.particles.dim if isinstance(basis, FamilyBasis) \
        else basis.mesh.dim()
    F = basis.interpolate(u).grad + np.eye(d).reshape(d, d, 1, 1)
    return float(np.sum(basis.dx * material.energy(F)))


def energy_capture(basis, field, material, exact_energy):
    r"""Ratio of the discrete strain energy of the nodal interpolant of
    ``field`` to ``exact_energy`` (:math:`\int_\Omega W`).

    A quadrature-and-gradient consistency check that needs no solve: a
    linear field gives 1 to round-off on every linearly consistent
    discretization; a bending field shows how much of its energy a
    discretization sees — below 1 means too soft in that mode, above 1
    too stiff (locking).  ``benchmarks/bending_3d.py`` uses it to explain
    the 3-D Cook's membrane results.
    """
    return discrete_energy(basis, nodal_interpolant(basis, field),
                           material) / float(exact_energy)


def linear_patch_test(mesh, neumann, gradient=None, E=100.0, nu=0.3,
                      particles=None, **basis_kwargs):
    """Linear patch test (thesis (7.1)–(7.2)) on ``mesh``.

    The exact field is ``u = gradient · X``; Dirichlet values on all
    boundary facets except ``neumann`` (facets or a callable), where the
    consistent load ``P · A^i`` of the exact stress is applied.  Returns a
    dict with the max nodal error, εL2, εH1 and the basis.
    """
    d = mesh.dim()
    if gradient is None:
        gradient = PATCH_GRADIENT_2D if d == 2 else PATCH_GRADIENT_3D
    gradient = np.asarray(gradient, dtype=float)
    lam, mu = lame(E, nu)
    eps = 0.5 * (gradient + gradient.T)
    sigma = 2 * mu * eps + lam * np.trace(eps) * np.eye(d)
    if particles is None:
        particles = Particles.from_mesh(mesh)
    basis = FamilyBasis(particles, dim=d, **basis_kwargs)
    K = assemble(linear_elasticity(lam, mu), basis)
    nf = mesh.normalize_facets(neumann)
    f = stress_load(basis, nf, sigma)
    dirichlet = np.setdiff1d(mesh.boundary_facets(), nf)
    D = basis.get_dofs(dirichlet)
    uex = (gradient @ particles.x).T.ravel()
    u = solve_held(basis, K, f, uex, D)
    return {
        "max_error": float(np.abs(u - uex).max()),
        "L2": l2_error(basis, u, lambda x: gradient @ x),
        "H1": h1_error(basis, u, lambda x: gradient.reshape(
            d, d, *([1] * (x.ndim - 1)))),
        "basis": basis,
        "u": u,
    }


#: quadratic patch-test field (7.4): u_a = L[a]·X + X·Q[a]·X
QUADRATIC_PATCH_L = np.array([[0.12, 0.14], [0.11, 0.13]])
QUADRATIC_PATCH_Q = np.array([[[0.16, 0.09], [0.09, 0.2]],
                              [[0.15, 0.05], [0.05, 0.21]]])


def quadratic_patch_test(mesh, neumann, E=100.0, nu=0.3, **basis_kwargs):
    r"""Quadratic patch test (thesis (7.4)–(7.6)) on a 2-D ``mesh``:
    :math:`u = L X + X^T Q X`, linear stress, the constant body force
    :math:`-\mathrm{Div}\,P` as nodal forces :math:`b V^i`, Dirichlet on
    all boundary facets but ``neumann``, where the FE-consistent traction
    load :math:`\int_\Gamma N_i P(x) n` is applied.  Returns a dict like
    :func:`linear_patch_test`."""
    if mesh.dim() != 2:
        raise ValueError("the quadratic patch test (7.4) is 2-D")
    lam, mu = lame(E, nu)
    L, Q = QUADRATIC_PATCH_L, QUADRATIC_PATCH_Q

    def u_exact(x):
        return np.einsum("ab,b...->a...", L, x) + np.einsum(
            "abc,b...,c...->a...", Q, x, x)

    def grad_exact(x):
        return L.reshape(2, 2, *([1] * (x.ndim - 1))) + 2 * np.einsum(
            "abc,c...->ab...", Q, x)

    def stress(x):
        g = grad_exact(x)
        eps = 0.5 * (g + np.swapaxes(g, 0, 1))
        tr = eps[0, 0] + eps[1, 1]
        return 2 * mu * eps + lam * tr * np.eye(2).reshape(
            2, 2, *([1] * (np.ndim(tr))))

    # b = -Div P = -(mu Δu + (lam + mu) grad div u), constant (7.6)
    lap = 2 * np.trace(Q, axis1=1, axis2=2)
    graddiv = 2 * np.einsum("bab->a", Q)
    b = -(mu * lap + (lam + mu) * graddiv)
    particles = Particles.from_mesh(mesh)
    basis = FamilyBasis(particles, dim=2, **basis_kwargs)
    K = assemble(linear_elasticity(lam, mu), basis)
    nf = mesh.normalize_facets(neumann)
    fb = fem.FacetBasis(particles.facet_mesh(),  # local, see facet_origin
                        fem.ElementVector(linear_elements(mesh)[0]),
                        facets=nf, intorder=4)
    x0 = particles.facet_origin.reshape(2, 1, 1)
    f = fem.LinearForm(lambda v, w: sum(
        (stress(w.x + x0)[a] * w.n).sum(axis=0) * v[a] for a in range(2))
    ).assemble(fb)
    if basis.area_correction is not None:
        # discrete surface terms (VC boundary variant 's'/'sn'): for the
        # linear stress P(x) = P(X^i) + ∇P (x - X^i) the load changes by
        # P(X^i)·δA^i + ∇P : (δA_2^i - X^i ⊗ δA^i); here on the Neumann
        # facets only (Dirichlet rows are eliminated anyway)
        on = np.zeros(particles.n, dtype=bool)
        on[mesh.facets[:, nf].ravel()] = True
        x = particles.x
        dA = basis.area_correction * on
        P0 = stress(x)  # (a, b, n)
        df = np.einsum("abn,bn->an", P0, dA)
        if basis.area2_correction is not None:
            gradP = stress(np.eye(2)[:, :, None]) - stress(
                np.zeros((2, 1)))[..., None]  # [a, b, c, 0]: ∂P_ab/∂x_c
            dA2 = basis.area2_correction * on  # [c, b, n]
            df += np.einsum("abc,cbn->an", gradP[..., 0],
                            dA2 - x[:, None, :] * dA[None])
        f = f + df.T.ravel()
    f = f + np.repeat(particles.volumes, 2) * np.tile(b, particles.n)
    dirichlet = np.setdiff1d(mesh.boundary_facets(), nf)
    D = basis.get_dofs(dirichlet)
    uex = u_exact(particles.x).T.ravel()
    u = solve_held(basis, K, f, uex, D)
    return {
        "max_error": float(np.abs(u - uex).max()),
        "L2": l2_error(basis, u, u_exact),
        "H1": h1_error(basis, u, grad_exact),
        "basis": basis,
        "u": u,
    }


def kirsch_displacement(x, lam, mu, radius=1.0):
    r"""Kirsch's solution: the displacements ``(2, ...)`` at ``x``
    ``(2, ...)`` of an infinite plate in plane strain with a traction-free
    circular hole of ``radius`` about the origin, under unit tension in
    :math:`x` far away (Lamé ``lam``, ``mu``); its hoop stress on the hole
    is :math:`1 - 2\cos 2\theta`, 3 at :math:`\theta = \pm\pi/2`.  On a
    finite part of the plate with these displacements on its outer
    boundary it is the exact solution of a stress concentration.

    >>> import numpy as np
    >>> u = kirsch_displacement(np.array([[2.0], [0.0]]), 1.5, 1.0)
    >>> float(np.round(u[1, 0], 12))  # on the x axis: no u_y
    0.0
    """
    kappa = 3 - 2 * lam / (lam + mu)  # plane strain: 3 - 4 nu
    a2 = radius ** 2
    r, t = np.hypot(x[0], x[1]), np.arctan2(x[1], x[0])
    c, s = np.cos(2 * t), np.sin(2 * t)
    ur = (r * ((kappa - 1) / 2 + c) + a2 / r * (1 + (1 + kappa) * c)
          - a2 ** 2 / r ** 3 * c) / (4 * mu)
    ut = ((1 - kappa) * a2 / r - r - a2 ** 2 / r ** 3) * s / (4 * mu)
    return np.array([ur * np.cos(t) - ut * np.sin(t),
                     ur * np.sin(t) + ut * np.cos(t)])
