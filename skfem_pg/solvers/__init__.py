"""Solvers: linear (sparse direct, AMG-Krylov), the static Newton
method with adaptive load steps that drives any formulation (and commits
the history of plastic models per converged step), checkpoints."""
from .linear import (direct, linear_solver, AMGSolver, rigid_body_modes,
                     pardiso_available, DIRECT_LIMIT)
from .static import newton, ConvergenceError, PG_CANDIDATES
from . import checkpoint
from ..dofs import as_dofs

__all__ = ["direct", "linear_solver", "AMGSolver", "rigid_body_modes",
           "pardiso_available", "DIRECT_LIMIT", "newton",
           "ConvergenceError", "PG_CANDIDATES", "as_dofs", "checkpoint"]
