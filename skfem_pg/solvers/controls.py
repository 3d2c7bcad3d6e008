r"""The option records of the drivers: Newton's method
(:func:`~skfem_pg.solvers.newton`, serial and distributed), Newmark
(:func:`~skfem_pg.solvers.newmark`) and central differences
(:func:`~skfem_pg.solvers.central_difference`).

A driver takes its numerical controls as one record (``controls=``) or as
keywords of the record's field names, which replace the record's fields::

    from skfem_pg.solvers import NewtonControls, newton
    tight = NewtonControls(tol=1e-12, line_search=True)
    x, hist = newton(model, f, D=D, controls=tight, verbose=False)

Each record checks its values when it is made and names the one it
refuses; an unknown keyword raises ``TypeError`` naming it.
"""
import dataclasses
from typing import Optional

import numpy as np

from ..progress import check_verbose


class Controls:
    """What the records share: :meth:`of`."""

    @classmethod
    def of(cls, controls=None, defaults=None, **kw):
        """``controls`` (a record of this class, or ``None``) with ``kw``
        (keywords of its field names) replacing fields; ``defaults``: the
        keywords a driver's record starts from when ``controls`` is
        ``None``."""
        known = {f.name for f in dataclasses.fields(cls)}
        bad = sorted(set(kw) - known)
        if bad:
            raise TypeError("unknown control(s) {} of {}: the controls are "
                            "{}".format(", ".join(bad), cls.__name__,
                                        ", ".join(sorted(known))))
        if controls is None:
            controls = cls(**(defaults or {}))
        elif not isinstance(controls, cls):
            raise TypeError("controls must be a {}, got {}".format(
                cls.__name__, type(controls).__name__))
        return dataclasses.replace(controls, **kw) if kw else controls


@dataclasses.dataclass(frozen=True)
class NewtonControls(Controls):
    r"""The controls of Newton's method with adaptive load stepping, shared
    by :func:`~skfem_pg.solvers.newton` and the distributed
    :func:`skfem_pg.distributed.newton` (which pass their keywords of these
    names into one record).

    Attributes
    ----------
    steps
        Initial number of load steps (the step then adapts).
    tol
        Convergence: ``|r_free| <= tol * max(|λ f_ext|, |r_0|)`` where
        ``r_0`` is the first residual of the step; or every field's Newton
        increment below ``1e-10`` of its magnitude; or the energy of the
        last increment :math:`|\Delta x\cdot r|` below ``tol²`` times
        that of the first (a measure in units of work, whatever the
        fields: with pressures and dilatations as unknowns the residual
        norm mixes units); or, once the residual stops decreasing (its
        round-off floor, set by the bulk modulus and not by the load),
        that energy below ``ROUNDOFF_ENERGY · tol`` (:mod:`~skfem_pg.solvers.static`) times the first,
        or, flat for three iterations below ``STALL_RESIDUAL`` of the
        reference norm, below ``ROUNDOFF_ENERGY`` times the first (the
        history's ``reason`` then says "round-off floor").
    maxiter
        Newton iterations per load step at most.
    min_step
        The smallest load step: a step that would be cut below it raises
        :class:`~skfem_pg.solvers.ConvergenceError`.
    adaptive
        ``True``: a step that converges in at most 4 iterations doubles
        the next one, a failed step is halved (down to ``min_step``).
        ``False``: ``steps`` equal steps, and a failed one raises
        :class:`~skfem_pg.solvers.ConvergenceError` at once (robustness studies: the largest
        step that converges).
    predictor
        Start each load step from the linear extrapolation of the last two
        converged states (secant predictor) instead of the last one; a
        step that fails from it is cut like any other.
    line_search
        ``True``: halve an increment whose iterate fails, or a later
        one that raises the residual (at most
        :data:`~skfem_pg.solvers.static.LINE_SEARCH_HALVINGS` times), before the step counts as
        failed (:func:`~skfem_pg.solvers.static.newton_iterations`).  ``False``: full Newton
        increments, a failed iterate cuts the step.
    verbose
        ``True``: a line per load step (on rank 0 of a distributed run);
        ``False``: silent; ``"auto"``: the lines from a few seconds into
        the run on (:mod:`skfem_pg.progress`).
    reuse
        Modified Newton (serial :func:`~skfem_pg.solvers.newton` with a
        direct solve): keep the factorization of a tangent for later
        iterations and load steps while each increment cuts the residual
        by :data:`~skfem_pg.solvers.static.REUSE_CONTRACTION`, undo an
        increment that raises it, and refactorize a fresh tangent
        (:class:`~skfem_pg.solvers.static.KeptTangent`).  A step then
        doubles the next one when it needed at most 2 fresh tangents
        (the history's ``tangents``).

    Examples
    --------
    A record, or its fields as keywords of the driver (they replace the
    record's):

    >>> c = NewtonControls(steps=4, tol=1e-10)
    >>> NewtonControls.of(c, steps=8).steps, c.tol
    (8, 1e-10)

    """

    steps: int = 1
    tol: float = 1e-9
    maxiter: int = 25
    min_step: float = 1.0 / 1024
    adaptive: bool = True
    predictor: bool = True
    line_search: bool = False
    verbose: object = "auto"
    reuse: bool = False

    def __post_init__(self):
        check_controls(steps=self.steps, tol=self.tol, maxiter=self.maxiter,
                        min_step=self.min_step)
        check_verbose(self.verbose)
        if self.adaptive and 1.0 / self.steps < self.min_step:
            raise ValueError(
                "steps = {} asks for load steps of {:.3g}, below min_step = "
                "{:.3g}, where a failed step stops the run: use fewer steps "
                "or a smaller min_step".format(self.steps, 1.0 / self.steps,
                                               self.min_step))


