"""A hyperelastic block clamped on its loaded faces and compressed by 30 %
(the getting-started case of FE packages, e.g. FElupe's clamped cube):
does PG complete wherever FE completes, and with how many inverted cells?

The unit cube, iso/vol neo-Hooke with mu = 1 and bulk modulus K = 2; the
face x = 0 clamped, the face x = 1 clamped in y and z and moved by -0.3 in
x, in ``--steps`` fixed load steps (default 6; a failed step stops the
run) or, with ``--adaptive``, in steps that are cut where Newton fails.
The clamped edges are where the material is squeezed out: there the
deformation is most severe.

Node sets: regular n x n x n hexahedral grids (``--sizes``: n cells per
side; PG = the default there, VC PBG Unl with the thesis recipe; FE H1 on
the same nodes) and, with ``--tets``, the same grids split into
tetrahedra (PG = the default there, VC PBG Unl kNN; FE O1).  Prints per
node set and method: the reaction force on the moving face (against the
finest completed H1 as reference), whether the run completed or at which
load and why it stopped, the smallest J at the method's points, the
collocation cells the final displacement turns inside out
(``particles.inverted_cells``), load steps, Newton iterations and wall
time.  ``--results`` writes the table to benchmarks/README.md.

    python demos/compression_3d.py [--sizes 6 14 21] [--tets] [--adaptive]
        [--steps 6]
"""
import time

import numpy as np
import skfem as fem

import skfem_pg as pg
from skfem_pg import materials as mat
from skfem_pg.discretization.particles import inverted_cells
from skfem_pg.scenes import Scene
from harness import (demo_parser, markdown_table, update_results)
from skfem_pg.solvers import ConvergenceError, newton

MATERIAL = mat.NeoHookeIsoVol(mu=1.0, K=2.0)
STRAIN = 0.3


def block(n, tets=False):
    m = fem.MeshHex.init_tensor(*[np.linspace(0.0, 1.0, n + 1)] * 3)
    m = m.with_boundaries({"left": lambda x: np.isclose(x[0], 0.0),
                           "right": lambda x: np.isclose(x[0], 1.0)})
    return pg.meshing.tetrahedra(m) if tets else m


def scene(n, tets=False):
    return Scene("compression", block(n, tets), MATERIAL, clamped=["left"],
                 prescribed={"right": {0: -STRAIN, 1: 0.0, 2: 0.0}})


def run(sc, scheme, steps, adaptive):
    """Newton on ``scheme``: the reaction force, how far it got and why,
    min J, inverted collocation cells, steps, iterations, seconds."""
    t0 = time.perf_counter()
    basis, model, f, D, u_D, _ = sc.setup(scheme)
    right = np.unique(basis.get_dofs("right").all("u^1"))
    out = dict(force=np.nan, load=0.0, status="done", steps=0, its=0)

    def step(x, load, f_int):
        out["force"], out["load"] = -f_int[right].sum(), load
    x = None
    try:
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            x, hist = newton(model, f, D=D, u_D=u_D, steps=steps,
                             adaptive=adaptive, min_step=1.0 / 256,
                             verbose=False, callback=step)
        out["steps"] = len(hist)
        out["its"] = sum(len(h["residuals"]) - 1 for h in hist)
    except ConvergenceError as err:
        out["status"] = "stopped at {:.3f}: {}".format(
            err.load, str(err).split(";")[0])
        out["steps"] = len(err.history)
        x = err.u  # the last converged state
    out["seconds"] = time.perf_counter() - t0
    if x is not None and out["steps"]:
        u = x[:basis.N]
        out["min_J"] = float(model.min_J(model.state(x)))
        particles = getattr(basis, "particles", None) or \
            pg.Particles.from_mesh(sc.mesh)
        out["inverted"] = len(inverted_cells(particles, u))
    else:
        out["min_J"], out["inverted"] = np.nan, "–"
    return out


def main(sizes=(6, 14, 21), tets=False, steps=6, adaptive=False,
         results=None):
    print(pg.threads.describe())
    fe = "O1" if tets else "H1"
    rows, ref = [], None
    for n in sizes:
        sc = scene(n, tets)
        print("{} {}: {} nodes, {} cells".format(
            "tets" if tets else "hexes", n, sc.mesh.nvertices,
            sc.mesh.nelements), flush=True)
        for scheme in (fe, "PG"):
            r = run(sc, scheme, steps, adaptive)
            r.update(n=n, nodes=sc.mesh.nvertices, method=scheme)
            rows.append(r)
            print("  {:3s} {}: force {:.5f} at load {:.3f}, min J {:.3g}, "
                  "inverted cells {}, {} steps, {} Newton its, {:.1f} s"
                  .format(scheme, r["status"], r["force"], r["load"],
                          r["min_J"], r["inverted"], r["steps"], r["its"],
                          r["seconds"]), flush=True)
            if scheme == fe and r["status"] == "done":
                ref = r
    table = markdown_table(
        ["nodes", "method", "reached", "force", "vs finest " + fe,
         "min J", "inverted cells", "steps", "Newton its", "time [s]"],
        [[r["nodes"], r["method"], r["status"], "{:.5f}".format(r["force"]),
          "{:+.2%}".format(r["force"] / ref["force"] - 1)
          if ref and r["status"] == "done" else "–",
          "{:.3g}".format(r["min_J"]), r["inverted"], r["steps"], r["its"],
          "{:.1f}".format(r["seconds"])] for r in rows])
    print(table)
    if results:
        print("updated", update_results(
            results, "compression_3d{}{}".format("_tets" if tets else "",
                                                 "_adaptive" if adaptive
                                                 else ""),
            "`python demos/compression_3d.py --sizes {}{} --steps {}{}`: "
            "unit cube, neo-Hooke mu = 1, K = 2, clamped faces, compressed "
            "by {:.0%}; {} on the same nodes; force on the moving face."
            "\n\n".format(" ".join(str(n) for n in sizes),
                          " --tets" if tets else "", steps,
                          " --adaptive" if adaptive else "", STRAIN, fe)
            + table))
    return rows


if __name__ == "__main__":
    ap = demo_parser(__doc__, results=True)
    ap.add_argument("--sizes", type=int, nargs="+", default=[6, 14, 21],
                    help="cells per side of the hexahedral grids")
    ap.add_argument("--tets", action="store_true",
                    help="the grids split into tetrahedra (PG kNN, O1)")
    ap.add_argument("--steps", type=int, default=6,
                    help='load steps of the compression')
    ap.add_argument("--adaptive", action="store_true",
                    help="cut failed load steps instead of stopping")
    a = ap.parse_args()
    if a.quick:
        a.sizes, a.steps = [3], 2
    main(a.sizes, a.tets, a.steps, a.adaptive, a.results)
