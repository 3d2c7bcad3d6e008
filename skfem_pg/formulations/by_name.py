"""Formulations by their thesis name (Table 7.1): the model a name's
formulation token makes of a basis and a material.

======================  ===================================================
token                   model
======================  ===================================================
``Unl``, ``U1``, ``U2``  :class:`~.displacement.Hyperelastic` (PG)
``T1`` ... ``H2``       :class:`~.displacement.Hyperelastic` (FE)
``UnlP0``               :class:`~.dilatation.MeanDilatation` (PBG),
                        :class:`~.master_dilatation.MasterDilatation` (PPG)
``U2P1``                :class:`~.dilatation.MeanDilatation` of order 1
                        (PBG, WTE2 basis)
``Q1P0``, ``H1P0``      :class:`~.dilatation.MeanDilatation`, or with an
                        incompressible material
                        :class:`~.incompressible.IncompressibleP0`
``IUnlP0``              :class:`~.incompressible.IncompressibleP0` (PBG),
                        :class:`~.master_dilatation.MasterIncompressible`
                        (PPG)
``U2P1C``               :class:`~.nodal.NodalPressure` (PBG, WTE2 basis)
``Unl+P1C``             :class:`~.nodal.NodalPressure` with the bubble
                        (PBG, MTE1 basis)
``U1SUnl``              :class:`~.stabilized.U1SUnl` (PBG, MTE1 basis for
                        the stabilization, WTE1 at the masters)
``U1SIG``               :class:`~.stabilized.U1SIG` (PBG, WTE1 at the
                        masters)
======================  ===================================================
"""
import numpy as np

from .dilatation import MeanDilatation
from .displacement import Hyperelastic
from .incompressible import IncompressibleP0
from .master_dilatation import MasterDilatation, MasterIncompressible
from .nodal import NodalPressure
from .stabilized import U1SIG, U1SUnl
from ..naming import FE_NAMES, SHAPES

#: built formulation tokens beyond the displacement ones
MIXED = {"UnlP0": MeanDilatation, "IUnlP0": IncompressibleP0}
#: the stabilized under-integrated formulations (6.3)
STABILIZED = {"U1SUnl": U1SUnl, "U1SIG": U1SIG}


def _incompressible(material):
    return not np.isfinite(getattr(material, "K", 0.0))


def model_for(formulation, basis, material, tangent="consistent"):
    """The model of ``formulation`` (a token of Table 7.1 or an FE
    method) on ``basis`` with ``material``.  An unknown token, or a
    family basis whose shape functions are not the token's
    (:data:`~skfem_pg.naming.SHAPES`: ``U2``, ``U2P1``, ``U2P1C`` need
    WTE2), raises ``ValueError`` naming it."""
    if formulation not in SHAPES and formulation not in FE_NAMES:
        raise ValueError(
            "unknown formulation {!r}: Table 7.1 tokens are {}; FE methods "
            "{}".format(formulation, ", ".join(SHAPES), ", ".join(FE_NAMES)))
    shape = getattr(basis, "shape", None)
    if isinstance(shape, str) and formulation in SHAPES \
            and SHAPES[formulation] == "WTE2" and shape != "WTE2":
        raise ValueError(
            "{} is a formulation of WTE2 shape functions (Table 7.1); this "
            "basis has {}: build it with shape='WTE2' (or use the thesis "
            "name, e.g. 'PBG {}')".format(formulation, shape, formulation))
    if formulation in STABILIZED:
        return STABILIZED[formulation].of(basis, material)
    if formulation in ("Q1P0", "H1P0"):
        cls = IncompressibleP0 if _incompressible(material) \
            else MeanDilatation
        return cls.of(basis, material)
    if formulation == "U2P1":
        if _incompressible(material):
            raise ValueError("U2P1 condenses p and Theta with a finite bulk "
                             "modulus; nu = 0.5 is not built for it")
        return MeanDilatation.of(basis, material, order=1)
    if formulation in ("U2P1C", "Unl+P1C"):
        return NodalPressure.of(basis, material,
                                bubble=formulation == "Unl+P1C")
    if formulation in MIXED:
        if formulation == "UnlP0" and _incompressible(material):
            raise ValueError("UnlP0 condenses the pressure with a finite "
                             "bulk modulus; for nu = 0.5 use IUnlP0")
        if getattr(basis, "is_petrov", False):  # PPG: at the master
            return (MasterDilatation if formulation == "UnlP0"
                    else MasterIncompressible).of(basis, material)
        return MIXED[formulation].of(basis, material)
    return Hyperelastic(basis, material, tangent=tangent)
