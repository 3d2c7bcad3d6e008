r"""Particles split among MPI ranks, and each rank's part of the basis.

Every rank holds the mesh and the particle geometry (positions, volumes,
area vectors: :math:`2d + 1` numbers per particle, cheap next to the
families).  METIS (pymetis, the partitioner behind scikit-fem's
``Dofs.decompose``) splits the particles along the mesh's vertex graph;
rank ``r`` *owns* the particles of its part and the families they master.

A rank builds only what its own families need: the families themselves
(from the cells within four rings of its particles, which reach every
member and the up to three rings of enlargement of
:func:`~skfem_pg.discretization.families.from_mesh`), their shape
derivatives, bond and VC corrections, forms and matrices.  The members of
its families that other ranks own — one ring of particles — are its
*halo*.  The rank's :class:`~skfem_pg.FamilyBasis` lives on the local
particles ``owned + halo`` (in that order), with its own dof numbering
``d·p + c``.

Numbering (what PETSc sees): particles are renumbered rank by rank, owned
particles in ascending order, so that rank ``r`` owns the contiguous
PETSc rows of its particles (``d`` per particle, interlaced as in
scikit-fem).  :meth:`Partition.l2g` maps local dofs to these global dofs,
:meth:`Partition.gather` brings a distributed vector back to scikit-fem's
serial numbering on every rank.

The VC correction couples all families through one sparse system
(:func:`~skfem_pg.discretization.vc.first_order.vc_correction`).  Its pieces
are rank-local — each rank's families give their columns of the scalar
constraint matrix :math:`\Phi^T`, their :math:`B^k` and their part of
the residual, summed over ranks — and rank 0 solves the assembled system
with the serial code (:func:`solve_pinned_lu`, the same pivoting LU and
minimum-norm projection), then broadcasts :math:`\alpha`.  So the
distributed VC basis *is* the serial one up to the order of floating-point
sums (tests: 1e-12).  The price is a scalar :math:`n \times n` system on
rank 0, :math:`d^3` times cheaper than the block system (AMG above 15k
particles, ``vc_solver="amg"``).  With
``vc_solver="petsc"`` no rank holds more than its own families: the same
pinned system is solved on all ranks by GMRES
(:mod:`~skfem_pg.distributed.vc`; equal to the serial basis to 1e-12 in
the tests) — many times slower than rank 0's solve
(benchmarks/README.md, "Measurements behind the defaults"), so it is
the choice only where rank 0's memory is the limit.
"""
import copy
import hashlib

import numpy as np
import scipy.sparse as sp
import skfem as fem

from ..discretization import families as families_mod
from ..discretization import petrov
from ..discretization import recipes
from ..discretization.moment_quadrature import family_options, hat_moments
from ..discretization.basis import FamilyBasis
from ..discretization.builder import BasisSpec
from ..discretization.families import Families
from ..discretization.particles import Particles
from ..errors import FamilyError, describe_particle
from .comm import as_mpi, petsc, raise_together
from .vc import local_solver, vc_correction

#: cell rings around the owned particles from which their families are
#: built: one for the family, three for from_mesh's enlargement
RINGS = 4


def _require_same(comm, what, *arrays):
    """Raise naming the ranks whose ``arrays`` differ from rank 0's (every
    rank must hold the same mesh: a rank with another one would build
    families that do not fit the others')."""
    h = hashlib.sha256()
    for a in arrays:
        a = np.ascontiguousarray(a)
        h.update(repr((a.dtype.str, a.shape)).encode())
        h.update(a.tobytes())
    digests = comm.allgather(h.hexdigest())
    other = [r for r, d in enumerate(digests) if d != digests[0]]
    if other:
        raise ValueError(
            "every rank must hold the same {}: rank{} {} differ{} from rank "
            "0's (build it the same way on every rank, or broadcast it)"
            .format(what, "s" if len(other) > 1 else "",
                    ", ".join(map(str, other)),
                    "" if len(other) > 1 else "s"))


