"""The one registry of PG formulations: each formulation token of a name
(Table 7.1's ``Unl``, ``UnlP0``, ... and any a user adds) with what the
package derives from it.

================  =====================================================
field             used by
================  =====================================================
``shape``         :func:`skfem_pg.naming.parse`: the shape functions of
                  the displacement basis (``WTE1``, ``MTE1``, ``WTE2``);
                  first order (WTE1, MTE1): the bond correction is the
                  default
``build``         :func:`skfem_pg.formulations.model_for`:
                  ``build(basis, material, tangent)`` returns the model
                  (:class:`~skfem_pg.formulations.Hyperelastic` or a
                  subclass: ``state``, ``internal_force``, ``tangent``,
                  ``commit``, ``min_J``, ``n_u``; what Newton's method,
                  Newmark and central differences ask of it)
``kind``          ``"displacement"`` (a basis of this shape is named by
                  it: :func:`skfem_pg.naming.name_of`), ``"mixed"``
                  or ``"stabilized"``
``master_only``   the gradient lives at the master alone: no bond
                  correction (U1SIG)
``updated_lagrangian``  the UL frame is built for it
``distributed``   the distributed Newton solves it
                  (``Scene.solve(..., comm=...)``)
================  =====================================================

:mod:`skfem_pg.formulations.by_name` registers Table 7.1; a formulation
of one's own is one :func:`register` call, after which names with its
token parse, build and solve (``Scene.solve("VCPBG MyToken")``).  This
module imports nothing of the package, so every layer may read it.
"""
import re
from dataclasses import dataclass
from typing import Callable

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

    @property
    def first_order(self):
        return self.shape in ("WTE1", "MTE1")


_FORMULATIONS = {}


def register(token, shape, build, kind="displacement", master_only=False,
             updated_lagrangian=False, distributed=False, replace=False):
    """Register the formulation ``token`` (see the module docstring);
    ``ValueError`` naming what does not fit (a token with blanks, an
    unknown shape or kind, a ``build`` that is not callable, a token
    already registered unless ``replace``).  Returns the record."""
    if not isinstance(token, str) or not re.fullmatch(r"[^\s]+", token) \
            or token in ("TL", "UL", "noBC", "kNN", "FEM"):
        raise ValueError("a formulation token is one word and not a name "
                         "keyword, got {!r}".format(token))
    if shape not in SHAPE_FUNCTIONS:
        raise ValueError("formulation {!r}: shape must be one of {}, got "
                         "{!r}".format(token, ", ".join(SHAPE_FUNCTIONS),
                                      shape))
    if kind not in KINDS:
        raise ValueError("formulation {!r}: kind must be one of {}, got "
                         "{!r}".format(token, ", ".join(KINDS), kind))
    if not callable(build):
        raise ValueError("formulation {!r}: build must be callable "
                         "(basis, material, tangent) -> model".format(token))
    if token in _FORMULATIONS and not replace:
        raise ValueError("formulation {!r} is registered already (pass "
                         "replace=True to replace it)".format(token))
    record = Formulation(token, shape, build, kind, bool(master_only),
                         bool(updated_lagrangian), bool(distributed))
    _FORMULATIONS[token] = record
    return record


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
