"""Dynamic Cook membrane, total against updated Lagrangian (thesis 7.2.4,
Figs. 7.12-7.13).

Cook's membrane (48 x 44/16 mm, plane strain), left edge clamped, E = 210
GPa, nu = 0.3 (neo-Hooke; the thesis does not name the law), rho0 = 7.85
g/cm^3 (steel; not in the thesis).  The right edge carries the vertical
line load (7.9) q(t) = q0 sin(pi t / 0.01 ms) for t <= 0.02 ms, zero
after; the thesis prints q0 = 10000 kN/mm, which with E = 210 GPa would
bend the membrane by about 18 m — read here as 10000 N/mm = 10 kN/mm
[interpretation: a static tip deflection of about 18 mm, the thesis'
pictures' scale].  Newmark (beta 1/4, gamma 1/2), 500 steps over 0.12 ms,
the UL variants rebuilt every step (to provoke the tensile instability);
units mm, µs, kN.

Variants (Fig. 7.12): PBG (no correction), VCPBG (VC, no bond correction),
BCPBG (bond correction), VCBCPBG (both), each TL and UL; the clamped edge
is not a sliding boundary, so the thesis' VC boundary variant 'sn' is
used.  Thesis: TL variants differ marginally; PBG UL crashes at about
0.08 ms; VCPBG UL deviates visibly; VCBCPBG UL agrees very well with TL.

Prints per variant how far it got, the tip's vertical displacement at a
few times, the largest deviation from its TL run, Newton iterations and
wall time; writes out/cook_dynamic.png (tip displacement over time) and a
VTU series of VCBCPBG UL (u, v).  ``--results benchmarks/README.md``
writes the table there.

    python demos/cook_dynamic.py [--n 16] [--steps 500] [--variants ...]
"""
import os
import time

import numpy as np

import skfem_pg as pg
from skfem_pg.materials import NeoHooke
from skfem_pg.scenes import Scene
from skfem_pg.io import VTUSeries
from harness import (demo_parser, markdown_table, new_figure, output_dir,
                     save_figure, update_results)
from skfem_pg.solvers import DynamicsError, lumped_mass, newmark

E, NU, RHO = 210.0, 0.3, 7.85
Q0 = 10.0  # kN/mm (module docstring)
PULSE = 20.0  # µs
T_END = 120.0  # µs
TIP = (48.0, 60.0)
#: Fig. 7.12's variants -> the thesis name (TL / UL appended)
VARIANTS = {
    "PBG": "PBG Unl {} noBC",
    "VCPBG": "VCPBG V3sn Unl {} noBC",
    "BCPBG": "BCPBG Unl {}",
    "VCBCPBG": "VCBCPBG V5sn Unl {}",
}


def load(t, q0=Q0):
    """q(t) of (7.9) [kN/mm]."""
    return q0 * np.sin(np.pi * t / 10.0) if t <= PULSE else 0.0


def run(sc, name, steps, series=None, q0=Q0):
    t0 = time.perf_counter()
    basis, model, _, D, _, _ = sc.setup(name)
    f1 = pg.traction(basis, "right", [0.0, 1.0])
    m = lumped_mass(basis, RHO)
    X = basis.doflocs
    tip = int(np.flatnonzero(np.isclose(X[0], TIP[0])
                             & np.isclose(X[1], TIP[1])
                             & (np.arange(basis.N) % 2 == 1))[0])
    curve = {"t": [], "tip": [], "iterations": [], "Fxy": []}

    def output(t, x, v, rec):
        curve["t"].append(t)
        curve["tip"].append(x[tip])
        curve["iterations"].append(rec["iterations"])
        # Fig. 7.13's colour scale: F_xy in [-0.2, 0.2]
        curve["Fxy"].append(float(np.abs(model.state(x)["F"][0, 1]).max()))
        if series is not None:
            series.add(t, lambda fn: pg.write_vtu(
                fn, basis.particles, u=x[:basis.N], v=v))

    status = "done"
    try:
        newmark(model, m, T_END, T_END / steps,
                f_ext=lambda t: load(t, q0) * f1,
                D=D, callback=output, verbose=False, dt_min=T_END / steps / 64)
    except DynamicsError as err:
        status = "crashed at {:.4f} ms".format(err.t / 1000)
    return dict(curve={k: np.array(v) for k, v in curve.items()},
                status=status, seconds=time.perf_counter() - t0,
                updates=getattr(model, "updates", 0))