def _vertex_graph(mesh):
    """``(E, A)``: vertex–cell incidence (vertices × cells) and the vertex
    adjacency of the mesh (no diagonal)."""
    t = mesh.t
    nv, ne = mesh.nvertices, t.shape[1]
    E = sp.csr_matrix((np.ones(t.size, dtype=bool),
                       (t.ravel(), np.tile(np.arange(ne), t.shape[0]))),
                      shape=(nv, ne))
    A = (E @ E.T).astype(bool).tolil()
    A.setdiag(False)
    return E, A.tocsr()


def metis_parts(mesh, nparts):
    """Owner rank of each mesh vertex: METIS (pymetis ``part_graph``) on
    the vertex graph, balanced in vertex count."""
    if nparts == 1:
        return np.zeros(mesh.nvertices, dtype=np.int64)
    try:
        import pymetis
    except ImportError as err:  # pragma: no cover - the extra installs it
        raise ImportError("partitioning needs pymetis: pip install "
                          "'skfem-pg[mpi]'") from err
    _, A = _vertex_graph(mesh)
    A.sort_indices()
    if hasattr(pymetis, "CSRAdjacency"):  # pymetis >= 2025
        _, parts = pymetis.part_graph(nparts, adjacency=pymetis.CSRAdjacency(
            A.indptr, A.indices))
    else:
        _, parts = pymetis.part_graph(nparts, xadj=A.indptr,
                                      adjncy=A.indices)
    return np.asarray(parts, dtype=np.int64)


def _subset(fam, keep):
    """The families of ``fam`` whose master satisfies ``keep`` (a boolean
    array over particles), in the same order."""
    idx = np.nonzero(keep[fam.masters])[0]
    sizes = fam.sizes[idx]
    offsets = np.concatenate([[0], np.cumsum(sizes)])
    take = (np.repeat(fam.offsets[idx] - offsets[:-1], sizes)
            + np.arange(offsets[-1]))
    return Families(offsets, fam.members[take], fam.n_particles)


