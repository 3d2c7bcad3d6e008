"""3-D scale run: PG (the default on tetrahedra, VC PBG Unl kNN) linear
elasticity on gmsh tetrahedra of the unit cube, from mesh to solution, with
peak memory, against O1 on the same nodes.

The cube is clamped at x = 0 and pulled by a uniform traction in +y on
x = 1 (E = 1, nu = 0.3); each size runs in a fresh process so that its peak
resident memory is its own.  Reported per size: gmsh meshing, particles
(scikit-fem mesh entities, volumes, checks), the PG preprocessing split
(families, gradients, bond, VC), PG and O1 assembly, the AMG-CG solves
(``skfem_pg.solvers.linear_solver("amg")``), the mean y-displacement of the
loaded face for both, and the peak resident memory after the PG basis,
after its assembly and condensation, after its solve, and of the whole
run (O1 included).  The preprocessing growth exponent is fitted between
the smallest and the largest size.

    python benchmarks/scale_3d.py [--sizes 0.05 0.035 0.025 0.02]
"""
import json
import os
import resource
import subprocess
import sys
import time

import numpy as np

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)),
                       "README.md")


def clock(fn, *args, **kw):
    t0 = time.perf_counter()
    out = fn(*args, **kw)
    return out, time.perf_counter() - t0


def one(size):
    """Everything for one mesh size; returns a dict (run in a child)."""
    import skfem as fem
    import skfem_pg as pg
    from skfem_pg.materials import lame
    from skfem_pg.formulations import linear_elasticity
    from skfem_pg.solvers import linear_solver
    r = {"size": size}
    mesh, r["mesh"] = clock(pg.meshing.from_geo,
                            pg.meshing.geo_path("cube.geo"), size=size)
    r["particles_n"] = int(mesh.nvertices)
    print("  {} particles".format(mesh.nvertices), flush=True)
    particles, r["particles"] = clock(pg.Particles.from_mesh, mesh)
    basis, r["basis"] = clock(pg.FamilyBasis, particles, dim=3)
    r["peak_basis"] = peak_gb()
    r.update({"pg_" + k: v for k, v in basis.timings.items()})
    r["vc_solver"] = basis.vc_report.solver
    r["vc_residual"] = basis.vc_report.residual_after
    print("  PG basis {:.1f} s {}".format(r["basis"], {
        k: round(v, 2) for k, v in basis.timings.items()}), flush=True)
    form = linear_elasticity(*lame(1.0, 0.3))
    D = basis.get_dofs(nodes=lambda x: np.isclose(x[0], 0.0))
    o1 = fem.Basis(mesh, fem.ElementVector(fem.ElementTetP1()))
    facets = mesh.facets_satisfying(lambda x: np.isclose(x[0], 1.0),
                                    boundaries_only=True)
    loads = {"o1": fem.LinearForm(lambda v, w: v[1]).assemble(
        fem.FacetBasis(mesh, o1.elem, facets=facets)),
        "pg": pg.loads.traction(basis, facets, [0.0, 1.0, 0.0])}
    right = np.nonzero(np.isclose(mesh.p[0], 1.0))[0]
    for name, B in (("pg", basis), ("o1", o1)):  # PG first: its peaks
        K, r[name + "_assemble"] = clock(pg.assemble, form, B)
        r[name + "_nnz"] = int(K.nnz)
        I = np.setdiff1d(np.arange(B.N), D)
        # one solve: no extra candidates (their setup pays only when a
        # Newton run reuses the hierarchy, benchmarks/solvers_3d.py)
        lin = linear_solver("amg", B.doflocs[:, I], components=I % 3)
        A = pg.solvers.submatrix(K, I)
        del K
        r[name + "_peak_assembly"] = peak_gb()
        x, r[name + "_solve"] = clock(lin, A, loads[name][I])
        del A
        r[name + "_peak_solve"] = peak_gb()
        r[name + "_cg"] = lin.amg.stats["iterations"][-1]
        u = np.zeros(B.N)
        u[I] = x
        r[name + "_uy"] = float(u[3 * right + 1].mean())
        print("  {} assemble {:.1f} s, solve {:.1f} s ({} CG its), "
              "mean u_y {:.6f}".format(name, r[name + "_assemble"],
                                       r[name + "_solve"], r[name + "_cg"],
                                       r[name + "_uy"]), flush=True)
    r["peak_gb"] = peak_gb()
    return r


