"""scikit-fem's gallery with the basis swapped (issue 45, item 4): three
of its examples on their own meshes, FE against the PG default and the
moment quadrature (MQ) on the same nodes, against overkills.

* ``ex03`` — the linear elastic eigenvalue problem (a 5 x 1 strip of
  49 x 9 quadrilaterals, clamped on the left, lambda = mu = 1, unit
  density): the six lowest eigenvalues against Q2 on the mesh refined
  three times; FE with the consistent and the lumped mass matrix (PG's
  is diagonal, the particle volumes);
* ``ex11`` — linear elasticity on the unit cube of hexahedra (E = 1000,
  nu = 0.3), the right face pulled by 0.3 and the left clamped: the
  strain energy against H2 on the cube refined three times (the example's
  own mesh, 729 nodes, is the finest node set);
* ``ex22`` — Poisson with a unit load on the L-shaped domain (the
  example refines it adaptively; here uniformly, 2 to 4 times): the
  compliance f.u against P2 on the domain refined seven times.

Signed errors in %; one table per example into ``benchmarks/README.md``
and ``docs/guide/accuracy.md`` (sections ``gallery_*``).

    python benchmarks/gallery.py [--examples ex03 ex11 ex22]
"""
import numpy as np
import scipy.sparse as sp
import skfem as fem
from skfem.helpers import ddot, dot, eye, sym_grad, trace
from skfem.models.elasticity import lame_parameters
from skfem.models.poisson import laplace, unit_load

import skfem_pg as pg
from harness import demo_parser, markdown_table, update_results
from recipes_2d import RESULTS

#: PG variants: column name -> FamilyBasis keywords
VARIANTS = {"PG default": {},
            "PG MQ": dict(shape="WTE2", family_quadrature="moments")}


def write(name, text):
    for page in RESULTS:
        print("updated", update_results(page, "gallery_" + name, text))


def elasticity(lam, mu):
    def C(T):
        return 2.0 * mu * T + lam * eye(trace(T), T.shape[0])
    return fem.BilinearForm(lambda u, v, w: ddot(C(sym_grad(u)),
                                                 sym_grad(v)))


def assemble(form, basis):
    return (pg.assemble(form, basis) if isinstance(basis, pg.FamilyBasis)
            else form.assemble(basis))


def signed(values, reference):
    return ["{:+.2f}".format(v) for v in 100 * (values / reference - 1)]


def refinement_rows(label, meshes, measure, fe_basis, dim, reference):
    """A row per mesh: its nodes and the signed errors of ``measure(basis,
    mesh)`` with ``fe_basis(mesh)`` and each of :data:`VARIANTS`."""
    rows = []
    for m in meshes:
        bases = [fe_basis(m)] + [pg.FamilyBasis(m, dim=dim, **kw)
                                 for kw in VARIANTS.values()]
        rows.append([m.nvertices] + signed(
            np.array([measure(b, m) for b in bases]), reference))
        print(label, rows[-1], flush=True)
    return rows


