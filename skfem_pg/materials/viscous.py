r"""A Newtonian fluid, weakly compressible: the material of the thesis'
flow outlook (8.2), whose viscous law the thesis does not write.

The Cauchy stress is a bulk pressure plus Stokes' viscous stress,

.. math::

    \sigma = \tfrac K2\big(J - J^{-1}\big) I
        + 2\eta\,\mathrm{dev}\,D, \qquad
    D = \mathrm{sym}\,L,\quad L = \dot F F^{-1},

so :math:`P = \tfrac K2 (J^2 - 1) F^{-T} + J\eta\big(L + L^T
- \tfrac23 \mathrm{tr} L\, I\big) F^{-T}` (the volumetric part is
:class:`~skfem_pg.materials.NeoHookeIsoVol`'s with :math:`\mu = 0`; in 2-D
plane strain, :math:`D_{zz} = 0`).  The fluid has no shear stiffness: it
stores only the volumetric energy :math:`\frac K4 (J^2 - 1 - 2\ln J)`, and
the viscous stress dissipates.

**The rate** :math:`\dot F` is the time integrator's: each point keeps the
committed :math:`F_n` (a history, :class:`~skfem_pg.formulations.History`)
and the driver binds, per step, :math:`\dot F = a\,(F - F_n) + \dot F_0`
with Newmark's :math:`a = \gamma/(\beta\Delta t)` and :math:`\dot F_0` the
gradient of :math:`(1 - \gamma/\beta) v_n + \Delta t (1 - \gamma/2\beta)
a_n` (:func:`skfem_pg.newmark`), so that :math:`\dot F = \nabla v_{n+1}`,
Newmark's velocity, wherever :math:`F` is linear in the displacements;
after the run, the final velocity gradient stays bound (the model's
fields and stresses at the final state).  Before a run, or after one
that stopped early, no rate is bound and the material refuses to answer;
static Newton and central differences refuse the model.
"""
import numpy as np

from .constants import check_finite, check_moduli
from .hyperelastic import inverse_and_det

#: the Stokes deviator: 2/3 of the trace, in 2-D (plane strain) too
_DEV = 2.0 / 3.0


class NoRateError(RuntimeError):
    """A viscous material was evaluated without a time step."""


class NewtonianFluid:
    r"""A weakly compressible Newtonian fluid (module docstring): bulk
    modulus ``K``, dynamic viscosity ``eta``.  Give its density to
    :func:`~skfem_pg.lumped_mass`.  A stateful material: it runs in
    :func:`~skfem_pg.newmark` on PBG UnlP0 with the local VC correction
    (``vc_solver="local"``) and on FE Q1P0 / H1P0, which take the
    volumetric part themselves; the formulations that cannot hold a fluid
    are refused, each for its measured reason
    (:func:`skfem_pg.solvers.rates.check_fluid_model`).

    Examples
    --------
    Water (thesis 8.2), in Pa and Pa s:

    >>> water = NewtonianFluid(K=2.08e9, eta=1e-3)
    >>> water.mu, water.nu_kinematic(1e3)
    (0.0, 1e-06)

    """

    stateful = True
    #: no shear stiffness (the mixed formulations' isochoric modulus)
    mu = 0.0

    def __init__(self, *, K, eta):
        (self.K,) = check_moduli(K=K)
        (self.eta,) = check_finite("NewtonianFluid", eta=eta)
        if self.eta < 0:
            raise ValueError("NewtonianFluid: the viscosity eta must not "
                             "be negative, got {}".format(self.eta))
        # (a, Fdot0), bound by the time integrator; private: not a
        # parameter (a checkpoint's fingerprint of the material omits it)
        self._rate = None

    def __repr__(self):
        return "NewtonianFluid(K={:g}, eta={:g})".format(self.K, self.eta)

    def nu_kinematic(self, rho):
        """The kinematic viscosity :math:`\\eta/\\rho`."""
        return self.eta / float(rho)

    def isochoric(self, with_damage=False):
        """The viscous part alone (``K = 0``): what the mixed
        formulations evaluate at their points (they take the volumetric
        part themselves)."""
        m = NewtonianFluid(K=1.0, eta=self.eta)
        m.K = 0.0
        return m

    @property
    def rate(self):
        """The bound ``(a, Fdot0)``, or ``None``."""
        return self._rate

    def bind_rate(self, a, Fdot0):
        r"""Bind :math:`\dot F = a (F - F_n) + \dot F_0` (module
        docstring); ``a = None`` unbinds."""
        self._rate = None if a is None else (float(a), Fdot0)

    # -- the stateful-material interface of History ---------------------
    def initial_history(self, point_shape):
        # F_n is the identity (an empty array until the first commit:
        # the dimension comes with the first F)
        return {"alpha": np.zeros(point_shape), "F": np.zeros(0)}

    def update(self, F, history):
        """The response at ``F`` from the committed ``history``."""
        if self.rate is None:
            raise NoRateError(
                "{!r} has no time step bound: a viscous stress needs the "
                "rate of F, which skfem_pg.newmark binds per step (static "
                "Newton and central differences do not)".format(self))
        return _Response(self, F, history)

    def stress(self, F):
        raise NoRateError("{!r} is stateful: evaluate it through a model's "
                          "history in skfem_pg.newmark".format(self))

    tangent = stress


