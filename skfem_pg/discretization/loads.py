r"""Load vectors consistent with the integration constraint.

Neumann loads are FE consistent, integrated with the linear shape
functions of the facets the particles were collocated from (4.31)–(4.35):

* :func:`traction`: :math:`f^i = \int_\Gamma N_i\, t \, d\Gamma`
  (for a constant traction on a flat face: :math:`t\,|A^i_\Gamma|`);
* :func:`stress_load`: :math:`f^i = \bar P \cdot A^i_\Gamma`, the load of a
  homogeneous nominal stress :math:`\bar P` (what a patch test applies);
* :func:`body_force`: :math:`f^i = \rho_0 b(X^i)\, V^i`.

Because the same :math:`A^i` enter the VC correction, a linear field is
reproduced exactly (patch test).  With the thesis' VC boundary variants
``s``/``sn`` (:mod:`skfem_pg.discretization.vc.boundary`) the surface
particles' discrete area vectors (4.35) differ from the FE ones by
``basis.area_correction``; the loads then use the discrete vectors (4.32), the
correction at a particle shared in proportion to the part of its area vector
lying on the loaded ``facets`` (exact on a flat face and wherever all faces of
the particle carry the same stress).

With ``s``/``sn`` the resultant of a constant traction on a face is
therefore not the face's area times the traction but the sum of the
discrete lengths: on the Cook membrane's left edge +0.68 / +0.33 / +0.17 %
(``sn``) and −1.4 / −0.76 / −0.38 % (``s``) at 8 / 16 / 32 elements per
side, O(h); exact with ``min-norm`` (the default) and ``p``.  It cannot be
made exact without breaking the patch test: under ``sn`` a surface
particle inside a face keeps the face normal, so a patch-consistent load
there is :math:`t\,|A^i_h|`, and at a 2-D corner the split of
:math:`A^i_h` onto its two face normals is unique — every term of the
face's resultant is fixed by the patch test.
"""
from __future__ import annotations

import warnings
from typing import Callable

import numpy as np
import skfem as fem
from numpy.typing import ArrayLike
from skfem.assembly.basis import AbstractBasis

from ..errors import SurfaceLoadWarning
from .layout import is_family_basis


def call_user(f, x, what, *args):
    """``f(x, *args)`` of a user's callable as a float array.  ``x`` goes
    in as a plain, writable copy: scikit-fem hands forms its points as a
    ``DiscreteField``, on which ``np.zeros_like(x)`` is a ``DiscreteField``
    too and item assignment (``o[1] = 0.01``) is lost — a load that is
    silently zero.  Non-finite values raise, naming ``what``."""
    x = np.array(np.asarray(x), dtype=float)
    v = np.array(np.asarray(f(x, *args)), dtype=float)
    bad = ~np.isfinite(v)
    if bad.any():
        raise ValueError("{} returned {} non-finite values".format(
            what, int(bad.sum())))
    return v


def warn_if_zero(values, what):
    """A user's load function that returned zero at every point is almost
    never what was meant (e.g. item assignment on a view that was lost):
    say so."""
    if values.size and not np.any(values):
        warnings.warn("{} is zero at every point it was evaluated at: no "
                      "load is applied".format(what), stacklevel=3)


def fe_traction(basis, facets, t, what="traction t", mesh=None):
    r""":math:`f_i = \int_\Gamma N_i\, t\, d\Gamma` on ``facets`` (indices
    or a boundary name) of a scikit-fem cell basis, by its element's facet
    basis on ``mesh`` (default ``basis.mesh``); ``t`` as in
    :func:`traction`."""
    if not isinstance(basis, fem.CellBasis):
        raise TypeError("a traction needs a FamilyBasis or a scikit-fem "
                        "CellBasis, got {}".format(type(basis).__name__))
    nc = basis.elem.dim if isinstance(basis.elem, fem.ElementVector) \
        else None
    fb = fem.FacetBasis(basis.mesh if mesh is None else mesh, basis.elem,
                        facets=facets)
    if callable(t):
        warn_if_zero(call_user(t, fb.global_coordinates(), what), what)
    else:
        t = _constant_of(t, nc, what)

    return _traction_form(t, nc, what).assemble(fb)


def _traction_form(t, nc, what, origin=0.0):
    r"""The linear form :math:`\int_\Gamma N_i\, t\, d\Gamma` of a
    constant traction (checked) or a callable one, which sees the facet
    points shifted by ``origin``; ``nc`` components (``None``: scalar)."""
    def load(v, w):
        tv = call_user(t, np.asarray(w.x) + origin, what) if callable(t) \
            else t
        if nc is None:
            return tv * v
        tv = np.asarray(tv, dtype=float)
        if tv.ndim == 1:
            tv = tv[:, None, None]
        return sum(tv[a] * v[a] for a in range(nc))
    return fem.LinearForm(load)


