"""PBG recipes on 2-D node sets (issue 45, item 1): the family rule, the
quadrature weights and the bond weight exponent, against T1 / Q1 on the
same nodes, in bending, tension and on a scalar (Poisson) problem.

Geometries (gmsh triangles and recombined quadrilaterals of the same
size; plane strain, lambda = 100, mu = 40):

* ``ring`` — a curved cantilever, the quarter ring 5 <= r <= 6 clamped at
  y = 0, a unit traction in x on its end x = 0 (bending); with mapped
  quadrilaterals (2, 4, 8, 16 cells through the thickness) as a third
  node set;
* ``beam`` — a straight cantilever 10 x 1 clamped at x = 0, a unit
  traction in y at x = 10 (bending);
* ``lshape`` — an L bracket (the square 4 x 4 less [1, 4] x [1, 4], arms
  of width 1) clamped at y = 0, a unit traction in x on its top end y = 4
  (bending with a re-entrant corner);
* ``hole`` — a quarter plate 4 x 4 with an elliptic hole (semi-axes 1 in
  x, 0.5 in y), symmetry on x = 0 and y = 0, pulled in y on y = 4
  (tension, stress concentration);
* ``poisson`` — -div grad u = 1, u = 0 on the boundary of the unit
  square, the L bracket and the unit disk.

Variants: the thesis recipe (the default on quadrilaterals), ``meshU``
(the default on triangles), nearest-neighbour families with ties, and
the moment-matched quadrature of the quadratic fit
(``family_quadrature="moments"``,
:mod:`skfem_pg.discretization.moment_quadrature`).

Each value is the signed compliance error f.u / f.u_ref - 1 in % (+ =
soft, - = stiff); the reference is T2 on a finer mesh of the same
geometry (its own error, estimated by the T2 one size coarser, is
printed).  T2 / Q2 on the same cells (about four times the unknowns)
is the row to read per unknown: against PG on a node set with about four
times the nodes.  The ratio |e_PG| / |e_FE| at the finest node set is given
only where neither error changes sign under refinement.  One table per
geometry into ``benchmarks/README.md`` and ``docs/guide/accuracy.md``
(sections ``recipes_2d_*``).

    python benchmarks/recipes_2d.py [--geometries ring beam lshape hole poisson]
"""
import os
import tempfile
import time
import warnings

import numpy as np
import skfem as fem
from skfem.models.poisson import laplace, unit_load

import skfem_pg as pg
from skfem_pg.formulations import linear_elasticity
from harness import demo_parser, markdown_table, update_results

HERE = os.path.dirname(os.path.abspath(__file__))
#: the pages whose sections ``recipes_2d_*`` this script writes: the
#: measurements page and the documentation's accuracy page
RESULTS = [os.path.join(HERE, "README.md"),
           os.path.join(HERE, os.pardir, "docs", "guide", "accuracy.md")]
FORM = linear_elasticity(100.0, 40.0)


