"""Rate-dependent materials in the drivers: the viscous stress of a
:class:`~skfem_pg.materials.NewtonianFluid` needs the rate of F, which
only an integrator with velocities can give.  :func:`skfem_pg.newmark`
binds Newmark's rate at the start (:func:`start_newmark_rate`), per
step (:func:`bind_newmark_rate`) and at the end
(:func:`bind_velocity_rate`); the other
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


def check_fluid_model(model):
    """``ValueError`` naming the formulation if ``model`` carries a fluid
    (a rate-dependent material without shear stiffness) on a formulation
    that does not hold it (measured, ``tests/test_flow.py``): a fluid runs
    on a mean-dilatation model — PBG UnlP0 with the local VC correction,
    FE Q1P0 / H1P0.

    * displacement formulations lock: PBG Unl does not flow in the
      Poiseuille channel (-0.5 % of the velocity at 0.1 s), FE Q1 on
      perturbed quadrilaterals neither (0.03 %);
    * the nodal-pressure formulations (Unl+P1C, U2P1C) and UnlP0 with the
      global VC correction (or none) do not hold a column of water at
      rest: a linear pressure is not integrated exactly and the wall
      particles slide down at about g (Unl+P1C: J <= 0 after 0.026 s, its
      bubble creeping under the pressure gradient; UnlP0: 0.10 s).  The
      local correction's shares (the collocation mesh's integrals of its
      linear functions) integrate a family-constant pressure times the
      test gradients exactly for linear pressures: UnlP0 with it keeps
      the column within 7e-4 sqrt(gH), on perturbed quadrilaterals,
      triangles, hexahedra and tetrahedra too (``benchmarks/flow.py``).

    FE is left to the user: Q1P0 holds the column on a grid (3.5e-4) but
    not on perturbed quadrilaterals (J <= 0 after 0.09 s), H1P0 on
    perturbed hexahedra reaches 8.9e-2 sqrt(gH)."""
    material = rate_material(model)
    if material is None or getattr(material, "mu", None) != 0.0:
        return
    from ..discretization.layout import is_family_basis
    from ..formulations.dilatation import MeanDilatation
    basis = model.basis
    name = type(model).__name__
    if not isinstance(model, MeanDilatation):
        raise ValueError(
            "a NewtonianFluid on {}: a fluid runs on a mean-dilatation "
            "model (PBG UnlP0 with vc_solver='local', FE Q1P0 / H1P0); the "
            "displacement formulations lock and the nodal-pressure ones "
            "(Unl+P1C, U2P1C) do not hold a fluid at rest (skfem_pg."
            "solvers.rates.check_fluid_model)".format(name))
    if is_family_basis(basis):
        report = getattr(basis, "vc_report", None)
        if report is None or report.solver != "local":
            raise ValueError(
                "a NewtonianFluid on PBG UnlP0 with {}: it needs the local VC "
                "correction (FamilyBasis.from_name(mesh, 'VCBCPBG V5m "
                "UnlP0', dim=2, vc_solver='local')), which integrates a "
                "linear pressure exactly; without it a column of water at "
                "rest does not stay at rest (skfem_pg.solvers.rates."
                "check_fluid_model)".format(
                    "no VC correction" if report is None
                    else "the {} VC solve".format(report.solver)))


def start_newmark_rate(model, x, v, h, beta, gamma):
    r"""The rate at the start of a Newmark run from ``x`` with the
    velocities ``v``: the points' committed :math:`F_n` becomes that of
    ``x`` and :math:`\dot F = \frac{\gamma}{\beta h}(F - F_n) + \nabla
    v`, which is :math:`\nabla v` at ``x`` (with a rate factor that is
    not zero, the tangent at the start keeps its viscous part).  Does
    nothing for a rate-independent model."""
    if rate_material(model) is None:
        return
    check_fluid_model(model)
    bind_velocity_rate(model, v, h, beta, gamma)
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


def bind_velocity_rate(model, v, h, beta, gamma):
    r"""Bind :math:`\dot F = \frac{\gamma}{\beta h}(F - F_n) + \nabla
    v`, which is :math:`\nabla v` at the committed state: at the start
    of a run (:func:`start_newmark_rate`) and after one that reached its
    end, so that the model's state at the final unknowns — its fields,
    stresses, energy — carries the final velocity gradient.  (The static
    drivers refuse the model whatever is bound.)"""
    material = rate_material(model)
    if material is not None:
        material.bind_rate(gamma / (beta * h), model.rate_gradient(v))


def unbind_rate(model):
    """Unbind the rate after a run that stopped early: its last iterate's
    rate is no state to evaluate."""
    material = rate_material(model)
    if material is not None:
        material.bind_rate(None, None)
