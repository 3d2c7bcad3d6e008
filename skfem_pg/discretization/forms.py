"""scikit-fem's form decorators, assembled by the batched fast path.

``skfem_pg.BilinearForm`` and ``skfem_pg.LinearForm`` are scikit-fem's
:class:`skfem.BilinearForm` / :class:`skfem.LinearForm` (same decorator, same
form functions, same ``assemble`` signature); their ``assemble`` runs
:func:`skfem_pg.assemble` on family bases and scikit-fem cell bases, so a
script that swaps ``Basis`` for ``FamilyBasis`` changes one import line and
keeps fast-path speed (``tests/test_forms.py``; benchmarks/README.md,
"Measurements behind the defaults").  On a
Petrov–Galerkin basis they test with ``basis.test`` (scikit-fem's own forms
refuse such a basis: :func:`~skfem_pg.discretization.basis.form_roles`).
Forms the fast path cannot probe (``u.hess``, ...) and other bases (facet,
composite, mixed) take scikit-fem's generic path, the roles checked.

>>> from skfem_pg import BilinearForm
>>> @BilinearForm
... def laplace(u, v, w):
...     return u.grad[0] * v.grad[0] + u.grad[1] * v.grad[1]
"""
import skfem as fem

from . import assembly
from .basis import form_roles


def _fast(form, base, ubasis, vbasis, kwargs):
    if assembly.supports(ubasis):
        try:
            return assembly.assemble(form, ubasis, vbasis, **kwargs)
        except assembly.ProbeError:
            pass  # needs more than values and gradients
    if vbasis is None:
        vbasis = assembly.test_basis(form, ubasis)
    with form_roles(form, ubasis, vbasis, kwargs):
        if base is fem.LinearForm:
            return base.assemble(form, vbasis, **kwargs)
        return base.assemble(form, ubasis, vbasis, **kwargs)


class BilinearForm(fem.BilinearForm):
    """:class:`skfem.BilinearForm` whose :meth:`assemble` uses
    :func:`skfem_pg.assemble` where it can (module docstring).

    Examples
    --------
    The same form assembles on a family basis (batched) and on an FE basis:

    >>> import numpy as np, skfem as fem, skfem_pg as pg
    >>> from skfem.helpers import dot, grad
    >>> @BilinearForm
    ... def laplace(u, v, w):
    ...     return dot(grad(u), grad(v))
    >>> mesh = fem.MeshTri().refined(2)
    >>> K = laplace.assemble(pg.FamilyBasis(mesh))
    >>> K_fe = laplace.assemble(fem.Basis(mesh, fem.ElementTriP1()))
    >>> K.shape == K_fe.shape, bool(abs(K.sum()) < 1e-10)
    (True, True)

    """

    _pg_fast = True

    def assemble(self, ubasis, vbasis=None, **kwargs):
        return _fast(self, fem.BilinearForm, ubasis, vbasis, kwargs)


class LinearForm(fem.LinearForm):
    """:class:`skfem.LinearForm` whose :meth:`assemble` uses
    :func:`skfem_pg.assemble` where it can; on a Petrov–Galerkin family
    basis it tests with ``basis.test`` (internal forces (4.21)).

    Examples
    --------
    >>> import numpy as np, skfem as fem, skfem_pg as pg
    >>> @LinearForm
    ... def unit(v, w):
    ...     return v
    >>> basis = pg.FamilyBasis(fem.MeshQuad().refined(2))
    >>> round(float(unit.assemble(basis).sum()), 12)  # the domain's area
    1.0

    """

    _pg_fast = True

    def assemble(self, vbasis, **kwargs):
        return _fast(self, fem.LinearForm, vbasis, None, kwargs)
