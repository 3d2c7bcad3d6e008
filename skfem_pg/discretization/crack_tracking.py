r"""Crack tracking over a model's integration points (2-D): which points a
brittle criterion may fail (:class:`~skfem_pg.materials.damage.
CrackTracking`, issue 51).

A local criterion fails the point where the stress (or strain) is largest,
and near a sharp notch under shear that is the notch face, not the
direction a crack takes.  The crack tracking of Cervera & Chiumenti
(2006) lets the criterion fail only the points on the path a crack tip
chooses; here the tip chooses by the maximum tangential stress criterion
of Erdogan & Sih (1963), from the stress intensity factors fitted to the
stress around it.  The points are grouped into *sites* (a family basis:
the particles the points lie at; a scikit-fem basis: the Gauss points,
:func:`~skfem_pg.discretization.nonlocal_mean.point_sites`);
a site's spacing :math:`h_s` is the median distance to its four nearest
sites.  At an evaluation in which
some intact point reaches the criterion:

1. the *crack* is the sites with a failed point; each carries the line
   :math:`(d_c, d_c^\perp \cdot x)` it failed on, and whether it failed
   on a tip's path (or started a crack) or beside the crack;
2. the front end :math:`+d_c` of a site on a tip's path, and both ends
   :math:`\pm d_c` of a site that started a crack (at its point on its
   line: the crack is the polyline its tips chose), is *open* when no
   other crack site lies within ``reach`` spacings of it and 60 degrees
   of that direction (a path grows forward: its back end faces the tip
   it grew from); with the law's notch tips that no crack site closes
   (within ``reach`` and the ``cone`` their kink may take), the open
   ends within ``reach`` of each other and facing the same way are one
   *tip*, at their centroid, with their mean outward direction
   :math:`o`;
3. a tip's direction: in the frame whose x-axis is :math:`o` (the crack
   behind the tip), the near-tip fields of modes I and II and a T-stress,
   times :math:`\sqrt r`, fitted by least squares to the intact sites
   between one and ``tip_radius`` spacings from the tip (their mean
   Cauchy stress over their points), give :math:`K_I, K_{II}`; the tip
   turns by the criterion's kink :math:`\theta_c` (:func:`mts_angle`),
   at most ``cone`` degrees;
4. a site may fail (all its points that reach the criterion) when its
   cell (the points nearest to it) crosses the strip one spacing wide
   and ``reach`` spacings long from a tip along its direction (the path,
   about two sites wide), or when it lies beside a crack site or a
   notch tip (within half a spacing along its line; a notch's line is
   its direction through its tip) and within half of ``width`` spacings
   of that line (the crack widens about the line its tip chose, and
   about a notch's end, its root; it neither creeps sideways nor grows
   ahead of its tips); it carries that line;
5. a site farther than ``exclusion`` spacings from every crack site and
   notch tip starts a new crack (the largest criterion among such sites
   within ``exclusion`` of each other), its line normal to its largest
   principal stress.

Every other point that reaches the criterion is held just below it.
Within ``tip_radius`` spacings of a tip that is the singular field: the
largest principal stress peaks beside the path a tip takes (in mode II
on the crack's flank, 1.73 times its value on the path at the same
distance; in mode I at 60 degrees, 1.30 times), and the tip advances
when its path reaches the criterion.  Elsewhere a held point whose
criterion exceeds ``hold_limit`` times the critical value raises
:class:`TrackingError` naming it (the material would carry what it
cannot: with the connectivity kept the families that span a tracked
crack overstress its flanks).  :attr:`CrackTracker.most_held` records
the most held in both zones.  The
points that fail carry their line in the history (``crack_line``), so
that the state is the committed history alone (a cut Newton step, a
checkpoint, a crack-aware rebuild carry it).  The work is done only at
evaluations in which a point reaches the criterion: k-d trees over the
crack's and the tips' neighbourhoods, no loop over points.
"""
import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from .nonlocal_mean import point_sites

class TrackingError(RuntimeError):
    """A tracked criterion holds a point off the crack's path far above
    its critical value (:class:`~skfem_pg.materials.damage.CrackTracking`'s
    ``hold_limit``): ``ratio``, its criterion over the critical value, and
    ``position`` ``(2,)``, its site in the reference configuration."""

    def __init__(self, message, ratio=np.nan, position=(np.nan, np.nan)):
        super().__init__(message)
        self.ratio = float(ratio)
        self.position = np.asarray(position, dtype=float)


