"""The optional MPI stack: mpi4py, petsc4py (and pymetis), imported on
first use with an error that names the extra which installs them."""

EXTRA = ("install the MPI extra: pip install 'skfem-pg[mpi]' (compiles "
         "PETSc), or on Debian/Ubuntu apt-get install python3-petsc4py "
         "python3-mpi4py and pip install pymetis (README, 'MPI')")


def mpi():
    """The ``mpi4py.MPI`` module."""
    try:
        from mpi4py import MPI
    except ImportError as err:
        raise ImportError("skfem_pg.distributed needs mpi4py: " + EXTRA) \
            from err
    return MPI


def petsc():
    """The ``petsc4py.PETSc`` module (initialised)."""
    try:
        from petsc4py import PETSc
    except ImportError as err:
        raise ImportError("skfem_pg.distributed needs petsc4py: " + EXTRA) \
            from err
    return PETSc


def as_mpi(comm=None):
    """An ``mpi4py`` communicator from ``comm`` (``mpi4py``, ``petsc4py``
    or ``None`` for the world)."""
    MPI = mpi()
    if comm is None:
        return MPI.COMM_WORLD
    if hasattr(comm, "tompi4py"):
        return comm.tompi4py()
    if isinstance(comm, MPI.Comm):
        return comm
    raise TypeError("comm must be an mpi4py or petsc4py communicator, got "
                    "{}".format(type(comm).__name__))
