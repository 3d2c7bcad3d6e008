"""PBG recipes on 3-D node sets: the thesis' (mesh families, volume
weights) against kNN (nearest-neighbour families, uniform weights, unit
bond weights; the default on tetrahedra since issue #27) and the
moment-matched quadrature of the quadratic fit (MQ, issue 45), O1 and O2
on the same nodes, linear elasticity (lambda = 100, mu = 40).

Geometries (``--geometries``):

* ``cook`` — the 3-D Cook's membrane (``cook3d.geo``, thickness 10,
  clamped at x = 0, traction 0.04 in z on x = 48): corner w(48, 60, 10);
* ``beam`` — a cantilever 20 x 2 x 2 (``beam3d.geo``), tip traction 0.01
  in z: w(20, 1, 1);
* ``hole`` — a plate 10 x 10 x 2 with a through hole of radius 2
  (``plate_hole3d.geo``), pulled in x by 0.01: u(10, 5, 1);
* ``hex`` — the Cook's membrane on regular n x n x n/4 hexahedral grids
  distorted by ±0.3h (H1 instead of O1/O2), where the thesis recipe wins.

Errors of the probe value and of the compliance f·u against an O2
overkill on a finer tetrahedral mesh (H2 on the hex grids' problem), whose
own error is estimated by its difference to the overkill one size
coarser (printed).  Nodes, non-zeros per row and wall time (basis or FE
setup, assembly, ``pg.solvers.direct``) per run; one table per geometry
into ``benchmarks/README.md``.

    python benchmarks/recipes_3d.py [--geometries cook beam hole hex]
"""
import os
import time
import warnings

import numpy as np
import skfem as fem

import skfem_pg as pg
from skfem_pg.formulations import linear_elasticity
from harness import (demo_parser, markdown_table, update_results)

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS = os.path.join(HERE, "README.md")
FORM = linear_elasticity(100.0, 40.0)
#: geometry -> (geo file, clamp x, load x, load component, load, probe,
#: node-set sizes, overkill sizes (coarser, finer))
GEOMETRIES = {
    "cook": ("cook3d.geo", 0.0, 48.0, 2, 0.04, (48.0, 60.0, 10.0),
             (3.5, 2.5, 2.0, 1.6, 1.3), (1.0, 0.8)),
    "beam": ("beam3d.geo", 0.0, 20.0, 2, 0.01, (20.0, 1.0, 1.0),
             (1.0, 0.7, 0.5, 0.35, 0.25), (0.18, 0.14)),
    "hole": ("plate_hole3d.geo", 0.0, 10.0, 0, 0.01, (10.0, 5.0, 1.0),
             (1.2, 0.8, 0.6, 0.45, 0.35), (0.3, 0.25)),
}
HEX = (12, 16, 20, 24)
METHODS = {
    "O1": lambda m: fem.Basis(m, fem.ElementVector(fem.ElementTetP1())),
    "O2": lambda m: fem.Basis(m, fem.ElementVector(fem.ElementTetP2())),
    "H1": lambda m: fem.Basis(m, fem.ElementVector(fem.ElementHex1())),
    "PG thesis (mesh)": lambda m: pg.FamilyBasis(m, dim=3, families="mesh"),
    "PG kNN": lambda m: pg.FamilyBasis(m, dim=3, families="nearest"),
    "PG MQ": lambda m: pg.FamilyBasis(m, dim=3, shape="WTE2",
                                      family_quadrature="moments"),
}


