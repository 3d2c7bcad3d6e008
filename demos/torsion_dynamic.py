"""Dynamic torsion of an elasto-plastic prism (thesis 7.3.6, Table 7.5):
maximal e_p at 360 degrees on a distorted node set (D1), the angle at
which the adaptive Newmark step fails on a more distorted one (D2).

The 1 x 1 x 5 mm prism of 7.3.2, bottom clamped, the top rotated about the
prism axis at one rotation per 10 µs from rest; the steel of 7.3.5 (E =
206.9, nu = 0.29, sigma_y0 = 0.45, sigma_yinf = 1.165, H = 0.13 kN/mm^2,
delta = 16.93) with rho0 = 7.85 g/cm^3; units mm, µs, kN.  n x n x 5n
hexahedra (thesis: 7 x 7 x 35 = 1715, ``--full``; default n = 3) whose
interior nodes are perturbed by up to 0.25 h (D1) and 0.5 h (D2)
(``pg.meshing.distort``; the thesis draws U(-0.25, 0.25) h and U(-0.5, 0.5)
h).  Implicit Newmark (``newmark``) from a step of 2 degrees, halved on
failure, regrown after easy steps; D2 stops where a step of 0.1 degree
(``dt_min``) does not converge, and that angle is the failure angle
(``--max-angle`` caps the run).  Beside each failure, the inversion
diagnostic: how many collocation cells the last converged state turns
inside out (``particles.inverted_cells``).  Newton takes full increments
(a failed iterate cuts the step), as the thesis' failure angles assume;
``--line-search`` halves an increment that fails or raises the residual
first (:func:`skfem_pg.solvers.newton`).

Prints per formulation: max e_p at 360 degrees (D1) and the failure angle
(D2) beside Table 7.5, steps and wall time; writes out/torsion_dynamic.png
(max e_p over the angle) and, for D1, a VTU of the last state per
formulation.  ``--results benchmarks/README.md`` writes the table there.

    python demos/torsion_dynamic.py [--n 3] [--methods ...] [--full]
                                    [--max-angle 720] [--line-search]

``--quick`` (what ``tests/test_demos.py`` runs, about 20 s): VCPBG U1SIG and
FEM H1P0 on 2 x 2 x 10 hexahedra, both node sets to 90 degrees; on so few
nodes the particle e_p is not converged (4.0 against H1P0's 0.77).
"""
import math
import os
import time

import numpy as np
import skfem as fem

import skfem_pg as pg
from skfem_pg.discretization.particles import inverted_cells
from skfem_pg.materials import J2Plasticity
from skfem_pg.scenes import Scene
from harness import (demo_parser, markdown_table, new_figure, output_dir,
                     save_figure, update_results)
from skfem_pg.solvers import DynamicsError, lumped_mass, newmark

STEEL = J2Plasticity.from_young(206.9, 0.29, 0.45, H=0.13, sigma_yinf=1.165,
                                delta=16.93)
RHO = 7.85
A, L = 1.0, 5.0
TURN = 10.0  # µs per rotation
#: Table 7.5: name -> (the name solved, max e_p at 360 deg D1, failure
#: angle D2)
METHODS = {
    "VCPBG Unl": ("VCPBG Unl", 0.92, 1076.7),
    "VCPBG U2": ("VCPBG U2", 0.91, 641.5),
    "VCPBG UnlP0": ("VCPBG UnlP0", 1.97, 1150.0),
    "VCPBG U2P1": ("VCPBG U2P1", 1.29, 872.9),
    "VCPBG U2P1C": ("VCPBG U2P1C", 2.32, 460.0),
    "VCPBG Unl+P1C": ("VCPBG Unl+P1C", 10.86, 1364.2),
    "VCPBG U1SUnl": ("VCPBG U1SUnl", 1.24, 1351.6),
    "VCPBG U1SIG": ("VCPBG U1SIG", 1.3, 2119.1),
    "VCPPG Unl": ("VCPPG Unl", None, 2.9),
    "VCPPG UnlP0": ("VCPPG UnlP0", 1.52, 45.1),
    "FEM H1": ("FEM H1", 1.05, 11.0),
    "FEM H1P0": ("FEM H1P0", 1.33, 97.2),
}
DEFAULT = ["VCPBG Unl", "VCPBG U1SIG", "FEM H1", "FEM H1P0"]


