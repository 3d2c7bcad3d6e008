"""Cook's membrane, linear plane stress: PG versus scikit-fem FE on the same
node sets — error against wall time.

Geometry (0,0), (48,44), (48,60), (0,44); E = 1, nu = 1/3, plane stress;
left edge clamped, total shear load 1 on the right edge.  The quantity is the
vertical displacement v(48, 52); the literature value is 23.96, our reference
is a Q2 overkill solution (Richardson-extrapolated from 64x64 and 128x128,
``skfem_pg.scenes.reference.linear_cook``, cached).

Methods on the same nodes (regular and ±0.3h distorted node sets):
  T1, Q1          scikit-fem elements
  PBG U1          WTE1 (classical correspondence), uncorrected
  PBG Unl         MTE1 + bond correction, no VC correction
  VC PBG Unl      MTE1 + bond correction + V5 (the default FamilyBasis)

Prints a table (error, preprocess / assemble / solve seconds) and writes
out/cook_membrane.png and a VTU of the finest VC PBG Unl solution.

    python demos/cook_membrane.py [--max-n 128]
"""
import os
import time

import numpy as np
import skfem as fem

import skfem_pg as pg
from harness import demo_parser, output_dir
from skfem_pg.materials import lame
from skfem_pg.formulations import linear_elasticity
from skfem_pg.scenes.reference import linear_cook
from harness import plot_error_vs_time

OUT = output_dir(create=False)  # --out, $SKFEM_PG_OUT or ./out
POINT = np.array([48.0, 52.0])
LITERATURE = 23.96

#: one direct solver for every method (RCM + SuperLU, skfem_pg.solvers)
SOLVER = pg.solvers.direct

LAM, MU = lame(1.0, 1.0 / 3.0, plane_stress=True)
FORM = linear_elasticity(LAM, MU)

PG_METHODS = {
    "PBG U1": dict(shape="WTE1"),
    "PBG Unl": dict(shape="MTE1", bond=True, vc=None),
    "VC PBG Unl": dict(shape="MTE1", bond=True, vc="V5"),
}


def tip_dof(mesh):
    return 2 * pg.meshing.vertex_at(mesh, POINT) + 1


def solve_fe(mesh, elem):
    t0 = time.perf_counter()
    b = fem.Basis(mesh, fem.ElementVector(elem))
    fb = fem.FacetBasis(mesh, fem.ElementVector(elem), facets="right")
    f = fem.LinearForm(lambda v, w: v[1] / 16.0).assemble(fb)
    D = b.get_dofs("left")
    t1 = time.perf_counter()
    K = FORM.assemble(b)
    t2 = time.perf_counter()
    u = fem.solve(*fem.condense(K, f, D=D), solver=SOLVER)
    t3 = time.perf_counter()
    return u, (t1 - t0, t2 - t1, t3 - t2)


def solve_pg(mesh, kw):
    t0 = time.perf_counter()
    b = pg.FamilyBasis(pg.Particles.from_mesh(mesh), dim=2, **kw)
    f = pg.traction(b, "right", [0.0, 1.0 / 16.0])
    D = b.get_dofs("left")
    t1 = time.perf_counter()
    K = pg.assemble(FORM, b)
    t2 = time.perf_counter()
    u = fem.solve(*fem.condense(K, f, D=D), solver=SOLVER)
    t3 = time.perf_counter()
    return u, (t1 - t0, t2 - t1, t3 - t2), b


def main(max_n=64, ref_sizes=(64, 128)):
    ref, _ = linear_cook(LAM, MU, ref_sizes)
    print("reference v(48,52) = {:.5f} (Q2 overkill; literature {})"
          .format(ref, LITERATURE))
    ns = [n for n in (4, 8, 16, 32, 64, 128) if n <= max_n]
    rows = []
    last = None
    for label, amount in (("regular", 0.0), ("irregular", 0.3)):
        for n in ns:
            quad = pg.meshing.cook_membrane(n)
            if amount:
                quad = pg.meshing.distort(quad, amount, seed=n)
                quad = quad.with_boundaries({
                    "left": lambda x: np.isclose(x[0], 0.0),
                    "right": lambda x: np.isclose(x[0], 48.0)})
            tri = quad.to_meshtri().with_boundaries({
                "left": lambda x: np.isclose(x[0], 0.0),
                "right": lambda x: np.isclose(x[0], 48.0)})
            dof = tip_dof(quad)
            for name, mesh, elem in (("T1", tri, fem.ElementTriP1()),
                                     ("Q1", quad, fem.ElementQuad1())):
                u, t = solve_fe(mesh, elem)
                rows.append((label, n, name, u[dof], t))
            for name, kw in PG_METHODS.items():
                u, t, b = solve_pg(quad, kw)
                rows.append((label, n, name, u[dof], t))
                if name == "VC PBG Unl":
                    last = (b, u)
    print("\n{:9s} {:>4s} {:>7s} {:12s} {:>10s} {:>9s} {:>8s} {:>8s} {:>8s}"
          .format("nodes", "n", "np", "method", "v(48,52)", "rel.err",
                  "pre[s]", "asm[s]", "solve[s]"))
    for label, n, name, v, t in rows:
        print("{:9s} {:4d} {:7d} {:12s} {:10.5f} {:9.2e} {:8.4f} {:8.4f} "
              "{:8.4f}".format(label, n, (n + 1) ** 2, name, v,
                               abs(v - ref) / ref, *t))
    os.makedirs(OUT, exist_ok=True)
    plot(rows, ref, os.path.join(OUT, "cook_membrane.png"))
    b, u = last
    pg.write_vtu(os.path.join(OUT, "cook_membrane.vtu"), b.particles,
                 displacement=u)
    print("\nwrote " + OUT + "/cook_membrane.png and cook_membrane.vtu")
    return rows, ref


def plot(rows, ref, fn):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5), sharey=True)
    styles = {"T1": "k--o", "Q1": "k-s", "PBG U1": "C1-^",
              "PBG Unl": "C2-v", "VC PBG Unl": "C0-D"}
    for ax, label in zip(axes, ("regular", "irregular")):
        sel = [dict(method=name, err=abs(v - ref) / ref,
                    **dict(zip(("preprocess", "assemble", "solve"), t)))
               for lab, n, name, v, t in rows if lab == label]
        plot_error_vs_time(ax, sel, styles, "relative error of v(48, 52)",
                           "Cook's membrane, {} node sets".format(label),
                           target=None)
    fig.tight_layout()
    fig.savefig(fn, dpi=120)


if __name__ == "__main__":
    ap = demo_parser(__doc__)
    ap.add_argument("--max-n", type=int, default=64,
                    help="finest elements per side (even; default 64)")
    a = ap.parse_args()
    OUT = output_dir(a.out)
    main(8, (16, 32)) if a.quick else main(a.max_n)
