"""3-D Cook's membrane (thesis Fig. 7.3 / 7.21): PG against O1 on the same
irregular tetrahedral node sets, H1P0 on distorted hexahedral grids, error
against wall time.

The 2-D outline (0,0), (48,44), (48,60), (0,44) extruded by a thickness of
10 in z (``skfem_pg/scenes/meshes/cook3d.geo``); clamped at x = 0; a dead area
load q = 4 in +z on the face x = 48 (thesis 7.1).  The thesis' figure with
thickness and material is not in the text: we use thickness 10 and the iso/vol
neo-Hooke (2.43) with lambda = 100, mu = 40 (the 2-D Cook's constants), so
that the mean-dilatation H1P0 applies.  The load bends the plate out of
plane by about 40 (load steps adapt).  Quantity: z-displacement of the
corner (48, 60, 10), against an H2 overkill on a regular 16 x 16 x 4 hex
mesh (cached; H2 on 8 x 8 x 2 gives 40.003, 16 x 16 x 4 40.169, H1P0 on
24 x 24 x 6 / 32 x 32 x 8 40.035 / 40.110: the reference itself is good to
about 0.2 %).

Node sets: gmsh tetrahedra of mesh sizes ``--sizes`` (VC PBG Unl with the
kNN recipe, the default, and with the thesis' mesh families, and BCPPG
Unl on the vertices, O1 on the same tetrahedra); H1P0 on regular
n x n x n/4 hex grids
with interior nodes distorted by ±0.3h (``--hex``; tetrahedra have no
mean-dilatation element here).  Prints errors, wall time (preprocess /
assemble / solve), the PG/O1 deviation and time ratios; writes
out/cook_3d.png and a VTU with von Mises stress.

    python demos/cook_3d.py [--sizes 5 3.5 2.5] [--hex 8 12 16]
        [--methods O1 "VC PBG Unl kNN" "VC PBG Unl" "BCPPG Unl"]
"""
import os

import skfem_pg as pg
from skfem_pg import materials as mat
from skfem_pg.analysis.postprocess import particle_fields
from skfem_pg.scenes.reference import overkill
from skfem_pg.scenes.reporting import (demo_parser, markdown_table, output_dir,
                                print_time_to_target, save_error_vs_time,
                                update_results, wall_time)
from skfem_pg.scenes import Scene

OUT = output_dir(create=False)  # --out, $SKFEM_PG_OUT or ./out
T, Q = 10.0, 4.0
CORNER = (48.0, 60.0, T)
MATERIAL = mat.NeoHookeIsoVol.from_lame(100.0, 40.0)
#: on the tetrahedral node sets; BCPPG Unl: Petrov–Galerkin with bond
#: correction and no VC (VC PPG is unstable on 3-D tets, see README)
METHODS = {"O1": {"scheme": "O1"},
           # the default on tetrahedra: nearest-neighbour families, uniform
           # weights (skfem_pg.discretization.recipes)
           "VC PBG Unl kNN": {"scheme": "PG"},
           # the thesis' recipe: mesh families, volume weights
           "VC PBG Unl": {"scheme": "PG", "families": "mesh"},
           "BCPPG Unl": {"scheme": "PG", "method": "PPG1", "vc": None}}
STYLES = {"O1": "k--o", "H1P0": "k-s", "VC PBG Unl": "C0-D",
          "VC PBG Unl kNN": "C2-v", "BCPPG Unl": "C1-s"}


def cook3d(n, nz, distortion=0.0, seed=0):
    return pg.meshing.cook_membrane_3d(n, nz, T, distortion, seed)


def scene(mesh):
    return Scene("cook3d", mesh, MATERIAL, clamped=["left"],
                 tractions={"right": [0.0, 0.0, Q]},
                 probes={"corner": CORNER}, steps=8)


def run(sc, name, kw, label, w_ref, rows):
    """Solve ``sc`` with ``kw`` (scheme and basis options), append a table
    row, print it."""
    r = sc.solve(**kw)
    w = r.probes["corner"][2]
    rows.append(dict(label=label, nodes=sc.mesh.nvertices, method=name,
                     w=w, err=abs(w - w_ref) / abs(w_ref),
                     steps=len(r.history), **r.times))
    print("  {:5d} nodes {:11s} w = {:9.5f}  rel.err {:.2e}  {:.2f} s"
          .format(sc.mesh.nvertices, name, w, rows[-1]["err"], r.total_time),
          flush=True)
    return r


