r"""The nonlocal mean of a field at a model's integration points: what
:class:`~skfem_pg.materials.damage.NonlocalStrainDamage` fails its points
on (issue 51).

.. math:: \bar v(x) = \frac{\sum_q \alpha(|x - x_q|)\, V_q\, m_q\, v_q}
          {\sum_q \alpha(|x - x_q|)\, V_q\, m_q}, \qquad \alpha(r) =
          \langle 1 - r^2/R^2 \rangle^2,

with the mask :math:`m_q` (1 for the points that take part: the intact
ones) and the reference positions :math:`x_q`.  On a family basis the
points are the family members (the flat layout of
:mod:`~skfem_pg.discretization.layout`), several at each particle: their
masked mean (by weight) at each particle comes first, then the bell over
the particles within :math:`R` (weights: the particles' volumes), and
each point takes its particle's mean.  On a scikit-fem basis the points
are the Gauss points, weighted by ``dx``, each its own site.  Four
sparse products per evaluation; the operators are built once per basis
(:func:`point_sites`, shared with the crack tracking).
"""
import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from .layout import is_family_basis


def _bell(x, radius, volumes):
    """The bell's matrix ``(n, n)`` over the points ``x`` ``(d, n)``:
    row i, column j: alpha(|x_i - x_j|) V_j."""
    n = x.shape[1]
    pairs = cKDTree(x.T).query_pairs(radius, output_type="ndarray")
    i = np.concatenate([pairs[:, 0], pairs[:, 1], np.arange(n)])
    j = np.concatenate([pairs[:, 1], pairs[:, 0], np.arange(n)])
    r2 = ((x[:, i] - x[:, j]) ** 2).sum(axis=0)
    a = np.clip(1.0 - r2 / radius ** 2, 0.0, None) ** 2 * volumes[j]
    return sp.csr_matrix((a, (i, j)), shape=(n, n))


def point_sites(basis, what):
    """Where a model's integration points on ``basis`` lie: ``(at, x,
    volumes, gather)``: ``at`` each point's site, ``x`` ``(d, n)`` and
    ``volumes`` the sites', ``gather`` the sparse ``(n, N_q)`` matrix of
    the points' weights (row i: the points at site i).  On a family basis
    the sites are the particles (the points' members in the flat layout);
    on a scikit-fem basis every Gauss point is its own site (its ``dx``).
    A basis on MPI ranks is refused: ``what`` (a nonlocal mean, crack
    tracking) needs the points of the neighbouring ranks."""
    if getattr(basis, "distributed", None) is not None:
        raise NotImplementedError(
            "{} over the points of a basis on MPI ranks is not built (it "
            "needs the points of the neighbouring ranks): run it serially"
            .format(what))
    if is_family_basis(basis):
        particles = basis.particles
        at, x, volumes = (basis.families.members, particles.x,
                          particles.volumes)
        w = basis.flat_weights().ravel()
    else:
        x = np.asarray(basis.global_coordinates())
        x = x.reshape(x.shape[0], -1)
        volumes = w = np.asarray(basis.dx, dtype=float).ravel()
        at = np.arange(w.size)
    gather = sp.csr_matrix((w, (at, np.arange(at.size))),
                           shape=(x.shape[1], at.size))
    return at, x, volumes, gather


class NonlocalAverage:
    """The masked bell mean of radius ``radius`` over the integration
    points of ``basis`` (module docstring): ``average(values, mask)``
    with ``values`` and ``mask`` one entry per point (in the order of
    the model's point arrays, flattened).

    Examples
    --------
    The mean of a linear field on a grid's particles is exact away from
    the edges:

    >>> import skfem as fem, skfem_pg as pg
    >>> basis = pg.FamilyBasis(fem.MeshTri.init_tensor(
    ...     np.linspace(0, 4, 17), np.linspace(0, 4, 17)), dim=2)
    >>> average = NonlocalAverage(basis, radius=0.6)
    >>> x = basis.particles.x[:, basis.families.members]
    >>> v = average(x[0], np.ones(x.shape[1], dtype=bool))
    >>> inner = np.all(np.abs(x - 2) < 1, axis=0)
    >>> bool(np.abs(v - x[0])[inner].max() < 1e-12)
    True
    """

    def __init__(self, basis, radius):
        if not radius > 0:
            raise ValueError("NonlocalAverage: the radius must be positive, "
                             "got {}".format(radius))
        self.basis, self.radius = basis, float(radius)
        self.at, x, volumes, self._gather = point_sites(
            basis, "a nonlocal mean")
        self._bell = _bell(x, self.radius, volumes)
        self.n_points = self.at.size

    def __repr__(self):
        return "NonlocalAverage(radius={:g}, {} points)".format(
            self.radius, self.n_points)

    def __call__(self, values, mask):
        """The masked bell mean of ``values`` at every point (0 where no
        masked point lies within the radius)."""
        values = np.asarray(values, dtype=float).ravel()
        m = np.asarray(mask, dtype=float).ravel()
        if values.size != self.n_points or m.size != self.n_points:
            raise ValueError(
                "NonlocalAverage: {} values and {} mask entries for the "
                "{} points of the basis".format(values.size, m.size,
                                                self.n_points))
        # the masked mean at each site, then the bell over the sites that
        # have one (on a scikit-fem basis: each Gauss point is its site)
        num, den = self._gather @ (m * values), self._gather @ m
        has = den > 0
        mean = np.where(has, num / np.where(has, den, 1.0), 0.0)
        num, den = self._bell @ mean, self._bell @ has.astype(float)
        out = np.where(den > 0, num / np.where(den > 0, den, 1.0), 0.0)
        return out[self.at]
