r"""The parts a :class:`~skfem_pg.FamilyBasis` is made of, and what each
supports.

scikit-fem makes a basis of parts (``CellBasis(mesh, element, mapping,
quadrature)``); a family basis has five, held by
:class:`~skfem_pg.discretization.builder.BasisSpec`:

* :class:`FamilyRule` — which particles form each family (``families``);
* :class:`Shape` — the Taylor expansion (3.32) and its bond weights
  (3.33) (``shape``, ``weight_exponent``);
* :class:`Quadrature` — where a family integrates, with which weights
  (``family_quadrature``, ``weights``);
* :class:`Correction` — bond (5.55) and VC corrections (``bond``,
  ``vc``, ``vc_boundary``, ``vc_solver``, ``vc_exclude``,
  ``vc_tolerance``);
* :class:`Method` — Bubnov– or Petrov–Galerkin and the test derivatives
  (``method``, ``test_shape``, ``lme_mu``).

A part checks its own values when it is made; :meth:`Part.conflict` says
what it needs of the others and :meth:`Part.refusal` which
:data:`CAPABILITIES` it does not support.  A spec supports a capability if
none of its parts refuses it (:func:`refusal`): this module is the one
place where the combinations of options are decided — the builder's hot
path, :meth:`~skfem_pg.distributed.Partition.basis`, the crack-aware
models, the updated Lagrangian frame and the names of Table 7.1
(:mod:`skfem_pg.naming`) ask it.

>>> ppg2 = Parts(correction=Correction(vc="V3"), method=Method("PPG2"))
>>> print(refusal("mpi", ppg2))
method='PPG2' on MPI: this version distributes PBG and PPG1
>>> print(refusal("grouped", Parts()))
None
"""
import dataclasses
from typing import Optional

import numpy as np

from ..errors import FamilyError
from .vc.boundary import BOUNDARY_VARIANTS

#: what a basis may be asked to do, and who asks
CAPABILITIES = {
    "grouped": "the stages run per family-size group, without padding "
               "(builder)",
    "mpi": "a rank's part of a distributed basis (Partition.basis)",
    "local_vc": "vc_solver='local' (skfem_pg.discretization.vc.local)",
    "crack_rebuild": "crack-aware families rebuilt from the intact cells "
                     "(skfem_pg.formulations.crack_aware)",
    "updated_lagrangian": "rebuilt on moved particles, the history "
                          "carried between members (UpdatedLagrangian)",
}

METHODS = ("PBG", "PPG1", "PPG2")
#: the VC variants each kind of method accepts
#: (:func:`~skfem_pg.discretization.vc.first_order.correction_functions`)
VC_VARIANTS = {"PBG": ("V2", "V3", "V4", "V5", "VC2"),
               "PPG": ("V1", "V2", "V3", "V4", "VC2")}
#: the VC system's boundary variants (:mod:`~skfem_pg.discretization.vc.boundary`)
BOUNDARIES = BOUNDARY_VARIANTS
#: keyword of :class:`~skfem_pg.FamilyBasis` -> (the part, its field)
FIELDS = {"shape": ("shape", "name"),
          "weight_exponent": ("shape", "weight_exponent"),
          "weights": ("quadrature", "weights"),
          "family_quadrature": ("quadrature", "rule"),
          "bond": ("correction", "bond"), "vc": ("correction", "vc"),
          "vc_boundary": ("correction", "boundary"),
          "vc_solver": ("correction", "solver"),
          "vc_exclude": ("correction", "exclude"),
          "vc_tolerance": ("correction", "tolerance"),
          "method": ("method", "name"),
          "test_shape": ("method", "test_shape"),
          "lme_mu": ("method", "lme_mu")}


class Part:
    """What every part answers; a part is a frozen record."""

    def conflict(self, parts) -> Optional[str]:
        """Why this part cannot work with the other ``parts``, or
        ``None``."""
        return None

    def refusal(self, capability, parts) -> Optional[str]:
        """Why this part does not support ``capability`` (a key of
        :data:`CAPABILITIES`) together with ``parts``, or ``None``."""
        return None

    def min_members(self, dim) -> int:
        """The smallest family (master included) this part works on."""
        return 0


