"""The 3-D Cook's membrane on MPI ranks: VC PBG Unl (neo-Hooke, Newton on
PETSc CG + GAMG) distributed with :mod:`skfem_pg.distributed`, per-rank
timings, and the difference to the serial run.

The 2-D Cook outline extruded by 10 in z, hexahedral grid of ``--n`` x
``--n`` x ``--nz`` cells (interior nodes distorted by ±0.2 h), clamped at
x = 0, a dead load ``--load`` per unit area in +z on x = 48 (the
thesis' 7.1 setting of demos/cook_3d.py, iso/vol neo-Hooke with
lambda = 100, mu = 40).  Rank 0 then solves the same problem serially
(``skfem_pg.solvers.newton``: sparse direct up to 10k unknowns, AMG-CG
above) and prints
max|u - u_serial| / max|u_serial|.

    python demos/cook_mpi.py [--n 12] [--nz 3] [--load 4] [--no-serial]
    mpirun -n 2 python demos/cook_mpi.py [...]

(as root, Open MPI needs ``--allow-run-as-root``; on two cores
``--oversubscribe`` lets ``-n 2`` start beside other processes.)  Writes
out/cook_mpi_<ranks>.pvtu with a VTU piece per rank (displacements and
the owner rank of each particle; ParaView opens the .pvtu),
out/cook_mpi_<ranks>.png (the partition on the deformed membrane) and,
with ``--json FILE``, the timings that benchmarks/mpi_scaling.py
tabulates.
"""
import json
import os
import resource
import time

import numpy as np
import skfem as fem

import skfem_pg as pg
from skfem_pg import distributed as dist
from skfem_pg import materials as mat
from skfem_pg.formulations import Hyperelastic
from harness import demo_parser, output_dir

MATERIAL = mat.NeoHookeIsoVol.from_lame(100.0, 40.0)
CORNER = (48.0, 60.0, 10.0)


def problem(n, nz, load):
    """Mesh, serial load vector and clamped dofs (on every rank)."""
    mesh = pg.meshing.cook_membrane_3d(n, nz, distortion=0.2, seed=n)
    e = fem.ElementVector(fem.ElementHex1())
    fb = fem.FacetBasis(mesh, e, facets=mesh.boundaries["right"])
    f = fem.LinearForm(lambda v, w: load * v[2]).assemble(fb)
    D = fem.Basis(mesh, e).get_dofs(mesh.boundaries["left"]).all()
    return mesh, f, D


def corner_w(mesh, u):
    k = int(np.argmin(((mesh.p.T - CORNER) ** 2).sum(1)))
    return u[3 * k + 2]


