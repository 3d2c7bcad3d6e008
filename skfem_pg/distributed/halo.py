r"""The communication of a run on ranks whose vectors live on the local
particles (owned, then halo; :meth:`Partition.basis`): a family's
contributions to its members are summed to their owners, and the owners'
sums are copied back to every rank that holds the particle as halo.

After :meth:`HaloExchange.complete` a local vector holds at every local
dof — owned or halo — the same value as the serial vector at that dof
(up to the order of the floating-point sums), so the time integration
proceeds on all local dofs alike and the halo copies stay equal to their
owners' values without a separate exchange of displacements.  Sums over
dofs (energies, dot products) count the owned dofs only.

Messages go to neighbour ranks only (those that share a particle), as
non-blocking point-to-point sends of NumPy buffers: one round halo →
owner (add), one round owner → halo (copy).  The owner adds its own part
first and the ranks' parts in rank order, so every rank gets the same
bits.
"""
import numpy as np

from .comm import mpi
from ..solvers.exchange import start_vector


class HaloExchange:
    """The exchange pattern of ``part``'s local particles (set by its last
    :meth:`~Partition.basis` or :meth:`~Partition.fe_basis`) for vectors of
    ``ncomp`` components per particle (interlaced, ``ncomp·p + c``).

    Attributes
    ----------
    owned_dofs
        ``True`` at the local dofs this rank owns (sums count these).
    """

    def __init__(self, part, ncomp):
        self.part, self.comm, self.nc = part, part.comm, int(ncomp)
        local, owner, rank = part.local, part.owner, part.rank
        index = np.full(part.n, -1, dtype=np.int64)
        index[local] = np.arange(len(local))
        halo = local[owner[local] != rank]
        # what this rank holds of each other rank's particles (global
        # indices, ascending), and what each other rank holds of its own
        self.recv_from = {}  # rank -> local positions of its particles
        for r in np.unique(owner[halo]):
            self.recv_from[int(r)] = index[halo[owner[halo] == r]]
        wanted = self.comm.alltoall([
            local[self.recv_from[r]] if r in self.recv_from else
            np.zeros(0, dtype=np.int64) for r in range(part.size)])
        self.send_to = {r: index[w] for r, w in enumerate(wanted)
                        if len(w) and r != rank}
        if any(np.any(p < 0) for p in self.send_to.values()):
            raise ValueError("a rank holds a halo particle whose owner does "
                             "not hold it: the partition's local sets are "
                             "inconsistent")
        self.owned_dofs = np.repeat(owner[local] == rank, self.nc)
        self.n_local = len(local)
        self.messages = 0  # point-to-point messages sent

    # -- helpers --------------------------------------------------------------
    def _dofs(self, particles):
        nc = self.nc
        return (nc * particles[:, None] + np.arange(nc)).ravel()

    def _exchange(self, send, recv, data):
        """Send ``data[send[r]]`` to each rank ``r`` and receive into
        buffers of ``recv[r]``'s size; returns ``{r: received}``."""
        MPI = mpi()
        tail = data.shape[1:]
        reqs, got = [], {}
        for r, pos in recv.items():
            buf = np.empty((len(pos) * self.nc,) + tail)
            got[r] = buf
            reqs.append(self.comm.Irecv(buf, source=r, tag=71))
        bufs = []
        for r, pos in send.items():
            buf = np.ascontiguousarray(data[self._dofs(pos)])
            bufs.append(buf)
            reqs.append(self.comm.Isend(buf, dest=r, tag=71))
            self.messages += 1
        MPI.Request.Waitall(reqs)
        return got

    # -- the operations a driver injects --------------------------------------
    def complete(self, f):
        """The local contributions ``f`` (one value per local dof, from this
        rank's families or cells) summed over all ranks: owners add what the
        others sent, then send the totals back to the halos."""
        f = np.array(f, dtype=float)
        got = self._exchange(self.recv_from, self.send_to, f)
        for r in sorted(got):
            f[self._dofs(self.send_to[r])] += got[r]
        back = self._exchange(self.send_to, self.recv_from, f)
        for r, vals in back.items():
            f[self._dofs(self.recv_from[r])] = vals
        return f

    def dot(self, a, b, idx=None):
        r""":math:`\sum a_i b_i` over all dofs of all ranks (owned local
        dofs only; ``idx``: a subset of local dofs)."""
        if idx is None:
            w = self.owned_dofs
            s = float(np.dot(a[w], b[w]))
        else:
            idx = np.asarray(idx)
            if idx.dtype == bool:
                idx = np.flatnonzero(idx)
            idx = idx[self.owned_dofs[idx]]
            s = float(np.dot(a[idx], b[idx]))
        return self.sum(s)

    def dots(self, V, w):
        """The dot products of each vector of ``V`` with ``w`` over all
        ranks (one reduction)."""
        w = np.where(self.owned_dofs, w, 0.0)
        local = np.array([np.dot(q, w) for q in V])
        out = np.empty_like(local)
        self.comm.Allreduce(local, out, op=mpi().SUM)
        return out

    def sum(self, x):
        """A number summed over the ranks (``None`` stays ``None``)."""
        if x is None:
            return None
        return float(self.comm.allreduce(float(x), op=mpi().SUM))

    def min(self, x):
        return float(self.comm.allreduce(float(x), op=mpi().MIN))

    def max(self, x):
        return float(self.comm.allreduce(float(x), op=mpi().MAX))

    def any(self, flag):
        return bool(self.comm.allreduce(bool(flag), op=mpi().LOR))

    def first(self, message):
        """The first rank's non-``None`` ``message`` (a collective error:
        every rank raises when one rank fails), or ``None``."""
        got = self.comm.allgather(message)
        for r, m in enumerate(got):
            if m is not None:
                return m if self.part.size == 1 else \
                    "rank {}: {}".format(r, m)
        return None

    @property
    def root(self):
        """Whether this rank prints (rank 0)."""
        return self.part.rank == 0

    def serial_dofs(self):
        """The serial (scikit-fem) dof of each local dof."""
        return self._dofs(self.part.local)

    def start_vector(self):
        """A start vector that is a function of the serial dof number only,
        so that every partition (and the serial run) starts the same
        Lanczos iterations."""
        return start_vector(self.serial_dofs())

