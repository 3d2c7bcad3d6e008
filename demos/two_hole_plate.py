"""Ductile fracture of a steel plate with two holes (thesis 8.1, Fig. 8.1):
Johnson–Cook damage on PG particles beside FE with element erosion.

The thesis gives the geometry only in its Fig. 8.1(a); the one chosen here
(``meshes/plate_two_holes.geo``) is a 20 x 40 mm plate with holes of
radius 3 mm at (7, 17) and (13, 23): the ligament between them (2.5 mm)
runs at 45 degrees through the centre and is narrower than the two outer
bridges (4 mm), as the thesis' sequence (the middle first, the bridges
last) suggests of its figure.  Plane strain, total Lagrangian,
explicit central differences (the stable step estimated by the driver),
the bottom edge held and the top edge pulled up at 2000 mm/s from the
start (the thesis' v = 2000 mm/s), no mass scaling.  Steel after Broumand
& Khoei (2015), as in the thesis: rho0 = 7830 kg/m^3, E = 200 GPa,
nu = 0.29, Johnson–Cook flow stress A + B e_p^n (A = 792 MPa, B = 510 MPa,
n = 0.26) and damage D = sum de_p / (D1 + D2 exp(D3 triaxiality)) with
D1 = 0.05, D2 = 3.44, D3 = -2.12, failure at Dc = 0.3
(:mod:`skfem_pg.materials.damage`: a failed point keeps no deviatoric
stress and no tension).  Units N, mm, s (density in t/mm^3).

Models on the nodes of one gmsh quad mesh: the thesis' ``VCPBG V3m
U1SIG`` (connectivity kept across the crack, as in the thesis) and U1SIG
with crack-aware families (:class:`~skfem_pg.formulations.
CrackAwareU1SIG`: failed cells are removed, the families, shape
functions and VC correction rebuilt on the rest, so nothing connects the
broken parts); PG Unl (``VCBCPBG V5sn Unl``) with its connectivity kept
and crack-aware (:class:`~skfem_pg.formulations.CrackAware`); and FE Q1
with the same law at its Gauss points (a cell whose points fail is
eroded).  The crack-aware bases take the VC boundary variant ``sn``
(normal component of the correction fixed at surface particles, the
thesis' option), and so does Unl with its connectivity kept, for the
comparison: with the minimum-norm variant the corrections of the
families along a fresh crack grow, and the stable step fell within 0.1
ms of the first failure from 1.1e-7 to 7e-10 s (Unl) and to 2.7e-9 s
(U1SIG) (``sn``: 5.6e-8 and 4.5e-8 s).
Prints, per model, when the first point fails and where, the peak bottom
force and stored energy and when they fall, the angle at which the outer
bridges tear (the thesis' figure: about 45 degrees), the failed share,
the energy balance and the run time.  Writes ``out/two_hole_plate.png`` (damage on
the deformed plate at four times per model, and the bottom force, stored
and released energy over time) and a VTU series per model
(``out/two_hole_plate/<model>/step_NNN.vtu`` with ``.pvd``: u, damage).

    python demos/two_hole_plate.py [--h 1.0] [--t-end 2e-3] [--methods ...]
"""
import os
import time

import numpy as np
import skfem as fem

import skfem_pg as pg
from skfem_pg.discretization.elementwise import Elements
from skfem_pg.formulations import (CrackAware, CrackAwareU1SIG, Hyperelastic,
                                   model_for)
from skfem_pg.io import VTUSeries, step_writer
from skfem_pg.materials import (J2Plasticity, JohnsonCookDamage,
                                JohnsonCookHardening)
from skfem_pg.scenes.meshing import from_geo, geo_path
from skfem_pg.solvers import DynamicsError
from harness import demo_parser, new_figure, output_dir, save_figure

STEEL = J2Plasticity.from_young(
    200e3, 0.29, hardening=JohnsonCookHardening(792.0, 510.0, 0.26),
    damage=JohnsonCookDamage(0.05, 3.44, -2.12, 0.3))
