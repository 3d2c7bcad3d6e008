"""What a material from FElupe's library costs against the package's
hand-written laws (issue 50).

Two measurements, each the best of three in one process:

1. stress and tangent at 100,000 points (3-D): the package's
   ``NeoHookeIsoVol``, FElupe's hand-written ``NeoHooke`` through
   :class:`~skfem_pg.materials.FElupeMaterial`, and FElupe's
   tensortrax-differentiated ``neo_hooke`` plus ``Volumetric`` (a user's
   W(C) costs this);
2. a Newton solve of FElupe's getting-started cube (4 x 4 x 4 nodes,
   uniaxial, clamped, -30 %) with each law, on H1 and PG on the same
   nodes.  The laws differ in their volumetric part (the package's
   K/4 (J^2 - 1 - 2 ln J), FElupe's K/2 (J - 1)^2), so the times compare
   cost, not answers.

Run: ``python benchmarks/material_library.py --results
benchmarks/README.md`` (needs the ``felupe`` extra).
"""
import time

import numpy as np
import skfem as fem

from harness import demo_parser, markdown_table, update_results

import skfem_pg as pg
from skfem_pg import loadcase
from skfem_pg.formulations import Hyperelastic
from skfem_pg.materials import FElupeMaterial, NeoHookeIsoVol


def best_of(f, n=3):
    out = np.inf
    for _ in range(n):
        t = time.perf_counter()
        f()
        out = min(out, time.perf_counter() - t)
    return out


def main(results=None):
    import felupe
    laws = {"NeoHookeIsoVol (package)": NeoHookeIsoVol(mu=1.0, K=5.0),
            "felupe.NeoHooke": FElupeMaterial(felupe.NeoHooke(mu=1.0,
                                                              bulk=5.0)),
            "felupe neo_hooke + Volumetric (tensortrax)": FElupeMaterial(
                felupe.Hyperelastic(felupe.neo_hooke, mu=1.0)
                & felupe.Volumetric(bulk=5.0))}
    rng = np.random.default_rng(0)
    F = np.eye(3)[:, :, None] + 0.1 * rng.standard_normal((3, 3, 100000))
    rows = []
    ref = None
    for name, law in laws.items():
        t = best_of(lambda: (law.stress(F), law.tangent(F)))
        ref = t if ref is None else ref
        rows.append([name, "{:.3f}".format(t), "{:.2f}".format(t / ref)])
    text = markdown_table(["law", "stress + tangent, 1e5 points (s)",
                           "ratio"], rows)
    mesh = fem.MeshHex.init_tensor(*(np.linspace(0, 1, 4),) * 3)
    rows = []
    for bname, basis in (
            ("H1", fem.Basis(mesh, fem.ElementVector(fem.ElementHex1()),
                             intorder=3)),
            ("PG", pg.FamilyBasis(mesh, dim=3))):
        ref = None
        for name, law in laws.items():
            model = Hyperelastic(basis, law)
            case = loadcase.uniaxial(basis, move=-0.3, clamped=True)
            out = {}

            def run():
                out["x"] = pg.solvers.newton(case.problem(model), steps=5,
                                             tol=1e-12, verbose=False)[0]
            t = best_of(run)
            ref = t if ref is None else ref
            rows.append([bname, name, "{:.3f}".format(t),
                         "{:.2f}".format(t / ref),
                         "{:.6f}".format(case.reaction(model, out["x"]))])
    text += "\n\n" + markdown_table(
        ["basis", "law", "Newton (s)", "ratio", "reaction"], rows)
    print(text)
    if results:
        update_results(results, "material_library", text)


if __name__ == "__main__":
    ap = demo_parser(__doc__, results=True, quick=False)
    main(ap.parse_args().results)
