r"""The displacement formulation (U1, Unl, U2 and FE): hyperelasticity on any
vector basis, and the interface every formulation offers the solvers.

A *model* (this class, and those of :mod:`~skfem_pg.formulations.dilatation`
and :mod:`~skfem_pg.formulations.incompressible`) owns its fields.  Its
unknowns ``x`` (length ``model.N``) are the displacements in scikit-fem's
numbering of ``model.basis`` — always first, ``model.n_u`` of them — followed
by the global fields the formulation adds (e.g. one pressure per family for
IUnlP0); local fields (a condensed pressure and dilatation per family) live
in the state.  For ``x`` a model evaluates

* ``state(x)``: deformation gradients and whatever else it needs at the
  quadrature points,
* ``internal_force(state)``: the residual :math:`\partial\Pi/\partial x`
  without external loads (length ``N``),
* ``tangent(state)``: :math:`\partial^2\Pi/\partial x^2` (sparse ``N × N``),
* ``min_J(state)``: the smallest :math:`J = \det F` (inversion check),
* ``fields(x)``: the extra fields by name (per element / family),
* ``initial()``: the unknowns of the undeformed state (zero
  displacements and pressures, unit dilatations),
* ``commit(state)``: called by the solvers when a step has converged at
  ``state``; a model with a stateful material (J2 plasticity) makes that
  state's internal variables the committed ones (``model.history``,
  :class:`~skfem_pg.formulations.history.History`),

and names its unknowns in ``blocks`` (``(name, slice)``), so that Newton's
method measures convergence per field.  Loads, Dirichlet dofs and results
address the displacements alone, in scikit-fem numbering, whatever extra
fields exist.
"""
import numpy as np
import skfem as fem
from skfem.helpers import ddot, grad

from ..discretization.assembly import assemble
from ..discretization.elementwise import Elements
from ..materials.hyperelastic import det
from ..threads import kernel
from .history import History
from .tangents import fd_tangent
from ..discretization.layout import is_family_basis


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
    return basis.particles.dim if is_family_basis(basis) else \
        basis.mesh.dim()