class NotBuilt(str):
    """A :meth:`Part.conflict` answer naming a combination that could be
    built but is not (raised as ``NotImplementedError``; a plain string
    is a contradiction, raised as ``ValueError``)."""


@dataclasses.dataclass(frozen=True)
class FamilyRule(Part):
    """Which particles form each family: a rule of
    :data:`~skfem_pg.discretization.families.RULES` with keyword
    ``parameters`` (sorted ``(key, value)`` pairs; the defaults of WTE2
    and of the moment quadrature have some), or given
    :class:`~skfem_pg.Families` (``rule`` is the object).

    Examples
    --------
    >>> FamilyRule("horizon", (("factor", 2.51),)).describe()
    "'horizon' (factor=2.51)"
    >>> FamilyRule("mesh").refusal("mpi", Parts()) is None
    True

    """

    rule: object
    parameters: tuple = ()

    def __post_init__(self):
        from .families import Families
        if isinstance(self.rule, Families):
            if self.parameters:
                raise ValueError("given families take no parameters")
            return
        from .families import RULES
        if self.rule not in RULES:
            raise FamilyError("unknown family rule {!r}: one of {}, or a "
                              "Families object".format(
                                  self.rule, ", ".join(map(repr, RULES))))

    @property
    def given(self):
        """Whether the families were given, not made by a rule."""
        return not isinstance(self.rule, str)

    @property
    def name(self):
        """The rule's name (``"given"`` for given families); a rule with
        parameters is not one the keyword ``families`` names."""
        return "given" if self.given else self.rule

    def describe(self):
        """``'mesh'``, ``'horizon' (factor=2.51, min_size=11)``, ``given
        families``."""
        if self.given:
            return "given families"
        return repr(self.rule) + ("" if not self.parameters else " ({})".format(
            ", ".join("{}={!r}".format(*kv) for kv in self.parameters)))

    def build(self, particles):
        """The families on ``particles``."""
        if self.given:
            return self.rule
        from .families import RULES  # checked in __post_init__
        return RULES[self.rule](particles, **dict(self.parameters))

    def refusal(self, capability, parts):
        if capability == "mpi" and not self.given and \
                self.rule not in ("mesh", "nearest"):
            return ("families={} on MPI: a rank builds its families from "
                    "the mesh (rule 'mesh'), its nearest particles (rule "
                    "'nearest') or takes them given".format(self.describe()))
        if capability == "crack_rebuild" and (
                self.given or self.rule not in ("mesh", "nearest")
                or (self.rule == "mesh" and self.parameters)):
            return ("crack-aware families rebuild the families from the "
                    "intact cells: the basis needs the 'mesh' or the "
                    "'nearest' family rule, got {}".format(self.describe()))
        return None


@dataclasses.dataclass(frozen=True)
class Shape(Part):
    """The shape functions' derivatives: ``"MTE1"`` (moving Taylor
    expansion), ``"WTE1"`` (static, classical correspondence) or
    ``"WTE2"`` (second-order static), with bond weights
    :math:`\\omega = 1/|\\Delta X|^{2n}`, ``n = weight_exponent``.

    Examples
    --------
    >>> Shape("WTE2").min_members(2), Shape("MTE1").min_members(3)
    (6, 4)

    """

    name: str = "MTE1"
    weight_exponent: float = 1.0

    def __post_init__(self):
        from .shape import GRADIENTS
        if self.name not in GRADIENTS:
            raise ValueError("unknown shape functions {!r}; available: {}"
                             .format(self.name, ", ".join(GRADIENTS)))
        n = self.weight_exponent
        if isinstance(n, bool) or not isinstance(
                n, (int, float, np.number)) or not np.isfinite(n) or n < 0:
            raise ValueError("weight_exponent must be a number >= 0, got "
                             "{!r}".format(n))

    @property
    def linear(self):
        return self.name in ("MTE1", "WTE1")

    def min_members(self, dim):
        q = dim + dim * (dim + 1) // 2  # quadratic basis without constant
        return 1 + q if self.name == "WTE2" else dim + 1

    def refusal(self, capability, parts):
        if capability in ("grouped", "local_vc") and not self.linear:
            return "shape={!r} (the linear bases MTE1 and WTE1 only)".format(
                self.name)
        if capability == "mpi" and not self.linear and \
                parts.quadrature.rule != "moments":
            return ("shape={!r} on MPI: this version distributes the linear "
                    "bases MTE1 and WTE1, and WTE2 with family_quadrature="
                    "'moments'".format(self.name))
        return None


