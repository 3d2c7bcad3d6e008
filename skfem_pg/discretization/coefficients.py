r"""Piecewise coefficients on a family basis: a value per cell of the
collocation mesh (two materials, a heterogeneous conductivity) evaluated at
the family members.

A particle on a material interface belongs to both sides: a value per
particle gives it one side's value, and the result then depends on which
(scikit-fem's two-material example: −8.1 % or +0.4 % with the interface
particles given the one or the other).  :func:`cell_values_at_members`
evaluates the coefficient of the bond instead: member :math:`j` of family
:math:`k` gets the value of the cell that contains the bond midpoint
:math:`(X^k + X^j)/2`, and the master itself the volume-weighted mean of
the cells around it.  A family on the interface thus sees both sides, each
in proportion to its bonds.  With ``family_quadrature="moments"``
(:mod:`~skfem_pg.discretization.moment_quadrature`) the quadrature points
are not members: each gets the value of the cell that contains it.
"""
import numpy as np
import skfem as fem

from .layout import is_family_basis
from .particles import linear_elements


def cell_values_at_members(basis, values):
    """``values`` (one per cell of the basis' collocation mesh) at the
    family members, ``(nf, m)`` padded (zero in padded slots): a form
    coefficient, ``form.assemble(basis, k=cell_values_at_members(basis,
    k_cells))``.

    Raises ``ValueError`` for a basis without a collocation mesh or a
    ``values`` of another length."""
    if not is_family_basis(basis) or basis.mesh is None:
        raise ValueError("cell_values_at_members needs a FamilyBasis "
                         "collocated from a mesh's vertices")
    mesh = basis.mesh
    values = np.asarray(values, dtype=float)
    if values.shape != (mesh.nelements,):
        raise ValueError("one value per cell of the collocation mesh ({}), "
                         "got shape {}".format(mesh.nelements, values.shape))
    x = basis.particles.x
    mem, mask = basis.families.padded()
    masters = mem[:, 0]
    mid = 0.5 * (x[:, masters][:, :, None] + x[:, mem])  # (d, nf, m)
    cells = mesh.element_finder()(*mid.reshape(mid.shape[0], -1))
    out = values[cells].reshape(mem.shape)
    # the master: the volume-weighted mean of the cells around it
    e1, _ = linear_elements(mesh)
    volume = fem.Functional(lambda w: 1.0 + 0.0 * w.x[0]).elemental(
        fem.Basis(mesh, e1))
    weight = np.zeros(mesh.nvertices)
    total = np.zeros(mesh.nvertices)
    np.add.at(weight, mesh.t.ravel(),
              np.broadcast_to(volume, mesh.t.shape).ravel())
    np.add.at(total, mesh.t.ravel(),
              np.broadcast_to(volume * values, mesh.t.shape).ravel())
    out[:, 0] = total[masters] / weight[masters]
    points = getattr(basis, "points", None)
    if points is not None:  # family_quadrature="moments": its own points
        out = _at_points(mesh, values, points, basis.dx > 0, out[:, :1])
    return np.where(mask, out, 0.0)


def _at_points(mesh, values, points, used, master_mean):
    """``values`` of the cells that contain the quadrature points
    ``points`` ``(nf, m, d)`` where ``used``, else the masters' mean (a
    point outside the node set's polygon, beside a curved boundary)."""
    out = np.broadcast_to(master_mean, used.shape).copy()
    find = mesh.element_finder()
    P = points[used]  # (n, d)
    cells = np.full(len(P), -1)
    try:
        cells[:] = find(*P.T)
    except ValueError:  # some point outside: one at a time
        for i, q in enumerate(P):
            try:
                cells[i] = find(*q[:, None])[0]
            except ValueError:
                pass
    inside = cells >= 0
    vals = out[used]
    vals[inside] = values[cells[inside]]
    out[used] = vals
    return out


__all__ = ["cell_values_at_members"]
