"""Formulations by their thesis name (Table 7.1): the model a name's
formulation token makes of a basis and a material.

=========================  ===================================================
token                      model
=========================  ===================================================
``Unl``, ``U1``, ``U2``    :class:`~.displacement.Hyperelastic` (PG)
``T1`` ... ``H2``          :class:`~.displacement.Hyperelastic` (FE)
``UnlP0``                  :class:`~.dilatation.MeanDilatation` (PBG),
                           :class:`~.master_dilatation.MasterDilatation` (PPG)
``U2P1``                   :class:`~.dilatation.MeanDilatation` of order 1
                           (PBG, WTE2 basis)
``Q1P0``, ``H1P0``         :class:`~.dilatation.MeanDilatation`, or with an
                           incompressible material
                           :class:`~.incompressible.IncompressibleP0`
``IUnlP0``                 :class:`~.incompressible.IncompressibleP0` (PBG),
                           :class:`~.master_dilatation.MasterIncompressible`
                           (PPG)
``U2P1C``                  :class:`~.nodal.NodalPressure` (PBG, WTE2 basis)
``Unl+P1C``                :class:`~.nodal.NodalPressure` with the bubble
                           (PBG, MTE1 basis)
``U1SUnl``                 :class:`~.stabilized.U1SUnl` (PBG, MTE1 basis for
                           the stabilization, WTE1 at the masters)
``U1SIG``                  :class:`~.stabilized.U1SIG` (PBG, WTE1 at the
                           masters)
=========================  ===================================================
"""
import numpy as np

from .dilatation import MeanDilatation
from .displacement import Hyperelastic
from .incompressible import IncompressibleP0
from .master_dilatation import MasterDilatation, MasterIncompressible
from .nodal import NodalPressure
from .protocol import check_model
from .stabilized import U1SIG, U1SUnl
from .. import registry


def _incompressible(material):
    return not np.isfinite(getattr(material, "K", 0.0))


def _displacement(basis, material, tangent):
    return Hyperelastic(basis, material, tangent=tangent)


#: the scene builds :class:`UpdatedLagrange` for this build in the UL frame
_displacement.updated_lagrangian = True


def _mean_dilatation(token, incompressible):
    """UnlP0 / IUnlP0: the PBG model, at the master on a PPG basis."""
    pbg, ppg = ((IncompressibleP0, MasterIncompressible) if incompressible
                else (MeanDilatation, MasterDilatation))

    def build(basis, material, tangent):
        if not incompressible and _incompressible(material):
            raise ValueError("{} condenses the pressure with a finite bulk "
                             "modulus; for nu = 0.5 use IUnlP0".format(token))
        cls = ppg if getattr(basis, "is_petrov", False) else pbg
        return cls.of(basis, material)
    return build


def _u2p1(basis, material, tangent):
    if _incompressible(material):
        raise ValueError("U2P1 condenses p and Theta with a finite bulk "
                         "modulus; nu = 0.5 is not built for it")
    return MeanDilatation.of(basis, material, order=1)


def _nodal(bubble):
    def build(basis, material, tangent):
        return NodalPressure.of(basis, material, bubble=bubble)
    return build


def _stabilized(cls):
    def build(basis, material, tangent):
        return cls.of(basis, material)
    return build


# Table 7.1, in the order of the thesis (the displacement formulations
# first: name_of names a basis by the first of its shape)
for _token, _shape in (("U1", "WTE1"), ("Unl", "MTE1"), ("U2", "WTE2")):
    registry.register(_token, _shape, _displacement,
                      updated_lagrangian=True,
                      distributed=_shape != "WTE2")
registry.register("UnlP0", "MTE1", _mean_dilatation("UnlP0", False),
                  kind="mixed")
registry.register("IUnlP0", "MTE1", _mean_dilatation("IUnlP0", True),
                  kind="mixed")
registry.register("Unl+P1C", "MTE1", _nodal(True), kind="mixed")
registry.register("U2P1", "WTE2", _u2p1, kind="mixed")
registry.register("U2P1C", "WTE2", _nodal(False), kind="mixed")
registry.register("U1SUnl", "MTE1", _stabilized(U1SUnl), kind="stabilized")
registry.register("U1SIG", "WTE1", _stabilized(U1SIG), kind="stabilized",
                  master_only=True)


def model_for(formulation, basis, material, tangent="consistent"):
    """The model of ``formulation`` (a token of :mod:`skfem_pg.registry`:
    Table 7.1's or one a user registered, or an FE method) on ``basis``
    with ``material``.  An unknown token, or a family basis whose shape
    functions are not the token's (``U2``, ``U2P1``, ``U2P1C`` need
    WTE2), raises ``ValueError`` naming it."""
    if formulation in registry.fe_names():
        if registry.fe_method(formulation).mean_dilatation:
            cls = IncompressibleP0 if _incompressible(material) \
                else MeanDilatation
            return cls.of(basis, material)
        return Hyperelastic(basis, material, tangent=tangent)
    try:
        record = registry.formulation(formulation)
    except ValueError as err:
        raise ValueError("{}; FE methods {}".format(
            err, ", ".join(registry.fe_names()))) from None
    shape = getattr(basis, "shape", None)
    if isinstance(shape, str) and record.shape == "WTE2" and shape != "WTE2":
        raise ValueError(
            "{} is a formulation of WTE2 shape functions (Table 7.1); this "
            "basis has {}: build it with shape='WTE2' (or use the thesis "
            "name, e.g. 'PBG {}')".format(formulation, shape, formulation))
    return check_model(record.build(basis, material, tangent), formulation)