@dataclasses.dataclass(frozen=True)
class NewmarkControls(Controls):
    """The controls of :func:`~skfem_pg.solvers.newmark`.

    Attributes
    ----------
    beta, gamma
        Newmark's parameters (default average acceleration, 1/4 and 1/2;
        ``gamma >= 1/2``).
    dt_min
        Smallest step before the run stops (default ``dt / 1024``).
    tol, maxiter, line_search
        Newton's method per step (:class:`NewtonControls`).
    max_contact_passes
        Solves per step at most while a wall's active set changes.
    output_every
        A record (and the callback) every this many converged steps.
    verbose
        Progress and cut steps: ``True``, ``False`` or ``"auto"``
        (:mod:`skfem_pg.progress`).
    predictor
        Where Newton's method starts a step: ``"displacement"`` (default:
        at the last step's unknowns) or ``"acceleration"`` (where the last
        acceleration, held constant, would take them).  Measured (issue
        51): the constant-acceleration start breaks incompressibility
        near held walls, and Newton on a stiff fluid (water in the
        Poiseuille channel, PBG UnlP0, 17 x 17 perturbed particles) then
        diverged and cut its steps: 186 steps instead of 25 and 33 s
        against 4 s from the last unknowns, the same answer; the 3-D
        dynamic torsion (U1SIG) 177 against 111 steps, 29 against 21 s;
        the dynamic Cook 76 against 66 Newton iterations.

    Examples
    --------
    >>> NewmarkControls().beta, NewmarkControls().gamma  # the trapezoidal rule
    (0.25, 0.5)

    """

    beta: float = 0.25
    gamma: float = 0.5
    dt_min: Optional[float] = None
    tol: float = 1e-8
    maxiter: int = 20
    line_search: bool = False
    max_contact_passes: int = 20
    output_every: int = 1
    verbose: object = "auto"
    predictor: str = "displacement"

    def __post_init__(self):
        if self.predictor not in ("displacement", "acceleration"):
            raise ValueError("predictor must be 'displacement' or "
                             "'acceleration', got {!r}".format(
                                 self.predictor))
        if not (np.isfinite(self.beta) and np.isfinite(self.gamma)
                and 0 < self.beta and 0 < self.gamma):
            raise ValueError("beta and gamma must be positive numbers, got "
                             "beta = {!r}, gamma = {!r}".format(self.beta,
                                                               self.gamma))
        if self.gamma < 0.5:
            raise ValueError(
                "gamma = {!r} < 1/2 makes Newmark's method add energy "
                "(negative numerical damping: a run's energy balance drifts "
                "by tens of per cent); use gamma >= 1/2 (1/2: no damping)"
                .format(self.gamma))
        check_controls(tol=self.tol, maxiter=self.maxiter)
        check_verbose(self.verbose)
        _positive_int(self.max_contact_passes, "max_contact_passes")
        _positive_int(self.output_every, "output_every")


