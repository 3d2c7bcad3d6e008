r"""Boundary conditions of the VC correction system, thesis section 5.3
(Table 7.1: ``p``, ``s``, ``sn``).

The constraint system ``A α = b`` of a first-order VC correction
(:func:`~skfem_pg.discretization.vc.first_order.vc_correction`: rows = the
integration constraints (5.18) of the particles, ``d`` each; columns = the
correction factors :math:`\alpha^k` of the families, ``d`` each) is singular:
the consistency modes it preserves are zero eigenvalues (``d + d²`` for V3/V5).
The thesis removes them with boundary conditions on the correction factors:

``p``
    :math:`\alpha^k = 0` at ``d + 1`` selected particles (as many unknowns
    as there are zero modes; a point singularity under refinement).
``s``
    :math:`\alpha^k = 0` at all surface particles.  The constraints of the
    surface particles are then not imposed: their nodal area vectors
    become whatever the corrected derivatives give, the discrete
    divergence theorem (4.35), and no longer match FE's.
``sn``
    only the normal component :math:`n^k\cdot\alpha^k = 0` at surface
    particles, imposed with nodal Lagrange multipliers (the default of the
    thesis).  The multiplier absorbs the normal component of the surface
    constraint: the discrete surface vectors keep the FE direction
    :math:`n^i` (tangential residual zero), only their length changes.

With ``s`` and ``sn`` the system is square, ``d·n_int + (d−1)·n_surf``
(``sn``) or ``d·n_int`` (``s``) equations in as many unknowns, and solved by
one sparse LU.  Neumann loads must then use the discrete surface vectors
(thesis (4.32)–(4.35)); :func:`skfem_pg.discretization.loads.stress_load` and
:func:`~skfem_pg.discretization.loads.traction` do so through
``basis.area_correction``. The package's default (``"min-norm"``) imposes every
constraint with the FE-consistent :math:`A^i` and takes the minimum-norm
solution instead.

Measured (``benchmarks/README.md``): all variants pass the linear patch test, none is more
accurate than min-norm on the 2-D manufactured problem (L2 / Q1: 2.46
min-norm, 2.39 p, 2.72 sn), and on the 3-D Cook tetrahedra ``p`` and
``sn`` are erratic (corner errors −60 % and −35 % on one node set each).
"""
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spl

from ...errors import VCSolveError

BOUNDARY_VARIANTS = ("min-norm", "p", "s", "sn")


def surface_frames(area):
    """Unit normals ``n`` (``(ns, d)``) and orthonormal tangents ``t``
    (``(ns, d-1, d)``) of the surface particles ``surf`` (those with a
    non-zero area vector ``area`` ``(d, np)``): ``(surf, n, t)``."""
    a = np.asarray(area, dtype=float).T
    norm = np.linalg.norm(a, axis=1)
    scale = norm.max() if norm.size and norm.max() > 0 else 1.0
    surf = np.nonzero(norm > 1e-12 * scale)[0]
    n = a[surf] / norm[surf, None]
    # rows 2.. of V^T in the SVD of the 1×d row n span its complement
    _, _, vt = np.linalg.svd(n[:, None, :])
    return surf, n, vt[:, 1:, :]


def interface_edge(area, surface):
    """Surface particles that also lie on an FE–PG interface: a non-zero
    ``surface`` vector (true surface) and a different ``area`` vector (the
    PG region's boundary, interface included).  ``None`` without an
    interface."""
    if surface is None:
        return None
    area, surface = np.asarray(area), np.asarray(surface)
    scale = max(np.abs(area).max(), 1e-300)
    on = np.linalg.norm(surface, axis=0) > 1e-12 * scale
    return on & (np.linalg.norm(area - surface, axis=0) > 1e-12 * scale)


