"""Cook's membrane, neo-Hooke, irregular gmsh triangle node sets:
PG against T1 on the same nodes, error against wall time.

Thesis 7.1: mu = 40, lambda = 100 (plane strain, (2.42)); left edge
clamped; a dead shear load on the right edge.  The thesis does not print
the load: we use a total shear of 40 (traction 2.5 on the 16-long edge),
which makes the tip displacement 15 % smaller than the linear solution's —
clearly nonlinear.  Quantity: vertical displacement of the top-right corner
(48, 60), compared with a T2 overkill solution (cached in
~/.cache/skfem_pg, or $SKFEM_PG_CACHE).

Methods on each node set (meshes/cook.geo, element sizes
--sizes):
  T1                       scikit-fem P1 triangles, consistent tangent
  PBG Unl                  MTE1 + bond correction, no VC
  VC PBG Unl               MTE1 + bond correction + V5 (default FamilyBasis)
  VC PBG Unl (FD tangent)  the same with a finite-difference tangent
  VC PPG Unl               Petrov-Galerkin PPG1: MTE1 trial, WTE1 test
                           derivatives at the masters + V3 (non-symmetric)

Prints error, L2 error at the particles and wall time (preprocess /
assemble / solve), the time each method needs for 1 % tip error, and the
consistent-versus-FD tangent speedup; writes out/cook_neohooke.png
and a VTU with displacement, F, Cauchy and von Mises stress.

    python demos/cook_neohooke.py [--sizes 4 2 1 0.5] [--ref-size 1]
"""
import os
import time


import skfem_pg as pg
from skfem_pg import materials as mat
from skfem_pg.analysis.postprocess import particle_fields
from skfem_pg.scenes.reference import overkill
from harness import (demo_parser, markdown_table, output_dir,
                     print_time_to_target, save_error_vs_time, update_results,
                     wall_time)
from skfem_pg.scenes import Scene

OUT = output_dir(create=False)  # --out, $SKFEM_PG_OUT or ./out
MU, LAM = 40.0, 100.0
TOTAL_SHEAR = 40.0
TIP = (48.0, 60.0)

METHODS = {
    "T1": ("T1", {}),
    "PBG Unl": ("PG", {"vc": None}),
    "VC PBG Unl": ("PG", {}),
    "VC PBG Unl (FD tangent)": ("PG", {"tangent": "fd"}),
    "VC PPG Unl": ("PG", {"method": "PPG1"}),
}

STYLES = {"T1": "k--o", "PBG Unl": "C2-v", "VC PBG Unl": "C0-D",
          "VC PBG Unl (FD tangent)": "C3:x", "VC PPG Unl": "C1-s"}


def scene(mesh):
    return Scene("cook-neohooke", mesh, mat.NeoHooke(lam=LAM, mu=MU),
                 clamped=["left"],
                 tractions={"right": [0.0, TOTAL_SHEAR / 16.0]},
                 probes={"tip": TIP}, steps=1)


def gmsh_cook(size):
    return pg.meshing.from_geo(pg.meshing.geo_path("cook.geo"), size=size)


