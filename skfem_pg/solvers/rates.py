"""Rate-dependent materials in the drivers: the viscous stress of a
:class:`~skfem_pg.materials.NewtonianFluid` needs the rate of F, which
only an integrator with velocities can give.  :func:`skfem_pg.newmark`
binds Newmark's rate at the start (:func:`start_newmark_rate`) and per
step (:func:`bind_newmark_rate`); the other
drivers refuse such a model by name (:func:`refuse_rate_dependent`)."""
import numpy as np


def rate_material(model):
    """The rate-dependent material a model evaluates at its points (one
    with ``bind_rate``), else ``None``."""
    history = getattr(model, "history", None)
    material = getattr(history, "material", None)
    return material if hasattr(material, "bind_rate") else None


def refuse_rate_dependent(model, driver):
    """``ValueError`` naming ``driver`` and the material if ``model``'s
    material needs a rate (a viscous fluid)."""
    material = rate_material(model)
    if material is not None:
        raise ValueError(
            "{} has no velocities to give the viscous stress of {!r}: "
            "integrate it with skfem_pg.newmark".format(driver, material))


def start_newmark_rate(model, x, v, h, beta, gamma):
    r"""The rate at the start of a Newmark run from ``x`` with the
    velocities ``v``: the points' committed :math:`F_n` becomes that of
    ``x`` and :math:`\dot F = \frac{\gamma}{\beta h}(F - F_n) + \nabla
    v`, which is :math:`\nabla v` at ``x`` (a rate factor that is not
    zero keeps a bubble's local system regular with a fluid's zero shear
    modulus).  Does nothing for a rate-independent model."""
    material = rate_material(model)
    if material is None:
        return
    material.bind_rate(gamma / (beta * h), model.rate_gradient(v))
    model.history.commit(model.state(x)["F"])


def bind_newmark_rate(model, h, beta, gamma, v, a):
    r"""Bind :math:`\dot F = \nabla v_{n+1}` of a Newmark step of size
    ``h`` from the state ``(v, a)`` (displacement dofs) at its start:
    :math:`\dot F = \frac{\gamma}{\beta h}(F - F_n) + \nabla\big((1 -
    \frac\gamma\beta) v_n + h (1 - \frac{\gamma}{2\beta}) a_n\big)`
    (:mod:`~skfem_pg.materials.viscous`).  Does nothing for a
    rate-independent model."""
    material = rate_material(model)
    if material is None:
        return
    w = (1 - gamma / beta) * np.asarray(v) + h * (
        1 - gamma / (2 * beta)) * np.asarray(a)
    material.bind_rate(gamma / (beta * h), model.rate_gradient(w))


def end_newmark_rate(model, v, h, beta, gamma):
    r"""After a run that reached its end with the velocities ``v``: bind
    :math:`\dot F = \frac{\gamma}{\beta h}(F - F_n) + \nabla v` (the
    last step committed :math:`F_n`), so that the model's state at the
    final unknowns — its fields, stresses, energy — carries the final
    velocity gradient.  (The static drivers refuse the model whatever is
    bound.)"""
    material = rate_material(model)
    if material is not None:
        material.bind_rate(gamma / (beta * h), model.rate_gradient(v))


def unbind_rate(model):
    """Unbind the rate after a run that stopped early: its last iterate's
    rate is no state to evaluate."""
    material = rate_material(model)
    if material is not None:
        material.bind_rate(None, None)
