"""Solvers: linear (sparse direct, AMG-Krylov), the static Newton
method with adaptive load steps that drives any formulation (and commits
the history of plastic models per converged step), checkpoints; dynamics:
lumped mass, implicit Newmark, explicit central differences, a rigid
frictionless wall, energy bookkeeping; free-surface flow on particles that
re-neighbour (:func:`free_surface_flow`).  The drivers take a
:class:`~skfem_pg.solvers.problem.Problem` (or a model and its loads as
keywords)."""
from .linear import (direct, Factorization, linear_solver, AMGSolver, rigid_body_modes,
                     pardiso_available, DIRECT_LIMIT,
                     DIRECT_LIMIT_PARDISO, DIRECT_NNZ_LIMIT_PARDISO,
                     auto_direct_limit, submatrix)
from .controls import NewtonControls, NewmarkControls, ExplicitControls
from .problem import Problem, Solution
from .static import newton, ConvergenceError, PG_CANDIDATES
from .mass import lumped_mass
from .dynamics import DynamicsError, Trajectory, EnergyBalance
from .contact import RigidWall
from .newmark import newmark
from .free_surface import free_surface_flow, FlowResult
from .explicit import (central_difference, stable_time_step,
                       max_frequency)
from . import checkpoint
from ..dofs import as_dofs

__all__ = ["direct", "Factorization", "linear_solver", "AMGSolver", "rigid_body_modes",
           "pardiso_available", "DIRECT_LIMIT", "DIRECT_LIMIT_PARDISO",
           "DIRECT_NNZ_LIMIT_PARDISO",
           "auto_direct_limit", "submatrix", "newton", "NewtonControls",
           "NewmarkControls", "ExplicitControls",
           "ConvergenceError", "PG_CANDIDATES", "as_dofs", "checkpoint",
           "lumped_mass", "DynamicsError", "Trajectory", "EnergyBalance",
           "RigidWall", "newmark", "central_difference", "stable_time_step",
           "max_frequency", "Problem", "Solution", "free_surface_flow",
           "FlowResult"]
