"""Why VC PBG Unl is soft on the 3-D Cook's membrane: out-of-plane bending
of a plate four to eight particle layers thick.

The 3-D Cook's membrane of ``demos/cook_3d.py`` (outline (0,0), (48,44),
(48,60), (0,44), thickness 10, clamped at x = 0, load in z on x = 48) is a
plate in bending.  This benchmark isolates the discretization error from
the geometric nonlinearity:

1. **Energy capture** (no solve, :func:`skfem_pg.analysis.energy_capture`):
   the discrete strain energy of the nodal interpolant of the pure bending
   field :math:`u = (-\\kappa x (z - T/2),\\ 0,\\ \\kappa x^2/2)`
   (:math:`\\varepsilon_{xx} = -\\kappa(z - T/2)`, all other strains zero)
   divided by the exact :math:`\\frac12(\\lambda+2\\mu)\\kappa^2 A T^3/12`.
   ``quadrature`` is the same sum with the exact gradients at the
   quadrature points (members for PG), so it shows the quadrature's part
   of the error; the rest is the gradients'.  Below 1: the discretization
   is too soft in bending; above 1: too stiff (O1 locks).
2. **Linear Cook**: the same plate with linear elasticity (lambda = 100,
   mu = 40) and a small load; z-displacement of the corner (48, 60, 10)
   against H2 on a 16 x 16 x 4 hex grid (O2 on the gmsh tetrahedra of size
   2 agrees to 0.07 %), for O1 and PG on the same gmsh tetrahedra, with
   wall time.

Node sets: gmsh tetrahedra (``meshes/cook3d.geo``, ``--sizes``)
and regular hexahedral grids split into tetrahedra (``--grids``), distorted by
±0.3h.  Writes ``out/bending_3d.png``.

    python benchmarks/bending_3d.py [--sizes 5 3.5 2.5 2] [--grids 8 12 16]
"""
import os
import time
import warnings

import numpy as np
import skfem as fem

import skfem_pg as pg
from harness import (demo_parser, markdown_table, output_dir, update_results)
from skfem_pg import families as families_mod
from skfem_pg import materials as mat
from skfem_pg.analysis import energy_capture
from skfem_pg.scenes import Scene

HERE = os.path.dirname(os.path.abspath(__file__))
T = 10.0  # the thickness of pg.meshing.cook_membrane_3d
CORNER = (48.0, 60.0, T)

RESULTS = os.path.join(HERE, "README.md")  # measured tables, written here
OUT = output_dir(create=False)  # --out, $SKFEM_PG_OUT or ./out
LAM, MU = 100.0, 40.0
MATERIAL = mat.LinearElastic(lam=LAM, mu=MU)
AREA = 0.5 * (44.0 + 16.0) * 48.0  # the Cook outline
KAPPA = 1e-3
Q = 0.04  # linear: any load; the nonlinear demo uses 4

#: PG variants: label -> FamilyBasis keywords (families as a builder)
PG = {
    "VC PBG Unl": {},
    "PBG Unl": {"vc": None},
    "VC PBG Unl, 10 nearest": {
        "families": lambda p: families_mod.nearest(p, 10)},
    # Petrov–Galerkin: no energy, so only in the Cook table
    "BCPPG Unl (no VC)": {"method": "PPG1", "vc": None},
}
STYLES = {"O1": "k--o", "VC PBG Unl": "C0-D", "PBG Unl": "C2-v",
          "VC PBG Unl, 10 nearest": "C1-s", "BCPPG Unl (no VC)": "C3-^"}


def bending(x):
    """Pure bending about the y axis, ``(3, n)`` at ``x`` (``(3, ...)``)."""
    return np.array([-KAPPA * x[0] * (x[2] - 0.5 * T), 0.0 * x[0],
                     0.5 * KAPPA * x[0] ** 2])


def bending_gradient(x):
    z = np.zeros_like(x[0])
    return np.array([[-KAPPA * (x[2] - 0.5 * T), z, -KAPPA * x[0]],
                     [z, z, z],
                     [KAPPA * x[0], z, z]])


EXACT = 0.5 * (LAM + 2 * MU) * KAPPA ** 2 * AREA * T ** 3 / 12.0


def capture(basis):
    """(energy ratio, quadrature-only ratio): the latter with the exact
    gradients at the quadrature points."""
    X = np.asarray(basis.global_coordinates())
    F = bending_gradient(X) + np.eye(3).reshape(3, 3, 1, 1)
    quadrature = np.sum(basis.dx * MATERIAL.energy(F)) / EXACT
    return energy_capture(basis, bending, MATERIAL, EXACT), float(quadrature)


def with_families(mesh, kw):
    """``kw`` with its family builder (if any) applied to ``mesh``."""
    kw = dict(kw)
    if "families" in kw:
        kw["families"] = kw["families"](pg.Particles.from_mesh(mesh))
    return kw


def energy_table(node_sets):
    print("\n1. energy capture of pure bending (1 = exact; quadrature: "
          "exact gradients, same weights)")
    print("{:24s} {:>6s} {:26s} {:>8s} {:>10s}".format(
        "node set", "nodes", "method", "energy", "quadrature"))
    for label, mesh in node_sets:
        fe = fem.Basis(mesh, fem.ElementVector(fem.ElementTetP1()),
                       intorder=1)
        rows = [("O1", fe)]
        for n, kw in PG.items():
            if kw.get("method", "PBG") == "PBG":
                rows.append((n, pg.FamilyBasis(
                    mesh, dim=3, **with_families(mesh, kw))))
        for name, b in rows:
            e, q = capture(b)
            print("{:24s} {:6d} {:26s} {:8.3f} {:10.3f}".format(
                label, mesh.nvertices, name, e, q), flush=True)


