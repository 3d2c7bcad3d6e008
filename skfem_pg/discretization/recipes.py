r"""Recipes: which families, quadrature weights and bond weights a PBG
basis uses when the caller does not say.

A recipe is three choices made together, because they act together:

* the family rule (:data:`skfem_pg.discretization.families.RULES`):
  ``"mesh"`` (the vertices of the cells around the master),
  ``"nearest"`` (the :math:`k` nearest particles, made pairwise) or
  ``"horizon"``;
* the quadrature weights (:mod:`skfem_pg.discretization.quadrature`):
  ``"volume"`` (4.30) or ``"uniform"``;
* the bond weight exponent :math:`n` of :math:`\omega = 1/|\Delta X|^{2n}`
  in the Taylor expansions (thesis (3.33); :math:`n = 0` weighs every
  bond the same).

=========  ===============================================  ===================
recipe     families, weights, exponent                      default for
=========  ===============================================  ===================
``mesh``   ``"mesh"``, ``"volume"``, 1 (the thesis')        quadrilaterals;
                                                            hexahedra;
                                                            PPG, WTE1/WTE2;
                                                            particles w/o mesh
                                                            (``"horizon"``)
``meshU``  ``"mesh"``, ``"uniform"``, 0                     PBG MTE1 on 2-D
                                                            triangles
``kNN``    ``"nearest"`` (10, pairwise), ``"uniform"``, 0   PBG MTE1 on 3-D
                                                            tetrahedra
=========  ===============================================  ===================

Why ``kNN`` on tetrahedra.  A gmsh tetrahedral mesh gives a vertex 14
neighbours on average and up to 30, spread over the cells around it. The
1-ring family, weighted by member volumes, averages the strain energy of a
bending field over a region that reaches far beyond the master, and VC PBG
Unl is soft. The nearest ten particles are the compact neighbourhood that
the moving Taylor expansion needs (at least nine others in general
position). Uniform weights keep the energy at the family, not on its
largest (farthest) members, and unit bond weights use the few members
evenly. Each choice alone helps little. Together they converge from below,
like FE, on the 3-D Cook membrane, beams and plates (tables
``recipes_3d_*`` in ``benchmarks/README.md``, written by
``benchmarks/recipes_3d.py``).

Why ``meshU`` on triangles.  The same two weight choices on the 1-ring
families of a 2-D triangle mesh are soft by a fraction of T1's error, with
the same sign at every refinement, in plane-strain bending and tension.
On Poisson problems they are stiff, about as far off as P1. Families of
nearest neighbours are no better there and change sign under refinement
(issue 45; ``benchmarks/recipes_2d.py``, section "2-D recipes" of
``benchmarks/README.md``).

On quadrilaterals and hexahedral grids, no recipe of MTE1 is robustly
better than the thesis' (the winner changes with the geometry), so
``mesh`` stays their default. In bending on coarse node sets it is soft
(``tests/test_gallery.py``; ``docs/examples/ex02_cantilever.py``). What is
robustly better there is not a recipe but another quadrature: the
quadratic fit WTE2 at moment-matched points (``shape="WTE2",
family_quadrature="moments"``,
:mod:`~skfem_pg.discretization.moment_quadrature`), which is opt-in until
the thesis' formulations are measured on it.

The Table 7.1 names mean what the thesis means (``mesh``);
the package tokens ``kNN`` and ``meshU`` at the end of a name select
these recipes (``"VCBCPBG V5m Unl TL kNN"``, :mod:`skfem_pg.naming`).
"""
import numpy as np
import skfem as fem

#: recipe name -> (family rule, quadrature weights, bond weight exponent)
RECIPES = {
    "mesh": ("mesh", "volume", 1),
    "meshU": ("mesh", "uniform", 0),
    "kNN": ("nearest", "uniform", 0),
}
#: family rule -> the (weights, exponent) it comes with when named
#: alone (``families="mesh"``: the thesis'); other rules and given
#: families: the thesis' ("volume", 1)
_WITH_RULE = {"mesh": ("volume", 1), "nearest": ("uniform", 0)}


def default_recipe(particles, method="PBG", shape="MTE1"):
    """The recipe :class:`~skfem_pg.FamilyBasis` uses when ``families``
    is not given (module docstring): for PBG with MTE1 on the vertices of
    a simplex mesh ``"kNN"`` in 3-D and ``"meshU"`` in 2-D, else
    ``"mesh"``.

    >>> import skfem as fem, skfem_pg as pg
    >>> default_recipe(pg.Particles.from_mesh(fem.MeshTri()))
    'meshU'
    >>> default_recipe(pg.Particles.from_mesh(fem.MeshQuad()))
    'mesh'
    """
    mesh = particles.mesh
    if method == "PBG" and shape == "MTE1" and particles.kind == "vertices":
        if particles.dim == 3 and isinstance(mesh, fem.MeshTet):
            return "kNN"
        if particles.dim == 2 and isinstance(mesh, fem.MeshTri):
            return "meshU"
    return "mesh"


def resolve(particles, families, weights, weight_exponent, method, shape):
    """``(families, weights, weight_exponent, recipe)`` with every
    ``None`` / ``"auto"`` replaced: ``families=None`` takes the default
    recipe's rule, weights and exponent; a named rule its own
    (``"nearest"``: ``"uniform"``, 0; ``"mesh"`` and any other rule or
    given families: the thesis' ``"volume"``, 1); ``recipe`` the name of
    :data:`RECIPES` whose three choices the result makes (the default
    recipe's name first), else ``None``."""
    if families is None:
        default = default_recipe(particles, method, shape)
        families, w, n = RECIPES[default]
    else:
        default = None
        w, n = weights_of_rule(families)
    if weights in (None, "auto"):
        weights = w
    if weight_exponent in (None, "auto"):
        weight_exponent = n
    return families, weights, weight_exponent, name_of(
        families, weights, weight_exponent)


def name_of(rule, weights, weight_exponent):
    """The name of the recipe that is family rule ``rule``, ``weights``
    and ``weight_exponent``, else ``None`` (given families, other
    combinations).

    >>> name_of("nearest", "uniform", 0), name_of("nearest", "volume", 0)
    ('kNN', None)
    """
    key = (rule if isinstance(rule, str) else None, weights,
           weight_exponent)
    return next((k for k, v in RECIPES.items() if v == key), None)


def weights_of_rule(rule):
    """``(weights, exponent)`` a family rule named alone comes with
    (``"nearest"``: uniform, 0; ``"mesh"``, other rules and given
    families: the thesis' volume weights (4.30), 1)."""
    return _WITH_RULE.get(rule if isinstance(rule, str) else None,
                          RECIPES["mesh"][1:])


def check_exponent(n):
    """The bond weight exponent as a float; raises ``ValueError`` for a
    negative or non-finite one (a negative exponent weighs far members
    more than near ones, which the Taylor expansions do not survive on
    graded node sets)."""
    try:
        v = float(n)
    except (TypeError, ValueError):
        raise ValueError("weight_exponent must be a number >= 0, got {!r}"
                         .format(n)) from None
    if not np.isfinite(v) or v < 0:
        raise ValueError("weight_exponent must be a number >= 0, got {!r}"
                         .format(n))
    return v


__all__ = ["RECIPES", "default_recipe", "name_of", "resolve",
           "weights_of_rule",
           "check_exponent"]
