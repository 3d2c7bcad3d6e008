r"""Crack-aware families: the displacement formulation whose families stop
at the crack (beyond the thesis; its outlook, 8.1).

In the thesis' total Lagrangian run with damage, a failed point carries no
deviatoric stress and no tension, but the families keep their members: a
family whose master lies on one side of a crack still differentiates the
displacements of members on the other side, and the broken parts stay
connected through their shape functions.  The thesis proposes to remove
the members across the crack, to recompute the shape functions in the
initial (semi-total Lagrangian) or current configuration, and to let the
new crack surface enter the VC correction, only when needed.  This module
does that on particles collocated from a mesh's vertices with the mesh
family rule (the families are the vertices of the cells around the
master):

* **the crack is a set of failed cells** of the collocation mesh
  [choice made here]: a cell fails when at least ``fraction`` of the
  integration points :math:`(k, j)` it holds — master :math:`k` and
  member :math:`j` both vertices of the cell — have failed
  (:mod:`~skfem_pg.materials.damage`).  Pieces are cells connected
  through facets (:func:`~skfem_pg.discretization.cracks.separate`, the
  crack's geometry as functions of the mesh): where two pieces touch at a vertex
  only (a pinch, which the vertex' family would bridge; it makes the VC
  system near-singular — measured: derivatives of 1e14 on the two-hole
  plate), the cells of the smaller piece at that vertex fail too; a cell
  of which the crack leaves two or more vertices with this cell alone (a
  flap, held by one facet or less) fails too (with two such cells the VC
  system of the two-hole plate left a residual of 6e-2, without them
  1.5e-14); and a piece with fewer than
  ``min_piece`` vertices fails whole (debris: its particles keep their
  mass and move freely);
* **the particles are collocated again from the intact cells**
  (:meth:`Particles.from_mesh <skfem_pg.Particles.from_mesh>` with the
  intact cells as the element subset): volumes are the intact cells'
  lumped to their vertices, a vertex of no intact cell is inactive, and the
  FE-consistent area vectors :math:`A^i` are those of the intact region's
  boundary — **the crack faces included**, so the VC correction (5.18) of
  the new basis integrates each piece's divergence theorem over its own
  closed surface;
* **the families, shape functions, bond and VC corrections are rebuilt**
  with the basis' own options on these particles; the mesh rule then
  builds the families from the intact cells, and the nearest-neighbour
  rule (``families="nearest"``, the kNN recipe) takes the nearest among
  the particles the intact cells connect and those sharing a cell
  (:func:`~skfem_pg.discretization.families.nearest`), so no family spans
  a failed cell.  The VC correction is the local one (``vc="local"``,
  the default, below) or the basis' own (``vc="basis"``); an update (its
  cost: :attr:`CrackAware.update_seconds`) runs only in steps in which
  cells fail;
* **semi-total Lagrangian gradients**: after an update at :math:`u_c`,

  .. math::

      F = F_c + \sum_i (u^i - u_c^i) \otimes G^{kji},

  :math:`G` the rebuilt (reference) derivatives and :math:`F_c` the
  committed deformation gradient at the update, carried per point
  :math:`(k, j)`; the deformation is
  continuous across an update, and before the first update this is the
  total Lagrangian formulation exactly.  The committed history follows
  the points (:func:`~skfem_pg.formulations.updated_lagrange.
  remap_points`); a new point :math:`(k, j)` (a family the update gave
  a member it did not have) takes :math:`F_c` and the history of the
  point at its particle, :math:`(j, j)` (a failure and a tracked crack's
  line belong to the material there);
* **energy**: the stored energy of the points an update removes, and the
  change of the remaining points' weights, is released: it is added to
  :meth:`CrackAware.fracture_energy` (part of the dissipation an explicit
  run records).  The second part has either sign: the quadrature weights
  (4.30) of the members a family keeps can grow, and an update can add
  stored energy (measured on the two-hole plate: up to 40 N mm at one
  update, against 900 N mm stored).  The drivers book the work of the
  step of an update with the new basis' force, so they correct the
  released energy by half the removed forces' work over that step
  (:meth:`CrackAware.book_removed_work`, from
  :func:`~skfem_pg.solvers.dynamics.book_rebuild`): the internal work is
  then the stored plus the released energy to :math:`O(\Delta t^2)`
  (issue 51).  The driver's energy balance does not depend on it (it
  counts the work of the forces).

On MPI ranks (a basis from :meth:`Partition.basis
<skfem_pg.distributed.Partition.basis>`) the failed points of each cell
are counted over the ranks
(:func:`~skfem_pg.discretization.cracks.failure_counts`, one reduction), so
that every rank fails the same cells, and each rank rebuilds its part of
the basis on the intact cells, on the local particles of the first one
(:meth:`~skfem_pg.distributed.Partition.restricted`): the dofs, the
halo exchange and the lumped mass stay.  The rebuild of a
``vc_solver="local"`` basis needs no communication.

**Which VC correction** (issue 51, ``benchmarks/fracture_energy.py``;
the default ``vc="local"``): on unstructured triangles the global
correction of a rebuilt basis makes the families along the crack faces
stiff.  On the mode-I plate at h = 1 mm, after 210 updates, the largest
derivative weight was 33 times the intact body's and the highest
frequency 17 times; the stable step collapsed and the run stopped.  The
local correction (``vc_solver="local"``, boundary min-norm) kept them at
1.5 and 0.9 times, and that run completed.  So the families on the
intact cells take the local correction from the start, whatever the
basis' own; ``vc="basis"`` keeps the basis' (global) one.  With it
Kalthoff–Winkler on gmsh triangles completed at 4, 2 and 1 mm (23,606
particles), the crack angles 44/56, 60/57 and 65/69 degrees (upper/lower;
the experiment's is about 70), and on the square grid 73 degrees at 4 mm
(the global correction: 90).

:class:`CrackAwareUnlP0` does the same for PBG UnlP0 (its per-family
pressure projections rebuilt with the families), :class:`CrackAwareU1SIG`
for U1SIG (the material at the masters).

The thesis' variant — connectivity kept — is the plain
:class:`~skfem_pg.formulations.Hyperelastic` model on the same basis and
material.  After an update :meth:`CrackAware.commit` returns ``True``, and
the time integrators evaluate the internal force again on the new basis
before they use it.
"""
import time