def main(sizes=(5, 3.5, 2.5), hexes=(8, 12, 16), results=None,
         methods=None, section=None):
    global METHODS
    if methods:
        unknown = set(methods) - set(METHODS)
        if unknown or "O1" not in methods:
            raise SystemExit("--methods: O1 and any of {} (got {})".format(
                ", ".join(m for m in METHODS if m != "O1"), methods))
        METHODS = {m: METHODS[m] for m in METHODS if m in methods}
    print(pg.threads.describe())
    ref = overkill(scene(cook3d(16, 4)), refine=0, method="H2")
    w_ref = ref.probes["corner"][2]
    print("3-D Cook's membrane, q = {} in z, thickness {}; H2 overkill "
          "(16x16x4): w{} = {:.5f}".format(Q, T, CORNER, w_ref))
    rows, last = [], None
    geo = pg.meshing.geo_path("cook3d.geo")
    for s in sizes:
        sc = scene(pg.meshing.from_geo(geo, size=s))
        for name, kw in METHODS.items():
            r = run(sc, name, kw, "tet {}".format(s), w_ref, rows)
            last = r if name == "VC PBG Unl kNN" else last
    for n in hexes:
        run(scene(cook3d(n, max(1, n // 4), 0.3, seed=n)), "H1P0",
            {"scheme": "H1P0"}, "hex {}".format(n), w_ref, rows)
    print("\n{:>6s} {:11s} {:>9s} {:>9s} {:>6s} {:>7s} {:>7s} {:>7s}".format(
        "nodes", "method", "w", "rel.err", "steps", "pre[s]", "asm[s]",
        "slv[s]"))
    for r in rows:
        print("{nodes:6d} {method:11s} {w:9.5f} {err:9.2e} {steps:6d} "
              "{preprocess:7.3f} {assemble:7.3f} {solve:7.3f}".format(**r))
    print("\nper tetrahedral node set: PG deviation / O1 deviation, PG time "
          "/ O1 time (thesis at 1.2 M dof: 0.23, 1.56)")
    for s in sizes:
        label = "tet {}".format(s)
        sel = {r["method"]: r for r in rows if r["label"] == label}
        o1 = sel["O1"]
        print("  {:6d} nodes: ".format(o1["nodes"]) + ";  ".join(
            "{} {:.2f}, {:.2f}".format(name, sel[name]["err"] / o1["err"],
                                       wall_time(sel[name]) / wall_time(o1))
            for name in METHODS if name != "O1"))
    print_time_to_target(rows, list(METHODS) + ["H1P0"], 0.01,
                         "corner displacement error")
    if results:
        table = [[r["nodes"], r["label"], r["method"], "{:.5f}".format(r["w"]),
                  "{:.2e}".format(r["err"]),
                  "{:.2f}".format(wall_time(r))] for r in rows]
        subset = methods and len(METHODS) < 4
        print("updated", update_results(
            results, section or ("cook_3d_large" if subset else "cook_3d"),
            "`python demos/cook_3d.py --sizes {} --hex {}{}`: 3-D Cook's "
            "membrane, iso/vol neo-Hooke, q = {} in z; H2 overkill w = "
            "{:.5f}; corner error and wall time.\n\n".format(
                " ".join("{:g}".format(x) for x in sizes),
                " ".join(str(n) for n in hexes),
                " --methods " + " ".join("'{}'".format(m) for m in METHODS)
                if subset else "", Q, w_ref)
            + markdown_table(["nodes", "node set", "method", "w", "error",
                              "wall time [s]"], table)))
    os.makedirs(OUT, exist_ok=True)
    save_error_vs_time(os.path.join(OUT, "cook_3d.png"), rows, STYLES,
                       "relative error of w(48, 60, 10)",
                       "3-D Cook's membrane: gmsh tetrahedra (PG, O1), "
                       "distorted hexahedra (H1P0)")
    pg.write_vtu(os.path.join(OUT, "cook_3d.vtu"), last.basis.particles,
                 **particle_fields(last.basis, MATERIAL, last.u))
    print("wrote " + OUT + "/cook_3d.png and cook_3d.vtu")
    return rows


if __name__ == "__main__":
    ap = demo_parser(__doc__, results=True)
    ap.add_argument("--sizes", type=float, nargs="+", default=[5, 3.5, 2.5],
                    help="gmsh mesh sizes of the tetrahedral node sets")
    ap.add_argument("--hex", type=int, nargs="*", default=[8, 12, 16],
                    help="H1P0 hex grids n x n x n/4")
    ap.add_argument("--methods", nargs="+", help="subset of the tetrahedral "
                    "methods (O1 always): e.g. --methods O1 'VC PBG Unl'")
    ap.add_argument("--section", help="benchmarks/README.md section the "
                    "--results table goes to (default cook_3d, or "
                    "cook_3d_large with fewer --methods)")
    args = ap.parse_args()
    OUT = output_dir(args.out)
    main(args.sizes, args.hex, args.results, args.methods, args.section)
