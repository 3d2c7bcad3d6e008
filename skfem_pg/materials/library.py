r"""Materials from FElupe's library, on family and FE bases.

:class:`FElupeMaterial` wraps any hyperelastic constitutive material of
`FElupe <https://felupe.readthedocs.io>`_ — its built-in laws
(``NeoHooke``, ``NeoHookeCompressible``, ...) and the strain-energy
functions it differentiates with tensortrax (``Hyperelastic(ogden, ...)``,
``yeoh``, ``mooney_rivlin``, ``extended_tube``, ``arruda_boyce``, or a
user's :math:`W(C)`) — as a law of this package: ``stress(F)`` is FElupe's
``gradient`` (the first Piola–Kirchhoff stress), ``tangent(F)`` its
``hessian``, so no stress or tangent is written by hand.

In 2-D the law is evaluated in plane strain: ``F`` is embedded in
:math:`3\times3` with :math:`F_{33} = 1` and the in-plane blocks of the
stress and the tangent are returned.

FElupe and tensortrax are GPL-3.0 licensed; they are an optional extra
(``pip install skfem-pg[felupe]``) that this BSD-licensed package imports
only when a user builds one of these materials.  Materials with state
variables (FElupe's viscoelastic or plastic laws) are refused: their
history would have to travel through this package's models.
"""
import numpy as np

from .hyperelastic import Material

__all__ = ["FElupeMaterial"]


class FElupeMaterial(Material):
    r"""A FElupe hyperelastic material as a law of this package.

    Parameters
    ----------
    umat : felupe constitutive material
        An object with FElupe's ``gradient([F, statevars])`` and
        ``hessian([F, statevars])`` (and, for :meth:`energy`,
        ``function``); stateless.

    Examples
    --------
    An Ogden law differentiated by tensortrax: at ``F = I`` the stress
    vanishes and the tangent is the linear one, :math:`\mu` summed over
    the terms of the series, so :math:`A_{0101} = \mu = 1.2` (to 5e-9:
    tensortrax perturbs equal principal stretches to differentiate the
    eigenvalues):

    >>> import numpy as np, felupe
    >>> umat = felupe.Hyperelastic(felupe.ogden, mu=[1.0, 0.2],
    ...                            alpha=[1.7, -1.5])
    >>> law = FElupeMaterial(umat)
    >>> F = np.eye(2)[:, :, None]
    >>> round(float(np.abs(law.stress(F)).max()), 6)
    0.0
    >>> round(float(law.tangent(F)[0, 1, 0, 1, 0]), 6)
    1.2
    """

    def __init__(self, umat):
        missing = [m for m in ("gradient", "hessian")
                   if not callable(getattr(umat, m, None))]
        if missing:
            raise TypeError(
                "FElupeMaterial takes a FElupe constitutive material (with "
                "gradient and hessian); {} has no {}".format(
                    type(umat).__name__, " or ".join(missing)))
        template = getattr(umat, "x", None)
        nstate = 0 if template is None else int(np.size(template[-1]))
        if nstate:
            raise NotImplementedError(
                "{} has {} state variable(s): FElupeMaterial takes "
                "stateless (hyperelastic) laws".format(
                    type(umat).__name__, nstate))
        self.umat = umat

    def _args(self, F):
        """FElupe's ``[F (3, 3, 1, n), statevars]`` of ``F (d, d, ...)``
        (its laws take two trailing axes), ``d`` and the trailing shape."""
        F = np.asarray(F, dtype=float)
        d = F.shape[0]
        if d not in (2, 3) or F.shape[1] != d:
            raise ValueError("F must have shape (d, d, ...) with d = 2 "
                             "(plane strain) or 3, got {}".format(F.shape))
        trailing = F.shape[2:]
        n = int(np.prod(trailing, dtype=np.int64))
        F3 = np.zeros((3, 3, 1, n))
        F3[:d, :d] = F.reshape(d, d, 1, n)
        if d == 2:
            F3[2, 2] = 1.0
        return [F3, np.zeros((0, 1, n))], d, trailing

    def stress(self, F):
        x, d, trailing = self._args(F)
        P = np.asarray(self.umat.gradient(x)[0])[:d, :d]
        return P.reshape((d, d) + trailing)

    def tangent(self, F):
        x, d, trailing = self._args(F)
        A = np.asarray(self.umat.hessian(x)[0])[:d, :d, :d, :d]
        return A.reshape((d,) * 4 + trailing)

    def energy(self, F):
        x, _, trailing = self._args(F)
        function = getattr(self.umat, "function", None)
        if function is None:
            raise NotImplementedError(
                "{} gives no strain energy (FElupe's function); what needs "
                "W (energy balances) cannot use it".format(
                    type(self.umat).__name__))
        return np.asarray(function(x)[0]).reshape(trailing)

    def __repr__(self):
        return "FElupeMaterial({!r})".format(self.umat)
