"""Strong and weak scaling of explicit central differences on 1 and 2 MPI
ranks (``skfem_pg.distributed.central_difference``), with the serial
driver (``skfem_pg.solvers.central_difference``) on the same particles in
the 1-rank run.

The problem: a square copper bar (the Taylor rod's material, thesis
7.3.7: finite J2 plasticity, VCPBG V3m U1SIG) of ``a x a x L`` mm on a
hexahedral grid of ``n x n x nz`` cells, thrown at 227 m/s at a rigid
wall, for ``--t-end`` µs; the stable step from the distributed Lanczos
estimate.  Strong: the same grid on 1 and 2 ranks.  Weak: the bar twice
as long (``2 nz``, about twice the particles) on 2 ranks — the same
spacing, so the same steps.  Every case runs ``mpirun -n R`` in a fresh
process; rank times are the slowest rank's.  Writes the table to the
``explicit_scaling`` section of benchmarks/README.md.

    python benchmarks/explicit_scaling.py [--grids 8x24 12x36]
        [--t-end 20]

Needs the 'mpi' extra and ``mpirun`` (README, "MPI").
"""
import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time

import numpy as np

from harness import demo_parser, markdown_table, update_results
from mpi_scaling import mpirun

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS = os.path.join(HERE, "README.md")
METHOD = "VCPBG V3m U1SIG"
SIDE = 6.4  # mm, the Taylor rod's diameter


def bar(n, nz):
    """The hexahedral bar of ``n x n x nz`` cubes of side ``SIDE / n``,
    its axis along x, the end x = 0 on the wall."""
    import skfem as fem
    h = SIDE / n
    return fem.MeshHex.init_tensor(np.linspace(0, nz * h, nz + 1),
                                   np.linspace(-SIDE / 2, SIDE / 2, n + 1),
                                   np.linspace(-SIDE / 2, SIDE / 2, n + 1))


def worker(n, nz, t_end, out, serial):
    """One run on the ranks of the world communicator (and, with
    ``serial``, the serial driver on rank 0 after it); rank 0 writes the
    numbers to ``out``."""
    sys.path.insert(0, os.path.join(HERE, os.pardir, "demos"))
    import skfem_pg as pg
    from skfem_pg import distributed as dist
    from skfem_pg.formulations import model_for
    from skfem_pg.naming import formulation_of, parse
    from skfem_pg.solvers import RigidWall
    from taylor import COPPER, RHO, SPEED
    comm = dist.as_mpi()
    options, _ = parse(METHOD)
    kind = formulation_of(METHOD)
    mesh = bar(n, nz)
    t0 = time.perf_counter()
    part = dist.Partition(mesh, comm)
    basis = part.basis(dim=3, **options)
    model = model_for(kind, basis, COPPER)
    m = dist.lumped_mass(basis, part, RHO)
    setup = time.perf_counter() - t0
    v0 = np.zeros((part.n, 3))
    v0[:, 0] = -SPEED
    v0 = v0.ravel()
    tr = dist.central_difference(model, part, m, t_end, v0=v0,
                                 wall=RigidWall(0, 0.0), verbose=False)
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    per_rank = comm.gather(dict(owned=len(part.owned),
                                halo=len(part.local) - len(part.owned),
                                setup=setup, rss_mb=rss, **tr.times),
                           root=0)
    if comm.rank != 0:
        return
    record = dict(ranks=comm.size, n=n, nz=nz, particles=part.n,
                  steps=tr.steps, t_end=t_end, per_rank=per_rank)
    if serial:
        sb = pg.FamilyBasis(mesh, dim=3, **options)
        ts = pg.central_difference(model_for(kind, sb, COPPER),
                                   pg.lumped_mass(sb, RHO), t_end, v0=v0,
                                   wall=RigidWall(0, 0.0), verbose=False)
        record.update(serial_steps=ts.steps, serial_times=ts.times,
                      difference=float(np.abs(tr.x - ts.x).max()
                                       / np.abs(ts.x).max()))
    with open(out, "w") as fh:
        json.dump(record, fh, indent=1)


def run(ranks, n, nz, t_end, serial):
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "r.json")
        cmd = mpirun(ranks) + [sys.executable, os.path.abspath(__file__),
                               "--worker", "{}x{}".format(n, nz),
                               "--t-end", str(t_end), "--json", out]
        if serial:
            cmd.append("--serial")
        print("$", " ".join(cmd), flush=True)
        env = dict(os.environ, OMP_NUM_THREADS="1")
        subprocess.run(cmd, check=True, env=env)
        with open(out) as fh:
            return json.load(fh)


