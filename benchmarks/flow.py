"""Flow (thesis 8.2, issue 51): which formulations hold a fluid, how
accurate and how fast, against exact solutions, FE Q1P0 on the same nodes
and an experiment.

Water (rho = 1e3 kg/m^3, K = 2.08 GPa, eta = 1e-3 Pa s,
:class:`~skfem_pg.materials.NewtonianFluid`), Newmark's default rule:

1. a column of water at rest (0.1 m, slip walls at the sides and the
   bottom, a free top, gravity 9.81 m/s^2) for 0.1 s: the largest velocity
   over sqrt(gH), or where the run stopped, on grids, on grids whose
   interior nodes are moved by up to 0.3 spacings (0.15 in 3-D), on
   triangles and tetrahedra.  The formulations the package refuses for a
   fluid (:func:`skfem_pg.solvers.rates.check_fluid_model`) are run here
   with that check switched off, to show why;
2. Poiseuille's start-up (``demos/poiseuille.py``'s channel, 0.5 s): the
   largest error of v_x over v_max in the middle half of the channel
   against the analytic series, on n x n grids and perturbed ones;
3. the dam break (Martin & Moyce 1952, a column a wide and 2a high, a =
   5 cm): the surge front Z = z/a against T = t sqrt(2g/a), beside the
   experiment's points for n^2 = 2, a = 2.25 in (as digitised in PySPH's
   ``db_exp_data.py``, with its a = 1.125 in series and Koshizuka & Oka's
   1996 experiment for the spread between experiments), in the total
   Lagrangian frame until it stops (PG, and FE Q1P0 on 8 x 16 to 32 x 64
   cells: where the discretized model converges), and re-neighboured
   (:func:`skfem_pg.solvers.free_surface_flow`) until T = 4 or until it
   gains 5 % energy, on grids, perturbed quadrilaterals and perturbed
   triangles.

Run: ``python benchmarks/flow.py --results benchmarks/README.md`` (about
15 min on 2 cores).
"""
import os
import sys
import time

import numpy as np
import skfem as fem

from harness import demo_parser, markdown_table, update_results

import skfem_pg as pg
import skfem_pg.solvers.rates as rates
from skfem_pg.formulations import model_for
from skfem_pg.materials import NewtonianFluid
from skfem_pg.solvers import (DynamicsError, NewmarkControls, RigidWall,
                              free_surface_flow)

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                os.pardir, "demos"))
# the experiments' fronts, the front (over a) and its table cells
from dam_break import (MARTIN_MOYCE, OTHER_EXPERIMENTS,
                       against_experiment, front)

RHO, K, ETA = 1e3, 2.08e9, 1e-3
PG = "VCBCPBG V5m UnlP0"


def grid(n, lengths, perturb=0.0, simplex=False):
    """A grid of ``n`` cells per unit of ``lengths`` (a tuple: 2-D or
    3-D), its interior nodes moved by up to ``perturb`` spacings."""
    axes = [np.linspace(0, L, int(round(n * L / min(lengths))) + 1)
            for L in lengths]
    d = len(lengths)
    quad = (fem.MeshQuad if d == 2 else fem.MeshHex).init_tensor(*axes)
    simp = (fem.MeshTri if d == 2 else fem.MeshTet).init_tensor(*axes)
    mesh = simp if simplex else quad
    p = mesh.p.copy()
    inner = np.all((p > 1e-12) & (p < np.array(lengths)[:, None] - 1e-12),
                   axis=0)
    h = min(lengths) / n
    p[:, inner] += perturb * h * np.random.default_rng(1).uniform(
        -1, 1, (d, inner.sum()))
    return type(mesh)(p, mesh.t)


def setup(method, mesh, vc_solver="local"):
    """``(model, m, X, component)`` of ``method`` (a PG name or ``FEM
    Q1P0``) on ``mesh`` with water."""
    d = mesh.dim()
    fluid = NewtonianFluid(K=K, eta=ETA)
    if method.startswith("FEM"):
        elem = fem.ElementQuad1() if d == 2 else fem.ElementHex1()
        basis = fem.Basis(mesh, fem.ElementVector(elem))
        comp = np.zeros(basis.N, dtype=int)
        for i in range(d):
            comp[basis.nodal_dofs[i]] = i
    else:
        basis = pg.FamilyBasis.from_name(mesh, method, dim=d,
                                         vc_solver=vc_solver)
        comp = np.arange(basis.N) % d
    model = model_for(method.split()[-1], basis, fluid)
    return model, pg.lumped_mass(basis, RHO), basis.doflocs, comp


