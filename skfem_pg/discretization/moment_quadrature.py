r"""Moment-matched family quadrature (``family_quadrature="moments"``,
issue 45):
each family integrates its quadratic fit over the master's share of the
body exactly.

The thesis integrates a family at its members, :math:`\sum_{j\in H^k}
w_{kj} f(X^j)` with :math:`\sum_j w_{kj} = V^k`; the members' moving
Taylor gradients are one-sided, and for a bending field they return the
strain of a point pulled towards the family's centre, so the method is soft
(``benchmarks/README.md``, "2-D recipes").  Here the family's quadratic
Taylor fit WTE2 (:func:`~skfem_pg.discretization.shape.quadratic.wte2_at`,
exact for quadratic fields) is evaluated at :math:`2d` points chosen so that
the rule integrates every quadratic polynomial :math:`g` like the master's
hat function :math:`N_k` of the collocation mesh does:

.. math::

    \sum_{a=1}^{d}\tfrac{V^k}{2d}\big[g(X_c^k + s_a e_a) +
    g(X_c^k - s_a e_a)\big] = \int_\Omega N_k\, g\, d\Omega,
    \qquad s_a = \sqrt{d\,\lambda_a},

:math:`V^k = \int N_k`, :math:`X_c^k = \int N_k x / V^k`, and
:math:`\lambda_a, e_a` the eigenpairs of the central second moment
:math:`\int N_k (x - X_c^k)\otimes(x - X_c^k) / V^k`.  The hat functions
are a partition of unity, so the families tile the body and the discrete
energy of a quadratic displacement field is exact; the strain energy of the
fit's residual is not seen, and stability comes from the fit itself
(exactly the rigid-body zero modes, ``tests/test_moment_quadrature.py``).

The points take the family's first :math:`2d` quadrature slots (the other
slots weigh zero).  Their shape-function values (:attr:`FamilyBasis.values`)
are the master's, :math:`N^{kji} = \delta_{ik}`: a value form then
integrates against the hat functions, :math:`\sum_k\sum_j w_{kj}\,
f(y^{kj})\,\delta_{ik} = \int N_i f` for quadratic :math:`f` — the
FE-consistent loads that the VC correction's area vectors assume — and
the mass matrix stays diagonal, :math:`V^i`.  (The fit's own values
integrate a unit load to other shares than :math:`V^i` and gave 2–4 times
P1's error on Poisson problems where these give less than P1's,
``benchmarks/README.md``.)  The first-order VC correction (V3) then makes
the linear patch test exact.
"""
import numpy as np
import skfem as fem

from ..errors import ParticleError
from .particles import linear_elements
from .shape.quadratic import wte2_at


#: smallest family, master included, of the moment quadrature's default
#: families (the mesh's 1-ring, enlarged): in 2-D the quadratic fit's
#: 1 + 5 plus one (the triangles' 1-ring); in 3-D its 1 + 9 are too few
#: for well-conditioned fits on gmsh tetrahedra (a 20 x 2 x 2 cantilever,
#: 1089 nodes: −8.3 % with 12 members at least, −1.6 % with 14, −2.3 %
#: with 17; O1 −17 %), and 13–16 gave the same on Cook's membrane
#: (``benchmarks/README.md``, "2-D recipes"); in 2-D 8 or 10 were no
#: better than 7
MIN_MEMBERS = {2: 7, 3: 14}


def family_options(dim):
    """The keywords of
    :func:`~skfem_pg.discretization.families.from_mesh` that make the
    moment quadrature's default families: the 1-ring enlarged to
    :data:`MIN_MEMBERS` members and until the members' offsets determine
    a quadratic fit (``order=2``)."""
    if dim not in MIN_MEMBERS:
        raise NotImplementedError(
            "family_quadrature='moments' is built for 2-D and 3-D "
            "particles, got {}-D".format(dim))
    return dict(min_size=MIN_MEMBERS[dim], order=2)


def default_families(particles):
    """The moment quadrature's default families on ``particles``
    (:func:`family_options`)."""
    from .families import from_mesh
    return from_mesh(particles, **family_options(particles.dim))