import numpy as np

from ..discretization.basis import FamilyBasis
from ..discretization import parts
from ..discretization.cracks import failure_counts, pieces, separate
from ..discretization.particles import Particles
from ..discretization.elementwise import Elements
from ..errors import FamilyError, describe_particle
from ..threads import kernel
from .dilatation import MeanDilatation, compressible_moduli
from .displacement import Hyperelastic
from .history import History
from .stabilized import U1SIG
from .updated_lagrange import carry_points, point_keys


def cell_failure(basis, cells, failed, keys=None):
    """The failed share of the integration points each cell holds: points
    :math:`(k, j)` of ``basis`` with master ``k`` and member ``j`` both
    vertices of the cell (``cells``: ``(n_vertices, n_cells)``);
    ``failed``: per flat point of ``basis``, or per point of ``keys``
    (:math:`k n + j`; U1SIG: its masters, :math:`k n + k`)."""
    keys = point_keys(basis) if keys is None else keys
    bad, held = failure_counts(keys, basis.particles.n, cells, failed)
    return bad / np.maximum(held, 1)


class _CrackHistory(History):
    """The material's history plus the crack (intact cells, the update's
    :math:`u_c`, :math:`F_c` and released energy) in checkpoints: a
    restore rebuilds the model's basis on the saved intact cells before
    the point arrays are restored."""

    def __init__(self, material, model):
        super().__init__(material, lambda: model.point_basis)
        self._model = model

    def save(self):
        out = super().save() or {}
        out.update(self._model.crack_state())
        return out

    def mismatch(self, saved):
        """Why a checkpoint's arrays do not fit this model (its crack on
        another mesh), or ``None``: the point arrays are checked against
        the basis the crack rebuilds, in :meth:`restore`."""
        intact = saved.get("crack_intact")
        if intact is None:
            return "the checkpoint holds no crack (not a CrackAware run)"
        if intact.shape != self._model.intact.shape:
            return "its crack has {} cells, the mesh {}".format(
                intact.shape[0], self._model.intact.shape[0])
        return None

    def restore(self, saved):
        saved = dict(saved or {})
        crack = {k: saved.pop(k) for k in list(saved)
                 if k.startswith("crack_")}
        if crack:
            self._model.restore_crack(crack)
        n = self._model._n_points()
        for k, v in saved.items():
            if np.shape(v)[-1] != n:
                raise ValueError("history {!r} at {} points, the rebuilt "
                                 "basis has {}".format(k, np.shape(v)[-1],
                                                       n))
        super().restore(saved or None)