#: half-angle (degrees) of the cone in which another crack site closes an
#: end of a crack site
_END_CONE = 60.0
#: the role of a crack site that started a crack (its line's fourth
#: entry; 1: on a tip's path, 0: beside the crack)
_STARTED = 2.0


class CrackTracker:
    """The crack tracking of ``law`` (a :class:`~skfem_pg.materials.damage.
    CrackTracking`) over the integration points of ``basis`` (module
    docstring): ``tracker(indicator, sigma, failed, line, Dc)``.

    Examples
    --------
    A point reaching the criterion far from any crack starts one, in the
    direction normal to its largest principal stress:

    >>> import skfem as fem, skfem_pg as pg
    >>> from skfem_pg.materials import CrackTracking, CriticalStressDamage
    >>> basis = pg.FamilyBasis(fem.MeshTri.init_tensor(
    ...     np.linspace(0, 4, 9), np.linspace(0, 4, 9)), dim=2)
    >>> tracker = CrackTracker(basis, CrackTracking(CriticalStressDamage(1)))
    >>> n = tracker.n_points
    >>> sigma = np.zeros((n, 3, 3)); sigma[:, 1, 1] = 1.0  # pulled along y
    >>> ind = np.zeros(n); ind[0] = 1.0
    >>> none = np.zeros(n, dtype=bool)
    >>> out, line = tracker(ind, sigma, none, np.zeros((4, n)), 1.0)
    >>> float(out[0]), np.abs(line[:2, 0]).round(6).tolist()
    (1.0, [1.0, 0.0])
    """

    def __init__(self, basis, law):
        self.basis, self.law = basis, law
        self.at, x, _, self._gather = point_sites(
            basis, "crack tracking")
        if x.shape[0] != 2:
            raise NotImplementedError(
                "{!r}: crack tracking is built in 2-D; a {}-D model's crack "
                "is a surface, whose front is not tracked".format(
                    law, x.shape[0]))
        self.x = x
        self.n_points = self.at.size
        self._tree = cKDTree(x.T)
        # each site's spacing: the median distance to its four nearest
        # sites (not the square root of its volume, which on an edge or
        # a corner is a half or a quarter of its neighbours')
        if x.shape[1] < 5:
            raise ValueError("{!r}: {} site(s); the crack tracking needs at "
                             "least five".format(law, x.shape[1]))
        dist, _ = self._tree.query(x.T, k=5)
        self.h = np.median(dist[:, 1:], axis=1)
        xn, dn = law.notch_tips, law.notch_directions
        self._notches = (xn, dn, self.h[self._tree.query(xn.T)[1]]
                         if xn.shape[1] else np.zeros(0))
        #: ``{"near tips": (ratio, x), "elsewhere": (ratio, x)}``: the
        #: largest criterion over its critical value the tracking has
        #: held, at any evaluation, and where (the reference
        #: configuration), within ``tip_radius`` spacings of a tip and
        #: elsewhere; ``(0, nan)`` before any
        self.most_held = {zone: (0.0, np.full(2, np.nan))
                          for zone in ("near tips", "elsewhere")}

    def __repr__(self):
        return "CrackTracker({!r}, {} sites)".format(self.law, self.x.shape[1])

    def __call__(self, indicator, sigma, failed, line, Dc):
        r"""``(indicator, line)``: the criterion at the points
        ``indicator`` ``(n,)`` with the points it may not fail held just
        below ``Dc``, and the points' crack lines ``(4, n)`` (direction
        :math:`d` and offset :math:`d^\perp \cdot x` of the line through
        the tip that let them fail, :math:`d^\perp = (-d_y, d_x)`, and 1
        on a tip's path, 2 where a crack started, 0 beside it) with the
        ones failing now set.  ``sigma``: the points' Cauchy stresses
        ``(n, 3, 3)`` before failure; ``failed``, ``line``: the committed
        failures and lines."""
        indicator = np.asarray(indicator, dtype=float).ravel()
        failed = np.asarray(failed, dtype=bool).ravel()
        line = np.asarray(line, dtype=float).reshape(4, -1)
        if indicator.size != self.n_points:
            raise ValueError(
                "CrackTracker: {} values for the {} points of the basis"
                .format(indicator.size, self.n_points))
        candidate = (indicator >= Dc) & ~failed
        if not candidate.any():
            return indicator, line
        ns = self.x.shape[1]
        at = self.at
        site_failed = np.zeros(ns, dtype=bool)
        site_failed[at[failed]] = True
        site_line = np.zeros((4, ns))
        site_line[:, at[failed]] = line[:, failed]
        stress = self._site_stress(sigma, ~failed)
        sites = np.unique(at[candidate])
        allowed = np.zeros(ns, dtype=bool)
        new_line = np.zeros((4, ns))
        crack = np.flatnonzero(site_failed)
        allowed[crack] = True
        new_line[:, crack] = site_line[:, crack]
        # the tips are the ends of the paths (the sites beside them widen
        # the crack, they do not lead it)
        xt, outward, ht = self._tips(crack[site_line[3, crack] > 0],
                                     site_line)
        d_tip = self._tip_directions(xt, outward, ht, stress, site_failed)
        self._path(sites, xt, d_tip, ht, allowed, new_line)
        # the crack widens beside its sites and beside the notch tips (a
        # notch's end is the root of its crack)
        xn, dn, hn = self._notches
        self._beside(sites, np.hstack([self.x[:, crack], xn]), np.hstack([
            site_line[:, crack], np.vstack([dn, _offset(dn, xn),
                                            np.ones(xn.shape[1])])]),
            np.concatenate([self.h[crack], hn]), allowed, new_line)
        self._initiate(sites, crack, indicator, candidate, stress, allowed,
                       new_line)
        ok = allowed[at]
        held = candidate & ~ok
        if held.any():
            self._check_held(indicator / Dc, held, xt, ht)
        out = indicator.copy()
        out[held] = np.nextafter(Dc, -np.inf)
        new = candidate & ok
        line = line.copy()
        line[:, new] = new_line[:, at[new]]
        return out, line

    def _check_held(self, ratio, held, xt, ht):
        """Record the most the ``held`` points carry (``ratio``: their
        criterion over its critical value) within ``tip_radius`` spacings
        of a tip ``xt`` (spacings ``ht``) and elsewhere; raise
        :class:`TrackingError` for one elsewhere above ``hold_limit``."""
        law = self.law
        idx = np.flatnonzero(held)
        near = np.zeros(idx.size, dtype=bool)
        if xt.shape[1]:
            i, j = _near(cKDTree(xt.T), self.x[:, self.at[idx]],
                         law.tip_radius * ht.max())
            close = np.hypot(*(self.x[:, self.at[idx[i]]] - xt[:, j])) \
                <= law.tip_radius * ht[j]
            near[i[close]] = True
        for zone, mask in (("near tips", near), ("elsewhere", ~near)):
            if mask.any():
                k = idx[mask][np.argmax(ratio[idx[mask]])]
                if ratio[k] > self.most_held[zone][0]:
                    self.most_held[zone] = (ratio[k],
                                            self.x[:, self.at[k]].copy())
        far = idx[~near]
        if far.size == 0 or ratio[far].max() <= law.hold_limit:
            return
        k = far[np.argmax(ratio[far])]
        where = self.x[:, self.at[k]]
        raise TrackingError(
            "{!r}: {} point(s) held off the crack's path, farther than "
            "tip_radius from its tips, at up to {:.3g} times the criterion "
            "(point {} at particle {}, ({}) in the reference "
            "configuration), above hold_limit = {:g}: the material carries "
            "what it cannot (the crack's neighbours overstressed or the "
            "crack arrested); widen the crack (width), use crack-aware "
            "families, or run it untracked".format(
                law, int((ratio[far] > law.hold_limit).sum()), ratio[k], k,
                self.at[k], ", ".join("{:.6g}".format(c) for c in where),
                law.hold_limit), ratio[k], where)

    def _site_stress(self, sigma, mask):
        """The in-plane Cauchy stress ``(3, n_sites)`` (xx, yy, xy) of each
        site: the weighted mean over its points in ``mask``."""
        s = np.asarray(sigma, dtype=float).reshape(-1, 3, 3)
        comp = np.stack([s[:, 0, 0], s[:, 1, 1], s[:, 0, 1]])
        m = mask.astype(float)
        den = self._gather @ m
        num = (self._gather @ (comp * m).T).T
        return np.where(den > 0, num / np.where(den > 0, den, 1.0), 0.0)

    def _tips(self, crack, site_line):
        """The crack's tips ``(x (2, k), outward (2, k), spacing (k,))``:
        the open ends of the path sites ``crack`` (at their points on
        their lines; front ends, and back ends of the sites that started
        a crack) and the law's notch tips that no crack site closes,
        those within ``reach`` spacings of each other
        and facing the same way (within 60 degrees) merged into one at
        their centroid (a band several sites wide has one tip, and its
        stress is sampled around the band's middle)."""
        d, hc = site_line[:2, crack], self.h[crack]
        # the path sites' points on their lines: the crack is the polyline
        # its tips chose, and the sites' scatter about it (half a spacing)
        # does not add up
        xc = self.x[:, crack]
        nrm = np.stack([-d[1], d[0]])
        xc = xc - nrm * ((nrm * xc).sum(axis=0) - site_line[2, crack])
        reach = self.law.reach
        xn, dn, hn = self._notches
        # every end, the notches' first: (position, outward, spacing); a
        # site on a tip's path grows forward only (its tip lies behind
        # it), a site that started a crack both ways
        both = site_line[3, crack] == _STARTED
        xe = np.hstack([xn, xc, xc[:, both]])
        o = np.hstack([dn, d, -d[:, both]])
        he = np.concatenate([hn, hc, hc[both]])
        if xe.shape[1] == 0:
            return np.zeros((2, 0)), np.zeros((2, 0)), np.zeros(0)
        # an end is closed by a crack site within reach of it and 60
        # degrees of its outward direction (a site does not close its own
        # ends); a notch tip by one within the cone its kink may take
        cone = np.full(xe.shape[1], _END_CONE)
        cone[:xn.shape[1]] = max(_END_CONE, self.law.cone)
        closed = np.zeros(xe.shape[1], dtype=bool)
        if crack.size:
            end, other = _near(cKDTree(xc.T), xe, reach * he)
            v = xc[:, other] - xe[:, end]
            r = np.hypot(*v)
            along = (v * o[:, end]).sum(axis=0)
            shut = (r > 1e-12 * he[end]) & (
                along >= np.cos(np.radians(cone[end])) * r)
            closed[end[shut]] = True
        keep = ~closed
        xe, o, he = xe[:, keep], o[:, keep], he[keep]
        if xe.shape[1] == 0:
            return np.zeros((2, 0)), np.zeros((2, 0)), np.zeros(0)
        pairs = cKDTree(xe.T).query_pairs(reach * he.max(),
                                          output_type="ndarray")
        i, j = pairs[:, 0], pairs[:, 1]
        same = (np.hypot(*(xe[:, i] - xe[:, j])) <= reach * np.minimum(
            he[i], he[j])) & ((o[:, i] * o[:, j]).sum(axis=0)
                              >= np.cos(np.radians(_END_CONE)))
        graph = sp.coo_matrix((np.ones(same.sum()), (i[same], j[same])),
                              shape=(xe.shape[1], xe.shape[1]))
        k, label = connected_components(graph, directed=False)
        count = np.bincount(label, minlength=k)
        xt = np.stack([np.bincount(label, xe[c], k) for c in (0, 1)]) / count
        ot = np.stack([np.bincount(label, o[c], k) for c in (0, 1)])
        ot /= np.maximum(np.hypot(*ot), 1e-300)
        return xt, ot, np.bincount(label, he, k) / count

    def _tip_directions(self, xt, outward, ht, stress, site_failed):
        """Each tip's direction ``(2, k)``: the kink of the maximum
        tangential stress criterion from the stress intensity factors fitted
        to the intact sites around it (module docstring), turned by at most
        ``cone`` degrees from its outward direction."""
        k = xt.shape[1]
        if k == 0:
            return outward
        law = self.law
        tip, site = _near(self._tree, xt, law.tip_radius * ht)
        v = self.x[:, site] - xt[:, tip]
        r = np.hypot(*v)
        keep = ~site_failed[site] & (r >= ht[tip])
        site, tip, v, r = site[keep], tip[keep], v[:, keep], r[keep]
        # the frame: the crack lies behind the tip, against its outward
        # direction
        base = np.arctan2(outward[1], outward[0])
        K, _ = _fit(base[tip], v, r, stress[:, site], tip, k)
        enough = np.bincount(tip, minlength=k) >= 3
        turn = np.clip(np.where(enough, mts_angle(K[:, 0], K[:, 1]), 0.0),
                       -np.radians(law.cone), np.radians(law.cone))
        return np.stack([np.cos(base + turn), np.sin(base + turn)])

    def _path(self, sites, xt, d, ht, allowed, new_line):
        """Allow the candidate ``sites`` on the tips' paths: the sites whose
        cells (the points nearest to them) the strip from a tip ``xt``
        along its direction ``d``, ``reach`` of its spacings ``ht`` long
        and one spacing wide about the line, crosses (sampled at a tenth
        of a spacing): a path about two sites wide; they carry the tip's
        line."""
        free = np.zeros(self.x.shape[1], dtype=bool)
        free[sites[~allowed[sites]]] = True
        if not free.any():
            return
        law = self.law
        m = int(np.ceil(10 * law.reach)) + 1
        half = 0.5  # a strip one spacing wide: about two sites
        q = int(np.ceil(10 * half)) * 2 + 1
        s = np.linspace(0.0, law.reach, m)  # along, in spacings
        o = np.linspace(-half, half, q)  # across
        s, o = [a.ravel() for a in np.meshgrid(s, o, indexing="ij")]
        n = np.stack([-d[1], d[0]])
        points = xt[:, :, None] + (d[:, :, None] * s + n[:, :, None] * o) \
            * ht[None, :, None]  # (2, k, m q)
        _, on = self._tree.query(points.reshape(2, -1).T)
        tip = np.repeat(np.arange(xt.shape[1]), s.size)
        hit = free[on]
        on, tip = on[hit], tip[hit]
        on, first = np.unique(on, return_index=True)
        tip = tip[first]
        allowed[on] = True
        new_line[:2, on] = d[:, tip]
        new_line[2, on] = _offset(d, xt)[tip]
        new_line[3, on] = 1.0

    def _beside(self, sites, xc, lines, hc, allowed, new_line):
        """Allow the candidate ``sites`` beside the crack sites ``xc``
        (within half a spacing along their ``lines`` ``(4, k)``) and within
        half of ``width`` spacings of those lines: the crack widens about
        the line its tip chose; it neither creeps sideways nor grows ahead
        of its tips.  They carry that line."""
        free = sites[~allowed[sites]]
        if free.size == 0 or xc.shape[1] == 0:
            return
        # the pairs (candidate, crack site) near enough: a crack site lies
        # within half of width of its own line (beside sites) or about a
        # spacing (path sites)
        cand, site = _near(cKDTree(xc.T), self.x[:, free],
                           (0.5 + self.law.width) * hc.max() + 1e-12)
        d, h = lines[:2, site], hc[site]
        xf = self.x[:, free[cand]]
        along = ((xf - xc[:, site]) * d).sum(axis=0)
        across = np.abs(_offset(d, xf) - lines[2, site])
        inside = (np.abs(along) <= 0.5 * h) & \
            (across <= 0.5 * self.law.width * h)
        if not inside.any():
            return
        cand, site = cand[inside], site[inside]
        # each candidate takes the line of its nearest crack site
        order = np.lexsort((np.hypot(along[inside], across[inside]), cand))
        cand, site = cand[order], site[order]
        first = np.unique(cand, return_index=True)[1]
        hit, nearest = free[cand[first]], site[first]
        allowed[hit] = True
        new_line[:, hit] = lines[:, nearest]
        new_line[3, hit] = 0.0

    def _initiate(self, sites, crack, indicator, candidate, stress,
                  allowed, new_line):
        """Start cracks at the candidate sites farther than ``exclusion``
        spacings from the crack and from the notch tips (module
        docstring)."""
        free = sites[~allowed[sites]]
        if free.size == 0:
            return
        law = self.law
        reach = law.exclusion * self.h[free]
        taken = np.hstack([self.x[:, crack], self._notches[0]])
        if taken.shape[1]:
            dist, _ = cKDTree(taken.T).query(self.x[:, free].T)
            free, reach = free[dist > reach], reach[dist > reach]
            if free.size == 0:
                return
        level = np.full(self.x.shape[1], -np.inf)
        np.maximum.at(level, self.at[candidate], indicator[candidate])
        pairs = cKDTree(self.x[:, free].T).query_pairs(
            reach.max(), output_type="ndarray")
        lose = np.zeros(free.size, dtype=bool)
        if pairs.size:
            i, j = pairs[:, 0], pairs[:, 1]
            r = np.hypot(*(self.x[:, free[i]] - self.x[:, free[j]]))
            close = r <= np.minimum(reach[i], reach[j])
            i, j = i[close], j[close]
            li, lj = level[free[i]], level[free[j]]
            first = (li > lj) | ((li == lj) & (free[i] < free[j]))
            lose[j[first]] = True
            lose[i[~first]] = True
        start = free[~lose]
        sxx, syy, sxy = stress[:, start]
        # the largest principal stress' direction, and the crack normal
        # to it
        angle = 0.5 * np.arctan2(2 * sxy, sxx - syy)
        allowed[start] = True
        d = np.stack([-np.sin(angle), np.cos(angle)])
        new_line[:, start] = np.vstack([d, _offset(d, self.x[:, start]),
                                        np.full(start.size, _STARTED)])