def row(kind, r, base=None):
    """A table row and the run's time (the slowest rank's)."""
    ranks = r["per_rank"]
    t = max(p["total"] for p in ranks)
    est = max(p["estimate"] for p in ranks)
    us = 1e6 * t / (r["steps"] * r["particles"])
    cells = [kind, r["ranks"], "{} x {} x {}".format(r["n"], r["n"],
                                                     r["nz"]),
             r["particles"], r["steps"], "{:.1f}".format(t),
             "{:.0f} %".format(100 * est / t), "{:.2f}".format(us),
             "{:.0f}".format(max(p["rss_mb"] for p in ranks)),
             "" if base is None else base(t, r)]
    if "serial_times" in r:
        ts = r["serial_times"]["total"]
        cells += ["{:.1f} ({} steps)".format(ts, r["serial_steps"]),
                  "{:.1e}".format(r["difference"])]
    else:
        cells += ["", ""]
    return cells, t


def weak_efficiency(one, t1, two, t2):
    """The weak-scaling efficiency per step and particle: the 1-rank run's
    wall time per particle-step over twice the 2-rank run's (1: two ranks
    do twice the particle-steps in the same time)."""
    per = [t / (r["steps"] * r["particles"]) for r, t in ((one, t1),
                                                          (two, t2))]
    return per[0] / (two["ranks"] * per[1])


def main():
    ap = demo_parser(__doc__, results=True)
    ap.add_argument("--grids", nargs="+", default=["8x24", "12x36"],
                    help="grids NxNZ: strong on 1 and 2 ranks; weak: NxNZ "
                         "on 1 rank against Nx(2NZ) on 2")
    ap.add_argument("--t-end", type=float, default=20.0,
                    help="simulated time [µs]")
    ap.add_argument("--worker", default=None, help=argparse.SUPPRESS)
    ap.add_argument("--serial", action="store_true",
                    help="(worker) also the serial driver on rank 0")
    ap.add_argument("--json", default=None, help="(worker) output file")
    args = ap.parse_args()
    if args.worker:
        n, nz = (int(v) for v in args.worker.split("x"))
        return worker(n, nz, args.t_end, args.json, args.serial)
    if args.quick:
        args.grids, args.t_end = ["4x12"], 2.0
    rows = []
    for grid in args.grids:
        n, nz = (int(v) for v in grid.split("x"))
        one = run(1, n, nz, args.t_end, serial=True)
        two = run(2, n, nz, args.t_end, serial=False)
        wide = run(2, n, 2 * nz, args.t_end, serial=False)
        c1, t1 = row("strong / weak base", one)
        c2, _ = row("strong", two, lambda t, r: "speed-up {:.2f}".format(
            t1 / t))
        c3, _ = row("weak", wide, lambda t, r: "efficiency {:.2f} ({} / {} "
                    "steps); per step and particle {:.2f}".format(
                        t1 / t, r["steps"], one["steps"],
                        weak_efficiency(one, t1, r, t)))
        rows += [c1, c2, c3]
    header = ["scaling", "ranks", "grid", "particles", "steps", "total s",
              "estimate share", "µs per particle-step", "peak MB per rank",
              "against 1 rank", "serial driver s", "max diff. to serial"]
    table = markdown_table(header, rows)
    print(table)
    text = (
        "Explicit central differences on MPI ranks, "
        "`benchmarks/explicit_scaling.py`: a {0} mm square copper bar "
        "(the Taylor rod's material and speed, {1}) of hexahedral cubes "
        "thrown at a rigid wall for {2} µs; the stable step by distributed "
        "Lanczos iterations.  Times are the slowest rank's (setup "
        "excluded); under mpirun every process runs its BLAS on one "
        "thread.  Strong: the same bar on 2 ranks.  Weak: the bar twice "
        "as long (about twice the particles, the same spacing) on 2 "
        "ranks; it takes more steps (its stable-step estimates differ), so "
        "the efficiency is given per step and particle too.  The serial driver (`skfem_pg.solvers.central_difference`)"
        " ran on rank 0 of the 1-rank run.\n\n".format(SIDE, METHOD,
                                                          args.t_end)
        + table)
    if not args.quick:
        update_results(args.results or RESULTS, "explicit_scaling", text)


if __name__ == "__main__":
    main()