@dataclasses.dataclass(frozen=True)
class Quadrature(Part):
    """Where a family integrates: at its members (``rule="members"``, the
    thesis' (4.25)) with PBG weights ``"volume"`` (4.30) or
    ``"uniform"`` (PPG integrates with the member volumes), or at the
    moment-matched points (``rule="moments"``,
    :mod:`~skfem_pg.discretization.moment_quadrature`), which make their
    own weights.

    Examples
    --------
    >>> q = Quadrature(rule="moments")
    >>> print(q.conflict(Parts(quadrature=q)))  # MTE1 by default
    family_quadrature='moments' integrates the quadratic fit WTE2 of PBG: pass shape='WTE2' (method='PBG'), got shape='MTE1', method='PBG'

    """

    weights: str = "volume"
    rule: str = "members"

    def __post_init__(self):
        if self.rule not in ("members", "moments"):
            raise ValueError("family_quadrature must be 'members' or "
                             "'moments', got {!r}".format(self.rule))
        from .quadrature import weight_rule
        weight_rule(self.weights)  # a known rule, or ValueError naming it

    def conflict(self, parts):
        if self.rule != "moments":
            return None
        if parts.shape.name != "WTE2" or parts.method.name != "PBG":
            return ("family_quadrature='moments' integrates the quadratic "
                    "fit WTE2 of PBG: pass shape='WTE2' (method='PBG'), got "
                    "shape={!r}, method={!r}".format(parts.shape.name,
                                                     parts.method.name))
        c = parts.correction
        if c.vc not in (None, "V3") or c.boundary != "min-norm" \
                or c.exclude is not None:
            return NotBuilt(
                "family_quadrature='moments' is built with the first-order "
                "VC V3 (or none), vc_boundary='min-norm' and no vc_exclude; "
                "got vc={!r}, vc_boundary={!r}".format(c.vc, c.boundary))
        return None

    def refusal(self, capability, parts):
        if capability == "grouped" and self.rule != "members":
            return "family_quadrature='moments'"
        if capability == "updated_lagrangian" and self.rule != "members":
            return ("UL with family_quadrature={!r}: the history is carried "
                    "over between the members of old and new families, and "
                    "the moment quadrature's points are not members (they "
                    "move with the hat functions' principal axes)".format(
                        self.rule))
        return None


