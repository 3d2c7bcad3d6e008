"""Formulations: what a discretization (one or several bases) and a
material make into the residual and tangent that the solvers drive.
The model interface (fields, residual, tangent) is described in
:mod:`~skfem_pg.formulations.displacement`.

=================  ========================================================
``linear``         linear elasticity as a plain scikit-fem form
``displacement``   :class:`Hyperelastic`: the displacement formulation (PG
                   U1/Unl/U2, FE T1/Q1/O1/H1/...)
``dilatation``     :class:`MeanDilatation`: one condensed pressure and
                   dilatation per element — FE Q1P0/H1P0, PBG UnlP0
``incompressible`` :class:`IncompressibleP0`: nu = 0.5, one pressure per
                   element as a global unknown — PBG IUnlP0, FE Q1P0/H1P0
``tangents``       finite-difference tangent of family forces
=================  ========================================================
"""
from .linear import linear_elasticity
from .displacement import Hyperelastic, internal_force, material_tangent
from .dilatation import MeanDilatation
from .incompressible import IncompressibleP0
from .tangents import fd_tangent

__all__ = ["linear_elasticity", "Hyperelastic", "internal_force",
           "material_tangent", "MeanDilatation", "IncompressibleP0",
           "fd_tangent"]