def solve(make, mesh, spec):
    """(probe value, compliance, nnz per row, seconds) of one method."""
    _, xc, xl, comp, q, probe = spec[:6]
    t0 = time.perf_counter()
    basis = make(mesh)
    K = pg.assemble(FORM, basis)
    elem = basis.elem if isinstance(basis, fem.Basis) else \
        fem.ElementVector(pg.particles.linear_elements(mesh)[0])
    fb = fem.FacetBasis(mesh, elem, facets=mesh.facets_satisfying(
        lambda x: np.isclose(x[0], xl)))
    f = fem.LinearForm(lambda v, w: q * v[comp]).assemble(fb)
    D = basis.get_dofs(mesh.facets_satisfying(
        lambda x: np.isclose(x[0], xc)))
    D = D.all() if hasattr(D, "all") else D
    u = fem.solve(*fem.condense(K, f, D=D), solver=pg.solvers.direct)
    seconds = time.perf_counter() - t0
    w = float((basis.probes(np.array(probe)[:, None]) @ u)[comp])
    return w, float(f @ u), K.nnz / K.shape[0], seconds


def study(name, spec, meshes, methods, ref_meshes, ref_method):
    refs = [solve(METHODS[ref_method], m, spec)[:2] for m in ref_meshes]
    (w0, c0), (wr, cr) = refs
    print("\n{}: overkill {} on {} / {} nodes: w {:.7f} / {:.7f}, "
          "compliance {:.7e} / {:.7e} (difference {:.2%}, {:.2%})".format(
              name, ref_method, ref_meshes[0].nvertices,
              ref_meshes[1].nvertices, w0, wr, c0, cr, wr / w0 - 1,
              cr / c0 - 1), flush=True)
    rows = []
    for mesh in meshes:
        for method in methods:
            w, c, nnz, t = solve(METHODS[method], mesh, spec)
            rows.append([mesh.nvertices, method, "{:+.2%}".format(w / wr - 1),
                         "{:+.2%}".format(c / cr - 1), "{:.0f}".format(nnz),
                         "{:.2f}".format(t)])
            print("{:6d} {:18s} w {:>8s}  compliance {:>8s}  nnz/row {:>4s}"
                  "  {:>6s} s".format(*rows[-1]), flush=True)
    text = ("`python benchmarks/recipes_3d.py --geometries {}`: linear "
            "elasticity; errors against {} on {} nodes (its difference to "
            "{} nodes: w {:.2%}, compliance {:.2%}).\n\n".format(
                name, ref_method, ref_meshes[1].nvertices,
                ref_meshes[0].nvertices, wr / w0 - 1, cr / c0 - 1)
            + markdown_table(["nodes", "method", "probe error",
                              "compliance error", "nnz/row", "time [s]"],
                             rows))
    print("updated", update_results(RESULTS, "recipes_3d_" + name, text))


def main(geometries):
    warnings.filterwarnings("ignore", message="Indefinite matrix")
    print(pg.threads.describe())
    print("direct solver:", "MKL PARDISO" if
          pg.solvers.linear.pardiso_available() else "SuperLU (RCM + MMD)")
    for g in geometries:
        if g == "hex":
            spec = GEOMETRIES["cook"]
            meshes = [pg.meshing.cook_membrane_3d(n, n // 4, 10.0, 0.3, n)
                      for n in HEX]
            refs = [pg.meshing.cook_membrane_3d(n, n // 4, 10.0)
                    for n in (24, 32)]
            METHODS["H2"] = lambda m: fem.Basis(
                m, fem.ElementVector(fem.ElementHex2()))
            study(g, spec, meshes, ["H1", "PG thesis (mesh)", "PG kNN",
                                    "PG MQ"], refs, "H2")
            continue
        spec = GEOMETRIES[g]
        geo = pg.meshing.geo_path(spec[0])
        meshes = [pg.meshing.from_geo(geo, size=s) for s in spec[6]]
        refs = [pg.meshing.from_geo(geo, size=s) for s in spec[7]]
        study(g, spec, meshes, ["O1", "O2", "PG thesis (mesh)", "PG kNN",
                                "PG MQ"], refs, "O2")


if __name__ == "__main__":
    ap = demo_parser(__doc__)
    ap.add_argument("--geometries", nargs="+", default=["cook", "beam",
                                                        "hole", "hex"],
                    choices=["cook", "beam", "hole", "hex"],
                    help="which node sets to study: Cook's membrane, a cantilever, a plate with a hole (tetrahedra), a hexahedral grid")
    main(ap.parse_args().geometries)
