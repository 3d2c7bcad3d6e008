r"""Finite-strain J2 elasto-plasticity (thesis 2.3.2, (2.46)–(2.54)) with the
exponential return map (4.41), batched over all integration points.

Multiplicative split :math:`F = F_e F_p` with isochoric plastic flow
(:math:`J_p = 1`, (2.13)); the history is :math:`C_p^{-1}` (symmetric,
(2.17)) and the hardening variable :math:`\alpha` (= the accumulated
plastic strain :math:`\bar e_p`, since :math:`|n_F| = \sqrt{3/2}`).

* Elastic part (2.46), neo-Hooke with the iso/vol split:
  :math:`W = \frac\mu2(\mathrm{tr}\,\bar b_e - 3) + \frac K4(J^2 - 1 - 2\ln
  J)`, :math:`\bar b_e = J^{-2/3} F C_p^{-1} F^T` (2.16); Kirchhoff stress
  :math:`\tau = \mu\,\mathrm{dev}\,\bar b_e + \frac K2(J^2 - 1) I`,
  :math:`P = \tau F^{-T}` (2.47), (2.48).
* Yield function (2.49), (2.50): :math:`\phi = \sigma_{vM}(\tau) -
  \sigma_y(\alpha)`, :math:`\sigma_{vM} = \sqrt{\tfrac32\,\tau_{dev}:
  \tau_{dev}}`, :math:`\sigma_y = \sigma_{y0} + H\alpha + (\sigma_{y\infty}
  - \sigma_{y0})(1 - e^{-\delta\alpha})`.
* Flow (2.51), (2.52): :math:`n = \partial\phi/\partial\tau = \tfrac32
  \tau_{dev}/\sigma_{vM}`, :math:`\dot C_p^{-1} = -2\dot\lambda F^{-1} n F
  C_p^{-1}`, :math:`\dot\alpha = \dot\lambda`.
* Exponential integration (4.41) *with the minus sign that (2.52)
  requires* (the printed (4.41) lost it):
  :math:`C_p^{-1} = F^{-1}\exp(-2\Delta\alpha\, n) F C_{p,n}^{-1}`, i.e.
  :math:`b_e = \exp(-2\Delta\alpha\, n)\, b_e^{tr}` with the trial
  :math:`b_e^{tr} = F C_{p,n}^{-1} F^T`.  As :math:`n` is an isotropic
  function of :math:`b_e`, all three are coaxial: in the eigenbasis of
  :math:`b_e^{tr}` (eigenvalues :math:`\beta_A`) the return map is, with
  :math:`x_A = \ln b_{e,A}`,

  .. math:: x_A - \ln\beta_A + 2\Delta\alpha\, n_A(x) = 0, \qquad
            \sigma_{vM}(x) - \sigma_y(\alpha_n + \Delta\alpha) = 0,

  four equations per plastic point, solved by a batched local Newton (no
  loop over points).  The exponential keeps :math:`\det b_e = J^2`
  (isochoric flow) to round-off.
* Algorithmic tangent: implicit differentiation of the local equations
  gives :math:`\partial\tau_A/\partial\beta_B`; the spectral formula
  :math:`\mathbb D = \sum_{AB}\partial_{\beta_B}\tau_A\, m_A\otimes m_B +
  \sum_{A\ne B}\frac{\tau_A - \tau_B}{\beta_A - \beta_B}\, m_{AB}`
  (its limit :math:`\partial_{\beta_A}\tau_A - \partial_{\beta_B}\tau_A` at
  equal eigenvalues, as in homogeneous uniaxial states), then
  :math:`\mathbb A_{iJkL} = 2\mathbb D_{imkb}(FC_{p,n}^{-1})_{bL}
  F^{-1}_{Jm} - P_{iL}F^{-1}_{Jk}` plus the volumetric part.  Checked
  against central differences of the stress update in
  ``tests/test_plasticity.py``.

In 2-D the state is plane strain: :math:`F_{33} = 1`, and the
out-of-plane component of :math:`C_p^{-1}` evolves with the others.
"""
import numpy as np

from .constants import check_moduli
from .damage import triaxiality
from .hardening import LinearSaturation
from .hyperelastic import Material, NeoHookeIsoVol, inverse_and_det

#: local Newton: tolerance on the scaled residual and iteration limit
RETURN_TOL = 1e-12
RETURN_MAXITER = 50
#: relative eigenvalue gap below which the spectral tangent uses the
#: equal-eigenvalue limit (error ~ gap^2 either way)
EIGEN_GAP = 1e-6


#: the deviatoric projector of principal values, delta_AB - 1/3
_DEVIATOR = np.eye(3) - 1.0 / 3.0


def _von_mises(tau):
    """:math:`\\sigma_{vM} = \\sqrt{3/2\\,\\tau:\\tau}` of deviatoric principal
    stresses ``(n, 3)``."""
    return np.sqrt(1.5 * (tau[:, 0] ** 2 + tau[:, 1] ** 2 + tau[:, 2] ** 2))


