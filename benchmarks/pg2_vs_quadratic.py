"""PG2 against quadratic FE per unknown and per second (issue 48, item 3).

PG2 (:mod:`skfem_pg.discretization.blend`: the families' quadratic fits
blended by the mesh's hat functions, one unknown per vertex and
component, Dirichlet conditions by Nitsche terms) beside T1/Q1, T2/Q2,
O1/O2, H1/H2 and the first-order PG on the same node sets:

* 2-D, linear elasticity (plane strain, lambda = 100, mu = 40; the
  geometries of ``recipes_2d.py``, gmsh triangles): ``ring`` (a curved
  cantilever) and ``hole`` (a plate with an elliptic hole in tension);
  signed compliance error against T2 overkill;
* 3-D, neo-Hooke (iso/vol, lambda = 100, mu = 40): ``beam3d``, a
  cantilever 4 x 1 x 1 of hexahedra (n x n/4 x n/4 cells) clamped at x =
  0 with a dead traction 0.5 in -z on x = 4 (tip deflection; FE O1/O2 on
  the hexahedra split into tetrahedra, the same vertices); the reference
  is H2 on 32 x 8 x 8 cells.  The 3-D Cook is ``demos/cook_3d.py
  --methods O1 O2 PG2``.

Every row: node set, unknowns, signed error in %, wall seconds (basis,
assembly and solve; all Newton iterations), the tangent's non-zeros per
row; then each method's time to 1 % and 0.3 % (the first node set from
which on its error stays within).  Tables into ``benchmarks/README.md``
(sections ``pg2_*``).

    python benchmarks/pg2_vs_quadratic.py [--geometries ring hole beam3d]
        [--quick]
"""
import os
import time

import numpy as np
import skfem as fem

import skfem_pg as pg
from harness import demo_parser, markdown_table, update_results
from recipes_2d import ELASTIC, FORM, elastic_compliance, occ_mesh
from skfem_pg.formulations import Hyperelastic, WeakDirichlet
from skfem_pg.materials import LinearElastic, NeoHookeIsoVol
from skfem_pg.scenes import Scene

HERE = os.path.dirname(os.path.abspath(__file__))
#: the page whose sections ``pg2_*`` this script writes
RESULTS = os.path.join(HERE, "README.md")
TARGETS = (0.01, 0.003)
#: 2-D node-set sizes (gmsh) per geometry, finest last
SIZES_2D = {"ring": (0.5, 0.25, 0.12, 0.06), "hole": (0.6, 0.3, 0.15,
                                                      0.075)}
#: 3-D beam: cells along the length (n x n/4 x n/4)
SIZES_3D = (8, 12, 16, 24)


def pg2_compliance(mesh, spec):
    """f.u of the linear elastic problem ``spec`` (``recipes_2d.ELASTIC``)
    on PG2, the clamps by Nitsche terms; ``(f.u, nnz per row)``."""
    _, _, _, clamps, (loaded, t) = spec
    basis = pg.FamilyBasis(mesh, dim=2, order=2)
    conditions = [(mesh.facets_satisfying(select), {c: 0.0 for c in comps})
                  for select, comps in clamps]
    model = WeakDirichlet(Hyperelastic(basis, LinearElastic(lam=100.0, mu=40.0)),
                          conditions)
    f = pg.traction(basis, mesh.facets_satisfying(loaded), list(t))
    s = model.state(np.zeros(basis.N))
    K = model.tangent(s)
    u = pg.solvers.direct(K, f + model.load() - model.internal_force(s))
    return float(f @ u), K.nnz / K.shape[0]


def fe_compliance(mesh, spec, quadratic):
    elem = fem.ElementTriP2() if quadratic else fem.ElementTriP1()
    basis = fem.Basis(mesh, fem.ElementVector(elem))
    K = pg.assemble(FORM, basis)
    return elastic_compliance(basis, mesh, spec), K.nnz / K.shape[0], \
        basis.N


def pg_compliance(mesh, spec):
    basis = pg.FamilyBasis(mesh, dim=2)
    K = pg.assemble(FORM, basis)
    return elastic_compliance(basis, mesh, spec), K.nnz / K.shape[0]


def timed(fun, *args):
    t0 = time.perf_counter()
    out = fun(*args)
    return out, time.perf_counter() - t0


def time_to(rows, method, target):
    """Seconds of the first node set from which on ``method``'s error
    stays within ``target``; ``None`` if never."""
    mine = [r for r in rows if r["method"] == method]
    for i, r in enumerate(mine):
        if all(abs(q["err"]) <= 100 * target for q in mine[i:]):
            return r
    return None


def summary(rows, methods):
    out = []
    for m in methods:
        cells = [m]
        for t in TARGETS:
            r = time_to(rows, m, t)
            cells.append("{:.2f} s ({} unknowns)".format(r["seconds"],
                                                        r["dofs"])
                         if r else "not reached")
        out.append(cells)
    return markdown_table(["method"] + ["time to {:g} %".format(100 * t)
                                        for t in TARGETS], out)


