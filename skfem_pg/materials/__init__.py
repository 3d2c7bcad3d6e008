"""Material laws as functions of the deformation gradient (hyperelastic
today), and the checks and conversions of elastic constants."""
from .constants import check_moduli, lame
from .hyperelastic import (Material, LinearElastic, StVenantKirchhoff,
                           NeoHooke, NeoHookeIsoVol, inverse_and_det)

__all__ = ["check_moduli", "lame", "Material", "LinearElastic",
           "StVenantKirchhoff", "NeoHooke", "NeoHookeIsoVol",
           "inverse_and_det"]
