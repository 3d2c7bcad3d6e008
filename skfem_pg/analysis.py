r"""Verification tools (thesis chapter 7): discrete error norms and the
linear patch test.

Discrete norms (7.3), with particle volumes and family weights as
quadrature:

.. math::

    \varepsilon_{L2} = \Big(\sum_p V^p |u^p - u(X^p)|^2\Big)^{1/2}, \qquad
    \varepsilon_{H1} = \Big(\sum_k\sum_j w_{kj}
        |\nabla u_h^{kj} - \nabla u(X^j)|^2\Big)^{1/2}.
"""
import numpy as np
import skfem as fem

from .basis import FamilyBasis, pbg_weights
from .assembly import assemble
from .loads import stress_load
from .models import lame, linear_elasticity
from .particles import Particles

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
    ``(ncomp, dim, ...)`` at member positions ``x`` (``(dim, nf, m)``).
    The quadrature is the PBG one, :math:`w_{kj} = V^kV^j/V_H^k`, for PPG
    bases too (their weights :math:`V^j` count each particle once per
    family it belongs to)."""
    g = basis.interpolate(u).grad
    x = basis.global_coordinates()
    ge = np.broadcast_to(exact_grad(np.asarray(x)), g.shape)
    err = ((g - ge) ** 2).reshape(-1, *g.shape[-2:]).sum(axis=0)
    return float(np.sqrt(np.sum(
        pbg_weights(basis.particles.volumes, basis.families) * err)))


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
    u = fem.solve(*fem.condense(K, f, x=uex, D=D))
    return {
        "max_error": float(np.abs(u - uex).max()),
        "L2": l2_error(basis, u, lambda x: gradient @ x),
        "H1": h1_error(basis, u, lambda x: gradient.reshape(
            d, d, *([1] * (x.ndim - 1)))),
        "basis": basis,
        "u": u,
    }
