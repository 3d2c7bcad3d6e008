r"""Thesis names of formulations (Table 7.1) <-> ``FamilyBasis`` options.

A name reads ``[VC|VC2][BC]{PBG|PPG|PPG1|PPG2} [V1..V5][p|s|sn|m]
{formulation} [TL|UL] [noBC] [kNN|meshU] [MQ]``, e.g.
``"VCBCPBG V5sn Unl TL"``, or
``FEM {T1|Q1|O1|H1|Q1P0|H1P0|T2|Q2|O2|H2}`` for the FE comparators:

==========  ==============================================================
``VC``      first-order variational consistency, correction functions
            ``V1``…``V5`` (default V5 for PBG, V3 for PPG); ``VC2``: the
            second-order correction (PBG: V4 functions, PPG1: V1)
``BC``      bond correction (5.55) — **the default of every first-order
            formulation** (U1, Unl) in Table 7.1, written or not; the
            package's token ``noBC`` at the end switches it off
``PBG``     Bubnov–Galerkin; ``PPG`` = ``PPG1`` Petrov–Galerkin (4.21),
            ``PPG2`` (4.22)
``p s sn``  boundary conditions of the VC system
            (:mod:`skfem_pg.discretization.vc.boundary`); **default** ``sn``,
            as in Table 7.1.  ``m`` (a package extension) is the package's
            minimum-norm solve
``U1``      WTE1 (classical correspondence), ``Unl`` MTE1, ``U2`` WTE2
``UnlP0``   mixed (thesis 6.2): ``UnlP0``, ``IUnlP0``, ``Unl+P1C`` on MTE1
            displacements, ``U2P1``, ``U2P1C`` on WTE2; stabilized (6.3):
            ``U1SUnl`` (WTE1 at the masters, stabilized on its MTE1
            basis), ``U1SIG`` on WTE1 without bond correction
``TL``      total Lagrangian reference frame (the default; ``UL``, updated
            Lagrange)
``kNN``     a package token: the ``kNN`` recipe of
            :mod:`skfem_pg.discretization.recipes` (families of the 10
            nearest particles, pairwise; uniform quadrature weights
            :math:`V^k/n_k`; unit bond weights) instead of the thesis'
            mesh families, volume weights (4.30) and
            :math:`\omega = 1/|\Delta X|^2` — the keyword API's default
            for PBG Unl on 3-D tetrahedra
``meshU``   a package token: the ``meshU`` recipe (the thesis' mesh
            families with uniform quadrature weights and unit bond
            weights) — the keyword API's default for PBG Unl on 2-D
            triangles
``MQ``      a package token: the moment-matched family quadrature
            (:mod:`skfem_pg.discretization.moment_quadrature`) of U2
            instead of the members
``k=v``     package options at the end, for what Table 7.1 has no word
            for: ``families=`` a rule (``nearest``, ``horizon``,
            ``mesh``) or ``given`` (pass ``families=`` to
            :meth:`~skfem_pg.FamilyBasis.from_name`), ``weights=``
            ``uniform`` / ``volume``, ``n=`` the bond weight exponent,
            ``test=`` PPG's test derivatives, ``lme_mu=``, ``solver=`` the
            VC solve, ``exclude=given`` (pass ``vc_exclude=``)
==========  ==============================================================

So ``"VCPBG Unl"`` means ``"VCBCPBG V5sn Unl TL"`` and ``"PBG Unl"`` means
``"BCPBG Unl TL"``.  The keyword API of :class:`~skfem_pg.FamilyBasis` has
its own, measured defaults: the bond correction as there (on for MTE1) and
the minimum-norm VC solve (``vc_boundary="min-norm"``), which passes the
same patch tests and is less erratic than ``sn`` on 3-D tetrahedra
(``benchmarks/README.md``); ``FamilyBasis.from_name(p, name,
vc_boundary="min-norm")`` or
the suffix ``m`` gets it for a thesis name.

:func:`name_of` prints every option of a basis this way, so that the name
of any basis gives the basis back:

>>> import skfem as fem, skfem_pg as pg
>>> p = pg.Particles.from_mesh(fem.MeshQuad().refined(2))
>>> pg.FamilyBasis(p, "horizon", dim=2).name
'VCBCPBG V5m Unl TL families=horizon'
>>> pg.FamilyBasis(p, "nearest", dim=2, weights="volume").name
'VCBCPBG V5m Unl TL families=nearest n=0'

Every formulation of Table 7.1 parses: :func:`parse` gives the options of
its *displacement* basis (MTE1 for ``UnlP0``, WTE2 for ``U2P1``, ...) and
:func:`formulation_of` the formulation token, which
:func:`skfem_pg.formulations.by_name.model_for` turns into a model (and
which raises ``NotImplementedError`` for a combination that is not
built, naming it).
"""
import re

