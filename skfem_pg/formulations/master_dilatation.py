r"""PPG UnlP0 (thesis (6.2), 6.2.1): the volumetric energy evaluated once
per family, at its master.

In PPG (4.21) every bond carries the stress of the trial deformation
gradient :math:`F^{jk}` at :math:`X^k` computed in family :math:`j`, tested
with the derivative at the master (:mod:`skfem_pg.discretization.petrov`).
UnlP0 keeps that for the isochoric part and takes the volumetric part once
per particle, from the master's own :math:`F^{kk}` ((6.2); condensed:
:math:`\Theta^k = J^{kk}`, :math:`p^k = U'(J^{kk})`, a selective
underintegration of (6.3)):

.. math::

    \delta W = \sum_k V^k \sum_{j\in H^k} \big[P_{iso}(F^{jk})
        + P_{vol}(F^{kk})\big] : \big((\delta u^j - \delta u^k)\otimes
        G_t^{kkj}\big), \qquad P_{vol} = p\,JF^{-T},\quad
        U(J) = \tfrac K4 (J^2 - 1 - 2\ln J).

With the test vectors :math:`S^k_i` of particle :math:`k`
(:math:`S^k_j = G_t^{kkj}`, :math:`S^k_k = -\sum_j G_t^{kkj}`, on the
members of :math:`H^k`) the volumetric residual is
:math:`V^k P_{vol}^k\,S^k_i` and its tangent the one-point block

.. math::

    K^k_{(ic)(le)} = V^k\, S^k_{ib}\,\mathbb A_{vol,cbeL}(F^{kk})\,
        G^{kkl}_L ,\qquad \mathbb A_{vol} = U''\,(JF^{-T})\otimes(JF^{-T})
        + p\,\partial_F(JF^{-T}),

non-symmetric like every PPG tangent.  The pressure is one value per
particle (``fields``), which the volumetric underintegration lets
oscillate (thesis 7.2.5: PPG UnlP0 formally passes the inf-sup test).
"""
import numpy as np

from ..discretization.assembly import FixedPattern, assemble
from ..discretization.petrov import reverse_slots
from ..materials import NeoHookeIsoVol, check_moduli, inverse_and_det
from ..threads import kernel
from .dilatation import d_JFinvT, compressible_moduli
from .displacement import Hyperelastic, material_tangent
from .incompressible import incompressible_shear_modulus