def hat_moments(particles):
    r"""``(V, Xc, M2)`` of every particle's hat function on its collocation
    mesh: :math:`\int N_k`, the centroid :math:`\int N_k x / \int N_k`
    ``(n, d)`` and the central second moment per volume ``(n, d, d)``,
    by exact quadrature over the particles' cells (zero-volume particles:
    their position and zero)."""
    mesh = particles.mesh
    if mesh is None or particles.kind != "vertices":
        raise ParticleError(
            "family_quadrature='moments' integrates the particles' hat "
            "functions on their collocation mesh: it needs particles "
            "collocated from a mesh's vertices (Particles.from_mesh), got "
            "{}".format(
                "particles without a mesh" if mesh is None
                else "{} particles".format(particles.kind)))
    e1, _ = linear_elements(mesh)
    kw = {} if particles.elements is None else {
        "elements": particles.elements}
    basis = fem.Basis(mesh, e1, intorder=4, **kw)
    d = mesh.dim()
    S0 = fem.LinearForm(lambda v, w: v).assemble(basis)
    S1 = np.array([fem.LinearForm(lambda v, w, a=a: v * w.x[a])
                   .assemble(basis) for a in range(d)]).T
    S2 = np.empty((len(S0), d, d))
    for a in range(d):  # d(d+1)/2 assemblies, the rest by symmetry
        for b in range(a, d):
            S2[:, a, b] = S2[:, b, a] = fem.LinearForm(
                lambda v, w, a=a, b=b: v * w.x[a] * w.x[b]).assemble(basis)
    V = np.where(S0 > 0, S0, 1.0)
    Xc = np.where(S0[:, None] > 0, S1 / V[:, None], particles.x.T)
    M2 = S2 / V[:, None, None] - Xc[:, :, None] * Xc[:, None, :]
    M2[S0 <= 0] = 0.0
    return S0, Xc, M2


def moment_points(particles, families, moments=None):
    """The :math:`2d` quadrature points of each family (module docstring):
    ``(points, weights)``, shapes ``(nf, 2d, d)`` and ``(nf, 2d)``;
    ``moments``: :func:`hat_moments` given (a rank's particles, which have
    no mesh)."""
    V, Xc, M2 = hat_moments(particles) if moments is None else moments
    k = families.masters
    d = particles.dim
    lam, vec = np.linalg.eigh(M2[k])
    s = np.sqrt(d * np.maximum(lam, 0.0))  # (nf, d)
    axes = vec * s[:, None, :]  # columns s_a e_a
    pts = np.concatenate([Xc[k][:, None, :] + np.swapaxes(axes, 1, 2),
                          Xc[k][:, None, :] - np.swapaxes(axes, 1, 2)],
                         axis=1)
    return pts, np.repeat(V[k][:, None] / (2 * d), 2 * d, axis=1)


def moment_quadrature(particles, families, n=1, moments=None):
    r"""``(G, dx, values, points, G_master)`` of a family basis with the
    moment-matched quadrature: padded ``(nf, m, m, d)`` derivatives at the
    quadrature slots (the :math:`2d` points first, zero elsewhere),
    ``(nf, m)`` weights, ``(nf, m, m)`` shape-function values (the
    master's at the points, :math:`\delta_{ij}` elsewhere), ``(nf, m,
    d)`` slot positions (the members' in the unused slots) and the fit's
    derivatives at the masters ``(nf, m, d)`` (particle output)."""
    mem, mask = families.padded()
    nf, m = mem.shape
    d = particles.dim
    pts, w = moment_points(particles, families, moments)
    P = pts.shape[1]
    small = np.nonzero(families.sizes < P)[0]
    if len(small):  # the unpadded layout keeps n_k slots per family
        raise ParticleError(
            "family_quadrature='moments' puts {} points into each family; "
            "the family of particle {} has {} members".format(
                P, families.masters[small[0]], families.sizes[small[0]]))
    x, V = particles.x, particles.volumes
    at_master = x.T[families.masters][:, None, :]
    Gp = wte2_at(x, V, families, np.concatenate([pts, at_master], 1), n=n)
    G = np.zeros((nf, m, m, d))
    G[:, :P] = Gp[:, :P]
    dx = np.zeros((nf, m))
    dx[:, :P] = w
    values = np.broadcast_to(np.eye(m), (nf, m, m)) * mask[:, None, :]
    values = np.array(values)
    values[:, :P] = 0.0
    values[:, :P, 0] = 1.0  # the master's value at its points
    points = x.T[mem].copy()
    points[:, :P] = pts
    return G, dx, values, points, Gp[:, P]


__all__ = ["MIN_MEMBERS", "default_families", "family_options", "hat_moments",
           "moment_points", "moment_quadrature"]