def _check_crack_inputs(basis, material, fraction, what):
    """Named errors for what crack-aware families cannot take (on a rank
    of a :class:`~skfem_pg.distributed.Partition`, whose families follow
    the mesh rule, the partition's particles are checked)."""
    part = getattr(basis, "distributed", None)
    p = basis.particles if part is None else part.particles
    if p.kind != "vertices" or p.mesh is None:
        raise ValueError("crack-aware families remove failed cells of "
                         "the collocation mesh: the particles must be "
                         "a mesh's vertices (Particles.from_mesh)")
    why = None if part is not None else \
        parts.refusal("crack_rebuild", basis.spec.parts)
    if why is not None:  # a rank's families follow the partition's rule
        raise ValueError(why)
    damage = getattr(material, "damage", None)
    if not getattr(material, "stateful", False) or damage is None:
        raise ValueError("{!r} has no damage law: nothing can fail "
                         "(J2Plasticity(..., damage=JohnsonCookDamage"
                         "(...)))".format(material))
    if not 0.0 < float(fraction) <= 1.0:
        raise ValueError("fraction must be in (0, 1], got {!r}".format(
            fraction))


class _Crack:
    """What the crack-aware models share (module docstring): the intact
    cells, when they fail, the update's bookkeeping, checkpoints.  A model
    adds :meth:`_keys` (its points as :math:`k n + j`), :meth:`_carry`
    (the history and :math:`F_c` onto a new basis), :meth:`_set_basis`
    and :meth:`_n_points`."""

    def _init_crack(self, basis, fraction, min_piece, vc):
        part = getattr(basis, "distributed", None)
        #: on MPI ranks: the partition and the local particles of the
        #: whole body's basis (every rebuild keeps them)
        self._part = part
        self._local = None if part is None else part.local.copy()
        particles = basis.particles if part is None else part.particles
        self.material = _CrackHistory(self.material.material, self)
        self.fraction = float(fraction)
        d = particles.dim
        self.min_piece = d + 2 if min_piece is None else int(min_piece)
        if self.min_piece < d + 1:
            raise ValueError("min_piece must be at least dim + 1 = {}, got "
                             "{}".format(d + 1, min_piece))
        mesh = particles.mesh
        self.intact = np.zeros(mesh.t.shape[1], dtype=bool)
        self.intact[np.arange(mesh.t.shape[1]) if particles.elements is None
                    else particles.elements] = True
        self.u_c = np.zeros(self.N)
        self.F_c = None  # the identity until the first update
        self.released_at_updates = 0.0
        #: the closure energy (:meth:`closure_energy`) of the points the
        #: updates removed
        self.closure_at_updates = 0.0
        self.updates, self.update_seconds, self.update_log = 0, 0.0, []
        self._n_failed = 0
        if vc not in ("local", "basis"):
            raise ValueError("vc must be 'local' (the local VC correction "
                             "on the intact cells) or 'basis' (the basis' "
                             "own), got {!r}".format(vc))
        self.vc = vc
        if vc == "local" and self._options.get("vc") is not None \
                and self._options.get("vc_solver") != "local":
            # the families on the intact cells take the local correction
            # from the start (module docstring, "Which VC correction")
            self._options = dict(self._options, vc_solver="local",
                                 vc_boundary="min-norm")
            try:
                self._set_basis(self._basis_on(self.intact))
            except NotImplementedError as err:
                raise ValueError(
                    "crack-aware families with vc='local' rebuild the basis "
                    "with the local VC correction, which this basis' "
                    "options do not take ({}); pass vc='basis' to keep its "
                    "own".format(err)) from None

    @property
    def _mesh(self):
        return (self.basis.particles if self._part is None
                else self._part).mesh

    def _global(self, local):
        """Particle numbers of the whole body (local ones on a rank)."""
        return local if self._part is None else self._local[local]

    def _total(self, count):
        """A count summed over the ranks (as it is serially)."""
        return count if self._part is None else \
            int(self._part.sum_ranks(np.array([count]))[0])

    # -- the crack ------------------------------------------------------
    def cells_to_fail(self, failed):
        """The intact cells that fail with the points ``failed`` (per
        point of the history), debris included (module docstring)."""
        mesh = self._mesh
        idx = np.flatnonzero(self.intact)
        keys, n = self._keys(), mesh.p.shape[1]
        if self._part is not None:  # in the whole body's numbering
            k, j = np.divmod(keys, self.basis.particles.n)
            keys = self._local[k] * n + self._local[j]
        bad, held = failure_counts(keys, n, mesh.t[:, idx], failed)
        if self._part is not None:  # every point lives on one rank
            bad, held = self._part.sum_ranks(np.stack([bad, held]))
        share = bad / np.maximum(held, 1)
        fail = np.zeros_like(self.intact)
        fail[idx[share >= self.fraction - 1e-12]] = True
        if not fail.any():
            return fail
        return self.intact & ~separate(mesh, self.intact & ~fail,
                                       self.min_piece)

    def _basis_on(self, intact):
        """The basis of the model's options on the intact cells (on a
        rank: its part of it, on the local particles of the first)."""
        cells = np.flatnonzero(intact)
        if self._part is not None:
            return self._part.restricted(cells).basis(local=self._local,
                                                      **self._options)
        particles = Particles.from_mesh(self._mesh, elements=cells)
        return FamilyBasis(particles, **self._options)

    def update(self, u, F, fail):
        """Fail the cells ``fail`` at the displacements ``u`` (``F``: the
        committed gradients at the history's points): collocate, rebuild,
        carry :math:`F` and the history over and book the released
        energy."""
        t0 = time.perf_counter()
        intact = self.intact & ~fail
        if not intact.any():
            raise FamilyError("every cell of the collocation mesh has "
                              "failed: nothing is left to build families on")
        u = np.array(u[:self.N], dtype=float)
        before = self._stored_and_released(u)
        closure = self._closure()
        new = self._basis_on(intact)
        self._check_pieces(new, intact)
        self.F_c = self._carry(new, np.asarray(F))
        self._set_basis(new)
        self.intact, self.u_c = intact, u
        self.released_at_updates += before - self._stored_and_released(u)
        self.closure_at_updates += closure - self._closure()
        self.updates += 1
        seconds = time.perf_counter() - t0
        self.update_seconds += seconds
        self.update_log.append({"cells": int(fail.sum()),
                                "seconds": seconds,
                                "vc": float(new.timings.get("vc", 0.0))})
        return new

    def _stored_and_released(self, u):
        """The stored energy at ``u`` plus what the failed points released
        (the energy an update must account for)."""
        r = super().fracture_energy()
        return self.energy(self.state(u)) + (0.0 if r is None else r)

    def _check_pieces(self, new, intact):
        """No family may reach across a failed cell into another piece
        (the mesh rule enlarges a small family ring by ring, then by its
        nearest particles): raise :class:`FamilyError` naming the first
        master whose family does."""
        mesh = self._mesh
        cells = np.flatnonzero(intact)
        label, _ = pieces(mesh, intact)
        vertex = np.full(mesh.p.shape[1], -1)
        vertex[mesh.t[:, cells].ravel()] = np.repeat(
            label[None], mesh.t.shape[0], axis=0).ravel()
        fam = new.families
        k = self._global(np.repeat(fam.masters, fam.sizes))
        bad = vertex[self._global(np.asarray(fam.members))] != vertex[k]
        if bad.any():
            m = k[np.flatnonzero(bad)[0]]
            raise FamilyError(
                "the family of {} reaches across the crack (it was "
                "enlarged beyond its piece of intact cells)".format(
                    describe_particle(m, mesh.p[:, m])))

    def crack_state(self):
        """The crack as checkpoint arrays (``crack_*``): the intact cells,
        :math:`u_c`, :math:`F_c`, the energy released at updates, the
        closure energy of the points they removed and the count of
        failed points."""
        out = {"crack_intact": self.intact.astype(float),
               "crack_u_c": self.u_c.copy(),
               "crack_released": np.array(self.released_at_updates),
               "crack_closure": np.array(self.closure_at_updates),
               "crack_n_failed": np.array(float(self._n_failed))}
        if self.F_c is not None:
            out["crack_F_c"] = np.array(self.F_c)
        return out

    def restore_crack(self, crack):
        """The crack of a checkpoint (:meth:`crack_state`): the basis
        rebuilt on its intact cells."""
        intact = np.asarray(crack["crack_intact"]) > 0.5
        if self.updates or not intact.all():
            self._set_basis(self._basis_on(intact))
        self.intact = intact
        self.u_c = np.asarray(crack["crack_u_c"], dtype=float)
        F = crack.get("crack_F_c")
        self.F_c = None if F is None else np.asarray(F, dtype=float)
        self.released_at_updates = float(crack["crack_released"])
        self.closure_at_updates = float(crack.get("crack_closure", 0.0))
        self._n_failed = int(crack["crack_n_failed"])

    # -- the model ------------------------------------------------------
    def commit(self, state):
        """Commit the step's history; where points failed, fail the cells
        they take with them and rebuild (:meth:`update`).  Returns whether
        the basis changed (the drivers then evaluate the internal force
        again)."""
        super().commit(state)
        failed = self.history.failed()
        if failed is None:
            return False
        n = self._total(int(failed.sum()))  # the ranks decide together
        if n == self._n_failed:
            return False
        self._n_failed = n
        fail = self.cells_to_fail(failed)
        if not fail.any():
            return False
        self.update(state["u"], np.array(state[self._gradient_key]), fail)
        self._n_failed = self._total(int(self.history.failed().sum()))
        return True

    def fracture_energy(self):
        """What the failed points released, plus what the updates released
        (module docstring)."""
        return super().fracture_energy() + self.released_at_updates

    def _closure(self):
        r = super().closure_energy()
        return 0.0 if r is None else r

    def closure_energy(self):
        """The closure energy (:meth:`Hyperelastic.closure_energy
        <skfem_pg.formulations.Hyperelastic.closure_energy>`), the
        removed points' included."""
        return self._closure() + self.closure_at_updates

    def book_removed_work(self, work):
        """The driver's correction of an update's released energy: the
        half of the removed forces' work over the step that its trapezoid
        no longer counts (:func:`~skfem_pg.solvers.dynamics.
        book_rebuild`), so that the released energy is the one the
        integrator's work implies."""
        self.released_at_updates += float(work)