def table(rows):
    return markdown_table(
        ["node set", "method", "unknowns", "error", "seconds",
         "nnz / row"],
        [[r["set"], r["method"], r["dofs"], "{:+.3f} %".format(r["err"]),
          "{:.2f}".format(r["seconds"]), "{:.0f}".format(r["nnz"])]
         for r in rows])


def study_2d(name, quick):
    spec = ELASTIC[name]
    build, ref_size = spec[0], spec[2]
    sizes = SIZES_2D[name][:2] if quick else SIZES_2D[name]
    ref_mesh = occ_mesh(build, ref_size if not quick else sizes[-1] / 2,
                        order=2)
    ref, _, _ = fe_compliance(ref_mesh, spec, True)
    print("{}: T2 reference on {} nodes, f.u = {:.8g}".format(
        name, ref_mesh.nvertices, ref), flush=True)
    rows = []
    for s in sizes:
        mesh = occ_mesh(build, s)
        label = "{} nodes (h {:g})".format(mesh.nvertices, s)
        runs = {
            "T1": lambda: fe_compliance(mesh, spec, False),
            "T2": lambda: fe_compliance(mesh, spec, True),
            "PG": lambda: pg_compliance(mesh, spec) + (2 * mesh.nvertices,),
            "PG2": lambda: pg2_compliance(mesh, spec)
            + (2 * mesh.nvertices,)}
        for method, run in runs.items():
            (c, nnz, dofs), sec = timed(run)
            rows.append(dict(set=label, method=method, dofs=dofs,
                             err=100 * (c / ref - 1), seconds=sec, nnz=nnz))
            print("  {:24s} {:4s} {:6d} unknowns {:+8.3f} % {:6.2f} s "
                  "nnz/row {:.0f}".format(label, method, dofs,
                                          rows[-1]["err"], sec, nnz),
                  flush=True)
    return ("`python benchmarks/pg2_vs_quadratic.py --geometries {}`: "
            "signed compliance error against T2 on {} nodes; gmsh "
            "triangles.\n\n".format(name, ref_mesh.nvertices)
            + table(rows) + "\n\n" + summary(rows, ["T1", "T2", "PG",
                                                     "PG2"]))


MATERIAL = NeoHookeIsoVol.from_lame(100.0, 40.0)


def beam3d(n):
    m = fem.MeshHex.init_tensor(np.linspace(0, 4, n + 1),
                                *(np.linspace(0, 1, n // 4 + 1),) * 2)
    m = m.with_boundaries({"left": lambda x: x[0] == 0,
                           "right": lambda x: x[0] == 4})
    return Scene("beam3d", m, MATERIAL, clamped=["left"],
                 tractions={"right": [0.0, 0.0, -0.5]},
                 probes={"tip": (4.0, 1.0, 1.0)}, steps=2)


def study_beam3d(quick):
    sizes = SIZES_3D[:2] if quick else SIZES_3D
    ref_n = 16 if quick else 32
    ref = beam3d(ref_n).solve("H2", verbose=False).probes["tip"][2]
    print("beam3d: H2 on {} x {} x {}: w = {:.7f}".format(
        ref_n, ref_n // 4, ref_n // 4, ref), flush=True)
    rows = []
    for n in sizes:
        sc = beam3d(n)
        label = "{} x {} x {} ({} nodes)".format(n, n // 4, n // 4,
                                                 sc.mesh.nvertices)
        for method in ("H1", "O1", "H2", "O2", "PG", "PG2"):
            t0 = time.perf_counter()
            r = sc.solve(method, verbose=False)
            sec = time.perf_counter() - t0
            K = r.model.tangent(r.model.state(r.x))
            rows.append(dict(set=label, method=method, dofs=len(r.u),
                             err=100 * (r.probes["tip"][2] / ref - 1),
                             seconds=sec, nnz=K.nnz / K.shape[0]))
            print("  {:28s} {:4s} {:6d} unknowns {:+8.3f} % {:6.2f} s "
                  "nnz/row {:.0f}".format(label, method, len(r.u),
                                          rows[-1]["err"], sec,
                                          rows[-1]["nnz"]), flush=True)
    return ("`python benchmarks/pg2_vs_quadratic.py --geometries beam3d`: "
            "tip deflection of a neo-Hooke cantilever 4 x 1 x 1 "
            "(hexahedra; O1/O2 on them split into tetrahedra) against H2 "
            "on {} x {} x {} cells.\n\n".format(ref_n, ref_n // 4,
                                                 ref_n // 4)
            + table(rows) + "\n\n" + summary(
                rows, ["H1", "O1", "H2", "O2", "PG", "PG2"]))


def main(geometries=("ring", "hole", "beam3d"), quick=False):
    print(pg.threads.describe())
    for g in geometries:
        text = study_beam3d(quick) if g == "beam3d" else study_2d(g, quick)
        print(text)
        if not quick:
            print("updated", update_results(RESULTS, "pg2_" + g, text))


if __name__ == "__main__":
    parser = demo_parser(__doc__)
    parser.add_argument("--geometries", nargs="+",
                        default=["ring", "hole", "beam3d"],
                        choices=["ring", "hole", "beam3d"],
                        help="the problems to run (module docstring)")
    args = parser.parse_args()
    main(args.geometries, args.quick)
