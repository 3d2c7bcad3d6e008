r"""Convergence studies on manufactured solutions (thesis 7.2.4, Fig. 7.11).

Linear elasticity with a smooth exact field :math:`u`, full Dirichlet
boundary (the exact values at the boundary nodes) and the body force

.. math::

    b_i = -\partial_j\sigma_{ij}
        = -\mu\,\Delta u_i - (\lambda + \mu)\,\partial_i(\nabla\cdot u),

applied as nodal forces :math:`b(X^i)V^i` in PG and as the usual load
vector in FE.  Errors are relative and use the same discrete norms for PG
and FE on the same nodes: :math:`\varepsilon_{L2}` with the lumped particle
volumes (7.3); :math:`\varepsilon_{H1}` with each method's own quadrature
(families and members for PG, Gauss points for FE).
"""
import time

import numpy as np
import skfem as fem

from .verification import h1_error, solve_held
from ..discretization.assembly import assemble
from ..discretization.basis import FamilyBasis
from ..discretization.loads import body_force
from ..formulations.linear import linear_elasticity
from ..discretization.particles import Particles, linear_elements


class PlaneWaves:
    r"""Exact field :math:`u_a(x) = \sum_w A_{wa}\sin(k_w\cdot x + \phi_w)`
    with its gradient and Hessian (any dimension).

    Default: two waves with wave numbers of order :math:`\pi` on the unit
    square/cube (about a quarter to half a wavelength per unit length).
    """

    def __init__(self, dim, k=None, amplitude=None, phase=None):
        if k is None:
            k = np.pi * np.array([[1.0, 0.5, 0.75], [-0.5, 1.25, 0.5]])
        if amplitude is None:
            amplitude = np.array([[0.1, -0.05, 0.08], [0.04, 0.1, -0.06]])
        if phase is None:
            phase = np.array([0.3, 1.1])
        self.dim = dim
        self.k = np.asarray(k, float)[:, :dim]
        self.A = np.asarray(amplitude, float)[:, :dim]
        self.phase = np.asarray(phase, float)

    @classmethod
    def hillman2019(cls):
        r"""The thesis' field (7.7) on :math:`[-1, 1]^2`:
        :math:`u = (\sin\frac{\pi X}{2}\cos\frac{\pi Y}{2},
        \cos\frac{\pi X}{2}\sin\frac{\pi Y}{2})`, written as two waves
        with :math:`k = \frac\pi2(1, \pm 1)`."""
        k = 0.5 * np.pi * np.array([[1.0, 1.0], [1.0, -1.0]])
        return cls(2, k=k, amplitude=[[0.5, 0.5], [0.5, -0.5]],
                   phase=[0.0, 0.0])

    def _arg(self, x):
        x = np.asarray(x, float)
        return np.tensordot(self.k, x, axes=(1, 0)) \
            + self.phase.reshape((-1,) + (1,) * (x.ndim - 1))

    def __call__(self, x):
        """Values, shape ``(dim, ...)`` for ``x`` of shape ``(dim, ...)``."""
        return np.tensordot(self.A.T, np.sin(self._arg(x)), axes=1)

    def grad(self, x):
        """:math:`\\partial_b u_a`, shape ``(dim, dim, ...)``."""
        c = np.cos(self._arg(x))
        return np.einsum("wa,wb,w...->ab...", self.A, self.k, c)

    def hess(self, x):
        """:math:`\\partial_b\\partial_c u_a`, shape ``(dim,)*3 + ...``."""
        s = np.sin(self._arg(x))
        return -np.einsum("wa,wb,wc,w...->abc...", self.A, self.k, self.k, s)

    def body_force(self, lam, mu):
        """The body force of linear elasticity, a function of ``x``."""
        def b(x):
            H = self.hess(x)
            lap = np.einsum("abb...->a...", H)
            graddiv = np.einsum("bab...->a...", H)
            return -mu * lap - (lam + mu) * graddiv
        return b


def solve_manufactured(mesh, field, lam, mu, scheme="PG", **basis_kwargs):
    """Solve the manufactured problem on ``mesh`` with ``scheme="PG"``
    (``basis_kwargs`` go to :class:`FamilyBasis`, e.g. ``method="PPG1"``)
    or ``"FE"`` (the mesh's own linear element).  Returns a dict: nodes,
    h, relative ``L2`` and ``H1`` errors, seconds (setup + assembly +
    solve)."""
    d = mesh.dim()
    t0 = time.perf_counter()
    b = field.body_force(lam, mu)
    D = mesh.boundary_nodes()
    if scheme == "PG":
        basis = FamilyBasis(Particles.from_mesh(mesh), dim=d, **basis_kwargs)
        K = assemble(linear_elasticity(lam, mu), basis)
        f = body_force(basis, b)
    elif scheme == "FE":
        basis = fem.Basis(mesh, fem.ElementVector(linear_elements(mesh)[0]))
        K = assemble(linear_elasticity(lam, mu), basis)
        f = fem.LinearForm(lambda v, w: sum(
            b(w.x)[a] * v[a] for a in range(d))).assemble(basis)
    else:
        raise ValueError("scheme must be 'PG' or 'FE', got {!r}"
                         .format(scheme))
    dofs = (d * D[:, None] + np.arange(d)).ravel()
    u_ex = field(mesh.p).T.ravel()
    u = solve_held(basis, K, f, u_ex, dofs)
    seconds = time.perf_counter() - t0
    particles = Particles.from_mesh(mesh) if scheme == "FE" \
        else basis.particles
    V = particles.volumes
    e = (u - u_ex).reshape(-1, d)
    l2 = np.sqrt(np.sum(V * (e ** 2).sum(1)))
    l2_ref = np.sqrt(np.sum(V * (u_ex.reshape(-1, d) ** 2).sum(1)))
    if scheme == "PG":
        h1 = h1_error(basis, u, field.grad)
    else:
        x = np.asarray(basis.global_coordinates())
        de = basis.interpolate(u).grad - field.grad(x)
        h1 = np.sqrt(np.sum(basis.dx * (de ** 2).sum((0, 1))))
    g = field.grad(particles.x)
    h1_ref = np.sqrt(np.sum(V * (g ** 2).sum((0, 1))))
    # h = (|Ω| / n)^(1/d) from the lumped volumes, which sum to |Ω|
    h = (V.sum() / mesh.nvertices) ** (1.0 / d)
    return {"scheme": scheme, "nodes": mesh.nvertices, "h": float(h),
            "L2": float(l2 / l2_ref), "H1": float(h1 / h1_ref),
            "seconds": seconds}


def rates(h, err):
    """Least-squares slope of :math:`\\log e` against :math:`\\log h`, and
    the slopes between successive refinements."""
    lh, le = np.log(np.asarray(h)), np.log(np.asarray(err))
    return float(np.polyfit(lh, le, 1)[0]), np.diff(le) / np.diff(lh)
