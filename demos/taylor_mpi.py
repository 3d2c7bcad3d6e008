"""The Taylor anvil impact on MPI ranks: explicit central differences with
:func:`skfem_pg.distributed.central_difference`, equal to the serial run
step for step.

The problem of ``demos/taylor.py`` (thesis 7.3.7: a copper rod at 227
m/s on a rigid wall, finite J2 plasticity, the whole rod with ``2n``
elements across the radius).  Every rank builds the families of the
particles it owns (METIS partition of the rod's mesh), integrates its
local particles and exchanges the internal forces of its halo with its
neighbour ranks once per step; energies, the stable step (distributed
Lanczos iterations) and the wall's bookkeeping are reduced over the
ranks.  Rank 0 then runs the same problem serially (unless
``--no-serial``) and prints the steps of both runs and
max|u - u_serial| / max|u_serial|.

Prints per rank the owned and halo particles, the time split (forces,
stable-step estimates, contact, output) and the particle-steps per second
of the run on ranks and of the serial one.  Writes a ``.pvtu`` series
(out/taylor_mpi_<ranks>.pvd, a piece per rank and output: u, v, e_p and
the owner rank; ParaView opens the .pvd) and, with ``--json FILE``, the
numbers that benchmarks/README.md tabulates.

    python demos/taylor_mpi.py [--n 1] [--method "VCPBG U1SIG"] [--t-end 80]
    mpirun -n 2 python demos/taylor_mpi.py [...]

(as root, Open MPI needs ``--allow-run-as-root``; on two cores
``--oversubscribe`` lets ``-n 2`` start beside other processes.)
"""
import json
import os
import resource
import time

import numpy as np

import skfem_pg as pg
from skfem_pg import distributed as dist
from skfem_pg.formulations import model_for
from skfem_pg.io import VTUSeries
from skfem_pg.naming import formulation_of, parse
from skfem_pg.solvers import RigidWall, central_difference, lumped_mass
from harness import demo_parser, output_dir
from taylor import COPPER, METHODS, RHO, ROD, SPEED, T_END

EXPLICIT = [k for k, v in METHODS.items() if v[1] and
            not k.startswith("FEM")]


def initial_velocity(n_particles):
    """-SPEED in x at every particle (serial numbering, 3 dofs each)."""
    v0 = np.zeros((n_particles, 3))
    v0[:, 0] = -SPEED
    return v0.ravel()


def length(mesh, x):
    """The rod's length: the axis node at the far end, displaced."""
    top = int(np.argmin(np.abs(mesh.p[0] - ROD["length"])
                        + np.hypot(mesh.p[1], mesh.p[2])))
    return ROD["length"] + x[3 * top]


def serial_per_particle(part, basis, values):
    """Per-family values of the rank's families as one serial array on
    every rank (a particle without a family: 0)."""
    out = np.zeros(part.n)
    for k, v in part.comm.allgather((part.local[basis.families.masters],
                                     np.asarray(values))):
        out[k] = v
    return out


