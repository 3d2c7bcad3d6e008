"""Checks of dof indices against a system size."""
import numpy as np


def as_dofs(D, N, what="Dirichlet dofs"):
    """Prescribed dofs as a sorted, unique int array, checked against the
    system size ``N``: a scikit-fem ``DofsView`` / ``Dofs``, or integer
    indices; booleans, negative, non-integer and out-of-range entries
    raise (``-1`` would silently address the last dof)."""
    if D is None:
        return np.zeros(0, dtype=np.int64)
    if hasattr(D, "flatten"):
        D = D.flatten()
    D = np.asarray(D).ravel()
    if D.size == 0:
        return np.zeros(0, dtype=np.int64)
    if D.dtype == bool:
        raise ValueError("{} must be indices, got a boolean array; use "
                         "np.flatnonzero(mask)".format(what))
    if not np.issubdtype(D.dtype, np.integer):
        if not np.issubdtype(D.dtype, np.floating) or np.any(
                D != np.round(D)):
            raise ValueError("{} must be integer indices, got {} values, "
                             "e.g. {!r}".format(what, D.dtype, D[0]))
    D = D.astype(np.int64)
    bad = (D < 0) | (D >= N)
    if np.any(bad):
        raise ValueError("{} must lie in 0..{} ({} in all); got {} (negative "
                         "indices are not accepted)".format(
                             what, N - 1, N, D[bad][:5]))
    return np.unique(D)