def reduction(masters, area, boundary, n_particles, active, full=None):
    """Sparse ``(R, T)`` for ``boundary`` ``"s"`` or ``"sn"``: the imposed
    equations are ``R @ (A α - b) = 0`` (interior particles: all
    components; surface particles under ``sn``: the tangential ones), the
    unknowns ``α = T @ γ`` (interior families: all components; families of
    surface particles under ``sn``: the tangential ones).  ``masters``:
    the master particle of each family; ``area`` the true surface's area
    vectors.  ``full`` (boolean per particle) marks surface particles
    treated as under ``s`` even with ``sn``: those on the edge of an FE–PG
    interface, where ``sn`` leaves the reduced system singular (one zero
    singular value on a coupled quad patch, measured) and ``s`` does
    not."""
    if boundary not in ("s", "sn"):
        raise ValueError("reduction() is for the boundary variants 's' and "
                         "'sn', got {!r}".format(boundary))
    area = np.asarray(area, dtype=float)
    d = area.shape[0]
    surf, _, t = surface_frames(area)
    is_surf = np.zeros(n_particles, dtype=bool)
    is_surf[surf] = True
    sn_at = is_surf.copy()  # surface particles with a tangential part
    if full is not None:
        sn_at &= ~np.asarray(full, dtype=bool)

    def operator(owners):
        """``(d·len(owners)) × n_reduced``: identity blocks for interior
        owners, tangent bases for surface owners (``sn``)."""
        inner = np.nonzero(~is_surf[owners] & active[owners])[0]
        rows = [(d * inner[:, None] + np.arange(d)).ravel()]
        cols = [np.arange(d * len(inner))]
        vals = [np.ones(d * len(inner))]
        ncol = d * len(inner)
        if boundary == "sn":
            pos = np.full(n_particles, -1)
            pos[surf] = np.arange(len(surf))
            on = np.nonzero(sn_at[owners] & active[owners])[0]
            tt = t[pos[owners[on]]]  # (non, d-1, d): [block, tangent, comp]
            rows.append(np.broadcast_to((d * on)[:, None, None]
                                        + np.arange(d), tt.shape).ravel())
            cols.append(np.broadcast_to(
                (ncol + (d - 1) * np.arange(len(on)))[:, None, None]
                + np.arange(d - 1)[None, :, None], tt.shape).ravel())
            vals.append(tt.ravel())
            ncol += (d - 1) * len(on)
        return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows),
                                                     np.concatenate(cols))),
                             shape=(d * len(owners), ncol))

    T = operator(np.asarray(masters))
    R = operator(np.arange(n_particles)).T.tocsr()
    return R, T


def solve_reduced(A, b, R, T):
    """Solve the square reduced system ``(R A T) γ = R b`` by sparse LU;
    returns ``α = T γ``.  Raises ``ValueError`` if it is not square and
    :class:`~skfem_pg.errors.VCSolveError` if it is singular."""
    K = (R @ A @ T).tocsc()
    if K.shape[0] != K.shape[1]:
        raise ValueError(
            "the reduced VC system has {} equations and {} unknowns: the "
            "boundary variants 's'/'sn' need one family per particle, "
            "mastered by it".format(*K.shape))
    try:
        lu = spl.splu(K, permc_spec="COLAMD")
    except RuntimeError as err:
        raise VCSolveError("the reduced VC system is singular ({}): the "
                           "interior families cannot satisfy the interior "
                           "constraints".format(err)) from None
    rb = R @ b
    g = lu.solve(rb)
    g += lu.solve(rb - K @ g)  # one step of iterative refinement
    res = np.linalg.norm(K @ g - rb)
    if not np.all(np.isfinite(g)) or res > 1e-8 * max(np.linalg.norm(rb),
                                                       1e-300):
        raise VCSolveError(
            "the reduced VC system is singular to working precision "
            "(relative residual {:.1e} after LU); this boundary variant "
            "does not regularise it — use another one".format(
                res / max(np.linalg.norm(rb), 1e-300)))
    return T @ g