def main(n=16, steps=500, variants=None, results=None, out=None, q0=Q0):
    out = output_dir(out)
    print(pg.threads.describe())
    sc = Scene("cook-dynamic", pg.meshing.cook_membrane(n),
               NeoHooke(lam=E * NU / ((1 + NU) * (1 - 2 * NU)),
                        mu=E / (2 * (1 + NU))),
               clamped=["left"])
    print("dynamic Cook membrane, {} particles, {} Newmark steps over {} µs,"
          " q0 = {} kN/mm for {} µs".format(sc.mesh.nvertices, steps, T_END,
                                           q0, PULSE), flush=True)
    rows, runs = [], {}
    for v in variants or VARIANTS:
        for frame in ("TL", "UL"):
            name = VARIANTS[v].format(frame)
            series = VTUSeries(os.path.join(out, "cook_dynamic")) \
                if (v, frame) == ("VCBCPBG", "UL") else None
            print("  {} ...".format(name), flush=True)
            r = runs[v, frame] = run(sc, name, steps, series, q0)
            c = r["curve"]
            print("    {}: tip {:.3f} mm at {:.4f} ms, {} Newton iterations, "
                  "{:.0f} s".format(r["status"], c["tip"][-1],
                                    c["t"][-1] / 1000,
                                    int(c["iterations"].sum()),
                                    r["seconds"]), flush=True)
        tl, ul = runs[v, "TL"]["curve"], runs[v, "UL"]["curve"]
        k = min(len(tl["t"]), len(ul["t"]))
        dev = np.abs(ul["tip"][:k] - tl["tip"][:k]).max() / max(
            np.abs(tl["tip"]).max(), 1e-300)
        for frame in ("TL", "UL"):
            r = runs[v, frame]
            c = r["curve"]
            at = [np.interp(s, c["t"], c["tip"]) if c["t"][-1] >= s - 1e-9
                  else np.nan for s in (24.0, 60.0, 120.0)]
            rows.append([v + " " + frame, r["status"]] +
                        ["{:.2f}".format(a) for a in at] +
                        ["{:.1%}".format(dev) if frame == "UL" else "–",
                         "{:.3f}".format(c["Fxy"].max()),
                         int(c["iterations"].sum()),
                         "{:.0f}".format(r["seconds"])])
    text = markdown_table(
        ["variant", "reached", "tip u_y 0.024 ms", "0.06 ms", "0.12 ms",
         "max UL-TL deviation (of max |u_y|)", "max |F_xy|", "Newton its",
         "time [s]"],
        rows)
    print(text)
    if results:
        print("updated", update_results(
            results, "cook_dynamic_{}_{}_{:g}".format(n, steps, q0),
            "`python demos/cook_dynamic.py --n {} --steps {} --q0 {:g}`: {} "
            "particles.\n\n".format(n, steps, q0, sc.mesh.nvertices)
            + text))
    plot(runs, os.path.join(out, "cook_dynamic.png"))
    return runs


def plot(runs, fn):
    fig, ax = new_figure()
    for (v, frame), r in runs.items():
        c = r["curve"]
        ax.plot(c["t"] / 1000, c["tip"], "-" if frame == "TL" else "--",
                label="{} {}".format(v, frame))
    ax.set_xlabel("t [ms]")
    ax.set_ylabel("tip displacement u_y [mm]")
    ax.legend(fontsize=7, ncol=2)
    save_figure(fig, fn)


if __name__ == "__main__":
    ap = demo_parser(__doc__, results=True)
    ap.add_argument("--n", type=int, default=16,
                    help="elements per side (default 16)")
    ap.add_argument("--steps", type=int, default=500,
                    help="Newmark steps over 0.12 ms (default 500, the "
                    "thesis')")
    ap.add_argument("--variants", nargs="+", choices=list(VARIANTS),
                    help='which of the Fig. 7.12 variants to run (default: all)')
    ap.add_argument("--q0", type=float, default=Q0,
                    help="load amplitude [kN/mm] (default 10: the thesis' "
                    "10000 read as N/mm)")
    a = ap.parse_args()
    if a.quick:
        a.n, a.steps = 4, 20
    main(a.n, a.steps, a.variants, a.results, a.out, a.q0)
