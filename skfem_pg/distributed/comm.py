"""The optional MPI stack: mpi4py, petsc4py (and pymetis), imported on
first use with an error that names the extra which installs them."""

EXTRA = ("install the MPI extra: pip install 'skfem-pg[mpi]' (compiles "
         "PETSc), or on Debian/Ubuntu apt-get install python3-petsc4py "
         "python3-mpi4py and pip install pymetis (docs/guide/mpi.md)")


def mpi():
    """The ``mpi4py.MPI`` module."""
    try:
        from mpi4py import MPI
    except ImportError as err:
        raise ImportError("skfem_pg.distributed needs mpi4py: " + EXTRA) \
            from err
    return MPI


#: where Debian/Ubuntu's python3-petsc4py puts the module: its ``.pth``
#: looks under ``$PETSC_DIR`` (default ``/usr/lib/petsc``, a link only the
#: -dev package makes), so a plain ``import petsc4py`` fails without it
DEBIAN_PETSC4PY = "/usr/lib/petscdir/*/*-real/lib/python3/dist-packages"


def _debian_petsc4py():
    """The newest Debian petsc4py directory, or ``None``."""
    import glob
    import os
    found = [d for d in glob.glob(DEBIAN_PETSC4PY)
             if os.path.isdir(os.path.join(d, "petsc4py"))]
    return max(found) if found else None


def petsc():
    """The ``petsc4py.PETSc`` module (initialised).  Finds Debian's
    prebuilt petsc4py by itself when ``PETSC_DIR`` is not set."""
    import os
    import sys
    try:
        from petsc4py import PETSc
    except ImportError as err:
        where = _debian_petsc4py()
        if where is None or where in sys.path:
            raise ImportError("skfem_pg.distributed needs petsc4py: "
                              + EXTRA) from err
        os.environ.setdefault(
            "PETSC_DIR", where[:-len("/lib/python3/dist-packages")])
        sys.path.append(where)
        return petsc()
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


def raise_together(comm, error):
    """Raise on every rank of ``comm`` when one rank has an ``error`` (an
    exception, or ``None``): that rank raises its own, the others a
    ``RuntimeError`` naming it.  Call it where ranks are about to enter a
    collective the failing rank would never reach, so that none is left
    waiting (one ``allgather`` of the messages)."""
    messages = comm.allgather(None if error is None else "{}: {}".format(
        type(error).__name__, error))
    if error is not None:
        raise error
    for rank, message in enumerate(messages):
        if message is not None:
            raise RuntimeError("rank {} failed: {}".format(rank, message))