def _check_pbg(basis):
    if not isinstance(basis, FamilyBasis) or basis.is_petrov:
        raise ValueError("crack-aware families are built for PBG family "
                         "bases, got {}".format(type(basis).__name__))


class _SemiTotal:
    """The displacement-type crack-aware models (Unl, UnlP0): the points
    are the members of the families on the intact cells (``current``)
    and :math:`F = F_c + \\sum_i (u^i - u^i_c)\\otimes G^{kji}` (module
    docstring); the model's own assembly runs on ``point_basis``."""

    _gradient_key = "F"

    def _bind_crack(self, basis, fraction, min_piece, vc):
        self.current = basis
        self._options = basis.options
        self._init_crack(basis, fraction, min_piece, vc)

    def _keys(self):
        return point_keys(self.current)

    def _carry(self, new, F):
        # a new point (k, j) takes the state at its particle j, that of
        # (j, j): a failure, a tracked crack's line belong to the
        # material there
        return carry_points(self.history, self.current, new, F,
                            donor="member")

    def _set_basis(self, new):
        self.current = new

    def _n_points(self):
        return self.current.flat_weights().shape[-1]

    @property
    def point_basis(self):
        """The basis on the intact cells: its points carry the history."""
        return self.current

    def deformation_gradient(self, u):
        dF = self.current.interpolate(np.asarray(u)[:self.n_u] - self.u_c[
            :self.n_u], flat=True).grad
        return dF + (self._eye if self.F_c is None else self.F_c)

    @kernel
    def state(self, u):
        s = super().state(u)
        s["u"] = u
        return s


