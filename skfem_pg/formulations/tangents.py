r"""Finite-difference tangent of PG internal forces (what correspondence
codes such as Peridigm do), for comparison with the consistent tangent.

The internal force of family ``k`` on its member ``i`` is

.. math:: f^k_i = \sum_j w_{kj}\, P(F^{kj})\, G^{kji}, \qquad
          F^{kj} = I + \sum_l u^l\otimes G^{kjl}.

Perturbing the displacement of member ``l`` in direction ``c`` by
:math:`\pm\varepsilon` changes :math:`F^{kj}` by
:math:`\pm\varepsilon\, e_c\otimes G^{kjl}` in every family at once, so a
central difference per local dof (``m·d`` stress evaluations, a loop over
local dofs, not over families) gives all local tangents; they are summed
into the sparse pattern like any other family matrix.
"""
import numpy as np

from ..discretization.assembly import assemble_local


def local_internal_forces(G, dx, P):
    """:math:`f^k_{i} = \\sum_j w_{kj} P^{kj} G^{kji}`, shape
    ``(nfc, m, d)``, for derivatives ``G`` ``(nfc, m, m, d)``, weights
    ``dx`` ``(nfc, m)`` and stresses ``P`` of shape ``(d, d, nfc, m)``."""
    Pt = np.moveaxis(P, (0, 1), (-2, -1))  # (k, j, a, J)
    GW = G * dx[:, :, None, None]  # (k, j, i, J)
    return (GW @ np.swapaxes(Pt, -1, -2)).sum(axis=1)  # (k, i, a)


def fd_tangent(basis, material, F, rel_step=1e-7):
    """Sparse tangent of the internal forces by central differences of the
    family forces; ``F`` is the deformation gradient at the members,
    ``(d, d, nf, m)`` padded or ``(d, d, 1, N_q)`` flat.  The perturbation
    is ``rel_step`` times the family radius, so that ``F`` changes by about
    ``rel_step``."""
    if basis.ncomp is None:
        raise ValueError("fd_tangent needs a vector basis (dim=d)")
    d = basis.ncomp
    h = np.asarray(basis.mesh_parameters())[:, 0]
    L = basis.layout
    dxs = basis.grouped_weights()

    def local_matrices(bi, block, sl):
        G, dx = block.G[sl], dxs[bi][sl]
        nfc, m = G.shape[:2]
        eps = rel_step * h[block.index[sl]]
        F0 = L.take(F, block.group)[:, :, sl]
        K = np.zeros((nfc, m, m, d, d))
        for l in range(m):
            for c in range(d):
                dF = np.zeros_like(F0)
                dF[c] = np.moveaxis(G[:, :, l, :], -1, 0) * eps[:, None]
                fp = local_internal_forces(G, dx, material.stress(F0 + dF))
                fm = local_internal_forces(G, dx, material.stress(F0 - dF))
                K[:, :, l, :, c] = (fp - fm) / (2 * eps[:, None, None])
        return K

    return assemble_local(basis, local_matrices)