@dataclasses.dataclass(frozen=True)
class Correction(Part):
    """The corrections of the derivatives: the bond correction (5.55) and
    a variationally consistent one (``vc``: ``"V1"``…``"V5"``,
    ``"VC2"`` or ``None``) with the VC system's ``boundary``
    (:mod:`~skfem_pg.discretization.vc.boundary`), ``solver``, the
    particles it ``exclude``\\ s and the residual ``tolerance`` it
    accepts.

    Examples
    --------
    >>> c = Correction(bond=False, vc="V5")
    >>> print(c.conflict(Parts(correction=c)))
    vc='V5' keeps the bond mapping and needs bond=True; use vc='V3' without bond correction

    """

    bond: bool = True
    vc: Optional[str] = "V5"
    boundary: str = "min-norm"
    solver: str = "auto"
    exclude: object = None
    tolerance: Optional[float] = 1e-8

    def __post_init__(self):
        if self.vc not in (None, "V1", "V2", "V3", "V4", "V5", "VC2"):
            raise ValueError("unknown VC correction vc={!r}: V1 ... V5, "
                             "VC2 or None".format(self.vc))
        if self.boundary not in BOUNDARIES:
            raise ValueError("VC boundary variant {!r} is not available: use "
                             "one of {}".format(self.boundary,
                                                ", ".join(BOUNDARIES)))
        t = self.tolerance
        if t is not None and not (
                isinstance(t, (int, float, np.number)) and np.isfinite(t)
                and t > 0):
            raise ValueError(
                "vc_tolerance must be a positive number (the largest VC "
                "constraint residual accepted, default 1e-8) or None (keep "
                "any correction, with a warning), got {!r}".format(t))

    def min_members(self, dim):
        q = dim + dim * (dim + 1) // 2
        if self.vc in ("V2", "V4", "VC2"):
            return 2 + q  # WLS2 with a constant term
        return dim + 2 if self.vc is not None else dim + 1

    def conflict(self, parts):
        shape, method = parts.shape.name, parts.method.name
        if self.bond and shape == "WTE2":
            return ("the bond correction (5.55) is for linear bases; use "
                    "bond=False with shape='WTE2'")
        if self.vc == "VC2" and (shape != "WTE2" or method == "PPG2"):
            return ("vc='VC2' (second-order VC) needs the quadratic trial "
                    "basis: shape='WTE2', method='PBG' or 'PPG1'")
        allowed = VC_VARIANTS["PBG" if method == "PBG" else "PPG"]
        if self.vc is not None and self.vc not in allowed:
            return ("vc={!r} is not available for {}: use one of {} or None"
                    .format(self.vc, method, ", ".join(allowed)))
        if self.vc == "V5" and not self.bond:
            return ("vc='V5' keeps the bond mapping and needs bond=True; use "
                    "vc='V3' without bond correction")
        if self.boundary != "min-norm" and (
                self.vc is None or method == "PPG2"
                or (self.vc == "VC2" and self.boundary != "s")):
            return NotBuilt(
                "vc_boundary={!r} is implemented for the first-order VC of "
                "PBG and PPG1 (vc V1, V3, V4, V5) and, 's' only, for VC2; "
                "not for {} vc={}".format(self.boundary, method, self.vc))
        if self.solver == "local":
            why = refusal("local_vc", parts)
            if why is not None:
                return NotBuilt("vc_solver='local' "
                                "(skfem_pg.discretization.vc.local): "
                                + why)
        return None

    def refusal(self, capability, parts):
        if capability in ("grouped", "mpi", "local_vc"):
            vcs = (("V3", "V5") if capability == "local_vc"
                   else (None, "V3", "V5"))
            bounds = (("min-norm",) if capability == "local_vc"
                      else ("min-norm", "p"))
            if self.vc not in vcs:
                return "vc={!r} (takes {})".format(self.vc, ", ".join(
                    map(str, vcs)))
            if self.boundary not in bounds:
                return "vc_boundary={!r} (takes {})".format(
                    self.boundary, ", ".join(map(repr, bounds)))
            if self.exclude is not None:
                return "vc_exclude (the solve enforces every constraint)"
        return None


@dataclasses.dataclass(frozen=True)
class Method(Part):
    """``"PBG"`` (Bubnov–Galerkin) or ``"PPG1"`` / ``"PPG2"``
    (Petrov–Galerkin (4.21), (4.22)) with its test derivatives at the
    masters (``test_shape``; ``lme_mu``: the locality of ``"LME"``).

    Examples
    --------
    >>> print(Method("PPG2").refusal("updated_lagrangian", Parts()))
    UL is built for PBG, not method='PPG2'

    """

    name: str = "PBG"
    test_shape: str = "master"
    lme_mu: float = 1.8

    def __post_init__(self):
        if self.name not in METHODS:
            raise NotImplementedError(
                "method {!r} is not available; this version implements {}"
                .format(self.name, ", ".join(METHODS)))
        from .builder import TEST_GRADIENTS  # the registered test rules
        if self.test_shape not in TEST_GRADIENTS:
            raise ValueError("test_shape must be one of {}, got {!r}".format(
                ", ".join(TEST_GRADIENTS), self.test_shape))
        if self.test_shape != "master" and self.name == "PBG":
            raise ValueError("test_shape={!r} is a Petrov–Galerkin option: "
                             "use method='PPG1' or 'PPG2'".format(
                                 self.test_shape))

    @property
    def petrov(self):
        return self.name != "PBG"

    def min_members(self, dim):
        q = dim + dim * (dim + 1) // 2
        return 2 + q if self.test_shape == "WLS2" else 0

    def refusal(self, capability, parts):
        if capability == "updated_lagrangian" and self.name != "PBG":
            return "UL is built for PBG, not method={!r}".format(self.name)
        if capability in ("grouped", "local_vc") and self.name != "PBG":
            return "method={!r} (PBG only)".format(self.name)
        if capability == "mpi":
            if self.name not in ("PBG", "PPG1"):
                return ("method={!r} on MPI: this version distributes PBG "
                        "and PPG1".format(self.name))
            if self.name == "PPG1" and (
                    self.test_shape != "master"
                    or parts.correction.boundary != "min-norm"
                    or parts.correction.vc not in (None, "V3")):
                return ("PPG1 on MPI takes vc V3 or None, vc_boundary="
                        "'min-norm' and test_shape='master' (its VC solve "
                        "and test derivatives span the ranks)")
        return None


