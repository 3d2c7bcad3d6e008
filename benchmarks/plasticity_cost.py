"""Cost of the J2 return map: one plastic Newton iteration against the
hyperelastic one on the same basis (PG VC PBG Unl, U1SUnl, U1SIG and FE
H1P0, 3-D cube).

A unit cube of n^3 hexahedra (default n = 10: 1331 nodes), stretched 5 %
(every point plastic for the steel of thesis 7.3.5); per formulation and
material: seconds of the state (F), the internal force (with the stress
update), the tangent (material tangent + assembly) and the linear solve,
and the return map's cost per integration point (U1SUnl / U1SIG: one per
family, at the master; ``vs Unl``: the total against PG Unl's hyperelastic
iteration).  The batched kernels run
with the package's default of one BLAS thread (``skfem_pg.threads``).

    python benchmarks/plasticity_cost.py [--n 10] [--results FILE]
"""
import time

import numpy as np
import skfem as fem

import skfem_pg as pg
from skfem_pg.formulations.by_name import model_for
from skfem_pg.materials import J2Plasticity
from harness import (demo_parser, markdown_table, update_results)
from skfem_pg.solvers import linear_solver

STEEL = J2Plasticity.from_young(206.9, 0.29, 0.45, H=0.13, sigma_yinf=1.165,
                                delta=16.93)


def iteration(model, basis, D):
    u = np.zeros(model.N)
    x = basis.doflocs
    c = np.arange(model.n_u) % 3  # u = (0.05 x, -0.02 y, -0.02 z)
    u[:model.n_u] = np.where(c == 0, 0.05, -0.02) * x[c, np.arange(
        model.n_u)]
    if model.N > model.n_u:
        u[model.n_u:] = model.initial()[model.n_u:]
    best = np.full(3, np.inf)
    for _ in range(3):  # a fresh state each time: no cached response
        t0 = time.perf_counter()
        s = model.state(u)
        t1 = time.perf_counter()
        model.internal_force(s)  # the stress update happens here
        t2 = time.perf_counter()
        K = model.tangent(s)
        t3 = time.perf_counter()
        best = np.minimum(best, [t1 - t0, t2 - t1, t3 - t2])
    t_state, t_force, t_tan = best
    I = np.setdiff1d(np.arange(model.N), D)
    lin = linear_solver("direct", None)
    t0 = time.perf_counter()
    lin(K[I][:, I].tocsr(), np.ones(I.size))
    t_solve = time.perf_counter() - t0
    h = getattr(model, "history", None)
    npts = None if h is None else h.committed["alpha"].size
    F = s["F1"] if "F1" in s else s["F"]  # U1S*: the masters' F
    plastic = None if h is None else float(h.response(F).plastic.mean())
    return dict(state=t_state, force=t_force, tangent=t_tan, solve=t_solve,
                points=npts, plastic=plastic)


def main():
    ap = demo_parser(__doc__, results=True)
    ap.add_argument("--n", type=int, default=10,
                    help='cells per side of the unit cube')
    args = ap.parse_args()
    n = args.n
    mesh = fem.MeshHex.init_tensor(*[np.linspace(0, 1, n + 1)] * 3)
    mesh = mesh.with_defaults()
    elastic = STEEL.elastic()
    print("cube {0}x{0}x{0}, {1} nodes; seconds (best of 3)".format(
        n, mesh.nvertices))
    print("{:8s} {:10s} {:>7s} {:>7s} {:>7s} {:>7s} {:>7s} {:>8s} {:>6s} "
          "{:>6s}".format("basis", "material", "state", "force", "tangent",
                          "solve", "total", "us/point", "ratio", "vs Unl"))
    unl, table = None, []
    pgb = pg.FamilyBasis(mesh, dim=3)
    for label, make, token in [
            ("PG Unl", lambda: pgb, "Unl"),
            ("U1SUnl", lambda: pgb, "U1SUnl"),
            ("U1SIG", lambda: pgb, "U1SIG"),
            ("H1P0", lambda: fem.Basis(mesh, fem.ElementVector(
                fem.ElementHex1()), intorder=2), "H1P0")]:
        basis = make()
        D = basis.get_dofs("left").all()
        rows = {}
        for name, material in (("neo-Hooke", elastic), ("J2", STEEL)):
            model = model_for(token, basis, material)
            rows[name] = iteration(model, basis, D)
        base = sum(v for k, v in rows["neo-Hooke"].items()
                   if k in ("state", "force", "tangent", "solve"))
        unl = base if unl is None else unl
        for name, r in rows.items():
            tot = r["state"] + r["force"] + r["tangent"] + r["solve"]
            extra = (tot - base) / r["points"] * 1e6 if r["points"] else 0.0
            print("{:8s} {:10s} {:7.3f} {:7.3f} {:7.3f} {:7.3f} {:7.3f} "
                  "{:>8s} {:6.2f} {:6.2f}".format(
                      label, name, r["state"], r["force"], r["tangent"],
                      r["solve"], tot, "{:.2f}".format(extra)
                      if r["points"] else "-", tot / base, tot / unl))
            table.append([label, name] + ["{:.3f}".format(v) for v in (
                r["state"], r["force"], r["tangent"], r["solve"], tot)] + [
                "{:.1f}".format(extra) if r["points"] else "–",
                r["points"] or "–", "{:.2f}".format(tot / base),
                "{:.2f}".format(tot / unl)])
        print("  {} points, {:.0%} plastic".format(rows["J2"]["points"],
                                                   rows["J2"]["plastic"]))
    if args.results:
        print("updated", update_results(
            args.results, "plasticity_cost_{}".format(n),
            "`python benchmarks/plasticity_cost.py --n {0}`: one Newton "
            "iteration on the unit cube of {0}^3 hexahedra ({1} nodes), "
            "stretched 5 % (every point plastic); seconds, best of 3; "
            "`extra us/point`: the plastic iteration's extra time per "
            "return-map point; `ratio`: against the same basis' hyperelastic"
            " iteration, `vs Unl`: against PG Unl's.\n\n".format(
                n, mesh.nvertices) + markdown_table(
                ["basis", "material", "state", "force", "tangent", "solve",
                 "total", "extra us/point", "points", "ratio", "vs Unl"],
                table)))


if __name__ == "__main__":
    main()
