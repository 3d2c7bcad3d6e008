r"""FamilyBasis — particle families as scikit-fem elements.

A family :math:`H^k` is an element whose quadrature points are its members
``j`` and whose basis functions are its members ``i`` ((4.25),
(4.30)).  With

* quadrature weights (PBG, (4.25), (4.30))
  :math:`w_{kj} = V^k V^j / V_H^k`, :math:`V_H^k = \sum_{j\in H^k} V^j`,
* basis-function gradients :math:`G^{kji}` (MTE1/WTE1, bond and VC
  corrections), and values :math:`\delta_{ij}` (the particle value),

scikit-fem's own ``BilinearForm``/``LinearForm``/``Functional`` assemble the
Peridynamic Bubnov–Galerkin (PBG) method:

.. math::

    \delta W = \sum_k \sum_{j\in H^k} w_{kj}\, P(F^{kj}) : \delta F^{kj},
    \qquad F^{kj} = I + \sum_i u^i\otimes G^{kji}.

Petrov–Galerkin (``method="PPG1"``/``"PPG2"``,
:mod:`skfem_pg.discretization.petrov`): the same elements with weights
:math:`V^k` and a separate test basis ``basis.test`` (derivatives at the
masters, VC-corrected); assemble with
:func:`skfem_pg.assemble`, which picks ``basis.test`` up, or with
scikit-fem's ``form.assemble(basis, basis.test)``.

Degrees of freedom follow scikit-fem's nodal numbering of the mesh the
particles were collocated from (vector dof ``c`` of particle ``p`` is
``dim * p + c``), so family bases and FE bases on the same mesh add into one
system.  ``G`` and ``dx`` are padded to the largest family size ``m``
(padded slots have zero weight and zero gradient) for scikit-fem's generic
assembly; the batched hot paths (:func:`skfem_pg.assemble`,
``interpolate``, the models) use the unpadded size groups of
:mod:`skfem_pg.discretization.layout` instead.
"""
import copy
import sys
import time
import warnings

import numpy as np
import skfem as fem
from skfem.assembly.basis import AbstractBasis
from skfem.element import DiscreteField

from . import families as families_mod
from . import petrov
from . import recipes
from .corrections import (bond_correction, check_correction,
                          correction_functions, family_radii, vc_correction)
from ..dofs import as_dofs
from ..errors import FamilyError, SlowAssemblyWarning, describe_particle
from .particles import Particles, linear_elements
from .quadrature import volume_weights, weight_rule
from .shape import GRADIENTS
from ..threads import kernel
from .shape.least_squares import (mls1_master_gradients,
                                   wls1_master_gradients,
                                   wls2_master_gradients)
from .shape.lme import lme_master_gradients
from .vc2 import vc2_correction
from ..naming import name_of, parse

METHODS = ("PBG", "PPG1", "PPG2")
#: test derivatives of PPG at the masters
#: least-squares PPG test derivatives at the masters
LS_TEST_GRADIENTS = {"WLS1": wls1_master_gradients,
                     "WLS2": wls2_master_gradients,
                     "MLS1": mls1_master_gradients}
TEST_SHAPES = ("master", "WTE1", "WLS1", "WLS2", "MLS1", "LME")


#: PBG quadrature weights :math:`w_{kj} = V^k V^j / V_H^k` (4.30), the
#: thesis' rule (:func:`~skfem_pg.discretization.quadrature.volume_weights`)
pbg_weights = volume_weights


