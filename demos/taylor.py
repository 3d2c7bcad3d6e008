"""Taylor anvil impact, finite J2 plasticity in dynamics (thesis 7.3.7,
Table 7.6).

A copper rod (length 32.4 mm, radius 3.2 mm: the benchmark's standard
values; the thesis gives them only in its Fig. 7.27) hits a rigid
frictionless wall at 227 m/s; E = 117, nu = 0.35, sigma_y = 0.4,
H = 0.1 kN/mm^2, rho0 = 8.93 g/cm^3; 80 µs.  Units: mm, µs, kN, GPa and
g/cm^3 (consistent: 1 kN µs^2/mm = 1 mg), so 227 m/s is 0.227 mm/µs.

The wall is the thesis' simplified contact: the normal displacement of the
rod's nodes held at the wall while the reaction is compressive, released
when it turns tensile (:class:`skfem_pg.solvers.RigidWall`).  The whole rod
is modelled (``pg.meshing.taylor_rod``; on a quarter with symmetry planes
the VC corrections at the axis corner stiffen the explicit step ninefold,
see its docstring), ``2n`` elements across the radius, its nodes the
particles.  The impact face slides on the wall, so the PG formulations use
the minimum-norm VC solve ('V5m' / 'V3m'; the thesis' default 'sn' fails
the patch test on sliding boundaries).

Explicit central differences (``central_difference``, the stable step
re-estimated every 100 steps) for VCPBG Unl, UnlP0, U1SUnl, U1SIG and the
FE comparators H1 and H1P0 (row-sum lumped mass); implicit Newmark with
1000 steps over 80 µs (the thesis'; 0.08 µs, also when ``--t-end`` is
shorter) for U2, U2P1, U2P1C and Unl+P1C behind
``--newmark`` (hours), Newton with its line search (full increments cycle
on Unl+P1C's first step).  Prints per formulation: final length, mushroom
radius (the largest radial position of the nodes that started on the
impact face), max e_p, beside the literature band and the thesis' row;
steps, the smallest step, the energy balance error, the energy the wall
took at impact, and the wall time with particle-steps per second.  Writes
out/taylor.png (length and kinetic energy over time) and a VTU series per
formulation (out/taylor/<name>/step_NNN.vtu, .pvd; u, v and e_p).
``--results benchmarks/README.md`` writes the table there.

``--tets`` splits the hexahedra into tetrahedra on the same nodes and runs
each formulation with the thesis' recipe and the PBG MTE1 ones (not U2,
U2P1, U2P1C, U1SIG) with kNN too (their default on tetrahedra), FEM O1 in place of H1 /
H1P0.

    python demos/taylor.py [--n 1] [--methods ...] [--newmark] [--t-end 80]
                           [--tets]
"""
import os
import time

import numpy as np

import skfem_pg as pg
from skfem_pg.materials import J2Plasticity
from skfem_pg.naming import knn_name
from skfem_pg.scenes import Scene
from skfem_pg.io import VTUSeries, step_writer
from harness import (demo_parser, markdown_table, new_figure, output_dir,
                     save_figure, update_results)
from skfem_pg.solvers import (DynamicsError, RigidWall, central_difference,
                              lumped_mass, newmark)

COPPER = J2Plasticity.from_young(117.0, 0.35, 0.4, H=0.1)
RHO = 8.93  # g/cm^3 = mg/mm^3
SPEED = 0.227  # mm/µs
T_END = 80.0  # µs
ROD = pg.meshing.TAYLOR_ROD
#: Table 7.6 name -> (the name solved, explicit?, thesis: length, radius,
#: max e_p)
METHODS = {
    "VCPBG Unl": ("VCPBG V5m Unl", True, (21.32, 6.47, 2.81)),
    "VCPBG UnlP0": ("VCPBG V5m UnlP0", True, (21.48, 7.30, 3.56)),
    "VCPBG U1SUnl": ("VCPBG V5m U1SUnl", True, (21.52, 7.16, 3.73)),
    "VCPBG U1SIG": ("VCPBG V3m U1SIG", True, (21.45, 7.26, 4.46)),
    "FEM H1": ("FEM H1", True, None),
    "FEM H1P0": ("FEM H1P0", True, None),
    "VCPBG U2": ("VCPBG V3m U2", False, (21.44, 6.85, 2.94)),
    "VCPBG U2P1": ("VCPBG V3m U2P1", False, (21.43, 6.88, 3.03)),
    "VCPBG U2P1C": ("VCPBG V3m U2P1C", False, (21.31, 6.70, 2.49)),
    "VCPBG Unl+P1C": ("VCPBG V5m Unl+P1C", False, (21.54, 7.28, 3.35)),
}
DEFAULT = ["VCPBG U1SIG", "FEM H1P0"]
#: the literature's band (Table 7.6: Kamoulakis ... Cihan et al.)
LITERATURE = {"length": (21.26, 21.66), "radius": (6.84, 7.24),
              "ep": (2.47, 4.06)}
