r"""
FE and particles in one model, coupled through shared nodes
===========================================================

A family basis collocated from some cells of a mesh numbers its unknowns
like scikit-fem's vector elements on the whole mesh, so an FE basis on the
other cells and the particle basis assemble into one matrix by ``+``.  Here
Q1 takes the left half of a distorted 48 × 12 strip and VC PBG Unl the
right half; the particles on the interface are shared.

The numbers it shows: the coupled model passes the linear patch test (the
exact linear field on the boundary, error inside at round-off, 1e-10 or
less), and the strip's end shear gives a tip deflection between those of
pure Q1 and pure PG on the same nodes.
"""
import os

import numpy as np
import skfem as fem

import skfem_pg as pg
from skfem_pg.formulations import linear_elasticity

STIFFNESS = linear_elasticity(lam=100.0, mu=40.0)
mesh = pg.meshing.distort(fem.MeshQuad.init_tensor(
    np.linspace(0, 48, 33), np.linspace(0, 12, 9)), 0.3, seed=3)
mesh = mesh.with_boundaries({"left": lambda x: x[0] == 0,
                             "right": lambda x: x[0] == 48})
left = mesh.elements_satisfying(lambda x: x[0] < 24)
right = mesh.elements_satisfying(lambda x: x[0] >= 24)
fe = fem.Basis(mesh, fem.ElementVector(fem.ElementQuad1()), elements=left)
pgb = pg.FamilyBasis(pg.Particles.from_mesh(mesh, elements=right), dim=2)
K = pg.assemble(STIFFNESS, fe) + pg.assemble(STIFFNESS, pgb)

# patch test: u = A x + b on the boundary, the same field inside
A, b = np.array([[1e-3, 2e-3], [-5e-4, 1.5e-3]]), np.array([0.1, -0.2])
exact = (A @ mesh.p + b[:, None]).T.ravel()  # interleaved, as scikit-fem
D = fe.get_dofs(mesh.boundary_facets())
boundary = np.union1d(D.flatten(), pgb.get_dofs(mesh.boundary_facets())
                      .flatten())
u = fem.solve(*fem.condense(K, np.zeros(K.shape[0]), x=exact, D=boundary))
patch = np.abs(u - exact).max() / np.abs(exact).max()
print("coupled patch test: max error {:.1e}".format(patch))

# the sheared strip: Q1 | PG against pure Q1 and pure PG on the same nodes
TIP = np.array([[48.0], [6.0]])


def tip(K, f, basis):
    u = fem.solve(*fem.condense(K, f, D=basis.get_dofs("left")))
    return (basis.probes(TIP) @ u)[1], u


q1 = fem.Basis(mesh, fem.ElementVector(fem.ElementQuad1()))
whole = pg.FamilyBasis(mesh, dim=2)
f = pg.traction(whole, "right", [0.0, 1.0 / 12])
w_coupled, u = tip(K, f, q1)
w_q1 = tip(pg.assemble(STIFFNESS, q1), f, q1)[0]
w_pg = tip(pg.assemble(STIFFNESS, whole), f, whole)[0]
print("tip deflection: Q1 {:.4f} | coupled {:.4f} | PG {:.4f}".format(
    w_q1, w_coupled, w_pg))

if __name__ == "__main__":
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 2.6))
    moved = fem.MeshQuad(mesh.p + 2 * u.reshape(-1, 2).T, mesh.t)
    for cells, color in ((left, "0.7"), (right, "C0")):
        for c in cells:
            ax.fill(*moved.p[:, moved.t[:, c]], color=color, ec="k", lw=0.3)
    ax.set_aspect("equal")
    ax.set_title("Q1 (grey) | VC PBG Unl (blue), displacements × 2")
    out = os.environ.get("SKFEM_PG_OUT", "out")
    os.makedirs(out, exist_ok=True)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "ex03_coupling.png"), dpi=120)