class MasterDilatation(Hyperelastic):
    """PPG UnlP0 on a Petrov–Galerkin :class:`~skfem_pg.FamilyBasis`
    (``method="PPG1"``) whose families are mastered by every particle;
    iso/vol neo-Hooke with shear modulus ``mu`` and bulk modulus ``K``.

    ``fields(u)``: the pressure ``p`` and dilatation ``Theta`` (= J at the
    master) per particle.

    Examples
    --------
    >>> import numpy as np, skfem as fem, skfem_pg as pg
    >>> basis = pg.FamilyBasis(fem.MeshQuad().refined(2), dim=2, method="PPG1")
    >>> model = MasterDilatation(basis, mu=40.0, K=100.0)
    >>> model.N == basis.N
    True

    """

    #: VC boundary variants with which it is unstable in 3-D (refused)
    unstable_3d = ("min-norm", "p")

    def __init__(self, basis, mu, K):
        if not getattr(basis, "is_petrov", False) or basis.method != "PPG1":
            raise NotImplementedError(
                "the master-point dilatation is PPG UnlP0 on a PPG1 basis "
                "(got {}); PBG UnlP0 is MeanDilatation".format(
                    getattr(basis, "method", type(basis).__name__)))
        if basis.particles.dim == 3 and basis.vc is not None and \
                basis.vc_boundary in self.unstable_3d:
            raise ValueError(
                "PPG UnlP0 in 3-D with the VC boundary variant {!r} is "
                "unstable: its constrained tangent at rest has eigenvalues "
                "with negative real part (measured: 4 on a clamped 4x4x4 "
                "hexahedral cube with 'm', 8 with 'm' and 51 with 'p' on "
                "the necking bar; none with 's' / 'sn' on a clamped cube, "
                "none in 2-D); use PBG UnlP0 ('VCPPG V3sn UnlP0' without "
                "sliding boundaries is stable at rest but diverged on the "
                "whole necking bar)"
                .format(basis.vc_boundary))
        super().__init__(basis, NeoHookeIsoVol.isochoric(mu))
        (self.K,) = check_moduli(K=K)
        p, fam = basis.particles, basis.families
        fam.require_every_master(p.x, "PPG UnlP0 / IUnlP0")
        mem, mask = fam.padded()
        self.mem = np.where(mask, mem, mem[:, :1])  # pads -> the master
        self.V = p.volumes[fam.masters]  # V^k per family
        self._G0 = basis.G[:, 0] * mask[:, :, None]  # trial at the master
        # the master's own point (k, k) in the flat layout: F^{kk} there
        self._master_points = np.empty(len(fam.masters), dtype=np.int64)
        for g in basis.layout:
            self._master_points[g.families] = g.flat[:, 0]
        # S^k: sum over the bonds (f, q) with mem[f, q] = k of the test
        # derivatives, gathered on family k's slots
        T = basis.test.G  # (nf, m, m, d): T[f, q, 0] = G_t^{kkf}
        index = np.full(p.n, -1)
        index[fam.masters] = np.arange(len(fam.masters))
        rev = reverse_slots(fam)
        nf, m, d = mask.shape + (p.dim,)
        S = np.zeros((nf, m, d))
        f, q = np.nonzero(mask & (np.arange(m) > 0))
        k = index[mem[f, q]]
        np.add.at(S, (k, rev[f, q]), T[f, q, 0])
        np.add.at(S, (k, np.zeros_like(k)), T[f, q, q])
        self.S = S
        self._pattern = None

    @classmethod
    def of(cls, basis, material):
        """From a :class:`~skfem_pg.materials.NeoHookeIsoVol`."""
        return cls(basis, *compressible_moduli(material, "PPG UnlP0")
                   ).with_material(material)

    def _master(self, F):
        """:math:`F^{kk}` per family, ``(d, d, nf)``, from the flat
        deformation gradients ``F`` ``(d, d, 1, N_q)``."""
        return F[:, :, 0, self._master_points]

    def _volumetric(self, Fm):
        Finv, J = inverse_and_det(Fm)
        K = self.K
        p = 0.5 * K * (J - 1.0 / J)
        return Finv, J, p, p * J * np.swapaxes(Finv, 0, 1)

    @kernel
    def state(self, u):
        s = super().state(u)
        Finv, J, p, Pv = self._volumetric(self._master(s["F"]))
        s.update(Finv_m=Finv, J_m=J, p=p, P_vol=Pv)
        return s

    def energy(self, state):
        J = state["J_m"]
        U = 0.25 * self.K * (J ** 2 - 1 - 2 * np.log(J))
        return super().energy(state) + float(np.sum(self.V * U))

    def fields(self, x):
        s = self.state(np.asarray(x, dtype=float))
        n = self.basis.particles.n
        p, Th = np.empty(n), np.empty(n)
        masters = self.basis.families.masters
        p[masters], Th[masters] = s["p"], s["J_m"]
        return {"p": p, "Theta": Th}

    @kernel
    def internal_force(self, state):
        r = super().internal_force(state)
        d = self.S.shape[-1]
        # V^k P_vol^k S^k_i on the members of family k
        loc = np.einsum("k,cbk,kib->kic", self.V, state["P_vol"], self.S)
        return r + np.bincount(
            (d * self.mem[:, :, None] + np.arange(d)).ravel(), loc.ravel(),
            minlength=self.n_u)

    def _family_dofs(self):
        """``(nf, m d)`` displacement dofs of each family's members."""
        nf, m, d = self.S.shape
        return (d * self.mem[:, :, None] + np.arange(d)).reshape(nf, m * d)

    def _tangent_parts(self, state, A_vol):
        r""":math:`\sum_{ej} w\,\nabla\delta u : \mathbb A_{iso} :
        \nabla du` (sparse, ``N × N``) and the one-point blocks
        :math:`V^k S^k_{ib} \mathbb A_{vol} G^{kkl}_L` ``(nf, m, d, m, d)``
        of the volumetric stiffness ``A_vol`` at the masters."""
        K = assemble(material_tangent, self.basis,
                     A=self.material.tangent(state["F"]))
        SA = np.einsum("k,kib,cbeLk->kiceL", self.V, self.S, A_vol)
        return K, np.einsum("kiceL,klL->kicle", SA, self._G0)

    @kernel
    def tangent(self, state):
        Finv, J, p = state["Finv_m"], state["J_m"], state["p"]
        Q = J * np.swapaxes(Finv, 0, 1)
        Upp = 0.5 * self.K * (1.0 + 1.0 / J ** 2)
        K, uu = self._tangent_parts(state, Upp * Q[:, :, None, None]
                                    * Q[None, None] + p * d_JFinvT(J, Finv))
        if self._pattern is None:
            dofs = self._family_dofs()
            shape = dofs.shape + dofs.shape[-1:]  # (nf, m d, m d)
            self._pattern = FixedPattern(
                np.broadcast_to(dofs[:, :, None], shape).ravel(),
                np.broadcast_to(dofs[:, None, :], shape).ravel(), self.n_u)
        return K + self._pattern.matrix(uu.ravel())


