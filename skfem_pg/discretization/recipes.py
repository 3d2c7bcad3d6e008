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
``mesh``   ``"mesh"``, ``"volume"``, 1 (the thesis')        2-D; hexahedra;
                                                            PPG, WTE1/WTE2;
                                                            particles w/o mesh
                                                            (``"horizon"``)
``kNN``    ``"nearest"`` (10, pairwise), ``"uniform"``, 0   PBG MTE1 on 3-D
                                                            tetrahedra
=========  ===============================================  ===================

Why ``kNN`` on tetrahedra.  A gmsh tetrahedral mesh gives a vertex 14
neighbours on average and as many as 30, spread over the cells around it;
the 1-ring family, weighted by member volumes, averages the strain energy
of a bending field over a region reaching far beyond the master
(:mod:`~skfem_pg.discretization.quadrature`), and VC PBG Unl is soft: on
the linear 3-D Cook's membrane its corner error is +15 / +25 / +19 / +13 /
+9.2 % at 615 / 1343 / 2254 / 4038 / 6813 nodes (O1: −30 / −18 / −14 /
−8.8 / −6.3 %; against an O2 overkill on 25.5k nodes, itself within about
0.1 %).  The nearest ten particles are the compact neighbourhood the
moving Taylor expansion needs (at least nine others in general position;
pairwise completion adds two on average); uniform weights keep the energy
at the family instead of on its largest (farthest) members, and unit bond
weights use the few members evenly.  Each choice alone helps little
(uniform weights on 1-ring families: +7.8 % at 2254 nodes; ten nearest
with volume weights: +5.1 %, stalling there); together they converge from
below like FE: −18 / −3.1 / −1.7 / +0.4 / −0.03 % on the same node sets
(the tables ``recipes_3d_*`` in ``benchmarks/README.md``, written by
``benchmarks/recipes_3d.py``).  On hexahedral grids (at most 27 regularly
placed members) and in 2-D the thesis recipe was measured the more
accurate on the geometries of ``recipes_3d`` and stays the default; in
bending on coarse node sets it is soft there too (a 5 × 1 × 1 hexahedral
beam, 525 nodes: tip +38 %, ``kNN`` −2.0 %, H1 −3.4 %,
``tests/test_gallery.py``; the plane-strain cantilever of
``docs/examples/ex02_cantilever.py``, 297 nodes: +6.5 %, ``kNN`` −2.8 %,
Q1 −2.2 %), which a change of default would have to weigh.

The Table 7.1 names mean what the thesis means (``mesh``);
the package token ``kNN`` at the end of a name selects this recipe
(``"VCBCPBG V5m Unl TL kNN"``, :mod:`skfem_pg.naming`).
"""
import numpy as np
import skfem as fem

#: recipe name -> (family rule, quadrature weights, bond weight exponent)
RECIPES = {
    "mesh": ("mesh", "volume", 1),
    "kNN": ("nearest", "uniform", 0),
}
#: family rule -> the (weights, exponent) it comes with; other rules and
#: given families: the thesis' ("volume", 1)
_WITH_RULE = {rule: (w, n) for rule, w, n in RECIPES.values()}


def default_recipe(particles, method="PBG", shape="MTE1"):
    """The recipe :class:`~skfem_pg.FamilyBasis` uses when neither
    ``families`` nor ``weights`` is given (module docstring): ``"kNN"``
    for PBG with MTE1 on the vertices of a 3-D simplex mesh, else
    ``"mesh"``."""
    mesh = particles.mesh
    if (method == "PBG" and shape == "MTE1" and particles.dim == 3
            and isinstance(mesh, fem.MeshTet)
            and particles.kind == "vertices"):
        return "kNN"
    return "mesh"


def resolve(particles, families, weights, weight_exponent, method, shape):
    """``(families, weights, weight_exponent, recipe)`` with every
    ``None`` / ``"auto"`` replaced: ``families`` (``None``: the default
    recipe's rule) a rule name or a :class:`~skfem_pg.Families`; weights
    and exponent follow the family rule (``"nearest"``: ``"uniform"``, 0;
    any other rule or given families: ``"volume"``, 1); ``recipe`` the
    name of :data:`RECIPES` whose three choices the result makes, else
    ``None``."""
    if families is None:
        families = RECIPES[default_recipe(particles, method, shape)][0]
    rule = families if isinstance(families, str) else None
    w, n = _WITH_RULE.get(rule, RECIPES["mesh"][1:])
    if weights in (None, "auto"):
        weights = w
    if weight_exponent in (None, "auto"):
        weight_exponent = n
    key = (rule, weights, weight_exponent)
    recipe = next((k for k, v in RECIPES.items() if v == key), None)
    return families, weights, weight_exponent, recipe


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


__all__ = ["RECIPES", "default_recipe", "resolve",
           "check_exponent"]