class Hyperelastic:
    """Displacement-based hyperelasticity on ``basis``.

    ``tangent="fd"`` builds the tangent by central differences of the
    family forces (family bases only), as correspondence codes do.

    A stateful ``material`` (:class:`~skfem_pg.materials.J2Plasticity`) is
    bound to the model's integration points: ``model.history`` holds its
    committed internal variables, per family member :math:`(k, j)` on a
    family basis, per Gauss point on a scikit-fem basis.

    Examples
    --------
    >>> import numpy as np, skfem as fem, skfem_pg as pg
    >>> from skfem_pg.materials import NeoHooke
    >>> basis = pg.FamilyBasis(fem.MeshQuad().refined(2), dim=2)
    >>> model = Hyperelastic(basis, NeoHooke(lam=60.0, mu=40.0))
    >>> state = model.state(np.zeros(model.N))
    >>> float(np.abs(model.internal_force(state)).max()), model.min_J(state)
    (0.0, 1.0)

    """

    def __init__(self, basis, material, tangent="consistent"):
        if tangent not in ("consistent", "fd"):
            raise ValueError("tangent must be 'consistent' or 'fd'")
        if tangent == "fd" and not is_family_basis(basis):
            raise ValueError("the finite-difference tangent is built from "
                             "family forces: it needs a FamilyBasis")
        if not np.isfinite(getattr(material, "K", 0.0)):
            raise ValueError(
                "{!r} is incompressible (K = inf): a displacement "
                "formulation cannot carry it; use the IUnlP0 formulation "
                "(skfem_pg.formulations.IncompressibleP0)".format(material))
        if tangent == "fd" and getattr(material, "stateful", False):
            raise ValueError("the finite-difference tangent evaluates the "
                             "material at perturbed members; {!r} has a "
                             "history: use tangent='consistent'".format(
                                 material))
        self.basis, self.tangent_kind = basis, tangent
        self.material = (History(material, lambda: self.point_basis)
                         if getattr(material, "stateful", False)
                         else material)
        self.n_u = basis.N
        d = _dim(basis)
        self._eye = np.eye(d).reshape(d, d, 1, 1)

    @property
    def N(self):
        """Number of unknowns: displacements, then the model's global
        fields."""
        return self.n_u

    @property
    def blocks(self):
        """``(name, slice)`` of each field in the unknowns."""
        return [("u", slice(0, self.n_u))]

    def fields(self, x):
        """Extra fields of the solution ``x`` by name (none here)."""
        return {}

    def initial(self):
        """Unknowns of the undeformed, unloaded state."""
        return np.zeros(self.N)

    @property
    def history(self):
        """The :class:`~skfem_pg.formulations.history.History` of a
        stateful material, else ``None``."""
        return self.material if isinstance(self.material, History) \
            else None

    def with_material(self, material):
        """Bind the (isochoric) ``material`` the formulation evaluates at
        its points — how the mixed formulations take a stateful material
        whose volumetric part they treat themselves; returns ``self``."""
        if getattr(material, "stateful", False):
            self.material = History(material.isochoric(),
                                    lambda: self.point_basis)
        return self

    def commit(self, state):
        """A step converged at ``state``: commit its internal variables
        (nothing to do for a hyperelastic material)."""
        if self.history is not None:
            self.history.commit(state["F"])

    @property
    def point_basis(self):
        """The basis whose integration points carry the history
        (``basis``; the current one in the updated Lagrangian frame)."""
        return self.basis

    def failed(self):
        """Where the committed damage of a damage law
        (:mod:`~skfem_pg.materials.damage`) has failed the points
        (:attr:`point_basis`' integration points), else ``None``."""
        return None if self.history is None else self.history.failed()

    def fracture_energy(self):
        """The elastic energy the failed points released when they failed
        (:mod:`~skfem_pg.materials.damage`), integrated; ``None`` without
        a damage law.  Part of the internal work an explicit run records
        as dissipation."""
        r = None if self.history is None else self.history.released()
        return None if r is None else self._point_integral(r)

    def closure_energy(self):
        """What the trapezoid of the internal work booked beyond the
        failed points' energy where they close and open (the kink of
        their pressure at :math:`J = 1`, :meth:`~skfem_pg.materials.
        plasticity.Response.closure_step`), integrated; ``None`` without a
        damage law.  The drivers' records carry it apart from the
        released energy, and their balance takes it off."""
        r = None if self.history is None else self.history.closure()
        return None if r is None else self._point_integral(r)

    def _point_integral(self, r):
        r""":math:`\sum w\, r` of point data ``r`` over
        :attr:`point_basis` (its :class:`Elements` cached: the explicit
        driver asks for the closure every step)."""
        E = getattr(self, "_point_elements", None)
        if E is None or E.basis is not self.point_basis:
            E = self._point_elements = Elements(self.point_basis)
        return float(E.sum(r).sum())

    def plastic_strain(self):
        """The committed accumulated plastic strain :math:`\\bar e_p`
        (the hardening variable) per element — its weighted mean over the
        element's points: per family (particle) on a family basis, per
        cell on a scikit-fem basis — and its maximum over all points;
        ``None`` for a material without history."""
        h = self.history
        if h is None:
            return None
        E = Elements(self.point_basis)
        a = h.alpha()
        if a is None:
            a = np.zeros(E.point_shape)
        return E.sum(a) / E.volumes, float(a.max(initial=0.0))

    @kernel
    def state(self, u):
        """``{"F": ...}`` at the quadrature points: for a family basis in
        the unpadded flat layout ``(d, d, 1, N_q)``
        (:mod:`skfem_pg.discretization.layout`),
        so the material is evaluated only at real members."""
        return {"F": self.deformation_gradient(u)}

    def deformation_gradient(self, u):
        r""":math:`F = I + \nabla u` at the points (a crack-aware model
        continues it from its last update)."""
        if is_family_basis(self.basis):
            return self.basis.interpolate(u, flat=True).grad + self._eye
        return self.basis.interpolate(u).grad + self._eye

    def rate_gradient(self, w):
        """The gradient of the nodal displacement-dof vector ``w`` at the
        points where the material lives, in the layout of ``state(u)["F"]``
        — how a driver gives a rate-dependent material its velocity
        gradient (:mod:`skfem_pg.solvers.rates`)."""
        w = np.asarray(w, dtype=float)[:self.n_u]
        if is_family_basis(self.point_basis):
            return self.point_basis.interpolate(w, flat=True).grad
        return self.point_basis.interpolate(w).grad

    def energy(self, state):
        """Stored energy :math:`\\sum w\\, W(F)` of ``state``."""
        basis = self.point_basis
        dx = (basis.flat_weights() if is_family_basis(basis)
              else basis.dx)
        return float(np.sum(dx * self.material.energy(state["F"])))

    def min_J(self, state):
        return float(det(state["F"]).min())

    @kernel
    def stress(self, state):
        return self.material.stress(state["F"])

    @kernel
    def internal_force(self, state):
        return assemble(internal_force, self.point_basis,
                        P=self.stress(state))

    @kernel
    def tangent(self, state):
        if self.tangent_kind == "fd":
            return fd_tangent(self.basis, self.material, state["F"])
        return assemble(material_tangent, self.point_basis,
                        A=self.material.tangent(state["F"]))