class CrackAware(_Crack, _SemiTotal, Hyperelastic):
    """The displacement formulation whose families stop at failed cells
    (module docstring) on ``basis`` (a PBG :class:`~skfem_pg.FamilyBasis`
    collocated from a mesh's vertices with the ``"mesh"`` family rule) with
    ``material``, a :class:`~skfem_pg.materials.J2Plasticity` with a damage
    law.

    ``fraction``: the failed share of its points at which a cell fails;
    ``min_piece``: pieces cut off with fewer vertices fail whole (default
    ``dim + 2``, the smallest family a VC-corrected basis takes);
    ``vc``: ``"local"`` (default) corrects the families on the intact
    cells, from the start, by the local VC correction (``vc_solver=
    "local"``, boundary min-norm), whatever the basis' own (module
    docstring, "Which VC correction"); ``"basis"`` keeps the basis' own.

    ``model.basis`` stays the basis of the whole body (dofs, loads,
    Dirichlet boundaries); ``model.current`` is the basis on the intact
    cells, ``model.intact`` the mask of the mesh's intact cells.
    ``updates``, ``update_seconds`` and ``update_log`` (per update: the
    cells failed and the seconds) say how often the families were rebuilt
    and what it cost.

    Examples
    --------
    The mesh families of a block, with a Johnson–Cook damage law: before
    anything fails every cell is intact and the model is the plain
    displacement formulation:

    >>> import numpy as np, skfem as fem, skfem_pg as pg
    >>> from skfem_pg.materials import (J2Plasticity, JohnsonCookDamage,
    ...                                 JohnsonCookHardening)
    >>> steel = J2Plasticity.from_young(
    ...     200e3, 0.29, hardening=JohnsonCookHardening(792.0, 510.0, 0.26),
    ...     damage=JohnsonCookDamage(0.05, 3.44, -2.12, 0.3))
    >>> mesh = fem.MeshQuad().refined(2)
    >>> basis = pg.FamilyBasis(mesh, "mesh", dim=2)
    >>> model = CrackAware(basis, steel)
    >>> bool(model.intact.all()), model.updates
    (True, 0)

    """

    def __init__(self, basis, material, fraction=0.5, min_piece=None,
                 vc="local"):
        _check_pbg(basis)
        _check_crack_inputs(basis, material, fraction, "Unl")
        super().__init__(basis, material)
        self._bind_crack(basis, fraction, min_piece, vc)


