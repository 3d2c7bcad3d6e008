"""Linear patch test (thesis 7.1–7.2, Table 7.2).

u = (0.1X + 0.3Y, 0.2X + 0.4Y) on [-1, 1]², E = 100, nu = 0.3 (plane strain),
Dirichlet on the left, bottom and right edges, the consistent Neumann load on
the top edge.  PBG variants on regular quads, ±0.3h distorted quads and
unstructured gmsh triangles (about 1345 particles, as in the thesis).

Prints εL2, εH1 and the max nodal error next to the thesis values, and writes
out/patch_test.png (εL2 per variant and node set).

    python demos/patch_test.py
"""
import os

import numpy as np
import skfem as fem

import skfem_pg as pg
from harness import demo_parser, output_dir
from skfem_pg.analysis import linear_patch_test
from skfem_pg.naming import parse

OUT = output_dir(create=False)  # --out, $SKFEM_PG_OUT or ./out

#: rows by thesis name (Table 7.1 defaults: BC for Unl/U1, VC boundary sn,
#: TL; ``noBC`` and the suffix ``m`` = min-norm are the package's own)
VARIANTS = ["PBG U1 TL noBC", "PBG Unl TL noBC", "PBG Unl",
            "VCPBG V3m Unl TL noBC", "VCBCPBG V5m Unl", "VCPBG V5sn Unl",
            "VCBCPBG V5s Unl", "VCBCPBG V5p Unl", "PPG Unl TL noBC",
            "PPG Unl", "VCPPG V3m Unl TL noBC", "VCPPG V3sn Unl TL noBC",
            "VCPPG V3sn Unl", "VCBCPPG V3m Unl"]
#: thesis Table 7.2 (εL2, εH1) on 1345 irregular particles, its own names
THESIS = {"PBG Unl": (8.563e-3, 1.284e-1),
          "VCPBG V5sn Unl": (2.518e-14, 1.154e-12),
          "PPG Unl": (9.532e-2, 2.336e-1),
          "VCPPG V3sn Unl": (6.489e-17, 9.974e-16)}


def node_sets(quick=False):
    square = fem.MeshQuad.init_tensor(
        *[np.linspace(-1, 1, 9 if quick else 37)] * 2)
    gmsh = pg.meshing.from_geo(pg.meshing.geo_path("square.geo"),
                               size=0.25 if quick else 0.0575)
    return {
        "regular quads": square,
        "distorted quads": pg.meshing.distort(square, 0.3, seed=1),
        "gmsh triangles": gmsh,
    }


def main(quick=False):
    rows = []
    for set_name, mesh in node_sets(quick).items():
        for name in VARIANTS:
            kw, _ = parse(name)
            r = linear_patch_test(mesh, lambda x: np.isclose(x[1], 1.0), **kw)
            rows.append((set_name, mesh.nvertices, name, r["L2"], r["H1"],
                         r["max_error"]))
    print("{:16s} {:>5s} {:23s} {:>10s} {:>10s} {:>10s} {:>20s}".format(
        "node set", "np", "variant", "eps_L2", "eps_H1", "max|e|",
        "thesis eps_L2/H1"))
    for s, n, name, l2, h1, mx in rows:
        th = THESIS.get(name) if s == "gmsh triangles" else None
        ref = "{:.2e} / {:.2e}".format(*th) if th else ""
        print("{:16s} {:5d} {:23s} {:10.3e} {:10.3e} {:10.3e} {:>20s}".format(
            s, n, name, l2, h1, mx, ref))
    os.makedirs(OUT, exist_ok=True)
    plot(rows, os.path.join(OUT, "patch_test.png"))
    print("\nwrote " + OUT + "/patch_test.png")
    return rows


def plot(rows, fn):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    sets = list(dict.fromkeys(r[0] for r in rows))
    names = list(VARIANTS)
    fig, ax = plt.subplots(figsize=(11, 4.5))
    w = 0.8 / len(sets)
    for i, s in enumerate(sets):
        vals = [max(r[3], 1e-17) for r in rows if r[0] == s]
        ax.bar(np.arange(len(names)) + i * w, vals, w, label=s)
    ax.set_yscale("log")
    ax.set_xticks(np.arange(len(names)) + w * (len(sets) - 1) / 2)
    ax.set_xticklabels(names, rotation=25, ha="right")
    ax.set_ylabel(r"$\varepsilon_{L2}$")
    ax.axhline(1e-10, color="k", lw=0.8, ls="--")
    ax.set_title("Linear patch test (thesis Table 7.2)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(fn, dpi=120)


if __name__ == "__main__":
    ap = demo_parser(__doc__)
    a = ap.parse_args()
    OUT = output_dir(a.out)
    main(a.quick)
