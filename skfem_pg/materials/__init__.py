"""Material laws as functions of the deformation gradient: hyperelastic
(stateless) and finite J2 elasto-plasticity (with history; hardening laws,
ductile damage), and the checks
and conversions of elastic constants."""
from .constants import check_moduli, lame
from .hyperelastic import (Material, LinearElastic, StVenantKirchhoff,
                           NeoHooke, NeoHookeIsoVol, inverse_and_det)
from .plasticity import J2Plasticity, ReturnMapError
from .hardening import LinearSaturation, JohnsonCookHardening
from .damage import (CrackTracking, CriticalStrainDamage,
                     CriticalStressDamage, JohnsonCookDamage,
                     NonlocalStrainDamage)
from .library import FElupeMaterial
from .viscous import NewtonianFluid, NoRateError

__all__ = ["check_moduli", "lame", "Material", "LinearElastic",
           "StVenantKirchhoff", "NeoHooke", "NeoHookeIsoVol",
           "inverse_and_det", "J2Plasticity", "ReturnMapError",
           "LinearSaturation", "JohnsonCookHardening", "JohnsonCookDamage",
           "CriticalStrainDamage", "CriticalStressDamage", "CrackTracking",
           "NonlocalStrainDamage", "FElupeMaterial",
           "NewtonianFluid", "NoRateError"]
