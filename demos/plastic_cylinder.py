"""Thick-walled cylinder, finite J2 plasticity: the inner pressure against
the plane-strain limit (2/sqrt 3) sigma_y ln(b/a).

Quarter ring a = 1 <= r <= b = 2, plane strain, symmetry planes, the inner
radius pushed out radially to u(a) = 0.01 (about three times the
displacement at which the whole wall yields; strains stay near 1 %, so the
small-strain limit applies); E = 1000, nu = 0.3, perfect plasticity,
sigma_y = 1 (``J2Plasticity``).  FE Q1, Q1P0 and PG Unl, UnlP0, Unl+P1C on
the same nodes (annulus, 6 x 12 elements; ``--n`` refines).

Prints, per formulation, the pressure at each load step over the limit,
the maximal accumulated plastic strain, Newton's residuals in the last
step (quadratic convergence of the algorithmic tangent) and the wall
time; writes out/plastic_cylinder.png (pressure against u(a)) and
out/plastic_cylinder.vtu (the PG UnlP0 particles with u and e_p).

    python demos/plastic_cylinder.py [--n 6]
"""
import os
import time

import numpy as np

import skfem_pg as pg
from skfem_pg.materials import J2Plasticity
from skfem_pg.scenes import Scene
from harness import demo_parser, output_dir
from skfem_pg.solvers import newton

A, B, U_A = 1.0, 2.0, 0.01
MATERIAL = J2Plasticity.from_young(1000.0, 0.3, 1.0)
LIMIT = 2 / np.sqrt(3) * MATERIAL.sigma_y0 * np.log(B / A)
METHODS = ["FEM Q1", "FEM Q1P0", "VCPBG V5m Unl", "VCPBG V5m UnlP0",
           "VCPBG V5m Unl+P1C"]


def inner_pressure(model, basis, x):
    """The pressure on the inner radius from the radial reactions (the
    symmetry planes' reactions at the corner nodes are tangential):
    sum R . e_r = p a pi/2."""
    R = model.internal_force(model.state(x))[:model.n_u].reshape(-1, 2)
    nodes = np.unique(basis.get_dofs("inner").all("u^1") // 2)
    X = basis.doflocs[:, 2 * nodes]
    return np.sum(R[nodes] * (X / np.hypot(*X)).T) / (A * np.pi / 2)


def run(scene, method, steps=10):
    """Pressure after each of ``steps`` equal load steps."""
    basis, model, f, D, u_D, _ = scene.setup(method)
    t0 = time.perf_counter()
    x, pressures, last = None, [], None
    for i in range(1, steps + 1):  # one call per step: pressure history
        x, hist = newton(model, f, D=D, u_D=lambda t, i=i: u_D(
            (i - 1 + t) / steps), u0=x, verbose=False)
        pressures.append(inner_pressure(model, basis, x))
        last = hist[-1]["residuals"]
    return basis, model, x, np.array(pressures), last, \
        time.perf_counter() - t0


def main():
    ap = demo_parser(__doc__)
    ap.add_argument("--n", type=int, default=6,
                    help="elements across the wall (default 6)")
    args = ap.parse_args()
    if args.quick:
        args.n = 2
    out = output_dir(args.out)
    scene = Scene("plastic cylinder", pg.meshing.annulus(args.n, A, B), MATERIAL, prescribed={
        "inner": lambda x, t: t * U_A * x / np.hypot(x[0], x[1]),
        "xaxis": {1: 0.0}, "yaxis": {0: 0.0}})
    steps = 10
    ua = U_A * np.arange(1, steps + 1) / steps
    print("limit pressure (2/sqrt 3) sigma_y ln(b/a) = {:.5f}".format(LIMIT))
    print("{:20s} {:>8s} {:>8s} {:>8s} {:>7s} {:>6s}  last step |r|".format(
        "method", "p/plim", "(u/2)", "(u/5)", "max ep", "s"))
    curves, vtu = {}, None
    for method in METHODS:
        basis, model, x, p, res, sec = run(scene, method, steps)
        curves[method] = p
        ep, ep_max = model.plastic_strain()
        print("{:20s} {:8.4f} {:8.4f} {:8.4f} {:7.4f} {:6.2f}  {}".format(
            method, p[-1] / LIMIT, p[steps // 2 - 1] / LIMIT,
            p[steps // 5 - 1] / LIMIT, ep_max, sec,
            " ".join("{:.1e}".format(r) for r in res)), flush=True)
        if method == "VCPBG V5m UnlP0":
            vtu = (basis, x[:model.n_u], ep)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4))
    for method, p in curves.items():
        ax.plot(np.r_[0, ua], np.r_[0, p] / LIMIT, marker=".", label=method)
    ax.axhline(1.0, color="k", lw=0.8, ls="--", label="limit")
    ax.set_xlabel("inner radial displacement u(a)")
    ax.set_ylabel("inner pressure / limit pressure")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "plastic_cylinder.png"), dpi=120)
    basis, u, ep = vtu
    pg.write_vtu(os.path.join(out, "plastic_cylinder.vtu"),
                 basis.particles, u=u, ep=ep)
    print("wrote", os.path.join(out, "plastic_cylinder.png"), "and .vtu")


if __name__ == "__main__":
    main()
