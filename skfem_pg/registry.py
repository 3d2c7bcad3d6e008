"""The one registry of PG formulations: each formulation token of a name
(Table 7.1's ``Unl``, ``UnlP0``, ... and any a user adds) with what the
package derives from it.

========================  =====================================================
field                     used by
========================  =====================================================
``shape``                 :func:`skfem_pg.naming.parse`: the shape functions of
                          the displacement basis (``WTE1``, ``MTE1``,
                          ``WTE2``);
                          first order (WTE1, MTE1): the bond correction is the
                          default
``build``                 :func:`skfem_pg.formulations.model_for`:
                          ``build(basis, material, tangent)`` returns the model
                          (:class:`~skfem_pg.formulations.Hyperelastic` or a
                          subclass: ``state``, ``internal_force``, ``tangent``,
                          ``commit``, ``min_J``, ``n_u``; what Newton's method,
                          Newmark and central differences ask of it)
``kind``                  ``"displacement"`` (a basis of this shape is named by
                          it: :func:`skfem_pg.naming.name_of`), ``"mixed"``
                          or ``"stabilized"``
``master_only``           the gradient lives at the master alone: no bond
                          correction (U1SIG)
``updated_lagrangian``    the UL frame is built for it: ``True`` for the
                          package's displacement formulation (the scene
                          builds :class:`~skfem_pg.formulations.
                          UpdatedLagrange`), or a callable
                          ``build_ul(basis, material, every)`` that builds
                          the formulation's own UL model
``distributed``           the distributed Newton solves it
                          (``Scene.solve(..., comm=...)``)
========================  =====================================================

:mod:`skfem_pg.formulations.by_name` registers Table 7.1; a formulation
of one's own is one :func:`register` call, after which names with its
token parse, build and solve (``Scene.solve("VCPBG MyToken")``).  This
module imports nothing of the package, so every layer may read it.

The FE comparators (``T1`` … ``H2``, ``Q1P0``, ``H1P0``) are registered
here too (:func:`fe_method`): the scikit-fem mesh type each runs on, its
scalar element, its Gauss rule and whether it is the mean-dilatation
(P0) variant; :class:`~skfem_pg.scenes.Scene`, the name parser and
``model_for`` read them.
"""
import inspect
import re
from dataclasses import dataclass
from typing import Callable

import skfem as fem

#: the shape functions a formulation's displacement basis may have
SHAPE_FUNCTIONS = ("WTE1", "MTE1", "WTE2")
#: formulation kinds
KINDS = ("displacement", "mixed", "stabilized")


@dataclass(frozen=True)
class Formulation:
    """One registered formulation (see the module docstring)."""
    token: str
    shape: str
    build: Callable
    kind: str = "displacement"
    master_only: bool = False
    updated_lagrangian: bool = False
    distributed: bool = False
    build_ul: Callable = None

    @property
    def first_order(self):
        return self.shape in ("WTE1", "MTE1")


_FORMULATIONS = {}


def register(token, shape, build, kind="displacement", master_only=False,
             updated_lagrangian=False, distributed=False, replace=False):
    """Register the formulation ``token`` (see the module docstring);
    ``ValueError`` naming what does not fit (a token with blanks, a name
    keyword or an FE comparator's name, an unknown shape or kind, a
    ``build`` that is not callable with ``(basis, material, tangent)``,
    ``updated_lagrangian=True`` for a formulation the package's UL model
    does not build, a token already registered unless ``replace``).
    Returns the record."""
    if not isinstance(token, str) or not re.fullmatch(r"[^\s]+", token) \
            or token in ("TL", "UL", "noBC", "kNN", "meshU", "MQ",
                             "FEM"):
        raise ValueError("a formulation token is one word and not a name "
                         "keyword, got {!r}".format(token))
    if token in _FE:
        raise ValueError("{!r} is the name of an FE comparator (a scene "
                         "solves the FE method under it, never this "
                         "formulation): choose another token".format(token))
    if shape not in SHAPE_FUNCTIONS:
        raise ValueError("formulation {!r}: shape must be one of {}, got "
                         "{!r}".format(token, ", ".join(SHAPE_FUNCTIONS),
                                      shape))
    if kind not in KINDS:
        raise ValueError("formulation {!r}: kind must be one of {}, got "
                         "{!r}".format(token, ", ".join(KINDS), kind))
    if not callable(build) or not _accepts(build, 3):
        raise ValueError("formulation {!r}: build must be callable as "
                         "build(basis, material, tangent) -> model, got {!r}"
                         .format(token, build))
    build_ul = None
    if callable(updated_lagrangian) and not isinstance(updated_lagrangian,
                                                       bool):
        if not _accepts(updated_lagrangian, 3):
            raise ValueError(
                "formulation {!r}: updated_lagrangian must be True or "
                "callable as build_ul(basis, material, every) -> model"
                .format(token))
        build_ul = updated_lagrangian
    elif updated_lagrangian and not getattr(build, "updated_lagrangian",
                                            False):
        raise ValueError(
            "formulation {!r}: updated_lagrangian=True builds the "
            "package's UpdatedLagrange model (the displacement "
            "formulation), not {!r}: pass updated_lagrangian=build_ul, a "
            "callable (basis, material, every) -> your model in the UL "
            "frame".format(token, build))
    if token in _FORMULATIONS and not replace:
        raise ValueError("formulation {!r} is registered already (pass "
                         "replace=True to replace it)".format(token))
    record = Formulation(token, shape, build, kind, bool(master_only),
                         bool(updated_lagrangian), bool(distributed),
                         build_ul)
    _FORMULATIONS[token] = record
    return record


