"""2-D punch (thesis 7.3.1, Fig. 7.16): compress until the solver fails.

A block [0, 2] x [0, 1] (64 x 32 quads; the thesis' node set size) is pushed
down on the left half of its top edge by u_y = -1 (the full thickness),
applied with adaptive load steps; left edge: u_x = 0 (symmetry), bottom:
u_y = 0.  Neo-Hooke, E = 1, nu = 0.3 (plane strain).  The thesis' figure
with the exact geometry and material is not in the text; these choices
follow its description (a block compressed on the left by u -> -1 until
failure, 64 x 32 regular nodes).

Q1 and VC PBG Unl run on the same nodes until Newton cannot advance (step
below 1e-3 of the load); the maximal compression reached is reported as the
remaining thickness under the punch (thesis: Q1 39 %, VC PBG Unl 1.3 %, of
the initial thickness).  Beside it, the number of mesh cells that the final
displacement turns inside out (``particles.inverted_cells``): PG checks
J > 0 only at its own integration points (min J), so its particles can
cross while every J^{kj} stays positive.  Prints one line per method;
writes out/punch.png (final configurations) and punch_pg.vtu.

    python demos/punch.py [--nx 64 --ny 32]
"""
import os
import time

import numpy as np
import skfem as fem

import skfem_pg as pg
from harness import demo_parser, output_dir
from skfem_pg import materials as mat
from skfem_pg.formulations import Hyperelastic
from skfem_pg.discretization.particles import inverted_cells
from harness import markdown_table, update_results
from skfem_pg.analysis.postprocess import particle_fields
from skfem_pg.solvers import newton, ConvergenceError

OUT = output_dir(create=False)  # --out, $SKFEM_PG_OUT or ./out
E, NU = 1.0, 0.3


def block(nx, ny):
    mesh = fem.MeshQuad.init_tensor(np.linspace(0, 2, nx + 1),
                                    np.linspace(0, 1, ny + 1))
    return mesh.with_boundaries({
        "punch": lambda x: np.isclose(x[1], 1) & (x[0] < 1),
        "left": lambda x: np.isclose(x[0], 0),
        "bottom": lambda x: np.isclose(x[1], 0)})


def compress(basis, material, min_step=1e-3):
    D = np.concatenate([basis.get_dofs("punch").nodal["u^2"],
                        basis.get_dofs("left").nodal["u^1"],
                        basis.get_dofs("bottom").nodal["u^2"]])
    D = np.unique(D)
    u_D = np.zeros(basis.N)
    u_D[basis.get_dofs("punch").nodal["u^2"]] = -1.0
    t0 = time.perf_counter()
    try:
        u, hist = newton(Hyperelastic(basis, material), D=D, u_D=u_D,
                         steps=20, min_step=min_step, verbose=False)
        load, reason = 1.0, "reached full compression"
    except ConvergenceError as err:
        u, hist, load = err.u, err.history, err.load
        reason = str(err).split(";")[0]
    return dict(u=u, load=load, steps=len(hist), reason=reason,
                newton=sum(len(h["residuals"]) - 1 for h in hist),
                seconds=time.perf_counter() - t0,
                min_J=min(h["min_J"] for h in hist) if hist else np.nan)


def main(nx=64, ny=32, results=None):
    lam, mu = pg.materials.lame(E, NU)
    material = mat.NeoHooke(lam=lam, mu=mu)
    mesh = block(nx, ny)
    runs = {
        "Q1": fem.Basis(mesh, fem.ElementVector(fem.ElementQuad1())),
        "VC PBG Unl": pg.FamilyBasis(pg.Particles.from_mesh(mesh), dim=2),
    }
    res = {}
    print("2-D punch, {} x {} nodes, neo-Hooke E={}, nu={}".format(
        nx + 1, ny + 1, E, NU))
    particles = runs["VC PBG Unl"].particles
    for name, basis in runs.items():
        res[name] = r = compress(basis, material)
        r["inverted"] = len(inverted_cells(particles, r["u"]))
        print("  {:11s} remaining thickness {:6.2%} of the initial "
              "(load factor {:.4f}); {} steps, {} Newton iterations, "
              "{:.1f} s; min J {:.3g}; inverted cells {} of {}; {}".format(
                  name, 1 - r["load"], r["load"], r["steps"], r["newton"],
                  r["seconds"], r["min_J"], r["inverted"], mesh.nelements,
                  r["reason"]))
    print("  thesis: Q1 39 %, VC PBG Unl 1.3 % of the initial thickness")
    if results:
        table = [[name, "{:.2%}".format(1 - r["load"]),
                  "{} of {}".format(r["inverted"], mesh.nelements),
                  "{:.3g}".format(r["min_J"]), r["steps"], r["newton"],
                  "{:.1f}".format(r["seconds"])] for name, r in res.items()]
        print("updated", update_results(
            results, "punch_{}x{}".format(nx, ny),
            "`python demos/punch.py --nx {} --ny {}`: remaining thickness "
            "under the punch when Newton stops (thesis: Q1 39 %, VC PBG "
            "Unl 1.3 %), and the collocation cells the final displacement "
            "turns inside out.\n\n".format(nx, ny)
            + markdown_table(["method", "remaining thickness",
                              "inverted cells", "min J", "steps",
                              "Newton it.", "time [s]"], table)))
    os.makedirs(OUT, exist_ok=True)
    plot(mesh, res, runs, os.path.join(OUT, "punch.png"))
    b = runs["VC PBG Unl"]
    pg.write_vtu(os.path.join(OUT, "punch_pg.vtu"), b.particles,
                 **particle_fields(b, material, res["VC PBG Unl"]["u"]))
    print("wrote " + OUT + "/punch.png and punch_pg.vtu")
    return res


def plot(mesh, res, runs, fn):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import PolyCollection
    fig, axes = plt.subplots(1, 2, figsize=(11, 3.8), sharey=True)
    for ax, name in zip(axes, res):
        x = mesh.p + res[name]["u"].reshape(-1, 2).T
        if name == "Q1":
            ax.add_collection(PolyCollection(
                [x[:, mesh.t[:, e]].T for e in range(mesh.nelements)],
                facecolor="0.85", edgecolor="0.3", lw=0.3))
        else:
            ax.scatter(x[0], x[1], s=2, c="C0")
        ax.set_title("{}: remaining thickness {:.1%}".format(
            name, 1 - res[name]["load"]))
        ax.set_aspect("equal")
        ax.autoscale()
    fig.tight_layout()
    fig.savefig(fn, dpi=120)


if __name__ == "__main__":
    ap = demo_parser(__doc__, results=True)
    ap.add_argument("--nx", type=int, default=64,
                    help='elements along the block')
    ap.add_argument("--ny", type=int, default=32,
                    help="elements through the block's height")
    a = ap.parse_args()
    OUT = output_dir(a.out)
    main(*((8, 4) if a.quick else (a.nx, a.ny)), a.results)
