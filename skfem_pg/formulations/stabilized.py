r"""Under-integrated U1 with stabilization (thesis 6.3): U1SUnl and U1SIG.

U1 (6.17) evaluates the material once per family, at the master, with the
static Taylor expansion (WTE1) gradient :math:`F^{kk}`:
:math:`\Pi = \sum_k V^k W(F^{kk})` — one return map per particle, but rank
deficient (the classical correspondence zero-energy modes).  Both
stabilizations keep the material evaluation (and the history
:math:`h^{kk}`) at the master and add an elastic energy that is zero for
linear fields.

**U1SUnl** (6.18)–(6.20), full-integration stabilization:

.. math::

    \Pi = \sum_k \Big[V^k\big(W(F^{kk}; h^{kk}) - \tilde W^k(F^{kk})\big)
          + \sum_{j\in H^k} w_{kj}\, \tilde W^k(F^{kj})\Big],

:math:`F^{kj}` the MTE1 (Unl) gradients with their own bond and VC
corrections, :math:`\tilde W^k` the elastic energy (2.46) at the master's
committed plastic metric :math:`C_p^{-1,kk}`
(:class:`~skfem_pg.materials.frozen.FrozenPlasticity`) with

.. math::

    \tilde E = \min[E, \max(\eta E, |\sigma_{vM}/\alpha|)], \qquad
    \tilde\nu = \min(0.49, \nu), \qquad \eta = 10^{-3}   \qquad (6.20)

from the master's committed :math:`\sigma_{vM}` and :math:`\alpha` —
frozen during a load step, like U1SIG's :math:`\tilde A` [interpretation:
the thesis does not say when :math:`\tilde E` is updated; freezing it keeps
the step's Newton exact].  An elastic material with :math:`\nu \le 0.49`
makes U1SUnl equal to Unl.

**U1SIG** (6.21)–(6.28), implicit-gradient stabilization: the Taylor
expansion :math:`P' = P^k + \tilde A^k : (F' - F^k)` integrated over a
particle of second moment :math:`M_2^k` gives

.. math::

    \Pi = \sum_k V^k W(F^{kk}; h^{kk})
        + \tfrac12 \sum_k M_{xx}^k \sum_E \partial_E H^k : \tilde A^k :
          \partial_E H^k,
    \qquad \partial_E H^k = \sum_i u^i\otimes
          \frac{\partial^2 N^{kki}_{MLS1}}{\partial X\,\partial X_E},

(6.25), (6.26), (6.28), with :math:`\tilde A^k` the elastic tangent of
:math:`\tilde W^k` at the committed master state, frozen per load step
(Bubnov–Galerkin), and the MLS1 second derivatives of
:func:`~skfem_pg.discretization.shape.least_squares.mls1_master_hessians`.
The moment :math:`M_{xx}` of a particle of volume :math:`V`:

* 3-D (6.27), a sphere: :math:`\frac{4\pi}{15}R^5 = \frac{(3/\pi)^{2/3}}
  {10\cdot 2^{1/3}} V^{5/3}`, :math:`R = (3V/4\pi)^{1/3}`;
* 2-D, **not in the thesis**: a disk of area :math:`A = V` (unit
  thickness), :math:`\int x^2 dA = \frac\pi4 R^4 = A^2/(4\pi)`,
  :math:`R = \sqrt{A/\pi}` (:func:`second_moment`).

U1's zero-energy modes disappear with either stabilization
(``tests/test_stabilized.py`` counts the free block's zero eigenvalues).
"""
import numpy as np

from ..discretization.assembly import assemble, assemble_local, batched_view
from ..discretization.basis import FamilyBasis
from ..discretization.elementwise import Elements
from ..discretization.shape.least_squares import mls1_master_hessians
from ..materials.frozen import FrozenPlasticity
from ..materials.hyperelastic import NeoHookeIsoVol, StVenantKirchhoff, \
    NeoHooke, LinearElastic, det
from ..materials.plasticity import J2Plasticity
from ..threads import kernel
from .displacement import Hyperelastic, internal_force, material_tangent

#: (6.20): the smallest stabilization modulus relative to E, and the
#: largest stabilization Poisson ratio
ETA = 1e-3
NU_MAX = 0.49