def scene(mesh):
    return Scene("cook3d-linear", mesh, MATERIAL, clamped=["left"],
                 tractions={"right": [0.0, 0.0, Q]},
                 probes={"corner": CORNER})


def cook_table(sizes, w_ref):
    print("\n2. linear 3-D Cook, corner z-displacement (H2 16x16x4: "
          "{:.6f})".format(w_ref))
    print("{:>6s} {:26s} {:>10s} {:>9s} {:>8s}".format(
        "nodes", "method", "w", "rel.err", "time[s]"))
    rows = []
    geo = pg.meshing.geo_path("cook3d.geo")
    for s in sizes:
        sc = scene(pg.meshing.from_geo(geo, size=s))
        runs = [("O1", {"scheme": "O1"})] + [
            (n, dict(kw, scheme="PG")) for n, kw in PG.items()]
        for name, kw in runs:
            t0 = time.perf_counter()
            r = sc.solve(**with_families(sc.mesh, kw))
            t = time.perf_counter() - t0
            w = r.probes["corner"][2]
            rows.append(dict(method=name, nodes=sc.mesh.nvertices, w=w,
                             err=(w - w_ref) / w_ref, time=t))
            print("{nodes:6d} {method:26s} {w:10.6f} {err:+9.2%} "
                  "{time:8.2f}".format(**rows[-1]), flush=True)
    return rows


def plot(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    for name in ["O1"] + list(PG):
        r = [x for x in rows if x["method"] == name]
        n = [x["nodes"] for x in r]
        e = [x["err"] for x in r]
        ax[0].plot(n, e, STYLES[name], label=name)
        ax[1].loglog([x["time"] for x in r], np.abs(e), STYLES[name],
                     label=name)
    ax[0].axhline(0, color="0.5", lw=0.5)
    ax[0].set_xlabel("nodes")
    ax[0].set_ylabel("signed relative error of w")
    ax[1].set_xlabel("wall time [s]")
    ax[1].set_ylabel("|relative error|")
    ax[0].legend(fontsize=8)
    fig.suptitle("linear 3-D Cook's membrane (plate bending), gmsh "
                 "tetrahedra")
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main(sizes=(5, 3.5, 2.5, 2.0), grids=(8, 12, 16)):
    print(pg.threads.describe())
    warnings.filterwarnings("ignore", message="Indefinite matrix")
    geo = pg.meshing.geo_path("cook3d.geo")
    sets = [("gmsh size {}".format(s), pg.meshing.from_geo(geo, size=s))
            for s in sizes]
    for n in grids:
        h = pg.meshing.cook_membrane_3d(n, max(1, n // 4), T, 0.3, seed=n)
        sets.append(("hex {}x{}x{} split, ±0.3h".format(n, n, n // 4),
                     pg.meshing.transfer_boundaries(h, h.to_meshtet())))
    # a linear field is captured exactly by every method (consistency)
    b = pg.FamilyBasis(sets[0][1], dim=3)
    grad = np.array([[0.1, 0.3, -0.2], [0.2, 0.4, 0.1], [-0.1, 0.05, 0.3]])
    lin = energy_capture(b, lambda x: np.tensordot(grad, x, 1), MATERIAL,
                         MATERIAL.energy(np.eye(3) + grad)
                         * b.particles.volumes.sum())
    print("linear field, VC PBG Unl on {} nodes: energy ratio - 1 = "
          "{:.1e}".format(sets[0][1].nvertices, lin - 1))
    energy_table(sets)
    ref = scene(pg.meshing.cook_membrane_3d(16, 4, T)).solve("H2")
    rows = cook_table(sizes, ref.probes["corner"][2])
    print("updated", update_results(
        RESULTS, "bending_3d_linear_cook",
        "`python benchmarks/bending_3d.py --sizes {}`: linear 3-D Cook "
        "(plate bending), corner z-displacement against H2 16×16×4 "
        "(w = {:.6f}), gmsh tetrahedra.\n\n".format(
            " ".join("{:g}".format(x) for x in sizes),
            ref.probes["corner"][2])
        + markdown_table(["nodes", "method", "w", "error", "time [s]"],
                         [[r["nodes"], r["method"], "{:.6f}".format(r["w"]),
                           "{:+.2%}".format(r["err"]),
                           "{:.2f}".format(r["time"])] for r in rows])))
    os.makedirs(OUT, exist_ok=True)
    plot(rows, os.path.join(OUT, "bending_3d.png"))
    print("wrote " + OUT + "/bending_3d.png")
    return rows


if __name__ == "__main__":
    ap = demo_parser(__doc__)
    ap.add_argument("--sizes", type=float, nargs="+",
                    default=[5, 3.5, 2.5, 2.0],
                    help="gmsh mesh sizes of the tetrahedral node sets")
    ap.add_argument("--grids", type=int, nargs="*", default=[8, 12, 16],
                    help="hex grids n x n x n/4 split into tetrahedra")
    args = ap.parse_args()
    OUT = output_dir(args.out)
    main(args.sizes, args.grids)
