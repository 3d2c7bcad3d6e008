r"""Nonlinear solid models that Newton's method drives.

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
:class:`MeanDilatation`
    Q1P0 / H1P0 (Simo–Taylor–Pister mean dilatation) for the iso/vol split
    neo-Hooke (2.43): per element a constant dilatation
    :math:`\Theta_e = \frac1{V_e}\int_e J` and pressure
    :math:`p_e = U'(\Theta_e)`, condensed,

    .. math:: \Pi = \sum_e \int_e W_{iso}(F) + V_e U(\Theta_e),\qquad
              U(\Theta) = \tfrac K4(\Theta^2 - 1 - 2\ln\Theta).

    Its tangent has a rank-one term per element,
    :math:`\frac{U''(\Theta_e)}{V_e}\, g_e\otimes g_e` with
    :math:`g_e = \int_e J F^{-T}:\nabla\varphi`.
"""
import numpy as np
import scipy.sparse as sp
import skfem as fem
from skfem.helpers import ddot, grad

from .assembly import assemble
from .threads import kernel
from .materials import NeoHookeIsoVol, inverse_and_det
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
        the unpadded flat layout ``(d, d, 1, N_q)`` (:mod:`skfem_pg.layout`),
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


class MeanDilatation(Hyperelastic):
    """Q1P0 / H1P0 mean dilatation on a scikit-fem vector basis (see the
    module docstring) for the iso/vol neo-Hooke with shear modulus ``mu``
    and bulk modulus ``K``."""

    def __init__(self, basis, mu, K):
        if hasattr(basis, "G"):
            raise ValueError("MeanDilatation is the FE comparator; for "
                             "particles use the UnlP0 formulation")
        super().__init__(basis, NeoHookeIsoVol.isochoric(mu))
        self.K = float(K)
        self.material_full = NeoHookeIsoVol(mu, K)
        self._V = basis.dx.sum(axis=1)

    @kernel
    def state(self, u):
        s = super().state(u)
        J = _det(s["F"])
        s["J"] = J
        s["Theta"] = (J * self.basis.dx).sum(axis=1) / self._V
        return s

    def _pressure(self, Theta):
        return 0.5 * self.K * (Theta - 1.0 / Theta)

    @kernel
    def stress(self, state):
        F, J = state["F"], state["J"]
        FinvT = np.swapaxes(inverse_and_det(F)[0], 0, 1)
        p = self._pressure(state["Theta"])[:, None]
        return self.material.stress(F) + p * J * FinvT

    @kernel
    def tangent(self, state):
        F, J, Theta = state["F"], state["J"], state["Theta"]
        Finv = inverse_and_det(F)[0]
        FinvT = np.swapaxes(Finv, 0, 1)
        p = self._pressure(Theta)[:, None]
        # d(J F^-T)/dF = J (F^-T (x) F^-T - F^-1_Jk F^-1_Li)
        dJFinvT = J * (FinvT[:, :, None, None] * FinvT[None, None]
                       - np.einsum("Jk...,Li...->iJkL...", Finv, Finv))
        A = self.material.tangent(F) + p * dJFinvT
        K = assemble(material_tangent, self.basis, A=A)
        # rank-one volumetric term per element
        g = internal_force.elemental(self.basis, P=J * FinvT).tolocal()
        Upp = 0.5 * self.K * (1.0 + 1.0 / Theta ** 2)
        loc = (Upp / self._V)[:, None, None] * g[:, :, None] * g[:, None, :]
        ed = self.basis.element_dofs  # (Nbfun, nel)
        rows = np.broadcast_to(ed.T[:, :, None], loc.shape)
        cols = np.broadcast_to(ed.T[:, None, :], loc.shape)
        Kvol = sp.coo_matrix((loc.ravel(), (rows.ravel(), cols.ravel())),
                             shape=K.shape).tocsr()
        return K + Kvol
