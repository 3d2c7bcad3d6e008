r"""What a time integrator asks of the communication between the parts of
a model: the serial run's answers (this module); a run on MPI ranks
injects a halo exchange with the same methods (issue 32, in progress).

One time-stepping skeleton (:func:`skfem_pg.solvers.central_difference`)
serves both: it works on the vectors of the model it is given (serial:
all dofs; on a rank: the rank's local dofs, owned then halo) and calls

* ``complete(f)``: the rank's contributions summed over all ranks at
  every local dof (internal forces, matrix–vector products);
* ``dot(a, b, idx)``, ``dots(V, w)``, ``sum``, ``min``, ``max``, ``any``: reductions
  over the ranks (energies, the minimum J, the stable step);
* ``first(message)``: an error on one rank stops every rank;
* ``start_vector()``: the Lanczos start vector as a function of the
  serial dof numbers, so that serial and distributed estimates of the
  stable step agree to round-off;
* ``root``: whether this part prints progress.
"""
import numpy as np


def start_vector(dofs):
    """Deterministic entries in [0.5, 1.5) from the (serial) dof numbers
    ``dofs`` (a hash-like function: no dof ordering is preferred)."""
    x = np.asarray(dofs, dtype=np.float64)
    return 1.0 + 0.5 * np.sin(12.9898 * x + 78.233 * np.sin(0.1 * x))


class SerialExchange:
    """The serial run: nothing to exchange, sums over all dofs."""

    root = True

    def __init__(self, n):
        self.n = int(n)

    @staticmethod
    def complete(f):
        return f

    @staticmethod
    def dot(a, b, idx=None):
        if idx is None:
            return float(np.dot(a, b))
        return float(np.dot(a[idx], b[idx]))

    @staticmethod
    def dots(V, w):
        """The dot products of each vector of ``V`` with ``w``."""
        return np.array([np.dot(q, w) for q in V])

    @staticmethod
    def sum(x):
        return None if x is None else float(x)

    @staticmethod
    def min(x):
        return float(x)

    @staticmethod
    def max(x):
        return float(x)

    @staticmethod
    def any(flag):
        return bool(flag)

    @staticmethod
    def first(message):
        return message

    def start_vector(self):
        return start_vector(np.arange(self.n))
