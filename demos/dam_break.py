"""The dam break (thesis 8.2) against Martin & Moyce's experiment (1952):
a column of water a = 5 cm wide and 2a high collapses along a dry floor.

Water (rho = 1e3 kg/m^3, K = 2.08 GPa, eta = 1e-3 Pa s,
:class:`~skfem_pg.materials.NewtonianFluid`) on PG VCBCPBG V5m UnlP0 with
the local VC correction, wetted walls at x = 0 and y = 0 (frictionless,
the water slides along them and does not lift off: ``RigidWall(...,
release=False)``).  Two frames on the same particles:

* total Lagrangian (the thesis' run, Newmark's trapezoidal rule): the
  families are the first ones; the surge shears them until a family
  inverts (J <= 0);
* re-neighboured (:func:`skfem_pg.solvers.free_surface_flow`,
  :class:`~skfem_pg.formulations.UpdatedLagrangeFluid`): the particles
  are triangulated again (an alpha shape) when their cells wear out,
  particles that crowd at the stagnation corner are merged, the
  velocities are given to the masses lumped on the new cells with their
  momentum and energy, Newmark's rule damps what the step does not
  resolve (``FLOW_CONTROLS``, gamma = 0.55), and the run would stop if it
  created more than 5 % of the energy scale.

Prints the surge front Z = z/a (the furthest particle of the alpha shape)
at T = t sqrt(2g/a) = 1, 2, 3, 4 beside the experiment's, where each run
ended and its largest energy gain; writes out/dam_break.png (the front
against T, the particles at the end) and the re-neighboured run as a VTU
series out/dam_break.pvd (the alpha shape's triangles, velocity, mass).

    python demos/dam_break.py [--n 16] [--perturb 0.3]
"""
import os
import time

import meshio
import numpy as np
import skfem as fem

import skfem_pg as pg
from skfem_pg.discretization.retriangulation import (alpha_shape,
                                                      attached)
from skfem_pg.formulations import model_for
from skfem_pg.io import VTUSeries
from skfem_pg.materials import NewtonianFluid
from skfem_pg.solvers import DynamicsError, RigidWall, free_surface_flow
from harness import demo_parser, output_dir

RHO, K, ETA, A, G = 1e3, 2.08e9, 1e-3, 0.05, 9.81
SCALE = np.sqrt(2 * G / A)  # T = t SCALE
PG = "VCBCPBG V5m UnlP0"
#: (T, Z) of Martin & Moyce's Fig. 3, n^2 = 2, a = 2.25 in (as digitised
#: in PySPH's db_exp_data.py)
MARTIN_MOYCE = np.array([
    [0.832, 1.217], [1.219, 1.474], [1.997, 2.292], [2.547, 2.995],
    [3.345, 4.134], [4.034, 4.944], [4.418, 5.881], [5.091, 6.980]])
#: the spread between experiments: Martin & Moyce's a = 1.125 in column
#: and Koshizuka & Oka (1996), as digitised in the same file
OTHER_EXPERIMENTS = {
    "Martin & Moyce, a = 1.125 in": np.array([
        [0.849, 1.245], [1.212, 1.443], [1.602, 1.884], [2.283, 2.689],
        [2.950, 3.728], [3.598, 4.528], [3.905, 4.999], [4.592, 5.841]]),
    "Koshizuka & Oka 1996": np.array([
        [0.381, 1.111], [0.769, 1.252], [1.153, 1.505], [1.537, 1.892],
        [1.935, 2.241], [2.323, 2.615], [2.719, 3.003], [3.096, 3.624]])}


def column(n, perturb):
    """The column on n x 2n cells, its interior nodes moved by up to
    ``perturb`` spacings (then triangles)."""
    axes = (np.linspace(0, A, n + 1), np.linspace(0, 2 * A, 2 * n + 1))
    if perturb == 0:
        return fem.MeshQuad.init_tensor(*axes)
    mesh = fem.MeshTri.init_tensor(*axes)
    p = mesh.p.copy()
    inner = np.all((p > 1e-12) & (p < np.array([[A], [2 * A]]) - 1e-12),
                   axis=0)
    p[:, inner] += perturb * A / n * np.random.default_rng(1).uniform(
        -1, 1, (2, inner.sum()))
    return fem.MeshTri(p, mesh.t)


def front(x, m):
    """The furthest particle of the alpha shape (a drop ahead of the
    surge does not count), over a."""
    return x[0, attached(x, np.sqrt(m / RHO))].max() / A


def against_experiment(T, Z, times=(1.0, 2.0, 3.0, 4.0)):
    """Table cells of a front ``Z(T)`` at ``times``: its value and its
    signed error against Martin & Moyce (``—`` past the run's end)."""
    cells = []
    for Tq in times:
        if Tq > T[-1] + 1e-9:
            cells.append("—")
            continue
        z = np.interp(Tq, T, Z)
        cells.append("{:.2f} ({:+.0f} %)".format(
            z, 100 * (z / np.interp(Tq, *MARTIN_MOYCE.T) - 1)))
    return cells


def energy(x, v, m):
    return 0.5 * np.sum(m * (v * v).sum(axis=0)) + G * np.sum(m * x[1])


