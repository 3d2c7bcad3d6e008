"""Preprocessing, assembly and solve: VC PBG Unl against scikit-fem Q1 on the
same ±0.3h distorted quad node sets, 10k to 250k particles, in one run.

Reports per size: PG preprocessing split (particles, families, gradients,
bond, VC), PG assembly (fast path, first call with the sparsity pattern and
repeated), scikit-fem Q1 assembly and solve, and the ratios
PG-assembly / Q1-assembly and preprocessing / Q1-solve.  Absolute times
drift between machines; the ratios are the result.

    python benchmarks/assembly_scaling.py [--sizes 100 200 300 400 500]

(``--sizes`` are elements per side: 101² ≈ 10k ... 501² ≈ 250k particles.)
"""
import json
import os
import time

import numpy as np
import skfem as fem

import skfem_pg as pg
from harness import (demo_parser, markdown_table, output_dir, update_results)
from skfem_pg.materials import lame
from skfem_pg.formulations import linear_elasticity

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)),
                       "README.md")  # the measured tables, written here
OUT = output_dir(create=False)  # --out, $SKFEM_PG_OUT or ./out
FORM = linear_elasticity(*lame(1.0, 0.3))
#: one direct solver for Q1 and PG alike (RCM + SuperLU, skfem_pg.solvers)
SOLVER = pg.solvers.direct


def clock(fn, *args, **kw):
    t0 = time.perf_counter()
    out = fn(*args, **kw)
    return out, time.perf_counter() - t0


def amg_solve(K, f, D, doflocs, candidates=0):
    """CG + pyamg smoothed aggregation with rigid body modes (and, for PG,
    ``candidates`` smoothed random near-null-space vectors)."""
    I = np.setdiff1d(np.arange(K.shape[0]), D)
    x = np.zeros(K.shape[0])
    x[I] = pg.solvers.linear_solver("amg", doflocs[:, I], tol=1e-10,
                                    candidates=candidates)(
        K[I][:, I].tocsr(), f[I])
    return x


def run(n, generic=False, pg_solve=False, amg=False, dim=2):
    Mesh, E = ((fem.MeshQuad, fem.ElementQuad1) if dim == 2
               else (fem.MeshHex, fem.ElementHex1))
    # ±0.3h in 2-D; in 3-D ±0.2h: ±0.3h folds hexahedra (the particle
    # checks refuse the mesh at n = 30)
    mesh = pg.meshing.distort(
        Mesh.init_tensor(*[np.linspace(0, 1, n + 1)] * dim),
        0.3 if dim == 2 else 0.2, seed=n)
    r = {"n": n, "particles": int(mesh.nvertices)}
    # --- scikit-fem Q1 / H1 --------------------------------------------
    q1, r["q1_basis"] = clock(fem.Basis, mesh, fem.ElementVector(E()))
    Kq, r["q1_assemble"] = clock(FORM.assemble, q1)
    _, r["q1_fast_first"] = clock(pg.assemble, FORM, q1)
    Kf, r["q1_fast"] = clock(pg.assemble, FORM, q1)
    r["fast_vs_generic_fe"] = float(abs(Kf - Kq).max() / abs(Kq).max())
    f = q1.zeros()
    f[q1.get_dofs(lambda x: np.isclose(x[0], 1)).nodal["u^2"]] = 1.0 / n
    D = q1.get_dofs(lambda x: np.isclose(x[0], 0))
    Dflat = D.flatten()
    if dim == 2:
        uq, r["q1_solve"] = clock(
            lambda: fem.solve(*fem.condense(Kq, f, D=D), solver=SOLVER))
    else:  # 3-D: AMG-CG (direct solves of PG fill beyond reach)
        uq, r["q1_solve"] = clock(amg_solve, Kq, f, Dflat, q1.doflocs)
    r["q1_nnz"] = int(Kq.nnz)
    if amg and dim == 2:
        _, r["q1_solve_amg"] = clock(amg_solve, Kq, f, Dflat, q1.doflocs)
    # --- PG ------------------------------------------------------------
    t0 = time.perf_counter()
    particles, r["pg_particles"] = clock(pg.Particles.from_mesh, mesh)
    basis = pg.FamilyBasis(particles, dim=dim)
    r["pg_preprocess"] = time.perf_counter() - t0
    for k, v in basis.timings.items():
        r["pg_" + k] = v
    r["vc_residual_after"] = basis.vc_report.residual_after
    K, r["pg_assemble_first"] = clock(pg.assemble, FORM, basis)
    K, r["pg_assemble"] = clock(pg.assemble, FORM, basis)
    r["pg_nnz"] = int(K.nnz)
    if generic:
        basis._basis = None
        Kg, r["pg_assemble_generic"] = clock(FORM.assemble, basis)
        r["generic_vs_fast"] = float(abs(Kg - K).max() / abs(K).max())
    if pg_solve and dim == 2:
        u, r["pg_solve"] = clock(
            lambda: fem.solve(*fem.condense(K, f, D=D), solver=SOLVER))
        r["tip_pg_vs_q1"] = float(u[-1] / uq[-1])
    elif pg_solve:
        u, r["pg_solve"] = clock(amg_solve, K, f, Dflat, basis.doflocs,
                                 pg.solvers.PG_CANDIDATES)
        r["tip_pg_vs_q1"] = float(u[-1] / uq[-1])
    if amg and dim == 2:
        _, r["pg_solve_amg"] = clock(amg_solve, K, f, Dflat, basis.doflocs)
    r["ratio_asm"] = r["pg_assemble"] / r["q1_assemble"]
    r["ratio_asm_fast"] = r["pg_assemble"] / r["q1_fast"]
    r["ratio_asm_first"] = r["pg_assemble_first"] / r["q1_assemble"]
    r["ratio_pre_q1solve"] = r["pg_preprocess"] / r["q1_solve"]
    return r


