"""Curves along a static run: force–displacement and any other probe.

A :class:`Curve` is a callback of :func:`skfem_pg.solvers.newton`
(``callback(x, load, f_int)`` after each converged step): it records one
point per load step from two functions of the unknowns, the load factor
and the internal force vector, and plots them with matplotlib.
:meth:`skfem_pg.loadcase.LoadCase.curve` gives the reaction of a load
case's moved face against its displacement (FElupe's
``CharacteristicCurve``).

>>> import skfem as fem, skfem_pg as pg
>>> from skfem_pg.formulations import Hyperelastic
>>> from skfem_pg.materials import NeoHooke
>>> basis = pg.FamilyBasis(fem.MeshQuad().refined(2), dim=2)
>>> model = Hyperelastic(basis, NeoHooke(lam=2.0, mu=1.0))
>>> case = pg.loadcase.uniaxial(basis, move=0.2)
>>> curve = case.curve()
>>> x, _ = pg.solvers.newton(case.problem(model), steps=4, adaptive=False,
...                          callback=curve, verbose=False)
>>> len(curve), round(float(curve.y[-1]), 6)   # the origin and 4 steps
(5, 0.51694)
"""
from __future__ import annotations

from typing import Callable

import numpy as np

__all__ = ["Curve"]


class Curve:
    """Points ``(x, y)`` recorded along a static run.

    Parameters
    ----------
    x, y : callable
        ``f(u, load, f_int) -> float`` of the unknowns, the load factor and
        the internal force vector (the reactions at prescribed dofs).
    xlabel, ylabel, label : str
        Axis labels and the legend entry of :meth:`plot`.
    origin : tuple of float or None
        The point of the unloaded state, recorded first (default ``(0,
        0)``; ``None``: none).

    Notes
    -----
    The recorded points are the arrays ``curve.x`` and ``curve.y``, their
    load factors ``curve.load``.
    """

    def __init__(self, x: Callable, y: Callable, xlabel: str = "x",
                 ylabel: str = "y", label: str | None = None,
                 origin: tuple | None = (0.0, 0.0)):
        if not (callable(x) and callable(y)):
            raise TypeError("Curve takes two callables f(u, load, f_int)")
        self._x, self._y = x, y
        self.xlabel, self.ylabel, self.label = xlabel, ylabel, label
        self._points = [] if origin is None else [
            (float(origin[0]), float(origin[1]), 0.0)]

    def __call__(self, u, load, f_int):
        self._points.append((float(self._x(u, load, f_int)),
                             float(self._y(u, load, f_int)), float(load)))

    def __len__(self):
        return len(self._points)

    x = property(lambda self: np.array([p[0] for p in self._points]))
    y = property(lambda self: np.array([p[1] for p in self._points]))
    load = property(lambda self: np.array([p[2] for p in self._points]))

    def plot(self, ax=None, **kwargs):
        """Plot ``y`` over ``x`` (markers at the load steps) on ``ax`` (a
        new figure's axes if ``None``); returns the axes."""
        if ax is None:
            import matplotlib.pyplot as plt
            ax = plt.subplots()[1]
        kwargs.setdefault("marker", "o")
        ax.plot(self.x, self.y, label=self.label, **kwargs)
        ax.set_xlabel(self.xlabel)
        ax.set_ylabel(self.ylabel)
        if self.label is not None:
            ax.legend()
        return ax

    def __repr__(self):
        return "<Curve {!r} over {!r}: {} points>".format(
            self.ylabel, self.xlabel, len(self))