def prism(n, amount, seed=0):
    m = fem.MeshHex.init_tensor(np.linspace(0, A, n + 1),
                                np.linspace(0, A, n + 1),
                                np.linspace(0, L, 5 * n + 1))
    if amount:
        m = pg.meshing.distort(m, amount, seed=seed)
    return m.with_boundaries({"bottom": lambda x: np.isclose(x[2], 0.0),
                              "top": lambda x: np.isclose(x[2], L)})


def twist(x, t):
    """The top's displacement at time ``t`` [µs]: a rotation by 360
    degrees per ``TURN`` about the axis x = y = A/2."""
    a = 2 * math.pi * t / TURN
    c, s = math.cos(a), math.sin(a)
    X, Y = x[0] - 0.5 * A, x[1] - 0.5 * A
    return np.array([c * X - s * Y - X, s * X + c * Y - Y, 0.0 * x[2]])


def run(mesh, solved, max_angle, vtu=None, line_search=False):
    """Twist to ``max_angle`` degrees (or failure): the angle reached, the
    max e_p over the angle, the inversion diagnostic."""
    t0 = time.perf_counter()
    sc = Scene("torsion-dynamic", mesh, STEEL, clamped=["bottom"],
               prescribed={"top": twist})
    basis, model, _, D, u_D, _ = sc.setup(solved)
    m = lumped_mass(basis, RHO)
    dt = 2.0 / 360 * TURN  # 2 degrees
    curve = {"angle": [0.0], "ep": [0.0]}
    last = {"x": np.zeros(model.N)}

    def output(t, x, v, rec):
        curve["angle"].append(360.0 * t / TURN)
        curve["ep"].append(model.plastic_strain()[1])
        last["x"] = x

    status = "done"
    t_end = max_angle / 360.0 * TURN
    try:
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            tr = newmark(model, m, t_end, dt, D=D, u_D=u_D, callback=output,
                         dt_min=0.1 / 360 * TURN, verbose=True,
                         maxiter=15, line_search=line_search)
        steps = tr.steps
    except DynamicsError:
        status = "failed"
        steps = len(curve["angle"]) - 1
    x = last["x"]
    bad = inverted_cells(basis.particles, x[:basis.N]) if hasattr(
        basis, "particles") else _fe_inverted(basis, x)
    if vtu is not None and hasattr(basis, "particles"):
        pg.write_vtu(vtu, basis.particles, u=x[:basis.N],
                     ep=model.plastic_strain()[0])
    return dict(angle=curve["angle"][-1], curve={k: np.array(v) for k, v in
                                                 curve.items()},
                status=status, steps=steps, inverted=int(bad.size),
                seconds=time.perf_counter() - t0)


def _fe_inverted(basis, x):
    """Cells of an FE mesh with a non-positive corner Jacobian."""
    mesh = basis.mesh
    d = mesh.dim()
    p = mesh.p + x[:basis.N].reshape(-1, d).T
    X = type(mesh).init_refdom().p
    s0 = np.sign(mesh._mapping().detDF(X))
    J = type(mesh)(p, mesh.t)._mapping().detDF(X) * s0
    return np.flatnonzero(np.any(J <= 0, axis=1))


def ep_at(curve, angle):
    a, e = curve["angle"], curve["ep"]
    return float(np.interp(angle, a, e)) if a[-1] >= angle - 1e-9 \
        else None


