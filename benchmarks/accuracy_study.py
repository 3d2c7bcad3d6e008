"""Accuracy study: the error of PG variants relative to FE on the same nodes
(issue #3, item 6; thesis 7.2.3, Fig. 7.11).

Manufactured solution of the thesis (7.7)–(7.8) on [-1, 1]², E = 100e3,
nu = 0.3, full Dirichlet boundary; ±0.3h distorted (``--distortion``; 0:
regular, the two node-set families of Fig. 7.11) quad node sets (FE: Q1)
and the same nodes split into triangles (FE: T1).  For each PG variant:
relative L2 / H1 errors at the finest node set, their ratio to FE's, the
least-squares rates, and the setup + assembly + solve time relative to FE's.
Writes out/accuracy_study.png (L2 error against nodes).

    python benchmarks/accuracy_study.py [--sizes 8 16 32 64] [--distortion 0.3]
"""
import os

import numpy as np
import skfem as fem

import skfem_pg as pg
from harness import (demo_parser, markdown_table, output_dir, update_results)
from skfem_pg.analysis.convergence import PlaneWaves, rates, solve_manufactured
from skfem_pg.materials import lame

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)),
                       "README.md")  # the measured tables, written here
OUT = output_dir(create=False)  # --out, $SKFEM_PG_OUT or ./out
FIELD = PlaneWaves.hillman2019()
LAM, MU = lame(100e3, 0.3)

VARIANTS = {
    "PBG Unl": dict(vc=None),
    "VC PBG Unl (V5, default)": dict(),
    "VC PBG Unl V3, no BC": dict(bond=False, vc="V3"),
    "VC PBG Unl, n = 2": dict(weight_exponent=2),
    "VC PBG Unl V5p": dict(vc_boundary="p"),
    "VC PBG Unl V5sn": dict(vc_boundary="sn"),
    "VC PBG Unl, δ = 2.01h": "horizon",
    "VC PPG Unl (BC)": dict(method="PPG1"),
    "VC PPG Unl, no BC": dict(method="PPG1", bond=False),
    "VC PPG Unl, LME test": dict(method="PPG1", test_shape="LME"),
    "VC PPG Unl, WLS1 test": dict(method="PPG1", test_shape="WLS1"),
    "VC PPG Unl, MLS1 test": dict(method="PPG1", test_shape="MLS1"),
    "VC PPG Unl V3sn (BC)": dict(method="PPG1", vc_boundary="sn"),
    "VC PPG U2, WTE1 test": dict(method="PPG1", shape="WTE2",
                                 test_shape="WTE1"),
    "PPG Unl": dict(method="PPG1", vc=None),
}


def node_set(n, kind, distortion=0.3):
    m = fem.MeshQuad.init_tensor(np.linspace(-1, 1, n + 1),
                                 np.linspace(-1, 1, n + 1))
    if distortion:
        m = pg.meshing.distort(m, distortion, seed=n)
    return m.to_meshtri() if kind == "tri" else m


def run(kind, sizes, distortion=0.3):
    meshes = [node_set(n, kind, distortion) for n in sizes]
    series = {"FE": [solve_manufactured(m, FIELD, LAM, MU, "FE")
                     for m in meshes]}
    for name, kw in VARIANTS.items():
        rows = []
        for m in meshes:
            if kw == "horizon":
                p = pg.Particles.from_mesh(m)
                kw_m = dict(families=pg.families.horizon(p, factor=2.01))
            else:
                kw_m = kw
            rows.append(solve_manufactured(m, FIELD, LAM, MU, "PG", **kw_m))
        series[name] = rows
    return series


