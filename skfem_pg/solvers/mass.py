r"""Lumped (diagonal) mass of a displacement basis (thesis 4.4, (4.13),
(4.14), (4.46)).

A particle discretization's mass is diagonal by construction, without
lumping: :math:`M^k = \rho_0^k V^k\, I_d` per particle.  The FE
comparators on the same nodes use the row-sum lumped consistent mass
:math:`m_i = \sum_j \int \rho_0 \phi_i \cdot \phi_j`, positive for the
linear elements (T1, Q1, O1, H1 and their P0 variants) and for Q2/H2, and
refused for T2/O2, whose row sums vanish or turn negative at the
vertices.

The time integrators (:mod:`~skfem_pg.solvers.newmark`,
:mod:`~skfem_pg.solvers.explicit`) take the mass as this vector, one entry
per displacement dof in scikit-fem's interleaved numbering.
"""
from __future__ import annotations

import numpy as np
import skfem as fem
from numpy.typing import ArrayLike
from skfem.assembly.basis import AbstractBasis
from skfem.helpers import dot

from ..discretization.layout import is_family_basis


@fem.BilinearForm
def _mass_form(u, v, w):
    return w.rho * dot(u, v)


def row_sums(basis, rho):
    """The row sums of the consistent mass of a scikit-fem basis, ``rho``
    a number or one value per element of its mesh (unchecked: on an MPI
    rank the sums are partial until added over the ranks)."""
    nel = basis.mesh.t.shape[1]
    rho = _per(rho, nel, "element")
    tind = basis.tind if basis.tind is not None else np.arange(nel)
    rho_q = np.broadcast_to(rho[tind][:, None], basis.dx.shape)
    return np.asarray(_mass_form.assemble(basis, rho=rho_q).sum(
        axis=1)).ravel()


def lumped_mass(basis: AbstractBasis,
                rho: float | ArrayLike) -> np.ndarray:
    """The diagonal mass, one entry per dof of ``basis`` (length
    ``basis.N``).

    ``rho``: the reference density :math:`\\rho_0`, a number or one value
    per particle (family basis) or per element (scikit-fem basis).  For
    a :class:`~skfem_pg.FamilyBasis`: :math:`\\rho_0^k V^k` per component
    of particle ``k``; for a scikit-fem vector basis: the row sums of the
    consistent mass.  Raises ``ValueError`` for a non-positive density and,
    naming the dof and its location, for a non-positive lumped entry
    (quadratic elements; a particle without volume)."""
    if is_family_basis(basis):
        p = basis.particles
        d = p.dim
        rho = _per(rho, p.n, "particle")
        m = np.repeat(rho * p.volumes, d)
        if m.shape[0] != basis.N:
            raise ValueError("the basis has {} dofs, its {} particles {}"
                             .format(basis.N, p.n, m.shape[0]))
        where = "particle"
    else:
        m = row_sums(basis, rho)
        where = "dof"
    bad = np.flatnonzero(~(m > 1e-12 * np.abs(m).max(initial=0.0)))
    if bad.size:
        d = getattr(basis, "particles", None)
        d = d.dim if d is not None else basis.mesh.dim()
        i = bad[0]
        raise ValueError(
            "lumped mass {:.3g} at {} {} ({} non-positive of {}), position "
            "({}): {}".format(m[i], where, i // d if where == "particle"
                            else i, bad.size, m.shape[0],
                            ", ".join("{:.6g}".format(c)
                                      for c in basis.doflocs[:, i]),
                            "a particle without volume" if where ==
                            "particle" else "row-sum lumping needs linear "
                            "elements (T1, Q1, O1, H1) or Q2/H2, not T2/O2"))
    return m


def _per(rho, n, what):
    rho = np.asarray(rho, dtype=float)
    if rho.ndim == 0:
        rho = np.full(n, float(rho))
    if rho.shape != (n,):
        raise ValueError("rho must be a number or one value per {} ({}), "
                         "got shape {}".format(what, n, rho.shape))
    if not np.all(rho > 0):
        raise ValueError("rho must be positive, got {} at {} {}".format(
            rho[~(rho > 0)][0], what, np.flatnonzero(~(rho > 0))[0]))
    return rho

