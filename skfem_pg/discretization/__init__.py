"""The discretization: mesh → particles → families → shape-function
derivatives → corrections → :class:`FamilyBasis`, and the batched assembly
that turns scikit-fem forms on it (and on FE cell bases) into sparse
systems.

=========================  ====================================================
``particles``              particles collocated from meshes (volumes, area
                           vectors, fold and inversion checks)
``families``               family builders (mesh connectivity, horizons,
                           nearest neighbours) and their rule names
``moment_quadrature``      the moment-matched family quadrature of the
                           quadratic fit (``family_quadrature``)
``recipes``                which families, quadrature and bond weights a
                           basis uses by default (thesis', meshU or kNN)
``quadrature``             PBG quadrature weights (volume (4.30), uniform)
``shape``                  WTE1/MTE1, WTE2, least-squares and LME derivatives
``corrections``            the bond correction (5.55) and the check of a
                           corrected basis
``vc``                     variationally consistent corrections (5.2): the
                           first-order system (:class:`VCSystem`), boundary
                           variants, VC2, local VC
``petrov``                 PPG test bases (4.21), (4.22)
``layout``                 families grouped by size (unpadded hot paths)
``parts``                  the parts of a basis (family rule, shape,
                           quadrature, correction, method) and what each
                           supports: the one capability table
``builder``                :class:`BasisSpec` (the parts, resolved from the
                           keywords) and the stages one builder composes
``basis``                  :class:`FamilyBasis`, the container of the built
                           arrays behind scikit-fem's basis interface
``blend``                  :class:`BlendBasis` (PG2): the families' quadratic
                           fits blended by the mesh's hat functions
``assembly``, ``forms``    batched assembly; the fast-path decorators
``loads``                  tractions, stress and body loads on FE and PG bases
``coefficients``           piecewise (per-cell) coefficients at the members
``nonlocal_mean``          :class:`~skfem_pg.discretization.nonlocal_mean.
                           NonlocalAverage`: bell means over a model's points
``crack_tracking``         :class:`~skfem_pg.discretization.crack_tracking.
                           CrackTracker`: which points a tracked brittle
                           criterion may fail (2-D)
=========================  ====================================================
"""
from .particles import Particles
from .families import Families
from .builder import BasisSpec
from .basis import FamilyBasis
from .blend import BlendBasis
from .assembly import assemble, block_pattern
from .forms import BilinearForm, LinearForm
from .loads import traction, stress_load, body_force

__all__ = ["Particles", "Families", "BasisSpec", "FamilyBasis", "BlendBasis",
           "assemble",
           "block_pattern", "BilinearForm", "LinearForm", "traction",
           "stress_load", "body_force"]
