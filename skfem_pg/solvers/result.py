"""The result of a load-stepped solve: displacements, the formulation's
fields, probes, timings, and the reactions of prescribed boundaries.

It lives below :mod:`skfem_pg.scenes` (which returns it) and
:mod:`skfem_pg.distributed` (whose ``DistributedResult`` extends it).
"""
from dataclasses import dataclass, field

import numpy as np


@dataclass
class Result:
    """A scene solution.

    ``u``: the displacements in scikit-fem numbering of ``basis`` (for
    every formulation); ``fields``: the formulation's extra fields by name
    (e.g. ``p`` and ``Theta`` per element or family for Q1P0 / UnlP0;
    ``ep``, the accumulated plastic strain, per family or cell for a
    plastic material);
    ``x``: all unknowns of ``model`` (``u`` first); ``f_ext``: the external
    forces at the end of the load path.

    Examples
    --------
    >>> import numpy as np, skfem as fem
    >>> from skfem_pg import Scene
    >>> from skfem_pg.materials import NeoHooke
    >>> mesh = fem.MeshQuad().refined(2).with_boundaries(
    ...     {"left": lambda x: x[0] == 0, "right": lambda x: x[0] == 1})
    >>> res = Scene("block", mesh, NeoHooke(lam=60.0, mu=40.0),
    ...             clamped=["left"], tractions={"right": [1.0, 0.0]}
    ...             ).solve("PG", verbose=False)
    >>> res.u.shape == (res.basis.N,), res.history[-1]["load"]
    (True, 1.0)

    """
    method: str
    u: np.ndarray
    basis: object
    probes: dict
    times: dict
    history: list = field(default_factory=list)
    fields: dict = field(default_factory=dict)
    model: object = None
    x: np.ndarray = None
    f_ext: np.ndarray = None

    @property
    def total_time(self):
        return sum(self.times.values())

    def __repr__(self):
        """One line: method, unknowns, load steps, probes, seconds (the
        dataclass' default printed every array in full)."""
        probes = ", ".join("{}=({})".format(k, ", ".join(
            "{:.5g}".format(c) for c in np.ravel(v)))
            for k, v in self.probes.items())
        return "<{} {!r}: {} displacement dofs{}, {} load step(s){}, " \
            "{:.2f} s>".format(
                type(self).__name__, self.method, len(self.u),
                "" if not self.fields else " + " + ", ".join(self.fields),
                len(self.history), "" if not probes else ", " + probes,
                self.total_time)

    __str__ = __repr__

    def residual(self):
        """:math:`f_{int}(u) - f_{ext}` on the displacement dofs: zero
        (to the solver's tolerance) where the displacements are free, the
        reaction forces where they are prescribed."""
        r = self.model.internal_force(self.model.state(self.x))
        return r[:len(self.u)] - self.f_ext

    def reaction(self, boundary):
        """The total reaction force vector ``(d,)`` on the named
        ``boundary`` (or facets): the sum, per component, of the residual
        :meth:`residual` over the boundary's dofs (nodal and, for
        quadratic elements, facet and edge dofs).  Meaningful on a
        boundary whose displacements are prescribed.  Conditions imposed
        by Nitsche terms (PG2, :class:`~skfem_pg.formulations.
        WeakDirichlet`) report their consistent flux instead."""
        weak = getattr(self.model, "reaction", None)
        if weak is not None:  # Dirichlet by Nitsche terms (PG2)
            return weak(self.x, boundary)
        r = self.residual()
        dofs = self.basis.get_dofs(boundary)
        d = self.basis.mesh.dim()
        return np.array([r[dofs.all("u^{}".format(c + 1))].sum()
                         for c in range(d)])
