"""Rank-local matrices and vectors into distributed PETSc objects, and the
Krylov solvers on them.

Vectors take scikit-fem's route (``COOData.topetsc``): a scatter that
adds the rank-local entries into the distributed vector through the
local-to-global dof map.  Matrices are summed in CSR by the owners of
their rows (:func:`matrix`: scikit-fem's ``MATIS`` conversion was 100×
slower on family bases).  The global numbering is the partition's
(:class:`~skfem_pg.distributed.Partition`: owned particles contiguous per
rank), and the block size is the number of field components, which GAMG
reads together with the rigid-body near-null space.
"""
import numpy as np
import scipy.sparse as sp

from .comm import mpi, petsc
from ..errors import SingularSystemError
from ..solvers.linear import RIGID_MODE_TOL

#: GAMG's drop tolerance unless the options set one
GAMG_THRESHOLD = 0.05

#: iterations of the GMRES that takes over from a CG meeting an indefinite
#: tangent; beyond them the Newton step is cut instead
GMRES_FALLBACK_ITERATIONS = 500

#: default Krylov tolerance (relative): tight enough that the Newton
#: solutions match the serial direct ones to 1e-10
RTOL = 1e-12


def _iset(part):
    """PETSc index set of the local dofs' global numbers (cached on the
    partition)."""
    PETSc = petsc()
    key = (len(part.local), part.ncomp)
    cached = getattr(part, "_petsc_iset", None)
    if cached is None or cached[0] != key:
        cached = (key, PETSc.IS().createGeneral(
            part.l2g().astype(PETSc.IntType), comm=part.petsc_comm))
        part._petsc_iset = cached
    return cached[1]


def matrix(A, part):
    """Distributed ``MATMPIAIJ`` of the rank-local matrices ``A`` (scipy
    sparse, local dofs) of all ranks, summed.

    The rows of halo dofs go to their owners (one ``alltoall``); each
    rank sums its rows in CSR with global columns and hands them to
    ``MatCreateMPIAIJWithArrays`` — exact preallocation, no ``MatSetValues``
    (scikit-fem's ``MATIS`` route with ``MatConvert`` was about 100 times
    slower).
    """
    A = sp.coo_matrix(A)
    g = part.l2g()
    # an explicit (zero) diagonal in every owned row: PETSc's
    # MatZeroRowsColumns needs it, and a dof without stiffness is then
    # named by check_rigid_body_modes instead of failing there (error 73)
    own = g[:part.n_owned_dofs]  # the owned dofs come first (basis)
    return global_matrix(np.concatenate([g[A.row], own]),
                         np.concatenate([g[A.col], own]),
                         np.concatenate([A.data, np.zeros(len(own))]),
                         part, part.ncomp)


