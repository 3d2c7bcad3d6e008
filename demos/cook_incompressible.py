"""Nearly incompressible Cook's membrane (plane strain): mixed PG
formulations against Q1P0, T1 and Q1 on the same irregular node sets,
error against wall time.

G = 0.375, lambda = 7.5e6 (nu = 0.49999998), left edge clamped, a unit
total shear on the right edge; vertical displacement v(48, 52) (the middle
of the loaded edge), published 16.4326.  The published value is a linear
(small-strain) one, so the scene is the iso/vol neo-Hooke solid under a
load of ``LOAD`` = 1e-5 and v is divided by it (the geometric nonlinearity
is then of order 1e-5).  Reference: Q1P0 on the regular 256 x 256 mesh
(also printed: 64 and 128, and the Richardson extrapolation), cached in
~/.cache/skfem_pg.

Node sets: the n x n Cook quadrilaterals, interior nodes moved by ±0.3h
(T1 on the same nodes, each quad split in two).  Methods: Q1, T1, Q1P0,
VCPBG Unl, VCPBG UnlP0, VCPBG Unl+P1C, VCPBG U2P1, VCPBG U2P1C (the
thesis' default VC boundary variant sn) and VCBCPBG V5m UnlP0, Unl+P1C
(the package's min-norm variant).

Prints v, its error against the reference and against 16.4326, Newton
iterations and wall time; writes out/cook_incompressible.png (error
against wall time) and out/cook_incompressible.vtu (VCBCPBG V5m Unl+P1C
on the finest set: displacement, stresses and the nodal pressure).

    python demos/cook_incompressible.py [--sizes 8 16 32] [--full]
"""
import os

import numpy as np

import skfem_pg as pg
from skfem_pg import materials as mat
from skfem_pg.analysis.postprocess import particle_fields
from skfem_pg.scenes import Scene
from skfem_pg.scenes.reference import overkill
from harness import (demo_parser, markdown_table, output_dir,
                     print_time_to_target, save_error_vs_time, update_results,
                     wall_time)

G, LAM = 0.375, 7.5e6
MATERIAL = mat.NeoHookeIsoVol(mu=G, K=LAM + 2.0 * G / 3.0)
LOAD = 1e-5  # total shear; results are divided by it
POINT = (48.0, 52.0)
PUBLISHED = 16.4326

METHODS = ["Q1", "T1", "Q1P0", "VCPBG Unl", "VCPBG UnlP0",
           "VCBCPBG V5m UnlP0", "VCPBG Unl+P1C", "VCBCPBG V5m Unl+P1C",
           "VCPBG U2P1", "VCPBG U2P1C"]
STYLES = {"Q1": "C7:s", "T1": "k--o", "Q1P0": "k-s", "VCPBG Unl": "C2-v",
          "VCPBG UnlP0": "C1-^", "VCBCPBG V5m UnlP0": "C1:^",
          "VCPBG Unl+P1C": "C0-D", "VCBCPBG V5m Unl+P1C": "C0:D",
          "VCPBG U2P1": "C3:x", "VCPBG U2P1C": "C4-.+"}


def named(mesh):
    return mesh.with_boundaries({
        "left": lambda x: np.isclose(x[0], 0.0),
        "right": lambda x: np.isclose(x[0], 48.0)})


def node_set(n, distortion=0.3):
    m = pg.meshing.cook_membrane(n)
    return named(pg.meshing.distort(m, distortion, seed=n)) if distortion \
        else m


def scene(mesh):
    return Scene("cook-incompressible", mesh, MATERIAL, clamped=["left"],
                 tractions={"right": [0.0, LOAD / 16.0]},
                 probes={"v": POINT})


def reference(verbose=True, base=64):
    """v of Q1P0 on the regular ``base``, twice and four times finer meshes
    (the last as ``overkill`` of the ``base`` mesh refined twice), and the
    Richardson extrapolation with the observed rate."""
    v = []
    for refine in (0, 1, 2):
        r = overkill(scene(node_set(base, 0.0)), refine=refine, method="Q1P0",
                     solver="direct", verbose=verbose)
        v.append(r.probes["v"][1] / LOAD)
    ratio = (v[1] - v[0]) / (v[2] - v[1])
    return v, v[2] + (v[2] - v[1]) / (ratio - 1.0)


