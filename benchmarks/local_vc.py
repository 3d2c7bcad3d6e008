"""Local against global VC correction: accuracy on the same nodes and the
correction's cost (``vc_solver="local"``, skfem_pg.discretization.vc.local).

1. **Manufactured solution** (thesis (7.7)–(7.8), full Dirichlet
   boundary, ±0.3h distorted quads and triangles): relative L2 and H1
   errors and rates of VC PBG Unl with the global and the local
   correction, Q1/T1 on the same nodes.
2. **Linear Cook 2-D** (plane stress, E = 1, nu = 1/3): v(48, 52) against
   the Q2 overkill of ``skfem_pg.scenes.reference.linear_cook`` (23.9672;
   literature 23.96), regular and ±0.3h distorted quads.
3. **Linear Cook 3-D** (lambda = 100, mu = 40, plate bending): corner
   z-displacement against H2 on a 16 x 16 x 4 hex grid, on distorted hex
   grids (the thesis recipe's mesh families) and their tetrahedra (mesh
   families: the local correction needs every element neighbour in the
   family; the global correction also with the kNN families of the
   default tet recipe), beside H1 / O1 and O2 on the same nodes.
4. **Cost**: seconds of the correction alone (``basis.timings["vc"]``) and
   of the whole basis, global against local, 2-D up to 257² particles and
   3-D hex grids (±0.2h) up to 31³.

    python benchmarks/local_vc.py [--quick] [--results benchmarks/README.md]
"""
import time
import warnings

import numpy as np
import skfem as fem

import skfem_pg as pg
from harness import demo_parser, markdown_table, update_results
from skfem_pg import materials as mat
from skfem_pg.analysis.convergence import (PlaneWaves, rates,
                                           solve_manufactured)
from skfem_pg.formulations import linear_elasticity
from skfem_pg.materials import lame
from skfem_pg.scenes import Scene
from skfem_pg.scenes.reference import linear_cook

VARIANTS = {"global VC": {}, "local VC": {"vc_solver": "local"}}


def manufactured(ns):
    lam, mu = lame(100e3, 0.3)
    field = PlaneWaves.hillman2019()
    rows = []
    for kind in ("quad", "tri"):
        sets = []
        for n in ns:
            m = fem.MeshQuad.init_tensor(np.linspace(-1, 1, n + 1),
                                         np.linspace(-1, 1, n + 1))
            m = pg.meshing.distort(m, 0.3, seed=n)
            sets.append(m.to_meshtri() if kind == "tri" else m)
        runs = [("FE " + ("T1" if kind == "tri" else "Q1"), "FE", {})] + [
            ("VC PBG Unl, " + k, "PG", kw) for k, kw in VARIANTS.items()]
        for label, scheme, kw in runs:
            r = [solve_manufactured(m, field, lam, mu, scheme, **kw)
                 for m in sets]
            h = [x["h"] for x in r]
            rows.append([kind, label,
                         "{:.2f}".format(rates(h, [x["L2"] for x in r])[0]),
                         "{:.2f}".format(rates(h, [x["H1"] for x in r])[0]),
                         "{:.3e}".format(r[-1]["L2"]),
                         "{:.3e}".format(r[-1]["H1"]),
                         "{:.2f}".format(r[-1]["seconds"])])
            print(" ".join(rows[-1]), flush=True)
    return markdown_table(
        ["nodes", "method", "L2 rate", "H1 rate",
         "L2 at {0}²".format(ns[-1] + 1), "H1 at {0}²".format(ns[-1] + 1),
         "s at {0}²".format(ns[-1] + 1)], rows)


def cook_2d(ns):
    lam, mu = lame(1.0, 1.0 / 3.0, plane_stress=True)
    ref, _ = linear_cook(lam, mu)
    form = linear_elasticity(lam, mu)
    rows = []
    for label, amount in (("regular", 0.0), ("±0.3h", 0.3)):
        for n in ns:
            mesh = pg.meshing.cook_membrane(n)
            if amount:
                mesh = pg.meshing.distort(mesh, amount, seed=n) \
                    .with_boundaries({
                        "left": lambda x: np.isclose(x[0], 0.0),
                        "right": lambda x: np.isclose(x[0], 48.0)})
            dof = 2 * pg.meshing.vertex_at(mesh, (48.0, 52.0)) + 1
            e = fem.ElementVector(fem.ElementQuad1())
            t0 = time.perf_counter()
            b = fem.Basis(mesh, e)
            f = fem.LinearForm(lambda v, w: v[1] / 16.0).assemble(
                fem.FacetBasis(mesh, e, facets="right"))
            u = fem.solve(*fem.condense(form.assemble(b), f,
                                        D=b.get_dofs("left")))
            out = [("Q1", u[dof], time.perf_counter() - t0)]
            for k, kw in VARIANTS.items():
                t0 = time.perf_counter()
                pb = pg.FamilyBasis(mesh, dim=2, **kw)
                f = pg.traction(pb, "right", [0.0, 1.0 / 16.0])
                u = fem.solve(*fem.condense(pg.assemble(form, pb), f,
                                            D=pb.get_dofs("left")))
                out.append(("VC PBG Unl, " + k, u[dof],
                            time.perf_counter() - t0))
            for name, v, t in out:
                rows.append([label, (n + 1) ** 2, name, "{:.5f}".format(v),
                             "{:+.2%}".format((v - ref) / ref),
                             "{:.2f}".format(t)])
                print(" ".join(map(str, rows[-1])), flush=True)
    return ref, markdown_table(["nodes", "particles", "method", "v(48,52)",
                                "error", "s"], rows)


