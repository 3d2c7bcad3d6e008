"""Torsion of a square hyperelastic prism (thesis 7.3.2, Table 7.4): the
largest rotation that converges in one load step and the fewest equal
steps for a full turn, displacement-based against mixed formulations.

A 1 x 1 x 5 mm prism (units m, N), iso/vol neo-Hooke K = 5e8, mu =
1.61148e8, bottom clamped, top rotated about the prism axis (prescribed
``f(x, t)``, its z-displacement zero), n x n x 5n hexahedral elements (the
thesis: 16 x 16 x 80; default 3 x 3 x 15).  Newton (``tol`` 1e-9, at most
25 iterations, secant predictor) with fixed equal steps and no cutting
(``newton(adaptive=False)``):

* max step: the largest integer angle whose single step converges
  (doubling from 1 degree, then bisection); convergence need not be
  monotone in the angle, so this is the largest angle found by that
  search;
* steps/360: the fewest equal steps of a full turn that all converge,
  starting at ceil(360 / max step) (doubling, then bisection).

Methods as Table 7.4 names them; every PG variant with VC (VCBCPBG V5sn:
the package's default; the thesis' names omit the corrections): H1, H1P0,
PBG Unl, PPG Unl, PBG UnlP0, PBG U2, PBG U2P1, PBG U2P1C, PBG Unl+P1C, PPG
UnlP0, and the stabilized under-integrated PBG U1SIG and U1SUnl (thesis
6.3; U1SUnl is not in Table 7.4).  Prints the table beside the thesis', writes
out/torsion.png (von Mises at the end of the full turn, H1P0 and the last
PG formulation that made it) and out/torsion.vtu.

    python demos/torsion.py [--n 3] [--methods ...] [--full]
"""
import math
import os
import time

import numpy as np
import skfem as fem

import skfem_pg as pg
from skfem_pg import materials as mat
from skfem_pg.analysis.postprocess import (cauchy_and_von_mises,
                                          particle_fields)
from skfem_pg.scenes import Scene
from harness import (demo_parser, markdown_table, output_dir, save_figure,
                     update_results)
from skfem_pg.solvers import ConvergenceError, newton

A, L = 1e-3, 5e-3
MATERIAL = mat.NeoHookeIsoVol(mu=1.61148e8, K=5e8)
#: Table 7.4: method -> (max step [deg], steps / 360)
THESIS = {"FEM H1": (7, 72), "FEM H1P0": (42, 9), "PPG Unl": (17, 60),
          "PPG UnlP0": (64, 6), "PBG Unl": (12, 72), "PBG U2": (4, 90),
          "PBG UnlP0": (54, 7), "PBG U2P1": (58, 7), "PBG U2P1C": (47, 8),
          "PBG Unl+P1C": (49, 8), "PBG U1SIG": (4, 90),
          "PBG U1SUnl": ("–", "–")}  # U1SUnl: not in Table 7.4
#: Table 7.4 name -> the name solved here
SOLVED = {"FEM H1": "H1", "FEM H1P0": "H1P0", "PPG Unl": "VCPPG Unl",
          "PPG UnlP0": "VCPPG UnlP0", "PBG Unl": "VCPBG Unl",
          "PBG U2": "VCPBG U2", "PBG UnlP0": "VCPBG UnlP0",
          "PBG U2P1": "VCPBG U2P1", "PBG U2P1C": "VCPBG U2P1C",
          "PBG Unl+P1C": "VCPBG Unl+P1C", "PBG U1SIG": "VCPBG U1SIG",
          "PBG U1SUnl": "VCPBG U1SUnl"}


def prism(n):
    m = fem.MeshHex.init_tensor(np.linspace(0, A, n + 1),
                                np.linspace(0, A, n + 1),
                                np.linspace(0, L, 5 * n + 1))
    return m.with_boundaries({"bottom": lambda x: np.isclose(x[2], 0.0),
                              "top": lambda x: np.isclose(x[2], L)})


class Twist:
    """The top's prescribed displacement at load factor ``t``: a rotation
    by ``t * angle`` degrees about the axis x = y = A/2; ``angle`` is set
    between runs."""

    def __init__(self, angle=0.0):
        self.angle = angle

    def __call__(self, x, t):
        a = math.radians(self.angle * t)
        c, s = math.cos(a), math.sin(a)
        X, Y = x[0] - A / 2, x[1] - A / 2
        return np.array([c * X - s * Y - X, s * X + c * Y - Y,
                         np.zeros_like(X)])


def runs(name, mesh, twist):
    """``run(angle, steps)`` -> converged? for one method (its basis and
    model are built once); ``last`` keeps the last full turn."""
    sc = Scene("torsion", mesh, MATERIAL, clamped=["bottom"],
               prescribed={"top": twist})
    basis, model, f, D, u_D, _ = sc.setup(name)
    last = {}

    def run(angle, steps):
        twist.angle = angle
        try:
            with np.errstate(invalid="ignore", divide="ignore",
                             over="ignore"):  # failing steps reach J <= 0
                x, _ = newton(model, f, D=D, u_D=u_D, steps=steps,
                              adaptive=False, verbose=False)
        except ConvergenceError:
            return False
        if angle == 360:  # a full turn: kept for the VTU
            last.update(x=x, basis=basis, model=model)
        return True
    return run, last


