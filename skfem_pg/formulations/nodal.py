r"""Nodal pressure and dilatation as global unknowns: PBG U2P1C (thesis
(6.11)) and the bubble-enriched Unl+P1C ((6.12)–(6.16)).

Every particle carries :math:`p^i, \Theta^i` beside its displacement.
Inside family :math:`H^k` both are linear, extrapolated from the master
with gradients of the displacement basis at the master (6.11):

.. math::

    p^{kj} = p^k + \Big(\sum_i (p^i - p^k)\,\partial N^{kki}\Big)\cdot
    \Delta X^{kj} = \sum_i N_p^{kji} p^i, \qquad
    \Delta X^{kj} = X^j - X^k,

(the same for :math:`\Theta`), :math:`\partial N^{kki}` the corrected
derivatives ``G[k, 0, i]`` of the displacement basis (U2P1C: WTE2; Unl+P1C:
MTE1 with BC and VC, a linear basis, as the thesis asks).  Unl+P1C adds one
bubble per family, a local vector :math:`u_b^k`, with (6.12), (6.15),
(6.16)

.. math::

    F^{kj} = I + \sum_i u^i\otimes\partial N^{kji} + u_b^k\otimes
    (X^j - X_c^k), \qquad X_c^k = \sum_j V^j X^j / V_H^k,

whose gradient has zero weighted mean (6.14), so the VC integration
constraint is undisturbed.  The functional is (6.3) with these fields,

.. math::

    \Pi = \sum_k\sum_j w_{kj}\big[W_{iso}(F^{kj}) + U(\Theta^{kj})
        + p^{kj}(J^{kj} - \Theta^{kj})\big].

Unknowns ``x = [u, p, Θ]``: displacements in scikit-fem numbering, then
one p and one Θ per particle.  The bubble is condensed (6.6) exactly: for
given ``x`` a batched local Newton over all families solves
:math:`R_b^k = \sum_j w_{kj} P^{kj}\,(X^j - X_c^k) = 0` (``d × d`` systems,
to :math:`|\Delta u_b|\,|X^j - X_c^k| \le 10^{-13}`; a step is capped
at 0.2 of strain), so the residual is a
function of ``x`` alone and its derivative, by the implicit function
theorem, the condensed tangent :math:`K_{aa} - K_{ab}K_{bb}^{-1}K_{ba}`.

The tangent couples u, p, Θ (a symmetric, indefinite saddle point: the
direct solver).  p and Θ are global even in explicit runs, the cost the
thesis notes.
"""
import numpy as np

from ..discretization.assembly import FixedPattern, assemble
from ..discretization.elementwise import Elements
from ..materials import (NeoHookeIsoVol, ReturnMapError, check_moduli,
                         inverse_and_det)
from ..threads import kernel
from .dilatation import d_JFinvT, compressible_moduli
from .displacement import Hyperelastic, internal_force, material_tangent
from ..discretization.layout import is_family_basis

#: local Newton of the bubble: largest iterations, and the tolerance on
#: the change of F
BUBBLE_MAXITER, BUBBLE_TOL = 40, 1e-13
#: the largest change of the bubble's strain in one local iteration
BUBBLE_STEP = 0.2
#: halvings of a family's bubble step before it is taken anyway
BUBBLE_HALVINGS = 10


class _Group:
    """Per size group: member indices, weights, derivatives, the p/Θ
    interpolation ``Np[k, j, i]`` and the bubble gradients ``b[k, j]``."""

    def __init__(self, g, G, dx, x, V):
        self.flat, self.families, self.members = g.flat, g.families, \
            g.members
        self.G, self.dx = G, dx
        X = x[:, g.members]  # (d, k, j)
        dX = np.moveaxis(X - X[:, :, :1], 0, -1)  # (k, j, d)
        a = np.einsum("kid,kjd->kji", G[:, 0], dX)  # G^{kki}·ΔX^{kj}
        self.Np = a.copy()
        self.Np[:, :, 0] += 1.0 - a.sum(axis=-1)
        Vm = V[g.members]
        Xc = (X * Vm).sum(axis=-1) / Vm.sum(axis=-1)  # (d, k)
        self.b = np.moveaxis(X - Xc[:, :, None], 0, -1)  # (k, j, d)


