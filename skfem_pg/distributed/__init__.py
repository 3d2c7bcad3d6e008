"""PG on PETSc/MPI: each rank builds and assembles the families of the
particles it owns; PETSc sums the ranks' parts and solves.

=================  =====================================================
``partition``      :class:`Partition`: METIS split of the particles, the
                   rank's families and local basis (owned + halo
                   particles), FE bases on a rank's cells, numbering,
                   PPG1's halo exchange
``vc``             the VC correction over ranks: the constraint system
                   of all ranks' families, solved on rank 0 or (GMRES)
                   on all ranks; the local VC of a rank's families
``petsc``          local matrices/vectors into distributed PETSc ones
                   (rows summed by their owners), KSP with GAMG and the
                   rigid-body near-null space, options strings
``solve``          linear solve and Newton's method on PETSc
``halo``           the halo exchange of a run on local vectors (sum to
                   the owners, copy back) and the reductions
``explicit``       central differences on ranks (the serial skeleton
                   with the exchange injected), per-rank checkpoints
``mass``           the lumped mass on a rank's local dofs
``io``             parallel VTU: a piece per rank and the ``.pvtu``
``comm``           the optional MPI stack (mpi4py, petsc4py, pymetis)
=================  =====================================================

Run a script on two ranks with ``mpirun -n 2 python script.py``; see
``demos/cook_mpi.py`` and the user guide's "MPI (PETSc)" page.
"""
from .comm import as_mpi
from .partition import Partition, metis_parts
from .solve import solve, newton
from .io import write_pvtu
from .halo import HaloExchange
from .explicit import central_difference
from .mass import lumped_mass
from . import petsc

__all__ = ["Partition", "metis_parts", "solve", "newton", "petsc",
           "as_mpi", "write_pvtu", "HaloExchange", "central_difference",
           "lumped_mass"]