class ReturnMapError(RuntimeError):
    """The local Newton of the return map did not converge; ``points`` are
    the flat indices of the integration points concerned."""

    def __init__(self, message, points=()):
        super().__init__(message)
        self.points = np.asarray(points)


class J2Plasticity(Material):
    r"""Finite J2 elasto-plasticity with neo-Hooke elasticity, von Mises
    yield and isotropic hardening (module docstring); the parameters carry
    the thesis' symbols, (2.46)–(2.49).  Optionally with ductile damage
    (thesis 8.1): a damage indicator at every point, failure at its
    critical value.

    A stateful material: :meth:`initial_history` gives the history at a
    set of points and :meth:`update` the response to ``F`` from a
    committed history.  The formulations bind it to their integration
    points (:class:`~skfem_pg.formulations.history.History`).

    Parameters
    ----------
    mu, K
        Shear and bulk modulus of the elastic part (``K = np.inf``:
        incompressible, for the formulations that carry the pressure).
    sigma_y0
        Initial yield stress of the thesis' hardening law (2.49).
    H
        Linear hardening modulus.
    sigma_yinf
        Saturation yield stress (default ``sigma_y0``: no saturation).
    delta
        Saturation exponent.
    hardening
        Instead of ``sigma_y0, H, sigma_yinf, delta``: a hardening law of
        :mod:`~skfem_pg.materials.hardening`, e.g.
        ``JohnsonCookHardening(A, B, n)``.
    damage
        A damage law of :mod:`~skfem_pg.materials.damage`
        (``JohnsonCookDamage(D1, D2, D3, Dc)``), or ``None``.  The history
        then carries ``damage``; until a point fails its stress is the
        plain law's.  A *failed* point (``damage >= Dc``, from the step
        in which it gets there) carries no deviatoric stress and no
        tension: its Kirchhoff stress is the volumetric part
        :math:`\frac K2(J^2 - 1) I` while :math:`J < 1` (crack faces
        pressed together transmit pressure) and zero while
        :math:`J \ge 1`; its plastic strain and :math:`C_p^{-1}` stay
        where they were.

    Examples
    --------
    The thesis' steel of 8.1 (Broumand & Khoei 2015), in N, mm, s:

    >>> from skfem_pg.materials import (JohnsonCookHardening,
    ...                                 JohnsonCookDamage)
    >>> steel = J2Plasticity.from_young(
    ...     200e3, 0.29, hardening=JohnsonCookHardening(792.0, 510.0, 0.26),
    ...     damage=JohnsonCookDamage(0.05, 3.44, -2.12, 0.3))
    """

    stateful = True

    def __init__(self, *, mu, K, sigma_y0=None, H=0.0, sigma_yinf=None,
                 delta=0.0, hardening=None, damage=None):
        if isinstance(K, (int, float, np.number)) and np.isposinf(K):
            # incompressible: the documented use of inf
            self.mu, self.K = check_moduli(mu=mu)[0], np.inf
        else:  # nan, -inf and K <= 0 are refused by name
            self.mu, self.K = check_moduli(mu=mu, K=K)
        if hardening is None:
            if sigma_y0 is None:
                raise TypeError("J2Plasticity needs sigma_y0 (the thesis' "
                                "hardening law (2.49)) or hardening=")
            hardening = LinearSaturation(sigma_y0, H, sigma_yinf, delta)
        elif sigma_y0 is not None or H or sigma_yinf is not None or delta:
            raise TypeError("J2Plasticity: give either sigma_y0, H, "
                            "sigma_yinf, delta or hardening={!r}, not both"
                            .format(hardening))
        for name, law, needs in (("hardening", hardening,
                                  ("stress", "slope", "initial")),
                                 ("damage", damage,
                                  ("increment", "Dc"))):
            if law is not None and not all(hasattr(law, a) for a in needs):
                raise TypeError("J2Plasticity: {}={!r} is not a {} law "
                                "(it needs {})".format(name, law, name,
                                                       ", ".join(needs)))
        self.hardening, self.damage = hardening, damage

    def __repr__(self):
        return "J2Plasticity(mu={:g}, K={:g}, hardening={!r}{})".format(
            self.mu, self.K, self.hardening, "" if self.damage is None
            else ", damage={!r}".format(self.damage))

    @classmethod
    def from_young(cls, E, nu, sigma_y0=None, **kw):
        """From Young's modulus and Poisson's ratio."""
        E, nu = check_moduli(E=E, nu=nu)
        mu = E / (2 * (1 + nu))
        return cls(mu=mu, K=E / (3 * (1 - 2 * nu)), sigma_y0=sigma_y0, **kw)

    def isochoric(self, with_damage=False):
        """The same law without the volumetric part (``K = 0``), for the
        mixed formulations that add it per element or particle; the
        return map does not depend on ``K``.  With damage only for a
        formulation that says it carries it (``with_damage``: it gives
        the points their mean stress for the triaxiality, ``mean_stress``
        of :meth:`update`, and applies the no-tension rule to its
        pressure itself — :class:`~skfem_pg.formulations.MeanDilatation`);
        for the others a failed point's rule would act on a pressure they
        carry elsewhere."""
        if self.damage is not None and not with_damage:
            raise NotImplementedError(
                "{!r}: damage needs the pressure at the point (a failed "
                "point carries no tension); of the mixed formulations that "
                "add the pressure per element or particle only PBG UnlP0 "
                "and FE Q1P0/H1P0 (MeanDilatation) take it: use those, "
                "Unl, U1SUnl, U1SIG or FE Q1/H1/T1/O1".format(self))
        m = J2Plasticity(mu=self.mu, K=1.0, hardening=self.hardening,
                         damage=self.damage)
        m.K = 0.0
        return m

    def elastic(self):
        """The elastic part alone, :class:`NeoHookeIsoVol` (2.46)."""
        m = NeoHookeIsoVol(mu=self.mu, K=1.0)
        m.K = self.K
        return m

    # -- hardening -----------------------------------------------------
    @property
    def sigma_y0(self):
        """The initial yield stress, :math:`\\sigma_y(0)`."""
        return self.hardening.initial

    def yield_stress(self, alpha):
        r""":math:`\sigma_y(\alpha)` of the hardening law."""
        return self.hardening.stress(alpha)

    def _hardening_slope(self, a):
        return self.hardening.slope(a)

    # -- history -------------------------------------------------------
    def initial_history(self, point_shape):
        """The virgin state at points of shape ``point_shape``:
        ``Cp_inv`` ``(3, 3, *point_shape)`` the identity, ``alpha`` (and
        with a damage law ``damage`` and ``released``, the energy density
        a point released when it failed) zero; with a damage law also
        ``F_last``, the committed deformation gradient (3-D, the
        identity), against which a failing point's step is booked, and
        ``closure``, the energy density the steps lost at the point after
        it failed (:meth:`Response.closure_step`)."""
        shape = tuple(point_shape)
        Cp = np.broadcast_to(np.eye(3).reshape((3, 3) + (1,) * len(shape)),
                             (3, 3) + shape).copy()
        h = {"Cp_inv": Cp, "alpha": np.zeros(shape)}
        if self.damage is not None:
            h["damage"] = np.zeros(shape)
            h["released"] = np.zeros(shape)
            h["F_last"] = Cp.copy()  # the committed F (3-D), identity
            h["closure"] = np.zeros(shape)
            if getattr(self.damage, "tracking", False):
                h["crack_line"] = np.zeros((4,) + shape)
        return h

    # -- the stress update ---------------------------------------------
    def update(self, F, history, mean_stress=None, average=None,
               tracker=None):
        """The response to ``F`` ``(d, d, ...)`` from the committed
        ``history`` at the same points: a :class:`Response` with the
        stress ``P``, the trial history and (on demand) the algorithmic
        tangent.  ``mean_stress`` (per point, Kirchhoff): the mean stress
        the damage law's triaxiality takes instead of the law's own
        volumetric one (a mixed formulation's pressure, times J).
        ``average``: the nonlocal mean over the points
        (:class:`~skfem_pg.discretization.nonlocal_mean.NonlocalAverage`),
        which a nonlocal damage law needs; ``tracker``: the crack
        tracking over the points (:class:`~skfem_pg.discretization.
        crack_tracking.CrackTracker`), which a tracked one needs."""
        return Response(self, F, history, mean_stress, average, tracker)

    # stateless use (the virgin state): what the elastic formulations and
    # the hyperelastic checks call
    def stress(self, F):
        return self.update(F, self.initial_history(F.shape[2:])).P

    def tangent(self, F):
        return self.update(F, self.initial_history(F.shape[2:])).tangent()

    def energy(self, F, history=None):
        """Stored elastic energy :math:`W(\\bar b_e, J)` (2.46)."""
        h = self.initial_history(F.shape[2:]) if history is None \
            else history
        return self.update(F, h).energy()

    # -- principal-space pieces ---------------------------------------
    def _tau(self, x):
        """Deviatoric principal Kirchhoff stress of log stretches ``x``
        ``(n, 3)`` and its derivatives ``T[n, A, B] = d tau_A / d x_B``."""
        # means over the three stretches written out: numpy's reductions
        # over an axis of length 3 cost twice the rest of this function
        bb = np.exp(x - ((x[:, 0] + x[:, 1] + x[:, 2]) / 3.0)[:, None])
        tau = self.mu * (bb - ((bb[:, 0] + bb[:, 1] + bb[:, 2])
                               / 3.0)[:, None])
        # d bb_A / d x_B = bb_A (delta_AB - 1/3); its mean over A is
        # tau_B / (3 mu)
        T = (self.mu * bb)[:, :, None] * _DEVIATOR - tau[:, None, :] / 3.0
        return tau, T

    def _local_residual(self, x, da, xtr, alpha_n):
        tau, T = self._tau(x)
        s = np.maximum(_von_mises(tau), 1e-300)
        nA = 1.5 * tau / s[:, None]
        ds = 1.5 * np.einsum("na,nab->nb", tau, T) / s[:, None]
        dn = 1.5 * (T / s[:, None, None]
                    - tau[:, :, None] * ds[:, None, :] / s[:, None, None] ** 2)
        a = alpha_n + da
        R = np.empty((x.shape[0], 4))
        R[:, :3] = x - xtr + 2 * da[:, None] * nA
        R[:, 3] = (s - self.yield_stress(a)) / self.mu
        Jl = np.empty((x.shape[0], 4, 4))
        Jl[:, :3, :3] = np.eye(3) + 2 * da[:, None, None] * dn
        Jl[:, :3, 3] = 2 * nA
        Jl[:, 3, :3] = ds / self.mu
        Jl[:, 3, 3] = -self._hardening_slope(a) / self.mu
        return R, Jl, tau, T

    def _radial_start(self, xtr, alpha_n, iterations=40):
        r"""The start of the local Newton: the return along the trial
        direction, :math:`x = x^{tr} - 2\Delta\alpha\, n^{tr}`, with
        :math:`\sigma_{vM}(x) = \sigma_y(\alpha_n + \Delta\alpha)` solved
        by a bracketed Newton in :math:`[0, \Delta\alpha_{max}]` (where
        the deviator along :math:`n^{tr}` vanishes).  Exact for fixed
        principal directions (uniaxial, radial loading); a linear
        estimate :math:`\phi/(3\bar\mu + H')` overshoots at large steps
        (neo-Hooke stiffens) and can flip the flow direction."""
        tau, _ = self._tau(xtr)
        ntr = 1.5 * tau / _von_mises(tau)[:, None]
        xdev = xtr - xtr.mean(axis=1, keepdims=True)
        hi = np.sum(xdev * ntr, axis=1) / 3.0  # (x_dev . n) / (2 |n|^2)
        lo = np.zeros_like(hi)
        da = 0.5 * hi
        todo = np.arange(hi.size)  # the points not yet on the surface
        for _ in range(iterations):
            n, a, d = ntr[todo], alpha_n[todo], da[todo]
            t, T = self._tau(xtr[todo] - 2 * d[:, None] * n)
            sv = _von_mises(t)
            g = sv - self.yield_stress(a + d)
            lo[todo] = np.where(g > 0, d, lo[todo])
            hi[todo] = np.where(g > 0, hi[todo], d)
            dg = (1.5 * np.einsum("na,nab,nb->n", t, T, -2 * n)
                  / np.maximum(sv, 1e-300) - self._hardening_slope(a + d))
            new = d - g / np.where(dg < 0, dg, -1.0)
            outside = ~((new > lo[todo]) & (new < hi[todo]))
            done = np.abs(g) <= 1e-3 * RETURN_TOL * self.mu
            # a converged point keeps the value it converged at
            da[todo] = np.where(done, d, np.where(
                outside, 0.5 * (lo[todo] + hi[todo]), new))
            todo = todo[~done]
            if todo.size == 0:
                break
        return xtr - 2 * da[:, None] * ntr, da

    def return_map(self, xtr, alpha_n):
        """Principal log elastic stretches ``x`` ``(n, 3)`` and increments
        ``dalpha`` of the plastic points whose trial log stretches are
        ``xtr`` ``(n, 3)``, and at the solution the local Jacobians ``(n,
        4, 4)`` and the principal stresses with their derivatives
        (:meth:`_tau`), for the tangent."""
        n = xtr.shape[0]
        x, da = self._radial_start(xtr, alpha_n)
        todo = np.arange(n)
        Jl_all = np.empty((n, 4, 4))
        tau_all, T_all = np.empty((n, 3)), np.empty((n, 3, 3))
        for it in range(RETURN_MAXITER):
            R, Jl, tau, T = self._local_residual(
                x[todo], da[todo], xtr[todo], alpha_n[todo])
            done = np.abs(R).max(axis=1) <= RETURN_TOL
            i = todo[done]
            Jl_all[i], tau_all[i], T_all[i] = Jl[done], tau[done], T[done]
            todo, R, Jl = todo[~done], R[~done], Jl[~done]
            if todo.size == 0:
                return x, da, Jl_all, tau_all, T_all
            step = np.linalg.solve(Jl, -R[..., None])[..., 0]
            # a step may not make dalpha negative (the yield surface
            # would be left on the wrong side)
            t = np.ones(todo.size)
            neg = da[todo] + step[:, 3] < 0
            t[neg] = 0.5 * da[todo][neg] / np.maximum(-step[neg, 3], 1e-300)
            x[todo] += t[:, None] * step[:, :3]
            da[todo] += t * step[:, 3]
        raise ReturnMapError(
            "J2 return map: no convergence in {} local Newton iterations at "
            "{} point(s) (first: {}; trial log stretches {})".format(
                RETURN_MAXITER, todo.size, todo[0], xtr[todo[0]]), todo)