class FamilyBasis(AbstractBasis):
    """A scikit-fem basis whose elements are particle families.

    Parameters
    ----------
    particles
        :class:`~skfem_pg.Particles`, or a scikit-fem mesh (its vertices
        become particles, :meth:`Particles.from_mesh`).
    families
        :class:`~skfem_pg.discretization.families.Families`, or a rule of
        :data:`~skfem_pg.discretization.families.RULES`: ``"mesh"`` (mesh
        connectivity), ``"nearest"`` (the 10 (3-D) / 6 (2-D) nearest
        particles, pairwise) or ``"horizon"`` (1.51 h).  Default: the
        recipe of :mod:`~skfem_pg.discretization.recipes` — ``"nearest"``
        for PBG MTE1 on 3-D tetrahedra (recipe ``kNN``), else ``"mesh"``
        for mesh particles and a horizon of 1.51 h otherwise; for WTE2 a
        horizon of 2.51 h, small families enlarged to one member more
        than the quadratic basis needs.
    weights
        PBG quadrature weights
        (:mod:`~skfem_pg.discretization.quadrature`): ``"volume"``
        (:math:`V^k V^j / V_H^k`, (4.30)) or ``"uniform"``
        (:math:`V^k / n_k`).  Default (``"auto"``): the recipe's —
        ``"uniform"`` with ``"nearest"`` families, else ``"volume"``.
        PPG has its own weights (:math:`V^j`).
    shape
        ``"MTE1"`` (moving Taylor expansion, formulation Unl; default),
        ``"WTE1"`` (static Taylor expansion = classical correspondence,
        formulation U1) or ``"WTE2"`` (second-order static Taylor
        expansion, formulation U2; needs 5 (2-D) / 9 (3-D) non-master
        members, e.g. a 2.51 h horizon).
    bond
        Bond correction (5.55).  Default: on for MTE1 (PBG and PPG:
        VC PPG1 without it has negative eigenvalues on the free block,
        ``tests/test_eigen.py``), off for WTE1.
    vc
        Variationally consistent correction
        (:func:`~skfem_pg.discretization.corrections.correction_functions`):
        ``"V5"`` (default with bond correction), ``"V3"`` (default for MTE1
        without bond correction, for WTE2 and for PPG, whose test derivatives
        it corrects), ``"V4"`` (keeps quadratic consistency), ``"V2"``
        (second derivatives of WLS2 (5.61), keeps linear consistency;
        families of ``2 + q`` members and more), ``"V1"`` (PPG only),
        ``None`` (default for WTE1: the classical, uncorrected method), or
        ``"VC2"`` (second-order VC for ``shape="WTE2"``: PBG with V4
        correction functions, PPG1 (5.24) with V1 ones on its test
        derivatives; passes the quadratic patch test;
        :mod:`skfem_pg.discretization.vc2`).
    method
        ``"PBG"`` (Peridynamic Bubnov–Galerkin, symmetric; default),
        ``"PPG1"`` or ``"PPG2"`` (Peridynamic Petrov–Galerkin (4.21),
        (4.22): non-symmetric, test basis ``basis.test``; families are
        completed to pairwise ones; PPG2's VC solves (5.17) by LSQR and
        passes the patch test, but VC PPG2 is unstable, with a warning).
    dim
        Number of field components: ``None`` for a scalar field (e.g.
        Poisson), the spatial dimension for displacements.
    weight_exponent
        ``n`` in :math:`\\omega = 1/|\\Delta X|^{2n}`, ``n >= 0``.
        Default (``"auto"``): the recipe's — 0 with ``"nearest"``
        families, else 1.
    vc_solver
        Solver of the VC constraint system: ``"auto"`` (``"direct"``, in
        3-D above 15k particles ``"amg"``), ``"direct"`` (scalar sparse
        LU), ``"amg"`` (the same scalar system by AMG-GMRES, linear in
        the particle count) or ``"lsqr"``; on a distributed basis also
        ``"petsc"`` (:mod:`skfem_pg.distributed.vc`: solved on all ranks).
    area_vectors
        ``(dim, np)`` surface area vectors :math:`A^i`; default: the
        FE-consistent ones of ``particles.area_vectors()``.
    vc_exclude
        Particles whose integration constraints are not enforced — those
        with Dirichlet conditions, whose equations are eliminated.  The
        full V4 and VC2 systems are incompatible (their quadratic left null
        vectors meet the interpolation error of the surface term), so they
        reach round-off only with these excluded; VC2 then passes the
        quadratic patch test.  Uses the LSQR solve.
    vc_boundary
        Boundary conditions of the (singular) first-order VC system,
        :mod:`skfem_pg.discretization.vc_boundary`: ``"min-norm"`` (default;
        every constraint with FE-consistent :math:`A^i`), or the thesis'
        ``"p"``, ``"s"``, ``"sn"``.  With ``"s"``/``"sn"`` the surface
        particles' discrete area vectors (4.35) differ from FE's by
        ``basis.area_correction``, which the loads of
        :mod:`skfem_pg.discretization.loads` include.

    vc_tolerance
        Largest accepted constraint residual after the VC correction,
        relative to :math:`h^{d-1}` (default 1e-8: the patch test holds
        to about 1e-10).  Above it, and for non-finite or blown-up
        derivatives
        (:data:`~skfem_pg.discretization.corrections.GRADIENT_LIMIT`), the
        basis raises :class:`~skfem_pg.errors.CorrectionError` naming the worst
        particles.  ``None`` keeps an inexact correction with a warning
        (studies of the incompatible V2/V4/VC2 systems).
    distributed
        Set by :meth:`skfem_pg.distributed.Partition.basis` on a rank's
        part of a distributed basis: the partition, whose
        ``vc_correction`` solves the constraint system of all ranks'
        families and which supplies PPG1's test derivatives from the
        halo's families; the families come pairwise-complete.
    test_shape
        PPG test derivatives at the masters: ``"master"`` (the trial
        basis' own derivative there: WTE1 = MTE1 at the master, or WTE2),
        ``"WTE1"`` (e.g. the thesis' WTE2–WTE1 combination), ``"WLS1"``
        (linear least squares with a constant term), ``"WLS2"`` (its
        quadratic version), ``"MLS1"`` (moving least squares: weights and
        moment matrix differentiated too) or ``"LME"`` (local
        maximum entropy, :mod:`skfem_pg.discretization.shape.lme`, locality
        ``lme_mu``; surface masters, where LME degenerates, keep ``"master"``).

    Attributes
    ----------
    G
        ``(nf, m, m, d)`` corrected derivatives :math:`G^{kji}`.
    dx
        ``(nf, m)`` weights :math:`w_{kj}` (PPG: :math:`V^j`).
    test
        PPG only: the test basis (same families, dofs and weights, test
        derivatives of
        :func:`skfem_pg.discretization.petrov.element_test_gradients`);
        ``None`` for PBG.
    vc_report
        :class:`~skfem_pg.discretization.corrections.VCReport` (``None``
        without VC).
    area_correction
        ``(dim, np)`` discrete minus FE-consistent surface area vectors
        (``vc_boundary`` ``"s"``/``"sn"``), else ``None``.
    area2_correction
        VC2 with ``vc_boundary="s"``: ``(dim, dim, np)`` discrete minus
        FE-consistent first area moments :math:`A_2^i`, else ``None``.
    timings
        Seconds spent on families, gradients, bond and VC correction.

    """

    @kernel
    def __init__(self, particles, families=None, shape="MTE1", bond=None,
                 vc="auto", method="PBG", dim=None, weight_exponent="auto",
                 vc_solver="auto", area_vectors=None, vc_exclude=None,
                 test_shape="master", lme_mu=1.8, vc_boundary="min-norm",
                 vc_tolerance=1e-8, distributed=None, weights="auto"):
        if isinstance(particles, fem.Mesh):
            particles = Particles.from_mesh(particles)
        if not isinstance(particles, Particles):
            raise TypeError("particles must be a skfem_pg.Particles or a "
                            "scikit-fem mesh, got {}"
                            .format(type(particles).__name__))
        if dim is not None and (isinstance(dim, bool) or dim
                                != particles.dim):
            raise ValueError(
                "dim={!r} components on {}-D particles: a vector field "
                "(displacements) has dim={}, a scalar field dim=None"
                .format(dim, particles.dim, particles.dim))
        if method not in METHODS:
            raise NotImplementedError(
                "method {!r} is not available; this version implements {}"
                .format(method, ", ".join(METHODS)))
        if shape not in GRADIENTS:
            raise ValueError("unknown shape functions {!r}; available: {}"
                             .format(shape, ", ".join(GRADIENTS)))
        ppg = method != "PBG"
        if bond is None:  # PPG too: without it VC PPG1 is unstable
            bond = shape == "MTE1"
        if bond and shape == "WTE2":
            raise ValueError("the bond correction (5.55) is for linear "
                             "bases; use bond=False with shape='WTE2'")
        if vc == "auto":
            vc = {"MTE1": "V5" if bond and not ppg else "V3",
                  "WTE2": "V3"}.get(shape)
        if vc == "VC2" and (shape != "WTE2" or method == "PPG2"):
            raise ValueError("vc='VC2' (second-order VC) needs the quadratic "
                             "trial basis: shape='WTE2', method='PBG' or "
                             "'PPG1'")
        if test_shape not in TEST_SHAPES:
            raise ValueError("test_shape must be one of {}, got {!r}".format(
                ", ".join(TEST_SHAPES), test_shape))
        if test_shape != "master" and not ppg:
            raise ValueError("test_shape={!r} is a Petrov–Galerkin option: "
                             "use method='PPG1' or 'PPG2'".format(test_shape))
        allowed = (("V1", "V2", "V3", "V4", "VC2") if ppg
                   else ("V2", "V3", "V4", "V5", "VC2"))
        if vc is not None and vc not in allowed:
            raise ValueError("vc={!r} is not available for {}: use one of {} "
                             "or None".format(vc, method, ", ".join(allowed)))
        if vc == "V5" and not bond:
            raise ValueError("vc='V5' keeps the bond mapping and needs "
                             "bond=True; use vc='V3' without bond correction")
        if vc_boundary != "min-norm" and (
                vc is None or method == "PPG2"
                or (vc == "VC2" and vc_boundary != "s")):
            raise NotImplementedError(
                "vc_boundary={!r} is implemented for the first-order VC of "
                "PBG and PPG1 (vc V1, V3, V4, V5) and, 's' only, for VC2; "
                "not for {} vc={}".format(vc_boundary, method, vc))
        if vc is not None and area_vectors is None and particles.mesh is None:
            raise ValueError(
                "the VC correction needs surface area vectors A^i: these "
                "particles have no mesh, so pass area_vectors= (shape "
                "(dim, n)) or use vc=None")
        if ppg and weights not in ("auto", None, "volume"):
            raise ValueError("weights={!r} is a PBG option: PPG integrates "
                             "with the member volumes V^j".format(weights))
        t_families = time.perf_counter()
        if families is None and shape == "WTE2":
            # twice the d + d(d+1)/2 quadratic moments, plus the master:
            # with fewer, corner families of graded meshes (Cook's (48,
            # 60) at 7 members) give a singular WTE2 moment matrix
            d = particles.dim
            families = families_mod.horizon(
                particles, factor=2.51,
                min_size=1 + 2 * (d + d * (d + 1) // 2))
        elif families is None and particles.mesh is None:
            families = "horizon"
        families, weights, weight_exponent, self.recipe = recipes.resolve(
            particles, families, weights, weight_exponent, method, shape)
        weight_exponent = recipes.check_exponent(weight_exponent)
        self._weigh = weight_rule(weights)
        self.particles = particles
        self.shape, self.bond, self.vc, self.method = shape, bond, vc, method
        self.weights = weights
        # what rebuilds this basis on moved particles (updated Lagrange):
        # the family rule, not the families
        self.options = dict(
            shape=shape, bond=bond, vc=vc, method=method, dim=dim,
            weight_exponent=weight_exponent, vc_solver=vc_solver,
            vc_exclude=vc_exclude, test_shape=test_shape, lme_mu=lme_mu,
            vc_boundary=vc_boundary, vc_tolerance=vc_tolerance,
            weights=weights)
        if isinstance(families, str):
            self.options["families"] = families
        self.test_shape = test_shape
        self.distributed = distributed
        self._vc_correct = vc_correct = (
            vc_correction if distributed is None
            else distributed.vc_correction)
        self.weight_exponent = weight_exponent
        self.timings = {}
        x, V = particles.x, particles.volumes
        sdim = particles.dim

        t0 = t_families
        if isinstance(families, str):
            families = families_mod.build(families, particles)
        if ppg and distributed is None:  # a partition's come complete
            families = petrov.pairwise(families)
        self.families = families
        self._check_families()
        self.timings["families"] = time.perf_counter() - t0

        self.vc_report = None
        self.vc_boundary = vc_boundary
        unpadded = (not ppg and shape in ("MTE1", "WTE1")
                    and vc in (None, "V3", "V5") and vc_exclude is None
                    and vc_boundary in ("min-norm", "p"))
        self._G = self._G_groups = None
        if distributed is not None and not unpadded and not (
                method == "PPG1" and vc in (None, "V3")
                and vc_boundary == "min-norm" and test_shape == "master"):
            raise NotImplementedError(
                "a distributed basis is PBG with MTE1/WTE1 and vc V3/V5 "
                "or None, or PPG1 with vc V3 or None")
        if unpadded:  # the default: each size group without padding
            self._unpadded_pipeline(vc_solver, area_vectors, vc_tolerance)
        else:
            t0 = time.perf_counter()
            G = GRADIENTS[shape](x, V, families, n=weight_exponent)
            self.timings["gradients"] = time.perf_counter() - t0
            if bond:
                t0 = time.perf_counter()
                G = bond_correction(G, x, families)
                self.timings["bond"] = time.perf_counter() - t0

            mem, mask = families.padded()
            Vm = V[mem] * mask
            if ppg:
                self.dx = petrov.quadrature_weights(V, families)
                Gt = np.zeros_like(G)  # test derivatives at the masters
                Gt[:, 0] = G[:, 0]
                if test_shape == "LME":
                    g, ok = lme_master_gradients(x, families, mu=lme_mu)
                    Gt[ok, 0] = g[ok]
                elif test_shape in LS_TEST_GRADIENTS:
                    Gt[:, 0] = LS_TEST_GRADIENTS[test_shape](
                        x, V, families, n=weight_exponent)
                elif test_shape == "WTE1":
                    Gt[:, 0] = GRADIENTS["WTE1"](x, V, families,
                                                 n=weight_exponent)[:, 0]
                dx_t = np.zeros_like(Vm)
                dx_t[:, 0] = V[families.masters]
            else:
                self.dx = self._weigh(V, families)
            if vc is not None:
                t0 = time.perf_counter()
                area_vectors = self._area_vectors(area_vectors)
                # VC2 of PPG1 corrects test functions only: V1 functions
                # (the thesis' VC2PPG V1s U2); of PBG, V4 (keeps the trial's
                # quadratic consistency)
                surface = (particles.surface_area_vectors()
                           if particles.mesh is not None else None)
                phi = correction_functions("V1" if vc == "VC2" and ppg else vc,
                                           x, V, families, n=weight_exponent)
                if vc == "VC2" and ppg:
                    warnings.warn(
                        "VC2 PPG1 (VC2PPG V1 U2) passes the quadratic patch "
                        "test but is unstable here: its free tangent has "
                        "eigenvalues with negative real part (40 on a regular "
                        "20x10 block, 214 distorted) and it does not converge "
                        "on a manufactured solution; prefer PBG's VC2")
                    Gt, self.vc_report = vc2_correction(
                        Gt, dx_t, x, V, families, area_vectors,
                        particles.area_moments(), phi, exclude=vc_exclude,
                        boundary=vc_boundary, method="PPG1", surface=surface)
                elif vc == "VC2":
                    G, self.vc_report = vc2_correction(
                        G, self.dx, x, V, families, area_vectors,
                        particles.area_moments(), phi, exclude=vc_exclude,
                        boundary=vc_boundary, surface=surface)
                elif method == "PPG2":  # (5.17), its own sparse system
                    warnings.warn(
                        "VC PPG2 passes the patch test but is unstable here: "
                        "its tangent has eigenvalues with negative real part "
                        "(e.g. 4 on a regular 20x10 block) and it does not "
                        "converge on a manufactured solution; prefer PPG1")
                    Gm, self.vc_report = petrov.ppg2_vc_correction(
                        Gt[:, 0], V, families, area_vectors, phi,
                        exclude=vc_exclude)
                    Gt[:, 0] = Gm
                elif ppg:  # (5.16) is (5.18) with the master weights only
                    Gt, self.vc_report = vc_correct(
                        Gt, dx_t, x, V, families, area_vectors, phi,
                        variant=vc, solver=vc_solver, exclude=vc_exclude,
                        boundary=vc_boundary, surface=surface)
                else:
                    G, self.vc_report = vc_correction(
                        G, self.dx, x, V, families, area_vectors, phi,
                        variant=vc, solver=vc_solver, exclude=vc_exclude,
                        boundary=vc_boundary, surface=surface)
                self.timings["vc"] = time.perf_counter() - t0
            what = ("{} {}".format(method, shape) if vc is None
                    else "VC {} ({}{})".format(
                        vc, method, "" if vc_boundary == "min-norm"
                        else ", boundary " + vc_boundary))
            check_correction(Gt if ppg else G, x, families, self.vc_report,
                             vc_tolerance, what=what)
            if ppg:  # the trial derivatives too
                check_correction(G, x, families, None, what=shape + " trial")
            self.G = G
        self.test = None
        self.area_correction = (None if self.vc_report is None
                                else self.vc_report.area_correction)
        self.area2_correction = (None if self.vc_report is None
                                 else self.vc_report.area2_correction)

        # --- what scikit-fem's assembly reads ---------------------------
        self.ncomp = dim
        nc = 1 if dim is None else int(dim)
        self.mesh = particles.mesh if particles.kind == "vertices" else None
        if self.mesh is not None:
            e1, _ = linear_elements(self.mesh)
            self.elem = e1 if dim is None else fem.ElementVector(e1, dim=nc)
            self.dofs = fem.assembly.Dofs(self.mesh, self.elem)
        else:
            self.elem = None
            self.dofs = None
        self._N = nc * particles.n
        self.doflocs = np.repeat(x, nc, axis=1)
        mem = families.padded()[0]
        nf, m = mem.shape
        self.nelems = nf
        self.Nbfun = nc * m
        self.tind = None
        self._element_dofs = None  # padded; built when asked for
        self.X = np.zeros((sdim, m))  # members play the quadrature points
        self.W = np.ones(m)
        self._basis = None
        self._pattern = None
        self.trial = None  # set on a PPG test basis: its trial basis
        if ppg:
            self.test = copy.copy(self)
            self.test.G = petrov.element_test_gradients(
                Gt[:, 0], families, method, reverse=None
                if distributed is None else
                distributed.reverse_master_derivatives(Gt[:, 0], families))
            self.test.trial = self

    @property
    def is_petrov(self):
        """True for the trial and the test basis of PPG1 / PPG2."""
        return self.method != "PBG"

    @classmethod
    def from_name(cls, particles, name, families=None, **kwargs):
        """A basis from a thesis name (Table 7.1), e.g.
        ``FamilyBasis.from_name(p, "VCBCPBG V5 Unl", dim=2)``; see
        :mod:`skfem_pg.naming`."""
        kw, notes = parse(name)
        if (isinstance(particles, Particles) and particles.mesh is None
                and kw.get("families") == "mesh"):
            kw["families"] = "horizon"  # the thesis' rule without a mesh
        if families is not None:
            kw["families"] = families
        basis = cls(particles, **{**kw, **kwargs})
        basis.name_notes = notes
        return basis

    @property
    def name(self):
        """Thesis name, e.g. ``"VCBCPBG V5 Unl"``."""
        return name_of(self)

    # ------------------------------------------------------------------
    def _area_vectors(self, area_vectors):
        x = self.particles.x
        if area_vectors is None:
            area_vectors = self.particles.area_vectors()
        area_vectors = np.asarray(area_vectors, dtype=float)
        if area_vectors.shape != x.shape:
            raise ValueError("area_vectors must have shape {}, got {}"
                             .format(x.shape, area_vectors.shape))
        return area_vectors

    def _unpadded_pipeline(self, vc_solver, area_vectors, vc_tolerance):
        """PBG with MTE1/WTE1 derivatives, bond and V3/V5 correction, one
        size group at a time (:mod:`skfem_pg.discretization.layout`): work
        and storage :math:`\\propto \\sum_k m_k^2` instead of
        :math:`n_f m_{max}^2`; the kernels are the padded ones, run on each
        group's own families."""
        p, fam = self.particles, self.families
        x, V, n = p.x, p.volumes, self.weight_exponent
        L = fam.groups()
        subs = [L.subset(g) for g in L]
        t0 = time.perf_counter()
        Gs = [GRADIENTS[self.shape](x, V, f, n=n) for f in subs]
        self.timings["gradients"] = time.perf_counter() - t0
        if self.bond:
            t0 = time.perf_counter()
            Gs = [bond_correction(G, x, f) for G, f in zip(Gs, subs)]
            self.timings["bond"] = time.perf_counter() - t0
        dxs = [self._weigh(V, f) for f in subs]
        flat = np.empty(L.n_points)
        for g, d in zip(L, dxs):
            flat[g.flat] = d
        self.dx = L.flat_to_padded(flat)
        if self.vc is not None:
            t0 = time.perf_counter()
            area = self._area_vectors(area_vectors)
            phis = [correction_functions(self.vc, x, V, f, n=n)
                    for f in subs]
            Gs, self.vc_report = self._vc_correct(
                Gs, dxs, x, V, subs, area, phis, variant=self.vc,
                solver=vc_solver, boundary=self.vc_boundary,
                surface=(p.surface_area_vectors() if p.mesh is not None
                         else None), index=[g.families for g in L])
            self.timings["vc"] = time.perf_counter() - t0
        what = ("PBG {}".format(self.shape) if self.vc is None
                else "VC {} (PBG{})".format(
                    self.vc, "" if self.vc_boundary == "min-norm"
                    else ", boundary " + self.vc_boundary))
        check_correction(Gs, x, subs, self.vc_report, vc_tolerance,
                         what=what)
        self._G_groups = Gs

    def _check_families(self):
        p, fam = self.particles, self.families
        if fam.n_particles != p.n:
            raise FamilyError("families refer to {} particles, the particle "
                              "set has {}".format(fam.n_particles, p.n))
        inactive = ~p.active[fam.members]
        if np.any(inactive):
            q = fam.members[np.nonzero(inactive)[0][0]]
            raise FamilyError("{} has zero volume but is a family member"
                              .format(describe_particle(q, p.x[:, q])))
        # linear Taylor expansions need d others, WTE2 d + d(d+1)/2; MLS1
        # at the master (VC correction) needs d + 1 others
        d = p.dim
        need = d + 2 if self.vc is not None else d + 1
        q = d + d * (d + 1) // 2  # quadratic basis without constant
        if self.shape == "WTE2":
            need = max(need, 1 + q)
        if self.vc in ("V2", "V4", "VC2") or self.test_shape == "WLS2":
            need = max(need, 2 + q)  # WLS2 with a constant term
        families_mod.check_supports(p, fam, need, "{}{}".format(
            self.shape, " with VC correction" if self.vc else ""))

    @property
    def N(self):
        return self._N

    @property
    def element_dofs(self):
        """``(Nbfun, nf)`` dofs of the padded families (scikit-fem's
        generic assembly; built on first use)."""
        if self._element_dofs is None:
            nc = 1 if self.ncomp is None else self.ncomp
            mem = self.families.padded()[0]
            nf, m = mem.shape
            self._element_dofs = (nc * mem[:, :, None] + np.arange(nc)) \
                .reshape(nf, nc * m).T.astype(np.int64)
        return self._element_dofs

    @property
    def basis(self):
        """Basis functions at the members, built on first use (only the
        generic scikit-fem assembly path needs them)."""
        if self._basis is None:
            self._basis = [self._basis_function(ix)
                           for ix in range(self.Nbfun)]
        return self._basis

    def _basis_function(self, ix):
        nc = 1 if self.ncomp is None else self.ncomp
        a, c = divmod(ix, nc)
        mem, mask = self.families.padded()
        nf, m = mem.shape
        value = np.zeros((nf, m))
        value[:, a] = mask[:, a]
        grad = np.moveaxis(self.G[:, :, a, :], -1, 0)
        if self.ncomp is None:
            return (DiscreteField(value, grad),)
        V = np.zeros((nc, nf, m))
        V[c] = value
        Gr = np.zeros((nc,) + grad.shape)
        Gr[c] = grad
        return (DiscreteField(V, Gr),)

    @property
    def layout(self):
        """:class:`~skfem_pg.discretization.layout.SizeGroups` of the
        families: the unpadded layout of the hot paths."""
        return self.families.groups()

    @property
    def G(self):
        """``(nf, m, m, d)`` derivatives :math:`G^{kji}`, padded to the
        largest family (zero in padded slots).  Bases built without padding
        (the default PBG MTE1/WTE1 pipeline) assemble it on first access
        and keep it."""
        if self._G is None:
            L, Gs = self.layout, self._G_groups
            d = Gs[0].shape[-1]
            G = np.zeros((L.n_families, L.m_max, L.m_max, d))
            for g, Gg in zip(L, Gs):
                G[g.families, :g.m, :g.m] = Gg
            self._G = G
        return self._G

    @G.setter
    def G(self, value):
        self._G, self._G_groups, self._Gt_groups = value, None, None

    def grouped_gradients(self):
        """``G`` without padding: per size group ``(nf_b, m, m, d)``."""
        if self._G_groups is None:
            self._G_groups = [
                np.ascontiguousarray(self._G[g.families, :g.m, :g.m])
                for g in self.layout]
        return self._G_groups

    def grouped_gradients_t(self):
        """``G`` per size group in the layout of a gradient-only linear
        form (an internal force), ``(nf_b, m·d, m)``: rows ``(j, b)``,
        columns the nodes ``i``; cached (a copy of ``G``), so a time step
        does not transpose ``G`` again."""
        if getattr(self, "_Gt_groups", None) is None:
            self._Gt_groups = [
                np.ascontiguousarray(G.transpose(0, 1, 3, 2)).reshape(
                    G.shape[0], -1, G.shape[2])
                for G in self.grouped_gradients()]
        return self._Gt_groups

    def grouped_weights(self):
        """``dx`` without padding: per size group ``(nf_b, m)``."""
        return [self.layout.take(self.dx, g) for g in self.layout]

    def flat_weights(self):
        """``dx`` in the flat layout, ``(1, N_q)``."""
        return self.layout.padded_to_flat(self.dx)[None]

    @kernel
    def interpolate(self, w, flat=False):
        r"""Values and gradients of the nodal field ``w`` at the members:
        value :math:`u^j`, gradient :math:`\sum_i u^i\otimes G^{kji}`
        (so :math:`F = I + \text{grad}` for displacements).

        Padded trailing axes ``(nf, m_max)`` (what scikit-fem's generic
        assembly needs; zero in padded slots), or with ``flat=True`` the
        unpadded ``(1, N_q)`` of :mod:`skfem_pg.discretization.layout`, which
        :func:`skfem_pg.assemble` accepts too and which material models
        evaluate without the padding.
        """
        if self.trial is not None:
            raise ValueError(
                "interpolate() on the test basis of a Petrov–Galerkin "
                "FamilyBasis gives test-function gradients, not F - I: "
                "interpolate on the trial basis (basis.interpolate(u), not "
                "basis.test.interpolate(u))")
        w = np.asarray(w)
        if w.shape[0] != self.N:
            raise ValueError("Input array has wrong size: {} != N = {}"
                             .format(w.shape[0], self.N))
        L = self.layout
        nc = 1 if self.ncomp is None else self.ncomp
        d = self.particles.dim
        W = w.reshape(-1, nc)
        value = np.empty((nc, L.n_points))
        grad = np.empty((nc, d, L.n_points))
        for g, G in zip(L, self.grouped_gradients()):
            U = W[g.members]  # (nf_b, m, nc)
            value[:, g.flat] = np.moveaxis(U, -1, 0)
            gr = np.swapaxes(G, -1, -2) @ U[:, None]  # (nf_b, m, d, nc)
            grad[:, :, g.flat] = gr.transpose(3, 2, 0, 1)
        if flat:
            value, grad = value[..., None, :], grad[..., None, :]
        else:
            value, grad = L.flat_to_padded(value), L.flat_to_padded(grad)
        if self.ncomp is None:
            value, grad = value[0], grad[0]
        return DiscreteField(value, grad)

    # -- scikit-fem idioms -------------------------------------------------
    def _collocation_basis(self, what):
        if self.mesh is None:
            raise NotImplementedError(
                "{} needs particles collocated from a mesh's vertices; for "
                "{} particles use the particle values directly (u[basis."
                "nodal_dofs]) or skfem_pg.analysis.postprocess.particle_fields"
                .format(what, self.particles.kind))
        return fem.Basis(self.mesh, self.elem)

    def probes(self, x):
        r"""Sparse matrix ``P`` with ``P @ u`` the field at points ``x``
        (``(dim, n)``), as scikit-fem's ``CellBasis.probes``: the linear
        (P1/Q1) interpolant of the particle values on the collocation mesh
        — the particle values themselves at the particles.  PG has no
        shape-function values between particles (:math:`N^{ki}(X^j) =
        \delta_{ij}`); this is the interpolation its loads and VTU output
        use."""
        return self._collocation_basis("probes").probes(
            np.asarray(x, dtype=float))

    def project(self, interp, **kwargs):
        r"""Particle values of ``interp``: a callable of positions ``x``
        (``(dim, n)``, returning ``(n,)`` or ``(ncomp, n)``) or a dof
        vector.  With the PBG weights the mass matrix is diagonal and
        :math:`\sum_k\sum_j w_{kj} N^{ki}(X^j) N^{kl}(X^j) = \delta_{il}
        m_i` with :math:`m_i = \sum_{k \ni i} w_{ki}`, and the L2 projection
        :math:`\sum_k w_{ki} f(X^i) / m_i = f(X^i)` *is* the nodal
        interpolation.  Quadrature-point
        fields (``DiscreteField``) are not accepted: average them with
        :func:`skfem_pg.analysis.postprocess.particle_fields` instead."""
        if kwargs:
            raise TypeError("FamilyBasis.project takes no options ({})"
                            .format(", ".join(kwargs)))
        nc = 1 if self.ncomp is None else self.ncomp
        if callable(interp):
            v = np.asarray(interp(self.particles.x), dtype=float)
            if v.shape not in ((nc, self.particles.n),) + (
                    ((self.particles.n,),) if nc == 1 else ()):
                raise ValueError("the projected function must return shape "
                                 "{}, got {}".format(
                                     (nc, self.particles.n), v.shape))
            return v.reshape(nc, -1).T.ravel()
        v = np.asarray(interp)
        if isinstance(interp, DiscreteField) or v.shape != (self.N,):
            raise NotImplementedError(
                "FamilyBasis.project takes a callable of x or a dof vector "
                "of length {}; quadrature-point data: use "
                "skfem_pg.analysis.postprocess.particle_fields".format(self.N))
        return v.astype(float).copy()

    def plot(self, z, **kwargs):
        """scikit-fem's matplotlib ``plot`` of a scalar particle field on
        the collocation mesh (P1/Q1 interpolant); vector fields: plot a
        component, ``basis.plot(u[basis.nodal_dofs[0]])``."""
        z = np.asarray(z)
        if z.shape != (self.particles.n,):
            raise ValueError("plot takes one value per particle ({}), got "
                             "shape {}; for a vector field plot a component"
                             ", e.g. u[basis.nodal_dofs[0]]".format(
                                 self.particles.n, z.shape))
        if self.mesh is None:
            raise NotImplementedError(
                "plot needs a collocation mesh; scatter the particles "
                "(basis.particles.x) or write a VTU (skfem_pg.write_vtu)")
        e1, _ = linear_elements(self.mesh)
        from skfem.visuals.matplotlib import plot
        return plot(fem.Basis(self.mesh, e1), z, **kwargs)

    def draw(self, **kwargs):
        """The collocation mesh (scikit-fem's ``mesh.draw``)."""
        if self.mesh is None:
            raise NotImplementedError("draw needs a collocation mesh")
        return self.mesh.draw(**kwargs)

    def global_coordinates(self):
        mem, _ = self.families.padded()
        return DiscreteField(np.moveaxis(self.particles.x.T[mem], -1, 0))

    def mesh_parameters(self):
        """Family radius :math:`h_k` at every member."""
        mem, _ = self.families.padded()
        h = family_radii(self.particles.x, self.families)
        return DiscreteField(np.broadcast_to(h[:, None], mem.shape).copy())

    def default_parameters(self):
        """``w.x`` (member positions) and ``w.h`` (family radius)."""
        _check_generic_assembly(self, sys._getframe(1))
        return {"x": self.global_coordinates(),
                "h": self.mesh_parameters()}

    def get_dofs(self, facets=None, elements=None, nodes=None, skip=None):
        """Global dofs, as scikit-fem's ``Basis.get_dofs``.

        With vertex particles, ``facets`` (indices, callable, boundary name),
        ``elements`` and ``nodes`` refer to the mesh and the result is a
        scikit-fem ``DofsView``.  Other particle sets accept ``nodes`` only
        (particle indices or a callable on positions ``x`` of shape
        ``(dim, n)``) and return an index array.
        """
        if self.dofs is not None:
            return super().get_dofs(facets=facets, elements=elements,
                                    nodes=nodes, skip=skip)
        if nodes is None:
            raise ValueError("{} particles have no mesh facets: select dofs "
                             "with nodes=<indices or callable>".format(
                                 self.particles.kind))
        if callable(nodes):
            nodes = np.nonzero(nodes(self.particles.x))[0]
        nc = 1 if self.ncomp is None else self.ncomp
        nodes = as_dofs(nodes, self.particles.n,
                        "particle indices (get_dofs nodes=)")
        return (nc * nodes[:, None] + np.arange(nc)).ravel()

    def complement_dofs(self, *D):
        if self.dofs is not None:
            return super().complement_dofs(*D)
        return np.setdiff1d(np.arange(self.N), np.concatenate(
            [np.asarray(d).ravel() for d in D]))

    def split(self, x):
        if self.ncomp is None:
            return [(x, self)]
        return [(x[c::self.ncomp], None) for c in range(self.ncomp)]

    def __repr__(self):
        s = self.families.sizes
        return ("<skfem_pg FamilyBasis {} {}{}{}: {} families (size {}..{}),"
                " {} dofs>".format(
                    self.method, self.shape, "+BC" if self.bond else "",
                    "+" + self.vc if self.vc else "", self.nelems, s.min(),
                    s.max(), self.N))

    __str__ = __repr__


_PPG_HOWTO = ("assemble it with skfem_pg.assemble(form, basis) (it takes "
              "basis.test), with the package's forms "
              "(skfem_pg.BilinearForm / LinearForm), or with scikit-fem's "
              "generic path and the test basis given explicitly: "
              "bilinear form.assemble(basis, basis.test), linear "
              "form.assemble(basis.test, ...)")


def _check_generic_assembly(basis, frame):
    """Refuse scikit-fem's generic assembly where it would silently build
    the wrong thing on a Petrov–Galerkin basis, and say that it is slow.

    scikit-fem's ``BilinearForm._assemble(ubasis, vbasis)``,
    ``LinearForm._assemble`` and ``Functional.elemental`` ask the basis for
    ``default_parameters()``; ``frame`` is the caller's frame, whose locals
    tell the roles.  PPG needs trial functions from ``basis`` and test
    functions from ``basis.test``: ``form.assemble(basis)`` would test with
    the trial functions (a Bubnov–Galerkin matrix with PPG weights, e.g.
    8.3× too stiff on a cantilever), and a functional would count every
    particle once per family it belongs to.
    """
    form = frame.f_locals.get("self")
    if not isinstance(form, fem.assembly.form.Form):
        return
    name = getattr(form.form, "__name__", "form")
    if isinstance(form, fem.Functional):
        if basis.is_petrov:
            raise ValueError(
                "Functional '{}' on a Petrov–Galerkin FamilyBasis: its "
                "weights V^j count each particle once per family it belongs "
                "to, so the integral is wrong; integrate on a PBG basis of "
                "the same particles (FamilyBasis(..., method='PBG'))"
                .format(name))
        return
    loc = frame.f_locals
    u, v = loc.get("ubasis", basis), loc.get("vbasis", basis)
    if not isinstance(form, fem.LinearForm):  # bilinear (or trilinear)
        if isinstance(u, FamilyBasis) and u.trial is not None:
            raise ValueError(
                "BilinearForm '{}' got the Petrov–Galerkin test basis as "
                "its trial basis; {}".format(name, _PPG_HOWTO))
        if isinstance(u, FamilyBasis) and u.test is not None \
                and v is not u.test:
            raise ValueError(
                "BilinearForm '{}' on a Petrov–Galerkin FamilyBasis without "
                "its test basis would assemble a Bubnov–Galerkin matrix "
                "with PPG weights (wrong); {}".format(name, _PPG_HOWTO))
    elif isinstance(v, FamilyBasis) and v.test is not None:
        raise ValueError(
            "LinearForm '{}' on the trial basis of a Petrov–Galerkin "
            "FamilyBasis would test with the trial functions (wrong); {}"
            .format(name, _PPG_HOWTO))
    if (isinstance(form, fem.BilinearForm) and u is basis
            and not getattr(form, "_pg_fast", False)):
        warnings.warn(
            "scikit-fem's generic assembly of '{}' on a FamilyBasis calls "
            "the form once per pair of local basis functions ({} calls) and "
            "is 5-40x slower than skfem_pg.assemble; use "
            "skfem_pg.BilinearForm / LinearForm as decorators (same forms, "
            "fast path) or skfem_pg.assemble(form, basis)".format(
                name, basis.Nbfun ** 2), SlowAssemblyWarning, stacklevel=5)