def main():
    ap = demo_parser(__doc__)
    ap.add_argument("--n", type=int, default=12,
                    help="cells per side in the membrane's plane")
    ap.add_argument("--nz", type=int, default=3,
                    help='cells through the thickness')
    ap.add_argument("--load", type=float, default=4.0,
                    help='dead load per unit area in +z on x = 48')
    ap.add_argument("--steps", type=int, default=4,
                    help='initial load steps of the distributed Newton')
    ap.add_argument("--no-serial", action="store_true",
                    help='skip the serial comparison on rank 0')
    ap.add_argument("--options", default="",
                    help="PETSc options for the KSP, e.g. '-ksp_type gmres'")
    ap.add_argument("--fe", action="store_true",
                    help="rank 0 also solves H1 (scikit-fem hexahedra, "
                    "sparse direct) on the same nodes")
    ap.add_argument("--json", default=None,
                    help='write the timings of rank 0 to this JSON file (benchmarks/mpi_scaling.py)')
    args = ap.parse_args()
    if args.quick:
        args.n, args.nz, args.steps = 4, 1, 1
    comm = dist.as_mpi()
    rank, size = comm.rank, comm.size
    t_all = time.perf_counter()
    mesh, f, D = problem(args.n, args.nz, args.load)
    t = {"mesh": time.perf_counter() - t_all}
    t0 = time.perf_counter()
    part = dist.Partition(mesh, comm)
    t["partition"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    basis = part.basis(dim=3)
    t["basis"] = time.perf_counter() - t0
    t["vc"] = basis.timings.get("vc", 0.0)
    model = Hyperelastic(basis, MATERIAL)
    if rank == 0:
        print("3-D Cook, {} x {} x {} hex, {} particles ({} dofs) on {} "
              "rank(s); {}".format(args.n, args.n, args.nz, part.n,
                                   3 * part.n, size, pg.threads.describe()))
    t0 = time.perf_counter()
    u, hist = dist.newton(model, part, f, D=D, steps=args.steps, tol=1e-12,
                          options=args.options, verbose=rank == 0)
    t["newton"] = time.perf_counter() - t0
    t["assemble"] = sum(h["t_assemble"] for h in hist)
    t["ksp"] = sum(h["t_linear"] for h in hist)
    t["total"] = time.perf_counter() - t_all
    its = [len(h["residuals"]) - 1 for h in hist]
    ksp = [k for h in hist for k in h["krylov"]]
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    per_rank = comm.gather(dict(t, owned=len(part.owned), rss_mb=rss,
                                halo=len(part.local) - len(part.owned),
                                families=len(basis.families)), root=0)
    record = None
    if rank == 0:
        print("\nrank  owned  halo  partition  basis (VC)    assemble  "
              "KSP     Newton  total [s]  peak MB")
        for r, p in enumerate(per_rank):
            print("{:4d} {:6d} {:5d} {:10.2f} {:6.2f} ({:4.2f}) {:9.2f} "
                  "{:6.2f} {:8.2f} {:6.2f} {:8.0f}".format(
                      r, p["owned"], p["halo"], p["partition"], p["basis"],
                      p["vc"], p["assemble"], p["ksp"], p["newton"],
                      p["total"], p["rss_mb"]))
        print("Newton: {} steps, iterations {}, KSP iterations {} (mean "
              "{:.1f})".format(len(hist), its, ksp, np.mean(ksp)))
        w = corner_w(mesh, u)
        print("corner z-displacement: {:.6f}".format(w))
        record = dict(ranks=size, n=args.n, nz=args.nz, particles=part.n,
                      dofs=3 * part.n, load=args.load, steps=len(hist),
                      newton_iterations=its, ksp_iterations=ksp, w=w,
                      per_rank=per_rank)
    if rank == 0 and not args.no_serial:
        t0 = time.perf_counter()
        sb = pg.FamilyBasis(mesh, dim=3)
        u_s, hs = pg.solvers.newton(Hyperelastic(sb, MATERIAL), f, D=D,
                                    steps=args.steps, tol=1e-12,
                                    verbose=False)
        ts = time.perf_counter() - t0
        diff = np.abs(u - u_s).max() / np.abs(u_s).max()
        print("serial (rank 0, skfem_pg.solvers.newton, {}): {:.2f} s, {} "
              "steps; max|u - u_serial| / max|u_serial| = {:.2e}".format(
                  "AMG-CG" if hs[0]["krylov"] else "sparse direct", ts,
                  len(hs), diff))
        record.update(serial_seconds=ts, difference=diff)
    if rank == 0 and args.fe:
        t0 = time.perf_counter()
        hb = fem.Basis(mesh, fem.ElementVector(fem.ElementHex1()))
        u_h, hh = pg.solvers.newton(Hyperelastic(hb, MATERIAL), f, D=D,
                                    steps=args.steps, verbose=False)
        tf = time.perf_counter() - t0
        print("H1 on the same nodes (rank 0, {}): {:.2f} s, corner w "
              "{:.6f}".format("AMG-CG" if hh[0]["krylov"] else
                              "sparse direct", tf, corner_w(mesh, u_h)))
        record.update(fe_seconds=tf, fe_w=corner_w(mesh, u_h))
    comm.barrier()
    out = output_dir(args.out) if rank == 0 else None
    name = os.path.join(comm.bcast(out), "cook_mpi_{}".format(size))
    dist.write_pvtu(name + ".pvtu", part, u=u)  # a piece per rank
    if rank == 0:
        plot(part, u, name + ".png")
        print("wrote {0}.pvtu ({1} piece(s)), {0}.png".format(name, size))
        if args.json:
            with open(args.json, "w") as fh:
                json.dump(record, fh, indent=1)


def plot(part, u, filename):
    """The deformed membrane seen from the front (x, z), particles
    coloured by owner rank."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    x = part.particles.x + u.reshape(-1, 3).T
    fig, ax = plt.subplots(figsize=(6, 4))
    sc = ax.scatter(x[0], x[2], c=part.owner, s=6, cmap="coolwarm")
    ax.set_xlabel("x")
    ax.set_ylabel("z (deformed)")
    ax.set_aspect("equal")
    ax.set_title("3-D Cook on {} rank(s): owner of each particle".format(
        part.size))
    if part.size > 1:
        fig.colorbar(sc, ax=ax, label="rank")
    fig.tight_layout()
    fig.savefig(filename, dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    main()