def bisect(ok, good, bad):
    """The integer next to ``bad`` on ``good``'s side with ``ok`` (``ok
    (good)`` holds, ``ok(bad)`` does not; either may be the larger)."""
    while abs(good - bad) > 1:
        mid = (good + bad) // 2
        if ok(mid):
            good = mid
        else:
            bad = mid
    return good


def largest(ok, lo, limit):
    """Largest integer in [lo, limit] with ``ok`` (``ok(lo)`` holds) by
    doubling from ``lo``, then bisection."""
    while lo < limit:
        trial = min(2 * lo, limit)
        if not ok(trial):
            return bisect(ok, lo, trial)
        lo = trial
    return lo


def smallest(ok, start, limit):
    """Fewest steps in [start, limit] with ``ok``, doubling then
    bisection; None if even ``limit`` fails."""
    bad, good = start - 1, start
    while not ok(good):
        bad = good
        if good >= limit:
            return None
        good = min(2 * good, limit)
    return bisect(ok, good, bad)


def study(label, mesh, max_steps=180):
    twist = Twist()
    t0 = time.perf_counter()
    try:
        run, last = runs(SOLVED[label], mesh, twist)
    except NotImplementedError as err:
        print("{:12s} not built: {}".format(label, err))
        return None
    first = run(1, 1)
    step = largest(lambda a: run(a, 1), 1, 360) if first else 0
    steps = smallest(lambda m: run(360, m), math.ceil(360 / step),
                     max_steps) if step else None
    row = dict(method=label, solved=SOLVED[label], step=step, steps=steps,
               seconds=time.perf_counter() - t0, last=last)
    print("{:12s} ({:14s}) max step {:>3}°  steps/360° {:>4}   thesis "
          "{:>2}° / {:>2}   {:6.1f} s".format(
              label, SOLVED[label], step, steps or ">{}".format(max_steps),
              *THESIS[label], row["seconds"]), flush=True)
    return row


def von_mises_vtu(row, fn):
    basis, x = row["last"]["basis"], row["last"]["x"]
    u = x[:row["last"]["model"].n_u]
    if isinstance(basis, fem.Basis):
        mesh = basis.mesh
        F = basis.interpolate(u).grad + np.eye(3)[:, :, None, None]
        sig, vm = cauchy_and_von_mises(
            MATERIAL, F.reshape(3, 3, -1))
        import meshio
        meshio.write(fn, meshio.Mesh(
            (mesh.p + u.reshape(-1, 3).T).T, [("hexahedron", mesh.t.T)],
            cell_data={"von_mises": [vm.reshape(F.shape[2:]).mean(axis=1)]}))
        return
    fields = particle_fields(basis, MATERIAL, u)
    pg.write_vtu(fn, basis.particles, **fields)


def main(n=3, methods=None, results=None, out=None):
    out = output_dir(out)
    print(pg.threads.describe())
    mesh = prism(n)
    print("prism {} x {} x {} hexahedra ({} nodes)".format(
        n, n, 5 * n, mesh.nvertices))
    rows = [r for r in (study(m, mesh) for m in (methods or THESIS)) if r]
    table = markdown_table(
        ["method (solved as)", "max step [°]", "thesis", "steps / 360°",
         "thesis", "time [s]"],
        [["{} ({})".format(r["method"], r["solved"]), r["step"],
          THESIS[r["method"]][0], r["steps"] or "> 180",
          THESIS[r["method"]][1], "{:.0f}".format(r["seconds"])]
         for r in rows])
    print(table)
    if results:
        print("updated", update_results(
            results, "torsion_{}".format(n),
            "`python demos/torsion.py --n {}`: torsion of the 1 × 1 × 5 mm "
            "prism, {} × {} × {} hexahedra ({} nodes; the thesis: 16 × 16 × "
            "80), fixed equal steps, Newton tol 1e-9, at most 25 "
            "iterations.\n\n".format(n, n, n, 5 * n, mesh.nvertices) + table))
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4))
    y = np.arange(len(rows))
    ax.barh(y - 0.2, [r["step"] for r in rows], 0.4, label="measured")
    ax.barh(y + 0.2, [THESIS[r["method"]][0] if isinstance(
        THESIS[r["method"]][0], int) else 0 for r in rows], 0.4,
            label="thesis (16 x 16 x 80)")
    ax.set_yticks(y, [r["method"] for r in rows])
    ax.set_xlabel("largest converging single step [°]")
    ax.legend()
    save_figure(fig, os.path.join(out, "torsion.png"))
    for r in rows:
        if r["steps"] and r["last"]:
            fn = os.path.join(out, "torsion_{}.vtu".format(
                r["solved"].replace(" ", "_").replace("+", "p")))
            von_mises_vtu(r, fn)
    print("wrote the VTU of each method's last converged run to", out)
    return rows


if __name__ == "__main__":
    ap = demo_parser(__doc__, results=True)
    ap.add_argument("--n", type=int, default=3,
                    help="n x n x 5n hexahedra (thesis: 16)")
    ap.add_argument("--methods", nargs="+", choices=list(THESIS),
                    metavar="METHOD",
                    help="formulations of Table 7.4 to run (default: the demo's selection)")
    ap.add_argument("--full", action="store_true",
                    help="the thesis' 16 x 16 x 80 elements (hours)")
    a = ap.parse_args()
    if a.quick:
        a.n, a.methods = 2, ["FEM H1", "PBG Unl"]
    main(16 if a.full else a.n, a.methods, a.results, a.out)
