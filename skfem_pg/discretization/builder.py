r"""How a :class:`~skfem_pg.FamilyBasis` is made: its parts and the stages
one builder composes.

A basis is the result of a fixed sequence of stages, each a plain function
of the particles, the :class:`BasisSpec` (its parts,
:mod:`~skfem_pg.discretization.parts`, resolved from the keywords and
checked against each other when made) and what the earlier stages
computed:

1. **families** — a rule of
   :data:`skfem_pg.discretization.families.RULES` or given
   :class:`~skfem_pg.Families`; PPG completes them to pairwise ones;
2. **trial derivatives** :math:`G^{kji}` — a shape function of
   :data:`skfem_pg.discretization.shape.GRADIENTS` (MTE1/WTE1 (3.32),
   WTE2), then the bond correction (5.55);
3. **quadrature weights** — PBG's rule of
   :mod:`~skfem_pg.discretization.quadrature` ((4.30) or uniform), PPG's
   member volumes :math:`V^j`;
4. **test derivatives at the masters** (PPG) — a rule of
   :data:`TEST_GRADIENTS`;
5. **variational consistency** — a correction of :data:`CORRECTIONS`
   (first-order VC (5.18) of PBG and PPG1, (5.17) of PPG2, second-order
   VC2), checked by
   :func:`~skfem_pg.discretization.corrections.check_correction`.

:func:`build` runs them and returns the computed arrays
(:class:`BasisArrays`); :class:`~skfem_pg.FamilyBasis` holds them behind
scikit-fem's basis interface.  The default PBG pipeline with MTE1/WTE1 and
V3/V5 or no correction runs stages 2–5 one family-size group at a time
(:mod:`skfem_pg.discretization.layout`), without padding.

A new shape function, family rule, test rule or correction is one function
plus one entry in its table (``GRADIENTS``, ``RULES``,
:data:`TEST_GRADIENTS`, :data:`CORRECTIONS`); what it works with and
supports (MPI, the grouped path, crack-aware rebuilds) its part says in
:mod:`~skfem_pg.discretization.parts`.  The thesis names of Table 7.1
produce a :class:`BasisSpec` through :meth:`BasisSpec.from_name`, and
:attr:`BasisSpec.name` prints it back.
"""
import dataclasses
import time
import warnings
from typing import Optional

import numpy as np

from . import families as families_mod
from . import petrov
from . import recipes
from ..errors import FamilyError, describe_particle
from .corrections import bond_correction, check_correction
from .vc.first_order import VCSystem, correction_functions, vc_correction
from .families import Families
from .quadrature import weight_rule
from .shape import GRADIENTS
from .shape.least_squares import (mls1_master_gradients,
                                   wls1_master_gradients,
                                   wls2_master_gradients)
from .shape.lme import lme_master_gradients
from .vc.second_order import vc2_correction
from .moment_quadrature import moment_quadrature
from .moment_quadrature import family_options as moment_family_options
from .vc import local as local_vc
from . import parts as parts_mod
from ..naming import GIVEN, name_of, parse

METHODS = parts_mod.METHODS
VC_VARIANTS = parts_mod.VC_VARIANTS


def _trial_at_master(p, fam, G, spec):
    return G[:, 0]


def _wte1_at_master(p, fam, G, spec):
    return GRADIENTS["WTE1"](p.x, p.volumes, fam,
                             n=spec.weight_exponent)[:, 0]


def _least_squares(rule):
    def at_master(p, fam, G, spec):
        return rule(p.x, p.volumes, fam, n=spec.weight_exponent)
    at_master.__name__ = rule.__name__
    return at_master


def _lme_at_master(p, fam, G, spec):
    g, ok = lme_master_gradients(p.x, fam, mu=spec.lme_mu)
    out = G[:, 0].copy()
    out[ok] = g[ok]  # LME degenerates at surface masters: keep the trial's
    return out


#: PPG test derivatives at the masters, ``test_shape`` ->
#: ``f(particles, families, G, spec)`` returning ``(nf, m, d)``
TEST_GRADIENTS = {
    "master": _trial_at_master,
    "WTE1": _wte1_at_master,
    "WLS1": _least_squares(wls1_master_gradients),
    "WLS2": _least_squares(wls2_master_gradients),
    "MLS1": _least_squares(mls1_master_gradients),
    "LME": _lme_at_master,
}


