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


def check_sliding(basis, D):
    """Refuse sliding boundaries with the VC boundary variants ``s`` /
    ``sn`` (thesis 5.3; the default of the thesis' ``VCPBG`` names): they
    fix the corrections' boundary terms at the surface particles, and a
    particle with some but not all components prescribed then carries a
    spurious force — the linear patch test fails (a uniaxially compressed
    3-D block on a roller bottom: u_z 25 % off).  ``D`` are the prescribed
    dofs (interleaved components, as scikit-fem numbers them); raises
    naming a particle, returns ``None`` otherwise (other bases, other
    variants, no sliding dofs)."""
    if getattr(basis, "vc", None) is None or \
            getattr(basis, "vc_boundary", None) not in ("s", "sn"):
        return
    p = basis.particles
    d = basis.ncomp or 1
    if d == 1:
        return
    D = as_dofs(D, basis.N)
    count = np.bincount(D // d, minlength=p.n)
    active = np.zeros(p.n, dtype=bool)
    active[basis.families.masters] = True
    sliding = np.flatnonzero((count > 0) & (count < d) & active)
    if len(sliding):
        i = int(sliding[0])
        raise ValueError(
            "the VC boundary variant {!r} fails the patch test on sliding "
            "boundaries: particle {} at {} has {} of its {} components "
            "prescribed ({} such particles); use the min-norm variant "
            "('VCBCPBG V5m ...', 'VCBCPPG V3m ...') or 'p'".format(
                basis.vc_boundary, i, tuple(np.round(p.x[:, i], 12)),
                int(count[i]), d, len(sliding)))