from . import registry
from .discretization import parts, recipes

# the formulation tokens (their shape functions, kinds, the UL frame) and
# the FE comparators are those of skfem_pg.registry
_NAME = re.compile(r"^(?P<vc>VC2|VC)?(?P<bc>BC)?(?P<method>PBG|PPG1|PPG2|PPG)"
                   r"(?:\s+(?P<variant>V[1-5])?(?P<boundary>sn|s|p|m)?)?"
                   r"\s+(?P<form>\S+)(?:\s+(?P<frame>TL|UL))?"
                   r"(?:\s+(?P<nobc>noBC))?(?:\s+(?P<recipe>kNN|meshU))?"
                   r"(?:\s+(?P<quad>MQ))?"
                   r"(?P<options>(?:\s+[a-z_]+=\S+)*)$")
_BOUNDARY = {"p": "p", "s": "s", "sn": "sn", "m": "min-norm"}
#: what the options ``families=given`` and ``exclude=given`` stand for:
#: arrays the name cannot hold, passed beside it
GIVEN = "given"
#: name option -> (keyword, conversion)
_OPTIONS = {"families": ("families", str), "weights": ("weights", str),
            "n": ("weight_exponent", float), "test": ("test_shape", str),
            "lme_mu": ("lme_mu", float), "solver": ("vc_solver", str),
            "exclude": ("vc_exclude", str)}


def fe_method(name):
    """``"Q1P0"`` for ``"FEM Q1P0"`` (or ``"Q1P0"``); ``None`` if ``name``
    names no FE comparator."""
    parts = name.split()
    if parts[:1] == ["FEM"]:
        if len(parts) == 2 and parts[1] in registry.fe_names():
            return parts[1]
        raise ValueError("unknown FE comparator {!r}: FEM {}".format(
            name, " / ".join(registry.fe_names())))
    return parts[0] if len(parts) == 1 and parts[0] in registry.fe_names() \
        else None


def frame_of(name):
    """``"UL"`` or ``"TL"`` (the default) of a thesis name; ``"TL"`` for
    FE names."""
    if fe_method(name) is not None:
        return "TL"
    m = _NAME.match(name.strip())
    return (m.group("frame") if m is not None else None) or "TL"


def formulation_of(name):
    """The formulation token of a thesis name (``"UnlP0"`` for
    ``"VCBCPBG V5sn UnlP0 TL"``); FE names give their method
    (``"H1P0"`` for ``"FEM H1P0"``)."""
    fe = fe_method(name)
    if fe is not None:
        return fe
    parse(name)  # raises for what cannot be read
    return _NAME.match(name.strip()).group("form")