def _blend_traction(basis, facets, t):
    r""":func:`traction` on the blended quadratic basis (PG2): the
    consistent :math:`\int_\Gamma \psi_i t` with its own shape
    functions."""
    from .assembly import assemble
    fb = basis.boundary(facets)
    what = "the traction t(x)"
    if callable(t):
        warn_if_zero(call_user(t, fb.global_coordinates(), what), what)
    else:
        t = _constant_of(t, basis.ncomp, "traction t")
    return assemble(_traction_form(t, basis.ncomp, what), fb)


def _facet_basis(basis, facets, what):
    p = basis.particles
    if p.kind != "vertices":
        raise ValueError("{} needs vertex particles (surface particles); "
                         "these are {} particles: apply stress_load on "
                         "their area vectors instead".format(what, p.kind))
    return p._facet_basis(facets, vector=basis.ncomp is not None)


def traction(basis: AbstractBasis, facets,
             t: ArrayLike | Callable) -> np.ndarray:
    r"""Consistent nodal forces of a traction ``t`` on ``facets``, on a
    :class:`~skfem_pg.FamilyBasis` or a scikit-fem cell basis
    (:func:`fe_traction`).

    ``t``: constant vector (scalar for a scalar basis) or a callable of the
    facet quadrature points ``x`` (shape ``(dim, nfacets, nqp)``) returning
    an array of shape ``(dim, nfacets, nqp)``.  Returns a length-``N``
    vector.
    """
    from .blend import BlendBasis
    if isinstance(basis, BlendBasis):
        return _blend_traction(basis, facets, t)
    if not is_family_basis(basis):
        return fe_traction(basis, facets, t)
    fb = _facet_basis(basis, facets, "traction")
    # the facet basis is local (Particles.facet_origin); t sees global x
    origin = basis.particles.facet_origin.reshape(-1, 1, 1)
    if callable(t):
        tq = call_user(t, np.asarray(fb.global_coordinates()) + origin,
                       "the traction t(x)")
        warn_if_zero(tq, "the traction t(x)")
    else:
        t = _constant(t, basis, "traction t")
    f = _traction_form(t, basis.ncomp, "the traction t(x)",
                       origin).assemble(fb)
    dA = _area_correction(basis, facets)
    if dA is not None:  # |A_h| - |A| times the traction at the particles
        A = basis.particles.area_vectors(facets)
        dlen = np.linalg.norm(A + dA, axis=0) - np.linalg.norm(A, axis=0)
        x = basis.particles.x
        if callable(t):
            tv = call_user(t, x[:, :, None], "the traction t(x)")[..., 0]
        else:
            tv = np.broadcast_to(np.reshape(np.asarray(t, dtype=float),
                                            (-1, 1)), (max(1, np.size(t)),
                                                       x.shape[1]))
        extra = (tv * dlen).T.ravel()
        _warn_resultant(basis, f, extra, "traction")
        f = f + extra
    return _resize(f, basis)


def _warn_resultant(basis, f, extra, what):
    """:class:`~skfem_pg.errors.SurfaceLoadWarning` where the area
    correction of ``vc_boundary`` ``"s"``/``"sn"`` changes the resultant
    of the load ``f`` (its consistent part) by ``extra`` beyond
    round-off."""
    nc = 1 if basis.ncomp is None else basis.ncomp
    want = f.reshape(-1, nc).sum(axis=0)
    got = want + extra.reshape(-1, nc).sum(axis=0)
    scale = max(np.abs(want).max(initial=0.0), 1e-300)
    if np.abs(got - want).max() > 1e-10 * scale:
        k = int(np.argmax(np.abs(got - want)))
        warnings.warn(
            "vc_boundary={!r}: the {} applied has the resultant {} where "
            "{} was asked for ({:+.3g} % in component {}): the thesis' "
            "surface load on its corrected area vectors (4.35), which the "
            "patch test needs; the default vc_boundary='min-norm' (V5m) "
            "applies the requested load".format(
                basis.vc_boundary, what, np.round(got, 12).tolist(),
                np.round(want, 12).tolist(),
                100 * (got[k] - want[k]) / max(abs(want[k]), 1e-300), k),
            SurfaceLoadWarning, stacklevel=3)


def stress_load(basis: AbstractBasis, facets, P: ArrayLike) -> np.ndarray:
    r"""Nodal forces :math:`\bar P \cdot A^i_\Gamma` of a homogeneous nominal
    stress ``P`` (``(d, d)``) acting on ``facets``."""
    d = basis.particles.dim
    P = np.asarray(P, dtype=float)
    if basis.ncomp is None or P.shape != (d, d):
        raise ValueError(
            "stress_load needs a vector basis (dim={0}) and a ({0}, {0}) "
            "nominal stress, got {1} and shape {2}".format(
                d, "a scalar basis" if basis.ncomp is None else
                "dim={}".format(basis.ncomp), P.shape))
    A = basis.particles.area_vectors(facets)
    dA = _area_correction(basis, facets)
    f = P @ A  # (d, np)
    if dA is not None:
        extra = (P @ dA).T.ravel()
        _warn_resultant(basis, f.T.ravel(), extra, "stress load")
        return f.T.ravel() + extra
    return f.T.ravel()


