"""Cost of a time step: explicit central differences per formulation
against explicit FE (O1, H1, H1P0) on the same nodes, and an implicit
Newmark step against a quasi-static Newton iteration.

The Taylor rod of ``demos/taylor.py`` (``pg.meshing.taylor_rod(n)``, the
whole rod, default n = 1: 2337 nodes) hits the wall at 227 m/s; each
formulation runs ``--steps`` explicit steps from the impact with the step
fixed at 0.05 µs (below every formulation's stable step there), so the
plastic zone and the wall are active.  Per formulation: integration points,
milliseconds per step, particle-steps per second, the ratio to O1's step,
and the split of the run (force: state + internal force + stress update;
commit: the history; output and contact) plus one stable-step estimate
(``stable_time_step``: elastic tangent + Lanczos).  Implicit: the seconds
of a Newmark step (its Newton iterations) beside one quasi-static Newton
iteration (tangent + direct solve) on the same model.  Kernels use the
package's default of one BLAS thread (``skfem_pg.threads``).

    python benchmarks/dynamics_cost.py [--n 1] [--steps 40] [--results FILE]
"""
import time

import numpy as np

import skfem_pg as pg
from skfem_pg.scenes import Scene
from harness import (demo_parser, markdown_table, update_results)
from skfem_pg.solvers import (RigidWall, central_difference, linear_solver,
                              lumped_mass, newmark, stable_time_step)

COPPER = pg.materials.J2Plasticity.from_young(117.0, 0.35, 0.4, H=0.1)
EXPLICIT = ["FEM O1", "FEM H1", "FEM H1P0", "VCPBG V5m Unl",
            "VCPBG V5m UnlP0", "VCPBG V5m U1SUnl", "VCPBG V3m U1SIG"]
IMPLICIT = ["FEM H1P0", "VCPBG V5m Unl", "VCPBG V3m U1SIG"]
DT = 0.05  # µs


def setup(sc, name):
    basis, model, _, _, _, _ = sc.setup(name)
    m = lumped_mass(basis, 8.93)
    v0 = np.where(np.arange(basis.N) % 3 == 0, -0.227, 0.0)
    return basis, model, m, v0


def points(basis, model):
    lay = getattr(basis, "layout", None)
    if hasattr(model, "u1") and not hasattr(model, "_E2"):
        return len(model.u1.families.offsets) - 1  # U1SIG: the masters
    if lay is not None:
        return lay.n_points
    return basis.dx.size


def explicit(sc, name, steps):
    basis, model, m, v0 = setup(sc, name)
    t0 = time.perf_counter()
    dt = stable_time_step(model, m)
    t_est = time.perf_counter() - t0
    t0 = time.perf_counter()
    tr = central_difference(model, m, steps * DT, v0=v0, dt=DT,
                            wall=RigidWall(0, 0.0), verbose=False,
                            output_every=steps)
    total = time.perf_counter() - t0
    n = basis.N // 3
    return dict(points=points(basis, model), ms=1e3 * total / tr.steps,
                rate=n * tr.steps / total, times=tr.times, steps=tr.steps,
                estimate=t_est, dt=dt,
                ep=model.plastic_strain()[1])


def implicit(sc, name, steps=3):
    basis, model, m, v0 = setup(sc, name)
    tr = newmark(model, m, steps * 2 * DT, 2 * DT, v0=v0,
                 wall=RigidWall(0, 0.0), verbose=False)
    its = sum(h["iterations"] for h in tr.history)
    t_step = (tr.times["assemble"] + tr.times["linear"]) / tr.steps
    s = model.state(tr.x)
    t0 = time.perf_counter()
    K = model.tangent(s).tocsr()
    model.internal_force(s)
    I = np.arange(model.N)
    linear_solver("direct", None)(K[I][:, I].tocsr(), np.ones(I.size))
    t_newton = time.perf_counter() - t0
    return dict(step=t_step, its=its / tr.steps, newton=t_newton)


def main(n=1, steps=40, results=None):
    print(pg.threads.describe())
    sc = Scene("taylor", pg.meshing.taylor_rod(n), COPPER)
    print("Taylor rod n = {}: {} nodes; {} explicit steps of {} µs".format(
        n, sc.mesh.nvertices, steps, DT), flush=True)
    rows, o1 = [], None
    for name in EXPLICIT:
        r = explicit(sc, name, steps)
        o1 = r["ms"] if name == "FEM O1" else o1
        t = r["times"]
        print("  {}: {:.1f} ms/step".format(name, r["ms"]), flush=True)
        rows.append([name, r["points"], "{:.1f}".format(r["ms"]),
                     "{:.0f}".format(r["rate"]),
                     "{:.2f}".format(r["ms"] / o1),
                     "{:.0%}".format(t["force"] / t["total"]),
                     "{:.0%}".format(t["commit"] / t["total"]),
                     "{:.0%}".format((t["output"] + t["contact"])
                                     / t["total"]),
                     "{:.2f}".format(r["estimate"]),
                     "{:.3f}".format(r["dt"]), "{:.3f}".format(r["ep"])])
    text = markdown_table(
        ["formulation", "integration points", "ms/step",
         "particle-steps/s", "vs O1", "force", "commit", "output+contact",
         "stable-step estimate [s]", "stable dt [µs]", "max e_p"], rows)
    irows = []
    for name in IMPLICIT:
        r = implicit(sc, name)
        print("  {}: Newmark step {:.2f} s".format(name, r["step"]),
              flush=True)
        irows.append([name, "{:.2f}".format(r["step"]),
                      "{:.1f}".format(r["its"]),
                      "{:.2f}".format(r["newton"]),
                      "{:.1f}".format(r["step"] / r["newton"])])
    text += "\n\nImplicit (Newmark, dt = {} µs, 3 steps from the impact):" \
        "\n\n".format(2 * DT) + markdown_table(
            ["formulation", "s per Newmark step", "Newton its per step",
             "s per quasi-static Newton iteration (tangent + force + "
             "direct solve)", "step / iteration"], irows)
    print(text)
    if results:
        print("updated", update_results(
            results, "dynamics_cost_{}".format(n),
            "`python benchmarks/dynamics_cost.py --n {} --steps {}`: the "
            "Taylor rod ({} nodes), one BLAS thread in the kernels.\n\n"
            .format(n, steps, sc.mesh.nvertices) + text))


if __name__ == "__main__":
    ap = demo_parser(__doc__, results=True)
    ap.add_argument("--n", type=int, default=1,
                    help='refinement of the Taylor rod (pg.meshing.taylor_rod; 1: 2337 nodes)')
    ap.add_argument("--steps", type=int, default=40,
                    help='explicit steps timed per formulation')
    a = ap.parse_args()
    main(a.n, a.steps, a.results)
