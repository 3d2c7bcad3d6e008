"""FEM–PG coupling through shared nodes.

Part of a mesh is scikit-fem FE (Q1 or T1), the rest PG (VC PBG Unl).  Both
bases number dofs like scikit-fem's nodal P1/Q1 element, so the coupled
stiffness is the plain sum of the two matrices.  The PG particles get their
volumes lumped over the PG elements only, and their area vectors include the
FE–PG interface (FE-consistent), so the union passes the patch test.

1. Coupled linear patch test on ±0.3h distorted quads and triangles.
2. Cook's membrane (linear, plane stress, irregular nodes): Q1 left of
   x = 24, PG right of it, against pure Q1 and pure PG on the same nodes.

Prints the patch-test errors and the tip displacements with their errors
and times; writes out/coupling.png and coupling.vtu.

    python demos/coupling.py
"""
import os

import numpy as np
import skfem as fem

import skfem_pg as pg
from harness import demo_parser, output_dir
from skfem_pg.analysis import PATCH_GRADIENT_2D as GEX
from skfem_pg.materials import lame
from skfem_pg.formulations import linear_elasticity

from skfem_pg.scenes.reference import linear_cook

OUT = output_dir(create=False)  # --out, $SKFEM_PG_OUT or ./out


def coupled_bases(mesh, fe_side, dim=2, **kw):
    """FE basis on the elements where ``fe_side(x)`` holds, PG on the rest."""
    fe_el = mesh.elements_satisfying(fe_side)
    pg_el = np.setdiff1d(np.arange(mesh.nelements), fe_el)
    e1, _ = pg.particles.linear_elements(mesh)
    fe = fem.Basis(mesh, fem.ElementVector(e1), elements=fe_el)
    pgb = pg.FamilyBasis(pg.Particles.from_mesh(mesh, elements=pg_el),
                         dim=dim, **kw)
    return fe, pgb


def patch_test(kind):
    mesh = pg.meshing.distort(
        fem.MeshQuad.init_tensor(*[np.linspace(-1, 1, 21)] * 2), 0.3, seed=3)
    if kind == "tri":
        mesh = mesh.to_meshtri()
    lam, mu = lame(100.0, 0.3)
    form = linear_elasticity(lam, mu)
    eps = 0.5 * (GEX + GEX.T)
    sigma = 2 * mu * eps + lam * np.trace(eps) * np.eye(2)
    uex = (GEX @ mesh.p).T.ravel()
    top = mesh.facets_satisfying(lambda x: np.isclose(x[1], 1))
    out = {}
    for label, kw in (("VC PBG Unl", {}), ("PBG Unl (no VC)", {"vc": None})):
        fe, pgb = coupled_bases(mesh, lambda x: x[0] < 0, **kw)
        K = form.assemble(fe) + pg.assemble(form, pgb)
        f = pg.stress_load(pgb, top, sigma)
        D = fe.get_dofs(lambda x: np.isclose(np.abs(x[0]), 1) |
                        np.isclose(x[1], -1))
        u = fem.solve(*fem.condense(K, f, x=uex, D=D))
        out[label] = np.abs(u - uex).max()
    return out


#: Cook's membrane: E = 1, nu = 1/3, plane stress (as demos/cook_membrane.py)
COOK_LAM, COOK_MU = lame(1.0, 1.0 / 3.0, plane_stress=True)
COOK_FORM = linear_elasticity(COOK_LAM, COOK_MU)


def cook(n=32, ref_sizes=(64, 128)):
    ref, _ = linear_cook(COOK_LAM, COOK_MU, ref_sizes)
    mesh = pg.meshing.distort(pg.meshing.cook_membrane(n), 0.3, seed=n)
    mesh = mesh.with_boundaries({"left": lambda x: np.isclose(x[0], 0),
                                 "right": lambda x: np.isclose(x[0], 48)})
    dof = 2 * pg.meshing.vertex_at(mesh, (48.0, 52.0)) + 1
    q1 = fem.Basis(mesh, fem.ElementVector(fem.ElementQuad1()))
    D = q1.get_dofs("left")
    fb = fem.FacetBasis(mesh, fem.ElementVector(fem.ElementQuad1()),
                        facets="right")
    f = fem.LinearForm(lambda v, w: v[1] / 16.0).assemble(fb)
    res = {}
    res["Q1"] = fem.solve(*fem.condense(COOK_FORM.assemble(q1), f, D=D))
    pure = pg.FamilyBasis(pg.Particles.from_mesh(mesh), dim=2)
    res["VC PBG Unl"] = fem.solve(*fem.condense(
        pg.assemble(COOK_FORM, pure), f, D=D))
    fe, pgb = coupled_bases(mesh, lambda x: x[0] < 24)
    K = COOK_FORM.assemble(fe) + pg.assemble(COOK_FORM, pgb)
    res["Q1 | PG coupled"] = fem.solve(*fem.condense(K, f, D=D))
    return mesh, res, dof, ref, fe, pgb


def main(quick=False):
    print("coupled linear patch test, max nodal error (FE x < 0, PG x >= 0):")
    for kind in ("quad", "tri"):
        for label, err in patch_test(kind).items():
            print("  {:4s} FE + {:16s} {:.3e}".format(
                "Q1" if kind == "quad" else "T1", label, err))
    n = 8 if quick else 32
    mesh, res, dof, ref, fe, pgb = cook(n, (16, 32) if quick else (64, 128))
    print("\nCook's membrane, irregular {0}x{0} nodes, reference v(48,52) = "
          "{1:.4f}".format(n + 1, ref))
    for name, u in res.items():
        print("  {:16s} v = {:.4f}  rel. error {:.2e}".format(
            name, u[dof], abs(u[dof] - ref) / ref))
    os.makedirs(OUT, exist_ok=True)
    plot(mesh, res["Q1 | PG coupled"], fe, pgb,
         os.path.join(OUT, "coupling.png"))
    pg.write_vtu(os.path.join(OUT, "coupling.vtu"), pgb.particles,
                 displacement=res["Q1 | PG coupled"],
                 pg_particle=pgb.particles.active.astype(float))
    print("\nwrote " + OUT + "/coupling.png and coupling.vtu")
    return res


def plot(mesh, u, fe, pgb, fn):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import PolyCollection
    U = u.reshape(-1, 2).T
    x = mesh.p + U
    fig, ax = plt.subplots(figsize=(6, 6))
    polys = [x[:, mesh.t[:, e]].T for e in fe.tind]
    ax.add_collection(PolyCollection(polys, facecolor="0.85",
                                     edgecolor="0.4", lw=0.4,
                                     label="Q1 elements"))
    act = pgb.particles.active
    sc = ax.scatter(x[0, act], x[1, act], c=np.linalg.norm(U[:, act], axis=0),
                    s=8, cmap="viridis", label="PG particles")
    fig.colorbar(sc, ax=ax, label="|u|")
    ax.set_aspect("equal")
    ax.autoscale()
    ax.legend(loc="upper left")
    ax.set_title("Cook's membrane: Q1 (left) coupled to PG (right), "
                 "deformed")
    fig.tight_layout()
    fig.savefig(fn, dpi=120)


if __name__ == "__main__":
    ap = demo_parser(__doc__)
    a = ap.parse_args()
    OUT = output_dir(a.out)
    main(a.quick)
