"""Exceptions raised on bad input.

Every message names the culprit (particle index, position, family size) so a
user can find it in ParaView or in the mesh file.
"""
import warnings


class ParticleError(ValueError):
    """Invalid particle set: non-positive volume, duplicate positions, ..."""


class FamilyError(ValueError):
    """A family cannot support the requested basis (too few or collinear /
    coplanar members; singular moment matrix)."""


class CorrectionError(FamilyError):
    """A bond or VC correction cannot be computed accurately for these
    families (constraint residual above round-off, blown-up or non-finite
    derivatives)."""


class VCSolveError(CorrectionError, RuntimeError):
    """The VC system (5.18) of these families has no solution to working
    precision: its (reduced) matrix is singular, or its iterative solve
    stopped short.  A :class:`CorrectionError`, and a ``RuntimeError``
    (the type these solves raised before it existed)."""


class SingularSystemError(ValueError):
    """A linear system has no unique solution (rigid-body modes left free
    by too few Dirichlet conditions, a mechanism) or its solve did not
    reach a residual that makes the answer trustworthy."""


class UnsupportedMeshError(TypeError):
    """The mesh type is not a linear scikit-fem mesh (tri, quad, tet, hex)."""


class SecondDerivativeError(NotImplementedError):
    """A form reads second derivatives (``dd(u)``, ``u.hess``) of basis
    functions that carry first derivatives only."""


class _FirstDerivativesOnly:
    """Stands in for ``hess`` in the fields of a particle basis (family
    and PG2): any use of it raises :class:`SecondDerivativeError` instead
    of numpy's message about a ``None`` operand.  The shape functions
    carry values and first derivatives only (MTE1 (5.52), WTE1/WTE2, the
    PG2 fits); fourth-order problems (Kirchhoff plates, the biharmonic
    stream function) need a C¹ or non-conforming FE basis (Morley,
    Argyris)."""

    def _refuse(self, *args, **kwargs):
        raise SecondDerivativeError(
            "the form reads second derivatives (dd(u) / u.hess) of a "
            "particle basis (FamilyBasis, PG2), whose basis functions carry "
            "values and first derivatives only; pose a fourth-order "
            "problem on an FE basis "
            "(e.g. ElementTriMorley, ElementTriArgyris) or in mixed form "
            "with first derivatives")

    __array__ = __array_function__ = __array_ufunc__ = __getitem__ = \
        __mul__ = __rmul__ = __add__ = __radd__ = __sub__ = __rsub__ = \
        __truediv__ = __rtruediv__ = __matmul__ = __rmatmul__ = __neg__ = \
        __pow__ = __len__ = __iter__ = _refuse

    def __repr__(self):
        return "<no second derivatives: a FamilyBasis>"


#: the ``hess`` of every field a family basis hands to a form
NO_SECOND_DERIVATIVES = _FirstDerivativesOnly()


class SlowAssemblyWarning(UserWarning):
    """scikit-fem's generic assembly runs on a FamilyBasis: correct, but
    far slower than :func:`skfem_pg.assemble`."""


def warn_slow_assembly(kind, nbfun, stacklevel=3):
    """Warn (:class:`SlowAssemblyWarning`) that scikit-fem's generic
    assembly on a ``kind`` basis calls a bilinear form once per pair of
    its ``nbfun`` local functions."""
    warnings.warn(
        "scikit-fem's generic assembly on a {} calls the form once per "
        "local basis function ({}) or, bilinear, per pair of them ({} "
        "calls) and is far slower than skfem_pg.assemble; use "
        "skfem_pg.BilinearForm / LinearForm as decorators (same forms, "
        "fast path) or skfem_pg.assemble(form, basis)".format(
            kind, nbfun, nbfun ** 2), SlowAssemblyWarning,
        stacklevel=stacklevel)


class SurfaceLoadWarning(UserWarning):
    """The thesis' boundary variants ``vc_boundary="s"``/``"sn"`` move the
    surface particles' area vectors (4.35), and the consistent surface
    load with them: the applied resultant differs from the requested one
    (by about 1 % on the Cook membrane's loaded edge).  The default
    ``"min-norm"`` (V5m) applies the requested load."""


class MixedBasisWarning(UserWarning):
    """A form couples two family bases of different component counts on
    the same particles (a displacement–pressure pair): an equal-order PG
    pair that fails the inf-sup condition."""


def describe_particle(index, x):
    """``'particle 12 at (0.5, 1.25)'`` — used in error messages."""
    pos = ", ".join("{:.6g}".format(c) for c in x)
    return "particle {} at ({})".format(int(index), pos)
