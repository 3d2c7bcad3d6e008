"""skfem-pg: Peridynamic Galerkin (PG) particle methods for scikit-fem.

Particle families are scikit-fem elements: a :class:`FamilyBasis` plugs into
scikit-fem's own assembly, so the same ``BilinearForm`` assembles FE and PG.

>>> import numpy as np, skfem as fem, skfem_pg as pg
>>> mesh = fem.MeshQuad.init_tensor(np.linspace(0, 1, 5), np.linspace(0, 1, 5))
>>> basis = pg.FamilyBasis(pg.Particles.from_mesh(mesh), dim=2)
>>> basis.vc_report.residual_after < 1e-10
True
"""
from . import (families, shape, corrections, meshing, materials, solvers,
               models, threads)
from .errors import (ParticleError, FamilyError, CorrectionError,
                     UnsupportedMeshError, SlowAssemblyWarning)
from .particles import Particles
from .families import Families
from .basis import FamilyBasis
from .assembly import assemble, block_pattern
from .forms import BilinearForm, LinearForm
from .loads import traction, stress_load, body_force
from .io import write_vtu

__version__ = "0.1.0"

__all__ = ["Particles", "Families", "FamilyBasis", "assemble",
           "BilinearForm", "LinearForm", "SlowAssemblyWarning",
           "block_pattern", "traction", "stress_load", "body_force",
           "write_vtu", "families", "shape", "corrections", "meshing",
           "materials", "solvers", "models",
           "ParticleError", "FamilyError", "CorrectionError",
           "UnsupportedMeshError"]