RHO = 7.83e-9  # t/mm^3
SPEED = 2000.0  # mm/s
#: the suffix of a method whose families stop at the crack
CRACK_AWARE = "crack-aware"
METHODS = ("VCPBG V3m U1SIG", "VCPBG V3sn U1SIG " + CRACK_AWARE,
           "VCBCPBG V5sn Unl", "VCBCPBG V5sn Unl " + CRACK_AWARE, "FEM Q1")


def setup(mesh, method):
    """``(basis, model)`` of ``method`` on ``mesh``: a Table 7.1 name
    (connectivity kept), the same followed by ``crack-aware`` (Unl:
    :class:`~skfem_pg.formulations.CrackAware`, U1SIG:
    :class:`~skfem_pg.formulations.CrackAwareU1SIG`) or ``FEM Q1``."""
    if method.startswith("FEM"):
        basis = fem.Basis(mesh, fem.ElementVector(fem.ElementQuad1()))
        return basis, Hyperelastic(basis, STEEL)
    name, aware = method, method.endswith(" " + CRACK_AWARE)
    if aware:
        name = method[:-len(CRACK_AWARE) - 1]
    basis = pg.FamilyBasis.from_name(mesh, name, dim=2)
    # the plots and the VTU take a particle's value as its vertex's
    assert np.array_equal(basis.particles.x, mesh.p)
    if aware:
        u1sig = name.split()[-1] == "U1SIG"
        return basis, (CrackAwareU1SIG if u1sig else CrackAware)(basis,
                                                                 STEEL)
    return basis, model_for(name.split()[-1], basis, STEEL)


def damage_per_node(model, basis, mesh):
    """The failed share at each mesh vertex: of the particle's points (PG:
    the particles are the vertices; U1SIG has one point, its master's),
    of the cells around it (FE)."""
    failed = model.failed()
    if failed is None:
        return np.zeros(mesh.nvertices)
    if hasattr(basis, "particles"):
        E = Elements(model.point_basis)
        # per family; a particle in no family (all its cells failed,
        # crack-aware) counts as failed
        D = np.ones(mesh.nvertices)
        D[model.point_basis.families.masters] = (
            failed.astype(float) if failed.ndim == 1  # masters (U1SIG)
            else E.sum(failed.astype(float)) / E.volumes)
        return D
    cells = failed.mean(axis=1)
    corners = mesh.t.shape[0]
    total = np.bincount(mesh.t.ravel(), weights=np.tile(cells, corners),
                        minlength=mesh.nvertices)
    count = np.bincount(mesh.t.ravel(), minlength=mesh.nvertices)
    return total / np.maximum(count, 1)


def bridge_angles(mesh, D):
    """The angle (degrees from the x axis, in [0, 90]) at which each
    outer bridge — left of the lower hole (from the edge x = 0 to the hole
    at x = 4, around y = 17), right of the upper one (x = 16 to 20, around
    y = 23) — has torn: the line from the mean position of its failed
    vertices (``D >= 0.5``) by the plate's edge (within 1.5 mm) to that
    by the hole (within 1.5 mm); ``nan`` where either has none.  Across
    the bridge, perpendicular to the pull, is 0; the thesis' Fig. 8.1
    shows about 45."""
    x, y = mesh.p
    failed = D >= 0.5
    out = []
    for yc, edge, hole in ((17.0, x < 1.5, (x > 2.5) & (x < 4.5)),
                           (23.0, x > 18.5, (x > 15.5) & (x < 17.5))):
        near = failed & (np.abs(y - yc) < 6)
        if not (near & edge).any() or not (near & hole).any():
            out.append(np.nan)
            continue
        a, b = mesh.p[:, near & edge].mean(axis=1), \
            mesh.p[:, near & hole].mean(axis=1)
        out.append(float(np.degrees(np.arctan2(abs(b[1] - a[1]),
                                               abs(b[0] - a[0])))))
    return out