@dataclasses.dataclass(frozen=True)
class BasisSpec:
    """A :class:`~skfem_pg.FamilyBasis` as its parts
    (:class:`~skfem_pg.discretization.parts.Parts`: family rule, shape,
    quadrature, correction, method) and its number of components ``dim``
    (``None``: a scalar field), checked against each other when made.
    Make one with :meth:`resolve` (the keywords of
    :class:`~skfem_pg.FamilyBasis`, defaults filled in) or
    :meth:`from_name` (a Table 7.1 name); build the basis with
    ``FamilyBasis.from_spec``.  The keywords read back as attributes
    (``spec.vc``, ``spec.shape``, ...).

    >>> import skfem as fem, skfem_pg as pg
    >>> spec = BasisSpec.resolve(pg.Particles.from_mesh(fem.MeshQuad()),
    ...                          dim=2)
    >>> spec.shape, spec.vc, spec.recipe, spec.supports("mpi")
    ('MTE1', 'V5', 'mesh', True)
    >>> spec.name
    'VCBCPBG V5m Unl TL'
    """

    parts: parts_mod.Parts
    dim: Optional[int] = None

    def __post_init__(self):
        parts_mod.check(self.parts)

    family_rule = property(lambda self: self.parts.family_rule)

    @property
    def ppg(self):
        return self.parts.method.petrov

    @property
    def recipe(self):
        """The name of :data:`skfem_pg.discretization.recipes.RECIPES`
        whose family rule, weights and exponent these are, else
        ``None``."""
        rule = self.family_rule
        if self.family_quadrature != "members" or rule.given \
                or rule.parameters:
            return None
        return recipes.name_of(rule.rule, self.weights,
                               self.weight_exponent)

    def supports(self, capability):
        """Whether the parts support ``capability``
        (:data:`~skfem_pg.discretization.parts.CAPABILITIES`)."""
        return parts_mod.refusal(capability, self.parts) is None

    def require(self, capability, what=None):
        """Raise ``NotImplementedError`` naming the option that does not
        support ``capability``."""
        parts_mod.require(capability, self.parts, what)

    @property
    def grouped(self):
        """Whether the stages run per family-size group, without padding
        (PBG with MTE1/WTE1, vc V3/V5 or none, no excluded particles,
        boundary ``min-norm`` / ``p``)."""
        return self.supports("grouped")

    def min_members(self, space_dim):
        """The smallest family the parts work on (master included) in
        ``space_dim`` dimensions."""
        return parts_mod.min_members(self.parts, space_dim)

    @property
    def name(self):
        """The full thesis code (:func:`skfem_pg.naming.name_of`)."""
        return name_of(self)

    def options(self):
        """The keywords that rebuild a basis of this spec on moved particles
        (updated Lagrange): the family rule, not the families."""
        out = {"dim": self.dim}
        out.update((k, getattr(self, k)) for k in parts_mod.FIELDS)
        if self.family_quadrature == "moments":
            del out["weights"]  # the rule makes its own
        rule = self.family_rule
        if not rule.given and not rule.parameters:
            out["families"] = rule.rule
        return out

    @classmethod
    def from_name(cls, particles, name, families=None, **kwargs):
        """The spec of a thesis name (Table 7.1, :mod:`skfem_pg.naming`)
        and its notes; ``kwargs`` override what the name says."""
        kw, notes = parse(name)
        if particles.mesh is None and kw.get("families") == "mesh":
            kw["families"] = "horizon"  # the thesis' rule without a mesh
        for key, given in (("families", families),
                           ("vc_exclude", kwargs.get("vc_exclude"))):
            if kw.get(key) == GIVEN and given is None:
                raise ValueError(
                    "{!r} says its {} were given: pass {}=".format(
                        name, key.replace("vc_", ""), key))
        if families is not None:
            kw["families"] = families
        return cls.resolve(particles, **{**kw, **kwargs}), notes

    @classmethod
    def resolve(cls, particles, families=None, shape="MTE1", bond=None,
                vc="auto", method="PBG", dim=None, weight_exponent="auto",
                vc_solver="auto", vc_exclude=None, test_shape="master",
                lme_mu=1.8, vc_boundary="min-norm", vc_tolerance=1e-8,
                weights="auto", area_vectors=None,
                family_quadrature="members"):
        """The spec of :class:`~skfem_pg.FamilyBasis`'s keywords, defaults
        filled in; raises ``ValueError`` / ``NotImplementedError`` naming
        the option for a combination the stages cannot build
        (:mod:`~skfem_pg.discretization.parts`; ``area_vectors`` is only
        checked for presence)."""
        for key, value in (("families", families),
                           ("vc_exclude", vc_exclude)):
            if isinstance(value, str) and value == GIVEN:
                raise ValueError(
                    "{}='given' stands for {} passed beside a name: pass "
                    "them as {}=".format(key, "families" if key ==
                                         "families" else "particles", key))
        if dim is not None and (isinstance(dim, bool) or dim
                                != particles.dim):
            raise ValueError(
                "dim={!r} components on {}-D particles: a vector field "
                "(displacements) has dim={}, a scalar field dim=None"
                .format(dim, particles.dim, particles.dim))
        method = parts_mod.Method(method, test_shape, lme_mu)
        ppg = method.petrov
        if bond is None:  # PPG too: without it VC PPG1 is unstable
            bond = shape == "MTE1"
        if vc == "auto":
            vc = {"MTE1": "V5" if bond and not ppg else "V3",
                  "WTE2": "V3"}.get(shape)
        if vc is not None and area_vectors is None and particles.mesh is None:
            raise ValueError(
                "the VC correction needs surface area vectors A^i: these "
                "particles have no mesh, so pass area_vectors= (shape "
                "(dim, n)) or use vc=None")
        if ppg and weights not in ("auto", None, "volume"):
            raise ValueError("weights={!r} is a PBG option: PPG integrates "
                             "with the member volumes V^j".format(weights))
        if family_quadrature == "moments":
            if weights not in ("auto", None):
                raise ValueError(
                    "weights={!r}: family_quadrature='moments' makes its "
                    "own weights (the hat functions' moments)".format(
                        weights))
            weights = "uniform"  # not used: the rule makes its own
        if families is None:
            families = _default_rule(particles, shape, family_quadrature)
        rule = families.rule if isinstance(families, parts_mod.FamilyRule) \
            and not families.parameters else families
        rule, weights, weight_exponent, _ = recipes.resolve(
            particles, rule, weights, weight_exponent, method.name, shape)
        if ppg:  # PPG integrates with the member volumes
            weights = "volume"
        if not isinstance(rule, parts_mod.FamilyRule):
            rule = parts_mod.FamilyRule(rule)
        return cls(parts_mod.from_keywords(dict(
            shape=shape,
            weight_exponent=recipes.check_exponent(weight_exponent),
            weights=weights, family_quadrature=family_quadrature,
            bond=bool(bond), vc=vc, vc_boundary=vc_boundary,
            vc_solver=vc_solver, vc_exclude=vc_exclude,
            vc_tolerance=vc_tolerance, method=method.name,
            test_shape=test_shape, lme_mu=lme_mu), rule), dim)