def global_matrix(rows, cols, data, part, ncomp):
    """Distributed ``MATMPIAIJ`` from entries with global (PETSc) row and
    column numbers, summed over all ranks; ``ncomp`` rows per particle
    (the block size), rows owned as the partition's particles."""
    PETSc = petsc()
    offsets = ncomp * part.offsets
    first = offsets[part.rank]
    n, N = offsets[part.rank + 1] - first, offsets[-1]
    mine = (rows >= first) & (rows < first + n)
    if part.size > 1:
        dest = np.searchsorted(offsets, rows[~mine], side="right") - 1
        order = np.argsort(dest, kind="stable")
        cuts = np.cumsum(np.bincount(dest, minlength=part.size))[:-1]
        send = [np.split(a[~mine][order], cuts)
                for a in (rows, cols, data)]
        got = part.comm.alltoall(list(zip(*send)))
        rows = np.concatenate([rows[mine]] + [q[0] for q in got])
        cols = np.concatenate([cols[mine]] + [q[1] for q in got])
        data = np.concatenate([data[mine]] + [q[2] for q in got])
    M = sp.csr_matrix((data, (rows - first, cols)), shape=(n, N))
    M.sum_duplicates()
    M.sort_indices()
    it = PETSc.IntType
    return PETSc.Mat().createAIJ(
        size=((n, N), (n, N)), bsize=ncomp,
        csr=(M.indptr.astype(it), M.indices.astype(it), M.data),
        comm=part.petsc_comm)


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
    iset = _iset(part)
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
    iset = _iset(part)
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
    (GAMG's near-null space; built once per partition); ``None`` for a
    scalar field."""
    PETSc = petsc()
    d = part.dim
    if part.ncomp != d:
        return None
    if getattr(part, "_rigid_body_modes", None) is None:
        x = part.particles.x[:, part.owned].T.ravel()
        coords = PETSc.Vec().createMPI((len(x), d * part.n), bsize=d,
                                       comm=part.petsc_comm)
        coords.setArray(x)
        part._rigid_body_modes = PETSc.NullSpace().createRigidBody(coords)
        coords.destroy()
    return part._rigid_body_modes


def _options(prefix, options):
    """Put ``options`` (``"-ksp_type cg -pc_type gamg"`` or a dict
    without dashes) into PETSc's database under ``prefix``; returns the
    keys set."""
    PETSc = petsc()
    if not options:
        return []
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
    return [prefix + key for key, _ in items]


def _is_option(token):
    if not token.startswith("-"):
        return False
    try:  # a negative number is a value
        float(token)
        return False
    except ValueError:
        return True


#: the options a KSP of :func:`krylov` was given, by its handle: kept in
#: PETSc's database until :func:`solve_ksp` has run (options such as
#: ``-ksp_view`` or ``-ksp_converged_reason`` act at the solve), then
#: checked for use and removed
_PENDING = {}


def _options_used():
    """PETSc's ``PetscOptionsUsed`` (not wrapped by petsc4py) through
    ctypes on the loaded libpetsc, or ``None`` where it cannot be found
    (then unused options go unreported)."""
    import ctypes
    try:
        with open("/proc/self/maps") as fh:
            libs = sorted({line.split()[-1] for line in fh
                           if "libpetsc" in line and ".so" in line})
        f = ctypes.CDLL(libs[0]).PetscOptionsUsed
    except (OSError, IndexError, AttributeError):
        return None
    f.argtypes = [ctypes.c_void_p, ctypes.c_char_p,
                  ctypes.POINTER(ctypes.c_int)]

    def used(key):
        flag = ctypes.c_int(0)
        return f(None, key.encode(), ctypes.byref(flag)) != 0 \
            or bool(flag.value)
    return used


def krylov(A, part, options=None, symmetric=True, prefix="skfem_pg_",
           rtol=RTOL):
    """A KSP on ``A``: CG (GMRES if not ``symmetric``) with GAMG (drop
    tolerance :data:`GAMG_THRESHOLD`) and the rigid-body near-null space,
    relative tolerance ``rtol``; ``options`` (a PETSc options string or a
    dict, e.g. ``"-ksp_type gmres -pc_type hypre"``) and the command line
    (``-skfem_pg_ksp_...``, ``-skfem_pg_pc_...``) override the defaults.

    An option PETSc rejects (``-ksp_type cgg``) raises ``ValueError``
    naming it; an option nothing reads (a typo, ``-ksp_tyep``) raises
    after :func:`solve_ksp`; either way this call's options leave PETSc's
    database, so no later solve inherits them."""
    PETSc = petsc()
    ns = rigid_body_modes(part)
    if ns is not None:
        A.setNearNullSpace(ns)
    ksp = PETSc.KSP().create(comm=part.petsc_comm)
    ksp.setOptionsPrefix(prefix)
    ksp.setOperators(A)
    ksp.setType("cg" if symmetric else "gmres")
    pc = ksp.getPC()
    pc.setType("gamg")
    ksp.setTolerances(rtol=rtol, atol=0.0, max_it=5000)
    db = PETSc.Options()
    added = _options(prefix, options)
    ours = []
    if not db.hasName(prefix + "pc_gamg_threshold"):
        # drop weak couplings: on the 3-D Cook (13k dofs) CG took 110
        # iterations and 6.1 s instead of 222 and 10.4 s (PETSc's 0)
        db[prefix + "pc_gamg_threshold"] = GAMG_THRESHOLD
        ours.append(prefix + "pc_gamg_threshold")
    try:
        ksp.setFromOptions()
        ksp.setUp()  # GAMG reads its levels' options here
    except PETSc.Error as err:
        for key in added + ours:
            db.delValue(key)
        ksp.destroy()
        raise ValueError("PETSc rejected the options {!r} ({})".format(
            options, str(err).strip().splitlines()[0])) from None
    for key in ours:  # the package's default is read at set-up
        db.delValue(key)
    _PENDING[ksp.handle] = added
    return ksp


def release_options(ksp):
    """Remove the options :func:`krylov` gave ``ksp`` from PETSc's
    database; raise ``ValueError`` naming those nothing read."""
    keys = _PENDING.pop(ksp.handle, [])
    if not keys:
        return
    used = _options_used()
    db = petsc().Options()
    unused = [k for k in keys if used is not None and not used(k)]
    for key in keys:
        db.delValue(key)
    if unused:
        raise ValueError(
            "PETSc did not use the options {} (misspelt, or not for KSP "
            "{} / PC {})".format(" ".join("-" + k[len("skfem_pg_"):]
                                           if k.startswith("skfem_pg_")
                                           else "-" + k for k in unused),
                                  ksp.getType(), ksp.getPC().getType()))


#: largest true relative residual ``|b - A x| / |b|`` a distributed solve
#: may return (``-ksp_type preonly -pc_type none`` returns 0.99)
TRUE_RESIDUAL_LIMIT = 1e-4


def check_rigid_body_modes(A, part, tol=None):
    """Raise :class:`~skfem_pg.errors.SingularSystemError` if ``A``
    (Dirichlet rows and columns lifted) has dofs without stiffness (a zero
    diagonal: named by particle and position, e.g. the vertices outside a
    PG element subset when the FE cells were not assembled) or leaves
    rigid-body modes without stiffness (``|A r| <= tol max|diag A| |r|``),
    saying how many (``tol``: :data:`~skfem_pg.solvers.linear.RIGID_MODE_TOL`,
    also the zero-diagonal bound)."""
    tol = RIGID_MODE_TOL if tol is None else tol
    diag = A.getDiagonal()
    d = diag.getArray()
    scale = part.comm.allreduce(float(np.abs(d).max(initial=0.0)),
                                op=mpi().MAX)
    diag.destroy()
    bad = part.owned_serial_dofs()[np.abs(d) <= tol * scale]
    bad = np.concatenate(part.comm.allgather(bad))
    if len(bad):
        p = np.unique(bad // part.ncomp)
        x = part.particles.x[:, p[0]]
        raise SingularSystemError(
            "{} dofs of the distributed system have no stiffness (zero "
            "diagonal), first particle {} at ({}){}: assemble the FE cells "
            "outside the PG elements (Partition.fe_assemble) or prescribe "
            "those dofs".format(
                len(bad), p[0], ", ".join("{:.4g}".format(c) for c in x),
                "" if len(p) == 1 else " ({} particles)".format(len(p))))
    ns = rigid_body_modes(part)
    if ns is None:
        return
    y = A.createVecLeft()
    free = 0
    vecs = ns.getVecs()
    for r in vecs:
        A.mult(r, y)
        if y.norm() <= tol * scale * r.norm():
            free += 1
    y.destroy()
    if free:
        raise SingularSystemError(
            "the distributed system has no stiffness against {} of its {} "
            "rigid-body modes: add Dirichlet conditions that hold them"
            .format(free, len(vecs)))


class KSPError(RuntimeError):
    """A PETSc Krylov solve diverged (``reason``: PETSc's code)."""

    def __init__(self, message, reason):
        super().__init__(message)
        self.reason = reason


#: KSP reasons of an indefinite operator or preconditioner (CG cannot go
#: on; GMRES can)
INDEFINITE = (-8, -10)


def solve_ksp(ksp, b, part):
    """Solve with ``ksp``; a CG that meets an indefinite matrix (a
    tangent far from equilibrium) is restarted as GMRES with the same
    preconditioner; raise naming the reason when it diverges.  Returns
    ``(x, iterations)``: all iterations, CG's included."""
    x = empty_vector(part)
    try:
        ksp.solve(b, x)
        its = ksp.getIterationNumber()
        reason = ksp.getConvergedReason()
        if reason in INDEFINITE and ksp.getType() == "cg":
            ksp.setType("gmres")
            ksp.setGMRESRestart(200)
            ksp.setTolerances(max_it=GMRES_FALLBACK_ITERATIONS)
            x.set(0.0)
            ksp.solve(b, x)
            its += ksp.getIterationNumber()
            reason = ksp.getConvergedReason()
    finally:
        release_options(ksp)
    if reason >= 0:  # converged by its own measure: check the true one
        A = ksp.getOperators()[0]
        r = b.duplicate()
        A.mult(x, r)
        r.aypx(-1.0, b)
        nb = b.norm()
        rel = r.norm() / nb if nb > 0 else r.norm()
        r.destroy()
        if not rel <= TRUE_RESIDUAL_LIMIT:
            raise KSPError(
                "PETSc KSP {} with PC {} stopped after {} iterations with a "
                "true relative residual {:.3g} > {:g}: not a solution "
                "(options?)".format(ksp.getType(), ksp.getPC().getType(),
                                    its, rel, TRUE_RESIDUAL_LIMIT), reason)
    if reason < 0:
        raise KSPError(
            "PETSc KSP {} with PC {} diverged (reason {}) after {} "
            "iterations; pass other options, e.g. "
            "options='-ksp_type preonly -pc_type lu' if PETSc has a "
            "parallel direct solver (MUMPS)".format(
                ksp.getType(), ksp.getPC().getType(), reason,
                ksp.getIterationNumber()), reason)
    return x, its
