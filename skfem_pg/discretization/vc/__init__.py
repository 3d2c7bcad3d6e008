"""Variationally consistent (VC) corrections: the derivatives of a basis
corrected so that the integration constraint holds (thesis 5.2; (5.18)
for PBG, (5.16)/(5.17) for PPG, the second-order constraints of VC2).

=================  =====================================================
``first_order``    the constraint system of (5.18) (:class:`VCSystem`,
                   one record of what a correction reads), its solves
                   (sparse LU, AMG, LSQR) and the correction functions
                   V1–V5 (5.57)–(5.64)
``boundary``       the thesis' boundary variants ``p``, ``s``, ``sn`` of
                   the singular system
``second_order``   VC2: quadratic consistency (the second-order
                   constraints), PBG and PPG1
``local``          the local VC of the outlook 8.2: one d x d solve per
                   family, no global system
=================  =====================================================

The builder (:mod:`skfem_pg.discretization.builder`) makes the
:class:`VCSystem` of a basis and calls the correction its spec's parts
name; on MPI ranks :mod:`skfem_pg.distributed.vc` solves the same system
over all ranks.  The bond correction (5.55) and the check of a corrected
basis are :mod:`skfem_pg.discretization.corrections`.
"""
from .first_order import (VCReport, VCSystem, correction_functions,
                          vc_correction)
from .second_order import vc2_correction
from .local import local_vc_correction

__all__ = ["VCReport", "VCSystem", "correction_functions", "vc_correction",
           "vc2_correction", "local_vc_correction"]
