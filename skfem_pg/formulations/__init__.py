"""Formulations: what a discretization (one or several bases) and a
material make into the residual and tangent that the solvers drive.

=================  ========================================================
``linear``         linear elasticity as a plain scikit-fem form
``displacement``   :class:`Hyperelastic`: the displacement formulation (PG
                   U1/Unl/U2, FE T1/Q1/O1/H1/...)
``fe``             :class:`MeanDilatation`: FE Q1P0/H1P0
``tangents``       finite-difference tangent of family forces
=================  ========================================================
"""
from .linear import linear_elasticity
from .displacement import Hyperelastic, internal_force, material_tangent
from .fe import MeanDilatation
from .tangents import fd_tangent

__all__ = ["linear_elasticity", "Hyperelastic", "internal_force",
           "material_tangent", "MeanDilatation", "fd_tangent"]