class CrackAwareUnlP0(_Crack, _SemiTotal, MeanDilatation):
    """PBG UnlP0 (:class:`~skfem_pg.formulations.MeanDilatation`: the
    pressure and dilatation condensed per family) with crack-aware families
    (module docstring): after an update the per-family projections are
    those of the families on the intact cells.  ``material`` a
    :class:`~skfem_pg.materials.J2Plasticity` with a damage law; the
    points take the family pressure for their triaxiality and in
    expansion a family keeps the volumetric energy of its intact share (as
    :class:`~skfem_pg.formulations.MeanDilatation`).  ``fraction``,
    ``min_piece`` and ``vc`` as for :class:`CrackAware`.

    What an update releases can be negative here: a family keeps the
    volumetric energy of its intact share only while its failed points
    are in it; rebuilt without them, its whole volumetric energy returns
    (measured on the notched strip of ``tests/test_crack_aware.py``: -87
    N mm over four updates, against 10,370 N mm dissipated).  On MPI
    ranks as :class:`CrackAware` (each rank's families are its masters',
    so their projections are too).

    Examples
    --------
    >>> import skfem as fem, skfem_pg as pg
    >>> from skfem_pg.materials import CriticalStrainDamage, J2Plasticity
    >>> steel = J2Plasticity.from_young(
    ...     200e3, 0.3, 1e9, damage=CriticalStrainDamage(0.01))
    >>> basis = pg.FamilyBasis(fem.MeshTri().refined(2), "mesh", dim=2)
    >>> model = CrackAwareUnlP0(basis, steel)
    >>> model.N == basis.N, bool(model.intact.all())
    (True, True)

    """

    def __init__(self, basis, material, fraction=0.5, min_piece=None,
                 vc="local"):
        _check_pbg(basis)
        _check_crack_inputs(basis, material, fraction, "UnlP0")
        mu, K = compressible_moduli(material, "crack-aware UnlP0")
        MeanDilatation.__init__(self, basis, mu, K)
        self.with_material(material)
        self._bind_crack(basis, fraction, min_piece, vc)

    def _set_basis(self, new):
        """The families on the intact cells and their projections."""
        self.current = new
        E = self.elements = Elements(new)
        self.Phi = E.polynomials(self.order)
        self._Minv = np.linalg.inv(E.gram(self.Phi))