def _det33(A):
    """Determinants of ``(n, 3, 3)`` matrices, written out."""
    return (A[:, 0, 0] * (A[:, 1, 1] * A[:, 2, 2] - A[:, 1, 2] * A[:, 2, 1])
            - A[:, 0, 1] * (A[:, 1, 0] * A[:, 2, 2] - A[:, 1, 2] * A[:, 2, 0])
            + A[:, 0, 2] * (A[:, 1, 0] * A[:, 2, 1] - A[:, 1, 1] * A[:, 2, 0]))


def _embed3(F):
    """``(n, 3, 3)`` deformation gradients from ``(d, d, n)`` (plane strain
    in 2-D: :math:`F_{33} = 1`)."""
    d, n = F.shape[0], F.shape[2]
    if d == 3:
        return np.ascontiguousarray(np.moveaxis(F, 2, 0))
    F3 = np.zeros((n, 3, 3))
    F3[:, :d, :d] = np.moveaxis(F, 2, 0)
    F3[:, 2, 2] = 1.0
    return F3


class Response:
    """The stress update of :class:`J2Plasticity` at a set of points:
    ``P`` (``(d, d, ...)``), the trial ``history`` (what a converged step
    commits), ``plastic`` (where the step yields), :meth:`tangent` and
    :meth:`energy`."""

    def __init__(self, material, F, history, mean_stress=None,
                 average=None, tracker=None):
        self.material = m = material
        self.F = F
        d = F.shape[0]
        if d not in (2, 3) or F.shape[1] != d:
            raise ValueError("J2Plasticity needs F of shape (d, d, ...) with "
                             "d = 2 (plane strain) or 3, got {}".format(
                                 F.shape))
        if not np.isfinite(m.K):
            raise ValueError("{!r} is incompressible (K = inf): only the "
                             "formulations with a pressure unknown (IUnlP0) "
                             "carry it, through its isochoric part".format(m))
        self.point_shape = F.shape[2:]
        n = int(np.prod(self.point_shape))
        if history["alpha"].size != n:
            raise ValueError("a history of {} points for F at {}".format(
                history["alpha"].size, n))
        Cp = history["Cp_inv"].reshape(3, 3, n)
        alpha_n = history["alpha"].reshape(n)
        F3 = _embed3(F.reshape(d, d, n))
        # non-finite F (a failed local solve upstream): NaN stresses
        # there, so that the caller's step is cut
        bad = ~np.all(np.isfinite(F3), axis=(1, 2))
        if bad.any():
            F3[bad] = np.eye(3)
        self._F3 = F3
        Cpn = np.moveaxis(Cp, 2, 0)
        self._G = F3 @ Cpn  # F C_p,n^-1
        btr = self._G @ np.swapaxes(F3, 1, 2)
        btr = 0.5 * (btr + np.swapaxes(btr, 1, 2))
        self._btr = btr
        # the elastic trial state without eigenvalues: bb = btr / det^(1/3)
        # (the isochoric part), tau_dev = mu dev(bb); the spectral form
        # of the return map is needed at the plastic points alone
        det = _det33(btr)
        if not np.all(det > 0):
            neg = np.flatnonzero(~(det > 0))
            raise ReturnMapError(
                "J2Plasticity: b_e^tr not positive definite at {} point(s) "
                "(first {}): F inverted".format(neg.size, neg[0]), neg)
        bb = btr / np.cbrt(det)[:, None, None]
        tr = bb[:, 0, 0] + bb[:, 1, 1] + bb[:, 2, 2]
        tau_full = m.mu * bb
        for i in range(3):
            tau_full[:, i, i] -= m.mu * tr / 3.0
        vm = np.sqrt(1.5 * (tau_full * tau_full).sum(axis=(1, 2)))
        plastic = vm - m.yield_stress(alpha_n) > 0
        if m.damage is not None:
            damage = history["damage"].reshape(n).copy()
            plastic &= damage < m.damage.Dc  # a failed point does not flow
        self._trbb = tr
        alpha = alpha_n.copy()
        p = np.flatnonzero(plastic)
        self._p = p
        Finv3, J = inverse_and_det(np.moveaxis(F3, 0, -1))
        self._Finv = Finv = np.moveaxis(Finv3, -1, 0)  # (n, 3, 3)
        self.J = J
        Cp_new = Cpn.copy()  # elastic points keep C_p,n^-1
        if p.size:
            alpha[p] += self._return(btr, alpha_n, p, tau_full, Cp_new)
        self.plastic = plastic.reshape(self.point_shape)
        vol = 0.5 * m.K * (J ** 2 - 1) if m.K > 0 else np.zeros(n)
        failed = np.zeros(n, dtype=bool)
        if m.damage is not None:
            damage, released, failed, vol = self._damage(
                history, damage, (alpha, alpha_n), p, tau_full, vol,
                mean_stress, btr, average, tracker)
        self._failed = failed
        self.failed = failed.reshape(self.point_shape)
        for i in range(3):
            tau_full[:, i, i] += vol
        P3 = tau_full @ np.swapaxes(Finv, 1, 2)
        self._P3 = P3
        P3[bad] = np.nan
        self.P = np.moveaxis(P3[:, :d, :d], 0, 2).reshape(
            (d, d) + self.point_shape)
        self.history = {
            "Cp_inv": np.moveaxis(Cp_new, 0, 2).reshape(
                (3, 3) + self.point_shape),
            "alpha": alpha.reshape(self.point_shape)}
        if m.damage is not None:
            self.history["damage"] = damage.reshape(self.point_shape)
            self.history["released"] = released.reshape(self.point_shape)
            self.history["F_last"] = np.moveaxis(self._F3, 0, 2).reshape(
                (3, 3) + self.point_shape)
            self.history["closure"] = self._closure.reshape(self.point_shape)
            if self._line is not None:
                self.history["crack_line"] = self._line.reshape(
                    (4,) + self.point_shape)
        self._A = None
        self._spectral = None

    def _return(self, btr, alpha_n, p, tau_full, Cp_new):
        r"""The return map at the plastic points ``p``: their stress and
        :math:`C_p^{-1}` (in place in ``tau_full``, ``Cp_new``,
        ``_trbb``) and the increments of :math:`\alpha` there."""
        beta, Q = np.linalg.eigh(btr[p])
        xtr = np.log(beta)
        x, da, Jl, tau, T = self.material.return_map(xtr, alpha_n[p])
        # d(x, dalpha)/d xtr = Jl^-1 [I; 0]
        dtdx = T @ np.linalg.inv(Jl)[:, :3, :3]
        self._plastic_spectral = (beta, Q, x, tau, dtdx)
        QT = np.swapaxes(Q, 1, 2)
        tau_full[p] = (Q * tau[:, None, :]) @ QT
        ex = np.exp(x)
        self._trbb[p] = (ex / np.cbrt(ex.prod(axis=1))[:, None]).sum(
            axis=1)
        Fp = self._Finv[p] @ Q
        Cp_p = (Fp * ex[:, None, :]) @ np.swapaxes(Fp, 1, 2)
        Cp_new[p] = 0.5 * (Cp_p + np.swapaxes(Cp_p, 1, 2))
        return da

    def _damage(self, history, damage, alphas, p, tau_full, vol,
                mean_stress, btr, average=None, tracker=None):
        """``(damage, released, failed, vol)``: the damage law's step at
        the points (thesis 8.1), the energy density released by the
        points failing now, and a failed point's stress (no deviatoric
        part, pressure only in compression; in place in ``tau_full`` and
        ``_trbb``)."""
        m, J = self.material, self.J
        alpha, alpha_n = alphas
        n = J.shape[0]
        mean = vol if mean_stress is None else np.broadcast_to(
            np.asarray(mean_stress, dtype=float).reshape(-1), (n,))
        if p.size:
            damage[p] += m.damage.increment(alpha[p] - alpha_n[p],
                                            triaxiality(tau_full[p],
                                                        mean[p]))
        strain_law = getattr(m.damage, "indicator", None)
        stress_law = getattr(m.damage, "stress_indicator", None)
        tracked = getattr(m.damage, "tracking", False)
        self._line = None
        if strain_law is not None or stress_law is not None:
            if strain_law is None or tracked:
                # the stress before failure (a mixed formulation's
                # pressure where it gives one)
                tau = tau_full.copy()
                for i in range(3):
                    tau[:, i, i] += mean
            if strain_law is not None:  # a criterion on the elastic strain
                indicator = strain_law(btr)
            else:
                indicator = stress_law(tau, J)
            if getattr(m.damage, "radius", None) is not None:
                if average is None:
                    raise ValueError(
                        "{!r} is nonlocal: it is evaluated at a model's "
                        "points, which the model binds (PG or FE "
                        "displacement and mean-dilatation models), not "
                        "by itself".format(m.damage))
                # the nonlocal mean over the intact points
                indicator = average(indicator, history["damage"].reshape(n)
                                    < m.damage.Dc)
            if tracked:
                if tracker is None:
                    raise ValueError(
                        "{!r} tracks its crack over a model's points, which "
                        "the model binds (PG and FE displacement and "
                        "mean-dilatation models), not by itself".format(
                            m.damage))
                line = history.get("crack_line")  # none: a history of
                # the untracked law (a checkpoint): no lines yet
                indicator, self._line = tracker(
                    indicator, tau / J[:, None, None],
                    history["damage"].reshape(n) >= m.damage.Dc,
                    np.zeros((4, n)) if line is None
                    else line.reshape(4, n), m.damage.Dc)
            damage = np.maximum(damage, indicator)
        failed = damage >= m.damage.Dc
        # the energy density a point failing now releases: what it
        # would store intact, less what it keeps (pressure in
        # compression)
        released = history["released"].reshape(n).copy()
        now = failed & (history["damage"].reshape(n) < m.damage.Dc)
        if now.any():
            Jn = J[now]
            tension = Jn >= 1  # the volumetric part goes too
            released[now] += 0.5 * m.mu * (self._trbb[now] - 3) + \
                np.where(tension, 0.25 * m.K * (Jn ** 2 - 1
                                                - 2 * np.log(Jn)), 0.0)
            released[now] -= self._dropped_work(history, now, tau_full,
                                                vol, tension)
        self._closure = self.closure_step(history, mean_stress)
        # a failed point: no deviatoric stress, pressure only in
        # compression (module docstring of skfem_pg.materials.damage)
        tau_full[failed] = 0.0
        self._trbb[failed] = 3.0
        return damage, released, failed, np.where(failed & (J >= 1), 0.0,
                                                  vol)

    def _dropped_work(self, history, now, tau_full, vol, tension):
        r"""Half the work of the stress the points ``now`` drop, over the
        step: :math:`\tfrac12 (P - P_{failed}) : (F - F_n)` per unit
        volume.  A point failing in a step carries its failed stress at
        the step's end, so the step's work (the trapezoid of the internal
        forces, as the explicit and Newmark drivers book it) took only
        the intact stress at its start; the energy the point releases is
        its intact energy at the end less this half (to third order in
        the step; exact bookkeeping against the driver's work for total
        Lagrangian forces, :math:`f\cdot\Delta u = \sum V P:\Delta F`).
        Zero for a history without ``F_last`` (a checkpoint of an older
        version)."""
        F_last = history.get("F_last")
        if F_last is None:
            return 0.0
        n = self._F3.shape[0]
        dF = self._F3[now] - np.moveaxis(F_last.reshape(3, 3, n), 2, 0)[now]
        drop = tau_full[now].copy()  # deviatoric, intact
        for i in range(3):
            drop[:, i, i] += np.where(tension, vol[now], 0.0)
        P = drop @ np.swapaxes(self._Finv[now], 1, 2)
        return 0.5 * np.einsum("kij,kij->k", P, dF)

    def closure_step(self, history, mean_stress=None):
        r"""The committed ``closure`` plus this step's at the points
        failed at the step's start: what the trapezoid of the step's
        work books on a failed point's stress, :math:`\tfrac12 (P_n +
        P) : (F - F_n)`, less the change of its stored energy
        :math:`W(J) - W(J_n)`.  A failed point carries pressure in
        compression only (:math:`P = \tfrac12 K (J^2 - 1) F^{-T}` for
        :math:`J < 1`, zero in tension): its stress has a kink at
        :math:`J = 1`, and a step across it books :math:`\tfrac12 K a b`
        more work than the energy stored (:math:`a, b` the step's
        :math:`|J - 1|` on either side), second order in the step and not
        the third of a smooth stress.  The explicit and Newmark drivers'
        records carry the sum as ``closure`` and their balance takes it
        off the internal work (issue 51: on the mode-I plate with the
        nonlocal criterion, 1.2e-2 of the internal work at the default
        step).  Exact against the drivers' work for total
        Lagrangian forces (:math:`f\cdot\Delta u = \sum V P:\Delta
        F`); zero where the mixed formulations give the mean stress
        (``mean_stress``: their pressure is not the point's) and for a
        history without ``F_last`` (a checkpoint of an older version)."""
        m, n = self.material, self.J.shape[0]
        c = history.get("closure")
        c = np.zeros(n) if c is None else c.reshape(n).copy()
        F_last = history.get("F_last")
        was = history["damage"].reshape(n) >= m.damage.Dc
        if F_last is None or mean_stress is not None or m.K <= 0 \
                or not was.any():
            return c
        Fn = np.moveaxis(F_last.reshape(3, 3, n), 2, 0)[was]
        Finv_n, Jn = inverse_and_det(np.moveaxis(Fn, 0, -1))
        Finv_n = np.moveaxis(Finv_n, -1, 0)
        J = self.J[was]

        def stress_and_energy(J, Finv):
            closed = J < 1
            P = (np.where(closed, 0.5 * m.K * (J ** 2 - 1), 0.0)[:, None,
                                                                 None]
                 * np.swapaxes(Finv, 1, 2))
            return P, np.where(closed, 0.25 * m.K * (
                J ** 2 - 1 - 2 * np.log(J)), 0.0)
        P0, W0 = stress_and_energy(Jn, Finv_n)
        P1, W1 = stress_and_energy(J, self._Finv[was])
        c[was] += 0.5 * np.einsum("kij,kij->k", P0 + P1,
                                  self._F3[was] - Fn) - (W1 - W0)
        return c

    def spectral(self):
        """``(beta, Q, tau, dtau/dxtr)`` at every point: eigenvalues and
        vectors of the trial :math:`b_e^{tr}`, principal deviatoric
        Kirchhoff stresses and their derivatives by the trial log
        stretches (the return map's at the plastic points); computed on
        demand (the tangent), not for a stress alone."""
        if self._spectral is None:
            m = self.material
            beta, Q = np.linalg.eigh(self._btr)
            tau, dtdx = m._tau(np.log(beta))
            if self._p.size:
                bp, Qp, _, taup, dtp = self._plastic_spectral
                beta[self._p], Q[self._p] = bp, Qp
                tau[self._p], dtdx[self._p] = taup, dtp
            self._spectral = (beta, Q, tau, dtdx)
        return self._spectral

    def energy(self):
        """Stored elastic energy density at the points."""
        m = self.material
        W = 0.5 * m.mu * (self._trbb - 3)
        if m.K > 0:
            J = self.J
            W = W + np.where(self._failed & (J >= 1), 0.0, 0.25 * m.K * (
                J ** 2 - 1 - 2 * np.log(J)))
        return W.reshape(self.point_shape)

    def tangent(self):
        r""":math:`\mathbb A_{iJkL} = \partial P_{iJ}/\partial F_{kL}` of the
        stress update (the algorithmic tangent), ``(d, d, d, d, ...)``."""
        if self._A is None:
            self._A = self._tangent()
        return self._A

    def _tangent(self):
        m = self.material
        beta, Q, tau, dtdx = self.spectral()
        n = beta.shape[0]
        t = dtdx / beta[:, None, :]  # d tau_A / d beta_B
        # the spectral (shear) coefficients theta_AB, A != B
        Dp = np.zeros((n, 3, 3, 3, 3))
        for A in range(3):
            for B in range(3):
                Dp[:, A, A, B, B] = t[:, A, B]
        scale = beta.max(axis=1)
        for A, B in ((0, 1), (0, 2), (1, 2)):
            gap = beta[:, A] - beta[:, B]
            close = np.abs(gap) <= EIGEN_GAP * scale
            safe = np.where(close, 1.0, gap)
            th = np.where(close, 0.5 * (t[:, A, A] - t[:, A, B]
                                        + t[:, B, B] - t[:, B, A]),
                          (tau[:, A] - tau[:, B]) / safe)
            for (a, b) in ((A, B), (B, A)):
                Dp[:, a, b, a, b] += 0.5 * th
                Dp[:, a, b, b, a] += 0.5 * th
        # rotate to the reference axes: D_imab = Q_iA Q_mB Q_aC Q_bD D'_ABCD,
        # i.e. QQ D' QQ^T with the 9 x 9 Kronecker product QQ = Q (x) Q
        # (batched matrix products: a quarter of the four einsums' time)
        QQ = (Q[:, :, None, :, None] * Q[:, None, :, None, :]).reshape(
            n, 9, 9)
        D = QQ @ Dp.reshape(n, 9, 9) @ np.swapaxes(QQ, 1, 2)
        # A_iJkL = 2 D_imkb G_bL Finv_Jm - P_iL Finv_Jk  (+ volumetric)
        E = (D.reshape(n, 27, 3) @ self._G).reshape(n, 3, 3, 3, 3)  # imkL
        Finv = self._Finv
        A = 2 * (np.moveaxis(E, 2, 4).reshape(n, 27, 3)  # (ikL, m)
                 @ np.swapaxes(Finv, 1, 2)).reshape(n, 3, 3, 3, 3)  # ikLJ
        A = np.moveaxis(A, 4, 2)  # iJkL
        P3 = self._P3
        A -= P3[:, :, None, None, :] * Finv[:, None, :, :, None]
        failed = self._failed
        if failed.any():  # P = p F^-T: only the two terms below remain
            A[failed] = 0.0
            A[failed] -= (P3[failed, :, None, None, :]
                          * Finv[failed, None, :, :, None])
        if m.K > 0:
            J2 = np.where(failed & (self.J >= 1), 0.0, self.J ** 2)
            FinvT = np.swapaxes(Finv, 1, 2)
            # d[(K/2)(J^2 - 1) F^-T]: K J^2 F^-T x F^-T; the -F^-1 F^-1
            # part is in -P_iL Finv_Jk already
            A += m.K * J2[:, None, None, None, None] * \
                FinvT[:, :, :, None, None] * FinvT[:, None, None, :, :]
        d = self.F.shape[0]
        A = A[:, :d, :d, :d, :d]
        return np.moveaxis(A, 0, -1).reshape((d,) * 4 + self.point_shape)
