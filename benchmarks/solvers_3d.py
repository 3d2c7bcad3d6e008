"""Linear solvers on 3-D tangents, side by side on the same matrices: where
a sparse direct solve stops winning against AMG-CG, for PG (the default
kNN recipe) and O1 on the same gmsh tetrahedra of the 3-D Cook's
membrane (linear elasticity, lambda = 100, mu = 40, clamped at x = 0).

Per node set and method, seconds for one solve of the condensed system:

* ``pardiso`` — MKL PARDISO, symmetric indefinite mode on the upper
  triangle (``skfem_pg.solvers.direct``; ``pypardiso``, in the default
  install on x86-64 Linux and Windows);
* ``superlu`` — SciPy's direct solve (SuperLU, COLAMD, what
  ``linear_solver("direct")`` uses in 3-D without PARDISO);
* ``amg`` — ``AMGSolver`` without extra candidates (rigid-body modes
  only): setup + CG to 1e-10;
* ``amg+12`` — with ``PG_CANDIDATES`` = 12 smoothed random candidates
  (Newton's choice for PG), setup + CG;
* ``amg+12 reused`` — the CG time alone with a kept hierarchy: what each
  later Newton iteration pays while the hierarchy is reused.

Solutions are checked against each other (relative difference printed).
A method whose predicted time exceeds ``--max-seconds`` is skipped.

    python benchmarks/solvers_3d.py [--sizes 2.5 1.6 1.2 1.0 0.8]
        [--methods O1 PG] [--solvers pardiso superlu amg amg+12]
"""
import os
import time
import warnings

import numpy as np
import skfem as fem

import skfem_pg as pg
from skfem_pg.formulations import linear_elasticity
from harness import (demo_parser, markdown_table, update_results)
from skfem_pg.solvers.linear import AMGSolver, direct, pardiso_available
from skfem_pg.solvers.static import PG_CANDIDATES

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)),
                       "README.md")
FORM = linear_elasticity(100.0, 40.0)
METHODS = {
    "O1": lambda m: fem.Basis(m, fem.ElementVector(fem.ElementTetP1())),
    "PG": lambda m: pg.FamilyBasis(m, dim=3),
}


def system(method, mesh):
    """Condensed ``(A, b, (doflocs, components))`` of the clamped Cook's
    membrane."""
    basis = METHODS[method](mesh)
    K = pg.assemble(FORM, basis)
    fb = fem.FacetBasis(mesh, fem.ElementVector(fem.ElementTetP1()),
                        facets=mesh.facets_satisfying(
                            lambda x: np.isclose(x[0], 48.0)))
    f = fem.LinearForm(lambda v, w: 0.04 * v[2]).assemble(fb)
    D = basis.get_dofs(mesh.facets_satisfying(
        lambda x: np.isclose(x[0], 0.0)))
    D = D.all() if hasattr(D, "all") else D
    I = np.setdiff1d(np.arange(K.shape[0]), D)
    # interleaved vector dofs: dof j is component j % 3 of its node
    return K[I][:, I].tocsr(), f[I], (basis.doflocs[:, I], I % 3)


def timed(fun, *args):
    t0 = time.perf_counter()
    out = fun(*args)
    return out, time.perf_counter() - t0


def run(A, b, locs, name):
    """``(x, seconds, note)`` of one solver."""
    if name == "pardiso":
        x, t = timed(direct, A, b, "pardiso")
        return x, t, ""
    if name == "superlu":
        x, t = timed(direct, A, b, "colamd")
        return x, t, ""
    cands = PG_CANDIDATES if name == "amg+12" else 0
    amg = AMGSolver(locs[0], candidates=cands, components=locs[1])
    x, t = timed(amg, A, b)
    its = amg.stats["iterations"][-1]
    _, t2 = timed(amg, A, b)  # the hierarchy kept: a later Newton solve
    return x, t, "{} its, setup {:.1f} s, reused {:.1f} s".format(
        its, amg.stats["setup_seconds"] / amg.stats["builds"], t2)


def main():
    ap = demo_parser(__doc__)
    ap.add_argument("--sizes", type=float, nargs="+",
                    default=[2.5, 1.6, 1.2, 1.0, 0.8],
                    help='gmsh element sizes of the 3-D Cook tetrahedra')
    ap.add_argument("--methods", nargs="+", default=["O1", "PG"],
                    help='discretizations whose tangents are solved: O1 and/or PG')
    ap.add_argument("--solvers", nargs="+",
                    default=["pardiso", "superlu", "amg", "amg+12"],
                    help='pardiso, superlu, amg (rigid-body modes only), amg+12 (with 12 random candidates)')
    ap.add_argument("--max-seconds", type=float, default=300.0,
                    help='skip a method whose predicted solve time exceeds this')
    args = ap.parse_args()
    warnings.filterwarnings("ignore", message="Indefinite matrix")
    solvers = [s for s in args.solvers
               if s != "pardiso" or pardiso_available()]
    print(pg.threads.describe())
    geo = pg.meshing.geo_path("cook3d.geo")
    rows, last = [], {}
    for size in args.sizes:
        mesh = pg.meshing.from_geo(geo, size=size)
        for method in args.methods:
            (A, b, locs), t_asm = timed(system, method, mesh)
            n = A.shape[0]
            ref, out = None, {}
            for name in solvers:
                prev = last.get((method, name))
                if prev and prev[1] * (n / prev[0]) ** 1.5 \
                        > args.max_seconds:
                    out[name] = "skipped"
                    continue
                x, t, note = run(A, b, locs, name)
                last[(method, name)] = (n, t)
                ref = x if ref is None else ref
                diff = np.linalg.norm(x - ref) / np.linalg.norm(ref)
                out[name] = "{:.2f}".format(t) + (" ({})".format(note)
                                                  if note else "")
                print("{:6d} nodes {:3s} {:6d} unknowns  {:13s} {:7.2f} s"
                      "  {}  (difference {:.1e})".format(
                          mesh.nvertices, method, n, name, t, note, diff),
                      flush=True)
            rows.append([mesh.nvertices, method, n,
                         "{:.0f}".format(A.nnz / n)]
                        + [out[s] for s in solvers])
        table = markdown_table(["nodes", "method", "unknowns", "nnz/row"]
                               + ["{} [s]".format(s) for s in solvers], rows)
        update_results(RESULTS, "solvers_3d", (
            "`python benchmarks/solvers_3d.py --sizes {}`: one solve of the "
            "condensed linear 3-D Cook system ({}); AMG: setup + CG to "
            "1e-10, its CG iterations, and the CG time again with the "
            "hierarchy kept.\n\n".format(
                " ".join("{:g}".format(s) for s in args.sizes),
                pg.threads.describe()) + table))


if __name__ == "__main__":
    main()
