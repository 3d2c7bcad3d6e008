r"""History variables at a model's integration points (thesis 4.4.2).

A stateful material (:class:`~skfem_pg.materials.J2Plasticity`) evaluates
the stress from the deformation gradient *and* the internal variables of the
last converged step.  :class:`History` binds it to the points at which a
formulation evaluates its material — per family member :math:`(k, j)` for
the fully integrated PG formulations (the flat layout ``(1, N_q)``), per
Gauss point ``(n_elements, n_qp)`` for FE — and offers the formulation the
interface of a stateless material (``stress(F)``, ``tangent(F)``,
``energy(F)``), so every formulation carries plasticity unchanged.

* ``committed``: the internal variables of the last converged step; every
  evaluation starts from them (a Newton iteration never changes them);
* :meth:`commit`: after a converged step, the response at that step's
  ``F`` becomes the committed state; a step that Newton cuts is simply not
  committed, so the state after a failed step is the last converged one
  exactly (rollback);
* :meth:`save` / :meth:`restore`: copies of the committed arrays, which a
  checkpoint stores with the solution (:mod:`skfem_pg.solvers.checkpoint`).

The last response is cached (keyed on the identity of ``F``), so the
stress and the tangent at one state cost one return map.
"""
import copy
from contextlib import contextmanager

import numpy as np

from ..discretization.crack_tracking import CrackTracker
from ..discretization.nonlocal_mean import NonlocalAverage


