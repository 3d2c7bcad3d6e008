"""Strong and weak scaling of the distributed PG Newton (demos/cook_mpi.py)
on 1 and 2 MPI ranks, against the serial PG and H1 Newton solves of the
same nodes (``skfem_pg.solvers.newton``, ``solver="auto"``: AMG-CG above
10k unknowns) in the same run.

Each case runs ``mpirun -n R python demos/cook_mpi.py --json ...`` in a
fresh process group (3-D Cook, hexahedral grid, iso/vol neo-Hooke,
``--load``/``--steps``; VC PBG Unl; CG + GAMG).  Strong: the same grid
on 1 and 2 ranks.  Weak: about twice the particles on 2 ranks.  Writes
the table to the ``mpi_scaling`` section of benchmarks/README.md.

    python benchmarks/mpi_scaling.py [--strong 16x4 24x6] [--weak 18x4:24x5]
        [--load 0.5] [--steps 1]

Needs the 'mpi' extra and ``mpirun`` (README, "MPI").
"""
import json
import os
import subprocess
import sys
import tempfile

from harness import (demo_parser, markdown_table, update_results)

HERE = os.path.dirname(os.path.abspath(__file__))
DEMO = os.path.join(HERE, os.pardir, "demos", "cook_mpi.py")
RESULTS = os.path.join(HERE, "README.md")


def mpirun(ranks):
    cmd = ["mpirun", "-n", str(ranks)]
    if hasattr(os, "geteuid") and os.geteuid() == 0:
        cmd += ["--allow-run-as-root"]
    return cmd + ["--oversubscribe"]


def run(ranks, grid, load, steps, serial):
    n, nz = (int(v) for v in grid.split("x"))
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "r.json")
        cmd = mpirun(ranks) + [sys.executable, DEMO, "--n", str(n), "--nz",
                               str(nz), "--load", str(load), "--steps",
                               str(steps), "--json", out, "--out", tmp]
        if serial:
            cmd.append("--fe")
        else:
            cmd.append("--no-serial")
        print("$", " ".join(cmd[len(mpirun(ranks)):]) if ranks == 1 else
              " ".join(cmd), flush=True)
        subprocess.run(cmd, check=True)
        with open(out) as fh:
            return json.load(fh)


def row(kind, r, base=None):
    p0 = r["per_rank"][0]
    t = max(p["total"] - p["mesh"] for p in r["per_rank"])
    cells = [kind, r["ranks"], "{} x {} x {}".format(r["n"], r["n"],
                                                     r["nz"]),
             r["particles"], r["dofs"],
             "{:.2f}".format(max(p["basis"] for p in r["per_rank"])),
             "{:.2f}".format(p0["assemble"]), "{:.2f}".format(p0["ksp"]),
             "{:.2f}".format(t), sum(r["newton_iterations"]),
             "{:.0f}".format(sum(r["ksp_iterations"])
                             / len(r["ksp_iterations"]))]
    cells.append("" if base is None else "{:.2f}".format(base / t))
    cells.append("{:.1f}".format(r["serial_seconds"]) if "serial_seconds"
                 in r else "")
    cells.append("{:.1f}".format(r["fe_seconds"]) if "fe_seconds" in r
                 else "")
    cells.append("{:.1e}".format(r["difference"]) if "difference" in r
                 else "")
    return cells, t


def main():
    ap = demo_parser(__doc__, results=True)
    ap.add_argument("--strong", nargs="+", default=["16x4", "24x6"],
                    help="strong-scaling grids NxNZ (cook_mpi's --n x --nz), each on 1 and 2 ranks")
    ap.add_argument("--weak", nargs="+", default=["18x4:24x5"],
                    help='weak-scaling pairs A:B, grid A on 1 rank and grid B (about twice the particles) on 2')
    ap.add_argument("--load", type=float, default=0.5,
                    help="fraction of cook_mpi's load")
    ap.add_argument("--steps", type=int, default=1,
                    help='initial load steps of the Newton solve')
    args = ap.parse_args()
    rows = []
    for grid in args.strong:
        one = run(1, grid, args.load, args.steps, serial=True)
        two = run(2, grid, args.load, args.steps, serial=False)
        c1, t1 = row("strong", one)
        c2, _ = row("strong", two, base=t1)
        rows += [c1, c2]
    for pair in args.weak:
        g1, g2 = pair.split(":")
        one = run(1, g1, args.load, args.steps, serial=False)
        two = run(2, g2, args.load, args.steps, serial=False)
        c1, t1 = row("weak", one)
        c2, t2 = row("weak", two)
        c2[11] = "efficiency {:.2f}; per Newton iteration {:.2f}".format(
            t1 / t2, t1 / sum(one["newton_iterations"])
            / (t2 / sum(two["newton_iterations"])))
        rows += [c1, c2]
    header = ["scaling", "ranks", "grid", "particles", "dofs", "basis s",
              "assemble s", "KSP s", "total s", "Newton it", "KSP it/solve",
              "speed-up", "serial PG s", "serial H1 s",
              "max diff. to serial PG"]
    table = markdown_table(header, rows)
    print(table)
    text = (
        "3-D Cook (hexahedral grid, distortion 0.2 h), iso/vol neo-Hooke, "
        "load {} in {} step(s), VC PBG Unl on PETSc (CG + GAMG with the "
        "rigid-body near-null space, Newton rtol 1e-8), "
        "`benchmarks/mpi_scaling.py`.  Times are the slowest rank's "
        "(mesh excluded); serial PG and H1 are `skfem_pg.solvers.newton` "
        "(solver 'auto': sparse direct up to 10k unknowns, pyamg AMG-CG "
        "above) on the same nodes, on rank 0 of the 1-rank run; under "
        "mpirun every process, the 1-rank one too, runs its BLAS on one "
        "thread (Open MPI binds it to a core).  Weak: the thinner plate "
        "of the 2-rank grid needs other Newton iterations, so the "
        "efficiency per Newton iteration is given too.\n\n"
        .format(args.load, args.steps) + table)
    update_results(args.results or RESULTS, "mpi_scaling", text)


if __name__ == "__main__":
    main()