class _Response:
    """Stress, tangent and energy of :class:`NewtonianFluid` at ``F``."""

    def __init__(self, fluid, F, history):
        self.fluid, self.F = fluid, F
        d = F.shape[0]
        Fn = history["F"]
        if Fn.size == 0:  # the undeformed state, at every point
            Fn = np.broadcast_to(np.eye(d).reshape((d, d) + (1,) * (
                F.ndim - 2)), F.shape)
        a, Fdot0 = fluid.rate
        self.a = a
        self.Finv, self.J = inverse_and_det(F)
        self.L = np.einsum("ik...,kj...->ij...", a * (F - Fn) + Fdot0,
                           self.Finv)
        FinvT = np.swapaxes(self.Finv, 0, 1)
        L, J, eta = self.L, self.J, fluid.eta
        trL = np.einsum("ii...->...", L)
        sym = L + np.swapaxes(L, 0, 1)
        sym -= _DEV * trL * np.eye(d).reshape((d, d) + (1,) * (F.ndim - 2))
        self.P = (np.einsum("ib...,bJ...->iJ...", J * eta * sym, FinvT)
                  + 0.5 * fluid.K * (J ** 2 - 1) * FinvT)
        self.history = {"alpha": np.asarray(history["alpha"]),
                        "F": np.array(F, dtype=float)}

    def energy(self):
        J = self.J
        return 0.25 * self.fluid.K * (J ** 2 - 1 - 2 * np.log(J))

    def tangent(self):
        r""":math:`\partial P/\partial F`: the rate part :math:`a\,
        \partial P/\partial\dot F`, the change of :math:`J`,
        :math:`F^{-1}` and :math:`L` at a fixed :math:`\dot F`, and the
        volumetric part."""
        Finv, J, L, P = self.Finv, self.J, self.L, self.P
        eta, K, d = self.fluid.eta, self.fluid.K, self.F.shape[0]
        ex = (1,) * (self.F.ndim - 2)
        I = np.eye(d).reshape((d, d) + ex)
        Cinv = np.einsum("Lb...,Jb...->LJ...", Finv, Finv)
        FL = np.einsum("Ja...,ak...->Jk...", Finv, L)  # F^-1 L
        e = np.einsum
        # a dP/dFdot: J eta (d_ik Cinv_LJ + Finv_Li Finv_Jk
        #                    - 2/3 Finv_Ji Finv_Lk)
        rate = (e("ik...,LJ...->iJkL...", I, Cinv)
                + e("Li...,Jk...->iJkL...", Finv, Finv)
                - _DEV * e("Ji...,Lk...->iJkL...", Finv, Finv))
        # at fixed Fdot: dL = -L dF F^-1, dJ = J tr(F^-1 dF),
        # d(F^-T) = -F^-T dF^T F^-T; P_v below is the viscous stress only
        FinvT = np.swapaxes(Finv, 0, 1)
        Pvol = 0.5 * K * (J ** 2 - 1) * FinvT
        Pv = P - Pvol
        geo = (e("iJ...,Lk...->iJkL...", Pv, Finv)
               - J * eta * (e("ik...,LJ...->iJkL...", L, Cinv)
                            + e("Li...,Jk...->iJkL...", Finv, FL)
                            - _DEV * e("Lk...,Ji...->iJkL...", FL, Finv))
               - e("iL...,Jk...->iJkL...", Pv, Finv))
        vol = (K * J ** 2 * e("iJ...,kL...->iJkL...", FinvT, FinvT)
               - 0.5 * K * (J ** 2 - 1) * e("Jk...,Li...->iJkL...", Finv,
                                            Finv))
        return self.a * J * eta * rate + geo + vol
