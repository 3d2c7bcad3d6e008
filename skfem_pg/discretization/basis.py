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
masters, VC-corrected); assemble with the package's forms
(:class:`skfem_pg.BilinearForm`, :func:`skfem_pg.assemble`), which pick
``basis.test`` up.  scikit-fem's own forms refuse a Petrov–Galerkin basis:
they do not say which role a basis plays (:func:`form_roles`).

Degrees of freedom follow scikit-fem's nodal numbering of the mesh the
particles were collocated from (vector dof ``c`` of particle ``p`` is
``dim * p + c``), so family bases and FE bases on the same mesh add into one
system.  ``G`` and ``dx`` are padded to the largest family size ``m``
(padded slots have zero weight and zero gradient) for scikit-fem's generic
assembly; the batched hot paths (:func:`skfem_pg.assemble`,
``interpolate``, the models) use the unpadded size groups of
:mod:`skfem_pg.discretization.layout` instead.
"""
from __future__ import annotations

import contextlib
import contextvars
import copy
import inspect
import warnings

import numpy as np
import skfem as fem
from skfem.assembly.basis import AbstractBasis
from skfem.element import DiscreteField

from . import builder
from . import petrov
from .builder import BasisSpec
from .corrections import family_radii
from ..dofs import as_dofs
from ..errors import (MixedBasisWarning, NO_SECOND_DERIVATIVES,
                      warn_slow_assembly)
from .particles import Particles, linear_elements
from .quadrature import volume_weights
from ..threads import kernel
from ..naming import name_of
from .families import Families
from numpy.typing import ArrayLike


#: PBG quadrature weights :math:`w_{kj} = V^k V^j / V_H^k` (4.30), the
#: thesis' rule (:func:`~skfem_pg.discretization.quadrature.volume_weights`)
pbg_weights = volume_weights


class FamilyDofs(np.ndarray):
    """:attr:`FamilyBasis.element_dofs`: rows the local dofs, columns the
    *families* (column ``k``: particle ``k``'s family).  Selecting
    columns by an index array raises ``IndexError``, since on a
    scikit-fem basis the same expression selects mesh cells (scikit-fem's
    ex26: ``basis.element_dofs[:, mesh.subdomains['annulus']]`` picked
    the families of particles numbered like those cells, and the answer
    came out 0.0 without a word); rows, slices and single columns index
    as usual.  ``np.asarray(basis.element_dofs)`` is a plain array."""

    def __getitem__(self, key):
        plain = np.asarray(self)
        if isinstance(key, tuple) and len(key) >= 2 and not isinstance(
                key[1], (slice, int, np.integer, type(Ellipsis))):
            raise IndexError(
                "the columns of a FamilyBasis' element_dofs are its "
                "families (column k: particle k's family), not mesh cells. "
                "The dofs of the particles on cells C: "
                "basis.nodal_dofs[:, np.unique(mesh.t[:, C])].ravel() (all "
                "components); families by number: "
                "np.asarray(basis.element_dofs)[:, k]")
        return plain[key]

    @property
    def T(self):  # the transpose's columns are local dofs: a plain array
        return np.asarray(self).T

    def transpose(self, *axes):
        return np.asarray(self).transpose(*axes)


#: scikit-fem ``Basis`` keywords a FamilyBasis has no use for, and why
_FE_KEYWORDS = {
    "intorder": "a FamilyBasis integrates at its family members (or the "
                "moment-matched points: family_quadrature='moments'); "
                "there is no Gauss rule to choose",
    "quadrature": "a FamilyBasis integrates at its family members (or the "
                  "moment-matched points: family_quadrature='moments')",
    "mapping": "a FamilyBasis has no reference element to map",
    "elements": "collocate the particles from the part of the mesh: "
                "Particles.from_mesh(mesh.restrict(elements))",
}


def _refuse_fe_arguments(families, unknown):
    """``TypeError`` naming the PG way for scikit-fem ``Basis`` arguments:
    an element where ``families`` goes (``FamilyBasis(mesh, element)``,
    the literal swap of ``Basis(mesh, element)``) and ``Basis`` keywords."""
    if isinstance(families, (fem.Element, fem.ElementVector)):
        raise TypeError(
            "FamilyBasis(mesh, {}()): a FamilyBasis takes no element, each "
            "particle's family is its element.  For scikit-fem's Basis("
            "mesh, ElementVector(...)) write FamilyBasis(mesh, "
            "dim=mesh.dim()) (displacements), for a scalar Basis(mesh, "
            "element) FamilyBasis(mesh); the second argument is the family "
            "rule ('mesh', 'kNN', 'horizon', ...)".format(
                type(families).__name__))
    if unknown:
        known = sorted(k for k in unknown if k in _FE_KEYWORDS)
        if known:
            raise TypeError("FamilyBasis() got {}={!r}: {}".format(
                known[0], unknown[known[0]], _FE_KEYWORDS[known[0]]))
        options = [name for name, par in inspect.signature(
            FamilyBasis.__init__).parameters.items()
            if par.kind is par.POSITIONAL_OR_KEYWORD
            and name not in ("self", "particles")]
        raise TypeError(
            "FamilyBasis() got unexpected keyword argument(s) {}; its "
            "options are {}".format(", ".join(map(repr, sorted(unknown))),
                                    ", ".join(options)))


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
        particles and those as near as the last, pairwise) or
        ``"horizon"`` (1.51 h).  Default: the
        recipe of :mod:`~skfem_pg.discretization.recipes` — ``"nearest"``
        for PBG MTE1 on 3-D tetrahedra (recipe ``kNN``), else ``"mesh"``
        (on 2-D triangles with uniform weights and unit bond weights,
        recipe ``meshU``)
        for mesh particles and a horizon of 1.51 h otherwise; for WTE2 a
        horizon of 2.51 h, small families enlarged to one member more
        than the quadratic basis needs.
    weights
        PBG quadrature weights
        (:mod:`~skfem_pg.discretization.quadrature`): ``"volume"``
        (:math:`V^k V^j / V_H^k`, (4.30)) or ``"uniform"``
        (:math:`V^k / n_k`).  Default (``"auto"``): the recipe's —
        ``"uniform"`` for the default families on 2-D triangles and 3-D
        tetrahedra and with ``"nearest"`` families, else ``"volume"``.
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
        (:func:`~skfem_pg.discretization.vc.first_order.correction_functions`):
        ``"V5"`` (default with bond correction), ``"V3"`` (default for MTE1
        without bond correction, for WTE2 and for PPG, whose test derivatives
        it corrects), ``"V4"`` (keeps quadratic consistency), ``"V2"``
        (second derivatives of WLS2 (5.61), keeps linear consistency;
        families of ``2 + q`` members and more), ``"V1"`` (PPG only),
        ``None`` (default for WTE1: the classical, uncorrected method), or
        ``"VC2"`` (second-order VC for ``shape="WTE2"``: PBG with V4
        correction functions, PPG1 (5.24) with V1 ones on its test
        derivatives; passes the quadratic patch test;
        :mod:`skfem_pg.discretization.vc.second_order`).
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
        Default (``"auto"``): the recipe's — 0 where the weights are
        ``"uniform"`` by default, else 1.
    vc_solver
        Solver of the VC constraint system: ``"auto"`` (``"direct"``, in
        3-D above 15k particles ``"amg"``), ``"direct"`` (scalar sparse
        LU), ``"amg"`` (the same scalar system by AMG-GMRES, linear in
        the particle count) or ``"lsqr"``; on a distributed basis also
        ``"petsc"`` (:mod:`skfem_pg.distributed.vc`: solved on all ranks).
        ``"local"`` (:mod:`skfem_pg.discretization.vc.local`, the thesis'
        outlook 8.2) solves no global system: each family meets its share
        :math:`\\int N_k \\nabla N_i` of the constraint (the collocation
        mesh's linear functions), one :math:`d\\times d` solve per family
        — PBG on MTE1/WTE1 with V3/V5, boundary ``"min-norm"``, families
        holding every element neighbour (the mesh families); on MPI ranks
        no communication.
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
        :mod:`skfem_pg.discretization.vc.boundary`: ``"min-norm"`` (default;
        every constraint with FE-consistent :math:`A^i`), or the thesis'
        ``"p"``, ``"s"``, ``"sn"``.  With ``"s"``/``"sn"`` the surface
        particles' discrete area vectors (4.35) differ from FE's by
        ``basis.area_correction``, which the loads of
        :mod:`skfem_pg.discretization.loads` include.

    family_quadrature
        ``"members"`` (default: the members are the quadrature points,
        the thesis' (4.25)) or ``"moments"``
        (:mod:`~skfem_pg.discretization.moment_quadrature`: the quadratic
        fit WTE2 evaluated at :math:`2d` points per family that integrate
        quadratic polynomials like the master's hat function; with
        ``shape="WTE2"``, PBG, V3 or no VC; default families the mesh's
        1-ring, enlarged to 7 (2-D) / 14 (3-D) members).  In bending
        0.03–0.4 times T1's / Q1's error on the same nodes in 2-D, on
        3-D tetrahedra 0.1 times O1's from about 500 nodes
        (``benchmarks/README.md``, "2-D recipes").
    order
        1 (default): the thesis' PG, built from the options above.  2:
        the blended quadratic basis ``PG2``
        (:class:`~skfem_pg.discretization.blend.BlendBasis`: the
        families' WTE2 fits blended by the mesh's hat functions; its
        elements are the mesh cells), which takes ``dim``, ``families``
        and ``intorder`` only; ``FamilyBasis(mesh, dim=2, order=2)``
        returns that basis.
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
        :class:`~skfem_pg.discretization.vc.first_order.VCReport` (``None``
        without VC).
    area_correction
        ``(dim, np)`` discrete minus FE-consistent surface area vectors
        (``vc_boundary`` ``"s"``/``"sn"``), else ``None``.
    area2_correction
        VC2 with ``vc_boundary="s"``: ``(dim, dim, np)`` discrete minus
        FE-consistent first area moments :math:`A_2^i`, else ``None``.
    timings
        Seconds spent on families, gradients, bond and VC correction.

    Examples
    --------
    The default basis of a mesh's vertices assembles scikit-fem's forms
    like an FE basis on the same nodes (:func:`skfem_pg.assemble`: the
    batched path; ``form.assemble(basis)`` works too, slower); the
    stiffness matrix has the rigid-body modes as its null space:

    >>> import numpy as np, skfem as fem, skfem_pg as pg
    >>> from skfem.models.elasticity import linear_elasticity
    >>> mesh = fem.MeshTri().refined(2)
    >>> basis = FamilyBasis(mesh, dim=2)
    >>> basis.name
    'VCBCPBG V5m Unl TL meshU'
    >>> K = pg.assemble(linear_elasticity(1.0, 1.0), basis)
    >>> K.shape == (basis.N, basis.N), int(np.sum(np.linalg.eigvalsh(
    ...     K.toarray()) < 1e-10))
    (True, 3)

    """

    _generic_pending = False  # a scikit-fem form asked for parameters

    def __new__(cls, particles=None, *args, order: int = 1, **kwargs):
        # order=2: the blended quadratic basis, another kind of element
        # (a mesh cell over its vertices' families); __init__ is skipped
        if order == 2 and cls is FamilyBasis:
            from .blend import BlendBasis
            allowed = {"dim", "families", "intorder"}
            other = sorted(set(kwargs) - allowed)
            if args or other:
                raise TypeError(
                    "FamilyBasis(..., order=2) is the blended quadratic "
                    "basis (PG2, skfem_pg.discretization.blend.BlendBasis): "
                    "it takes dim=, families= and intorder= only, got {}"
                    .format(", ".join(other) if other else
                            "positional options"))
            return BlendBasis(particles, **kwargs)
        if order not in (1, 2):
            raise ValueError("order must be 1 (the thesis' PG, the options "
                             "below) or 2 (the blended quadratic basis "
                             "PG2), got {!r}".format(order))
        return super().__new__(cls)

    @kernel
    def __init__(self, particles: Particles | fem.Mesh,
                 families: str | Families | None = None,
                 shape: str = "MTE1", bond: bool | None = None,
                 vc: str | None = "auto", method: str = "PBG",
                 dim: int | None = None,
                 weight_exponent: float | str = "auto",
                 vc_solver: str = "auto",
                 area_vectors: np.ndarray | None = None,
                 vc_exclude: ArrayLike | None = None,
                 test_shape: str = "master", lme_mu: float = 1.8,
                 vc_boundary: str = "min-norm",
                 vc_tolerance: float | None = 1e-8, distributed=None,
                 weights: str = "auto",
                 family_quadrature: str = "members", order: int = 1,
                 **unknown) -> None:
        _refuse_fe_arguments(families, unknown)
        particles = _as_particles(particles)
        spec = BasisSpec.resolve(
            particles, families=families, shape=shape, bond=bond, vc=vc,
            method=method, dim=dim, weight_exponent=weight_exponent,
            vc_solver=vc_solver, vc_exclude=vc_exclude,
            test_shape=test_shape, lme_mu=lme_mu, vc_boundary=vc_boundary,
            vc_tolerance=vc_tolerance, weights=weights,
            area_vectors=area_vectors,
            family_quadrature=family_quadrature)
        self._hold(particles, spec, builder.build(
            particles, spec, area_vectors=area_vectors,
            distributed=distributed), distributed)

    @classmethod
    def from_spec(cls, particles: Particles | fem.Mesh, spec: BasisSpec,
                  area_vectors: np.ndarray | None = None,
                  distributed=None) -> "FamilyBasis":
        """The basis of a :class:`~skfem_pg.discretization.builder.BasisSpec`
        (the keyword constructor resolves one and calls the same builder)."""
        particles = _as_particles(particles)
        if spec.dim is not None and spec.dim != particles.dim:
            raise ValueError(
                "the spec was resolved for dim={} components, the particles "
                "are {}-D: resolve it on these particles (BasisSpec.resolve("
                "particles, ...))".format(spec.dim, particles.dim))
        basis = cls.__new__(cls)
        basis._hold(particles, spec, builder.build(
            particles, spec, area_vectors=area_vectors,
            distributed=distributed), distributed)
        return basis

    def _hold(self, particles, spec, arrays, distributed):
        """Keep the built arrays and set what scikit-fem's assembly reads."""
        self.particles, self.spec = particles, spec  # options: see below
        #: what rebuilds this basis on moved particles (updated Lagrange)
        self.options = spec.options()
        self.distributed = distributed
        self.families, self.dx = arrays.families, arrays.dx
        #: ``family_quadrature="moments"``: the values ``(nf, m, m)`` and
        #: positions ``(nf, m, d)`` of the quadrature slots; ``None``: the
        #: members (values :math:`\delta_{ij}`)
        self.values, self.points = arrays.values, arrays.points
        self._master_gradients = arrays.master_gradients
        self.timings, self.vc_report = arrays.timings, arrays.vc_report
        self._G, self._G_groups = arrays.G, arrays.G_groups
        self._Gt_groups = self._values_groups = None  # built when asked
        self.test = None
        report = self.vc_report
        self.area_correction = None if report is None \
            else report.area_correction
        self.area2_correction = None if report is None \
            else report.area2_correction

        # --- what scikit-fem's assembly reads ---------------------------
        dim = spec.dim
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
        self.doflocs = np.repeat(particles.x, nc, axis=1)
        nf, m = self.families.padded()[0].shape
        self.nelems = nf
        self.Nbfun = nc * m
        self.tind = None
        self._element_dofs = None  # padded; built when asked for
        self.X = np.zeros((particles.dim, m))  # members play the quad. points
        self.W = np.ones(m)
        self._basis = None
        self._pattern = None
        self.trial = None  # set on a PPG test basis: its trial basis
        if spec.ppg:
            Gm = arrays.test_master
            self.test = copy.copy(self)
            self.test.G = petrov.element_test_gradients(
                Gm, self.families, spec.method, reverse=None
                if distributed is None else
                distributed.reverse_master_derivatives(Gm, self.families))
            self.test.trial = self

    # the options, read from the spec (spec.parts: the one record of them)
    shape = property(lambda self: self.spec.shape)
    bond = property(lambda self: self.spec.bond)
    vc = property(lambda self: self.spec.vc)
    method = property(lambda self: self.spec.method)
    weights = property(lambda self: self.spec.weights)
    weight_exponent = property(lambda self: self.spec.weight_exponent)
    recipe = property(lambda self: self.spec.recipe)
    test_shape = property(lambda self: self.spec.test_shape)
    vc_boundary = property(lambda self: self.spec.vc_boundary)
    family_quadrature = property(lambda self: self.spec.family_quadrature)

    @property
    def is_petrov(self):
        """True for the trial and the test basis of PPG1 / PPG2."""
        return self.method != "PBG"

    @classmethod
    def from_name(cls, particles: Particles | fem.Mesh, name: str,
                  families: str | Families | None = None,
                  area_vectors: np.ndarray | None = None,
                  distributed=None, **kwargs) -> "FamilyBasis":
        """A basis from a thesis name (Table 7.1), e.g.
        ``FamilyBasis.from_name(p, "VCBCPBG V5 Unl", dim=2)``; see
        :mod:`skfem_pg.naming`."""
        particles = _as_particles(particles)
        spec, notes = BasisSpec.from_name(particles, name, families=families,
                                          area_vectors=area_vectors, **kwargs)
        basis = cls.from_spec(particles, spec, area_vectors=area_vectors,
                              distributed=distributed)
        basis.name_notes = notes
        return basis

    @property
    def name(self):
        """Thesis name, e.g. ``"VCBCPBG V5 Unl"``."""
        return name_of(self)

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
            self._element_dofs = np.ascontiguousarray(
                (nc * mem[:, :, None] + np.arange(nc)).reshape(nf, nc * m)
                .T.astype(np.int64)).view(FamilyDofs)
        return self._element_dofs

    @property
    def basis(self):
        """Basis functions at the members, built on first use (only the
        generic scikit-fem assembly path needs them).  A scikit-fem form
        that reads them warns once per assembly
        (:class:`~skfem_pg.errors.SlowAssemblyWarning`)."""
        if self._generic_pending:
            self._generic_pending = False
            warn_slow_assembly("FamilyBasis", self.Nbfun)
        if self._basis is None:
            self._basis = [self._basis_function(ix)
                           for ix in range(self.Nbfun)]
        return self._basis

    def _basis_function(self, ix):
        nc = 1 if self.ncomp is None else self.ncomp
        a, c = divmod(ix, nc)
        mem, mask = self.families.padded()
        nf, m = mem.shape
        if self.values is None:
            value = np.zeros((nf, m))
            value[:, a] = mask[:, a]
        else:
            value = self.values[:, :, a].copy()
        grad = np.moveaxis(self.G[:, :, a, :], -1, 0)
        if self.ncomp is None:
            return (DiscreteField(value, grad,
                                  hess=NO_SECOND_DERIVATIVES),)
        V = np.zeros((nc, nf, m))
        V[c] = value
        Gr = np.zeros((nc,) + grad.shape)
        Gr[c] = grad
        return (DiscreteField(V, Gr, hess=NO_SECOND_DERIVATIVES),)

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
        if self._Gt_groups is None:
            self._Gt_groups = [
                np.ascontiguousarray(G.transpose(0, 1, 3, 2)).reshape(
                    G.shape[0], -1, G.shape[2])
                for G in self.grouped_gradients()]
        return self._Gt_groups

    def grouped_values(self):
        r"""Shape-function values at the quadrature slots per size group,
        ``(nf_b, m, m)`` ``[k, j, i]``, or ``None`` where the members are
        the quadrature points (values :math:`\delta_{ij}`)."""
        if self.values is None:
            return None
        if self._values_groups is None:
            self._values_groups = [
                np.ascontiguousarray(self.values[g.families, :g.m, :g.m])
                for g in self.layout]
        return self._values_groups

    def master_gradients(self):
        r"""``(nf, m, d)`` derivatives :math:`G^{kki}` at each family's
        master (what particle output evaluates): the first quadrature
        slot's where the members are the quadrature points, the quadratic
        fit's at the master with ``family_quadrature="moments"``."""
        if self._master_gradients is not None:
            return self._master_gradients
        if self._G is not None:
            return self._G[:, 0]
        L = self.layout  # from the size groups: no padded G built
        Gm = np.zeros((L.n_families, L.m_max, self.particles.dim))
        for g, G in zip(L, self.grouped_gradients()):
            Gm[g.families, :g.m] = G[:, 0]
        return Gm

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
            cells = (self.mesh is not None
                     and w.shape[0] == self.mesh.nelements)
            raise ValueError(
                "Input array has wrong size: {} != N = {}{}".format(
                    w.shape[0], self.N,
                    " (one value per cell?  a FamilyBasis integrates at "
                    "its family members: evaluate a cell field there with "
                    "skfem_pg.discretization.coefficients."
                    "cell_values_at_members(basis, values))" if cells
                    else ""))
        L = self.layout
        nc = 1 if self.ncomp is None else self.ncomp
        d = self.particles.dim
        W = w.reshape(-1, nc)
        value = np.empty((nc, L.n_points))
        grad = np.empty((nc, d, L.n_points))
        Ns = self.grouped_values() or [None] * len(L.groups)
        for g, G, N in zip(L, self.grouped_gradients(), Ns):
            U = W[g.members]  # (nf_b, m, nc)
            value[:, g.flat] = np.moveaxis(U if N is None else N @ U, -1, 0)
            gr = np.swapaxes(G, -1, -2) @ U[:, None]  # (nf_b, m, d, nc)
            grad[:, :, g.flat] = gr.transpose(3, 2, 0, 1)
        if flat:
            value, grad = value[..., None, :], grad[..., None, :]
        else:
            # (..., 1, N_q) is unambiguous: a leading axis of length 1 (one
            # component, 1-D) is not taken for the flat layout's
            value = L.flat_to_padded(value[..., None, :])
            grad = L.flat_to_padded(grad[..., None, :])
        if self.ncomp is None:
            value, grad = value[0], grad[0]
        return DiscreteField(value, grad, hess=NO_SECOND_DERIVATIVES)

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
        x = np.asarray(x, dtype=float)
        d = self.particles.dim
        if x.ndim != 2 or x.shape[0] != d:
            raise ValueError(
                "probes takes points x of shape (dim, n) = ({}, n), got "
                "shape {}{}".format(d, x.shape, "; points as rows: pass x.T"
                                    if x.ndim == 2 and x.shape[1] == d
                                    else ""))
        return self._collocation_basis("probes").probes(x)

    def point_source(self, x):
        """The right-hand side of a unit point source at ``x``
        (``(dim,)``), as scikit-fem's ``CellBasis.point_source``: the
        values at ``x`` of the interpolant :meth:`probes` uses, one entry
        per particle dof (a scalar basis; for a vector basis give each
        component's load through :meth:`probes`)."""
        x = np.asarray(x, dtype=float)
        d = self.particles.dim
        if x.shape != (d,):
            raise ValueError("point_source takes one point of shape ({},), "
                             "got shape {}".format(d, x.shape))
        if self.ncomp is not None:
            raise ValueError(
                "point_source is a scalar basis' load; on a vector basis "
                "(dim={}) put a point force F at x as P = basis.probes("
                "x[:, None]) on each component: f[basis.nodal_dofs[c]] += "
                "F[c] * P.toarray()[0]".format(self.ncomp))
        return self.probes(x[:, None]).toarray()[0]

    def interpolator(self, y):
        """A function of points ``x`` (``(dim, n)``, or with trailing
        axes) returning the field ``y`` there, as scikit-fem's
        ``CellBasis.interpolator`` (the interpolant of :meth:`probes`)."""
        y = np.asarray(y)

        def interpfun(x):
            x = np.asarray(x, dtype=float)
            shape = x.shape
            out = self.probes(x.reshape(shape[0], -1)) @ y
            return out.reshape(shape[1:]) if len(shape) > 2 else out
        return interpfun

    def project(self, interp, **kwargs):
        r"""Particle values of ``interp``: a callable of positions ``x``
        (``(dim, n)``, returning ``(n,)`` or ``(ncomp, n)``) or a dof
        vector.  With the PBG weights the mass matrix is diagonal and
        :math:`\sum_k\sum_j w_{kj} N^{ki}(X^j) N^{kl}(X^j) = \delta_{il}
        m_i` with :math:`m_i = \sum_{k \ni i} w_{ki}`, and the L2 projection
        :math:`\sum_k w_{ki} f(X^i) / m_i = f(X^i)` *is* the nodal
        interpolation; with ``family_quadrature="moments"`` too (the
        values at the points are the master's,
        :mod:`~skfem_pg.discretization.moment_quadrature`).  Quadrature-point
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
                raise ValueError(
                    "the projected function is called with the particle "
                    "positions x of shape (dim, n) = {} (not scikit-fem's "
                    "(dim, elements, points)) and must return {}, got {}"
                    .format(self.particles.x.shape,
                            "(n,) or (1, n)" if nc == 1
                            else "(ncomp, n) = {}".format(
                                (nc, self.particles.n)), v.shape))
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

    def boundary(self, facets=None, intorder=None):
        """A scikit-fem ``FacetBasis`` on ``facets`` (default: the boundary)
        that interpolates this basis' dof vectors, as scikit-fem's
        ``CellBasis.boundary``: the particle values are the nodal values
        of the collocation mesh's linear element ``basis.elem``, so
        ``fb.interpolate(u)`` is their trace (P1/Q1 between particles) for
        boundary functionals such as a port's flux (scikit-fem's ex13).
        The reaction ``(K @ u)[basis.get_dofs(port)]`` is the consistent
        flux of a Dirichlet port, usually the more accurate one.

        >>> import numpy as np, skfem as fem, skfem_pg as pg
        >>> mesh = fem.MeshTri.init_tensor(*(np.linspace(0, 1, 5),) * 2)
        >>> basis = pg.FamilyBasis(mesh)
        >>> fb = basis.boundary(mesh.facets_satisfying(lambda x: x[0] == 1))
        >>> float(fem.Functional(lambda w: w.u).assemble(
        ...     fb, u=fb.interpolate(basis.project(lambda x: x[1]))))
        0.5
        """
        if self.mesh is None:
            raise NotImplementedError(
                "boundary needs particles collocated from a mesh's "
                "vertices; {} particles have no facets".format(
                    self.particles.kind))
        return fem.FacetBasis(self.mesh, self.elem, facets=facets,
                              intorder=intorder)

    def with_element(self, elem):
        """Not available: a family basis has no other element to swap in
        (its members are its quadrature points).  Raises with what to do
        instead (scikit-fem's examples use ``with_element`` to project
        stresses onto a DG element for plotting)."""
        raise NotImplementedError(
            "FamilyBasis.with_element({}): a family basis has no other "
            "element.  For stresses or strains per particle use "
            "skfem_pg.analysis.postprocess.particle_fields(basis, material, "
            "u); for "
            "a field on an FE element of the collocation mesh build "
            "fem.Basis(basis.mesh, elem) and interpolate the particle "
            "values there (basis.probes(x) gives the P1/Q1 interpolant)"
            .format(type(elem).__name__))

    def draw(self, **kwargs):
        """The collocation mesh (scikit-fem's ``mesh.draw``)."""
        if self.mesh is None:
            raise NotImplementedError("draw needs a collocation mesh")
        return self.mesh.draw(**kwargs)

    def global_coordinates(self):
        if self.points is not None:
            return DiscreteField(np.moveaxis(self.points, -1, 0))
        mem, _ = self.families.padded()
        return DiscreteField(np.moveaxis(self.particles.x.T[mem], -1, 0))

    def mesh_parameters(self):
        """Family radius :math:`h_k` at every member."""
        mem, _ = self.families.padded()
        h = family_radii(self.particles.x, self.families)
        return DiscreteField(np.broadcast_to(h[:, None], mem.shape).copy())

    def default_parameters(self):
        """``w.x`` (member positions) and ``w.h`` (family radius).

        Outside the package's forms (:func:`form_roles`) a Petrov–Galerkin
        basis refuses: scikit-fem's forms do not say whether it is asked as
        the trial or the test basis.
        """
        if _ROLES.get() is None:
            if self.is_petrov:
                raise ValueError(
                    "scikit-fem's own forms on a Petrov–Galerkin FamilyBasis "
                    "cannot say whether this basis is asked for trial or "
                    "test functions, and the wrong pairing is silently "
                    "wrong (a Bubnov–Galerkin matrix with PPG weights, "
                    "8.3x too stiff on a cantilever); {}; a Functional "
                    "needs a PBG basis of the same particles".format(
                        _PPG_HOWTO))
            self._generic_pending = True  # see the basis property
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


_PPG_HOWTO = ("assemble with the package's forms, which test with "
              "basis.test: skfem_pg.BilinearForm / LinearForm as decorators "
              "(the same form functions) or skfem_pg.assemble(form, basis)")


def _as_particles(particles):
    if isinstance(particles, fem.Mesh):
        particles = Particles.from_mesh(particles)
    if not isinstance(particles, Particles):
        raise TypeError("particles must be a skfem_pg.Particles or a "
                        "scikit-fem mesh, got {}"
                        .format(type(particles).__name__))
    return particles


def warn_equal_order_mixed(ubasis, vbasis):
    """Warn (:class:`~skfem_pg.errors.MixedBasisWarning`) when a form
    couples two family bases of different component counts on the same
    particles — a displacement–pressure pair of equal order, which fails
    the inf-sup condition (thesis 7.2.3; scikit-fem's mixed u–p example
    with both bases swapped diverges to NaN)."""
    if not (isinstance(ubasis, FamilyBasis)
            and isinstance(vbasis, FamilyBasis)
            and ubasis.ncomp != vbasis.ncomp):
        return
    pu, pv = ubasis.particles, vbasis.particles
    if pu is pv or (pu.n == pv.n and np.array_equal(pu.x, pv.x)):
        warnings.warn(
            "a form couples a {}-component and a {}-component FamilyBasis "
            "on the same particles: an equal-order PG displacement–"
            "pressure pair fails the inf-sup condition and its Newton "
            "iterations diverge.  Use the package's mixed formulations, "
            "which carry pressures per family or condensed nodal ones: "
            "Scene(...).solve('VCBCPBG V5m IUnlP0') or "
            "'... Unl+P1C', or skfem_pg.formulations.IncompressibleP0 "
            "with materials.NeoHookeIsoVol".format(
                ubasis.ncomp or 1, vbasis.ncomp or 1),
            MixedBasisWarning, stacklevel=4)


# Set while the package's own forms assemble (:func:`form_roles`): they
# pass the trial and the test basis explicitly, so the roles are known.
_ROLES = contextvars.ContextVar("skfem_pg_form_roles", default=None)


def check_roles(form, ubasis, vbasis=None, kwargs=None):
    """Refuse a trial/test pairing that would assemble a wrong matrix or
    vector on a Petrov–Galerkin basis, name bad coefficients, and warn on
    an equal-order displacement–pressure pair.

    PPG needs trial functions from ``basis`` and test functions from
    ``basis.test``: testing with the trial functions gives a
    Bubnov–Galerkin matrix with PPG weights (8.3× too stiff on a
    cantilever, ``tests/test_forms.py``), and a functional counts every
    particle once per family it belongs to.

    Parameters
    ----------
    form : skfem.assembly.form.Form
        The form (bilinear, linear or functional).
    ubasis : AbstractBasis
        The trial basis (a functional: the basis).
    vbasis : AbstractBasis, optional
        The test basis (a linear form: the basis it is assembled on);
        ``ubasis`` if omitted.
    kwargs : dict, optional
        The form's coefficients.

    Examples
    --------
    >>> import skfem as fem, skfem_pg as pg
    >>> b = pg.FamilyBasis(fem.MeshTri().refined(2), method="PPG1")
    >>> K = fem.BilinearForm(lambda u, v, w: u * v)
    >>> check_roles(K, b, b.test)   # trial, test: fine
    >>> check_roles(K, b)
    Traceback (most recent call last):
    ...
    ValueError: BilinearForm '<lambda>' on a Petrov–Galerkin ...
    """
    vbasis = ubasis if vbasis is None else vbasis
    name = getattr(form.form, "__name__", "form")
    if isinstance(ubasis, FamilyBasis) and kwargs:
        # FE quadrature data or another element's dofs: named here, before
        # scikit-fem's "Quadrature mismatch" / "wrong size"
        from .assembly import check_coefficients
        check_coefficients(ubasis, kwargs)
    if vbasis is not ubasis and isinstance(form, fem.BilinearForm):
        warn_equal_order_mixed(ubasis, vbasis)
    if isinstance(form, fem.Functional):
        if isinstance(ubasis, FamilyBasis) and ubasis.is_petrov:
            raise ValueError(
                "Functional '{}' on a Petrov–Galerkin FamilyBasis: its "
                "weights V^j count each particle once per family it belongs "
                "to, so the integral is wrong; integrate on a PBG basis of "
                "the same particles (FamilyBasis(..., method='PBG'))"
                .format(name))
    elif isinstance(form, fem.LinearForm):
        if isinstance(vbasis, FamilyBasis) and vbasis.test is not None:
            raise ValueError(
                "LinearForm '{}' on the trial basis of a Petrov–Galerkin "
                "FamilyBasis would test with the trial functions (wrong); "
                "{}".format(name, _PPG_HOWTO))
    elif isinstance(ubasis, FamilyBasis):  # bilinear
        if ubasis.trial is not None:
            raise ValueError(
                "BilinearForm '{}' got the Petrov–Galerkin test basis as "
                "its trial basis; {}".format(name, _PPG_HOWTO))
        if ubasis.test is not None and vbasis is not ubasis.test:
            raise ValueError(
                "BilinearForm '{}' on a Petrov–Galerkin FamilyBasis without "
                "its test basis would assemble a Bubnov–Galerkin matrix "
                "with PPG weights (wrong); {}".format(name, _PPG_HOWTO))


@contextlib.contextmanager
def form_roles(form, ubasis, vbasis=None, kwargs=None):
    """Assemble ``form`` with scikit-fem's generic path inside this block,
    the roles checked by :func:`check_roles`.

    A family basis' ``default_parameters`` refuses a Petrov–Galerkin basis
    outside such a block: scikit-fem's forms ask one basis for its
    parameters and do not say which role it plays, so only the package's
    forms (:class:`skfem_pg.BilinearForm`, :func:`skfem_pg.assemble`),
    which pass both bases, can vouch for the pairing.
    """
    check_roles(form, ubasis, vbasis, kwargs)
    token = _ROLES.set((ubasis, vbasis))
    try:
        yield
    finally:
        _ROLES.reset(token)
