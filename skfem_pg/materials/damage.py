r"""Damage laws for the J2 material: an uncoupled damage indicator
:math:`D` at every integration point that accumulates with the plastic
strain and fails the point at a critical value (thesis 8.1); and
brittle criteria on the elastic strain (:class:`CriticalStrainDamage`,
:class:`NonlocalStrainDamage`) and on the stress
(:class:`CriticalStressDamage`), and the crack tracking of either local
criterion (:class:`CrackTracking`, experimental).

:class:`JohnsonCookDamage` is Johnson and Cook's (1985) law without rate
and temperature terms, as the thesis uses it:

.. math:: D = \sum \frac{\Delta\bar e_p}{\varepsilon_f(\sigma^*)}, \qquad
          \varepsilon_f = D_1 + D_2 \exp(D_3\,\sigma^*), \qquad
          \sigma^* = \frac{\operatorname{tr}\sigma / 3}{\sigma_{vM}},

summed over the steps with :math:`\sigma^*` the stress triaxiality of the
step's stress (Cauchy or Kirchhoff: :math:`J` cancels); the point fails
when :math:`D \ge D_c`.  Where :math:`\varepsilon_f \le 0` (a negative
:math:`D_1` at high triaxiality) any plastic strain fails the point.
Until failure the stress does not depend on :math:`D` (the damage-free
limit is the plain J2 law exactly); what a failed point carries is
:class:`~skfem_pg.materials.J2Plasticity`'s (no deviatoric stress, no
tension).
"""
import numpy as np

from .constants import check_finite


class JohnsonCookDamage:
    r"""Johnson–Cook ductile damage (module docstring).

    Parameters
    ----------
    D1, D2, D3
        The failure strain's constants, :math:`\varepsilon_f = D_1 + D_2
        e^{D_3\sigma^*}` (``D2 >= 0``).
    Dc
        Critical damage, in (0, 1] (thesis 8.1: 0.3).

    Examples
    --------
    Broumand & Khoei's steel (thesis 8.1): the failure strain in pure
    shear and in uniaxial tension.

    >>> law = JohnsonCookDamage(0.05, 3.44, -2.12, 0.3)
    >>> law.failure_strain([0.0, 1 / 3])  # doctest: +ELLIPSIS
    array([3.49      , 1.7469...])
    """

    def __init__(self, D1, D2, D3, Dc):
        self.D1, self.D2, self.D3, self.Dc = check_finite(
            "JohnsonCookDamage", D1=D1, D2=D2, D3=D3, Dc=Dc)
        if self.D2 < 0:
            raise ValueError("JohnsonCookDamage: D2 must be >= 0, got {}"
                             .format(D2))
        if self.D2 == 0 and self.D1 <= 0:
            raise ValueError(
                "JohnsonCookDamage: with D2 = 0 the failure strain is D1 = "
                "{} at every triaxiality, and D1 <= 0 fails every point at "
                "its first plastic step; give D1 > 0 (or D2 > 0)".format(D1))
        if not 0 < self.Dc <= 1:
            raise ValueError("JohnsonCookDamage: the critical damage Dc must "
                             "lie in (0, 1], got {}".format(Dc))

    def __repr__(self):
        return "JohnsonCookDamage(D1={:g}, D2={:g}, D3={:g}, Dc={:g})".format(
            self.D1, self.D2, self.D3, self.Dc)

    def failure_strain(self, triaxiality):
        r""":math:`\varepsilon_f(\sigma^*) = D_1 + D_2 e^{D_3\sigma^*}`."""
        t = np.asarray(triaxiality, dtype=float)
        if self.D2 == 0:  # no 0 * inf where D3 t overflows
            return np.full(t.shape, self.D1)
        # exp saturates at inf (no failure) instead of overflowing to nan
        with np.errstate(over="ignore"):
            return self.D1 + self.D2 * np.exp(self.D3 * t)

    def increment(self, dalpha, triaxiality):
        r""":math:`\Delta D = \Delta\bar e_p / \varepsilon_f(\sigma^*)`
        (infinite where :math:`\varepsilon_f \le 0` and
        :math:`\Delta\bar e_p > 0`: the point fails)."""
        ef = self.failure_strain(triaxiality)
        da = np.asarray(dalpha, dtype=float)
        with np.errstate(divide="ignore"):
            return np.where(ef > 0, da / np.where(ef > 0, ef, 1.0),
                            np.where(da > 0, np.inf, 0.0))


