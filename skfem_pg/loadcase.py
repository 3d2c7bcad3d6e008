r"""Load cases: the boundary sets of the standard material tests.

The helpers are FElupe's (``felupe.dof.symmetry``, ``uniaxial``,
``biaxial``, ``planar``, ``shear``), with its names and meanings, on a
scikit-fem vector basis or a :class:`~skfem_pg.FamilyBasis`: a quarter
(eighth) of a specimen in :math:`x, y, z \ge 0` with symmetry planes at
0, its far faces moved by ``move`` at load factor 1.  Each returns a
:class:`LoadCase` — the prescribed dofs ``D``, their values ``u_D`` and
the moved dofs — that :func:`skfem_pg.solvers.newton` and
:class:`~skfem_pg.solvers.problem.Problem` take as they are:

>>> import skfem as fem, skfem_pg as pg
>>> from skfem_pg.materials import NeoHooke
>>> from skfem_pg.formulations import Hyperelastic
>>> basis = pg.FamilyBasis(fem.MeshQuad().refined(2), dim=2)
>>> case = uniaxial(basis, move=0.2)
>>> model = Hyperelastic(basis, NeoHooke(lam=2.0, mu=1.0))
>>> x, history = pg.solvers.newton(case.problem(model), verbose=False)
>>> round(case.reaction(model, x), 6)  # the force on the moved face
0.51694

— the homogeneous plane-strain stretch 1.2 of this material gives
:math:`P_{xx} = 0.516940` (lateral stretch :math:`\sqrt{2/2.44}`), which
the particles reproduce.

Planes are found by the dof positions with a tolerance of ``1e-8`` times
the body's extent; a plane with no dof raises ``ValueError`` naming it.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .solvers.problem import Problem

__all__ = ["LoadCase", "symmetry", "uniaxial", "biaxial", "planar", "shear"]

AXES = "xyz"


class LoadCase(NamedTuple):
    """Prescribed dofs of a load case.

    Attributes
    ----------
    D : ndarray
        All prescribed dofs (sorted, unique).
    u_D : ndarray
        ``(N,)`` their values at load factor 1 (zero elsewhere).
    moved : ndarray
        The dofs moved by the load case (the reaction's dofs).
    boundaries : dict
        The dofs of each named set (``"symx"``, ``"move"``, ...).
    """

    D: np.ndarray
    u_D: np.ndarray
    moved: np.ndarray
    boundaries: dict

    def problem(self, model, f_ext=None) -> Problem:
        """The :class:`~skfem_pg.solvers.problem.Problem` of ``model``
        under this load case (and ``f_ext``)."""
        return Problem(model, f_ext=f_ext, D=self.D, u_D=self.u_D)

    def curve(self, label=None):
        """A :class:`~skfem_pg.analysis.curves.Curve` of the reaction on
        the moved dofs over their mean displacement, to pass to
        :func:`~skfem_pg.solvers.newton` as its ``callback``."""
        from .analysis.curves import Curve
        moved = self.moved
        return Curve(lambda u, load, f: np.mean(u[moved]),
                     lambda u, load, f: f[moved].sum(),
                     xlabel="displacement of the moved face",
                     ylabel="reaction force", label=label)

    def reaction(self, model, x) -> float:
        """The force on the moved dofs at the unknowns ``x`` (the sum of
        the internal force there)."""
        f = model.internal_force(model.state(x))
        return float(f[self.moved].sum())


def _dof_positions(basis):
    """``(positions (d, n), dofs (d, n))`` per displacement component."""
    particles = getattr(basis, "particles", None)
    if particles is not None:
        nc = basis.ncomp
        if nc is None or nc != particles.dim:
            raise ValueError("a load case prescribes displacements: build "
                             "the basis with dim={}".format(particles.dim))
        n = particles.n
        return particles.x, nc * np.arange(n) + np.arange(nc)[:, None]
    idx = basis.split_indices()
    d = basis.mesh.dim()
    if len(idx) != d:
        raise ValueError("a load case prescribes displacements: give a "
                         "vector basis (ElementVector), not {} component(s)"
                         .format(len(idx)))
    x = basis.doflocs
    return x[:, idx[0]], np.array(idx)


class _Sets:
    """Dof sets on coordinate planes of a basis."""

    def __init__(self, basis):
        self.N = basis.N
        self.x, self.dofs = _dof_positions(basis)
        self.dim = self.x.shape[0]
        lo, hi = self.x.min(axis=1), self.x.max(axis=1)
        self.tol = 1e-8 * max(float((hi - lo).max()), 1e-300)
        self.lo, self.hi = lo, hi
        self.sets, self.values = {}, np.zeros(self.N)

    def plane(self, axis, value, components, name, move=0.0):
        """The dofs of ``components`` on the plane ``x[axis] = value``."""
        on = np.abs(self.x[axis] - value) <= self.tol
        if not on.any():
            raise ValueError(
                "load case set {!r}: no dof on the plane {} = {} (the body "
                "spans {} .. {})".format(name, AXES[axis], value,
                                         self.lo[axis], self.hi[axis]))
        dofs = self.dofs[list(components)][:, on].ravel()
        for other, held in self.sets.items():
            clash = np.intersect1d(held, dofs)
            clash = clash[self.values[clash] != move]
            if len(clash):
                raise ValueError(
                    "load case sets {!r} and {!r} prescribe dof {} at {} "
                    "twice, with {} and {}".format(
                        other, name, clash[0], self._where(clash[0]),
                        self.values[clash[0]], move))
        self.sets[name] = np.sort(dofs)
        self.values[dofs] = move
        return dofs

    def _where(self, dof):
        k = np.nonzero(self.dofs == dof)[1][0]
        return np.round(self.x[:, k], 12).tolist()

    def case(self, moved):
        D = np.unique(np.concatenate(list(self.sets.values()))) \
            if self.sets else np.zeros(0, dtype=np.int64)
        return LoadCase(D, self.values, np.sort(np.concatenate(moved))
                        if moved else np.zeros(0, dtype=np.int64),
                        self.sets)


def _flags(value, dim):
    flags = tuple(value) if hasattr(value, "__len__") else (value,) * 3
    return [bool(f) for f in flags[:dim]]


def _symmetry(sets, axes, at=(0.0, 0.0, 0.0)):
    for a, on in enumerate(_flags(axes, sets.dim)):
        if on:
            sets.plane(a, at[a], [a], "sym" + AXES[a])


def symmetry(basis, axes=(True, True, True), x=0.0, y=0.0,
             z=0.0) -> LoadCase:
    """Symmetry planes: the normal displacement is zero on the planes
    ``x``, ``y``, ``z`` where ``axes`` says so (sets ``"symx"``, ...).

    >>> import skfem as fem
    >>> basis = fem.Basis(fem.MeshQuad(), fem.ElementVector(
    ...     fem.ElementQuad1()))
    >>> symmetry(basis).D.tolist()   # u_x at x = 0, u_y at y = 0
    [0, 1, 3, 6]
    """
    sets = _Sets(basis)
    _symmetry(sets, axes, (x, y, z))
    return sets.case([])


def uniaxial(basis, move=0.2, axis=0, clamped=False, sym=True, left=None,
             right=None) -> LoadCase:
    """Uniaxial tension (compression with ``move < 0``) along ``axis``:
    the face ``right`` (default: the far one) moved by ``move``;
    symmetry planes at 0 (``sym``: one flag or one per axis); without
    symmetry along ``axis`` the face ``left`` is held along it;
    ``clamped``: the loaded faces held across too."""
    sets = _Sets(basis)
    flags = _flags(sym, sets.dim)
    _symmetry(sets, flags)
    right = sets.hi[axis] if right is None else right
    others = [a for a in range(sets.dim) if a != axis]
    if not flags[axis]:
        left = sets.lo[axis] if left is None else left
        sets.plane(axis, left, [axis], "left" + AXES[axis])
        if clamped:
            sets.plane(axis, left, others, "left" + "".join(
                AXES[a] for a in others))
    if clamped:
        sets.plane(axis, right, others, "right")
    moved = sets.plane(axis, right, [axis], "move", move)
    return sets.case([moved])


def biaxial(basis, move=0.2, clamped=False, right=None) -> LoadCase:
    """Equibiaxial tension in x and y on a quarter (eighth) with symmetry
    planes: the faces at ``right`` (default: the far ones) moved by
    ``move`` along their normals; ``clamped`` holds them across (not a
    valid test on a cube, whose loaded faces share an edge)."""
    sets = _Sets(basis)
    _symmetry(sets, True)
    moved = []
    for a, name in ((0, "move-x"), (1, "move-y")):
        at = sets.hi[a] if right is None else right
        if clamped:
            sets.plane(a, at, [1 - a], "right" if a == 0 else "top")
        moved.append(sets.plane(a, at, [a], name, move))
    return sets.case(moved)


def planar(basis, move=0.2, clamped=False, right=None) -> LoadCase:
    """Planar tension (pure shear): the face ``x = right`` moved by
    ``move`` along x, the face at the far y held along y."""
    sets = _Sets(basis)
    _symmetry(sets, True)
    at = sets.hi[0] if right is None else right
    if clamped:
        sets.plane(0, at, [1], "right")
    moved = sets.plane(0, at, [0], "move", move)
    sets.plane(1, sets.hi[1], [1], "fix-y")
    return sets.case([moved])


def shear(basis, move=0.2, axis_shear=0, axis_compression=1,
          compression=(0.0, 0.0), sym=True, bottom=None,
          top=None) -> LoadCase:
    """Simple shear between two plates: the ``bottom`` face (default: the
    near one along ``axis_compression``) held, the ``top`` face moved by
    ``move`` along ``axis_shear`` and both pressed together by
    ``compression`` (bottom, top); symmetry planes across the other
    axes."""
    sets = _Sets(basis)
    if axis_shear == axis_compression:
        raise ValueError("shear: axis_shear and axis_compression are both "
                         "{}".format(axis_shear))
    if sym:
        _symmetry(sets, [a not in (axis_shear, axis_compression)
                         for a in range(3)])
    c = axis_compression
    bottom = sets.lo[c] if bottom is None else bottom
    top = sets.hi[c] if top is None else top
    across = [a for a in range(sets.dim) if a != c]
    sets.plane(c, bottom, across, "bottom")
    sets.plane(c, top, [a for a in across if a != axis_shear], "top")
    sets.plane(c, bottom, [c], "compression_bottom", compression[0])
    sets.plane(c, top, [c], "compression_top", -compression[1])
    moved = sets.plane(c, top, [axis_shear], "move", move)
    return sets.case([moved])