def report(kind, series):
    fe = series["FE"]
    fe_name = "Q1" if kind == "quad" else "T1"
    print("\n{} node sets ({} nodes at the finest); FE = {}".format(
        kind, fe[-1]["nodes"], fe_name))
    print("{:26s} {:>9s} {:>7s} {:>9s} {:>7s} {:>6s} {:>6s} {:>7s}".format(
        "variant", "L2", "/FE", "H1", "/FE", "rL2", "rH1", "time/FE"))
    table = []
    for name, rows in series.items():
        h = [r["h"] for r in rows]
        r2 = rates(h, [r["L2"] for r in rows])[0]
        r1 = rates(h, [r["H1"] for r in rows])[0]
        last = rows[-1]
        print("{:26s} {:9.2e} {:7.2f} {:9.2e} {:7.2f} {:6.2f} {:6.2f} "
              "{:7.2f}".format(
                  fe_name if name == "FE" else name, last["L2"],
                  last["L2"] / fe[-1]["L2"], last["H1"],
                  last["H1"] / fe[-1]["H1"], r2, r1,
                  last["seconds"] / fe[-1]["seconds"]))
        table.append([fe_name if name == "FE" else name,
                      "{:.2e}".format(last["L2"]),
                      "{:.2f}".format(last["L2"] / fe[-1]["L2"]),
                      "{:.2e}".format(last["H1"]),
                      "{:.2f}".format(last["H1"] / fe[-1]["H1"]),
                      "{:.2f}".format(r2), "{:.2f}".format(r1),
                      "{:.2f}".format(last["seconds"] / fe[-1]["seconds"])])
    return table


def plot(all_series, fn, distortion=0.3):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5))
    for ax, (kind, series) in zip(axes, all_series.items()):
        for name, rows in series.items():
            style = "k--o" if name == "FE" else ".-"
            ax.loglog([r["nodes"] for r in rows], [r["L2"] for r in rows],
                      style, label=("Q1" if kind == "quad" else "T1")
                      if name == "FE" else name)
        ax.set_xlabel("nodes")
        ax.set_ylabel("relative L2 error")
        ax.set_title("{} node sets, ±{}h distorted".format(kind, distortion))
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(fn, dpi=120)
    plt.close(fig)


def main(sizes=(8, 16, 32, 64), distortion=0.3):
    print(pg.threads.describe())
    print("Manufactured solution (thesis 7.7), full Dirichlet, ±{}h "
          "distorted; errors relative, rates = least squares over nodes "
          "per side {}".format(distortion, list(sizes)))
    all_series = {}
    text = ["`python benchmarks/accuracy_study.py --sizes {} --distortion "
            "{}`: manufactured solution (thesis (7.7)), full Dirichlet, "
            "errors relative; `/FE` = ratio to Q1 (quads) or T1 "
            "(triangles) on the same nodes at the finest set; rates: "
            "least squares over all sets.".format(
                " ".join(map(str, sizes)), distortion)]
    for kind in ("quad", "tri"):
        all_series[kind] = run(kind, sizes, distortion)
        table = report(kind, all_series[kind])
        text.append("\n{} node sets, {} nodes at the finest:\n".format(
            kind, all_series[kind]["FE"][-1]["nodes"]))
        text.append(markdown_table(["variant", "L2", "L2/FE", "H1", "H1/FE",
                                    "L2 rate", "H1 rate", "time/FE"],
                                   table))
    print("updated", update_results(RESULTS, "accuracy_study{}".format(
        "" if distortion == 0.3 else "_{}".format(distortion)),
        "\n".join(text)))
    os.makedirs(OUT, exist_ok=True)
    fn = os.path.join(OUT, "accuracy_study{}.png".format(
        "" if distortion == 0.3 else "_{}".format(distortion)))
    plot(all_series, fn, distortion)
    print("\nwrote", os.path.relpath(fn))
    return all_series


if __name__ == "__main__":
    ap = demo_parser(__doc__)
    ap.add_argument("--sizes", type=int, nargs="+", default=[8, 16, 32, 64],
                    help='elements per side of the distorted unit squares')
    ap.add_argument("--distortion", type=float, default=0.3,
                    help="node perturbation in units of h (0: regular)")
    a = ap.parse_args()
    OUT = output_dir(a.out)
    main(a.sizes, a.distortion)
