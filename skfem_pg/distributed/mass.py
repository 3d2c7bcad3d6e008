"""The lumped mass on a rank's local dofs, for explicit runs on ranks
(:func:`skfem_pg.distributed.central_difference`)."""
import numpy as np

from ..discretization.layout import is_family_basis
from ..solvers.mass import lumped_mass as serial_lumped_mass, row_sums
from .halo import HaloExchange


def lumped_mass(basis, part, rho):
    """The diagonal mass on the rank's local dofs: a family basis from
    :meth:`Partition.basis` (:math:`\\rho_0 V^k` per particle: complete
    as it is) or an FE basis from :meth:`Partition.fe_basis` (the row sums
    of the rank's cells, summed over the ranks).  ``rho``: a number, or
    one value per particle / per element of the mesh (serial
    numbering)."""
    rho = np.asarray(rho, dtype=float)
    if is_family_basis(basis):
        if rho.ndim == 1 and rho.shape[0] == part.n:
            rho = rho[part.local]
        return serial_lumped_mass(basis, rho)
    if rho.ndim == 1 and rho.shape[0] == part.mesh.nelements:
        rho = rho[part.fe_cells]
    nc = basis.N // len(part.local)
    m = HaloExchange(part, nc).complete(row_sums(basis, rho))
    bad = np.flatnonzero(~(m > 0))
    if bad.size:
        raise ValueError("lumped mass {:.3g} at particle {} (serial "
                         "numbering): row-sum lumping needs linear elements"
                         .format(m[bad[0]], part.local[bad[0] // nc]))
    return m


__all__ = ["lumped_mass"]