def run(model, m, t_end, dt, check=True, **kw):
    """A Newmark run; ``check=False`` switches the fluid check off (to
    measure what it refuses).  ``(trajectory or DynamicsError, seconds,
    outputs [(t, x, v)])``."""
    outputs = []
    saved = rates.check_fluid_model
    if not check:
        rates.check_fluid_model = lambda model: None
    t0 = time.perf_counter()
    try:
        tr = pg.newmark(model, m, t_end, dt, verbose=False,
                        callback=lambda t, x, v, r: outputs.append(
                            (t, x.copy(), v.copy())), **kw)
    except DynamicsError as err:
        tr = err
    finally:
        rates.check_fluid_model = saved
    return tr, time.perf_counter() - t0, outputs


def column(method, mesh, vc_solver="local"):
    H = 0.1
    model, m, X, comp = setup(method, mesh, vc_solver)
    d = X.shape[0]
    up = comp == d - 1
    walls = np.isclose(X[d - 1], 0) & up
    for i in range(d - 1):
        walls |= (np.isclose(X[i], 0) | np.isclose(X[i], H)) & (comp == i)
    tr, s, outs = run(model, m, 0.1, 0.005, check=False,
                      f_ext=np.where(up, -m * 9.81, 0.0),
                      D=np.flatnonzero(walls))
    vmax = max(np.abs(v).max() for _, _, v in outs) / np.sqrt(9.81 * H)
    if isinstance(tr, DynamicsError):
        return "stopped at t = {:.3g} s (J <= 0); {:.2g} before".format(
            tr.t, vmax), s
    return "{:.1e}".format(vmax), s


def poiseuille(method, mesh):
    H, G = 1e-3, 2e-4
    nu = ETA / RHO
    model, m, X, comp = setup(method, mesh)
    along = comp == 0
    wall = np.isclose(X[1], 0) | np.isclose(X[1], H)
    end = np.isclose(X[0], 0) | np.isclose(X[0], H)
    tr, s, outs = run(model, m, 0.5, 0.02, f_ext=np.where(along, m * G,
                                                          0.0),
                      D=np.flatnonzero(wall | (end & ~along)))
    t, v = tr.t, tr.v
    middle = along & (X[0] > 0.25 * H) & (X[0] < 0.75 * H)
    y = X[1, middle]
    exact = G / (2 * nu) * y * (H - y)
    for k in range(1, 400, 2):
        exact -= (4 * G * H ** 2 / (nu * np.pi ** 3 * k ** 3)
                  * np.sin(k * np.pi * y / H)
                  * np.exp(-k ** 2 * np.pi ** 2 * nu * t / H ** 2))
    v_max = G * H ** 2 / (8 * nu)
    return (np.abs(v[middle] - exact).max() / v_max, tr.steps, s)