def reneighboured(mesh, t_end, dt, series):
    """``(T, Z, E, last (x, v), ended, merged, seconds)``."""
    rows, last = [], []

    def output(t, x, v, m):
        rows.append((t * SCALE, front(x, m), energy(x, v, m)))
        last[:] = [x, v]
        fmesh, kept = alpha_shape(x, np.sqrt(m / RHO), 1.2)
        cells = [("triangle", fmesh.t[:, kept].T),
                 ("vertex", np.arange(x.shape[1])[:, None])]
        points = np.column_stack([x.T, np.zeros(x.shape[1])])
        data = {"v": np.column_stack([v.T, np.zeros(x.shape[1])]), "m": m}
        series.add(t, lambda fn: meshio.Mesh(points, cells,
                                             point_data=data).write(fn))

    walls = [RigidWall(1, release=False), RigidWall(0, release=False)]
    t0 = time.perf_counter()
    ended, merged = "T = {:.2f}".format(t_end * SCALE), 0
    try:
        r = free_surface_flow(mesh, NewtonianFluid(K=K, eta=ETA), RHO,
                              t_end, dt, [0.0, -G], walls=walls,
                              callback=output, output_every=5, verbose=False)
        merged = len(r.merged)
    except DynamicsError as err:
        ended = "T = {:.2f}: {}".format(err.t * SCALE, str(err)[:60])
        merged = len(err.result.merged)
    T, Z, E = np.array(rows).T
    return T, Z, E, last, ended, merged, time.perf_counter() - t0


def total_lagrangian(mesh, t_end, dt):
    """``(T, Z, E, ended, seconds)`` of the thesis' frame."""
    basis = pg.FamilyBasis.from_name(mesh, PG, dim=2, vc_solver="local")
    model = model_for("UnlP0", basis, NewtonianFluid(K=K, eta=ETA))
    m = pg.lumped_mass(basis, RHO)
    X = basis.doflocs
    up = np.arange(basis.N) % 2 == 1
    walls = [RigidWall(1, release=False), RigidWall(0, release=False)]
    rows = []

    def output(t, u, v, record):
        x = X[:, ::2] + u.reshape(-1, 2).T
        rows.append((t * SCALE, front(x, m[::2]),
                     energy(x, v.reshape(-1, 2).T, m[::2])))

    t0 = time.perf_counter()
    ended = "T = {:.2f}".format(t_end * SCALE)
    try:
        pg.newmark(model, m, t_end, dt, f_ext=np.where(up, -m * G, 0.0),
                   wall=walls, callback=output, output_every=5,
                   verbose=False)
    except DynamicsError as err:
        ended = "T = {:.2f}: {}".format(err.t * SCALE, str(err)[:60])
    T, Z, E = np.array(rows).T
    return T, Z, E, ended, time.perf_counter() - t0


def main():
    ap = demo_parser(__doc__)
    ap.add_argument("--n", type=int, default=16,
                    help="particles across the column minus one (16)")
    ap.add_argument("--perturb", type=float, default=0.0,
                    help="move the interior nodes by up to this many "
                         "spacings (triangles)")
    args = ap.parse_args()
    n, T_end = (8, 2.0) if args.quick else (args.n, 4.0)
    dt = 2e-3 if n <= 8 else 1e-3
    mesh = column(n, args.perturb)
    out = output_dir(args.out)
    print("{} x {} particles{}, dt = {} s, to T = {}".format(
        n + 1, 2 * n + 1, ", perturbed {}".format(args.perturb)
        if args.perturb else "", dt, T_end))
    series = VTUSeries(os.path.join(out, "dam_break"))
    ul = reneighboured(mesh, T_end / SCALE, dt, series)
    tl = total_lagrangian(mesh, T_end / SCALE, dt)
    print("{:22s} {:>13s} {:>13s} {:>13s} {:>13s} {:>8s} {:>6s}  {}".format(
        "run", "Z(T=1)", "Z(T=2)", "Z(T=3)", "Z(T=4)", "E gain", "s",
        "ended"))
    for name, (T, Z, E, ended, sec) in (
            ("Martin & Moyce", (MARTIN_MOYCE[:, 0], MARTIN_MOYCE[:, 1],
                                None, "", 0.0)),
            ("re-neighboured", ul[:3] + ul[4:5] + ul[6:]),
            ("total Lagrangian", tl)):
        cells = against_experiment(T, Z)
        gain = "" if E is None else "{:+.1f}%".format(
            100 * (E.max() - E[0]) / (2 * E[0]))
        print("{:22s} {:>13s} {:>13s} {:>13s} {:>13s} {:>8s} {:6.1f}  {}"
              .format(name, *cells, gain, sec, ended), flush=True)
    print("merged particles: {}".format(ul[5]))
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(10, 4))
    ax.plot(*MARTIN_MOYCE.T, "ks", mfc="none", label="Martin & Moyce 1952")
    for (label, data), mark in zip(OTHER_EXPERIMENTS.items(), "^v"):
        ax.plot(*data.T, "k" + mark, mfc="none", ms=4, label=label)
    ax.plot(ul[0], ul[1], "C0-", label="PG UnlP0, re-neighboured")
    ax.plot(tl[0], tl[1], "C1--", label="PG UnlP0, total Lagrangian")
    ax.set_xlabel("T = t sqrt(2g/a)")
    ax.set_ylabel("front Z = z/a")
    ax.set_xlim(0, T_end)
    ax.set_ylim(1, max(ul[1].max(), tl[1].max()) + 0.5)
    ax.legend(fontsize=8)
    x, v = ul[3]
    sc = bx.scatter(x[0] / A, x[1] / A, c=np.hypot(*v), s=8, cmap="viridis")
    fig.colorbar(sc, ax=bx, label="|v| (m/s)")
    bx.set_aspect("equal")
    bx.set_xlabel("x/a")
    bx.set_ylabel("y/a")
    bx.set_title("re-neighboured, T = {:.2f}".format(ul[0][-1]))
    fig.tight_layout()
    fig.savefig(os.path.join(out, "dam_break.png"), dpi=120)
    print("wrote", os.path.join(out, "dam_break.png"), "and",
          os.path.join(out, "dam_break.pvd"))


if __name__ == "__main__":
    main()
