r"""Load vectors consistent with the integration constraint.

Neumann loads are FE consistent, integrated with the linear shape
functions of the facets the particles were collocated from (4.31)–(4.35):

* :func:`traction`: :math:`f^i = \int_\Gamma N_i\, t \, d\Gamma`
  (for a constant traction on a flat face: :math:`t\,|A^i_\Gamma|`);
* :func:`stress_load`: :math:`f^i = \bar P \cdot A^i_\Gamma`, the load of a
  homogeneous nominal stress :math:`\bar P` (what a patch test applies);
* :func:`body_force`: :math:`f^i = \rho_0 b(X^i)\, V^i`.

Because the same :math:`A^i` enter the VC correction, a linear field is
reproduced exactly (patch test).
"""
import numpy as np
import skfem as fem


def _facet_basis(basis, facets, what):
    p = basis.particles
    if p.kind != "vertices":
        raise ValueError("{} needs vertex particles (surface particles); "
                         "these are {} particles: apply stress_load on "
                         "their area vectors instead".format(what, p.kind))
    return p._facet_basis(facets, vector=basis.ncomp is not None)


def traction(basis, facets, t):
    r"""Consistent nodal forces of a traction ``t`` on ``facets``.

    ``t``: constant vector (scalar for a scalar basis) or a callable of the
    facet quadrature points ``x`` (shape ``(dim, nfacets, nqp)``) returning
    an array of shape ``(dim, nfacets, nqp)``.  Returns a length-``N``
    vector.
    """
    fb = _facet_basis(basis, facets, "traction")
    vector = basis.ncomp is not None

    @fem.LinearForm
    def load(v, w):
        tv = t(w.x) if callable(t) else t
        if vector:
            tv = np.asarray(tv, dtype=float)
            if tv.ndim == 1:
                tv = tv[:, None, None]
            return sum(tv[a] * v[a] for a in range(v.shape[0]))
        return tv * v

    f = load.assemble(fb)
    return _resize(f, basis)


def stress_load(basis, facets, P):
    r"""Nodal forces :math:`\bar P \cdot A^i_\Gamma` of a homogeneous nominal
    stress ``P`` (``(d, d)``) acting on ``facets``."""
    P = np.asarray(P, dtype=float)
    A = basis.particles.area_vectors(facets)
    f = P @ A  # (d, np)
    return f.T.ravel()


def body_force(basis, b, rho=1.0):
    r"""Nodal forces :math:`\rho_0 b(X^i) V^i` of a body force ``b``
    (constant vector or callable of positions ``(dim, n)``)."""
    x, V = basis.particles.x, basis.particles.volumes
    bv = b(x) if callable(b) else np.asarray(b, dtype=float)
    if basis.ncomp is None:
        return rho * np.broadcast_to(bv, V.shape) * V
    bv = np.broadcast_to(np.asarray(bv).reshape(basis.ncomp, -1),
                         (basis.ncomp, len(V)))
    return (rho * bv * V).T.ravel()


def _resize(f, basis):
    if f.shape[0] != basis.N:
        raise ValueError("load vector has {} entries, the basis {}".format(
            f.shape[0], basis.N))
    return f