def main(sizes, amg=False, dim=2):
    print(pg.threads.describe())
    rows = []
    hdr = ("{:>8s} {:>8s} {:>8s} {:>8s} {:>8s} {:>8s} {:>8s} {:>8s} {:>8s}"
           " {:>8s} {:>8s} {:>9s} {:>9s}")
    print(hdr.format("np", "pre[s]", "fam", "grad", "bond", "vc", "asm1st",
                     "asm", "Q1asm", "Q1solve", "PGsolve", "asm/Q1",
                     "pre/Q1slv"))
    for n in sizes:
        r = run(n, generic=n <= (100 if dim == 2 else 0), pg_solve=True,
                amg=amg, dim=dim)
        rows.append(r)
        print("{:8d} {:8.2f} {:8.2f} {:8.2f} {:8.2f} {:8.2f} {:8.2f} {:8.2f} "
              "{:8.2f} {:8.2f} {:>8s} {:9.2f} {:9.2f}".format(
                  r["particles"], r["pg_preprocess"], r["pg_families"],
                  r["pg_gradients"], r["pg_bond"], r["pg_vc"],
                  r["pg_assemble_first"], r["pg_assemble"],
                  r["q1_assemble"], r["q1_solve"],
                  "{:.2f}".format(r["pg_solve"]) if "pg_solve" in r else "-",
                  r["ratio_asm"], r["ratio_pre_q1solve"]), flush=True)
    for a, b in zip(rows, rows[1:]):
        g = np.log(b["particles"] / a["particles"])
        print("growth exponent {:6d} -> {:6d}: preprocess {:.2f}, VC {:.2f},"
              " PG asm {:.2f}, Q1 asm {:.2f}, Q1 solve {:.2f}".format(
                  a["particles"], b["particles"],
                  np.log(b["pg_preprocess"] / a["pg_preprocess"]) / g,
                  np.log(b["pg_vc"] / a["pg_vc"]) / g,
                  np.log(b["pg_assemble"] / a["pg_assemble"]) / g,
                  np.log(b["q1_assemble"] / a["q1_assemble"]) / g,
                  np.log(b["q1_solve"] / a["q1_solve"]) / g))
    for r in rows:
        if amg:
            print("{:8d} particles, AMG-CG (rigid body modes): Q1 {:.2f} s, "
                  "PG {:.2f} s, PG/Q1 {:.2f} (direct: {:.2f})".format(
                      r["particles"], r["q1_solve_amg"], r["pg_solve_amg"],
                      r["pg_solve_amg"] / r["q1_solve_amg"],
                      r["pg_solve"] / r["q1_solve"]))
    if rows and "pg_assemble_generic" in rows[0]:
        r = rows[0]
        print("generic scikit-fem path on PG at {} particles: {:.2f} s "
              "({:.1f}x the fast path; max rel. difference {:.1e})".format(
                  r["particles"], r["pg_assemble_generic"],
                  r["pg_assemble_generic"] / r["pg_assemble"],
                  r["generic_vs_fast"]))
    fe = "Q1" if dim == 2 else "H1"
    table = [[r["particles"], "{:.2f}".format(r["pg_preprocess"]),
              "{:.2f}".format(r["pg_vc"]), "{:.2f}".format(r["ratio_asm"]),
              "{:.2f}".format(r["ratio_asm_fast"]),
              "{:.2f}".format(r["ratio_pre_q1solve"]),
              "{:.1f}".format(r["pg_solve"] / r["q1_solve"])
              if "pg_solve" in r else "-"] for r in rows]
    growth = ""
    if len(rows) > 1:
        a, b = rows[0], rows[-1]
        g = np.log(b["particles"] / a["particles"])
        growth = ("\n\nGrowth exponents {:,} -> {:,} particles: PG "
                  "preprocessing {:.2f} (VC {:.2f}), PG assembly {:.2f}, "
                  "{} assembly (fast path) {:.2f}.".format(
                      a["particles"], b["particles"],
                      np.log(b["pg_preprocess"] / a["pg_preprocess"]) / g,
                      np.log(b["pg_vc"] / a["pg_vc"]) / g,
                      np.log(b["pg_assemble"] / a["pg_assemble"]) / g, fe,
                      np.log(b["q1_fast"] / a["q1_fast"]) / g))
    print("updated", update_results(
        RESULTS, "assembly_scaling" + ("" if dim == 2 else "_3d"),
        "`python benchmarks/assembly_scaling.py --dim {d} --sizes {s}`: VC "
        "PBG Unl and {fe}, linear elasticity, ±{dist}h distorted {cells}; "
        "{fe} assembled by scikit-fem's generic path and by the package's "
        "fast path (both denominators); solves {solve} ({t}).\n\n".format(
            d=dim, s=" ".join(str(n) for n in sizes), fe=fe,
            dist="0.3" if dim == 2 else "0.2",
            cells="quads" if dim == 2 else "hexahedra",
            solve="direct (`pg.solvers.direct`)" if dim == 2 else
            "AMG-CG (`pg.solvers.linear_solver('amg')`, PG with "
            "near-null-space candidates)", t=pg.threads.describe())
        + markdown_table(["particles", "PG preprocess [s]", "of which VC "
                          "[s]", "PG asm / {} asm (scikit-fem)".format(fe),
                          "PG asm / {} asm (fast path)".format(fe),
                          "preprocess / {} solve".format(fe),
                          "PG solve / {} solve".format(fe)], table)
        + growth))
    os.makedirs(OUT, exist_ok=True)
    with open(os.path.join(OUT, "assembly_scaling{}.json".format(
            "" if dim == 2 else "_3d")), "w") as fh:
        json.dump(rows, fh, indent=1)
    print("wrote " + OUT + "/assembly_scaling.json")
    return rows


if __name__ == "__main__":
    ap = demo_parser(__doc__)
    ap.add_argument("--sizes", type=int, nargs="+", default=None,
                    help="elements per side (default 100 ... 500 in 2-D, "
                    "20 30 40 in 3-D)")
    ap.add_argument("--dim", type=int, default=2, choices=(2, 3),
                    help='2: quadrilaterals against Q1; 3: hexahedra against H1')
    ap.add_argument("--amg", action="store_true",
                    help="also time CG + smoothed aggregation solves")
    a = ap.parse_args()
    OUT = output_dir(a.out)
    main(a.sizes or ([100, 200, 300, 400, 500] if a.dim == 2
                     else [20, 30, 40]), a.amg, a.dim)