class CriticalStrainDamage:
    r"""A brittle failure criterion: a point fails when the largest
    principal logarithmic strain of its trial elastic left Cauchy–Green
    tensor :math:`b_e^{tr}` (the elastic strain where the point does not
    yield) reaches ``critical_strain``,

    .. math:: D = \max_{steps} \frac{\tfrac12 \ln \lambda_{max}
              (b_e^{tr})}{\varepsilon_c}, \qquad \text{failure at }
              D \ge D_c = 1,

    the continuum counterpart of the bond-based model's critical stretch
    [not in the thesis; used for Kalthoff–Winkler's brittle mode with a
    yield stress the run does not reach].  A failed point is
    :class:`~skfem_pg.materials.J2Plasticity`'s (no deviatoric stress, no
    tension).  For a fracture energy :math:`G_0` and a crack one particle
    spacing :math:`h` wide, :meth:`from_fracture_energy` gives
    :math:`\varepsilon_c = \sqrt{2 G_0 / (E h)}` (the energy of a linear
    elastic band of width h strained to failure equals :math:`G_0` per
    unit crack area) [crack-band scaling, a choice].

    >>> law = CriticalStrainDamage(0.01)
    >>> float(law.indicator(np.diag([1.02 ** 2, 1.0, 1.0])[None])[0])
    ... # doctest: +ELLIPSIS
    1.98...
    """

    Dc = 1.0

    def __init__(self, critical_strain):
        (self.critical_strain,) = check_finite(
            "CriticalStrainDamage", critical_strain=critical_strain)
        if not self.critical_strain > 0:
            raise ValueError("CriticalStrainDamage: the critical strain must "
                             "be positive, got {}".format(critical_strain))

    @classmethod
    def from_fracture_energy(cls, G0, E, h):
        r"""The critical strain :math:`\sqrt{2 G_0/(E h)}` of a crack band
        of width ``h`` (class docstring)."""
        G0, E, h = check_finite("CriticalStrainDamage", G0=G0, E=E, h=h)
        if not (G0 > 0 and E > 0 and h > 0):
            raise ValueError("CriticalStrainDamage: G0, E and h must be "
                             "positive, got {}, {}, {}".format(G0, E, h))
        return cls(np.sqrt(2.0 * G0 / (E * h)))

    def __repr__(self):
        return "CriticalStrainDamage(critical_strain={:g})".format(
            self.critical_strain)

    def increment(self, dalpha, triaxiality):
        """No accumulation with the plastic strain."""
        return np.zeros(np.shape(dalpha))

    def indicator(self, b):
        r""":math:`\tfrac12\ln\lambda_{max}(b) / \varepsilon_c` of
        symmetric ``b`` ``(n, 3, 3)``."""
        lam = np.linalg.eigvalsh(b)[:, -1]
        return 0.5 * np.log(lam) / self.critical_strain


class CriticalStressDamage:
    r"""A brittle failure criterion on the stress (Rankine's): a point
    fails when its largest principal Cauchy stress reaches the tensile
    ``strength`` :math:`f_t`,

    .. math:: D = \max_{steps} \frac{\sigma_{max}}{f_t}, \qquad
              \text{failure at } D \ge D_c = 1,

    the point's stress before it fails (the plain law's; a mixed
    formulation's pressure where it gives one) [not in the thesis; the
    smeared counterpart of the maximum tangential stress criterion of
    Erdogan & Sih (1963), which sets a crack's direction normal to the
    largest principal stress at its tip].  Where
    :class:`CriticalStrainDamage` compares the largest principal strain,
    which a compression across it raises by Poisson's ratio
    (:math:`\varepsilon_1 = (\sigma_1 - \nu' \sigma_2)/E'`, with
    :math:`\nu' = \nu/(1 - \nu) = 0.43` in plane strain at
    :math:`\nu = 0.3`), this one compares the stress alone.  A failed
    point is :class:`~skfem_pg.materials.J2Plasticity`'s (no deviatoric
    stress, no tension).  For a fracture energy :math:`G_0` and a crack
    one particle spacing :math:`h` wide, :meth:`from_fracture_energy`
    gives :math:`f_t = \sqrt{2 G_0 E / h}` (the energy of a linear
    elastic band of width h stressed to :math:`f_t` uniaxially equals
    :math:`G_0` per unit crack area; :math:`E' = E/(1 - \nu^2)` in plane
    strain) [crack-band scaling, a choice; the same strength as
    :class:`CriticalStrainDamage`'s in uniaxial stress].

    >>> law = CriticalStressDamage(500.0)
    >>> float(law.stress_indicator(np.diag([600.0, -900.0, 0.0])[None],
    ...                            np.ones(1))[0])
    1.2
    """

    Dc = 1.0

    def __init__(self, strength):
        (self.strength,) = check_finite("CriticalStressDamage",
                                        strength=strength)
        if not self.strength > 0:
            raise ValueError("CriticalStressDamage: the strength must be "
                             "positive, got {}".format(strength))

    @classmethod
    def from_fracture_energy(cls, G0, E, h):
        r"""The strength :math:`\sqrt{2 G_0 E / h}` of a crack band of
        width ``h`` (class docstring)."""
        G0, E, h = check_finite("CriticalStressDamage", G0=G0, E=E, h=h)
        if not (G0 > 0 and E > 0 and h > 0):
            raise ValueError("CriticalStressDamage: G0, E and h must be "
                             "positive, got {}, {}, {}".format(G0, E, h))
        return cls(np.sqrt(2.0 * G0 * E / h))

    def __repr__(self):
        return "CriticalStressDamage(strength={:g})".format(self.strength)

    def increment(self, dalpha, triaxiality):
        """No accumulation with the plastic strain."""
        return np.zeros(np.shape(dalpha))

    def stress_indicator(self, tau, J):
        r""":math:`\sigma_{max} / f_t` of the Kirchhoff stresses ``tau``
        ``(n, 3, 3)`` at the volume ratios ``J`` ``(n,)`` (the Cauchy
        stress is :math:`\tau / J`)."""
        return np.linalg.eigvalsh(tau)[:, -1] / (
            np.asarray(J, dtype=float) * self.strength)