@dataclasses.dataclass(frozen=True)
class Parts:
    """The five parts, without the field's number of components.

    Examples
    --------
    >>> [type(p).__name__ for p in Parts()]
    ['Shape', 'Quadrature', 'Correction', 'Method', 'FamilyRule']

    """

    family_rule: FamilyRule = dataclasses.field(
        default_factory=lambda: FamilyRule("mesh"))
    shape: Shape = dataclasses.field(default_factory=Shape)
    quadrature: Quadrature = dataclasses.field(default_factory=Quadrature)
    correction: Correction = dataclasses.field(default_factory=Correction)
    method: Method = dataclasses.field(default_factory=Method)

    def __iter__(self):  # the family rule last: its defaults follow
        return iter((self.shape, self.quadrature, self.correction,
                     self.method, self.family_rule))


def from_keywords(keywords, family_rule=None):
    """The :class:`Parts` of :class:`~skfem_pg.FamilyBasis` keywords
    (:data:`FIELDS`; a part's fields not among them keep its defaults;
    other keys are ignored) with ``family_rule`` (default the mesh rule).

    >>> from_keywords({"shape": "WTE2", "bond": False}).correction.bond
    False
    """
    fields = {}
    for key, value in keywords.items():
        if key in FIELDS:
            part, field = FIELDS[key]
            fields.setdefault(part, {})[field] = value
    return Parts(family_rule=family_rule or FamilyRule("mesh"), **{
        part: kind(**fields.get(part, {})) for part, kind in (
            ("shape", Shape), ("quadrature", Quadrature),
            ("correction", Correction), ("method", Method))})


def conflict(parts):
    """The first of the parts' conflicts: ``None``, a string
    (``ValueError``) or :class:`NotBuilt` (``NotImplementedError``)."""
    return next((why for why in (p.conflict(parts) for p in parts)
                 if why is not None), None)


def check(parts):
    """Raise for the first conflict of ``parts`` (:func:`conflict`)."""
    why = conflict(parts)
    if why is not None:
        raise (NotImplementedError if isinstance(why, NotBuilt)
               else ValueError)(str(why))


def refusal(capability, parts):
    """Why ``parts`` do not support ``capability``, or ``None`` (the
    first part that refuses it says why)."""
    if capability not in CAPABILITIES:
        raise ValueError("unknown capability {!r}: one of {}".format(
            capability, ", ".join(CAPABILITIES)))
    return next((why for why in (p.refusal(capability, parts)
                                 for p in parts) if why is not None), None)


def require(capability, parts, what=None):
    """Raise ``NotImplementedError`` naming the option if ``parts`` do not
    support ``capability``; ``what`` prefixes the message."""
    why = refusal(capability, parts)
    if why is not None:
        raise NotImplementedError(
            "{}: {}".format(what, why) if what else why)


def min_members(parts, dim):
    """The smallest family the parts work on (the master included)."""
    return max(p.min_members(dim) for p in parts)


__all__ = ["BOUNDARIES", "CAPABILITIES", "Correction", "FamilyRule",
           "FIELDS", "METHODS", "Method", "NotBuilt", "Part", "Parts",
           "Quadrature", "Shape", "VC_VARIANTS",
           "check", "conflict", "from_keywords", "min_members", "refusal", "require"]
