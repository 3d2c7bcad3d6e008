"""Verification and analysis: discrete error norms and patch tests
(``verification``), manufactured-solution convergence (``convergence``),
free-block spectra (``spectrum``), the numerical inf-sup test
(``infsup``), particle stresses for output (``postprocess``) and curves
along a run (``curves``)."""
from .verification import (l2_error, h1_error, nodal_interpolant,
                           discrete_energy, energy_capture,
                           linear_patch_test, quadratic_patch_test,
                           kirsch_displacement, PATCH_GRADIENT_2D,
                           PATCH_GRADIENT_3D)
from .curves import Curve

__all__ = ["l2_error", "h1_error", "nodal_interpolant", "discrete_energy",
           "energy_capture", "linear_patch_test", "quadratic_patch_test",
           "kirsch_displacement", "PATCH_GRADIENT_2D", "PATCH_GRADIENT_3D",
           "Curve"]
