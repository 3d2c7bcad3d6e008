r"""Unpadded layout of member data: families grouped by size.

Families of a particle set have different sizes :math:`m_k` (6 to 24
members on gmsh tetrahedra).  A padded ``(nf, m_max)`` array wastes most of
its work there (on gmsh tetrahedra 42 % of the member slots are padding and
78 % of a padded local-matrix product), so the hot paths — interpolation,
material evaluation, local matrices and their scatter — run on
:class:`SizeGroups`: the families of each size ``m`` form one group whose
arrays ``(nf_b, m, ...)`` have no padding, and every cost is
:math:`\propto \sum_k m_k^p`.

Member data without a family axis is *flat*: one entry per (family, member)
pair in the order of ``Families.members`` (entry ``offsets[k] + j`` is
member ``j`` of family ``k``), :math:`N_q = \sum_k m_k` entries.  As a
scikit-fem quadrature field a flat array has the trailing shape
``(1, N_q)`` — one "element" holding all points — which
:meth:`~skfem_pg.FamilyBasis.interpolate` returns with ``flat=True`` and
:func:`skfem_pg.assemble` accepts beside the padded ``(nf, m_max)`` one.
"""
import numpy as np


class Group:
    """The families of one size.

    Attributes
    ----------
    families
        ``(nf_b,)`` family indices.
    m
        Their size (members, master included).
    flat
        ``(nf_b, m)`` flat indices of their members.
    members
        ``(nf_b, m)`` particle indices of their members.
    """

    __slots__ = ("families", "m", "flat", "members")

    def __init__(self, families, m, flat, members):
        self.families, self.m, self.flat, self.members = \
            families, m, flat, members

    def __len__(self):
        return len(self.families)

    def __repr__(self):
        return "<Group of {} families of size {}>".format(len(self), self.m)


class SizeGroups:
    """Families grouped by size (see the module docstring).

    Iterating yields the :class:`Group` s in ascending size; ``n_points``
    is :math:`N_q = \\sum_k m_k`, ``m_max`` the largest size.
    """

    def __init__(self, families):
        sizes = families.sizes
        offsets = families.offsets
        order = np.argsort(sizes, kind="stable")
        s = sizes[order]
        cuts = np.flatnonzero(np.diff(s)) + 1
        self.groups = []
        for fam in np.split(order, cuts):
            m = int(sizes[fam[0]])
            flat = offsets[fam][:, None] + np.arange(m)
            self.groups.append(Group(fam, m, flat, families.members[flat]))
        self.n_families = len(families)
        self._families_type = type(families)  # no import of families.py
        self.n_particles = families.n_particles
        self.n_points = int(offsets[-1])
        self.m_max = int(sizes.max())
        self.sizes = sizes

    def __iter__(self):
        return iter(self.groups)

    def __len__(self):
        return len(self.groups)

    def subset(self, group):
        """The families of ``group`` as a
        :class:`~skfem_pg.discretization.families.Families` of their own (no
        padding: the
        batched kernels run on it unchanged)."""
        nf, m = group.members.shape
        return self._families_type(np.arange(nf + 1) * m,
                                   group.members.ravel(), self.n_particles)

    def is_flat(self, shape):
        """Whether trailing quadrature axes ``shape`` are the flat layout
        ``(1, N_q)`` (else padded ``(nf, m_max)`` or broadcastable)."""
        return (tuple(shape[-2:]) == (1, self.n_points)
                and (self.n_families, self.m_max) != (1, self.n_points))

    def take(self, a, group, axis=-2):
        """``a[..., k, j, ...]`` of ``group``: its families' members, shape
        ``(..., nf_b, m, ...)``, from an array whose axes ``axis`` and
        ``axis + 1`` are the padded ``(nf, m_max)`` or flat ``(1, N_q)``
        layout (or broadcast from a length-1 axis)."""
        a = np.asarray(a)
        ax = axis % a.ndim
        shape = a.shape[ax:ax + 2]
        index = (slice(None),) * ax
        if self.is_flat(shape):
            return a[index + (0, group.flat)]
        fam = group.families if shape[0] != 1 else np.zeros(
            len(group), dtype=np.int64)
        cols = np.arange(group.m) if shape[1] != 1 else np.zeros(
            group.m, dtype=np.int64)
        return a[index + (fam[:, None], cols[None, :])]

    def flat_to_padded(self, a, fill=0.0):
        """A flat array ``(..., N_q)`` (or ``(..., 1, N_q)``) as the padded
        ``(..., nf, m_max)``, ``fill`` in the padding."""
        a = np.asarray(a)
        if a.ndim >= 2 and a.shape[-2] == 1 and a.shape[-1] == self.n_points:
            a = a[..., 0, :]
        out = np.full(a.shape[:-1] + (self.n_families, self.m_max), fill,
                      dtype=a.dtype)
        for g in self.groups:
            out[..., g.families[:, None], np.arange(g.m)] = a[..., g.flat]
        return out

    def padded_to_flat(self, a):
        """A padded array ``(..., nf, m_max)`` as flat ``(..., N_q)``."""
        a = np.asarray(a)
        out = np.empty(a.shape[:-2] + (self.n_points,), dtype=a.dtype)
        for g in self.groups:
            out[..., g.flat] = a[..., g.families[:, None], np.arange(g.m)]
        return out

    def __repr__(self):
        return ("<SizeGroups: {} families in {} sizes {}..{}, {} points>"
                ).format(
            self.n_families, len(self), self.groups[0].m, self.m_max,
            self.n_points)


def is_family_basis(basis):
    """Whether ``basis`` is a family basis (a
    :class:`~skfem_pg.FamilyBasis`: particles, families and their layout)
    rather than a scikit-fem cell basis — the one test the formulations,
    solvers and output use to tell PG from FE."""
    return hasattr(basis, "layout") and hasattr(basis, "particles")
