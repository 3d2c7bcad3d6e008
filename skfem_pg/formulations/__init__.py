"""Formulations: what a discretization (one or several bases) and a
material make into the residual and tangent that the solvers drive.
What a driver asks of a model is :class:`~.protocol.Model`
(:mod:`~skfem_pg.formulations.protocol`); the formulation tokens live in
:mod:`skfem_pg.registry`.

===========================  ==================================================
``linear``                   linear elasticity as a plain scikit-fem form
``displacement``             :class:`Hyperelastic`: the displacement
                             formulation (PG U1/Unl/U2, FE T1/Q1/O1/H1/...)
``dilatation``               :class:`MeanDilatation`: condensed polynomial
                             pressure and dilatation per element — FE
                             Q1P0/H1P0, PBG UnlP0, U2P1
``master_dilatation``        :class:`MasterDilatation`: PPG UnlP0, the
                             volumetric part once per particle, at the master;
                             :class:`MasterIncompressible`: PPG IUnlP0
``incompressible``           :class:`IncompressibleP0`: nu = 0.5, one pressure
                             per element as a global unknown — PBG IUnlP0, FE
                             Q1P0/H1P0
``nodal``                    :class:`NodalPressure`: nodal p and Theta as
                             global unknowns — PBG U2P1C, Unl+P1C (a condensed
                             bubble)
``stabilized``               :class:`U1SUnl`, :class:`U1SIG`: under-integrated
                             U1 (material and history at the masters) with
                             full-integration or implicit-gradient
                             stabilization
``protocol``                 :class:`Model`: what a driver may ask of a model
``by_name``                  Table 7.1's tokens registered (skfem_pg.registry)
                             and :func:`model_for`: the model of a token
``history``                  :class:`History`: a plastic material's internal
                             variables at a model's integration points,
                             committed per converged step
``tangents``                 finite-difference tangent of family forces
``bond_based``               :class:`BondBased`: bond-based peridynamics with
                             critical-stretch breaking (PMB), the classical
                             comparator on the same particles and drivers
``crack_aware``              :class:`CrackAware`, :class:`CrackAwareUnlP0`,
                             :class:`CrackAwareU1SIG`: Unl, UnlP0 and U1SIG
                             whose families stop at failed cells (beyond the
                             thesis' 8.1)
``nitsche``                  :class:`WeakDirichlet`: Dirichlet conditions by
                             Nitsche terms (the blended quadratic basis PG2)
``fluid_updated_lagrange``   :class:`UpdatedLagrangeFluid`: a fluid on PBG
                             UnlP0 re-neighboured on the alpha shape of its
                             particles (the dam break; beyond the thesis' 8.2)
===========================  ==================================================
"""
from .linear import linear_elasticity
from .displacement import Hyperelastic, internal_force, material_tangent
from .dilatation import MeanDilatation
from .incompressible import IncompressibleP0
from .master_dilatation import MasterDilatation, MasterIncompressible
from .nodal import NodalPressure
from .stabilized import U1SUnl, U1SIG
from .by_name import model_for
from .protocol import Model
from .tangents import fd_tangent
from .history import History
from .updated_lagrange import UpdatedLagrange
from .fluid_updated_lagrange import UpdatedLagrangeFluid
from .bond_based import BondBased, segment_cut
from .crack_aware import CrackAware, CrackAwareU1SIG, CrackAwareUnlP0
from .nitsche import WeakDirichlet

__all__ = ["linear_elasticity", "Hyperelastic", "internal_force",
           "material_tangent", "MeanDilatation", "MasterDilatation",
           "MasterIncompressible",
           "IncompressibleP0",
           "NodalPressure", "U1SUnl", "U1SIG", "model_for", "fd_tangent",
           "History", "UpdatedLagrange", "UpdatedLagrangeFluid",
           "Model", "BondBased",
           "segment_cut", "CrackAware", "CrackAwareU1SIG", "CrackAwareUnlP0",
           "WeakDirichlet"]
