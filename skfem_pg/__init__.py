"""skfem-pg: Peridynamic Galerkin (PG) particle methods for scikit-fem.

Particle families are scikit-fem elements: a :class:`FamilyBasis` plugs into
scikit-fem's own assembly, so the same ``BilinearForm`` assembles FE and PG.

The subpackages follow the data flow: :mod:`~skfem_pg.discretization`
(particles, families, shape functions, corrections, ``FamilyBasis``,
assembly) → :mod:`~skfem_pg.formulations` (with :mod:`~skfem_pg.materials`)
→ :mod:`~skfem_pg.solvers` → :mod:`~skfem_pg.analysis` and
:mod:`~skfem_pg.scenes`.

>>> import numpy as np, skfem as fem, skfem_pg as pg
>>> mesh = fem.MeshQuad.init_tensor(np.linspace(0, 1, 5), np.linspace(0, 1, 5))
>>> basis = pg.FamilyBasis(pg.Particles.from_mesh(mesh), dim=2)
>>> basis.vc_report.residual_after < 1e-10
True
"""
from . import (discretization, formulations, materials, solvers, analysis,
               scenes, threads, errors, registry, loadcase)
from .discretization import (particles, families, shape, corrections,
                             vc, loads)
from .scenes import meshing, reference
from .errors import (ParticleError, FamilyError, CorrectionError,
                     VCSolveError, UnsupportedMeshError, SlowAssemblyWarning,
                     MixedBasisWarning, SecondDerivativeError)
from .discretization import (Particles, Families, FamilyBasis, assemble,
                             block_pattern, BilinearForm, LinearForm,
                             traction, stress_load, body_force)
from .discretization.follower import FollowerPressure
from .io import write_vtu
from .scenes import Scene
from .solvers import (newton, newmark, central_difference, lumped_mass,
                      NewtonControls, Problem)
from .registry import register as register_formulation

__version__ = "0.1.0"

__all__ = ["Particles", "Families", "FamilyBasis", "assemble",
           "BilinearForm", "LinearForm", "SlowAssemblyWarning",
           "MixedBasisWarning",
           "block_pattern", "traction", "stress_load", "body_force",
           "write_vtu", "discretization", "formulations", "materials",
           "solvers", "analysis", "scenes", "families", "shape",
           "corrections", "vc", "meshing", "particles", "loads",
           "ParticleError", "FamilyError", "CorrectionError", "VCSolveError",
           "UnsupportedMeshError", "SecondDerivativeError", "registry",
           "register_formulation",
           "Scene", "newton", "newmark", "central_difference",
           "lumped_mass", "NewtonControls", "Problem", "loadcase",
           "FollowerPressure"]