NEWMARK_STEPS = 1000


def scene(n, tets=False):
    """The whole rod; ``tets``: its hexahedra split into tetrahedra on the
    same nodes."""
    mesh = pg.meshing.taylor_rod(n)
    return Scene("taylor", pg.meshing.tetrahedra(mesh) if tets else mesh,
                 COPPER)


def tet_methods(labels):
    """On tetrahedra: ``(label, solved, explicit, thesis)`` of each label
    with the thesis recipe, and of the PBG MTE1 ones (not U2, U2P1, U2P1C,
    U1SIG) with kNN too (the default there); FEM H1 and H1P0 become O1
    (O2's row-sum lumped mass is not positive)."""
    out = []
    for label in labels:
        solved, explicit, thesis = METHODS[label]
        if label.startswith("FEM"):
            if ("FEM O1", "FEM O1", True, None) not in out:
                out.append(("FEM O1", "FEM O1", True, None))
        else:
            out.append((label, solved, explicit, thesis))
            if knn_name(solved):  # PBG on MTE1 only
                out.append((label + " kNN", knn_name(solved),
                            explicit, thesis))
    return out


def run(sc, solved, explicit, t_end=T_END, series=None):
    """One formulation: final length, mushroom radius, max e_p, the time
    series of the length and the energies, and how it ended."""
    t0 = time.perf_counter()
    basis, model, _, _, _, t_pre = sc.setup(solved)
    d = 3
    m = lumped_mass(basis, RHO)
    X = basis.doflocs
    v0 = np.where(np.arange(basis.N) % d == 0, -SPEED, 0.0)
    nodes = X[:, ::d]
    top = int(np.argmin(np.abs(nodes[0] - ROD["length"])
                        + np.hypot(nodes[1], nodes[2])))
    foot = np.flatnonzero(np.abs(nodes[0]) < 1e-9)
    curve = {"t": [], "length": [], "kinetic": []}

    def output(t, x, v, rec):
        U = x[:basis.N].reshape(-1, d)
        curve["t"].append(t)
        curve["length"].append(ROD["length"] + U[top, 0])
        curve["kinetic"].append(rec["kinetic"])
        if series is not None:
            ep = model.plastic_strain()
            series.add(t, step_writer(basis, u=x[:basis.N], v=v,
                                      ep=ep[0] if ep else 0 * U[:, 0]))

    status = "done"
    wall = RigidWall(0, 0.0)
    try:
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            if explicit:
                tr = central_difference(model, m, t_end, v0=v0, wall=wall,
                                        callback=output)
            else:
                dt = T_END / NEWMARK_STEPS  # the thesis' step
                tr = newmark(model, m, t_end, dt, v0=v0, wall=wall,
                             callback=output, line_search=True,
                             output_every=max(1, round(t_end / dt / 20)))
        x, hist, steps = tr.x, tr.history, tr.steps
    except DynamicsError as err:
        status = "stopped at {:.2f} µs: {}".format(err.t, str(err)[:80])
        x, hist, steps = err.x, err.history, len(err.history)
        tr = None
    U = x[:basis.N].reshape(-1, d)
    P = nodes[:, foot].T + U[foot]
    ep = model.plastic_strain()
    return dict(
        length=ROD["length"] + U[top, 0],
        radius=float(np.hypot(P[:, 1], P[:, 2]).max()),
        ep=ep[1] if ep else 0.0, curve={k: np.array(v)
                                        for k, v in curve.items()},
        status=status, steps=steps, nodes=basis.N // d,
        dt_min=min((h["dt"] for h in hist if h.get("dt")), default=np.nan),
        error=max((abs(h["relative_error"]) for h in hist), default=np.nan),
        contact=hist[-1]["contact_loss"] / max(hist[0]["kinetic"], 1e-300)
        if hist else np.nan,
        times=tr.times if tr else {}, preprocess=t_pre,
        seconds=time.perf_counter() - t0)


def _band(v, key):
    lo, hi = LITERATURE[key]
    return "{:.2f}{}".format(v, "" if lo <= v <= hi else
                             " (below)" if v < lo else " (above)")


def row(label, r):
    thesis = r["thesis"]
    th = "{:.2f} / {:.2f} / {:.2f}".format(*thesis) if thesis else "–"
    per = r["nodes"] * r["steps"] / max(r["seconds"] - r["preprocess"],
                                        1e-9)
    return [label, _band(r["length"], "length"), _band(r["radius"],
                                                       "radius"),
            _band(r["ep"], "ep"), th, r["steps"],
            "{:.3g}".format(r["dt_min"]), "{:.1e}".format(r["error"]),
            "{:.1%}".format(r["contact"]), "{:.0f}".format(r["seconds"]),
            "{:.0f}".format(per), r["status"]]