def _moduli(material, formulation):
    """``(mu, K)`` of the elastic part of ``material``."""
    if isinstance(material, (NeoHookeIsoVol, J2Plasticity)):
        mu, K = material.mu, material.K
    elif isinstance(material, (NeoHooke, StVenantKirchhoff, LinearElastic)):
        mu, K = material.mu, material.lam + 2.0 * material.mu / 3.0
    else:
        raise ValueError("{} needs a material with elastic constants "
                         "(mu, K), got {!r}".format(formulation, material))
    if not np.isfinite(K) or K <= 0:
        raise ValueError("{} evaluates the material at the master in a "
                         "displacement formulation: it needs a finite bulk "
                         "modulus K > 0, got {!r}".format(formulation,
                                                          material))
    return float(mu), float(K)


def stabilized_moduli(mu, K, sigma_vm, alpha, eta=ETA, nu_max=NU_MAX):
    r"""``(mu~, K~)`` of (6.20): :math:`\tilde E = \min[E, \max(\eta E,
    |\sigma_{vM}/\alpha|)]` (``E`` where :math:`\alpha = 0`),
    :math:`\tilde\nu = \min(0.49, \nu)`; ``sigma_vm``, ``alpha`` arrays of
    the same shape."""
    E = 9.0 * K * mu / (3.0 * K + mu)
    nu = (3.0 * K - 2.0 * mu) / (2.0 * (3.0 * K + mu))
    alpha = np.asarray(alpha, float)
    secant = np.abs(np.asarray(sigma_vm, float)) / np.where(alpha > 0,
                                                            alpha, 1.0)
    Et = np.where(alpha > 0, np.minimum(E, np.maximum(eta * E, secant)), E)
    nut = min(nu_max, nu)
    return Et / (2.0 * (1.0 + nut)), Et / (3.0 * (1.0 - 2.0 * nut))


def second_moment(volumes, dim):
    r""":math:`M_{xx}` of particles of volume ``volumes`` (6.27): a
    sphere in 3-D, :math:`(4\pi/15)R^5`; a disk in 2-D (not in the thesis),
    :math:`A^2/(4\pi)`."""
    V = np.asarray(volumes, float)
    if dim == 3:
        return (3.0 / np.pi) ** (2.0 / 3.0) / (10.0 * 2.0 ** (1.0 / 3.0)) \
            * V ** (5.0 / 3.0)
    if dim == 2:
        return V ** 2 / (4.0 * np.pi)
    raise ValueError("second_moment: dim must be 2 or 3, got {}".format(dim))


def under_integrated(basis):
    """The U1 basis on the families of ``basis``: WTE1 without bond
    correction — its derivatives are the master's for every member, so
    with the PBG weights (which sum to :math:`V^k`) every form integrates
    :math:`V^k f(F^{kk})` — VC-corrected (V3, same boundary variant, VC
    solver and tolerance) if ``basis`` is; ``basis`` itself if it already
    is one."""
    if not isinstance(basis, FamilyBasis) or basis.is_petrov:
        raise ValueError("U1SUnl / U1SIG are built on a PBG FamilyBasis, "
                         "got {}".format(type(basis).__name__))
    if basis.shape == "WTE1" and not basis.bond and basis.vc in (None, "V3"):
        return basis
    if basis.vc not in (None, "V3", "V5"):
        raise ValueError("U1SUnl / U1SIG: first-order VC (V3, V5) or none, "
                         "got vc={!r}".format(basis.vc))
    on_ranks = {}
    part = getattr(basis, "distributed", None)
    if part is not None:  # a rank's part: its VC is solved over the ranks
        on_ranks["distributed"] = part
        if basis.vc is not None:
            on_ranks["area_vectors"] = part.area_vectors()[:, part.local]
    return FamilyBasis(basis.particles, families=basis.families,
                       shape="WTE1", bond=False,
                       vc=None if basis.vc is None else "V3",
                       vc_boundary=basis.vc_boundary, dim=basis.ncomp,
                       vc_solver=basis.spec.vc_solver,
                       vc_tolerance=basis.spec.vc_tolerance,
                       weight_exponent=basis.weight_exponent,
                       weights=basis.weights, **on_ranks)