def dam_break(frame, method, n, perturb=0.0, simplex=False, controls=None):
    """The dam break on ``n x 2n`` particles (``perturb``: interior nodes
    moved, ``simplex``: triangles) in the total Lagrangian frame
    (``frame="TL"``, ``method`` a PG name or FEM Q1P0) or with
    re-neighbouring (``"UL"``, :func:`skfem_pg.solvers.free_surface_flow`,
    wetted walls; ``controls``: Newmark's, else the driver's default).
    ``(T, Z, Zmax, (largest, last) E change / (weight x height), how it
    ended, merges, seconds)``."""
    a, g = 0.05, 9.81
    mesh = grid(n, (a, 2 * a), perturb, simplex)
    scale = np.sqrt(2 * g / a)
    dt = 1e-3 if n > 8 else 2e-3
    out = []

    def record(t, x, v, m):
        out.append((t * scale, front(x, m), 0.5 * np.sum(
            m * (v * v).sum(axis=0)) + g * np.sum(m * x[1]),
            x[0].max() / a))
    t0 = time.perf_counter()
    merges, end = 0, "T = 4"
    if frame == "UL":
        walls = [RigidWall(1, release=False), RigidWall(0, release=False)]
        try:
            r = free_surface_flow(mesh, NewtonianFluid(K=K, eta=ETA), RHO,
                                  4.0 / scale, dt, [0.0, -g], walls=walls,
                                  callback=record, output_every=5,
                                  verbose=False, **({} if controls is None
                                                    else {"controls":
                                                          controls}))
            merges = len(r.merged)
        except DynamicsError as err:
            merges = len(err.result.merged)
            why = ("energy gain > 5 %" if "gained" in str(err)
                   else "J <= 0" if "J <= 0" in str(err) else "stopped")
            end = "T = {:.2f} ({})".format(err.t * scale, why)
    else:
        model, m, X, comp = setup(method, mesh)
        up = comp == 1
        D = np.flatnonzero((np.isclose(X[1], 0) & up)
                           | (np.isclose(X[0], 0) & ~up))
        mp = m[comp == 0]
        tr, _, outs = run(model, m, 4.0 / scale, dt,
                          f_ext=np.where(up, -m * g, 0.0), D=D,
                          output_every=5)
        for t, u, v in outs:
            xs = np.array([X[i][comp == i] + u[:len(comp)][comp == i]
                           for i in range(2)])
            vs = np.array([v[comp == i] for i in range(2)])
            record(t, xs, vs, mp)
        if isinstance(tr, DynamicsError):
            end = "T = {:.2f} (J <= 0)".format(tr.t * scale)
    T, Z, E, Zmax = np.array(out).T
    gain = ((E.max() - E[0]) / (E[0] * 2),  # weight x height = 2 E0
            (E[-1] - E[0]) / (E[0] * 2))
    return T, Z, Zmax, gain, end, merges, time.perf_counter() - t0


