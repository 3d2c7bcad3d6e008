"""Poiseuille flow starting from rest (thesis 8.2, Fig. 8.2): water in a
channel driven by gravity along it, against the analytic series solution.

Water (rho = 1e3 kg/m^3, K = 2.08 GPa, eta = 1e-3 Pa s, thesis 8.2,
:class:`~skfem_pg.materials.NewtonianFluid`) fills a 1 mm x 1 mm piece of a
channel between two walls (no slip at y = 0 and y = H); gravity g = 2e-4
m/s^2 pulls it along x.  The ends slide (v_y = 0 there, v_x free): the
unidirectional flow v_x(y, t) is then the exact solution of the whole piece,

    v_x = g/(2 nu) y (H - y) - sum_{n odd} 4 g H^2/(nu pi^3 n^3)
          sin(n pi y/H) exp(-n^2 pi^2 nu t/H^2),    nu = eta/rho,

which grows to the parabola v_max = g H^2/(8 nu) = 2.5e-5 m/s in about
H^2/nu = 1 s.  Newmark's average acceleration rule (the default).

Methods on the same n x n nodes: PG VCBCPBG V5m UnlP0 with the local VC
correction (``vc_solver="local"``: its shares integrate a linear pressure
exactly, so the fluid also stays at rest under gravity, which the global
correction and the thesis' Unl+P1C do not; skfem_pg.solvers.rates.
check_fluid_model) and FE Q1P0.  Prints, per method, the largest error of
v_x along the middle column, over v_max, at t = 0.1 s and at the end, the
centre velocity over the exact one and the wall time; writes
out/poiseuille.png (the profiles) and the PG run as a VTU series
out/poiseuille.pvd.

    python demos/poiseuille.py [--n 16]
"""
import os
import time

import numpy as np
import skfem as fem

import skfem_pg as pg
from skfem_pg.formulations import model_for
from skfem_pg.io import VTUSeries, step_writer
from skfem_pg.materials import NewtonianFluid
from harness import demo_parser, output_dir

RHO, K, ETA, G, H = 1e3, 2.08e9, 1e-3, 2e-4, 1e-3
NU = ETA / RHO
V_MAX = G * H ** 2 / (8 * NU)
PG = "VCBCPBG V5m UnlP0"
METHODS = [PG, "FEM Q1P0"]
SNAPSHOTS = (0.05, 0.1, 0.2)


def exact(y, t, terms=200):
    """The start-up series (module docstring)."""
    v = G / (2 * NU) * y * (H - y)
    for k in range(1, 2 * terms, 2):
        v -= (4 * G * H ** 2 / (NU * np.pi ** 3 * k ** 3)
              * np.sin(k * np.pi * y / H)
              * np.exp(-k ** 2 * np.pi ** 2 * NU * t / H ** 2))
    return v


def run(method, n, dt, t_end, series=None):
    """The velocities along x at the middle column at ``SNAPSHOTS`` and
    ``t_end`` (``{t: (y, v_x)}``) and the wall time."""
    mesh = fem.MeshQuad.init_tensor(np.linspace(0, H, n + 1),
                                    np.linspace(0, H, n + 1))
    if method.startswith("FEM"):
        basis = fem.Basis(mesh, fem.ElementVector(fem.ElementQuad1()))
        along = np.zeros(basis.N, dtype=bool)
        along[basis.nodal_dofs[0]] = True
    else:
        basis = pg.FamilyBasis.from_name(mesh, method, dim=2,
                                         vc_solver="local")
        along = np.arange(basis.N) % 2 == 0
    model = model_for(method.split()[-1], basis,
                      NewtonianFluid(K=K, eta=ETA))
    m = pg.lumped_mass(basis, RHO)
    X = basis.doflocs
    wall = np.isclose(X[1], 0) | np.isclose(X[1], H)
    end = np.isclose(X[0], 0) | np.isclose(X[0], H)
    D = np.flatnonzero(wall | (end & ~along))  # no slip; the ends slide
    middle = along & np.isclose(X[0], H / 2)
    y = X[1, middle]
    profiles, last = {}, []

    def output(t, x, v, record):
        # a cut step moves the outputs off the snapshot times: interpolate
        for s in SNAPSHOTS + (t_end,):
            if s <= t_end and s not in profiles and t >= s * (1 - 1e-9):
                t0, v0 = last if last else (t, v)
                w = 1.0 if t == t0 else (s - t0) / (t - t0)
                profiles[s] = (y, ((1 - w) * v0 + w * v)[middle])
        last[:] = [t, v.copy()]
        if series is not None:
            series.add(t, step_writer(basis, u=x[:basis.N], v=v))

    t0 = time.perf_counter()
    pg.newmark(model, m, t_end, dt, f_ext=np.where(along, m * G, 0.0),
               D=D, callback=output, verbose=False)
    return profiles, time.perf_counter() - t0


def error(profile, t):
    y, v = profile
    return np.abs(v - exact(y, t)).max() / V_MAX


def main():
    ap = demo_parser(__doc__)
    ap.add_argument("--n", type=int, default=16,
                    help="nodes across the channel minus one (default 16)")
    args = ap.parse_args()
    n, dt, t_end = (8, 0.05, 0.5) if args.quick else (args.n, 0.01, 1.0)
    out = output_dir(args.out)
    print("n = {}, dt = {} s, t_end = {} s, v_max = {:.3g} m/s".format(
        n, dt, t_end, V_MAX))
    print("{:22s} {:>11s} {:>11s} {:>11s} {:>7s}".format(
        "method", "err t=0.1", "err end", "centre/ex", "s"))
    results = {}
    for method in METHODS:
        series = VTUSeries(os.path.join(out, "poiseuille")) \
            if method == METHODS[0] else None
        profiles, sec = run(method, n, dt, t_end, series)
        results[method] = profiles
        y, v = profiles[t_end]
        centre = v[np.argmin(np.abs(y - H / 2))] / exact(H / 2, t_end)
        print("{:22s} {:11.2e} {:11.2e} {:11.5f} {:7.2f}".format(
            method, error(profiles[0.1], 0.1), error(profiles[t_end],
                                                     t_end), centre, sec),
            flush=True)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4))
    yy = np.linspace(0, H, 101)
    for i, t in enumerate(SNAPSHOTS + (t_end,)):
        ax.plot(exact(yy, t) / V_MAX, yy / H, color="C{}".format(i), lw=1,
                label="exact, t = {:g} s".format(t))
        for method, marker in ((PG, "o"), ("FEM Q1P0", "x")):
            y, v = results[method][t]
            ax.plot(v / V_MAX, y / H, marker, color="C{}".format(i), ms=4,
                    mfc="none", label=method if i == 0 else None)
    ax.set_xlabel("v_x / v_max")
    ax.set_ylabel("y / H")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "poiseuille.png"), dpi=120)
    print("wrote", os.path.join(out, "poiseuille.png"), "and",
          os.path.join(out, "poiseuille.pvd"))


if __name__ == "__main__":
    main()