class Partition:
    """The particles of ``mesh`` split among the ranks of ``comm``.

    Parameters
    ----------
    mesh
        A linear scikit-fem mesh (the same on every rank).
    comm
        ``mpi4py`` or ``petsc4py`` communicator (default: the world).
    elements
        Optional element subset whose vertices are the particles (the PG
        part of an FE–PG coupled model, as in
        :meth:`~skfem_pg.Particles.from_mesh`); all vertices are
        partitioned, so FE dofs have owners too.
    owner
        Optional owner rank per vertex (default: METIS).
    fe_elements
        The FE cells of a coupled model (default: the cells outside
        ``elements``, none without it).  Rank ``r`` assembles the FE
        cells whose first vertex it owns (:meth:`fe_assemble`).

    Attributes
    ----------
    particles
        The global :class:`~skfem_pg.Particles` (replicated geometry).
    owner
        ``(n,)`` rank owning each particle.
    owned
        This rank's particles (global indices, ascending).
    petsc_index
        ``(n,)`` PETSc particle index of each particle.
    """

    def __init__(self, mesh, comm=None, elements=None, owner=None,
                 fe_elements=None):
        self.comm = as_mpi(comm)
        self.rank, self.size = self.comm.rank, self.comm.size
        _require_same(self.comm, "mesh", mesh.p, mesh.t)
        if elements is not None:
            _require_same(self.comm, "elements",
                          np.asarray(mesh.normalize_elements(elements)))
        self.mesh = mesh
        self.particles = Particles.from_mesh(mesh, elements=elements)
        n = self.particles.n
        if owner is None:
            owner = metis_parts(mesh, self.size) if self.rank == 0 else None
            owner = self.comm.bcast(owner, root=0)
        owner = np.asarray(owner, dtype=np.int64)
        if owner.shape != (n,) or owner.min() < 0 or \
                owner.max() >= self.size:
            raise ValueError("owner must give a rank in 0..{} for each of "
                             "the {} particles".format(self.size - 1, n))
        empty = np.setdiff1d(np.arange(self.size), owner)
        if len(empty):
            raise ValueError("rank {} owns no particle: {} particles are "
                             "too few for {} ranks".format(empty[0], n,
                                                           self.size))
        self.owner = owner
        order = np.lexsort((np.arange(n), owner))
        self.petsc_index = np.empty(n, dtype=np.int64)
        self.petsc_index[order] = np.arange(n)
        self.counts = np.bincount(owner, minlength=self.size)
        self.offsets = np.concatenate([[0], np.cumsum(self.counts)])
        self.owned = np.nonzero(owner == self.rank)[0]
        if fe_elements is None:
            fe = (np.zeros(0, dtype=np.int64) if elements is None else
                  np.setdiff1d(np.arange(mesh.nelements),
                               self.particles.elements))
        else:
            fe = np.asarray(mesh.normalize_elements(fe_elements),
                            dtype=np.int64)
        self.fe_cells = fe[owner[mesh.t[0, fe]] == self.rank]
        self._E = None
        self._area = None

    # -- geometry ----------------------------------------------------------
    @property
    def dim(self):
        return self.particles.dim

    @property
    def n(self):
        """Number of particles (all ranks)."""
        return self.particles.n

    def area_vectors(self):
        """Global FE-consistent area vectors (computed once)."""
        if self._area is None:
            self._area = self.particles.area_vectors()
        return self._area

    def ring_cells(self, rings=RINGS):
        """The cells within ``rings`` rings of the owned particles (the PG
        element subset only, if one was given)."""
        if self._E is None:
            self._E = _vertex_graph(self.mesh)[0]
        E, t = self._E, self.mesh.t
        cells = np.unique(E[self.owned].indices)
        for _ in range(rings - 1):
            cells = np.unique(E[np.unique(t[:, cells])].indices)
        pel = self.particles.elements
        return cells if pel is None else np.intersect1d(cells, pel)

    # -- families and the local basis ---------------------------------------
    def families(self, min_size=None, pairwise=False, order=1):
        """The families of the owned masters, in global particle numbers
        (mesh connectivity, as
        :func:`~skfem_pg.discretization.families.from_mesh`); with
        ``pairwise`` completed as
        :func:`~skfem_pg.discretization.petrov.pairwise` (from the
        families of twice as many rings: every family that may hold an
        owned particle); ``order=2``: enlarged until they determine a
        quadratic fit (the moment quadrature's)."""
        ring = families_mod.from_mesh(
            self.mesh, elements=self.ring_cells(2 * RINGS if pairwise
                                                else RINGS),
            min_size=min_size, order=order)
        if pairwise:
            ring = petrov.pairwise(ring)
        return _subset(ring, self._owned_active())

    def _owned_active(self):
        """Boolean over the particles: owned by this rank, and active."""
        mine = np.zeros(self.n, dtype=bool)
        mine[self.owned] = True
        return mine & self.particles.active

    def restricted(self, elements):
        """This partition with its particles collocated from the cells
        ``elements`` alone (a subset of its PG cells: the intact cells of
        a crack, :mod:`~skfem_pg.formulations.crack_aware`): the same
        owners and PETSc numbering; a vertex of no kept cell stays, with
        zero volume.  Its :meth:`basis` with ``local=`` the first basis'
        local particles shares that basis' dofs."""
        cells = np.asarray(elements, dtype=np.int64)
        pel = self.particles.elements
        if pel is not None and not np.isin(cells, pel).all():
            raise ValueError("restricted: cell {} is not one of the "
                             "partition's PG cells".format(
                                 cells[~np.isin(cells, pel)][0]))
        sub = copy.copy(self)
        sub.particles = Particles.from_mesh(self.mesh, elements=cells)
        sub._area = None
        sub._hat = None
        return sub

    def basis(self, families=None, local=None, **options):
        """This rank's :class:`~skfem_pg.FamilyBasis`: its owned families on
        its local particles (owned, then halo).  ``options`` are those of
        ``FamilyBasis`` (``shape``, ``bond``, ``vc``, ``dim``, ...);
        ``families``: global-numbered families of the owned masters
        (default :meth:`families`); ``local``: the local particles to
        build on (default: the owned ones and the members of their
        families; a basis rebuilt on fewer cells keeps the first one's,
        and a member outside them raises :class:`FamilyError`).  Sets
        :attr:`local` (local → global particle; a partition holds one
        local numbering, the last basis') and returns the basis."""
        method = options.get("method", "PBG")
        moments = options.get("family_quadrature") == "moments"
        # what the parts of the basis support on ranks (one table:
        # skfem_pg.discretization.parts), before any family is built
        BasisSpec.resolve(self.particles, families=families, **{
            k: v for k, v in options.items() if k != "area_vectors"}
        ).require("mpi", "on MPI")
        rule = ("moments" if moments and families is None
                else self._family_rule(families, method, options))
        fam = error = None
        try:  # an error here is raised on every rank (no rank left waiting)
            if rule == "moments":  # the serial default_families, per rank
                fam = self.families(**family_options(self.particles.dim))
            else:
                fam = (families if rule is None
                       else self.families(pairwise=method == "PPG1")
                       if rule == "mesh" else self.nearest_families())
            local = self._local_particles(fam, local)
        except Exception as err:  # noqa: BLE001 - raised on every rank
            error = err
        raise_together(self.comm, error)
        index = np.full(self.n, -1, dtype=np.int64)
        index[local] = np.arange(len(local))
        self.local = local
        masters = np.sort(np.concatenate(self.comm.allgather(fam.masters)))
        self._family_index = np.full(self.n, -1, dtype=np.int64)
        self._family_index[masters] = np.arange(len(masters))
        self._masters = masters
        p = self.particles
        # an element subset, even empty, lets owned FE-only vertices
        # (zero volume) stay in the local set; the families skip them
        lp = Particles(p.x[:, local], p.volumes[local],
                       elements=np.arange(0))
        lfam = Families(fam.offsets, index[fam.members], len(local))
        if options.get("vc", "auto") is not None:
            options.setdefault("area_vectors", self.area_vectors()[:, local])
        basis = FamilyBasis(lp, lfam, distributed=self, **options)
        self.ncomp = 1 if basis.ncomp is None else int(basis.ncomp)
        return basis

    def _family_rule(self, families, method, options):
        """The family rule of :meth:`basis` (``None`` for given families),
        the serial keyword defaults filled into ``options``: without
        ``families`` the recipe serial :class:`~skfem_pg.FamilyBasis`
        takes on these particles
        (:func:`~skfem_pg.discretization.recipes.default_recipe`), its
        quadrature weights and bond weight exponent too, so that a run
        on ranks repeats the serial one; a named rule its own weights."""
        if families is not None and not isinstance(families, str):
            return None
        if families is None:
            families, w, n = recipes.RECIPES[recipes.default_recipe(
                self.particles, method, options.get("shape", "MTE1"))]
        else:
            w, n = recipes.weights_of_rule(families)
        if method != "PBG":  # PPG integrates with the member volumes
            return families
        for key, value in (("weights", w), ("weight_exponent", n)):
            if options.get(key, "auto") in (None, "auto"):
                options[key] = value
        return families

    def hat_moments(self, local=False):
        """:func:`~skfem_pg.discretization.moment_quadrature.hat_moments`
        of the whole body (computed once, on every rank: the mesh is
        replicated); ``local``: restricted to :attr:`local`, what a rank's
        basis with ``family_quadrature="moments"`` integrates."""
        if getattr(self, "_hat", None) is None:
            self._hat = hat_moments(self.particles)
        if not local:
            return self._hat
        return tuple(a[self.local] for a in self._hat)

    def nearest_families(self):
        """The families of the owned masters by the ``"nearest"`` rule
        (:data:`~skfem_pg.discretization.families.NEAREST` neighbours,
        pairwise, with ties), in global particle numbers: built on the
        replicated particle positions, so the same as serial."""
        return _subset(families_mod.build("nearest", self.particles),
                       self._owned_active())

    def _local_particles(self, fam, local=None):
        """The local particles of a basis of the families ``fam``: owned,
        then halo (the members of ``fam`` and the vertices of the FE cells
        owned elsewhere), or ``local`` checked."""
        if np.any(self.owner[fam.masters] != self.rank):
            raise ValueError("a rank's basis holds the families of its "
                             "owned masters only")
        if local is None:
            halo = np.setdiff1d(np.union1d(fam.members,
                                           self.mesh.t[:, self.fe_cells]),
                                self.owned)
            return np.concatenate([self.owned, halo])
        local = np.asarray(local, dtype=np.int64)
        if not np.array_equal(local[:len(self.owned)], self.owned):
            raise ValueError("local particles must start with the "
                             "rank's owned ones, in order")
        outside = ~np.isin(fam.members, local)
        if outside.any():
            f = np.searchsorted(fam.offsets, np.flatnonzero(outside)[0],
                                side="right") - 1
            j, k = fam.members[outside][0], fam.masters[f]
            raise FamilyError(
                "the family of {} reaches {}, beyond the rank's local "
                "particles of the first basis".format(
                    describe_particle(k, self.particles.x[:, k]),
                    describe_particle(j, self.particles.x[:, j])))
        return local

    def fe_basis(self, element):
        """This rank's scikit-fem basis of ``element`` (linear: T1, Q1,
        O1, H1, vectorial) on the partition's FE cells that the rank
        assembles, on a mesh of its local vertices (owned, then the other
        vertices of its cells), so that the dofs are the local ones of
        :class:`~skfem_pg.distributed.halo.HaloExchange` (an FE model run
        on ranks).  Like :meth:`basis`, sets :attr:`local` (and
        ``ncomp``): the partition holds the last basis' numbering."""
        mesh, cells = self.mesh, self.fe_cells
        if len(cells) == 0:
            raise ValueError("rank {} assembles no FE cell (the partition's "
                             "fe_elements: a cell goes to the owner of its "
                             "first vertex)".format(self.rank))
        halo = np.setdiff1d(mesh.t[:, cells], self.owned)
        local = np.concatenate([self.owned, halo])
        index = np.full(self.n, -1, dtype=np.int64)
        index[local] = np.arange(len(local))
        sub = type(mesh)(mesh.p[:, local], index[mesh.t[:, cells]])
        basis = fem.Basis(sub, element)
        nc = basis.N // max(len(local), 1)
        if nc * len(local) != basis.N:
            raise ValueError("fe_basis takes linear elements (one dof per "
                             "vertex and component): {} has {} dofs on {} "
                             "vertices".format(type(element).__name__,
                                               basis.N, len(local)))
        self.local = local
        self.ncomp = nc
        return basis

    # -- FE cells of a coupled model ------------------------------------------
    def fe_assemble(self, form, element, **kwargs):
        """The rank's part of an FE form on its FE cells
        (``fe_elements``), in the local numbering of :meth:`basis`: the
        form assembled on ``skfem.Basis(mesh, element, elements=...)``
        and restricted to the local dofs; zero on a rank without FE
        cells.  Add it to the family basis' local matrix or vector."""
        nc = self.ncomp
        loc = self.local_serial_dofs()
        if len(self.fe_cells) == 0:
            if isinstance(form, fem.BilinearForm):
                return sp.csr_matrix((len(loc), len(loc)))
            return np.zeros(len(loc))
        basis = fem.Basis(self.mesh, element, elements=self.fe_cells)
        if basis.N != nc * self.n:
            raise ValueError("the FE element has {} dofs, the particles {} "
                             "({} per particle)".format(basis.N,
                                                        nc * self.n, nc))
        A = form.assemble(basis, **kwargs)
        if sp.issparse(A):
            return A.tocsr()[loc][:, loc]
        return np.asarray(A)[loc]

    # -- the VC correction, assembled over ranks -----------------------------
    def sum_ranks(self, a):
        """The array ``a`` (same shape on every rank) summed over the
        ranks, on every rank."""
        from mpi4py import MPI
        out = np.array(a)
        self.comm.Allreduce(MPI.IN_PLACE, out, op=MPI.SUM)
        return out

    def sum_particles(self, r):
        """Per-particle arrays of the local particles ``(n_local, ...)``
        summed over all ranks into ``(n, ...)`` on every rank."""
        out = np.zeros((self.n,) + r.shape[1:])
        out[self.local] = r  # each local particle once
        return self.sum_ranks(out)

    def vc_correction(self, *args, **kwargs):
        """:func:`skfem_pg.distributed.vc.vc_correction` on this partition
        (what a rank's :class:`~skfem_pg.FamilyBasis` calls)."""
        return vc_correction(self, *args, **kwargs)

    def local_vc_solver(self):
        """The ``vc_solve`` of a rank's basis with ``vc_solver="local"``
        (:func:`skfem_pg.distributed.vc.local_solver`)."""
        return local_solver(self)

    # -- PPG1: test derivatives from the halo's families ---------------------
    def reverse_master_derivatives(self, Gt, fam):
        r"""``g[f, q]`` :math:`= G_t^{kkf}`: the master derivative of the
        family of member ``k = mem[f, q]`` with respect to master ``f``
        (``Gt``: ``(nf, m, d)`` master derivatives of the rank's families,
        ``fam`` its local families).  Families of halo members live on
        their owners: the pairs are requested from them and answered
        (two ``alltoall`` exchanges)."""
        mem, mask = fam.padded()
        n, d = self.n, Gt.shape[-1]
        gm = self.local[mem]
        gf = np.broadcast_to(self.local[fam.masters][:, None], mem.shape)
        want_fam, want_mem = gm[mask], gf[mask]
        dest = self.owner[want_fam]
        order = np.argsort(dest, kind="stable")
        cuts = np.cumsum(np.bincount(dest, minlength=self.size))[:-1]
        asked = self.comm.alltoall(
            np.split(np.stack([want_fam, want_mem])[:, order], cuts,
                     axis=1))
        keys = (gf * n + gm)[mask]
        srt = np.argsort(keys)
        values = Gt[mask][srt]
        answers = []
        for q in asked:
            key = q[0] * n + q[1]
            pos = np.minimum(np.searchsorted(keys[srt], key), len(srt) - 1)
            bad = keys[srt][pos] != key
            if np.any(bad):
                raise ValueError(
                    "families are not pairwise across ranks: particle {} "
                    "is in the family of particle {} but not the other "
                    "way round".format(q[0][bad][0], q[1][bad][0]))
            answers.append(values[pos])
        got = self.comm.alltoall(answers)
        g = np.zeros(mem.shape + (d,))
        flat = np.empty((len(order), d))
        flat[order] = np.concatenate(got) if got else flat
        g[mask] = flat
        return g

    # -- numbering ---------------------------------------------------------
    @property
    def n_owned_dofs(self):
        return self.ncomp * len(self.owned)

    @property
    def N(self):
        """Number of dofs (all ranks)."""
        return self.ncomp * self.n

    def l2g(self, local_dofs=None):
        """PETSc global dofs of local dofs (default: all local dofs)."""
        nc = self.ncomp
        g = (nc * self.petsc_index[self.local][:, None]
             + np.arange(nc)).ravel()
        return g if local_dofs is None else g[np.asarray(local_dofs)]

    def serial_to_petsc(self, dofs):
        """PETSc global dofs of serial (scikit-fem) dofs (PETSc's integer
        type)."""
        dofs = np.asarray(dofs, dtype=np.int64)
        p, c = np.divmod(dofs, self.ncomp)
        return (self.ncomp * self.petsc_index[p] + c).astype(
            petsc().IntType)

    def owned_serial_dofs(self):
        """The serial dofs this rank owns, in PETSc order."""
        nc = self.ncomp
        return (nc * self.owned[:, None] + np.arange(nc)).ravel()

    def local_serial_dofs(self):
        """The serial dofs of the local particles, in local order."""
        nc = self.ncomp
        return (nc * self.local[:, None] + np.arange(nc)).ravel()

    def gather(self, vec):
        """A distributed PETSc vector in scikit-fem's serial numbering,
        as a NumPy array on every rank."""
        parts = self.comm.allgather(vec.getArray().copy())
        out = np.empty(self.N)
        nc = self.ncomp
        order = np.argsort(self.petsc_index)  # PETSc particle -> serial
        flat = np.concatenate(parts).reshape(-1, nc)
        out.reshape(-1, nc)[order] = flat
        return out

    @property
    def petsc_comm(self):
        return petsc().Comm(self.comm)