def main(results=None):
    text = []
    rows = []
    for label, mesh in (
            ("2-D grid 10 x 10", grid(10, (0.1, 0.1))),
            ("2-D grid, perturbed 0.3", grid(10, (0.1, 0.1), 0.3)),
            ("2-D triangles, perturbed 0.3", grid(10, (0.1, 0.1), 0.3,
                                                  True)),
            ("3-D hexahedra 6^3, perturbed 0.15",
             grid(6, (0.1,) * 3, 0.15)),
            ("3-D tetrahedra 6^3, perturbed 0.15",
             grid(6, (0.1,) * 3, 0.15, True))):
        variants = [(PG + ", local VC", PG, "local"),
                    (PG + ", global VC (refused)", PG, "auto")]
        if mesh.dim() == 2:
            variants.append(("VCBCPBG V5m Unl+P1C (refused)",
                             "VCBCPBG V5m Unl+P1C", "auto"))
        if isinstance(mesh, (fem.MeshQuad, fem.MeshHex)):
            fe = "FEM Q1P0" if mesh.dim() == 2 else "FEM H1P0"
            variants.append((fe, fe, None))
        for name, method, vcs in variants:
            cell, s = column(method, mesh, vcs)
            rows.append([label, name, cell, "{:.1f}".format(s)])
            print(" | ".join(rows[-1]), flush=True)
    text.append("A column of water at rest, 0.1 s: the largest velocity "
                "over sqrt(gH) (or where the run stopped):\n\n"
                + markdown_table(["mesh", "method", "max |v| / sqrt(gH)",
                                  "s"], rows))
    rows = []
    for label, n, perturb, simplex in (
            ("grid 8 x 8", 8, 0.0, False), ("grid 16 x 16", 16, 0.0, False),
            ("grid 32 x 32", 32, 0.0, False),
            ("grid 16 x 16, perturbed 0.3", 16, 0.3, False),
            ("triangles 16 x 16, perturbed 0.3", 16, 0.3, True)):
        mesh = grid(n, (1e-3, 1e-3), perturb, simplex)
        for method in (PG, "FEM Q1P0"):
            if simplex and method.startswith("FEM"):
                continue
            err, steps, s = poiseuille(method, mesh)
            rows.append([label, method, "{:.2e}".format(err), str(steps),
                         "{:.1f}".format(s)])
            print(" | ".join(rows[-1]), flush=True)
    text.append("Poiseuille's start-up at 0.5 s: the largest error of v_x "
                "over v_max in the middle half, the steps (a step cut "
                "adds some), the seconds:\n\n"
                + markdown_table(["mesh", "method", "error", "steps", "s"],
                                 rows))
    rows = []
    trapezoid = NewmarkControls()  # gamma = 1/2
    for frame, method, n, perturb, simplex, label, controls in (
            ("TL", PG, 8, 0.0, False, "grid 8 x 16", None),
            ("TL", "FEM Q1P0", 8, 0.0, False, "grid 8 x 16", None),
            ("TL", PG, 16, 0.0, False, "grid 16 x 32", None),
            ("TL", "FEM Q1P0", 16, 0.0, False, "grid 16 x 32", None),
            ("TL", "FEM Q1P0", 32, 0.0, False, "grid 32 x 64", None),
            ("TL", PG, 8, 0.3, True, "triangles 8 x 16, perturbed 0.3",
             None),
            ("UL", PG, 8, 0.0, False, "grid 8 x 16", None),
            ("UL", PG, 8, 0.0, False, "grid 8 x 16", trapezoid),
            ("UL", PG, 16, 0.0, False, "grid 16 x 32", None),
            ("UL", PG, 16, 0.0, False, "grid 16 x 32", trapezoid),
            ("UL", PG, 10, 0.3, False, "quadrilaterals 10 x 20, "
             "perturbed 0.3", None),
            ("UL", PG, 8, 0.3, True, "triangles 8 x 16, perturbed 0.3",
             None),
            ("UL", PG, 12, 0.3, True, "triangles 12 x 24, perturbed 0.3",
             None),
            ("UL", PG, 14, 0.2, True, "triangles 14 x 28, perturbed 0.2",
             None)):
        T, Z, Zmax, gain, end, merges, s = dam_break(
            frame, method, n, perturb, simplex, controls)
        cells = against_experiment(T, Z) + against_experiment(T, Zmax,
                                                              (2.0,))
        name = method + (", re-neighboured" if frame == "UL" else ", TL")
        if controls is not None:
            name += ", trapezoidal rule"
        rows.append([name, label] + cells + [
            end, "{:+.1f} %".format(100 * gain[0]),
            "{:+.1f} %".format(100 * gain[1]),
            str(merges) if frame == "UL" else "—", "{:.0f}".format(s)])
        print(" | ".join(rows[-1]), flush=True)
    text.append(
        "The dam break: the front Z (the alpha shape's furthest particle: "
        "a particle more than about 2.4 spacings ahead of the others does "
        "not count) at T = 1, 2, 3, 4 against Martin & Moyce ({}; "
        "their a = 1.125 in column: {}; Koshizuka & Oka: {}), and at "
        "T = 2 the furthest particle of all; where the run ended, "
        "the largest gain of kinetic plus potential energy (of weight x "
        "height; the fluid dissipates next to nothing), the particles "
        "merged; TL: total Lagrangian, slip walls; re-neighboured: "
        "`free_surface_flow` (`UpdatedLagrangeFluid`), wetted walls, its "
        "default Newmark rule (gamma = 0.55) or the trapezoidal one, "
        "stopped at a 5 % gain:\n\n".format(*[", ".join(
            "{:.2f}".format(np.interp(T, *data.T))
            for T in (1.0, 2.0, 3.0, 4.0)[:k])
            for data, k in zip((MARTIN_MOYCE, *OTHER_EXPERIMENTS.values()),
                               (4, 4, 3))])
        + markdown_table(["run", "particles", "T = 1", "T = 2", "T = 3",
                          "T = 4", "T = 2, furthest particle", "ended",
                          "energy gain", "energy at the end", "merged",
                          "s"], rows))
    text = "\n\n".join(text)
    print(text)
    if results:
        update_results(results, "flow", text)


if __name__ == "__main__":
    ap = demo_parser(__doc__, results=True, quick=False)
    main(ap.parse_args().results)