def _accepts(f, n):
    """Whether ``f`` can be called with ``n`` positional arguments (a
    callable without a signature passes)."""
    try:
        inspect.signature(f).bind(*([None] * n))
    except TypeError:
        return False
    except ValueError:  # no signature (a builtin)
        return True
    return True


def unregister(token):
    """Remove a formulation (a user's; tests)."""
    _FORMULATIONS.pop(token, None)


def formulation(token):
    """The record of ``token``; ``ValueError`` naming the registered ones
    if there is none."""
    try:
        return _FORMULATIONS[token]
    except KeyError:
        raise ValueError("unknown formulation {!r}: one of {}".format(
            token, ", ".join(_FORMULATIONS))) from None


def tokens(**where):
    """The registered tokens, in registration order, whose fields equal
    ``where`` (e.g. ``tokens(kind="displacement")``)."""
    return tuple(t for t, r in _FORMULATIONS.items()
                 if all(getattr(r, k) == v for k, v in where.items()))


@dataclass(frozen=True)
class FEMethod:
    """An FE comparator: the mesh type it needs (triangles and
    tetrahedra are split from quadrilaterals and hexahedra on the same
    nodes), its scalar element, its Gauss rule (``None``: scikit-fem's
    default) and whether it condenses a P0 pressure (Q1P0, H1P0)."""
    name: str
    mesh: type
    element: type
    intorder: int = None
    mean_dilatation: bool = False


_FE = {}


def register_fe(name, mesh, element, intorder=None, mean_dilatation=False):
    """Register an FE comparator (see :class:`FEMethod`); returns it."""
    record = FEMethod(name, mesh, element, intorder, bool(mean_dilatation))
    _FE[name] = record
    return record


def fe_method(name):
    """The :class:`FEMethod` of ``name``; ``ValueError`` naming the
    registered ones if there is none."""
    try:
        return _FE[name]
    except KeyError:
        raise ValueError("unknown FE method {!r}: one of {}".format(
            name, ", ".join(_FE))) from None


def unregister_fe(name):
    """Remove an FE comparator (a user's; tests)."""
    _FE.pop(name, None)


def fe_names():
    """The registered FE comparators, in registration order."""
    return tuple(_FE)


# Gauss rules: 2 and 3 points per direction for the multilinear and
# multiquadratic elements (scikit-fem's defaults use 3 and 7); one point
# for T1/O1, whose F is constant per element (exact; the default rule took
# 4x the points); T2/O2: scikit-fem's defaults
for _name, _mesh, _element, _order, _p0 in (
        ("T1", fem.MeshTri1, fem.ElementTriP1, 1, False),
        ("Q1", fem.MeshQuad1, fem.ElementQuad1, 2, False),
        ("O1", fem.MeshTet1, fem.ElementTetP1, 1, False),
        ("H1", fem.MeshHex1, fem.ElementHex1, 2, False),
        ("Q1P0", fem.MeshQuad1, fem.ElementQuad1, 2, True),
        ("H1P0", fem.MeshHex1, fem.ElementHex1, 2, True),
        ("T2", fem.MeshTri1, fem.ElementTriP2, None, False),
        ("Q2", fem.MeshQuad1, fem.ElementQuad2, 4, False),
        ("O2", fem.MeshTet1, fem.ElementTetP2, None, False),
        ("H2", fem.MeshHex1, fem.ElementHex2, 4, False)):
    register_fe(_name, _mesh, _element, _order, _p0)