class _MasterModel(Hyperelastic):
    """What U1SUnl and U1SIG share: the material (and its history) at the
    masters of the under-integrated basis ``u1``, the committed master
    state, and the stabilization moduli (6.20) frozen per step."""

    name = "U1S"
    #: the explicit driver's stable-step estimate forms its tangent
    #: products from internal forces (:func:`skfem_pg.solvers.explicit.
    #: max_frequency`): the material at the masters makes a force far
    #: cheaper than an assembled tangent (benchmarks/README.md, section
    #: explicit_mpi)
    matrix_free_estimate = True

    def __init__(self, basis, u1, material):
        self.mu0, self.K0 = _moduli(material, self.name)
        super().__init__(basis, material)
        self._F_committed = None
        self._bind(u1)

    def _bind(self, u1):
        """Derive what the model keeps of the under-integrated basis
        ``u1`` (a crack-aware model binds the basis of its intact cells
        after each rebuild, :mod:`~skfem_pg.formulations.crack_aware`)."""
        self.u1 = u1
        self._E1 = Elements(u1)
        self._master_flat = u1.families.offsets[:-1]
        self._G0 = None  # the masters' derivatives, built when asked
        self._frozen = (None, None)  # (key, (mu~, K~, Cp_inv, F))

    def master_F(self, u):
        """:math:`F^{kk}` ``(d, d, nf)``: the WTE1 gradient at the
        masters (each family's first member), from the masters' rows of
        the gradients alone."""
        d = self._eye.shape[0]
        U = np.asarray(u, dtype=float).reshape(-1, d)
        F = np.empty((d, d, len(self._master_flat)))
        for g, G0 in self._master_gradients():
            gr = np.swapaxes(U[g.members], 1, 2) @ G0  # (nf_b, a, b)
            F[:, :, g.families] = np.moveaxis(gr, 0, -1)
        return F + self._eye[:, :, :, 0]

    def _master_gradients(self):
        """Per size group of ``u1``: ``(group, G0)`` with ``G0`` ``(nf_b,
        m, d)`` the masters' derivatives :math:`G^{kki}` (cached)."""
        if self._G0 is None:
            self._G0 = [(g, np.ascontiguousarray(G[:, 0]))
                        for g, G in zip(self.u1.layout,
                                        self.u1.grouped_gradients())]
        return self._G0

    def _spread(self, a):
        """Per-family data ``(..., nf)`` at every member of ``u1``."""
        return self._E1.spread(a)

    def _committed(self):
        """``(key, F, Cp_inv, alpha)`` of the committed master state
        (identity and virgin before the first step); ``key`` changes
        whenever the committed state does."""
        nf, d = len(self._master_flat), self._eye.shape[0]
        h = self.history
        c = None if h is None else h.committed
        if c is not None and "F" in c:  # also after a checkpoint restore
            return c, c["F"], c["Cp_inv"], c["alpha"]
        if self._F_committed is not None and c is None:
            return self._F_committed, self._F_committed, np.broadcast_to(
                np.eye(3)[:, :, None], (3, 3, nf)), np.zeros(nf)
        F = np.broadcast_to(np.eye(d)[:, :, None], (d, d, nf))
        if c is None:
            return "virgin", F, np.broadcast_to(np.eye(3)[:, :, None],
                                                (3, 3, nf)), np.zeros(nf)
        return c, F, c["Cp_inv"], c["alpha"]

    def frozen(self):
        r"""``(mu~, K~, Cp_inv, F)`` of the committed master state: the
        stabilization moduli (6.20) per family (zero where the master has
        failed, :mod:`~skfem_pg.materials.damage`), the master's plastic
        metric and deformation gradient."""
        key, F, Cp, alpha = self._committed()
        if self._frozen[0] is not key:
            vm = FrozenPlasticity(self.mu0, self.K0, Cp).von_mises(F)
            mu, K = stabilized_moduli(self.mu0, self.K0, vm, alpha)
            failed = self.failed()
            if failed is not None and failed.any():
                # a failed master carries no stabilization either
                mu, K = np.where(failed, 0.0, mu), np.where(failed, 0.0, K)
            self._frozen = (key, (mu, K, Cp, F))
        return self._frozen[1]

    @kernel
    def state(self, u):
        return {"u": u, "F1": self.master_F(u)}

    def min_J(self, state):
        return float(det(state["F1"]).min())

    def commit(self, state):
        """A step converged: commit the master history and the state the
        next step's stabilization is frozen at."""
        F1 = np.array(state["F1"])
        if self.history is not None:
            self.history.commit(state["F1"])
            self.history.committed["F"] = F1
        self._F_committed = F1

    def plastic_strain(self):
        """:math:`\\bar e_p` per family (its master's) and its maximum."""
        h = self.history
        if h is None:
            return None
        a = h.alpha()
        if a is None:
            a = np.zeros(len(self._master_flat))
        return np.array(a), float(a.max(initial=0.0))

    def _point_integral(self, r):
        """Point data at the masters integrated, :math:`\\sum_k V^k r^k`
        (:meth:`_master_energy`): the released and the closure energy of
        :meth:`Hyperelastic.fracture_energy
        <skfem_pg.formulations.Hyperelastic.fracture_energy>` and
        :meth:`~skfem_pg.formulations.Hyperelastic.closure_energy` over the
        failed masters."""
        return self._master_energy(r)

    def _master_force(self, P1):
        r""":math:`\sum_k V^k P^k : \delta F^{kk}` (the U1 weights sum to
        :math:`V^k` and every member carries the master's derivatives),
        from the masters' rows alone."""
        d = self._eye.shape[0]
        V = self._E1.volumes
        f = np.zeros((self.u1.N // d, d))
        for g, G0 in self._master_gradients():
            P = np.moveaxis(P1[:, :, g.families], -1, 0)  # (nf_b, a, b)
            fk = (G0 @ np.swapaxes(P, 1, 2)) * V[g.families, None, None]
            for a in range(d):
                f[:, a] += np.bincount(g.members.ravel(),
                                       weights=fk[..., a].ravel(),
                                       minlength=f.shape[0])
        return f.ravel()

    def _master_tangent(self, A1):
        return assemble(material_tangent, self.u1, A=self._spread(A1))

    def _master_energy(self, W1):
        return float(np.sum(self._E1.volumes * W1))


class U1SUnl(_MasterModel):
    """U1SUnl (6.18)–(6.20) on the MTE1 (Unl) ``basis``; the
    under-integrated WTE1 part on :func:`under_integrated` of it (VC done
    twice, as the thesis says).  ``basis`` is the model's basis (dofs,
    loads).

    Examples
    --------
    >>> import numpy as np, skfem as fem, skfem_pg as pg
    >>> basis = pg.FamilyBasis(fem.MeshQuad().refined(2), dim=2)
    >>> from skfem_pg.materials import NeoHooke
    >>> model = U1SUnl(basis, NeoHooke(lam=60.0, mu=40.0))
    >>> state = model.state(np.zeros(model.N))
    >>> float(np.abs(model.internal_force(state)).max())
    0.0

    """

    name = "U1SUnl"

    def __init__(self, basis, material):
        if not isinstance(basis, FamilyBasis) or basis.shape != "MTE1" \
                or basis.is_petrov:
            got = ("a {} {} basis".format(basis.method, basis.shape)
                   if isinstance(basis, FamilyBasis)
                   else type(basis).__name__)
            raise ValueError("U1SUnl stabilizes with the full Unl "
                             "integration of a Bubnov-Galerkin basis: it "
                             "needs a PBG MTE1 basis, got {} (no PPG form "
                             "of U1SUnl is in Table 7.1)".format(got))
        super().__init__(basis, under_integrated(basis), material)
        self._E2 = Elements(basis)

    @classmethod
    def of(cls, basis, material):
        return cls(basis, material)

    def _stabilization(self):
        """:math:`\\tilde W^k` at the masters and at the Unl members."""
        mu, K, Cp, _ = self.frozen()
        at_master = FrozenPlasticity(mu, K, Cp)
        at_members = FrozenPlasticity(self._E2.spread(mu),
                                      self._E2.spread(K), self._E2.spread(Cp))
        return at_master, at_members

    @kernel
    def state(self, u):
        s = super().state(u)
        s["F"] = self.basis.interpolate(u, flat=True).grad + self._eye
        return s

    def min_J(self, state):
        return min(super().min_J(state), float(det(state["F"]).min()))

    def energy(self, state):
        Wm, Wj = self._stabilization()
        F1 = state["F1"]
        return (self._master_energy(self.material.energy(F1)
                                    - Wm.energy(F1))
                + float(np.sum(self.basis.flat_weights()
                               * Wj.energy(state["F"]))))

    @kernel
    def internal_force(self, state):
        Wm, Wj = self._stabilization()
        F1 = state["F1"]
        return (self._master_force(self.material.stress(F1) - Wm.stress(F1))
                + assemble(internal_force, self.basis,
                           P=Wj.stress(state["F"])))

    @kernel
    def tangent(self, state):
        Wm, Wj = self._stabilization()
        F1 = state["F1"]
        return (self._master_tangent(self.material.tangent(F1)
                                     - Wm.tangent(F1))
                + assemble(material_tangent, self.basis,
                           A=Wj.tangent(state["F"])))


class U1SIG(_MasterModel):
    """U1SIG (6.21)–(6.28) on the under-integrated WTE1 ``basis``
    (:func:`under_integrated` of the given one).

    Examples
    --------
    >>> import numpy as np, skfem as fem, skfem_pg as pg
    >>> from skfem_pg.materials import NeoHooke
    >>> basis = pg.FamilyBasis(fem.MeshQuad().refined(2), dim=2, shape="WTE1",
    ...                        bond=False)
    >>> model = U1SIG(basis, NeoHooke(lam=60.0, mu=40.0))
    >>> state = model.state(np.zeros(model.N))
    >>> float(np.abs(model.internal_force(state)).max())
    0.0

    """

    name = "U1SIG"

    def __init__(self, basis, material):
        u1 = under_integrated(basis)
        super().__init__(u1, u1, material)

    def _bind(self, u1):
        super()._bind(u1)
        p, fam = u1.particles, u1.families
        self.hessians = mls1_master_hessians(p.x, p.volumes, fam,
                                             n=u1.weight_exponent)
        self.M2 = second_moment(p.volumes[fam.masters], p.dim)
        self._Ks = (None, None)
        self._At = (None, None)

    @classmethod
    def of(cls, basis, material):
        return cls(basis, material)

    def stabilization_matrix(self):
        r"""The sparse :math:`\sum_k M_{xx}^k \sum_E B_E^{kT}\tilde A^k
        B_E^k` of (6.25), :math:`\tilde A^k` the elastic tangent of the
        committed master state (frozen per step)."""
        A = self._frozen_tangent()
        key = self._frozen[0]
        if self._Ks[0] is key and key is not None:
            return self._Ks[1]
        H, M2 = self.hessians, self.M2
        view = batched_view(self.u1)

        def local_matrices(bi, blk, sl):
            k = blk.index[sl]
            Hk = H[k, :blk.nloc]  # (ne, m, d, d): [k, i, B, E]
            Y = np.einsum("kiBE,kABCD->kAiCDE", Hk, A[k])
            return M2[k, None, None, None, None] * np.einsum(
                "kAiCDE,klDE->kAiCl", Y, Hk)

        Ks = assemble_local(self.u1, local_matrices, view, transposed=True)
        self._Ks = (key, Ks)
        return Ks

    def _frozen_tangent(self):
        r""":math:`\tilde A^k` ``(nf, d, d, d, d)`` of the committed master
        state, cached with it."""
        mu, K, Cp, F = self.frozen()
        key = self._frozen[0]
        if self._At[0] is not key or key is None:
            A = FrozenPlasticity(mu, K, Cp).tangent(np.ascontiguousarray(F))
            self._At = (key, np.ascontiguousarray(np.moveaxis(A, -1, 0)))
        return self._At[1]

    def stabilization_force(self, u):
        r"""The stabilization's force without its matrix:
        :math:`f_{Ai} = M_{xx}^k \sum_{BE} \partial^2_{BE} N^{kki}\,
        (\tilde A^k : \partial_E H^k)_{AB}`, :math:`\partial_E H^k_{CD} =
        \sum_l u^l_C\, \partial^2_{DE} N^{kkl}` — what an explicit step
        needs, where :math:`\tilde A^k` changes with every committed step
        and assembling the matrix would cost far more than the force."""
        A, H, M2 = self._frozen_tangent(), self.hessians, self.M2
        d = A.shape[1]
        U = np.asarray(u, dtype=float).reshape(-1, d)
        f = np.zeros_like(U)
        for blk in batched_view(self.u1).blocks:
            k, conn = blk.index, blk.conn
            Hk = H[k, :blk.nloc]  # (ne, m, d, d): [k, i, B, E]
            ne, m = conn.shape
            Hf = Hk.reshape(ne, m, d * d)
            # batched products instead of einsums (5x faster):
            # G_CDE = sum_l U_lC H_lDE; S_ABE = A_ABCD G_CDE;
            # f_iA = sum_BE H_iBE S_ABE
            G = np.swapaxes(U[conn], 1, 2) @ Hf  # (ne, C, DE)
            S = A[k].reshape(ne, d * d, d * d) @ G.reshape(ne, d, d, d) \
                .reshape(ne, d * d, d)  # (ne, AB, E)
            fk = M2[k, None, None] * (Hf @ np.swapaxes(
                S.reshape(ne, d, d * d), 1, 2))  # (ne, i, A)
            for a in range(d):
                f[:, a] += np.bincount(conn.ravel(), weights=fk[..., a]
                                       .ravel(), minlength=f.shape[0])
        return f.ravel()

    def energy(self, state):
        u = state["u"]
        return (self._master_energy(self.material.energy(state["F1"]))
                + 0.5 * float(u @ self.stabilization_force(u)))

    @kernel
    def internal_force(self, state):
        return (self._master_force(self.material.stress(state["F1"]))
                + self.stabilization_force(state["u"]))

    @kernel
    def tangent(self, state):
        return (self._master_tangent(self.material.tangent(state["F1"]))
                + self.stabilization_matrix())