def mts_angle(KI, KII):
    r"""The kink angle (radians) of the maximum tangential stress
    criterion (Erdogan & Sih 1963) at stress intensity factors ``KI``,
    ``KII``: :math:`\theta_c = 2 \arctan \frac{K_I - \sqrt{K_I^2 + 8
    K_{II}^2}}{4 K_{II}}` (0 where :math:`K_{II} = 0`).

    >>> round(float(np.degrees(mts_angle(0.0, 1.0))), 2)
    -70.53
    """
    KI, KII = np.asarray(KI, dtype=float), np.asarray(KII, dtype=float)
    safe = np.where(KII != 0, KII, 1.0)
    return np.where(KII != 0, 2 * np.arctan(
        (KI - np.sqrt(KI * KI + 8 * KII * KII)) / (4 * safe)), 0.0)


def _fit(frame, v, r, stress, tip, k):
    """The near-tip fields (:func:`_williams`) fitted to the sites'
    stresses by least squares, per tip, in the frames at the angles
    ``frame`` (per pair; the crack behind the tip along ``frame`` + pi):
    ``(K (k, 3): K_I, K_II, T; misfit (k,))``, the misfit the residual's
    share of the sampled stresses (both times sqrt r)."""
    c, s = np.cos(frame), np.sin(frame)
    theta = np.arctan2(-s * v[0] + c * v[1], c * v[0] + s * v[1])
    sxx, syy, sxy = stress
    rows = np.stack([c * c * sxx + s * s * syy + 2 * c * s * sxy,
                     s * s * sxx + c * c * syy - 2 * c * s * sxy,
                     (c * c - s * s) * sxy + c * s * (syy - sxx)]) \
        * np.sqrt(r)  # (3, pairs): the stresses in the frame
    fields = _williams(theta, r)  # (3 components, 3 unknowns, pairs)
    A = np.zeros((k, 3, 3))
    rhs = np.zeros((k, 3))
    for m in range(3):
        np.add.at(A, tip, np.einsum("ip,jp->pij", fields[m], fields[m]))
        np.add.at(rhs, tip, (fields[m] * rows[m]).T)
    A += (1e-12 * np.trace(A, axis1=1, axis2=2) + 1e-300)[:, None, None] \
        * np.eye(3)
    K = np.linalg.solve(A, rhs[..., None])[..., 0]
    res = rows - np.einsum("mjp,pj->mp", fields, K[tip])
    num = np.bincount(tip, (res * res).sum(axis=0), k)
    den = np.bincount(tip, (rows * rows).sum(axis=0), k)
    return K, num / np.maximum(den, 1e-300)