def main(sizes=(4.0, 2.0, 1.0), ref_size=1.0, ref_refine=1, results=None):
    t_start = time.perf_counter()
    print(pg.threads.describe())
    print("Cook's membrane, neo-Hooke (mu={}, lambda={}), total shear {}"
          .format(MU, LAM, TOTAL_SHEAR))
    ref = overkill(scene(gmsh_cook(ref_size)), refine=ref_refine)
    t_ref = time.perf_counter() - t_start
    v_ref = ref.probes["tip"][1]
    print("T2 overkill (gmsh size {}, refined {}x, {} elements): v{} = "
          "{:.5f}".format(ref_size, ref_refine, ref.mesh.nelements, TIP,
                          v_ref))
    rows = []
    last = None
    for size in sizes:
        sc = scene(gmsh_cook(size))
        nodes = pg.Particles.from_mesh(sc.mesh)
        for name, (method, kw) in METHODS.items():
            r = sc.solve(method, **kw)
            v = r.probes["tip"][1]
            # same discrete L2 norm at the nodes for PG and T1 (its dofs
            # are the vertex values)
            p = r.basis.particles if method == "PG" else nodes
            e, norm = ref.errors(p, r.u)
            l2 = e / norm
            if name == "VC PBG Unl":
                last = r
            rows.append(dict(size=size, nodes=sc.mesh.nvertices, method=name,
                             v=v, err=abs(v - v_ref) / abs(v_ref), l2=l2,
                             newton=sum(len(h["residuals"]) - 1
                                        for h in r.history), **r.times))
    print("\n{:>5s} {:>6s} {:24s} {:>9s} {:>9s} {:>9s} {:>4s} {:>7s} {:>7s} "
          "{:>7s} {:>7s}".format("size", "nodes", "method", "v_tip",
                                 "rel.err", "L2 rel", "it", "pre[s]",
                                 "asm[s]", "slv[s]", "tot[s]"))
    for r in rows:
        print("{size:5.2f} {nodes:6d} {method:24s} {v:9.5f} {err:9.2e} "
              "{l2:9.2e} {newton:4d} {preprocess:7.3f} {assemble:7.3f} "
              "{solve:7.3f}".format(**r) + " {:7.3f}".format(wall_time(r)))
    print_time_to_target(rows, METHODS, 0.01, "tip error")
    print("\nconsistent vs finite-difference tangent (VC PBG Unl):")
    for size in sizes:
        c = [r for r in rows if r["size"] == size and
             r["method"] == "VC PBG Unl"][0]
        f = [r for r in rows if r["size"] == size and
             r["method"] == "VC PBG Unl (FD tangent)"][0]
        print("  {:6d} nodes: assembly {:.3f} s vs {:.3f} s ({:.1f}x), "
              "Newton iterations {} vs {}".format(
                  c["nodes"], c["assemble"], f["assemble"],
                  f["assemble"] / c["assemble"], c["newton"], f["newton"]))
    if results:
        table = [[r["nodes"], r["method"], "{:.5f}".format(r["v"]),
                  "{:.2e}".format(r["err"]), "{:.2e}".format(r["l2"]),
                  r["newton"], "{:.3f}".format(wall_time(r))] for r in rows]
        print("updated", update_results(
            results, "cook_neohooke",
            "`python demos/cook_neohooke.py --sizes {}`: neo-Hooke Cook's "
            "membrane on gmsh triangle node sets; T2 overkill v = {:.5f} "
            "({} elements).\n\n".format(
                " ".join("{:g}".format(x) for x in sizes), v_ref,
                ref.mesh.nelements)
            + markdown_table(["nodes", "method", "v tip", "tip error",
                              "L2 error", "Newton it.", "wall time [s]"],
                             table)))
    os.makedirs(OUT, exist_ok=True)
    save_error_vs_time(os.path.join(OUT, "cook_neohooke.png"), rows, STYLES,
                       "relative error of v(48, 60)",
                       "Cook's membrane, neo-Hooke, irregular triangle nodes")
    fields = particle_fields(last.basis, mat.NeoHooke(lam=LAM, mu=MU), last.u)
    pg.write_vtu(os.path.join(OUT, "cook_neohooke.vtu"),
                 last.basis.particles, **fields)
    print("\nwrote " + OUT + "/cook_neohooke.png and cook_neohooke.vtu")
    print("run time {:.1f} s, of which {:.1f} s for the overkill (computed "
          "on a first run, then read from the cache)".format(
              time.perf_counter() - t_start, t_ref))
    return rows


if __name__ == "__main__":
    ap = demo_parser(__doc__, results=True)
    ap.add_argument("--sizes", type=float, nargs="+", default=[4, 2, 1],
                    help='gmsh element sizes of the triangle node sets (meshes/cook.geo)')
    ap.add_argument("--ref-size", type=float, default=1.0,
                    help="gmsh element size of the T2 overkill's mesh")
    ap.add_argument("--ref-refine", type=int, default=1,
                    help="uniform refinements of the overkill's mesh")
    a = ap.parse_args()
    OUT = output_dir(a.out)
    if a.quick:
        a.sizes, a.ref_size, a.ref_refine = [8.0], 8.0, 0
    main(a.sizes, a.ref_size, a.ref_refine, a.results)