@dataclasses.dataclass(frozen=True)
class ExplicitControls(Controls):
    """The controls of :func:`~skfem_pg.solvers.central_difference`.

    Attributes
    ----------
    safety
        The step is ``safety · 2/ω_max`` when no ``dt`` is given; in
        (0, 1].
    estimate_every
        Steps between estimates of ``ω_max``.
    output_every
        A record (and the callback) every this many steps; default about
        20 records, guessed from the first step.
    max_energy_error
        Stop with :class:`~skfem_pg.solvers.DynamicsError` when the
        relative energy balance error exceeds this.
    verbose
        Progress: ``True``, ``False`` or ``"auto"``
        (:mod:`skfem_pg.progress`).

    Examples
    --------
    >>> ExplicitControls.of(safety=0.5).safety
    0.5

    """

    safety: float = 0.8
    estimate_every: int = 100
    output_every: Optional[int] = None
    max_energy_error: float = 0.05
    verbose: object = "auto"

    def __post_init__(self):
        if not (np.isfinite(self.safety) and 0 < self.safety <= 1):
            raise ValueError("safety must be a factor in (0, 1] of the "
                             "stable step 2/omega_max (above 1 the central "
                             "differences are unstable), got {!r}".format(
                                 self.safety))
        _positive_int(self.estimate_every, "estimate_every")
        check_verbose(self.verbose)
        if self.output_every is not None:
            _positive_int(self.output_every, "output_every")
        if not self.max_energy_error > 0:
            raise ValueError("max_energy_error must be positive, got {!r}"
                             .format(self.max_energy_error))


def _positive_int(v, what):
    if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 1:
        raise ValueError("{} must be a positive integer, got {!r}".format(
            what, v))


def check_controls(steps=1, tol=1.0, maxiter=1, min_step=1.0, load0=0.0):
    """Named errors for load-stepping controls that would divide by zero,
    loop forever or run backwards."""
    if isinstance(steps, bool) or not isinstance(steps, (int, np.integer)) \
            or steps < 1:
        raise ValueError("steps must be a positive integer, got {!r}"
                         .format(steps))
    if isinstance(maxiter, bool) \
            or not isinstance(maxiter, (int, np.integer)) or maxiter < 1:
        raise ValueError("maxiter must be a positive integer, got {!r}"
                         .format(maxiter))
    if not (np.isfinite(tol) and tol > 0):
        raise ValueError("tol must be a positive number, got {!r}"
                         .format(tol))
    if not (np.isfinite(min_step) and 0 < min_step <= 1):
        raise ValueError("min_step must lie in (0, 1], got {!r}: the step "
                         "halving needs a floor".format(min_step))
    if not (np.isfinite(load0) and 0.0 <= load0 <= 1.0):
        raise ValueError("load0 must lie in [0, 1], got {!r}".format(load0))


__all__ = ["Controls", "ExplicitControls", "NewmarkControls",
           "NewtonControls", "check_controls"]
