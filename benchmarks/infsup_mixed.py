"""Numerical inf-sup test of the mixed PG pairs (thesis 7.2.5, Fig. 7.15)
beside Q1P0 and MINI.

Model problem: the unit square, plane strain, every boundary dof clamped
(the thesis' Fig. 7.14 fixes fewer dofs through a layer of wall
particles; ``--bc thesis`` fixes u_x on the left and right sides and one
corner completely, our reading of that figure), N x N elements on regular
and ±0.3h distorted node sets.  PG as in the thesis: families of radius
2.51 particle spacings, no VC correction (the test is about the trial
spaces).  beta is the square root of the smallest non-zero eigenvalue of
(7.11) (:func:`skfem_pg.analysis.infsup.infsup_mixed`), kpm the spurious
pressure modes (7.15).  A pair passes when beta stays bounded under
refinement; the slope of log beta over log N is printed for each pair
(0: bounded, -1: beta ~ h).

    python benchmarks/infsup_mixed.py [--sizes 4 8 16] [--bc clamped]
"""
import os
import time

import numpy as np
import skfem as fem

import skfem_pg as pg
from skfem_pg import materials as mat
from skfem_pg.analysis.infsup import infsup_fe, infsup_mixed, infsup_pg
from skfem_pg.formulations import MeanDilatation, NodalPressure
from harness import (demo_parser, markdown_table, output_dir, save_figure,
                     update_results)

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS = os.path.join(HERE, "README.md")
MATERIAL = mat.NeoHookeIsoVol(mu=1.0, K=10.0)  # the spaces do not depend on it


def node_set(N, distorted):
    m = fem.MeshQuad.init_tensor(np.linspace(0, 1, N + 1),
                                 np.linspace(0, 1, N + 1))
    return pg.meshing.distort(m, 0.3, seed=N) if distorted else m


def fixed_dofs(mesh, bc):
    x = mesh.p
    if bc == "clamped":
        b = mesh.boundary_nodes()
        return np.concatenate([2 * b, 2 * b + 1])
    side = np.flatnonzero(np.isclose(x[0], 0) | np.isclose(x[0], 1))
    corner = np.flatnonzero(np.isclose(x[0], 0) & np.isclose(x[1], 0))
    return np.concatenate([2 * side, 2 * corner + 1])


def family_basis(mesh, shape="MTE1"):
    p = pg.Particles.from_mesh(mesh)
    return pg.FamilyBasis(p, pg.families.horizon(p, factor=2.51), dim=2,
                          vc=None, shape=shape)


#: pair -> function(mesh) -> (inf-sup dict); FE first
PAIRS = {
    "Q1P0": lambda m, free: infsup_fe(
        fem.Basis(m, fem.ElementVector(fem.ElementQuad1()), intorder=2),
        free, fem.Basis(m, fem.ElementQuad0(), intorder=2)),
    "MINI": None,  # on the triangulated set, below
    "PBG Unl": lambda m, free: infsup_pg(family_basis(m), free),
    "PBG UnlP0": lambda m, free: infsup_mixed(
        MeanDilatation.of(family_basis(m), MATERIAL), free),
    "PBG U2P1": lambda m, free: infsup_mixed(
        MeanDilatation.of(family_basis(m, "WTE2"), MATERIAL, order=1), free),
    "PBG U2P1C": lambda m, free: infsup_mixed(
        NodalPressure.of(family_basis(m, "WTE2"), MATERIAL, bubble=False),
        free),
    "PBG Unl+P1C": lambda m, free: infsup_mixed(
        NodalPressure.of(family_basis(m), MATERIAL), free),
}


def mini(mesh, bc):
    t = mesh.to_meshtri()
    b = fem.Basis(t, fem.ElementVector(fem.ElementTriMini()))
    fixed = fixed_dofs(mesh, bc)  # vertex dofs: the same numbering
    free = np.setdiff1d(np.arange(b.N), fixed)
    return infsup_fe(b, free, fem.Basis(t, fem.ElementTriP1(),
                                        quadrature=b.quadrature))


def main(sizes=(4, 8, 16), bc="clamped", out=None):
    rows, betas = [], {}
    for distorted in (False, True):
        for name in PAIRS:
            for N in sizes:
                mesh = node_set(N, distorted)
                free = np.setdiff1d(np.arange(2 * mesh.nvertices),
                                    fixed_dofs(mesh, bc))
                t0 = time.perf_counter()
                r = mini(mesh, bc) if name == "MINI" else \
                    PAIRS[name](mesh, free)
                t = time.perf_counter() - t0
                betas.setdefault((name, distorted), []).append(r["beta"])
                rows.append([name, "±0.3h" if distorted else "regular", N,
                             r["n_u"], r["n_p"], "{:.4f}".format(r["beta"]),
                             r["kpm"], "{:.1f}".format(t)])
                print(*rows[-1], flush=True)
    slope = {k: np.polyfit(np.log(sizes), np.log(v), 1)[0]
             for k, v in betas.items()}
    summary = markdown_table(
        ["pair", "regular: beta at N = " + ", ".join(map(str, sizes)),
         "slope", "±0.3h: beta", "slope"],
        [[name, ", ".join("{:.3g}".format(b) for b in betas[name, False]),
          "{:+.2f}".format(slope[name, False]),
          ", ".join("{:.3g}".format(b) for b in betas[name, True]),
          "{:+.2f}".format(slope[name, True])] for name in PAIRS])
    print(summary)
    text = ("`python benchmarks/infsup_mixed.py --sizes {} --bc {}`: "
            "inf-sup value beta (7.14) and spurious pressure modes kpm "
            "(7.15) on the unit square ({}), PG families of radius 2.51 "
            "spacings without VC as in the thesis; MINI on the quads split "
            "into triangles.  slope = d log beta / d log N (0: bounded, "
            "-1: beta ~ h).\n\n".format(" ".join(map(str, sizes)), bc,
                                         "all boundary dofs clamped"
                                         if bc == "clamped" else
                                         "u_x fixed on left and right, one "
                                         "corner clamped")
            + summary + "\n\n" + markdown_table(
                ["pair", "node set", "N", "n_u", "n_p", "beta", "kpm",
                 "time [s]"], rows))
    print("updated", update_results(RESULTS, "infsup_mixed_" + bc, text))
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(10, 4), sharey=True)
    for a, distorted in zip(ax, (False, True)):
        for name in PAIRS:
            a.loglog(sizes, betas[name, distorted], "o-", label=name)
        a.set_xlabel("N")
        a.set_title("±0.3h" if distorted else "regular")
    ax[0].set_ylabel("inf-sup value beta")
    ax[0].legend(fontsize=8)
    out = output_dir(out)
    save_figure(fig, os.path.join(out, "infsup_mixed_{}.png".format(bc)))
    return betas


if __name__ == "__main__":
    ap = demo_parser(__doc__)
    ap.add_argument("--sizes", type=int, nargs="+", default=[4, 8, 16],
                    help='elements per side of the square node sets')
    ap.add_argument("--bc", choices=["clamped", "thesis"],
                    default="clamped",
                    help="boundary conditions: the clamped square, or the thesis' setting")
    args = ap.parse_args()
    main(args.sizes, args.bc, args.out)
