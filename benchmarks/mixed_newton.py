"""Cost of one Newton iteration of each mixed formulation against PBG Unl
and against the FE mean dilatation (Q1P0 in 2-D, H1P0 in 3-D) on the same
nodes.

A Newton iteration is what :func:`skfem_pg.solvers.newton` does per step:
the state at the points (F, the condensed or local fields: the bubble's
local Newton for Unl+P1C), the internal force, the tangent and the sparse
direct solve of the free unknowns (displacements and the global p / Theta
/ pressures).  The state is a random smooth deformation of the ±0.3h
distorted unit square / cube (iso/vol neo-Hooke, mu = 1, K = 1e3), the
same for every method.  Each phase is the fastest of ``--repeat`` runs;
ratios against PBG Unl (PBG U2 for the WTE2 formulations U2P1 and
U2P1C) and against Q1P0 / H1P0 in the same run; the first tangent of a
model with global p / Theta also finds its sparsity pattern (not timed:
the fastest run counts).  Direct
solver for all (scipy's SuperLU via ``pg.solvers.direct``: the saddle
points of IUnlP0, U2P1C and Unl+P1C need it), so the ratios compare like
with like.

    python benchmarks/mixed_newton.py [--n2 40] [--n3 10] [--repeat 3]
"""
import os
import time

import numpy as np
import scipy.sparse as sp
import skfem as fem

import skfem_pg as pg
from skfem_pg import materials as mat
from skfem_pg.formulations.by_name import model_for
from harness import (demo_parser, markdown_table, update_results)

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)),
                       "README.md")
MATERIAL = mat.NeoHookeIsoVol(mu=1.0, K=1e3)
INCOMPRESSIBLE = mat.NeoHookeIsoVol.incompressible(1.0)

#: label -> (thesis name of the basis, formulation token)
METHODS = [("FE", "Q1P0"), ("VCPBG Unl", "Unl"), ("VCPBG UnlP0", "UnlP0"),
           ("VCPPG Unl", "Unl"), ("VCPPG UnlP0", "UnlP0"),
           ("VCPBG IUnlP0", "IUnlP0"), ("VCPBG Unl+P1C", "Unl+P1C"),
           ("VCPBG U2", "U2"), ("VCPBG U2P1", "U2P1"),
           ("VCPBG U2P1C", "U2P1C")]


def node_set(dim, n):
    cls = fem.MeshQuad if dim == 2 else fem.MeshHex
    m = cls.init_tensor(*[np.linspace(0, 1, n + 1)] * dim)
    return pg.meshing.distort(m, 0.3, seed=1)


def basis_of(mesh, dim, name, token):
    if name == "FE":
        E = fem.ElementQuad1() if dim == 2 else fem.ElementHex1()
        return fem.Basis(mesh, fem.ElementVector(E), intorder=2)
    return pg.FamilyBasis.from_name(mesh, name, dim=dim)


def deformation(basis, model, dim):
    """A smooth deformation (a few percent strain) at the dof locations
    (interleaved components, as scikit-fem numbers them), the model's
    initial extras."""
    x = model.initial()
    X = np.asarray(basis.doflocs)  # (dim, N)
    c = np.arange(model.n_u) % dim
    u = np.choose(c, [0.02 * np.sin(2 * X[1]) + 0.01 * X[0] ** 2,
                      -0.015 * X[0] * X[1],
                      0.01 * np.cos(X[0] + X[1])][:dim])
    x[:model.n_u] = u
    return x


def best(f, repeat):
    t, out = np.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = f()
        t = min(t, time.perf_counter() - t0)
    return t, out


def one_iteration(mesh, dim, name, token, repeat):
    m = INCOMPRESSIBLE if token == "IUnlP0" else MATERIAL
    if name == "FE":
        token = "Q1P0" if dim == 2 else "H1P0"
    basis = basis_of(mesh, dim, name, token)
    model = model_for(token, basis, m)
    x = deformation(basis, model, dim)
    D = np.flatnonzero(np.isclose(np.repeat(mesh.p[0], dim), 0.0))
    free = np.setdiff1d(np.arange(model.N), D)
    t = {}
    t["state"], s = best(lambda: model.state(x), repeat)
    t["force"], r = best(lambda: model.internal_force(s), repeat)
    t["tangent"], K = best(lambda: model.tangent(s), repeat)
    Kff = sp.csr_matrix(K)[free][:, free]
    t["solve"], du = best(lambda: pg.solvers.direct(Kff, -r[free]), repeat)
    t["total"] = sum(t.values())
    label = token if name == "FE" else name.split()[-1]
    if "PPG" in name:
        label = "PPG " + label
    return label, model.N, K.nnz, t


def main(n2=40, n3=10, repeat=3):
    print(pg.threads.describe())
    sections = []
    for dim, n in ((2, n2), (3, n3)):
        mesh = node_set(dim, n)
        rows, times = [], {}
        for name, token in METHODS:
            label, N, nnz, t = one_iteration(mesh, dim, name, token, repeat)
            times[label] = t
            rows.append((label, N, nnz, t))
            print(dim, label, N, nnz, {k: round(v, 3) for k, v in t.items()},
                  flush=True)
        fe = "Q1P0" if dim == 2 else "H1P0"
        table = markdown_table(
            ["method", "unknowns", "nnz(K)", "state [s]", "force [s]",
             "tangent [s]", "solve [s]", "total [s]", "/ PBG Unl",
             "/ PBG U2", "/ " + fe],
            [[label, N, nnz] + ["{:.3f}".format(t[k]) for k in
                                ("state", "force", "tangent", "solve",
                                 "total")]
             + ["{:.2f}".format(t["total"] / times[ref]["total"])
                for ref in ("Unl", "U2", fe)]
             for label, N, nnz, t in rows])
        print(table)
        sections.append("{}-D, {} particles ({}{} ±0.3h distorted {}):\n\n"
                        .format(dim, mesh.nvertices, n,
                                "²" if dim == 2 else "³",
                                "quads" if dim == 2 else "hexahedra")
                        + table)
    print("updated", update_results(
        RESULTS, "mixed_newton",
        "`python benchmarks/mixed_newton.py --n2 {} --n3 {} --repeat {}`: "
        "one Newton iteration (state, internal force, tangent, direct "
        "solve with the x = 0 face clamped) of each formulation at the same "
        "smooth deformation, iso/vol neo-Hooke K = 1e3 mu (IUnlP0: nu = "
        "0.5); fastest of {} runs per phase.\n\n".format(n2, n3, repeat,
                                                          repeat)
        + "\n\n".join(sections)))


if __name__ == "__main__":
    ap = demo_parser(__doc__)
    ap.add_argument("--n2", type=int, default=40,
                    help='elements per side of the distorted unit square (2-D)')
    ap.add_argument("--n3", type=int, default=10,
                    help='elements per side of the distorted unit cube (3-D)')
    ap.add_argument("--repeat", type=int, default=3,
                    help='runs per phase; the fastest counts')
    args = ap.parse_args()
    main(args.n2, args.n3, args.repeat)