class CrackTracking:
    r"""A brittle criterion (:class:`CriticalStrainDamage` or
    :class:`CriticalStressDamage`) that fails only the points on the path
    a crack tip chooses: the crack tracking of Cervera & Chiumenti (2006)
    with the tip's direction from the maximum tangential stress criterion
    of Erdogan & Sih (1963) [not in the thesis; issue 51].  A local
    criterion fails the point where the stress is largest; next to a sharp
    notch under shear that is the notch face, and the crack follows the
    mesh (Kalthoff–Winkler on triangles).  Tracked, a point may fail only
    on the path ahead of a crack tip, which turns by the kink the
    criterion gives for the stress intensity factors fitted to the intact
    sites around the tip, beside the crack within its ``width``, or far
    from every crack (a new one); :class:`~skfem_pg.discretization.
    crack_tracking.CrackTracker` has the algorithm.  The lengths are in
    units of each site's spacing (the median distance to its four
    nearest sites).  2-D, serial; a formulation that binds its points
    evaluates it (the PG and FE displacement and mean-dilatation models,
    crack-aware ones included).  Experimental: see
    ``benchmarks/README.md`` for what it gives on Kalthoff–Winkler.

    Parameters
    ----------
    law
        The criterion: when a point fails.
    width
        The crack's width about the line its tip chose, within which the
        sites beside it may fail (spacings); with the connectivity kept a
        band two sites wide leaves the families that span it overstressed
        beside it, and on the square grid the crack stops.
    reach
        How far ahead of a tip a site may fail, and within which another
        crack site closes a crack site's end (spacings).
    tip_radius
        The stress intensity factors are fitted to the intact sites
        between one and this many spacings from the tip.
    cone
        The largest turn of a tip's direction from its crack's, in
        degrees (below 90).
    exclusion
        A new crack starts only this many spacings from every crack and
        notch tip.
    notches
        The tips of the notches (or initial cracks) the body has, as pairs
        ``((x, y), (d_x, d_y))``: the tip and the notch's direction (out
        of the notch into the material).  A notch tip is a crack tip from
        the start: the path from it follows the stress around it in the
        notch's frame.  Without them a crack starts where the criterion is
        first reached, normal to the largest principal stress there.
    hold_limit
        A point held off the path, farther than ``tip_radius`` spacings
        from every tip, whose criterion exceeds this many times its
        critical value raises :class:`~skfem_pg.discretization.
        crack_tracking.TrackingError` (``numpy.inf``: no limit; near a
        tip the held excess is the singular field's, module docstring of
        :mod:`~skfem_pg.discretization.crack_tracking`).

    Examples
    --------
    >>> CrackTracking(CriticalStressDamage(500.0))  # doctest: +ELLIPSIS
    CrackTracking(CriticalStressDamage(strength=500), width=3, reach=2, ...)
    """

    tracking = True

    def __init__(self, law, width=3.0, reach=2.0, tip_radius=3.0,
                 cone=75.0, exclusion=5.0, notches=(), hold_limit=2.0):
        if not isinstance(law, (CriticalStrainDamage, CriticalStressDamage)) \
                or isinstance(law, NonlocalStrainDamage):
            raise TypeError(
                "CrackTracking tracks a local brittle criterion "
                "(CriticalStrainDamage or CriticalStressDamage), got {!r}"
                .format(law))
        self.law = law
        self.width, self.reach, self.tip_radius, self.cone, \
            self.exclusion = \
            check_finite("CrackTracking", width=width, reach=reach,
                         tip_radius=tip_radius, cone=cone,
                         exclusion=exclusion)
        self.hold_limit = float(hold_limit)
        if not self.hold_limit >= 1.0:  # inf: no limit
            raise ValueError("CrackTracking: hold_limit must be at least 1, "
                             "got {}".format(hold_limit))
        for name in ("width", "reach", "tip_radius", "exclusion"):
            if not getattr(self, name) > 0:
                raise ValueError("CrackTracking: {} must be positive, got "
                                 "{}".format(name, getattr(self, name)))
        if not 0 < self.cone < 90:
            raise ValueError("CrackTracking: cone must lie in (0, 90) "
                             "degrees, got {}".format(cone))
        tips, directions = [], []
        for k, notch in enumerate(notches):
            try:
                tip, d = (np.asarray(a, dtype=float) for a in notch)
            except (TypeError, ValueError):
                tip = d = np.zeros(0)
            if tip.shape != (2,) or d.shape != (2,) or not (
                    np.all(np.isfinite(tip)) and np.all(np.isfinite(d))
                    and np.hypot(*d) > 0):
                raise ValueError(
                    "CrackTracking: notch {} must be ((x, y), (d_x, d_y)) "
                    "with finite numbers and a nonzero direction, got {!r}"
                    .format(k, notch))
            tips.append(tip)
            directions.append(d / np.hypot(*d))
        self.notch_tips = np.array(tips, dtype=float).reshape(-1, 2).T
        self.notch_directions = np.array(
            directions, dtype=float).reshape(-1, 2).T
        self.Dc = law.Dc
        for name in ("indicator", "stress_indicator"):
            if hasattr(law, name):
                setattr(self, name, getattr(law, name))

    def __repr__(self):
        return ("CrackTracking({!r}, width={:g}, reach={:g}, "
                "tip_radius={:g}, cone={:g}, exclusion={:g}{})".format(
                    self.law, self.width, self.reach, self.tip_radius,
                    self.cone, self.exclusion,
                    ", {} notches".format(self.notch_tips.shape[1])
                    if self.notch_tips.shape[1] else ""))

    def increment(self, dalpha, triaxiality):
        """No accumulation with the plastic strain."""
        return np.zeros(np.shape(dalpha))