class NodalPressure(Hyperelastic):
    """U2P1C (``bubble=False``, on a WTE2 basis) and Unl+P1C
    (``bubble=True``, on an MTE1 basis) on a PBG
    :class:`~skfem_pg.FamilyBasis` whose families are mastered by every
    particle; iso/vol neo-Hooke with shear modulus ``mu`` and bulk modulus
    ``K`` (see the module docstring).

    ``fields(x)`` gives the nodal ``p`` and ``Theta`` and, with the bubble,
    its amplitude ``bubble`` per family ``(n_f, d)``.

    Examples
    --------
    >>> import numpy as np, skfem as fem, skfem_pg as pg
    >>> basis = pg.FamilyBasis(fem.MeshQuad().refined(2), dim=2)
    >>> model = NodalPressure(basis, mu=40.0, K=100.0)
    >>> (model.N - model.n_u) // basis.particles.n  # p and Theta
    2

    """

    def __init__(self, basis, mu, K, bubble=True):
        if not is_family_basis(basis) or getattr(basis, "is_petrov",
                                                  False):
            raise NotImplementedError(
                "U2P1C and Unl+P1C are built on PBG family bases (got {})"
                .format(type(basis).__name__ if not is_family_basis(basis)
                        else "a Petrov–Galerkin basis"))
        if getattr(basis, "points", None) is not None:
            raise NotImplementedError(
                "U2P1C and Unl+P1C interpolate p and Theta from the "
                "master's derivatives to the members; with "
                "family_quadrature='moments' the quadrature points are not "
                "members: use the members (the default)")
        super().__init__(basis, NeoHookeIsoVol.isochoric(mu))
        (self.K,) = check_moduli(K=K)
        self.bubble = bool(bubble)
        p = basis.particles
        self.n = p.n
        basis.families.require_every_master(
            p.x, "nodal p and Theta (U2P1C / Unl+P1C on a subdomain is not "
            "built)")
        self.elements = Elements(basis)
        self.groups = [_Group(g, G, dx, p.x, p.volumes) for g, G, dx in zip(
            basis.layout, basis.grouped_gradients(),
            basis.grouped_weights())]
        L = basis.layout
        d = p.dim
        self._b = np.empty((d, 1, L.n_points))
        for gr in self.groups:
            self._b[:, 0, gr.flat] = np.moveaxis(gr.b, -1, 0)
        self._ub = np.zeros((d, L.n_families))  # warm start of the bubble
        self._ub_committed = self._ub  # of the last converged step
        self._pattern = None  # of the p, Theta and bubble blocks

    @classmethod
    def of(cls, basis, material, bubble=True):
        """From a :class:`~skfem_pg.materials.NeoHookeIsoVol`."""
        mu, K = compressible_moduli(material, "U2P1C / Unl+P1C")
        return cls(basis, mu, K, bubble=bubble).with_material(material)

    @property
    def N(self):
        return self.n_u + 2 * self.n

    @property
    def blocks(self):
        n_u, n = self.n_u, self.n
        return [("u", slice(0, n_u)), ("p", slice(n_u, n_u + n)),
                ("Theta", slice(n_u + n, n_u + 2 * n))]

    def initial(self):
        """Zero displacements and pressures, unit dilatations."""
        x = np.zeros(self.N)
        x[self.n_u + self.n:] = 1.0
        return x

    def _split(self, x):
        x = np.asarray(x, dtype=float)
        if x.shape != (self.N,):
            raise ValueError("{} unknowns: {} displacements, {} pressures "
                             "and {} dilatations ({} in all), got shape {}"
                             .format(type(self).__name__, self.n_u, self.n,
                                     self.n, self.N, x.shape))
        n_u, n = self.n_u, self.n
        return x[:n_u], x[n_u:n_u + n], x[n_u + n:]

    def _at_points(self, nodal):
        """:math:`\\sum_i N_p^{kji} a^i` in the flat layout ``(1, N_q)``."""
        out = np.empty((1, self.basis.layout.n_points))
        for gr in self.groups:
            out[0, gr.flat] = np.einsum("kji,ki->kj", gr.Np,
                                        nodal[gr.members])
        return out

    def _to_nodes(self, a):
        """:math:`\\sum_k\\sum_j w_{kj} a^{kj} N_p^{kji}` per particle."""
        out = np.zeros(self.n)
        for gr in self.groups:
            r = np.einsum("kj,kj,kji->ki", gr.dx, a[0, gr.flat], gr.Np)
            out += np.bincount(gr.members.ravel(), r.ravel(),
                               minlength=self.n)
        return out

    def _volumetric(self, F, p):
        Finv, J = inverse_and_det(F)
        return Finv, J, self.material.stress(F) + p * J * np.swapaxes(
            Finv, 0, 1)

    def _tangent_field(self, F, Finv, J, p):
        return self.material.tangent(F) + p * d_JFinvT(J, Finv)

    @kernel
    def state(self, x):
        u, p, Theta = self._split(x)
        F = super().state(u)["F"]
        p_pts, Th_pts = self._at_points(p), self._at_points(Theta)
        s = {"p": p_pts, "Theta": Th_pts}
        if self.bubble:
            F, ub, Kbb, vol = self._solve_bubble(F, p_pts)
            s.update(ub=ub, Kbb=Kbb)
        else:
            vol = None
        # the bubble's Newton ends with the stresses at F: not again
        Finv, J, P = self._volumetric(F, p_pts) if vol is None else vol
        s.update(F=F, Finv=Finv, J=J, P=P)
        return s

    def _solve_bubble(self, Fu, p):
        """The bubble amplitudes ``(d, n_f)`` with :math:`R_b = 0`, by a
        batched Newton from the last ones; should that fail (the last
        iterate of a cut step, another run's), from the last converged
        step's, then from zero; also :math:`K_{bb}` and ``(Finv, J, P)``
        at the resulting F (``None`` if it failed)."""
        error = None
        for start in (self._ub, self._ub_committed,
                      np.zeros_like(self._ub)):
            try:
                out = self._bubble_newton(Fu, p, start.copy())
            except ReturnMapError as err:  # a plastic material's local
                error = err  # Newton at an iterate: try the next start
                continue
            if out is not None:
                self._ub = out[1]
                return out
        if error is not None:  # Newton cuts the step, naming the reason
            raise error
        # no convergence (e.g. J <= 0 inside a family): let Newton cut
        return np.full_like(Fu, np.nan), self._ub, None, None

    def _bubble_newton(self, Fu, p, ub):
        """Newton on :math:`R_b^k(u_b^k) = 0`, every family at once (a
        family's bubble moves only its own points, so the families are
        independent): a step is capped at :data:`BUBBLE_STEP` of strain
        and halved, family by family, until that family's residual
        decreases (a plastic material's elastic–plastic switch made the
        full steps cycle between two states).  ``None`` if it does not
        converge, or converges to a root with J <= 0 somewhere (reached
        from the last iterate of a failed step: no bubble)."""
        E, b = self.elements, self._b
        bn = np.abs(b).max()

        def residual(ub):
            F = Fu + E.spread(ub)[:, None] * b[None]
            Finv, J, P = self._volumetric(F, p)
            Rb = E.sum(np.einsum("iJ...,J...->i...", P, b))  # (d, nf)
            return F, Finv, J, P, Rb

        F, Finv, J, P, Rb = residual(ub)
        for it in range(BUBBLE_MAXITER):
            A = self._tangent_field(F, Finv, J, p)
            Kbb = E.sum(np.einsum("iJkL...,J...,L...->ik...", A, b, b))
            Kbb = np.moveaxis(Kbb, -1, 0)  # (nf, d, d)
            try:
                dub = -np.linalg.solve(Kbb, Rb.T[..., None])[..., 0].T
            except np.linalg.LinAlgError:  # a family's K_bb is singular
                return None
            if not np.all(np.isfinite(dub)):
                return None
            step = np.abs(dub).max(axis=0) * bn  # the bubble's strain
            if step.max() <= BUBBLE_TOL:
                if not J.min() > 0:
                    return None
                # converged: the last step (below BUBBLE_TOL of strain)
                # is not taken, so F, its stresses and K_bb agree
                return F, ub, Kbb, (Finv, J, P)
            t = np.minimum(1.0, BUBBLE_STEP / np.maximum(step, 1e-300))
            r0 = np.linalg.norm(Rb, axis=0)
            for _ in range(BUBBLE_HALVINGS):
                try:
                    trial = residual(ub + dub * t)
                    worse = np.linalg.norm(trial[4], axis=0) > r0 * (
                        1 - 1e-4 * t)
                    worse &= step * t > BUBBLE_TOL  # round-off: accept
                except ReturnMapError as err:  # too wild: all shorter
                    trial, error = None, err
                    worse = np.ones_like(t, dtype=bool)
                if not worse.any():
                    break
                t[worse] *= 0.5
            else:
                if trial is None:
                    raise error
            ub = ub + dub * t
            F, Finv, J, P, Rb = trial
        return None

    def commit(self, state):
        """A step converged: its bubble is the next steps' second warm
        start (after the last iterate's); the history as for any model."""
        super().commit(state)
        if self.bubble and state.get("Kbb") is not None:
            self._ub_committed = state["ub"].copy()

    def min_J(self, state):
        if not np.all(np.isfinite(state["F"])):
            return -np.inf
        return float(min(state["J"].min(), state["Theta"].min()))

    def energy(self, state):
        Th = state["Theta"]
        U = 0.25 * self.K * (Th ** 2 - 1 - 2 * np.log(Th))
        dens = self.material.energy(state["F"]) + U + state["p"] * (
            state["J"] - Th)
        return float(np.sum(self.basis.flat_weights() * dens))

    def fields(self, x):
        _, p, Theta = self._split(x)
        out = {"p": p.copy(), "Theta": Theta.copy()}
        if self.bubble:
            out["bubble"] = self.state(x)["ub"].T.copy()
        return out

    @kernel
    def stress(self, state):
        return state["P"]

    @kernel
    def internal_force(self, state):
        r_u = assemble(internal_force, self.basis, P=state["P"])
        Th = state["Theta"]
        r_p = self._to_nodes(state["J"] - Th)
        r_t = self._to_nodes(0.5 * self.K * (Th - 1.0 / Th) - state["p"])
        return np.concatenate([r_u, r_p, r_t])

    @kernel
    def tangent(self, state):
        F, Finv, J, p = state["F"], state["Finv"], state["J"], state["p"]
        A = self._tangent_field(F, Finv, J, p)
        Kuu = assemble(material_tangent, self.basis, A=A)
        Q = J * np.swapaxes(Finv, 0, 1)
        Th = state["Theta"]
        Upp = 0.5 * self.K * (1.0 + 1.0 / Th ** 2)
        L = self.basis.layout
        d, n_u, n = self.elements.view.dim, self.n_u, self.n
        # local blocks: (rows, cols, values); the index arrays only until
        # the sparsity pattern is known (it does not change)
        half, full = ([], [], []), ([], [], [])
        indices = self._pattern is None

        def add(to, r, c, v):
            if indices:
                to[0].append(np.broadcast_to(r, v.shape).ravel())
                to[1].append(np.broadcast_to(c, v.shape).ravel())
            to[2].append(v.ravel())
        for gr in self.groups:
            k, m = gr.members.shape
            w, Np = gr.dx, gr.Np
            Qg = L.take(Q, gr)  # (c, b, k, j)
            udofs = d * gr.members[:, :, None] + np.arange(d)  # (k, i, c)
            pdofs, tdofs = n_u + gr.members, n_u + n + gr.members
            wNp = w[:, :, None] * Np  # (k, j, l)
            NpT = np.swapaxes(Np, 1, 2)  # (k, l, j)
            # K_up[k, i, c, l] = sum_j w Q_cb G_kjib Np_kjl (and K_pu)
            QG = np.einsum("cbkj,kjib->kicj", Qg, gr.G).reshape(k, m * d, m)
            add(half, udofs[..., None], pdofs[:, None, None, :],
                (QG @ wNp).reshape(k, m, d, m))
            # K_pT = -sum_j w Np Np (and K_Tp)
            add(half, pdofs[:, :, None], tdofs[:, None, :], -(NpT @ wNp))
            # K_TT = sum_j w U'' Np Np
            add(full, tdofs[:, :, None], tdofs[:, None, :],
                NpT @ (L.take(Upp, gr)[:, :, None] * wNp))
            if self.bubble:  # - K_ab K_bb^-1 K_ba over the (u, p) dofs
                b, Ag = gr.b, L.take(A, gr)  # (k, j, d), (c,b,e,L,k,j)
                # K_ub[k, i, c, e] = sum_jb G_kjib (w A_cbeL b_L)_kj
                Ab = np.einsum("cbeLkj,kjL->kjbce", Ag, w[:, :, None] * b)
                Kub = np.swapaxes(gr.G, 1, 2).reshape(k, m, m * d) \
                    @ Ab.reshape(k, m * d, d * d)
                # K_pb[k, l, e] = sum_j Np_kjl (w Q_eL b_L)_kj
                Kpb = NpT @ np.einsum("eLkj,kjL->kje", Qg, w[:, :, None] * b)
                Ka = np.concatenate([Kub.reshape(k, m * d, d), Kpb], axis=1)
                corr = -Ka @ np.linalg.solve(state["Kbb"][gr.families],
                                             np.swapaxes(Ka, 1, 2))
                a = np.concatenate([udofs.reshape(k, m * d), pdofs], axis=1)
                add(full, a[:, :, None], a[:, None, :], corr)

        if indices:
            rows = np.concatenate(half[0] + half[1] + full[0])
            cols = np.concatenate(half[1] + half[0] + full[1])
            self._pattern = FixedPattern(rows, cols, self.N)
        hv = np.concatenate(half[2])
        K = self._pattern.matrix(np.concatenate([hv, hv] + full[2]))
        Kuu.resize((self.N, self.N))
        return Kuu + K