def peak_gb():
    """The process' peak resident memory so far [GB]."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e6


def main():
    from harness import (demo_parser, markdown_table, update_results)
    import skfem_pg as pg
    p = demo_parser(__doc__)
    p.add_argument("--sizes", type=float, nargs="*",
                   default=[0.05, 0.035, 0.025, 0.02],
                    help='gmsh element sizes of the tetrahedral node sets, one process each')
    p.add_argument("--one", type=float, help=argparse_hide())
    args = p.parse_args()
    if args.one is not None:
        print("RESULT " + json.dumps(one(args.one)), flush=True)
        return
    print(pg.threads.describe())
    rows = []
    for s in args.sizes:
        print("mesh size {}".format(s), flush=True)
        proc = subprocess.run([sys.executable, __file__, "--one", str(s)],
                              stdout=subprocess.PIPE, text=True)
        out = [line for line in proc.stdout.splitlines()]
        for line in out:
            if not line.startswith("RESULT "):
                print(line)
        res = [json.loads(line[7:]) for line in out
               if line.startswith("RESULT ")]
        if not res:
            print("  failed (exit code {})".format(proc.returncode))
            break
        rows.append(res[0])
    table = markdown_table(
        ["particles", "mesh [s]", "particles [s]", "PG preprocess [s]",
         "gradients", "bond", "VC", "PG asm / O1 asm", "PG solve [s]",
         "O1 solve [s]", "CG its PG / O1", "u_y PG / O1",
         "peak after PG basis / assembly / solve [GB]", "peak [GB]"],
        [["{:,}".format(r["particles_n"]), "{:.1f}".format(r["mesh"]),
          "{:.1f}".format(r["particles"]), "{:.1f}".format(r["basis"]),
          "{:.1f}".format(r["pg_gradients"]), "{:.1f}".format(r["pg_bond"]),
          "{:.1f}".format(r["pg_vc"]),
          "{:.2f}".format(r["pg_assemble"] / r["o1_assemble"]),
          "{:.1f}".format(r["pg_solve"]), "{:.1f}".format(r["o1_solve"]),
          "{} / {}".format(r["pg_cg"], r["o1_cg"]),
          "{:.4f}".format(r["pg_uy"] / r["o1_uy"]),
          "{:.1f} / {:.1f} / {:.1f}".format(
              r["peak_basis"], r["pg_peak_assembly"], r["pg_peak_solve"]),
          "{:.1f}".format(r["peak_gb"])] for r in rows])
    text = ("`python benchmarks/scale_3d.py --sizes {}` (one process per "
            "size; {}).\n\n{}\n".format(
                " ".join(str(s) for s in args.sizes), pg.threads.describe(),
                table))
    if len(rows) > 1:
        a, b = rows[0], rows[-1]
        ratio = np.log(b["particles_n"] / a["particles_n"])
        text += ("\nGrowth exponents from {:,} to {:,} particles: PG "
                 "preprocessing {:.2f}, of which VC {:.2f}; PG solve {:.2f}, "
                 "O1 solve {:.2f}.\n".format(
                     a["particles_n"], b["particles_n"],
                     np.log(b["basis"] / a["basis"]) / ratio,
                     np.log(b["pg_vc"] / a["pg_vc"]) / ratio,
                     np.log(b["pg_solve"] / a["pg_solve"]) / ratio,
                     np.log(b["o1_solve"] / a["o1_solve"]) / ratio))
    print(text)
    print("updated", update_results(RESULTS, "scale_3d", text))


def argparse_hide():
    import argparse
    return argparse.SUPPRESS


if __name__ == "__main__":
    main()