class History:
    """The committed internal variables of ``material`` at a model's
    points; allocated on the first evaluation (the points' shape is that of
    ``F.shape[2:]``).  ``points``: a callable giving the basis whose
    integration points these are (the model's ``point_basis``), which a
    nonlocal damage law averages over
    (:class:`~skfem_pg.materials.damage.NonlocalStrainDamage`)."""

    stateful = True

    def __init__(self, material, points=None):
        if not getattr(material, "stateful", False):
            raise TypeError("{!r} has no history".format(material))
        self.material = material
        self.points = points
        self.committed = None
        self._last = None  # (F, response)
        self._mean = None  # (F, mean stress): bind_mean_stress
        self._average = None  # a NonlocalAverage, for its basis
        self._tracker = None  # a CrackTracker, for its basis

    def __repr__(self):
        return "History({!r})".format(self.material)

    def _check(self, F):
        shape = F.shape[2:]
        if self.committed is None:
            self.committed = self.material.initial_history(shape)
        elif self.committed["alpha"].shape != shape:
            raise ValueError(
                "the history of {!r} lives at points of shape {}, F has {}: "
                "a plastic material is evaluated only at the model's "
                "integration points".format(
                    self.material, self.committed["alpha"].shape, shape))

    def bind_mean_stress(self, F, mean_stress):
        """Evaluate the points at ``F`` (this very array) with the mean
        (Kirchhoff) stress ``mean_stress`` for the damage law's
        triaxiality: a mixed formulation's pressure, which the isochoric
        law does not see (:class:`~skfem_pg.formulations.
        MeanDilatation`)."""
        self._mean = (F, mean_stress)
        if self._last is not None and self._last[0] is F:
            self._last = None

    def response(self, F):
        """The material's response to ``F`` from the committed state."""
        if self._last is not None and self._last[0] is F:
            return self._last[1]
        self._check(F)
        kw = {}
        if self._mean is not None and self._mean[0] is F:
            kw["mean_stress"] = self._mean[1]
        damage = getattr(self.material, "damage", None)
        radius = getattr(damage, "radius", None)
        if radius is not None:
            kw["average"] = self._on_points(
                self.nonlocal_average(radius), F, "the nonlocal mean")
        if getattr(damage, "tracking", False):
            kw["tracker"] = self._on_points(self.crack_tracker(), F,
                                            "crack tracking")
        r = self.material.update(F, self.committed, **kw)
        self._last = (F, r)
        return r

    def _on_points(self, over, F, what):
        """``over`` (a nonlocal mean or a crack tracker over the point
        basis), checked against the points ``F`` lives at."""
        n = int(np.prod(F.shape[2:]))
        if n != over.n_points:
            raise ValueError(
                "{!r}: the model evaluates its material at {} points, its "
                "point basis has {} integration points (a formulation with "
                "the material at the masters, as U1SIG): {} is built for "
                "the PG and FE displacement and mean-dilatation models"
                .format(self.material.damage, n, over.n_points, what))
        return over

    def nonlocal_average(self, radius):
        """The :class:`~skfem_pg.discretization.nonlocal_mean.
        NonlocalAverage` of ``radius`` over the points (built again when
        the model's point basis changes: a crack-aware update)."""
        basis = None if self.points is None else self.points()
        if basis is None:
            raise ValueError(
                "{!r} is nonlocal, and this History was not given its "
                "points (History(material, points=...))".format(
                    self.material.damage))
        a = self._average
        if a is None or a.basis is not basis or a.radius != radius:
            self._average = a = NonlocalAverage(basis, radius)
        return a

    def crack_tracker(self):
        """The :class:`~skfem_pg.discretization.crack_tracking.
        CrackTracker` of the material's tracked damage law over the points
        (built again when the model's point basis changes, keeping its
        record of the most it held)."""
        basis = None if self.points is None else self.points()
        law = self.material.damage
        if basis is None:
            raise ValueError(
                "{!r} tracks its crack, and this History was not given its "
                "points (History(material, points=...))".format(law))
        t = self._tracker
        if t is None or t.basis is not basis or t.law is not law:
            self._tracker = CrackTracker(basis, law)
            if t is not None and t.law is law:  # what it held so far
                self._tracker.most_held = t.most_held
            t = self._tracker
        return t

    # the stateless-material interface the formulations call
    def stress(self, F):
        return self.response(F).P

    def tangent(self, F):
        return self.response(F).tangent()

    def energy(self, F):
        return self.response(F).energy()

    # -- steps ---------------------------------------------------------
    def commit(self, F):
        """Make the response at ``F`` (a converged step) the committed
        state."""
        r = self.response(F)
        self.committed = {k: v.copy() for k, v in r.history.items()}
        self._last = None

    def save(self):
        """Copies of the committed arrays (``None`` before any
        evaluation)."""
        if self.committed is None:
            return None
        return {k: v.copy() for k, v in self.committed.items()}

    def restore(self, saved):
        """Set the committed state to ``saved`` (from :meth:`save`)."""
        self.committed = None if saved is None else {
            k: np.array(v, dtype=float) for k, v in saved.items()}
        self._last = None

    @contextmanager
    def elastic_predictor(self):
        """Within this context the material does not yield: it answers
        with the elastic trial response from the committed state (the
        stiffness of elastic unloading in the current configuration, what
        the stable time step of an explicit run is estimated from)."""
        material, last = self.material, self._last
        elastic = copy.copy(material)
        elastic.yield_stress = lambda alpha: np.full(np.shape(alpha),
                                                     np.inf)
        self.material, self._last = elastic, None
        try:
            yield self
        finally:
            self.material, self._last = material, last

    def alpha(self):
        """The committed hardening variable (the accumulated plastic
        strain) at the points."""
        if self.committed is None:
            return None
        return self.committed["alpha"]

    def damage(self):
        """The committed damage indicator at the points (``None`` without
        a damage law, or before the first evaluation)."""
        if self.committed is None:
            return None
        return self.committed.get("damage")

    def failed(self):
        """Where the committed damage has reached the law's critical value
        (``None`` as for :meth:`damage`)."""
        D = self.damage()
        return None if D is None else D >= self.material.damage.Dc

    def released(self):
        """The committed energy density each point released when it
        failed (``None`` as for :meth:`damage`)."""
        if self.committed is None:
            return None
        return self.committed.get("released")

    def closure(self):
        """The committed energy density the steps lost at each failed
        point (:meth:`~skfem_pg.materials.plasticity.Response.
        closure_step`; ``None`` as for :meth:`damage`)."""
        if self.committed is None:
            return None
        return self.committed.get("closure")