def run(mesh, method, t_end, snapshots, folder, outputs):
    """Pull the plate with ``method`` until ``t_end``: at every output
    (``outputs`` steps apart; ``None``: the driver's about 20) the bottom
    force, the stored and released energies, a VTU step in ``folder``
    and, at the first output after each time of ``snapshots``, the
    displacement and damage for the figure."""
    basis, model = setup(mesh, method)
    X = basis.doflocs
    vertical = np.arange(basis.N) % 2 == 1
    bottom = np.flatnonzero(np.isclose(X[1], 0.0))
    top = np.flatnonzero(np.isclose(X[1], mesh.p[1].max()))

    def u_D(t):
        u = np.zeros(basis.N)
        u[top] = vertical[top] * SPEED * t
        return u
    series = VTUSeries(folder)
    curve, shots, first = [], [], []
    intact = getattr(model, "intact", None)
    wanted = list(snapshots)

    def watch(t, x, v, record):
        f = model.internal_force(model.state(x))
        D = damage_per_node(model, basis, mesh)
        curve.append((t, -f[bottom[vertical[bottom]]].sum(),
                      record.get("stored", np.nan),
                      record.get("fracture", 0.0)))
        if D.any() and not first:
            first.append((t, mesh.p[:, D > 0]))
        if wanted and t >= wanted[0] - 1e-15:
            wanted.pop(0)
            shots.append((t, x[:basis.N].copy(), D, None if intact is None
                          else model.intact.copy()))
        series.add(t, step_writer(basis, u=x[:basis.N], damage=D))
    t0 = time.perf_counter()
    try:
        tr = pg.central_difference(model, pg.lumped_mass(basis, RHO), t_end,
                                   D=np.concatenate([bottom, top]), u_D=u_D,
                                   callback=watch, output_every=outputs)
    except DynamicsError as err:  # reported with what was measured
        tr = err
    seconds = time.perf_counter() - t0
    return dict(method=method, curve=np.array(curve), shots=shots,
                first=first[0] if first else None, trajectory=tr,
                seconds=seconds, basis=basis, model=model,
                bridges=bridge_angles(mesh, damage_per_node(model, basis,
                                                            mesh)))


def report(r):
    """Print what :func:`run` measured for one model."""
    c = r["curve"]
    peak_f, peak_w = np.argmax(c[:, 1]), np.argmax(c[:, 2])
    tr, first = r["trajectory"], r["first"]
    if isinstance(tr, DynamicsError):
        print("\n{}: stopped at t = {:.3g} s after {:.1f} s ({})".format(
            r["method"], tr.t, r["seconds"], str(tr).split(": ", 1)[-1]))
        last = (tr.history or [{"relative_error": np.nan}])[-1]
    else:
        last = tr.history[-1]
        print("\n{}: {} steps in {:.1f} s".format(r["method"], tr.steps,
                                                  r["seconds"]))
    if first:
        where = first[1]
        print("  first failure at t = {:.3g} s at {} node(s): {}".format(
            first[0], where.shape[1], ", ".join(
                "({:.1f}, {:.1f})".format(*p) for p in where.T[:6])))
    else:
        print("  no point failed")
    print("  bottom force: peak {:.4g} N at t = {:.3g} s, last {:.4g} N"
          .format(c[peak_f, 1], c[peak_f, 0], c[-1, 1]))
    print("  stored energy: peak {:.4g} N mm at t = {:.3g} s, last {:.4g}"
          .format(c[peak_w, 2], c[peak_w, 0], c[-1, 2]))
    print("  the outer bridges tear at {} (left) and {} (right) to the x "
          "axis (thesis: about 45 degrees)".format(*(
              "not torn" if np.isnan(a) else "{:.0f} degrees".format(a)
              for a in r["bridges"])))
    print("  released by failure {:.4g} N mm; dissipation {:.4g}; energy "
          "balance {:.2e}".format(c[-1, 3], last.get("dissipation", np.nan),
                                  last["relative_error"]))
    m = r["model"]
    if isinstance(m, (CrackAware, CrackAwareU1SIG)):
        log = m.update_log
        print("  crack-aware: {} updates ({} cells failed), {:.1f} s in "
              "them ({:.1f} s VC solves), {:.0f} % of the run; {} "
              "particles left without cells".format(
                  m.updates, sum(e["cells"] for e in log), m.update_seconds,
                  sum(e["vc"] for e in log),
                  100 * m.update_seconds / r["seconds"],
                  int((~m.point_basis.particles.active).sum())))


