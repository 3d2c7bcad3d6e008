"""What a driver may ask of a model: the model protocol.

Newton's method (:func:`skfem_pg.solvers.newton`, serial and distributed),
Newmark and central differences, checkpoints and :class:`~skfem_pg.scenes.
Scene` use a model only through these members.
:class:`~skfem_pg.formulations.Hyperelastic` implements them for the
displacement formulations; the mixed and stabilized ones extend it.  A
formulation of one's own satisfies :class:`Model` (most simply by
subclassing ``Hyperelastic``) and is registered with
:func:`skfem_pg.register_formulation`.

The unknowns ``x`` hold the displacements first (``n_u`` of them, in the
basis' scikit-fem numbering), then the model's global fields (``N`` in
all).  A *state* is what the model computes once per iterate and reuses
(deformation gradients, condensed fields); drivers pass it back unread.
"""
from typing import Protocol, runtime_checkable


@runtime_checkable
class Model(Protocol):
    """The members a driver uses (see the module docstring)."""

    #: the displacement basis (a FamilyBasis or a scikit-fem Basis)
    basis: object
    #: number of displacement unknowns, first in ``x``
    n_u: int
    #: number of all unknowns
    N: int

    def initial(self):
        """The unknowns of the undeformed, unloaded state."""

    def state(self, x):
        """The state at the unknowns ``x`` (reused by the calls below)."""

    def internal_force(self, state):
        """:math:`f_{int}`, ``(N,)``."""

    def tangent(self, state):
        """:math:`\\partial f_{int} / \\partial x`, sparse ``(N, N)``."""

    def min_J(self, state):
        """The smallest :math:`\\det F` at the model's points (a driver
        cuts a step where it is not positive)."""

    def commit(self, state):
        """A step converged at ``state``: commit internal variables.  A
        model whose discretization changes here (crack-aware families
        rebuilt) returns ``True``; the time integrators then evaluate its
        internal force again before they use it."""

    def fields(self, x):
        """The model's extra fields of ``x`` by name (``{}`` if none)."""


#: the members of :class:`Model`, for the messages that name the missing
MEMBERS = ("basis", "n_u", "N", "initial", "state", "internal_force",
           "tangent", "min_J", "commit", "fields")


def _missing(model):
    return ", ".join(m for m in MEMBERS if not hasattr(model, m))


def check_model(model, token):
    """``model`` if it satisfies :class:`Model`, else ``TypeError`` naming
    the formulation ``token`` and the missing members."""
    if isinstance(model, Model):
        return model
    raise TypeError("formulation {!r} built a {} without {} (the model "
                    "protocol, skfem_pg.formulations.protocol.Model)".format(
                        token, type(model).__name__, _missing(model)))


def require_model(model, driver):
    """``model`` if it satisfies :class:`Model`, else ``TypeError`` naming
    the ``driver`` and the members it lacks — where a driver takes a
    model, so that the drivers use ``model.N`` and ``model.n_u`` without
    probing."""
    if isinstance(model, Model):
        return model
    raise TypeError("{} takes a model (skfem_pg.formulations.protocol."
                    "Model); {} lacks {}".format(
                        driver, type(model).__name__, _missing(model)))