class MasterIncompressible(MasterDilatation):
    r"""PPG IUnlP0: ν = 0.5 exactly, the constraint :math:`J^{kk} = 1`
    once per particle with its pressure :math:`p^k` as a global unknown
    (thesis 6.2, IUnlP0; used as PPG IUnlP0 in 7.3.3):

    .. math::

        \delta W = \sum_k V^k \sum_{j\in H^k} \big[P_{iso}(F^{jk})
            + p^k J^{kk} F^{kk,-T}\big] : \big((\delta u^j - \delta u^k)
            \otimes G_t^{kkj}\big) + \sum_k V^k\,\delta p^k (J^{kk} - 1).

    Unknowns ``[u, p]``, one p per particle (family); the tangent is a
    non-symmetric saddle point (zero p-p block: the direct solver's
    COLAMD path).  Isochoric neo-Hooke with shear modulus ``mu``.

    Examples
    --------
    >>> import numpy as np, skfem as fem, skfem_pg as pg
    >>> basis = pg.FamilyBasis(fem.MeshQuad().refined(2), dim=2, method="PPG1")
    >>> model = MasterIncompressible(basis, mu=40.0)
    >>> model.N - model.n_u == len(basis.families)  # a pressure per family
    True

    """

    unstable_3d = ()  # not measured unstable with any VC variant

    def __init__(self, basis, mu):
        super().__init__(basis, mu, 1.0)  # K unused: no volumetric energy
        self.K = np.inf

    @classmethod
    def of(cls, basis, material):
        """From :meth:`NeoHookeIsoVol.incompressible(mu)
        <skfem_pg.materials.NeoHookeIsoVol.incompressible>`."""
        return cls(basis, incompressible_shear_modulus(material)
                   ).with_material(material)

    @property
    def N(self):
        return self.n_u + len(self.V)

    @property
    def blocks(self):
        return [("u", slice(0, self.n_u)), ("p", slice(self.n_u, self.N))]

    def _split(self, x):
        x = np.asarray(x, dtype=float)
        if x.shape != (self.N,):
            raise ValueError("PPG IUnlP0 unknowns: {} displacements and {} "
                             "pressures ({} in all), got shape {}".format(
                                 self.n_u, len(self.V), self.N, x.shape))
        return x[:self.n_u], x[self.n_u:]

    @kernel
    def state(self, x):
        u, p = self._split(x)
        s = Hyperelastic.state(self, u)
        Finv, J = inverse_and_det(self._master(s["F"]))
        s.update(Finv_m=Finv, J_m=J, p=p,
                 P_vol=p * J * np.swapaxes(Finv, 0, 1))
        return s

    def energy(self, state):
        return Hyperelastic.energy(self, state) + float(np.sum(
            self.V * state["p"] * (state["J_m"] - 1.0)))

    def fields(self, x):
        _, p = self._split(x)
        s = self.state(x)
        n = self.basis.particles.n
        out = {"p": np.empty(n), "Theta": np.empty(n)}
        masters = self.basis.families.masters
        out["p"][masters], out["Theta"][masters] = p, s["J_m"]
        return out

    @kernel
    def internal_force(self, state):
        r_u = MasterDilatation.internal_force(self, state)
        return np.concatenate([r_u, self.V * (state["J_m"] - 1.0)])

    @kernel
    def tangent(self, state):
        Finv, J, p = state["Finv_m"], state["J_m"], state["p"]
        Q = J * np.swapaxes(Finv, 0, 1)  # dJ/dF at the master
        K, uu = self._tangent_parts(state, p * d_JFinvT(J, Finv))
        up = np.einsum("k,kib,cbk->kic", self.V, self.S, Q)  # (nf, m, d)
        pu = np.einsum("k,eLk,klL->kle", self.V, Q, self._G0)
        if self._pattern is None:
            nf, m, d = self.S.shape
            dofs = self._family_dofs()
            pdof = self.n_u + np.arange(nf)[:, None]
            rows = [np.broadcast_to(dofs[:, :, None], (nf, m * d, m * d)),
                    dofs, np.broadcast_to(pdof, (nf, m * d))]
            cols = [np.broadcast_to(dofs[:, None, :], (nf, m * d, m * d)),
                    np.broadcast_to(pdof, (nf, m * d)), dofs]
            self._pattern = FixedPattern(
                np.concatenate([r.ravel() for r in rows]),
                np.concatenate([c.ravel() for c in cols]), self.N)
        K.resize((self.N, self.N))
        return K + self._pattern.matrix(np.concatenate(
            [uu.ravel(), up.ravel(), pu.ravel()]))