def plot(results, mesh, fn):
    """Damage on the deformed plate at the snapshots and the force and
    energy curves, one row per model, to ``fn``."""
    rows = len(results)
    ncols = max(len(r["shots"]) for r in results) + 1
    fig, axes = new_figure(ncols, figsize=(3.2 * ncols, 4.2 * rows))
    fig.clf()
    for i, r in enumerate(results):
        for j, (t, u, D, intact) in enumerate(r["shots"]):
            ax = fig.add_subplot(rows, ncols, i * ncols + j + 1)
            U = u.reshape(-1, 2)[:mesh.nvertices].T
            # crack-aware: the intact cells only (a removed cell's
            # particles may have flown off as debris)
            q = mesh.t if intact is None else mesh.t[:, intact]
            tri = np.hstack([q[[0, 1, 2]], q[[0, 2, 3]]])
            ax.tripcolor(*(mesh.p + U), tri.T, D, shading="gouraud",
                         vmin=0, vmax=1, cmap="inferno_r")
            x = (mesh.p + U)[:, np.unique(q)]  # not the debris' flight
            ax.set_xlim(x[0].min() - 1, x[0].max() + 1)
            ax.set_ylim(x[1].min() - 1, x[1].max() + 1)
            ax.set_aspect("equal")
            ax.set_axis_off()
            ax.set_title("{}\nt = {:.2g} ms".format(r["method"], 1e3 * t),
                         fontsize=8)
        ax = fig.add_subplot(rows, ncols, (i + 1) * ncols)
        c = r["curve"]
        ax.plot(1e3 * c[:, 0], c[:, 1], label="bottom force [N]")
        ax2 = ax.twinx()
        ax2.plot(1e3 * c[:, 0], c[:, 2], "C1", label="stored [N mm]")
        ax2.plot(1e3 * c[:, 0], c[:, 3], "C2", label="released [N mm]")
        ax.set_xlabel("t [ms]")
        ax.set_title(r["method"], fontsize=8)
        ax.legend(loc="upper left", fontsize=7)
        ax2.legend(loc="upper right", fontsize=7)
    save_figure(fig, fn)


def main():
    ap = demo_parser(__doc__)
    ap.add_argument("--h", type=float, default=1.0,
                    help="gmsh mesh size in mm")
    ap.add_argument("--t-end", type=float, default=2e-3,
                    help="end time in seconds")
    ap.add_argument("--methods", nargs="+", default=list(METHODS),
                    help="Table 7.1 names and FEM Q1")
    args = ap.parse_args()
    if args.quick:
        args.h, args.t_end = 4.0, 3e-4
    out = output_dir(args.out)
    mesh = from_geo(geo_path("plate_two_holes.geo"), size=args.h,
                    recombine=True)
    print("{} nodes, {} cells".format(mesh.nvertices, mesh.nelements))
    # the cracks form within the first quarter of the default run
    snapshots = args.t_end * np.array([0.15, 0.25, 0.4, 1.0])
    results = []
    for method in args.methods:
        folder = os.path.join(out, "two_hole_plate", method.replace(" ", "_"))
        r = run(mesh, method, args.t_end, snapshots, folder, outputs=None
                if args.quick else 200)
        report(r)
        results.append(r)
    plot(results, mesh, os.path.join(out, "two_hole_plate.png"))


if __name__ == "__main__":
    main()