def _default_rule(particles, shape, family_quadrature):
    """The family rule of a basis without ``families``: the moment
    quadrature's 1-ring, WTE2's horizon, a horizon without a mesh, else
    ``None`` (the recipe's, :mod:`~skfem_pg.discretization.recipes`)."""
    d = particles.dim
    if family_quadrature == "moments":  # the 1-ring, a quadratic fit's
        if particles.mesh is None:
            raise ValueError(
                "family_quadrature='moments' needs particles collocated "
                "from a mesh's vertices (their hat functions' moments and "
                "1-ring families)")
        return parts_mod.FamilyRule("mesh", tuple(sorted(
            moment_family_options(d).items())))
    if shape == "WTE2":
        # twice the d + d(d+1)/2 quadratic moments, plus the master: with
        # fewer, corner families of graded meshes (Cook's (48, 60) at 7
        # members) give a singular WTE2 moment matrix
        return parts_mod.FamilyRule("horizon", (
            ("factor", 2.51), ("min_size", 1 + 2 * (d + d * (d + 1) // 2))))
    return "horizon" if particles.mesh is None else None


def _keyword(part, field):
    return property(lambda self: getattr(getattr(self.parts, part), field),
                    doc="``{}.{}`` of the parts".format(part, field))


# the keywords read back from the parts (spec.vc, spec.shape, ...)
for _key, (_part, _field) in parts_mod.FIELDS.items():
    setattr(BasisSpec, _key, _keyword(_part, _field))


@dataclasses.dataclass
class BasisArrays:
    """What :func:`build` computes.  ``G`` (padded ``(nf, m, m, d)``) or
    ``G_groups`` (per size group, the grouped pipeline) holds the trial
    derivatives; ``test_master`` PPG's ``(nf, m, d)`` test derivatives at
    the masters (``None`` for PBG)."""

    families: Families
    dx: np.ndarray
    G: Optional[np.ndarray] = None
    G_groups: Optional[list] = None
    test_master: Optional[np.ndarray] = None
    vc_report: object = None
    timings: dict = dataclasses.field(default_factory=dict)
    #: ``family_quadrature="moments"``: shape-function values ``(nf, m, m)``,
    #: positions ``(nf, m, d)`` of the quadrature slots, the derivatives at
    #: the masters ``(nf, m, d)``; ``None`` when the members are the
    #: quadrature points (values :math:`\delta_{ij}`)
    values: Optional[np.ndarray] = None
    points: Optional[np.ndarray] = None
    master_gradients: Optional[np.ndarray] = None


@dataclasses.dataclass
class _Context:
    """What a correction of :data:`CORRECTIONS` reads and writes."""

    particles: object
    spec: BasisSpec
    families: Families
    G: np.ndarray
    dx: np.ndarray
    Gt: Optional[np.ndarray]  # (nf, m, m, d), the masters' rows filled
    dx_t: Optional[np.ndarray]
    area: np.ndarray
    vc_solve: object  # vc_correction, or a partition's
    report: object = None

    @property
    def surface(self):
        return surface_of(self.particles)

    def phi(self, variant):
        p = self.particles
        return correction_functions(variant, p.x, p.volumes, self.families,
                                    n=self.spec.weight_exponent)

    def system(self, G, dx, variant):
        """The :class:`~skfem_pg.discretization.vc.first_order.VCSystem` of
        derivatives ``G`` with weights ``dx`` and the correction functions
        of ``variant``."""
        p = self.particles
        return VCSystem(G, dx, p.x, p.volumes, self.families, self.area,
                        self.phi(variant), self.surface)

    def options(self):
        """The keywords of a first-order VC solve, from the spec."""
        s = self.spec
        return dict(variant=s.vc, solver=s.vc_solver, exclude=s.vc_exclude,
                    boundary=s.vc_boundary)


def _first_order_pbg(c):
    c.G, c.report = c.vc_solve(c.system(c.G, c.dx, c.spec.vc),
                               **c.options())


def _first_order_ppg1(c):
    # (5.16) is (5.18) with the master weights only
    c.Gt, c.report = c.vc_solve(c.system(c.Gt, c.dx_t, c.spec.vc),
                                **c.options())


def _first_order_ppg2(c):  # (5.17), its own sparse system
    warnings.warn(
        "VC PPG2 passes the patch test but is unstable here: "
        "its tangent has eigenvalues with negative real part "
        "(e.g. 4 on a regular 20x10 block) and it does not "
        "converge on a manufactured solution; prefer PPG1")
    s, p = c.spec, c.particles
    Gm, c.report = petrov.ppg2_vc_correction(
        c.Gt[:, 0], p.volumes, c.families, c.area, c.phi(s.vc),
        exclude=s.vc_exclude)
    c.Gt[:, 0] = Gm


def _second_order_pbg(c):
    # V4-type functions keep the trial's quadratic consistency
    s, p = c.spec, c.particles
    c.G, c.report = vc2_correction(
        c.system(c.G, c.dx, s.vc), p.area_moments(), exclude=s.vc_exclude,
        boundary=s.vc_boundary)


def _second_order_ppg1(c):
    # corrects the test functions only: V1 functions (VC2PPG V1s U2)
    warnings.warn(
        "VC2 PPG1 (VC2PPG V1 U2) passes the quadratic patch "
        "test but is unstable here: its free tangent has "
        "eigenvalues with negative real part (40 on a regular "
        "20x10 block, 214 distorted) and it does not converge "
        "on a manufactured solution; prefer PBG's VC2")
    s, p = c.spec, c.particles
    c.Gt, c.report = vc2_correction(
        c.system(c.Gt, c.dx_t, "V1"), p.area_moments(),
        exclude=s.vc_exclude, boundary=s.vc_boundary, method="PPG1")


#: VC corrections of the padded pipeline, ``(method, order)`` ->
#: ``f(context)`` updating ``context.G`` (PBG) or ``context.Gt`` (PPG) and
#: ``context.report``; order 1 is every first-order variant V1–V5, order 2
#: is ``vc="VC2"``
CORRECTIONS = {
    ("PBG", 1): _first_order_pbg,
    ("PPG1", 1): _first_order_ppg1,
    ("PPG2", 1): _first_order_ppg2,
    ("PBG", 2): _second_order_pbg,
    ("PPG1", 2): _second_order_ppg1,
}


def surface_of(particles):
    """The area vectors over the true surface (zero on an FE–PG
    interface), or ``None`` for particles without a mesh."""
    return (particles.surface_area_vectors() if particles.mesh is not None
            else None)


def area_vectors_of(particles, area_vectors):
    """``area_vectors`` (default: the particles' FE-consistent ones) as a
    checked ``(dim, np)`` array."""
    x = particles.x
    if area_vectors is None:
        area_vectors = particles.area_vectors()
    area_vectors = np.asarray(area_vectors, dtype=float)
    if area_vectors.shape != x.shape:
        raise ValueError("area_vectors must have shape {}, got {}"
                         .format(x.shape, area_vectors.shape))
    bad = np.flatnonzero(~np.all(np.isfinite(area_vectors), axis=0))
    if len(bad):
        raise ValueError("area_vectors of {} particles are not finite "
                         "(first: {}, area vector {})".format(
                             len(bad), describe_particle(bad[0], x[:, bad[0]]),
                             area_vectors[:, bad[0]].tolist()))
    return area_vectors


def make_families(particles, spec, distributed=None):
    """Stage 1: the spec's families (its rule applied; PPG's made
    pairwise unless a partition made them), checked for the members the
    shape functions and corrections need."""
    fam = spec.family_rule.build(particles)
    if spec.ppg and distributed is None:  # a partition's come complete
        fam = petrov.pairwise(fam)
    check_family_sizes(particles, fam, spec)
    return fam


def check_family_sizes(p, fam, spec):
    """Raise :class:`~skfem_pg.errors.FamilyError` naming a particle whose
    family is too small for the spec's parts
    (:meth:`BasisSpec.min_members`: linear Taylor expansions need ``d``
    others, WTE2 ``d + d(d+1)/2``; MLS1 at the master (VC) ``d + 1``,
    second-order corrections and WLS2 a quadratic basis and a constant)."""
    if fam.n_particles != p.n:
        raise FamilyError("families refer to {} particles, the particle "
                          "set has {}".format(fam.n_particles, p.n))
    inactive = ~p.active[fam.members]
    if np.any(inactive):
        q = fam.members[np.nonzero(inactive)[0][0]]
        raise FamilyError("{} has zero volume but is a family member"
                          .format(describe_particle(q, p.x[:, q])))
    families_mod.check_supports(p, fam, spec.min_members(p.dim), "{}{}".format(
        spec.shape, " with VC correction" if spec.vc else ""))


def trial_gradients(particles, fam, spec, timings):
    """Stage 2: the shape functions' derivatives, bond-corrected if the
    spec says so."""
    t0 = time.perf_counter()
    G = GRADIENTS[spec.shape](particles.x, particles.volumes, fam,
                              n=spec.weight_exponent)
    timings["gradients"] = timings.get("gradients", 0.0) + (
        time.perf_counter() - t0)
    if spec.bond:
        t0 = time.perf_counter()
        G = bond_correction(G, particles.x, fam)
        timings["bond"] = timings.get("bond", 0.0) + (
            time.perf_counter() - t0)
    return G


def _what(spec):
    if spec.vc is None:
        return "{} {}".format(spec.method, spec.shape)
    return "VC {} ({}{})".format(
        spec.vc, spec.method, "" if spec.vc_boundary == "min-norm"
        else ", boundary " + spec.vc_boundary)


def _padded(particles, fam, spec, area_vectors, vc_solve, timings,
            moments=None):
    x, V = particles.x, particles.volumes
    extra = {}
    if spec.family_quadrature == "moments":
        t0 = time.perf_counter()
        G, dx, *more = moment_quadrature(particles, fam,
                                         n=spec.weight_exponent,
                                         moments=moments)
        extra = dict(zip(("values", "points", "master_gradients"), more))
        timings["gradients"] = time.perf_counter() - t0
    else:
        G = trial_gradients(particles, fam, spec, timings)
    Gt = dx_t = None
    if spec.ppg:
        dx = petrov.quadrature_weights(V, fam)
        Gt = np.zeros_like(G)
        Gt[:, 0] = TEST_GRADIENTS[spec.test_shape](particles, fam, G, spec)
        dx_t = np.zeros(fam.padded()[0].shape)  # the masters' weights only
        dx_t[:, 0] = V[fam.masters]
    elif not extra:
        dx = weight_rule(spec.weights)(V, fam)
    report = None
    first = G[:, 0].copy() if extra else None
    if spec.vc is not None:
        t0 = time.perf_counter()
        c = _Context(particles, spec, fam, G, dx, Gt, dx_t,
                     area_vectors_of(particles, area_vectors), vc_solve)
        CORRECTIONS[spec.method, 2 if spec.vc == "VC2" else 1](c)
        G, Gt, report = c.G, c.Gt, c.report
        timings["vc"] = time.perf_counter() - t0
    check_correction(Gt if spec.ppg else G, x, fam, report,
                     spec.vc_tolerance, what=_what(spec))
    if spec.ppg:  # the trial derivatives too
        check_correction(G, x, fam, None, what=spec.shape + " trial")
    if extra and spec.vc is not None:
        # the correction moves the masters' derivatives with the points'
        # (V3: the same α^k φ^{ki} at every point of family k)
        extra["master_gradients"] = extra["master_gradients"] + (
            G[:, 0] - first)
    return BasisArrays(fam, dx, G=G, vc_report=report, timings=timings,
                       test_master=None if Gt is None else Gt[:, 0],
                       **extra)


def _grouped(particles, fam, spec, area_vectors, vc_solve, timings):
    """PBG with MTE1/WTE1 derivatives, bond and V3/V5 correction, one size
    group at a time: work and storage :math:`\\propto \\sum_k m_k^2`
    instead of :math:`n_f m_{max}^2`; the kernels are the padded ones, run
    on each group's own families."""
    x, V = particles.x, particles.volumes
    L = fam.groups()
    subs = [L.subset(g) for g in L]
    Gs = [trial_gradients(particles, f, spec, timings) for f in subs]
    weigh = weight_rule(spec.weights)
    dxs = [weigh(V, f) for f in subs]
    flat = np.empty(L.n_points)
    for g, d in zip(L, dxs):
        flat[g.flat] = d
    report = None
    if spec.vc is not None:
        t0 = time.perf_counter()
        area = area_vectors_of(particles, area_vectors)
        phis = [correction_functions(spec.vc, x, V, f,
                                     n=spec.weight_exponent) for f in subs]
        Gs, report = vc_solve(
            VCSystem(Gs, dxs, x, V, subs, area, phis, surface_of(particles),
                     [g.families for g in L]),
            variant=spec.vc, solver=spec.vc_solver,
            boundary=spec.vc_boundary)
        timings["vc"] = time.perf_counter() - t0
    check_correction(Gs, x, subs, report, spec.vc_tolerance,
                     what=_what(spec))
    return BasisArrays(fam, L.flat_to_padded(flat), G_groups=Gs,
                       vc_report=report, timings=timings)


def build(particles, spec, area_vectors=None, distributed=None):
    """Run the stages of ``spec`` on ``particles``; ``distributed`` (a
    :class:`~skfem_pg.distributed.Partition`) supplies the VC solve of all
    ranks.  Returns :class:`BasisArrays`."""
    if distributed is not None:
        spec.require("mpi", "a distributed basis")
    timings = {}
    t0 = time.perf_counter()
    fam = make_families(particles, spec, distributed)
    timings["families"] = time.perf_counter() - t0
    if spec.vc_solver == "local":  # no global system, on ranks neither
        vc_solve = (local_vc.local_solver(particles) if distributed is None
                    else distributed.local_vc_solver())
    else:
        vc_solve = (vc_correction if distributed is None
                    else distributed.vc_correction)
    if spec.grouped:
        return _grouped(particles, fam, spec, area_vectors, vc_solve,
                        timings)
    moments = None  # a rank's particles have no mesh: the partition's
    if distributed is not None and spec.family_quadrature == "moments":
        moments = distributed.hat_moments(local=True)
    return _padded(particles, fam, spec, area_vectors, vc_solve, timings,
                   moments)


__all__ = ["BasisArrays", "BasisSpec", "CORRECTIONS", "METHODS", "surface_of",
           "TEST_GRADIENTS", "VC_VARIANTS", "area_vectors_of", "build",
           "check_family_sizes", "make_families",
           "trial_gradients"]