def main():
    ap = demo_parser(__doc__)
    ap.add_argument("--n", type=int, default=1,
                    help="2n elements across the radius")
    ap.add_argument("--method", default="VCPBG U1SIG", choices=EXPLICIT,
                    help="an explicit PG formulation of Table 7.6")
    ap.add_argument("--t-end", type=float, default=T_END,
                    help="simulated time [µs]")
    ap.add_argument("--no-serial", action="store_true",
                    help="skip the serial run on rank 0")
    ap.add_argument("--json", default=None,
                    help="write rank 0's numbers to this JSON file")
    args = ap.parse_args()
    if args.quick:
        args.n, args.t_end = 1, 2.0
    comm = dist.as_mpi()
    rank, size = comm.rank, comm.size
    solved = METHODS[args.method][0]
    options, _ = parse(solved)
    mesh = pg.meshing.taylor_rod(args.n)
    t0 = time.perf_counter()
    part = dist.Partition(mesh, comm)
    basis = part.basis(dim=3, **options)
    model = model_for(formulation_of(solved), basis, COPPER)
    m = dist.lumped_mass(basis, part, RHO)
    t_setup = time.perf_counter() - t0
    v0 = initial_velocity(part.n)
    if rank == 0:
        print("Taylor rod, {} ({}), {} particles on {} rank(s), {} µs; {}"
              .format(args.method, solved, part.n, size, args.t_end,
                      pg.threads.describe()), flush=True)
    out = comm.bcast(output_dir(args.out) if rank == 0 else None)
    stem = os.path.join(out, "taylor_mpi_{}".format(size))
    series = VTUSeries(stem, suffix="pvtu", collection=rank == 0)

    def output(t, x, v, rec):  # serial vectors on every rank (collective)
        ep = model.plastic_strain()
        series.add(t, lambda fn: dist.write_pvtu(
            fn, part, u=x, v=v,
            e_p=serial_per_particle(part, basis, ep[0])))
        if rank == 0:
            print("  t = {:6.2f} µs  length {:.3f} mm  kinetic {:.4g}"
                  .format(t, length(mesh, x), rec["kinetic"]), flush=True)

    t0 = time.perf_counter()
    tr = dist.central_difference(model, part, m, args.t_end, v0=v0,
                                 wall=RigidWall(0, 0.0), callback=output,
                                 verbose=False)
    seconds = time.perf_counter() - t0
    ep_max = max(comm.allgather(model.plastic_strain()[1]))
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    per_rank = comm.gather(dict(
        owned=len(part.owned), halo=len(part.local) - len(part.owned),
        setup=t_setup, rss_mb=rss,
        **{k: v for k, v in tr.times.items()}), root=0)
    if rank != 0:
        return
    print("\nrank  owned  halo  setup [s]  force  estimate  contact  "
          "output  total [s]  messages  peak MB")
    for r, p in enumerate(per_rank):
        print("{:4d} {:6d} {:5d} {:10.2f} {:6.2f} {:9.2f} {:8.2f} {:7.2f} "
              "{:10.2f} {:9d} {:8.0f}".format(
                  r, p["owned"], p["halo"], p["setup"], p["force"],
                  p["estimate"], p["contact"], p["output"], p["total"],
                  p["messages"], p["rss_mb"]))
    rate = part.n * tr.steps / tr.times["total"]
    print("on {} rank(s): {} steps, length {:.3f} mm, max e_p {:.3f}, "
          "energy error {:.1e}; {:.0f} particle-steps/s".format(
              size, tr.steps, length(mesh, tr.x), ep_max,
              max(abs(h["relative_error"]) for h in tr.history), rate))
    record = dict(ranks=size, n=args.n, method=args.method,
                  particles=part.n, t_end=args.t_end, steps=tr.steps,
                  length=length(mesh, tr.x), ep=ep_max, seconds=seconds,
                  rate=rate, per_rank=per_rank)
    if not args.no_serial:
        sb = pg.FamilyBasis(mesh, dim=3, **options)
        t0 = time.perf_counter()
        ts = central_difference(model_for(formulation_of(solved), sb,
                                          COPPER),
                                lumped_mass(sb, RHO), args.t_end, v0=v0,
                                wall=RigidWall(0, 0.0), verbose=False)
        srate = part.n * ts.steps / ts.times["total"]
        diff = np.abs(tr.x - ts.x).max() / np.abs(ts.x).max()
        print("serial (rank 0, skfem_pg.solvers.central_difference): {} "
              "steps, {:.0f} particle-steps/s (time split {}); "
              "max|u - u_serial| / max|u_serial| = {:.2e}".format(
                  ts.steps, srate,
                  {k: round(v, 2) for k, v in ts.times.items()}, diff))
        record.update(serial_steps=ts.steps, serial_rate=srate,
                      serial_times=ts.times, difference=diff)
    print("wrote {}.pvd ({} outputs, a piece per rank each)".format(
        stem, len(series.entries)))
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(record, fh, indent=1)


if __name__ == "__main__":
    main()