def _area_correction(basis, facets):
    """The part of ``basis.area_correction`` that belongs to ``facets``:
    scaled by :math:`|A^i_{f}| / (|A^i_{f}| + |A^i_s - A^i_{f}|)`,
    :math:`A^i_s` the area vector over the particles' own surface
    (:meth:`~skfem_pg.Particles.outer_facets`), :math:`A^i_f` over the
    loaded facets on it;
    ``None`` if the basis has no correction."""
    dA = getattr(basis, "area_correction", None)
    if dA is None:
        return None
    p = basis.particles
    # the released constraint belongs to the particles' own surface: the
    # loaded facets outside the PG region (on an FE part) and an FE–PG
    # interface (whose constraints are kept) take no share
    own = np.asarray(p.outer_facets())
    loaded = np.intersect1d(np.asarray(p.mesh.normalize_facets(facets)), own)
    Af = (p.area_vectors(loaded) if len(loaded)
          else np.zeros_like(dA))
    on = np.linalg.norm(Af, axis=0)
    off = np.linalg.norm(p.surface_area_vectors() - Af, axis=0)
    total = on + off
    share = np.divide(on, total, out=np.zeros_like(on), where=total > 0)
    return dA * share


def body_force(basis: AbstractBasis, b: ArrayLike | Callable,
               rho: float | ArrayLike = 1.0) -> np.ndarray:
    r"""Nodal forces of a body force ``b`` (a constant vector or a
    callable of reference positions ``(dim, ...)``) per unit mass, density
    ``rho``: :math:`\rho_0 b(X^i) V^i` on particles, the consistent
    :math:`\int \rho_0\, b \cdot v\, dV` on a scikit-fem basis (a
    callable ``rho`` there is evaluated at the quadrature points).

    >>> import skfem as fem, skfem_pg as pg
    >>> mesh = fem.MeshTri().refined(2)
    >>> fe = fem.Basis(mesh, fem.ElementVector(fem.ElementTriP1()))
    >>> for basis in (pg.FamilyBasis(mesh, dim=2), fe):
    ...     f = body_force(basis, [0.0, -9.81], rho=2.0)
    ...     print(round(float(f[1::2].sum()), 12))
    -19.62
    -19.62
    """
    if not is_family_basis(basis):
        return _consistent_body_force(basis, b, rho)
    x, V = basis.particles.x, basis.particles.volumes
    n = len(V)
    nc = 1 if basis.ncomp is None else basis.ncomp
    if callable(b):
        bv = call_user(b, x, "the body force b(x)")
        warn_if_zero(bv, "the body force b(x)")
    else:
        bv = np.asarray(b, dtype=float)
    if callable(b):
        shapes = [(nc, n)] if nc > 1 else [(n,), (1, n)]
    else:
        shapes = [(nc,)] if nc > 1 else [(), (1,)]
    if bv.shape not in shapes:
        raise ValueError(
            "body force b must be {} (or a callable of x returning shape "
            "{}), got shape {}".format(
                "a scalar" if nc == 1 else "a vector of length {}".format(nc),
                (nc, n) if nc > 1 else (n,), bv.shape))
    if basis.ncomp is None:
        return rho * np.broadcast_to(bv.reshape(-1), V.shape) * V
    bv = np.broadcast_to(bv.reshape(nc, -1), (nc, n))
    return (rho * bv * V).T.ravel()


def _consistent_body_force(basis, b, rho):
    r""":math:`\int \rho\, b \cdot v\, dV` on a scikit-fem vector (or
    scalar) basis."""
    nc = len(basis.split_indices()) if hasattr(basis, "split_indices") \
        else 1

    @fem.LinearForm
    def load(v, w):
        x = w.x
        bv = call_user(b, x, "the body force b(x)") if callable(b) \
            else np.asarray(b, dtype=float)
        r = call_user(rho, x, "the density rho(x)") if callable(rho) \
            else rho
        if nc == 1:
            return r * bv * v
        bv = np.asarray(bv, dtype=float)
        if bv.shape[0] != nc:
            raise ValueError("body force b must have {} components, got "
                             "shape {}".format(nc, bv.shape))
        bv = bv.reshape((nc,) + (1,) * (v.ndim - 1)) if bv.ndim == 1 \
            else bv
        return r * sum(bv[c] * v[c] for c in range(nc))
    return load.assemble(basis)


def _constant(t, basis, what):
    """A constant load as a float array of the basis' component count."""
    return _constant_of(t, basis.ncomp, what)


def _constant_of(t, nc, what):
    t = np.asarray(t, dtype=float)
    if nc is None:
        if t.size != 1:
            raise ValueError("{} on a scalar basis must be a scalar, got "
                             "shape {}".format(what, t.shape))
        return float(t.ravel()[0])
    if t.shape != (nc,):
        raise ValueError("{} must have {} components for this dim={} "
                         "basis, got shape {}".format(what, nc, nc, t.shape))
    return t


def _resize(f, basis):
    if f.shape[0] != basis.N:
        raise ValueError("load vector has {} entries, the basis {}".format(
            f.shape[0], basis.N))
    return f