class CrackAwareU1SIG(_Crack, U1SIG):
    r"""U1SIG (:class:`~skfem_pg.formulations.U1SIG`, the thesis' fracture
    formulation) with crack-aware families (module docstring): the
    material and its history at the masters, a cell fails when
    ``fraction`` of its vertices' masters have failed.  After an update
    the master gradients are :math:`F^{kk} = F^{kk}_c + \sum_i (u^i -
    u^i_c) \otimes G^{kki}`, and the implicit-gradient stabilization acts
    on the total displacement :math:`u` with the rebuilt families'
    second derivatives; the change of its energy at an update is booked
    as released, with the removed points' (module docstring).  The
    stabilization's energy :math:`\frac12 M_{xx}\,\partial_E H :
    \tilde A : \partial_E H` is then unchanged by a rigid rotation of a
    bent piece (:math:`\partial_E H` and :math:`\tilde A` rotate with
    it).  On :math:`u - u_c` (issue 51 found) it was not: the
    derivatives of :math:`(R - I) x_c` penalize the rotation of a piece
    that was bent at the update, and on the two-hole plate (1002
    particles) the pieces flying apart gained energy from the
    stabilization's force; the released energy climbed from 520 to
    1,620 N mm after the plate had come apart (226 N mm in all with the
    stabilization on :math:`u`, ``benchmarks/README.md``).
    ``fraction``, ``min_piece`` and ``vc`` as for
    :class:`CrackAware`."""

    _gradient_key = "F1"

    def __init__(self, basis, material, fraction=0.5, min_piece=None,
                 vc="local"):
        _check_pbg(basis)
        _check_crack_inputs(basis, material, fraction, "U1SIG")
        super().__init__(basis, material)
        self._options = self.u1.options
        self._init_crack(basis, fraction, min_piece, vc)

    @classmethod
    def of(cls, basis, material):
        return cls(basis, material)

    def _keys(self):
        m = self.u1.families.masters
        return m * self.u1.particles.n + m

    def _carry(self, new, F1):
        """The masters' history and :math:`F^{kk}` on ``new`` (whose
        masters are a subset of the current ones)."""
        where = np.full(self.u1.particles.n, -1)
        where[self.u1.families.masters] = np.arange(
            len(self.u1.families.masters))
        idx = where[new.families.masters]
        h = self.history
        if h.committed is not None:
            h.committed = {k: v[..., idx] for k, v in h.committed.items()}
            h._last = None
        if self._F_committed is not None:
            self._F_committed = self._F_committed[..., idx]
        return F1[..., idx]

    def _set_basis(self, new):
        self._bind(new)  # U1SIG's own binding of its basis

    def _n_points(self):
        return len(self.u1.families.masters)

    @property
    def point_basis(self):
        """The basis on the intact cells (its masters carry the
        history)."""
        return self.u1

    def master_F(self, u):
        F = super().master_F(np.asarray(u, dtype=float) - self.u_c)
        return F if self.F_c is None else F - self._eye[:, :, :, 0] \
            + self.F_c
