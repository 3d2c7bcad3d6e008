"""Do the cracks go where the experiment's go, on any mesh?  The crack
direction of Kalthoff–Winkler's test on square grids and gmsh triangles
at two spacings (issue 51).

The plate, the impact and the models of ``demos/kalthoff_winkler.py``
(maraging steel hit between its notches at 16.5 m/s, 90 µs): the
bond-based PMB, PG ``VCBCPBG V5sn Unl`` with its connectivity kept and
with crack-aware families (their default local VC), each with the
crack-band brittle criterion on the largest principal strain
(:class:`~skfem_pg.materials.CriticalStrainDamage`) and on the largest
principal stress (:class:`~skfem_pg.materials.CriticalStressDamage`),
on the demo's square grid (the notches cut out as one row of cells; PMB
cuts the bonds across them) and on gmsh triangles
(``meshes/kalthoff_winkler.geo``: notches 1 mm wide), at spacings 2 and
1 mm.  Each crack's direction to its notch is the chord from the notch
tip to the centroid of the crack's points 10–30 mm from the tip (the
experiment's about 70 degrees is the initial direction) and 40–60 mm from
it; the crack's points are the failed cells' centres (PG) or the
particles more than a third broken (PMB).  ``--tracked`` runs PG with the
crack tracking instead (:class:`~skfem_pg.materials.CrackTracking`: a
point fails only on the path a crack tip chooses by the maximum
tangential stress criterion; the notch tips given), beside PMB, into its
own table (a run its ``hold_limit`` stops is reported as stopped, with
what it held; the same runs with the limit lifted report the most the
tracking held, and where).  Beside them the failed cells
(PMB: particles), the drivers' energy balance, the steps and the seconds
of each run, and its seconds over PMB's on the same nodes.

Run: ``python benchmarks/crack_paths.py --results benchmarks/README.md
--meshes grid`` and ``... --meshes triangles`` (each its own table, its
rows written as they come; 41 and 73 min measured, side by side on 2
cores;
``--spacings`` and ``--models`` select a part; ``--tracked``, the same
for each mesh: 32 and 41 min side by side).
"""
import os
import sys
import time

import numpy as np

from harness import demo_parser, markdown_table, update_results

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                os.pardir, "demos"))
from kalthoff_winkler import (EXPERIMENT, FURTHER, INITIAL,  # noqa: E402
                              run_pg, run_pmb)
from skfem_pg.discretization.crack_tracking import \
    TrackingError  # noqa: E402

T_END = 9e-5
MODELS = ("PMB", "PG kept, strain", "PG kept, stress",
          "PG crack-aware, strain", "PG crack-aware, stress")
#: ``--tracked``: the criteria with the crack tracking
#: (:class:`~skfem_pg.materials.CrackTracking`, the notch tips given)
TRACKED = ("PMB", "PG kept, stress, tracked",
           "PG crack-aware, stress, tracked",
           "PG kept, stress, tracked, no hold limit",
           "PG crack-aware, stress, tracked, no hold limit")
HEADER = ["run", "mesh", "h (mm)", "particles",
          "initial, upper / lower (deg)", "further, upper / lower (deg)",
          "failed", "drivers' balance", "steps", "s", "s / PMB's"]
#: ``--tracked``: and the most the tracking held
HELD = "most held near tips / elsewhere (x criterion, at)"


def run(model, mesh, h):
    """One run: the table's cells after the first three (and, tracked,
    the most the tracking held)."""
    held = []
    if model == "PMB":
        (upper, lower), tr, m, basis, seconds = run_pmb(h, T_END, mesh)
        failed = int((m.damage() > 1 / 3).sum())
        n, balance, steps = (basis.particles.n,
                             tr.history[-1]["relative_error"], tr.steps)
    else:
        t0 = time.perf_counter()
        tracked = "tracked" in model
        limit = {"hold_limit": np.inf} if "no hold limit" in model else {}
        try:
            (upper, lower), failed, balance, steps, seconds, m = run_pg(
                h, T_END, "crack-aware" in model, mesh,
                model.split(", ")[1], tracked=tracked, **limit)
        except TrackingError as err:  # the tracking's own check stopped it
            seconds = time.perf_counter() - t0
            return ["", "stopped: a point held at {:.3g} x its criterion "
                    "at ({})".format(err.ratio, ", ".join(
                        "{:.6g}".format(c) for c in err.position)),
                    "", "", "", "",
                    "{:.1f}".format(seconds), ""], seconds
        n = m.basis.particles.n
        if tracked:
            most = m.history.crack_tracker().most_held
            held = [" / ".join("{:.2f} at ({:.1f}, {:.1f})".format(
                most[z][0], *most[z][1]) for z in ("near tips", "elsewhere"))]
    return [str(n),
            "{:.1f} / {:.1f}".format(upper[0], lower[0]),
            "{:.1f} / {:.1f}".format(upper[1], lower[1]),
            str(failed), "{:+.1e}".format(balance), str(steps),
            "{:.1f}".format(seconds)] + (held or [""]), seconds


def main(meshes, spacings, models, results=None, section="crack_paths_"):
    rows = []
    tracked = any("tracked" in m for m in models)
    header = HEADER + ([HELD] if tracked else [])
    for mesh in meshes:
        for h in spacings:
            pmb = None
            for model in models:
                cells, seconds = run(model, mesh, h)
                if model == "PMB":
                    pmb = seconds
                rows.append([model, mesh, "{:g}".format(h)] + cells[:-1] + [
                    "" if pmb is None else "{:.1f}".format(seconds / pmb)]
                    + (cells[-1:] if tracked else []))
                print(" | ".join(rows[-1]), flush=True)
                text = (
                    "Kalthoff–Winkler to {:g} µs on {}: the crack's "
                    "direction to the notch from each notch tip (upper / "
                    "lower), the chord to the centroid of its points "
                    "{:g}–{:g} mm (initial) and {:g}–{:g} mm (further) from "
                    "the tip, against the experiment's about {:.0f} degrees "
                    "(initial); PG's criterion on the largest principal "
                    "strain or stress:\n\n".format(
                        T_END * 1e6, " and ".join(meshes), *INITIAL,
                        *FURTHER, EXPERIMENT)
                    + markdown_table(header, rows))
                if results:  # row by row: a long run shows what it has
                    update_results(results, section + "_".join(meshes),
                                   text)
    print(text)


if __name__ == "__main__":
    ap = demo_parser(__doc__, results=True, quick=False)
    ap.add_argument("--meshes", nargs="+", choices=("grid", "triangles"),
                    default=["grid", "triangles"],
                    help="the node sets (one table for those given)")
    ap.add_argument("--spacings", nargs="+", type=float, default=[2.0, 1.0],
                    help="particle spacings in mm")
    ap.add_argument("--models", nargs="+", choices=MODELS + TRACKED[1:],
                    default=None, help="the models, in this order")
    ap.add_argument("--tracked", action="store_true",
                    help="PMB beside PG with the crack tracking (its own "
                         "table, crack_paths_tracked_<meshes>)")
    args = ap.parse_args()
    models = args.models or list(TRACKED if args.tracked else MODELS)
    main(args.meshes, args.spacings, models, args.results,
         "crack_paths_tracked_" if args.tracked else "crack_paths_")
