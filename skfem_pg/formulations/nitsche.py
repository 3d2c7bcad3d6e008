r"""Dirichlet conditions by Nitsche's method — for bases whose shape
functions on a boundary facet involve interior unknowns (the blended
quadratic basis ``PG2``, :mod:`skfem_pg.discretization.blend`), where
prescribing vertex values fixes the field only at the vertices.

On a boundary :math:`\Gamma_D` with prescribed components :math:`M u = M
g` (:math:`M` the diagonal selector of the prescribed components) the
residual gains

.. math::

    r(u; v) = -\int_{\Gamma_D} (P(F) N)\cdot M v
        - \int_{\Gamma_D} (\mathbb A_s : \nabla v\, N)\cdot M (u - g)
        + \int_{\Gamma_D} \frac{\beta E}{h}\, M (u - g)\cdot v,

with :math:`P` the first Piola-Kirchhoff stress, :math:`E` the largest
diagonal entry of the material's tangent :math:`\mathbb A_0` in the
undeformed state (:math:`\lambda + 2\mu` for an isotropic law), :math:`h`
the facet size and :math:`\beta` the penalty (default 20).  The first
term makes the method consistent (the exact solution satisfies it), the
second symmetric (Nitsche 1971; adjoint consistent for linear
elasticity, whence the L2 rate), the third stable.  Where every
prescribed value is zero (clamps, rollers) :math:`\mathbb A_s` is the
current tangent :math:`\mathbb A(F)`, and the tangent matrix drops the
term :math:`\partial\mathbb A\,(u - g)` (the boundary's discretization
error): it is symmetric, and the residual consistent.  With non-zero
values :math:`\mathbb A_s = \mathbb A_0`, so that the terms linear in
:math:`g` go into the load vector (:meth:`WeakDirichlet.load`; a
prescribed value grows with the load factor like the loads): consistent,
with an exact tangent that is not symmetric away from the undeformed
state (the solvers detect that).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import skfem as fem
from skfem.helpers import dot

from ..discretization.assembly import assemble
from ..discretization.loads import call_user

#: Nitsche penalty :math:`\beta` (times the stiffness over the facet
#: size); 20 gave the rates of ``benchmarks/second_order.py`` (L2 3.2-3.9).
PENALTY = 20.0


def _traction(T, n):
    """``T . n`` for ``T`` ``(d, d, ...)`` and normals ``(d, ...)``."""
    return np.einsum("ij...,j...->i...", T, n)


def _A0(material, d):
    A0 = material.tangent(np.eye(d).reshape(d, d, 1, 1))
    return np.asarray(A0)[..., 0, 0]


@fem.LinearForm
def _force(v, w):
    # -(P N).M v - (As : grad v N).M u + beta E / h (M u).v
    Asv = np.einsum("ijkl...,kl...->ij...", w.As, v.grad)
    return -dot(w.M * _traction(w.P, w.n), v) \
        - dot(_traction(Asv, w.n), w.M * w.u) \
        + w.pen / w.h * dot(w.M * w.u, v)


@fem.BilinearForm
def _stiffness(du, v, w):
    Adu = np.einsum("ijkl...,kl...->ij...", w.A, du.grad)
    Asv = np.einsum("ijkl...,kl...->ij...", w.As, v.grad)
    return -dot(w.M * _traction(Adu, w.n), v) \
        - dot(_traction(Asv, w.n), w.M * du) \
        + w.pen / w.h * dot(w.M * du, v)


@fem.LinearForm
def _load(v, w):
    # the terms of g: -(A0 : grad v N).M g + beta E / h (M g).v
    Asv = np.einsum("ijkl...,kl...->ij...", w.As, v.grad)
    return -dot(_traction(Asv, w.n), w.M * w.g) \
        + w.pen / w.h * dot(w.M * w.g, v)


class WeakDirichlet:
    """A model (:mod:`skfem_pg.formulations.displacement` protocol) with
    Dirichlet conditions imposed by Nitsche terms (module docstring).

    Parameters
    ----------
    model
        A displacement model on a vector basis that has ``boundary(facets)``
        (:class:`~skfem_pg.discretization.blend.BlendBasis`).
    conditions
        ``{boundary: what}``: a boundary name (or facet indices) and
        ``{component: value}`` at load factor 1, ``None`` (every
        component zero, a clamp) or a callable ``g(x)`` of the facet
        points ``(d, nfacets, nqp)`` returning the displacement there
        (every component; scaled by the load factor).  Facet index
        arrays, which a dict cannot key, go as a list of ``(facets,
        what)`` pairs.
    penalty
        :math:`\\beta` (default :data:`PENALTY`).

    Notes
    -----
    Newton's method then runs with no prescribed dofs and the load
    :meth:`load` added to the external forces.

    Examples
    --------
    >>> import skfem as fem, skfem_pg as pg
    >>> import numpy as np
    >>> mesh = fem.MeshTri.init_tensor(np.linspace(0, 3, 7),
    ...                                np.linspace(0, 1, 3))
    >>> mesh = mesh.with_boundaries({"left": lambda x: x[0] == 0})
    >>> basis = pg.FamilyBasis(mesh, dim=2, order=2)
    >>> model = WeakDirichlet(pg.formulations.Hyperelastic(
    ...     basis, pg.materials.NeoHooke(lam=1.0, mu=1.0)), {"left": None})
    >>> model.N == basis.N, bool(model.load().any())  # a clamp: no load
    (True, False)
    """

    def __init__(self, model, conditions, penalty: float = PENALTY):
        basis = model.basis
        if not hasattr(basis, "boundary") or basis.ncomp is None:
            raise TypeError(
                "WeakDirichlet needs a vector basis with boundary(facets) "
                "(FamilyBasis(mesh, dim=d, order=2)), got {}".format(
                    type(basis).__name__))
        if not penalty > 0:
            raise ValueError("the Nitsche penalty must be positive, got "
                             "{!r}".format(penalty))
        if getattr(model, "history", None) is not None:
            raise NotImplementedError(
                "WeakDirichlet with {!r}: the Nitsche terms evaluate the "
                "stress at the boundary's own points, where a stateful "
                "material has no history; use a hyperelastic law".format(
                    model.material))
        self.model, self.penalty = model, float(penalty)
        d = basis.ncomp
        material = model.material
        self._A0 = _A0(material, d)
        self._E = float(max(self._A0[a, b, a, b] for a in range(d)
                            for b in range(d)))
        self.terms = []  # (name, facet basis, selector M (d, 1, 1), g)
        pairs = conditions.items() if isinstance(conditions, dict) \
            else conditions
        for name, comps in pairs:
            fb = basis.boundary(name)
            M, g = np.zeros((d, 1, 1)), np.zeros((d, 1, 1))
            if callable(comps):  # every component, a field g(x)
                x = np.asarray(fb.global_coordinates())
                g = call_user(comps, x, "the prescribed displacement g(x) "
                              "on {!r}".format(name))
                if g.shape != x.shape:
                    raise ValueError(
                        "the prescribed displacement g(x) on {!r} must "
                        "return shape (dim, nfacets, nqp) = {}, got {}"
                        .format(name, x.shape, g.shape))
                self.terms.append((name, fb, np.ones((d, 1, 1)), g))
                continue
            for c, val in ({c: 0.0 for c in range(d)} if comps is None
                           else comps).items():
                if not 0 <= int(c) < d:
                    raise ValueError(
                        "{!r}: component {!r} of a {}-D displacement"
                        .format(name, c, d))
                M[int(c)], g[int(c)] = 1.0, float(val)
            self.terms.append((name, fb, M, g))
        #: every prescribed value zero (clamps, rollers): the symmetrizing
        #: term takes the current tangent, and so does the tangent matrix
        self.homogeneous = not any(np.any(t[3]) for t in self.terms)

    # --- the wrapped model's protocol ------------------------------------
    def __getattr__(self, name):
        if name == "model":  # not yet set: no recursion
            raise AttributeError(name)
        return getattr(self.model, name)

    def energy(self, state):
        r"""Not offered: the Nitsche terms are no potential's
        derivative."""
        raise NotImplementedError(
            "the Nitsche terms of WeakDirichlet have no potential")

    def state(self, x):
        s = dict(self.model.state(x))
        s["_weak_u"] = x[:self.model.n_u]
        return s

    def _params(self, fb, M, u=None):
        """The forms' coefficients on the facet basis ``fb``; with the
        displacements ``u`` also ``u``, ``P`` and ``A`` there, and ``As``
        the current tangent where the conditions are homogeneous."""
        d = fb.ncomp
        A0 = self._A0.reshape(self._A0.shape + (1, 1))
        p = dict(As=A0, M=M, pen=self.penalty * self._E)
        if u is not None:
            U = fb.interpolate(u)
            F = U.grad + np.eye(d).reshape(d, d, 1, 1)
            material = self.model.material
            p.update(u=np.asarray(U), P=material.stress(F),
                     A=material.tangent(F))
            if self.homogeneous:
                p["As"] = p["A"]
        return p

    def boundary_force(self, state, term):
        """The Nitsche terms' residual of one condition (length ``N``)."""
        _, fb, M, _ = term
        p = self._params(fb, M, state["_weak_u"])
        p.pop("A")
        return assemble(_force, fb, **p)

    def internal_force(self, state):
        r = self.model.internal_force(state)
        for term in self.terms:
            r = r + _pad(self.boundary_force(state, term), len(r))
        return r

    def tangent(self, state):
        K = self.model.tangent(state)
        for _, fb, M, _ in self.terms:
            p = self._params(fb, M, state["_weak_u"])
            p.pop("u"), p.pop("P")
            Kb = assemble(_stiffness, fb, **p)
            K = K + _pad_matrix(Kb, K.shape[0])
        return K

    def _term_load(self, term):
        _, fb, M, g = term
        if not np.any(g):
            return np.zeros(self.model.basis.N)
        return assemble(_load, fb, g=np.broadcast_to(g, (len(g),)
                                                      + fb.dx.shape),
                        **self._params(fb, M))

    def load(self):
        """The prescribed values' share of the external forces at load
        factor 1 (length ``N``)."""
        return sum((self._term_load(t) for t in self.terms),
                   np.zeros(self.model.basis.N))

    def reaction(self, x, boundary, load_factor=1.0):
        r"""The force ``(d,)`` the condition on ``boundary`` exerts on the
        body at ``x`` (prescribed values at ``load_factor``): minus its
        Nitsche terms' residual summed per component (the shape
        functions sum to one), the consistent flux :math:`\int_\Gamma
        (P N - \beta E/h\, M(u - g))`."""
        for term in self.terms:
            if _same(term[0], boundary):
                r = self.boundary_force(self.state(x), term) \
                    - load_factor * self._term_load(term)
                return -r.reshape(-1, len(term[2])).sum(0)
        raise ValueError("no weak Dirichlet condition on {!r}; the "
                         "conditions are on {}".format(
                             boundary, [t[0] for t in self.terms]))


def _same(a, b):
    if isinstance(a, str) or isinstance(b, str):
        return isinstance(a, str) and isinstance(b, str) and a == b
    return np.array_equal(np.asarray(a), np.asarray(b))


def _pad(r, n):
    if len(r) == n:
        return r
    out = np.zeros(n)
    out[:len(r)] = r
    return out


def _pad_matrix(K, n):
    if K.shape[0] == n:
        return K
    K = K.tocoo()
    return sp.csr_matrix((K.data, (K.row, K.col)), shape=(n, n))
