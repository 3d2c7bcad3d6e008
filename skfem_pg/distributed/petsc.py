"""Rank-local matrices and vectors into distributed PETSc objects, and the
Krylov solvers on them.

The conversion is scikit-fem's (``COOData.topetsc``): the rank's local
matrix becomes the local block of a ``MATIS`` through a local-to-global
map, PETSc sums the overlapping contributions and converts to
``MATMPIAIJ``.  Here the global numbering is the partition's
(:class:`~skfem_pg.distributed.Partition`: owned particles contiguous per
rank), the row ownership is the partition's, and the block size is the
number of field components, which GAMG reads together with the
rigid-body near-null space.
"""
import numpy as np
import scipy.sparse as sp

from .comm import petsc

#: default Krylov tolerance (relative): tight enough that the Newton
#: solutions match the serial direct ones to 1e-10
RTOL = 1e-12


def _maps(part):
    """``(lgmap, iset)`` of the local dofs (cached on the partition)."""
    PETSc = petsc()
    key = ("maps", len(part.local), part.ncomp)
    cached = getattr(part, "_petsc_maps", None)
    if cached is None or cached[0] != key:
        g = part.l2g().astype(PETSc.IntType)
        comm = part.petsc_comm
        cached = (key, PETSc.LGMap().create(g, bsize=1, comm=comm),
                  PETSc.IS().createGeneral(g, comm=comm))
        part._petsc_maps = cached
    return cached[1], cached[2]


def matrix(A, part):
    """Distributed ``MATMPIAIJ`` of the rank-local matrices ``A`` (scipy
    sparse, local dofs) of all ranks, summed."""
    PETSc = petsc()
    A = sp.csr_matrix(A)
    it = PETSc.IntType
    loc = PETSc.Mat().createAIJ(size=A.shape, csr=(
        A.indptr.astype(it), A.indices.astype(it), A.data),
        comm=PETSc.COMM_SELF)
    lgmap, _ = _maps(part)
    n, N = part.n_owned_dofs, part.N
    M = PETSc.Mat().create(comm=part.petsc_comm)
    M.setSizes(((n, N), (n, N)), bsize=part.ncomp)
    M.setType(PETSc.Mat.Type.IS)
    M.setLGMap(lgmap)
    M.setISLocalMat(loc)
    M.assemble()
    M.convert("mpiaij")
    loc.destroy()
    return M


def empty_vector(part):
    """A zero distributed vector with the partition's row ownership."""
    PETSc = petsc()
    v = PETSc.Vec().createMPI((part.n_owned_dofs, part.N),
                              bsize=part.ncomp, comm=part.petsc_comm)
    v.set(0.0)
    return v


def vector(f, part):
    """Distributed vector of the rank-local vectors ``f`` (local dofs) of
    all ranks, summed."""
    PETSc = petsc()
    loc = PETSc.Vec().createWithArray(np.ascontiguousarray(f, dtype=float),
                                      comm=PETSc.COMM_SELF)
    v = empty_vector(part)
    _, iset = _maps(part)
    scat = PETSc.Scatter().create(loc, None, v, iset)
    scat.scatter(loc, v, addv=PETSc.InsertMode.ADD)
    scat.destroy()
    loc.destroy()
    return v


def from_serial(f, part):
    """Distributed vector of a vector in scikit-fem's serial numbering that
    every rank holds (e.g. loads assembled on the replicated mesh)."""
    f = np.asarray(f, dtype=float)
    if f.shape != (part.N,):
        raise ValueError("a serial vector has {} entries (the dofs of all "
                         "particles), got shape {}".format(part.N, f.shape))
    v = empty_vector(part)
    v.setArray(f[part.owned_serial_dofs()])
    return v


def to_local(v, part):
    """The local dofs' values (owned and halo) of a distributed vector, as
    a NumPy array in the local basis' numbering."""
    PETSc = petsc()
    _, iset = _maps(part)
    loc = PETSc.Vec().createSeq(len(part.local) * part.ncomp,
                                comm=PETSc.COMM_SELF)
    scat = PETSc.Scatter().create(v, iset, loc, None)
    scat.scatter(v, loc, addv=PETSc.InsertMode.INSERT)
    out = loc.getArray().copy()
    scat.destroy()
    loc.destroy()
    return out


def rigid_body_modes(part):
    """``MatNullSpace`` of the rigid-body modes of the owned particles
    (GAMG's near-null space); ``None`` for a scalar field."""
    PETSc = petsc()
    d = part.dim
    if part.ncomp != d:
        return None
    x = part.particles.x[:, part.owned].T.ravel()
    coords = PETSc.Vec().createMPI((len(x), d * part.n), bsize=d,
                                   comm=part.petsc_comm)
    coords.setArray(x)
    ns = PETSc.NullSpace().createRigidBody(coords)
    coords.destroy()
    return ns


def _options(prefix, options):
    """Put ``options`` (``"-ksp_type cg -pc_type gamg"`` or a dict
    without dashes) into PETSc's database under ``prefix``."""
    PETSc = petsc()
    if not options:
        return
    db = PETSc.Options()
    if isinstance(options, str):
        tokens = options.split()
        items, i = [], 0
        while i < len(tokens):
            key = tokens[i]
            if not key.startswith("-"):
                raise ValueError("PETSc options string: {!r} is not an "
                                 "option (options start with '-')"
                                 .format(key))
            value = None
            if i + 1 < len(tokens) and not _is_option(tokens[i + 1]):
                value = tokens[i + 1]
                i += 1
            items.append((key[1:], value))
            i += 1
    else:
        items = [(k.lstrip("-"), v) for k, v in dict(options).items()]
    for key, value in items:
        db[prefix + key] = "" if value is None else value


def _is_option(token):
    if not token.startswith("-"):
        return False
    try:  # a negative number is a value
        float(token)
        return False
    except ValueError:
        return True


def krylov(A, part, options=None, symmetric=True, prefix="skfem_pg_",
           rtol=RTOL):
    """A KSP on ``A``: CG (GMRES if not ``symmetric``) with GAMG and the
    rigid-body near-null space; ``options`` (a PETSc options string or a
    dict, e.g. ``"-ksp_type gmres -pc_type hypre"``) and the command line
    (``-skfem_pg_ksp_...``, ``-skfem_pg_pc_...``) override the defaults."""
    PETSc = petsc()
    ns = rigid_body_modes(part)
    if ns is not None:
        A.setNearNullSpace(ns)
    ksp = PETSc.KSP().create(comm=part.petsc_comm)
    ksp.setOptionsPrefix(prefix)
    ksp.setOperators(A)
    ksp.setType("cg" if symmetric else "gmres")
    ksp.getPC().setType("gamg")
    ksp.setTolerances(rtol=rtol, atol=0.0, max_it=5000)
    _options(prefix, options)
    ksp.setFromOptions()
    return ksp


def solve_ksp(ksp, b, part):
    """Solve with ``ksp``; raise naming the reason when it diverges.
    Returns ``(x, iterations)``."""
    x = empty_vector(part)
    ksp.solve(b, x)
    reason = ksp.getConvergedReason()
    if reason < 0:
        raise RuntimeError(
            "PETSc KSP {} with PC {} diverged (reason {}) after {} "
            "iterations; pass other options, e.g. "
            "options='-ksp_type preonly -pc_type lu' if PETSc has a "
            "parallel direct solver (MUMPS)".format(
                ksp.getType(), ksp.getPC().getType(), reason,
                ksp.getIterationNumber()))
    return x, ksp.getIterationNumber()