def main(n=1, methods=None, results=None, out=None, t_end=T_END,
         tets=False):
    out = output_dir(out)
    print(pg.threads.describe())
    sc = scene(n, tets)
    cells = "tetrahedra" if tets else "hexahedra"
    print("Taylor rod L = {} mm, R = {} mm at {} mm/µs, {} µs: {} "
          "{}, {} nodes (n = {})".format(
              ROD["length"], ROD["radius"], SPEED, t_end, sc.mesh.nelements,
              cells, sc.mesh.nvertices, n), flush=True)
    rows = {}
    labels = methods or DEFAULT
    runs = tet_methods(labels) if tets else [
        (label,) + METHODS[label] for label in labels]
    for label, solved, explicit, thesis in runs:
        print("  {} ({}, {}) ...".format(label, solved, "central differences"
                                         if explicit else "Newmark"),
              flush=True)
        folder = os.path.join(out, "taylor", solved.replace(" ", "_")
                              .replace("+", "p"))
        rows[label] = r = run(sc, solved, explicit, t_end, VTUSeries(folder))
        r["thesis"] = thesis
        print("    {}: length {:.2f} mm, radius {:.2f} mm, max e_p {:.2f}; "
              "{} steps, {:.0f} s; time split {}".format(
                  r["status"], r["length"], r["radius"], r["ep"],
                  r["steps"], r["seconds"],
                  {k: round(v, 1) for k, v in r["times"].items()}),
              flush=True)
    text = markdown_table(
        ["formulation", "length [mm]", "mushroom radius [mm]", "max e_p",
         "thesis (length / radius / e_p)", "steps", "min dt [µs]",
         "energy error", "wall took (of T0)", "time [s]",
         "particle-steps/s", "reached"],
        [row(label, r) for label, r in rows.items()])
    text += ("\n\nLiterature (Table 7.6): length {}–{} mm, radius {}–{} mm, "
             "max e_p {}–{}; (below)/(above): outside that band.".format(
                 *LITERATURE["length"], *LITERATURE["radius"],
                 *LITERATURE["ep"]))
    print(text)
    if results:
        print("updated", update_results(
            results, "taylor_{}{}_{:g}".format(n, "_tets" if tets else "",
                                              t_end),
            "`python demos/taylor.py --n {} --methods {}{}`: the whole rod, "
            "{} {} / {} nodes, {:g} µs.\n\n".format(
                n, " ".join('"{}"'.format(m) for m in labels),
                " --tets" if tets else "", sc.mesh.nelements, cells,
                sc.mesh.nvertices, t_end) + text))
    plot(rows, os.path.join(out, "taylor.png"))
    print("wrote the VTU series in", os.path.join(out, "taylor"))
    return rows


def plot(rows, fn):
    fig, (a1, a2) = new_figure(2, figsize=(12, 4.5))
    for label, r in rows.items():
        c = r["curve"]
        a1.plot(c["t"], c["length"], label=label)
        a2.plot(c["t"], c["kinetic"], label=label)
    a1.axhspan(*LITERATURE["length"], color="0.85", label="literature")
    a1.set_xlabel("t [µs]")
    a1.set_ylabel("length [mm]")
    a2.set_xlabel("t [µs]")
    a2.set_ylabel("kinetic energy [J]")
    a1.legend(fontsize=7)
    save_figure(fig, fn)


if __name__ == "__main__":
    ap = demo_parser(__doc__, results=True)
    ap.add_argument("--n", type=int, default=1,
                    help="2n elements across the radius (default 1)")
    ap.add_argument("--methods", nargs="+", choices=list(METHODS),
                    metavar="METHOD", help="default: {}".format(
                        ", ".join(DEFAULT)))
    ap.add_argument("--explicit", action="store_true",
                    help="every explicit formulation of Table 7.6 and H1, "
                    "H1P0")
    ap.add_argument("--newmark", action="store_true",
                    help="also U2, U2P1, U2P1C, Unl+P1C with 1000 Newmark "
                    "steps (hours)")
    ap.add_argument("--t-end", type=float, default=T_END,
                    help="simulated time [µs] (default 80)")
    ap.add_argument("--tets", action="store_true",
                    help="the hexahedra split into tetrahedra on the same "
                    "nodes: each formulation with the thesis recipe, the "
                    "MTE1 ones also with kNN (their default there), FEM O1 "
                    "for H1/H1P0")
    a = ap.parse_args()
    if a.quick:  # the default methods (or --methods), 3 µs
        a.n, a.t_end = 1, 3.0
    methods = a.methods or (
        [k for k, v in METHODS.items() if v[1]] if a.explicit else
        list(DEFAULT))
    if a.newmark:
        methods += [k for k, v in METHODS.items() if not v[1]
                    and k not in methods]
    main(a.n, methods, a.results, a.out, a.t_end, a.tets)