def cook_3d(grids):
    material = mat.LinearElastic(lam=100.0, mu=40.0)
    corner = (48.0, 60.0, 10.0)

    def scene(mesh):
        return Scene("cook3d-linear", mesh, material, clamped=["left"],
                     tractions={"right": [0.0, 0.0, 0.04]},
                     probes={"corner": corner})
    ref = scene(pg.meshing.cook_membrane_3d(16, 4, 10.0)).solve("H2")
    w_ref = ref.probes["corner"][2]
    rows = []
    for n in grids:
        hexes = pg.meshing.cook_membrane_3d(n, max(1, n // 4), 10.0, 0.3,
                                            seed=n)
        tets = pg.meshing.transfer_boundaries(hexes, hexes.to_meshtet())
        for cells, mesh, fe in (("hex", hexes, ("H1",)),
                                ("tet", tets, ("O1", "O2"))):
            sc = scene(mesh)
            runs = [(name, dict(scheme=name)) for name in fe] + [
                ("VC PBG Unl, " + k, dict(kw, scheme="PG",
                                          families="mesh"))
                for k, kw in VARIANTS.items()]
            if cells == "tet":  # the default recipe there: kNN families
                runs.append(("VC PBG Unl, global VC, kNN (tet default)",
                             dict(scheme="PG")))
            for name, kw in runs:
                t0 = time.perf_counter()
                r = sc.solve(verbose=False, **kw)
                t = time.perf_counter() - t0
                w = r.probes["corner"][2]
                rows.append(["{} {}x{}x{}".format(cells, n, n, max(1, n // 4)),
                             mesh.nvertices, name, "{:.6f}".format(w),
                             "{:+.2%}".format((w - w_ref) / w_ref),
                             "{:.2f}".format(t)])
                print(" ".join(map(str, rows[-1])), flush=True)
    return w_ref, markdown_table(["node set", "nodes", "method", "w",
                                  "error", "s"], rows)


def cost(ns2, ns3):
    rows = []
    sets = [("2-D quads ±0.3h", n, lambda n: pg.meshing.distort(
        fem.MeshQuad.init_tensor(*[np.linspace(0, 1, n + 1)] * 2), 0.3,
        seed=n)) for n in ns2] + [
        ("3-D hexes ±0.2h", n, lambda n: pg.meshing.distort(
            fem.MeshHex.init_tensor(*[np.linspace(0, 1, n + 1)] * 3), 0.2,
            seed=n)) for n in ns3]
    for label, n, make in sets:
        mesh = make(n)
        out = []
        for k, kw in VARIANTS.items():
            t0 = time.perf_counter()
            b = pg.FamilyBasis(mesh, dim=mesh.dim(), **kw)
            total = time.perf_counter() - t0
            out.append((k, b.timings["vc"], total, b.vc_report))
        (_, g_vc, g_tot, g_rep), (_, l_vc, l_tot, l_rep) = out
        rows.append([label, mesh.nvertices, "{:.2f}".format(g_vc),
                     g_rep.solver, "{:.2f}".format(l_vc),
                     "{:.1f}x".format(g_vc / l_vc),
                     "{:.2f}".format(g_tot), "{:.2f}".format(l_tot),
                     "{:.1e} / {:.1e}".format(g_rep.residual_after,
                                              l_rep.residual_after)])
        print(" ".join(map(str, rows[-1])), flush=True)
    return markdown_table(
        ["node set", "particles", "global VC [s]", "global solver",
         "local VC [s]", "global / local", "basis, global [s]",
         "basis, local [s]", "residual after (global / local)"], rows)


def main():
    ap = demo_parser(__doc__, results=True)
    a = ap.parse_args()
    warnings.filterwarnings("ignore", message="Indefinite matrix")
    print(pg.threads.describe())
    if a.quick:
        ns, cook, grids, ns2, ns3 = (4, 8), (4, 8), (4,), (16,), (4,)
    else:
        ns, cook = (8, 16, 32, 64), (4, 8, 16, 32, 64)
        grids, ns2, ns3 = (4, 8, 12, 16), (64, 128, 256), (10, 20, 30)
    print("\n1. manufactured solution")
    t1 = manufactured(ns)
    print("\n2. linear Cook 2-D")
    ref2, t2 = cook_2d(cook)
    print("\n3. linear Cook 3-D")
    ref3, t3 = cook_3d(grids)
    print("\n4. cost of the correction")
    t4 = cost(ns2, ns3)
    text = ("`python benchmarks/local_vc.py`: the local VC correction "
            "(`vc_solver=\"local\"`) against the global one on the same "
            "nodes.\n\n1. Manufactured solution (7.7)–(7.8), ±0.3h "
            "distorted node sets, 9² … {}² nodes:\n\n{}\n\n2. Linear Cook "
            "2-D, v(48,52) against the Q2 overkill {:.5f}:\n\n{}\n\n"
            "3. Linear Cook 3-D, corner w against H2 16×16×4 ({:.6f}); "
            "PG with mesh families:\n\n{}\n\n4. Cost of the correction "
            "alone and of the whole basis:\n\n{}".format(
                ns[-1] + 1, t1, ref2, t2, ref3, t3, t4))
    print(text)
    if a.results:
        print("updated", update_results(a.results, "local_vc", text))


if __name__ == "__main__":
    main()