def parse(name):
    """``(kwargs, notes)`` for the displacement
    :class:`~skfem_pg.FamilyBasis` of a thesis name, with Table 7.1's
    defaults; raises ``ValueError`` naming what is not understood and
    ``NotImplementedError`` for combinations that are not built (UL for
    a formulation registered without it, :mod:`skfem_pg.registry`, or
    for other methods than PBG; see the checks below)."""
    if fe_method(name) is not None:
        raise ValueError("{!r} is an FE comparator, not a family basis: "
                         "use Scene.solve({!r})".format(name, name))
    m = _NAME.match(name.strip())
    if m is None:
        raise ValueError("cannot read the formulation name {!r}; expected "
                         "e.g. 'VCBCPBG V5sn Unl TL', 'PPG Unl' or 'FEM Q1'"
                         .format(name))
    g = m.groupdict()
    form = g["form"]
    try:
        record = registry.formulation(form)
    except ValueError as err:
        raise ValueError("{} (in {!r})".format(err, name)) from None
    if g["frame"] == "UL" and not record.updated_lagrangian:
        raise NotImplementedError(
            "{!r}: the updated Lagrangian frame (UL) is built for the "
            "displacement formulations {} of PBG".format(
                name, ", ".join(registry.tokens(updated_lagrangian=True))))
    method = {"PPG": "PPG1"}.get(g["method"], g["method"])
    first_order, shape = record.first_order, record.shape
    if g["bc"] and not first_order:
        raise ValueError("{!r}: the bond correction is for first-order "
                         "formulations ({}), not {}".format(
                             name, ", ".join(registry.tokens(
                                 first_order=True)), form))
    if g["bc"] and record.master_only:
        raise ValueError("{!r}: {} evaluates its gradient at the master "
                         "only, where the bond correction has no bond; "
                         "drop 'BC'".format(name, form))
    if g["bc"] and g["nobc"]:
        raise ValueError("{!r} asks for BC and noBC".format(name))
    kw = {"shape": shape, "method": method,
          "bond": first_order and not g["nobc"] and not record.master_only}
    if g["recipe"]:
        if method != "PBG" or shape != "MTE1":
            raise ValueError("{!r}: the {} recipe (uniform quadrature "
                             "weights) is for PBG on MTE1 bases".format(
                                 name, g["recipe"]))
        families, weights, exponent = recipes.RECIPES[g["recipe"]]
        kw.update(families=families, weights=weights,
                  weight_exponent=exponent)
    else:  # the thesis' families (WTE2: its horizon) and weights
        if shape != "WTE2":
            kw["families"] = "mesh"
        _, weights, exponent = recipes.RECIPES["mesh"]
        kw.update(weights=weights, weight_exponent=exponent)
    if g["quad"]:  # the rule makes its own weights; WTE2's exponent
        kw.pop("weights")
        kw["family_quadrature"] = "moments"
    notes = []
    kw.update(_options(name, g["options"]))
    if g["vc"] is None:
        if g["variant"] or g["boundary"]:
            raise ValueError("{!r}: a correction variant or boundary variant "
                             "without 'VC'".format(name))
        kw["vc"] = None
        return _checked(name, kw, g["frame"]), notes
    if g["vc"] == "VC2":
        kw["vc"] = "VC2"
        own = "V4" if method == "PBG" else "V1"
        if g["variant"] not in (None, own):
            notes.append("VC2 {} uses the {} correction functions here, not "
                         "{}".format(method, own, g["variant"]))
    else:
        kw["vc"] = g["variant"] or ("V5" if method == "PBG" and kw["bond"]
                                    else "V3")
    kw["vc_boundary"] = _BOUNDARY[g["boundary"] or "sn"]
    return _checked(name, kw, g["frame"]), notes


def _options(name, text):
    """The keywords of the ``k=v`` options at the end of a name."""
    kw = {}
    for item in text.split():
        key, _, value = item.partition("=")
        if key not in _OPTIONS or key in kw:
            raise ValueError("{!r}: {} option {!r}; the options are {}".format(
                name, "a repeated" if key in kw else "an unknown", key,
                ", ".join(k + "=" for k in _OPTIONS)))
        keyword, kind = _OPTIONS[key]
        try:
            kw[keyword] = kind(value)
        except ValueError:
            raise ValueError("{!r}: {}={!r} is not a number".format(
                name, key, value)) from None
    if kw.get("vc_exclude", GIVEN) != GIVEN:
        raise ValueError("{!r}: exclude= takes 'given' (pass the particles "
                         "as vc_exclude=)".format(name))
    return kw