def main(n=3, methods=None, max_angle=720.0, results=None, out=None,
         line_search=False, d1_angle=360.0):
    out = output_dir(out)
    print(pg.threads.describe())
    d1, d2 = prism(n, 0.25), prism(n, 0.5)
    print("dynamic torsion: {0} x {0} x {1} hexahedra, {2} nodes; D1 "
          "+-0.25 h to {4:g} deg, D2 +-0.5 h to failure (at most {3} deg)"
          .format(n, 5 * n, d1.nvertices, max_angle, d1_angle), flush=True)
    rows, runs = [], {}
    for label in methods or DEFAULT:
        solved, th_ep, th_fail = METHODS[label]
        print("  {} ...".format(label), flush=True)
        r1 = run(d1, solved, d1_angle, os.path.join(
            out, "torsion_dynamic_{}.vtu".format(
                solved.replace(" ", "_").replace("+", "p"))),
            line_search)
        ep1 = ep_at(r1["curve"], d1_angle)
        print("    D1: {} at {:.1f} deg, max e_p at {:g}: {}, {} steps, "
              "{:.0f} s".format(r1["status"], r1["angle"], d1_angle, ep1,
                                r1["steps"], r1["seconds"]), flush=True)
        r2 = run(d2, solved, max_angle, line_search=line_search)
        print("    D2: {} at {:.1f} deg ({} inverted cells), {} steps, "
              "{:.0f} s".format(r2["status"], r2["angle"], r2["inverted"],
                                r2["steps"], r2["seconds"]), flush=True)
        runs[label] = (r1, r2)
        rows.append([
            label, "–" if ep1 is None else "{:.2f}".format(ep1),
            "–" if th_ep is None else th_ep,
            ("{:.1f}" if r2["status"] == "failed" else ">= {:.0f}").format(
                r2["angle"]), th_fail, r2["inverted"],
            "{} / {}".format(r1["steps"], r2["steps"]),
            "{:.0f}".format(r1["seconds"] + r2["seconds"])])
    text = markdown_table(
        ["formulation", "max e_p at {:g} deg (D1)".format(d1_angle),
         "thesis",
         "failure angle [deg] (D2)", "thesis", "inverted cells at the end "
         "(D2)", "steps D1 / D2", "time [s]"], rows)
    print(text)
    if results:
        print("updated", update_results(
            results, "torsion_dynamic_{}_{:g}{}".format(
                n, max_angle, "_ls" if line_search else ""),
            "`python demos/torsion_dynamic.py --n {} --max-angle {:g}{}`: "
            "{} x {} x {} hexahedra ({} nodes).\n\n".format(
                n, max_angle, " --line-search" if line_search else "", n, n,
                5 * n, d1.nvertices) + text))
    plot(runs, os.path.join(out, "torsion_dynamic.png"))
    return runs


def plot(runs, fn):
    fig, ax = new_figure()
    for label, (r1, r2) in runs.items():
        line, = ax.plot(r1["curve"]["angle"], r1["curve"]["ep"],
                        label=label + " D1")
        ax.plot(r2["curve"]["angle"], r2["curve"]["ep"], "--",
                color=line.get_color(), label=label + " D2")
    ax.set_xlabel("twist [deg]")
    ax.set_ylabel("max e_p")
    ax.legend(fontsize=7, ncol=2)
    save_figure(fig, fn)


if __name__ == "__main__":
    ap = demo_parser(__doc__, results=True)
    ap.add_argument("--n", type=int, default=3,
                    help="n x n x 5n hexahedra (default 3)")
    ap.add_argument("--full", action="store_true",
                    help="n = 7, the thesis' 1715 elements, and every "
                    "formulation of Table 7.5 (hours)")
    ap.add_argument("--methods", nargs="+", choices=list(METHODS),
                    metavar="METHOD",
                    help="formulations of Table 7.5 to run (default: the demo's selection)")
    ap.add_argument("--max-angle", type=float, default=720.0,
                    help="where D2 stops if nothing fails (default 720)")
    ap.add_argument("--line-search", action="store_true",
                    help="Newton with its line search (default: full "
                    "increments, as the thesis' failure angles assume)")
    a = ap.parse_args()
    if a.quick:  # 2 x 2 x 10 hexahedra, both node sets to 90 degrees
        main(2, ["VCPBG U1SIG", "FEM H1P0"], 90.0, None, a.out, a.line_search,
             d1_angle=90.0)
        raise SystemExit
    main(7 if a.full else a.n,
         list(METHODS) if a.full and not a.methods else a.methods,
         a.max_angle if not a.full else 2400.0, a.results, a.out,
         a.line_search)
