r"""The displacement formulation (U1, Unl, U2 and FE): hyperelasticity on any
vector basis, the model Newton's method drives.

A model knows how to evaluate, for a displacement vector ``u``,

* ``state(u)``: the deformation gradient (and what else the model needs) at
  the quadrature points,
* ``internal_force(state)``: :math:`f_{int}`,
* ``tangent(state)``: :math:`\partial f_{int}/\partial u`,
* ``min_J(state)``: the smallest :math:`J = \det F` (inversion check).

:class:`Hyperelastic`
    Displacement formulation on any vector basis — scikit-fem FE (T1, Q1,
    O1, H1) or a :class:`~skfem_pg.FamilyBasis` (PBG).  Tangent consistent
    or, for family bases, by finite differences of the family forces.
Q1P0 / H1P0: :mod:`skfem_pg.formulations.fe`.
"""
import numpy as np
import skfem as fem
from skfem.helpers import ddot, grad

from ..discretization.assembly import assemble
from ..threads import kernel
from .tangents import fd_tangent


@fem.LinearForm
def internal_force(v, w):
    """:math:`\\int P : \\nabla v` with ``w.P`` the first Piola–Kirchhoff
    stress at the quadrature points."""
    return ddot(w.P, grad(v))


@fem.BilinearForm
def material_tangent(du, v, w):
    """:math:`\\int \\nabla v : \\mathbb A : \\nabla du` with ``w.A`` the
    consistent tangent."""
    Adu = (w.A * grad(du)[None, None]).sum(axis=(2, 3))  # A : grad(du)
    return ddot(Adu, grad(v))


def _tangent_coefficients(w, nc, nch):
    """Coefficients of :func:`material_tangent` for the batched assembly,
    on the gradient channels only: trial ``(a, 1+b)``, test ``(c, 1+e)``
    -> ``A[c, e, a, b]``, as a view ``(points..., a, b, c, e)`` of ``w.A``
    (the assembly gathers it per block, one copy)."""
    A = np.asarray(w.A)
    d = A.shape[0]
    return (np.moveaxis(A, (0, 1, 2, 3), (-2, -1, -4, -3)),
            list(range(1, d + 1)))


material_tangent.coefficients = _tangent_coefficients


def _dim(basis):
    return basis.particles.dim if hasattr(basis, "particles") else \
        basis.mesh.dim()


def _det(F):
    return np.linalg.det(np.moveaxis(F, (0, 1), (-2, -1)))


class Hyperelastic:
    """Displacement-based hyperelasticity on ``basis``.

    ``tangent="fd"`` builds the tangent by central differences of the
    family forces (family bases only), as correspondence codes do.
    """

    def __init__(self, basis, material, tangent="consistent"):
        if tangent not in ("consistent", "fd"):
            raise ValueError("tangent must be 'consistent' or 'fd'")
        if tangent == "fd" and not hasattr(basis, "G"):
            raise ValueError("the finite-difference tangent is built from "
                             "family forces: it needs a FamilyBasis")
        self.basis, self.material, self.tangent_kind = basis, material, \
            tangent
        d = _dim(basis)
        self._eye = np.eye(d).reshape(d, d, 1, 1)

    @kernel
    def state(self, u):
        """``{"F": ...}`` at the quadrature points: for a family basis in
        the unpadded flat layout ``(d, d, 1, N_q)`` (:mod:`skfem_pg.discretization.layout`),
        so the material is evaluated only at real members."""
        if hasattr(self.basis, "layout"):
            return {"F": self.basis.interpolate(u, flat=True).grad
                    + self._eye}
        return {"F": self.basis.interpolate(u).grad + self._eye}

    def energy(self, state):
        """Stored energy :math:`\\sum w\\, W(F)` of ``state``."""
        dx = (self.basis.flat_weights() if hasattr(self.basis, "layout")
              else self.basis.dx)
        return float(np.sum(dx * self.material.energy(state["F"])))

    def min_J(self, state):
        return float(_det(state["F"]).min())

    @kernel
    def stress(self, state):
        return self.material.stress(state["F"])

    @kernel
    def internal_force(self, state):
        return assemble(internal_force, self.basis, P=self.stress(state))

    @kernel
    def tangent(self, state):
        if self.tangent_kind == "fd":
            return fd_tangent(self.basis, self.material, state["F"])
        return assemble(material_tangent, self.basis,
                        A=self.material.tangent(state["F"]))
