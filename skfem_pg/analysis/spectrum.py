r"""Global eigenmode analysis of the free, unloaded tangent (thesis 7.2.1,
Fig. 7.6).

A stable discretization of a free body has exactly as many zero eigenvalues
as rigid-body modes (3 in 2-D, 6 in 3-D) and no *soft* deformation modes
below the lowest physical one.  Classical correspondence (U1: WTE1,
constant gradient per family) adds zero-energy and near-zero spurious modes.

:func:`free_modes` solves :math:`K\phi = \lambda M\phi` (``M`` lumped,
default identity), dense for small systems, shift-invert Lanczos/Arnoldi
otherwise; PPG tangents are non-symmetric (real parts are reported).
:func:`classify` counts zero and soft modes against a reference value, e.g.
the first deformation mode of an FE discretization of the same nodes.
"""
import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spl


def free_modes(K, M=None, n=None, dense_limit=3000, vectors=False):
    """Lowest ``n`` (default: all when dense, 30 otherwise) eigenvalues of
    :math:`K\\phi = \\lambda M\\phi`, ascending, normalized by the largest
    eigenvalue when dense (``"scale"`` entry); with ``vectors`` also the
    eigenvectors as columns.  ``M`` is a vector (lumped) or ``None``."""
    K = sp.csr_matrix(K)
    N = K.shape[0]
    Minv_sqrt = None if M is None else 1.0 / np.sqrt(np.asarray(M, float))
    if Minv_sqrt is not None:
        D = sp.diags(Minv_sqrt)
        K = (D @ K @ D).tocsr()
    symmetric = abs(K - K.T).max() <= 1e-12 * abs(K).max()
    if N <= dense_limit:
        A = K.toarray()
        if symmetric:
            lam, V = sla.eigh(0.5 * (A + A.T))
        else:
            lam, V = sla.eig(A)
            order = np.argsort(lam.real)
            lam, V = lam[order].real, V[:, order].real
        scale = float(np.abs(lam).max())
        if n is not None:
            lam, V = lam[:n], V[:, :n]
    else:
        n = 30 if n is None else n
        sigma = -1e-8 * abs(K).max()
        if symmetric:
            lam, V = spl.eigsh(K, k=n, sigma=sigma, which="LM")
        else:
            lam, V = spl.eigs(K, k=n, sigma=sigma, which="LM")
            lam, V = lam.real, V.real
        order = np.argsort(lam)
        lam, V = lam[order], V[:, order]
        scale = float(spl.eigsh(K if symmetric else 0.5 * (K + K.T), k=1,
                                which="LA", return_eigenvectors=False)[0])
    if Minv_sqrt is not None:
        V = Minv_sqrt[:, None] * V
    out = {"eigenvalues": lam, "scale": scale}
    if vectors:
        out["vectors"] = V
    return out


def classify(lam, scale, n_rigid, reference=None, zero_tol=1e-10,
             soft_factor=0.5):
    """Counts of ``zero`` eigenvalues (below ``zero_tol * scale``; those
    beyond ``n_rigid`` are ``spurious_zero``) and of ``soft`` ones:
    non-zero modes beyond the ``n_rigid`` lowest that lie
    below ``soft_factor * reference`` (e.g. FE's first deformation mode,
    same normalization)."""
    lam = np.asarray(lam)
    zero = int(np.sum(np.abs(lam) < zero_tol * scale))
    soft = 0
    if reference is not None:
        rest = lam[n_rigid:]
        soft = int(np.sum((np.abs(rest) >= zero_tol * scale)
                          & (rest < soft_factor * reference)))
    return {"zero": zero, "spurious_zero": max(zero - n_rigid, 0),
            "soft": soft, "first_deformation": float(lam[n_rigid])}