def _williams(theta, r):
    r"""The stresses (x'x', y'y', x'y' in the tip's frame) of the unit
    mode-I and mode-II near-tip fields and of a unit T-stress, times
    :math:`\sqrt r`: ``(3 components, 3 fields, pairs)``."""
    f = 1.0 / np.sqrt(2 * np.pi)
    c, s = np.cos(theta / 2), np.sin(theta / 2)
    c3, s3 = np.cos(1.5 * theta), np.sin(1.5 * theta)
    one = np.zeros_like(theta)
    mode1 = [f * c * (1 - s * s3), f * c * (1 + s * s3), f * c * s * c3]
    mode2 = [-f * s * (2 + c * c3), f * s * c * c3, f * c * (1 - s * s3)]
    tee = [np.sqrt(r), one, one]
    return np.array([[mode1[m], mode2[m], tee[m]] for m in range(3)])


def _near(tree, x, radius):
    """The pairs ``(i, j)``: point ``x[:, i]`` ``(2, n)`` and the point
    ``j`` of ``tree`` within ``radius`` (per point, or one) of it."""
    near = tree.query_ball_point(x.T, radius)
    counts = np.array([len(q) for q in near], dtype=int)
    if counts.sum() == 0:
        return np.zeros(0, dtype=int), np.zeros(0, dtype=int)
    return (np.repeat(np.arange(x.shape[1]), counts),
            np.concatenate([np.asarray(q, dtype=int) for q in near]))


def _offset(d, x):
    r""":math:`d^\perp \cdot x` with :math:`d^\perp = (-d_y, d_x)`: the
    offset of the lines through ``x`` along ``d`` (both ``(2, k)``)."""
    return -d[1] * x[0] + d[0] * x[1]