# -- ex03 ----------------------------------------------------------------
def ex03():
    stiffness = elasticity(1.0, 1.0)
    mass = fem.BilinearForm(lambda u, v, w: dot(u, v))
    mesh = (fem.MeshLine(np.linspace(0, 5, 50))
            * fem.MeshLine(np.linspace(0, 1, 10))).with_defaults()

    def eigenvalues(basis, m, lumped=False):
        M = assemble(mass, basis)
        if lumped:
            M = sp.diags(np.asarray(M.sum(axis=1)).ravel()).tocsr()
        D = basis.get_dofs(m.facets_satisfying(lambda x: x[0] < 1e-9))
        L, _ = fem.solve(*fem.condense(assemble(stiffness, basis), M,
                                       D=D.flatten()),
                         solver=fem.solver_eigen_scipy_sym(k=6, sigma=0.0))
        return L

    refs = [eigenvalues(fem.Basis(mesh.refined(r), fem.ElementVector(
        fem.ElementQuad2())), mesh.refined(r)) for r in (2, 3)]
    q1 = fem.Basis(mesh, fem.ElementVector(fem.ElementQuad1()), intorder=2)
    rows = [["Q1"] + signed(eigenvalues(q1, mesh), refs[1]),
            ["Q1, lumped mass"] + signed(eigenvalues(q1, mesh, True),
                                         refs[1])]
    for name, kw in VARIANTS.items():
        b = pg.FamilyBasis(mesh, dim=2, **kw)
        rows.append([name] + signed(eigenvalues(b, mesh), refs[1]))
    for r in rows:
        print("ex03", r, flush=True)
    write("ex03", "`python benchmarks/gallery.py --examples ex03`: the six "
          "lowest eigenvalues on the example's {} nodes, signed error in % "
          "against Q2 on the mesh refined three times ({:.1e} from twice)."
          "\n\n".format(mesh.nvertices, np.abs(refs[0] / refs[1] - 1).max())
          + markdown_table(["method"] + ["mode {}".format(k + 1)
                                         for k in range(6)], rows))


# -- ex11 ----------------------------------------------------------------
def ex11():
    form = elasticity(*lame_parameters(1e3, 0.3))

    def energy(basis, m):
        K = assemble(form, basis)
        right = basis.get_dofs(m.facets_satisfying(lambda x: x[0] > 1 - 1e-9))
        left = basis.get_dofs(m.facets_satisfying(lambda x: x[0] < 1e-9))
        u = np.zeros(basis.N)
        u[right.all("u^1")] = 0.3
        D = np.concatenate([right.flatten(), left.flatten()])
        u = fem.solve(*fem.condense(K, x=u, D=D))
        return u @ (K @ u)

    h2 = [fem.MeshHex().refined(r) for r in (2, 3)]
    refs = [energy(fem.Basis(m, fem.ElementVector(fem.ElementHex2())), m)
            for m in h2]
    print("ex11 overkill", refs, flush=True)
    rows = refinement_rows(
        "ex11", [fem.MeshHex().refined(r) for r in (1, 2, 3)], energy,
        lambda m: fem.Basis(m, fem.ElementVector(fem.ElementHex1()),
                            intorder=3), 3, refs[1])
    write("ex11", "`python benchmarks/gallery.py --examples ex11`: strain "
          "energy, signed error in % against H2 on the cube refined three "
          "times ({:+.1e} from twice).\n\n".format(
              refs[0] / refs[1] - 1)
          + markdown_table(["nodes", "H1", *VARIANTS], rows))


# -- ex22 ----------------------------------------------------------------
def ex22():
    def compliance(basis, m):
        D = basis.get_dofs(m.boundary_facets()).flatten()
        f = assemble(unit_load, basis)
        u = fem.solve(*fem.condense(assemble(laplace, basis), f, D=D))
        return f @ u

    refs = [compliance(fem.Basis(m, fem.ElementTriP2()), m) for m in
            (fem.MeshTri.init_lshaped().refined(r) for r in (6, 7))]
    rows = refinement_rows(
        "ex22", [fem.MeshTri.init_lshaped().refined(r) for r in (2, 3, 4)],
        compliance, lambda m: fem.Basis(m, fem.ElementTriP1()), None,
        refs[1])
    write("ex22", "`python benchmarks/gallery.py --examples ex22`: "
          "compliance f.u, signed error in % against P2 on the domain "
          "refined seven times ({:+.1e} from six).\n\n".format(
              refs[0] / refs[1] - 1)
          + markdown_table(["nodes", "P1", *VARIANTS], rows))


EXAMPLES = {"ex03": ex03, "ex11": ex11, "ex22": ex22}

if __name__ == "__main__":
    ap = demo_parser(__doc__, quick=False)
    ap.add_argument("--examples", nargs="+", default=list(EXAMPLES),
                    choices=list(EXAMPLES), help="which examples to run")
    for name in ap.parse_args().examples:
        EXAMPLES[name]()