def _checked(name, kw, frame):
    """``kw``, after the parts of :mod:`skfem_pg.discretization.parts`
    have said that they work together (and in the UL frame)."""
    try:  # families are not parts of this check (they may be 'given')
        ps = parts.from_keywords({k: v for k, v in kw.items()
                                  if k != "families"})
        parts.check(ps)
        if frame == "UL":
            parts.require("updated_lagrangian", ps)
    except (ValueError, NotImplementedError) as err:
        raise type(err)("{!r}: {}".format(name, err)) from None
    return kw


def knn_name(name):
    """``name`` with the package token ``kNN`` appended if the recipe
    applies to it (PBG on MTE1: Unl, UnlP0, Unl+P1C, U1SUnl ...), else
    None (PPG, WTE1's U1SIG, WTE2's U2 ...)."""
    try:
        parse(name + " kNN")
    except ValueError:
        return None
    return name + " kNN"


def name_of(basis):
    """The full thesis code of a :class:`~skfem_pg.FamilyBasis` (or its
    :class:`~skfem_pg.discretization.BasisSpec`), e.g.
    ``"VCBCPBG V5m Unl TL"``: every option written, those Table 7.1 has no
    word for as ``k=v`` options, so that :func:`parse` gives the basis
    back (given families and excluded particles are named ``given``)."""
    spec = getattr(basis, "spec", basis)
    vc = spec.vc
    form = {registry.formulation(f).shape: f for f in reversed(
        registry.tokens(kind="displacement"))}[spec.shape]
    first_order = registry.formulation(form).first_order
    prefix = ("VC2" if vc == "VC2" else "VC" if vc else "") + \
        ("BC" if spec.bond else "")
    method = {"PPG1": "PPG"}.get(spec.method, spec.method)
    if vc == "VC2":
        variant = " V4" if spec.method == "PBG" else " V1"
    else:
        variant = " " + vc if vc else ""
    if vc:
        variant += {v: k for k, v in _BOUNDARY.items()}[spec.vc_boundary]
    tail = " noBC" if first_order and not spec.bond else ""
    if spec.recipe in ("kNN", "meshU"):
        tail += " " + spec.recipe
    moments = spec.family_quadrature == "moments"
    if moments:
        tail += " MQ"
    return "{}{}{} {} TL{}{}".format(prefix, method, variant, form, tail,
                                     "".join(" {}={}".format(*kv) for kv in
                                             _options_of(spec, moments)))


def _options_of(spec, moments):
    """The ``(key, value)`` options a name needs beyond its tokens to
    give ``spec`` back (what :func:`parse` does not default to)."""
    rule = spec.family_rule
    if rule.given:
        yield "families", GIVEN
    elif not rule.parameters and spec.recipe not in ("kNN", "meshU") and (
            moments or spec.shape == "WTE2" or rule.rule != "mesh"):
        yield "families", rule.rule  # the defaults have parameters
    if spec.recipe not in ("kNN", "meshU") and not moments:
        w, n = recipes.RECIPES["mesh"][1:]  # the thesis'
        if spec.weights != w:
            yield "weights", spec.weights
        if spec.weight_exponent != n:
            yield "n", "{:g}".format(spec.weight_exponent)
    if spec.test_shape != "master":
        yield "test", spec.test_shape
        if spec.test_shape == "LME" and spec.lme_mu != 1.8:
            yield "lme_mu", "{!r}".format(spec.lme_mu)
    if spec.vc_solver != "auto":
        yield "solver", spec.vc_solver
    if spec.vc_exclude is not None:
        yield "exclude", GIVEN
