r"""Exactly incompressible: one pressure per element as a global unknown —
PBG IUnlP0 (thesis 6.2.1, "I" for incompressible) on a family basis, the
incompressible Q1P0 / H1P0 on an FE basis.

With :math:`\nu = 0.5` the dilatation is 1 and not an unknown; (6.3)
becomes

.. math::

    \Pi(u, p) = \sum_e\Big[\sum_j w_{ej} W_{iso}(F^{ej})
        + p_e \sum_j w_{ej} (J^{ej} - 1)\Big],

and the pressures cannot be condensed, because the pressure block of the
tangent (6.5, right) is zero.  Unknowns ``x = [u, p]``: the displacements
in scikit-fem numbering, then one pressure per element (family).
Residual and tangent

.. math::

    R_u = \sum_e\sum_j w_{ej}(P_{iso} + p_e J F^{-T}):\nabla\delta u,
    \qquad R_{p_e} = \sum_j w_{ej}(J^{ej} - 1),

    K = \begin{bmatrix} K_{uu} & G \\ G^T & 0\end{bmatrix},\quad
    K_{uu} = \sum\nolimits_{ej} w_{ej}\nabla\delta u : (\mathbb A_{iso}
        + p_e\,\partial_F(JF^{-T})) : \nabla du,\quad
    G_{:,e} = g_e = \sum_j w_{ej}\, JF^{-T} : \nabla N^{ej}.

The tangent is a symmetric saddle-point matrix (indefinite): Newton's
method solves it with the sparse direct solver (SuperLU with partial
pivoting copes with the zero block; CG and the AMG hierarchy of the
displacement formulations do not apply), which the ``"auto"`` solver
picks for models with extra fields.  The families must not outnumber what
the displacements can satisfy: a family basis has as many pressures as
particles, so IUnlP0 is solvable only where the displacement space is rich
enough (:mod:`skfem_pg.analysis.infsup`); a singular tangent shows as a
non-finite or diverging Newton step, which cuts the load step.
"""
import numpy as np
import scipy.sparse as sp

from ..discretization.assembly import assemble
from ..discretization.elementwise import Elements
from ..materials import J2Plasticity, NeoHookeIsoVol, inverse_and_det
from ..threads import kernel
from .dilatation import d_JFinvT
from .displacement import Hyperelastic, internal_force, material_tangent


def incompressible_shear_modulus(material):
    """The shear modulus of an incompressible iso/vol neo-Hooke material
    (:meth:`~skfem_pg.materials.NeoHookeIsoVol.incompressible`); anything
    else raises."""
    if not isinstance(material, (NeoHookeIsoVol, J2Plasticity)) \
            or np.isfinite(material.K):
        raise ValueError(
            "IUnlP0 is the incompressible limit (nu = 0.5): use "
            "NeoHookeIsoVol.incompressible(mu) (or J2Plasticity with "
            "K = inf); for a finite bulk modulus use UnlP0 / Q1P0 / H1P0, "
            "got {!r}".format(material))
    return material.mu


class IncompressibleP0(Hyperelastic):
    """IUnlP0 on a PBG :class:`~skfem_pg.FamilyBasis`, incompressible
    Q1P0 / H1P0 on a scikit-fem vector basis (see the module docstring);
    isochoric neo-Hooke with shear modulus ``mu``.

    ``fields(x)`` gives the per-element (per-family) pressure ``p``.

    Examples
    --------
    >>> import numpy as np, skfem as fem, skfem_pg as pg
    >>> basis = pg.FamilyBasis(fem.MeshQuad().refined(2), dim=2)
    >>> model = IncompressibleP0(basis, mu=40.0)
    >>> model.N > model.n_u == basis.N  # the pressures follow the displacements
    True

    """

    def __init__(self, basis, mu):
        if getattr(basis, "is_petrov", False):
            raise NotImplementedError(
                "IncompressibleP0 integrates over the family (PBG); PPG "
                "IUnlP0 (the constraint at the master) is "
                "MasterIncompressible")
        super().__init__(basis, NeoHookeIsoVol.isochoric(mu))
        self.elements = Elements(basis)
        self._Phi = self.elements.polynomials(0)

    @classmethod
    def of(cls, basis, material):
        """From :meth:`NeoHookeIsoVol.incompressible(mu)
        <skfem_pg.materials.NeoHookeIsoVol.incompressible>`."""
        return cls(basis, incompressible_shear_modulus(material)
                   ).with_material(material)

    @property
    def N(self):
        return self.n_u + self.elements.n

    @property
    def blocks(self):
        return [("u", slice(0, self.n_u)), ("p", slice(self.n_u, self.N))]

    def fields(self, x):
        return {"p": np.asarray(x[self.n_u:self.N], dtype=float).copy()}

    @kernel
    def state(self, x):
        x = np.asarray(x, dtype=float)
        if x.shape != (self.N,):
            raise ValueError("IUnlP0 unknowns: {} displacements and {} "
                             "pressures ({} in all), got shape {}".format(
                                 self.n_u, self.elements.n, self.N, x.shape))
        s = super().state(x[:self.n_u])
        Finv, J = inverse_and_det(s["F"])
        pe = x[self.n_u:]
        s.update(Finv=Finv, J=J, p_e=pe, p=self.elements.spread(pe))
        return s

    def min_J(self, state):
        return float(state["J"].min())

    def energy(self, state):
        """The Lagrangian :math:`\\Pi(u, p)` (stationary, not minimal)."""
        return super().energy(state) + float(np.dot(
            state["p_e"], self.elements.sum(state["J"] - 1.0)))

    @kernel
    def stress(self, state):
        FinvT = np.swapaxes(state["Finv"], 0, 1)
        return (self.material.stress(state["F"])
                + state["p"] * state["J"] * FinvT)

    @kernel
    def internal_force(self, state):
        r_u = assemble(internal_force, self.basis, P=self.stress(state))
        r_p = self.elements.sum(state["J"] - 1.0)
        return np.concatenate([r_u, r_p])

    @kernel
    def tangent(self, state):
        A = self.material.tangent(state["F"]) + state["p"] * d_JFinvT(
            state["J"], state["Finv"])
        Kuu = assemble(material_tangent, self.basis, A=A)
        E = self.elements
        G = E.coupling(E.moments(
            state["J"] * np.swapaxes(state["Finv"], 0, 1), self._Phi))
        return sp.bmat([[Kuu, G], [G.T, None]], format="csr")