def main(sizes=(8, 16, 32), results=None, out=None, ref_base=64):
    out = output_dir(out)
    print(pg.threads.describe())
    v_ref, v_extra = reference(base=ref_base)
    print("Q1P0 on regular {}², {}², {}²: v = {:.5f}, {:.5f}, {:.5f}; "
          "Richardson {:.5f}; published {}".format(
              ref_base, 2 * ref_base, 4 * ref_base, *v_ref, v_extra,
              PUBLISHED))
    ref = v_ref[2]
    rows, last = [], None
    for n in sizes:
        sc = scene(node_set(n))
        for name in METHODS:
            try:
                r = sc.solve(name)
            except Exception as err:  # report, go on with the others
                print("{:4d} {:16s} failed: {}: {}".format(
                    n, name, type(err).__name__, err))
                continue
            v = r.probes["v"][1] / LOAD
            row = dict(n=n, nodes=sc.mesh.nvertices, method=name, v=v,
                       err=abs(v - ref) / ref, pub=(v - PUBLISHED) / PUBLISHED,
                       newton=sum(len(h["residuals"]) - 1 for h in r.history),
                       **r.times)
            rows.append(row)
            print("{n:4d} {nodes:6d} {method:16s} v = {v:9.5f}  error "
                  "{err:8.2e}  vs published {pub:+8.2%}  Newton {newton:2d}"
                  "  {t:6.2f} s".format(t=wall_time(row), **row), flush=True)
            if name == "VCBCPBG V5m Unl+P1C":
                last = r
    print_time_to_target(rows, METHODS, 0.01, "error of v(48, 52)")
    table = markdown_table(
        ["n", "nodes", "method", "v(48, 52)", "error vs Q1P0 256²",
         "vs 16.4326", "Newton it.", "wall time [s]"],
        [[r["n"], r["nodes"], r["method"], "{:.4f}".format(r["v"]),
          "{:.2e}".format(r["err"]), "{:+.2%}".format(r["pub"]),
          r["newton"], "{:.2f}".format(wall_time(r))] for r in rows])
    print(table)
    if results:
        print("updated", update_results(
            results, "cook_incompressible",
            "`python demos/cook_incompressible.py --sizes {}`: nearly "
            "incompressible Cook (G = 0.375, lambda = 7.5e6, plane strain, "
            "small-strain limit), ±0.3h distorted n × n node sets.  "
            "Reference Q1P0 on regular 64², 128², 256²: {:.4f}, {:.4f}, "
            "{:.4f} (Richardson {:.4f}); published {}.\n\n".format(
                " ".join(map(str, sizes)), *v_ref, v_extra, PUBLISHED)
            + table))
    save_error_vs_time(os.path.join(out, "cook_incompressible.png"), rows,
                       STYLES, "relative error of v(48, 52)",
                       "nearly incompressible Cook, ±0.3h node sets")
    if last is not None:
        fields = particle_fields(last.basis, MATERIAL, last.u)
        fields["pressure"] = last.fields["p"]
        pg.write_vtu(os.path.join(out, "cook_incompressible.vtu"),
                     last.basis.particles, **fields)
    print("wrote {0}/cook_incompressible.png and {0}/cook_incompressible"
          ".vtu".format(out))
    return rows


if __name__ == "__main__":
    ap = demo_parser(__doc__, results=True)
    ap.add_argument("--sizes", type=int, nargs="+", default=[8, 16, 32],
                    help='elements per side of the Cook node sets')
    ap.add_argument("--full", action="store_true",
                    help="node sets 8, 16, 32, 64")
    a = ap.parse_args()
    if a.quick:
        main([8], None, a.out, ref_base=8)
    else:
        main([8, 16, 32, 64] if a.full else a.sizes, a.results, a.out)