def triaxiality(tau_dev, mean):
    r""":math:`\sigma^* = p / \sigma_{vM}` of Kirchhoff (or Cauchy)
    stresses given by their deviators ``tau_dev`` ``(n, 3, 3)`` and mean
    stresses ``mean`` ``(n,)`` (0 where the deviator vanishes)."""
    vm = np.sqrt(1.5 * (tau_dev * tau_dev).sum(axis=(1, 2)))
    return np.where(vm > 0, mean / np.where(vm > 0, vm, 1.0), 0.0)


class NonlocalStrainDamage(CriticalStrainDamage):
    r"""The brittle criterion of :class:`CriticalStrainDamage` on the
    *nonlocal* strain: a point fails when the weighted mean of the
    intact points' largest principal logarithmic strains within
    ``radius`` of it (in the reference configuration) reaches
    ``critical_strain``,

    .. math:: \bar\varepsilon(x) = \frac{\sum_{q\ intact} \alpha(|x -
              x_q|)\, V_q\, \varepsilon_q}{\sum_{q\ intact} \alpha(|x -
              x_q|)\, V_q}, \qquad \alpha(r) = \langle 1 - r^2/R^2
              \rangle^2,

    the bell of Jirásek's integral-type nonlocal models, averaged over
    the points the model evaluates the material at
    (:class:`~skfem_pg.discretization.nonlocal_mean.NonlocalAverage`; on a
    family basis the points at a particle first, then the particles
    within :math:`R`) [not in the thesis: its outlook's regularization,
    issue 51].  Failed points are left out of the mean, so a crack's
    opening does not spread the failure: the crack tip's field, smoothed
    over :math:`R`, decides.  With the radius fixed, the strength and the
    toughness of the criterion do not depend on the particle spacing
    :math:`h` (for :math:`h \ll R`), where the crack-band scaling of
    :meth:`CriticalStrainDamage.from_fracture_energy` changes the
    strength with :math:`h`.  :meth:`from_fracture_energy` gives the
    critical strain of a toughness.

    Only a formulation that binds its points evaluates it (the PG and FE
    displacement and mean-dilatation models, crack-aware ones
    included); serial runs only.

    Parameters
    ----------
    critical_strain
        The nonlocal strain at failure.
    radius
        :math:`R`, the averaging radius (in the mesh's length unit); a
        few particle spacings.

    Examples
    --------
    >>> law = NonlocalStrainDamage.from_fracture_energy(
    ...     22.17, 190e3, 0.3, radius=4.0)
    >>> law  # doctest: +ELLIPSIS
    NonlocalStrainDamage(critical_strain=0.0027..., radius=4)
    """

    def __init__(self, critical_strain, radius):
        super().__init__(critical_strain)
        (self.radius,) = check_finite("NonlocalStrainDamage", radius=radius)
        if not self.radius > 0:
            raise ValueError("NonlocalStrainDamage: the radius must be "
                             "positive, got {}".format(radius))

    @classmethod
    def from_fracture_energy(cls, G0, E, nu, radius, dim=2):
        r"""The critical strain at which a mode-I crack tip of fracture
        energy ``G0`` fails the point at the tip: with :math:`K_c =
        \sqrt{G_0 E'}`, :math:`E' = E/(1-\nu^2)` (plane strain),

        .. math:: \varepsilon_c = \bar\varepsilon_{K_I = K_c}(\text{tip})
                  = c_d(\nu)\, \frac{K_c}{E' \sqrt{R}},

        the near-tip field's largest principal strain (plane strain)
        averaged with the bell over the disc (``dim=2``) or the ball
        (``dim=3``, a straight front) of radius :math:`R` around the tip
        (:func:`tip_average`; :math:`c_2(0.3) = 0.543`)."""
        G0, E, nu, radius = check_finite(
            "NonlocalStrainDamage", G0=G0, E=E, nu=nu, radius=radius)
        if not (G0 > 0 and E > 0 and radius > 0 and -1 < nu < 0.5):
            raise ValueError(
                "NonlocalStrainDamage: G0, E and radius must be positive "
                "and -1 < nu < 0.5, got {}, {}, {}, {}".format(
                    G0, E, radius, nu))
        Ep = E / (1 - nu ** 2)
        return cls(tip_average(nu, dim) * np.sqrt(G0 * Ep) / (
            Ep * np.sqrt(radius)), radius)

    def __repr__(self):
        return "NonlocalStrainDamage(critical_strain={:g}, radius={:g})" \
            .format(self.critical_strain, self.radius)


