"""Cost of one 3-D Newton iteration: VC PBG Unl against O1 on the same gmsh
tetrahedra and against H1P0 on the same distorted hexahedral grids, split
into material (stress and tangent at the points), assembly (interpolation,
internal force, tangent) and the linear solve.

The problem is the 3-D Cook's membrane of ``demos/cook_3d.py`` (iso/vol
neo-Hooke, lambda = 100, mu = 40, load on the far face) at ``--load`` of
its load in ``--steps`` load steps, solved by ``skfem_pg.solvers.newton`` with
one linear solver per method (AMG keeps its hierarchy across iterations).
Times are per Newton iteration, failed load steps included; ratios against
the FE method on the same nodes in the same run.

    python benchmarks/newton_3d.py [--sizes 2.5 1.6 1.0 0.88] [--hex 24 40]
        [--solver auto|direct|amg] [--load 0.25] [--steps 2]
"""
import os
import time

import numpy as np

import skfem_pg as pg
from harness import (demo_parser, markdown_table, output_dir, update_results)

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)),
                       "README.md")
OUT = output_dir(create=False)
DEMOS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..",
                     "demos")


def cook_demo():
    """``demos/cook_3d.py`` as a module (its meshes and scene)."""
    import importlib.util
    spec = importlib.util.spec_from_file_location(
        "cook_3d", os.path.join(DEMOS, "cook_3d.py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


class Timed:
    """Wraps an object; calls of the methods ``names`` are timed into
    ``seconds[name]``."""

    def __init__(self, obj, names):
        self._obj, self._names = obj, names
        self.seconds = dict.fromkeys(names, 0.0)

    def __getattr__(self, name):
        attr = getattr(self._obj, name)
        if name not in self._names:
            return attr

        def timed(*args, **kwargs):
            t0 = time.perf_counter()
            out = attr(*args, **kwargs)
            self.seconds[name] += time.perf_counter() - t0
            return out
        return timed


def iterations(sc, scheme, solver, load, steps, candidates=None, **kw):
    """Newton's method (``skfem_pg.solvers.newton``) on the scene at
    ``load`` times its load in ``steps`` steps; per-iteration means of the
    phases (failed load steps included), the Krylov iterations per solve
    and the basis' preprocessing."""
    basis, model, f, D, u_D, t_pre = sc.setup(scheme, **kw)
    material = Timed(model.material, ("stress", "tangent"))
    model.material = material
    timed = Timed(model, ("state", "internal_force", "tangent"))
    I = np.setdiff1d(np.arange(basis.N), D)
    lin = pg.solvers.static.condensed_solver(solver, basis, I)
    if candidates is not None and hasattr(basis, "layout"):  # PG's AMG
        lin = pg.solvers.linear_solver(
            solver, basis.doflocs[:, I], candidates=candidates,
            components=I % 3)
    t_lin = [0.0]

    def solve(A, b):
        t0 = time.perf_counter()
        x = lin(A, b)
        t_lin[0] += time.perf_counter() - t0
        return x
    t0 = time.perf_counter()
    u, hist = pg.solvers.newton(timed, load * f, D=D,
                                u_D=lambda t: u_D(load * t),
                                steps=steps, solver=solve, verbose=False)
    wall = time.perf_counter() - t0
    n_it = sum(len(h["residuals"]) - 1 for h in hist)
    sec = timed.seconds
    mat = sum(material.seconds.values())
    out = dict(material=mat,
               assembly=sec["state"] + sec["internal_force"]
               + sec["tangent"] - mat,
               solve=t_lin[0])
    out["other"] = wall - sum(out.values())
    out = {k: v / n_it for k, v in out.items()}
    out["total"] = wall / n_it
    its = lin.amg.stats["iterations"]
    out.update(dofs=len(I), preprocess=t_pre, newton=n_it,
               krylov=float(np.mean(its)) if its else None,
               builds=lin.amg.stats["builds"],
               fallbacks=lin.amg.stats["fallbacks"])
    return out


def main():
    p = demo_parser(__doc__)
    p.add_argument("--sizes", type=float, nargs="*",
                   default=[2.5, 1.6, 1.0, 0.88],
                    help='gmsh element sizes of the tetrahedral node sets (meshes/cook3d.geo)')
    p.add_argument("--hex", type=int, nargs="*", default=[24, 40],
                    help='cells per side of the distorted hexahedral grids (PG against H1P0)')
    p.add_argument("--solver", default="auto",
                    help='linear solver of newton(): auto, direct or amg')
    p.add_argument("--load", type=float, default=0.25,
                   help="fraction of the Cook load (default 0.25)")
    p.add_argument("--steps", type=int, default=2,
                    help='load steps to reach --load')
    p.add_argument("--section", default="newton_3d",
                   help="benchmarks/README.md section of the table")
    p.add_argument("--candidates", type=int, help="PG's AMG near-null-"
                   "space candidates beyond the rigid-body modes (default: "
                   "Newton's, skfem_pg.solvers.PG_CANDIDATES)")
    args = p.parse_args()
    print(pg.threads.describe())
    rows = []
    sets = [("tet", s) for s in args.sizes] + [("hex", n) for n in args.hex]
    for kind, size in sets:
        if kind == "tet":
            mesh = pg.meshing.from_geo(pg.meshing.geo_path("cook3d.geo"),
                                       size=size)
            sc = cook_demo().scene(mesh.with_boundaries(
                {"left": lambda x: np.isclose(x[0], 0),
                 "right": lambda x: np.isclose(x[0], 48)}))
            fe = "O1"
        else:
            mod = cook_demo()
            mesh = mod.cook3d(size, size // 4, distortion=0.3)
            sc = mod.scene(mesh)
            fe = "H1P0"
        print("{} {}: {} nodes".format(kind, size, mesh.nvertices),
              flush=True)
        res = {}
        for scheme in (fe, "PG"):
            r = iterations(sc, scheme, args.solver, args.load, args.steps,
                           args.candidates)
            res[scheme] = r
            print("  {:5s} {newton} Newton iterations, each: material "
                  "{material:.3f} s, assembly {assembly:.3f} s, solve "
                  "{solve:.3f} s (Krylov its {kr}, AMG builds {builds}, "
                  "fallbacks {fallbacks}), other {other:.3f} s; total "
                  "{total:.3f} s; preprocess {preprocess:.2f} s".format(
                      scheme, kr=("-" if r["krylov"] is None
                                  else "{:.0f}".format(r["krylov"])), **r),
                  flush=True)
        a, b = res["PG"], res[fe]
        rows.append([kind, "{:,}".format(mesh.nvertices), fe,
                     "{:.2f}".format(b["total"]), "{:.2f}".format(a["total"]),
                     "{:.2f}".format(a["total"] / b["total"]),
                     "{:.2f}".format(a["material"] / b["material"]),
                     "{:.2f}".format(a["assembly"] / b["assembly"]),
                     "{:.2f}".format(a["solve"] / b["solve"]),
                     "{} / {}".format(*["-" if r["krylov"] is None else
                                        "{:.0f}".format(r["krylov"])
                                        for r in (a, b)]),
                     "{} / {}".format(a["newton"], b["newton"]),
                     "{:.2f}".format(a["preprocess"])])
        print("  PG / {}: {} per iteration".format(fe, rows[-1][5]))
        write(rows, args)  # after every node set: a cut run keeps its rows


def write(rows, args):
    """The results section of the rows so far."""
    table = markdown_table(
        ["nodes", "set", "FE", "FE [s/it]", "PG [s/it]", "PG / FE",
         "material", "assembly", "solve", "Krylov its PG / FE",
         "Newton its PG / FE", "PG preprocess [s]"],
        [[r[1], r[0]] + r[2:] for r in rows])
    text = ("`python benchmarks/newton_3d.py --sizes {z} --hex {h} --solver "
            "{s} --load {l} --steps {n}{c}`: `skfem_pg.solvers.newton` on the 3-D Cook's "
            "membrane of "
            "`demos/cook_3d.py` at {l} of its load in {n} load steps; PG = "
            "`Scene.solve(\"PG\")`'s default on the FE mesh's nodes (VC PBG "
            "Unl kNN on tetrahedra, the thesis' VC PBG Unl on hexahedra). "
            "Seconds per Newton "
            "iteration (failed load steps included) and the PG/FE ratios "
            "of its phases, in the same run; material = stress and "
            "tangent at the points, assembly = interpolation, internal "
            "force and tangent assembly, solve = the condensed linear "
            "solve ({t}).\n\n{tab}\n".format(
                z=" ".join("{:g}".format(x) for x in args.sizes),
                h=" ".join(str(x) for x in args.hex),
                s=args.solver, l=args.load, n=args.steps,
                c="" if args.candidates is None else
                " --candidates {}".format(args.candidates),
                t=pg.threads.describe(), tab=table))
    print(text)
    update_results(RESULTS, args.section, text)


if __name__ == "__main__":
    main()