def occ_mesh(build, size, quad=False, order=1, size_at=None):
    """A gmsh mesh of the OpenCASCADE geometry ``build(occ)``: triangles,
    or recombined quadrilaterals (``quad``), of size ``size``, or graded:
    ``size * size_at(x, y)`` (``size_at`` at most 1)."""
    import gmsh
    gmsh.initialize(interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        build(gmsh.model.occ)
        gmsh.model.occ.synchronize()
        gmsh.model.addPhysicalGroup(
            2, [e[1] for e in gmsh.model.getEntities(2)], 1)
        if size_at is None:
            gmsh.option.setNumber("Mesh.MeshSizeMax", size)
            gmsh.option.setNumber("Mesh.MeshSizeMin", 0.5 * size)
        else:
            gmsh.model.mesh.setSizeCallback(
                lambda dim, tag, x, y, z, lc: size * size_at(x, y))
            for option in ("ExtendFromBoundary", "FromPoints",
                           "FromCurvature"):
                gmsh.option.setNumber("Mesh.MeshSize" + option, 0)
        if quad:
            gmsh.option.setNumber("Mesh.RecombineAll", 1)
            gmsh.option.setNumber("Mesh.RecombinationAlgorithm", 1)
        gmsh.model.mesh.generate(2)
        gmsh.model.mesh.setOrder(order)
        with tempfile.TemporaryDirectory() as tmp:
            fn = os.path.join(tmp, "mesh.msh")
            gmsh.write(fn)
            mesh = fem.Mesh.load(fn)
    finally:
        gmsh.finalize()
    return pg.meshing.renumber(mesh) if order == 1 else mesh


def ring(occ):
    outer, inner = occ.addDisk(0, 0, 0, 6, 6), occ.addDisk(0, 0, 0, 5, 5)
    cut, _ = occ.cut([(2, outer)], [(2, inner)])
    occ.intersect(cut, [(2, occ.addRectangle(0, 0, 0, 10, 10))])


def mapped_ring(n):
    """The ring as mapped quadrilaterals, n cells through the thickness,
    8n around (near squares)."""
    m = fem.MeshQuad.init_tensor(np.linspace(5, 6, n + 1),
                                 np.linspace(0, np.pi / 2, 8 * n + 1))
    return fem.MeshQuad(np.array([m.p[0] * np.cos(m.p[1]),
                                  m.p[0] * np.sin(m.p[1])]), m.t)


def beam(occ):
    occ.addRectangle(0, 0, 0, 10, 1)


def lshape(occ):
    occ.cut([(2, occ.addRectangle(0, 0, 0, 4, 4))],
            [(2, occ.addRectangle(1, 1, 0, 3, 3))])


def hole(occ):
    loop = occ.addCurveLoop([occ.addEllipse(0, 0, 0, 1.0, 0.5)])
    occ.cut([(2, occ.addRectangle(0, 0, 0, 4, 4))],
            [(2, occ.addPlaneSurface([loop]))])


def square(occ):
    occ.addRectangle(0, 0, 0, 1, 1)


def disk(occ):
    occ.addDisk(0, 0, 0, 1, 1)


def on(axis, value):
    return lambda x: np.abs(x[axis] - value) < 1e-9


#: elasticity: geometry -> (builder, node-set sizes, overkill size,
#: [(clamped facets, components)], (loaded facets, traction))
ELASTIC = {
    "ring": (ring, (0.25, 0.12, 0.06), 0.02, [(on(1, 0), (0, 1))],
             (on(0, 0), (1.0, 0.0))),
    "beam": (beam, (0.25, 0.125, 0.0625), 0.02, [(on(0, 0), (0, 1))],
             (on(0, 10), (0.0, 1.0))),
    "lshape": (lshape, (0.25, 0.12, 0.06), 0.015, [(on(1, 0), (0, 1))],
               (on(1, 4), (1.0, 0.0))),
    "hole": (hole, (0.3, 0.15, 0.075), 0.02,
             [(on(0, 0), (0,)), (on(1, 0), (1,))], (on(1, 4), (0.0, 1.0))),
}
#: Poisson: domain -> (builder, node-set sizes, overkill size)
POISSON = {"square": (square, (0.1, 0.05, 0.025), 0.008),
           "lshape": (lshape, (0.25, 0.12, 0.06), 0.02),
           "disk": (disk, (0.2, 0.1, 0.05), 0.016)}


def _nearest(k):
    return lambda p: pg.families.nearest(p, k)


#: PBG variants: name -> FamilyBasis keywords (a callable ``families``
#: gets the particles)
VARIANTS = {
    "mesh, volume, n = 1 (thesis; default on quads)": dict(
        families="mesh"),
    "mesh, uniform, n = 0 (meshU; default on triangles)": dict(
        families="mesh", weights="uniform", weight_exponent=0),
    "mesh, uniform, n = 1": dict(families="mesh", weights="uniform",
                                 weight_exponent=1),
    "6 nearest + ties, uniform, n = 0": dict(
        families=_nearest(6), weights="uniform", weight_exponent=0),
    "6 nearest + ties, uniform, n = 1": dict(
        families=_nearest(6), weights="uniform", weight_exponent=1),
    "8 nearest + ties, uniform, n = 1": dict(
        families=_nearest(8), weights="uniform", weight_exponent=1),
    "12 nearest + ties, uniform, n = 1": dict(
        families=_nearest(12), weights="uniform", weight_exponent=1),
    "WTE2, moment quadrature (MQ)": dict(shape="WTE2",
                                         family_quadrature="moments"),
}


def fe_element(mesh):
    return pg.particles.linear_elements(mesh)[0]


#: the quadratic FE row of the tables: T2 / Q2 on the same cells
QUADRATIC = "quadratic"


def fe_basis(mesh, kw, vector):
    """The FE basis of a table row: linear FE (``kw`` None) or quadratic
    (``kw`` :data:`QUADRATIC`) on the node set's cells; else ``None``."""
    if kw is None:
        elem = fe_element(mesh)
    elif kw is QUADRATIC:
        elem = (fem.ElementTriP2() if isinstance(mesh, fem.MeshTri)
                else fem.ElementQuad2())
    else:
        return None
    return fem.Basis(mesh, fem.ElementVector(elem) if vector else elem)


def unknowns_ratio(mesh):
    """Unknowns of quadratic FE over the vertices' on ``mesh``."""
    e2 = (fem.ElementTriP2() if isinstance(mesh, fem.MeshTri)
          else fem.ElementQuad2())
    return fem.Basis(mesh, e2).N / mesh.nvertices


def _dirichlet(basis, mesh, clamps):
    D = []
    for select, comps in clamps:
        dofs = basis.get_dofs(mesh.facets_satisfying(select))
        for c in comps:
            key = "u^{}".format(c + 1)
            D += [d[key] for d in (dofs.nodal, dofs.facet) if key in d]
    return np.unique(np.concatenate(D))


def elastic_compliance(basis, mesh, spec):
    """f.u of the elastic problem ``spec`` on ``basis``."""
    _, _, _, clamps, (loaded, t) = spec
    K = pg.assemble(FORM, basis)
    facets = mesh.facets_satisfying(loaded)
    if isinstance(basis, pg.FamilyBasis):
        f = pg.traction(basis, facets, list(t))
    else:
        fb = fem.FacetBasis(mesh, basis.elem, facets=facets)
        f = fem.LinearForm(lambda v, w: t[0] * v[0] + t[1] * v[1]) \
            .assemble(fb)
    D = _dirichlet(basis, mesh, clamps)
    u = fem.solve(*fem.condense(K, f, D=D), solver=pg.solvers.direct)
    return float(f @ u)


def poisson_compliance(basis, mesh):
    K, f = pg.assemble(laplace, basis), pg.assemble(unit_load, basis)
    D = basis.get_dofs()
    D = D.all() if hasattr(D, "all") else D
    u = fem.solve(*fem.condense(K, f, D=D), solver=pg.solvers.direct)
    return float(f @ u)


def pg_basis(mesh, kw, dim):
    kw = dict(kw)
    p = pg.Particles.from_mesh(mesh)
    if callable(kw.get("families")):
        kw["families"] = kw["families"](p)
    return pg.FamilyBasis(p, dim=dim, **kw)


def ratio_at_finest(errs, fe_errs):
    """|e_PG| / |e_FE| at the finest node set as text, or ``"crosses
    zero"`` where either error changes sign under refinement (its small
    value there is a crossing, not convergence)."""
    if errs is fe_errs:
        return ""
    for e in (errs, fe_errs):
        if not np.all(np.isfinite(e)) or len(set(np.sign(e))) > 1:
            return "crosses zero"
    return "{:.2f}".format(abs(errs[-1] / fe_errs[-1]))


def table(title, kinds, compliance, reference):
    """Rows of signed errors for each variant on each node-set kind;
    printed and returned as markdown."""
    lines = []
    for kind, meshes in kinds.items():
        tri = isinstance(meshes[0], fem.MeshTri)
        fe_name = "T1" if tri else "Q1"
        fe2_name = "{} ({:.1f}x the unknowns)".format(
            "T2" if tri else "Q2", unknowns_ratio(meshes[-1]))
        runs = {fe_name: None, fe2_name: QUADRATIC, **VARIANTS}
        nodes = [int(m.nvertices) for m in meshes]
        rows, fe_err = [], None
        for name, kw in runs.items():
            errs, secs = [], 0.0
            for m in meshes:
                t0 = time.perf_counter()
                try:
                    c = compliance(m, kw)
                    errs.append(100 * (c / reference - 1))
                except (pg.FamilyError, pg.CorrectionError) as err:
                    print("   ", name, nodes, type(err).__name__, err)
                    errs.append(np.nan)
                secs += time.perf_counter() - t0
            if name == fe_name:
                fe_err = errs
            ratio = ratio_at_finest(errs, fe_err)
            rows.append([name] + ["{:+.2f} %".format(e) for e in errs]
                        + [ratio, "{:.2f}".format(secs)])
            print("  {:50s}".format(name) + " ".join(
                "{:+8.2f}".format(e) for e in errs), ratio, flush=True)
        lines.append("**{}, {}** ({} nodes; FE = {}; {} on the same "
                     "cells)\n\n".format(title, kind, " / ".join(
                         map(str, nodes)), fe_name, fe2_name)
            + markdown_table(["method"] + ["{} nodes".format(n)
                                           for n in nodes]
                             + ["PG/FE at the finest", "time [s]"], rows))
    return "\n\n".join(lines)


def overkill_and_node_sets(title, build, sizes, ref_size, solve):
    """``(n0, c0, n1, ref, kinds)``: ``solve(mesh)`` (f.u) on T2 meshes of
    sizes 1.5 ``ref_size`` and ``ref_size``, and the gmsh triangle and
    quadrilateral node sets of ``sizes``."""
    refs = []
    for s in (1.5 * ref_size, ref_size):
        m = occ_mesh(build, s, order=2)
        refs.append((m.nvertices, solve(m)))
    (n0, c0), (n1, ref) = refs
    print("\n{}: T2 overkill {} / {} nodes, compliance {:.7g} / {:.7g} "
          "({:+.1e})".format(title, n0, n1, c0, ref, ref / c0 - 1),
          flush=True)
    kinds = {"gmsh triangles": [occ_mesh(build, s) for s in sizes],
             "gmsh quadrilaterals": [occ_mesh(build, s, quad=True)
                                     for s in sizes]}
    return n0, c0, n1, ref, kinds


def elastic_study(name):
    spec = ELASTIC[name]
    n0, c0, n1, ref, kinds = overkill_and_node_sets(
        name, *spec[:3], lambda m: elastic_compliance(fem.Basis(
            m, fem.ElementVector(fem.ElementTriP2())), m, spec))
    if name == "ring":
        kinds["mapped quadrilaterals"] = [mapped_ring(n) for n in
                                          (2, 4, 8, 16)]

    def compliance(mesh, kw):
        basis = fe_basis(mesh, kw, True)
        if basis is None:
            basis = pg_basis(mesh, kw, 2)
        return elastic_compliance(basis, mesh, spec)

    text = ("`python benchmarks/recipes_2d.py --geometries {}`: signed "
            "compliance error (+ = soft) against T2 on {} nodes (its "
            "difference to {} nodes: {:+.1e}).\n\n".format(
                name, n1, n0, ref / c0 - 1)
            + table(name, kinds, compliance, ref))
    write(name, text)


def write(name, text):
    for page in RESULTS:
        print("updated", update_results(page, "recipes_2d_" + name, text))


def poisson_study():
    parts = []
    for name, (build, sizes, ref_size) in POISSON.items():
        n0, c0, n1, ref, kinds = overkill_and_node_sets(
            "poisson " + name, build, sizes, ref_size,
            lambda m: poisson_compliance(fem.Basis(m, fem.ElementTriP2()),
                                         m))

        def compliance(mesh, kw):
            basis = fe_basis(mesh, kw, False)
            if basis is None:
                basis = pg_basis(mesh, kw, None)
            return poisson_compliance(basis, mesh)

        parts.append("Against T2 on {} nodes ({:+.1e} to {} nodes); on "
                     "the disk the node sets' polygons lose area, which "
                     "FE and PG share.\n\n".format(n1, ref / c0 - 1, n0)
                     + table("Poisson, " + name, kinds, compliance, ref))
    text = ("`python benchmarks/recipes_2d.py --geometries poisson`: "
            "-div grad u = 1, u = 0 on the boundary; signed error of "
            "f.u (+ = soft).\n\n" + "\n\n".join(parts))
    write("poisson", text)


def main(geometries):
    warnings.filterwarnings("ignore", message="Indefinite matrix")
    for g in geometries:
        poisson_study() if g == "poisson" else elastic_study(g)


if __name__ == "__main__":
    ap = demo_parser(__doc__, quick=False)
    choices = list(ELASTIC) + ["poisson"]
    ap.add_argument("--geometries", nargs="+", default=choices,
                    choices=choices, help="which problems to study")
    main(ap.parse_args().geometries)