def tip_average(nu, dim=2, n=400):
    r""":math:`c_d(\nu)`: the bell-weighted mean over the disc
    (``dim=2``) or ball (``dim=3``) of radius :math:`R` centred at a mode-I
    crack tip (front) of the largest principal strain of the plane-strain
    near-tip field, in units of :math:`K_I / (E' \sqrt{R})` (midpoint
    quadrature, ``n`` intervals in the radius)."""
    if dim not in (2, 3):
        raise ValueError("tip_average: dim must be 2 or 3, got {}"
                         .format(dim))
    r = (np.arange(n) + 0.5) / n  # R = 1
    th = (np.arange(2 * n) + 0.5) / n * np.pi - np.pi
    rr, tt = np.meshgrid(r, th, indexing="ij")
    c, s = np.cos(tt / 2), np.sin(tt / 2)
    s3, c3 = np.sin(1.5 * tt), np.cos(1.5 * tt)
    f = 1 / np.sqrt(2 * np.pi * rr)  # K = 1
    sxx, syy, sxy = f * c * (1 - s * s3), f * c * (1 + s * s3), f * c * s * c3
    # plane strain with E' = E / (1 - nu^2) = 1
    exx = sxx - nu / (1 - nu) * syy
    eyy = syy - nu / (1 - nu) * sxx
    exy = sxy / (1 - nu)
    e1 = np.maximum(0.5 * (exx + eyy) + np.hypot(0.5 * (exx - eyy), exy),
                    0.0)
    if dim == 2:
        w = (1 - rr ** 2) ** 2 * rr
    else:  # the ball: the field does not vary along the front (z), and
        # the bell integrates over z to 8/15 (1 - r^2)^(5/2)
        w = (1 - rr ** 2) ** 2.5 * rr
    return float((w * e1).sum() / w.sum())
