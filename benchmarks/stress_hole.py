"""Stresses at a hole (issue 45, item 3): the particle stress a user gets
(:func:`skfem_pg.analysis.postprocess.particle_fields`) at a stress
concentration, against T1 / Q1 nodal averages on the same nodes.

Two problems (plane strain):

* ``kirsch`` — the exact solution: Kirsch's infinite plate with a circular
  hole (radius 1) under unit tension in x, on the quarter annulus
  1 <= r <= 5 with the exact displacements on r = 5 and symmetry on both
  axes (lambda = 1.5, mu = 1); polar grids, n cells radially (geometric
  spacing, near-square cells) and 2n around, as quadrilaterals and split
  into triangles (all diagonals one way), and gmsh triangles and
  quadrilaterals graded towards the hole.  Reported: sigma_xx at the
  particle (0, 1) (exact 3, the concentration factor) and the largest
  error of the hoop stress over the hole's particles, in % of 3;
* ``ellipse`` — a quarter plate 10 x 10 with an elliptic hole (semi-axes 2
  in x, 1 in y) pulled in y; gmsh meshes graded towards the hole's tip,
  triangles and recombined quadrilaterals.  Reference: T2 on curved
  (second-order) elements, graded finer; sigma_yy at the tip (2, 0) and at
  the ligament point (2.05, 0), where node values are read through the
  mesh's linear interpolation (what ParaView shows).  The tip is a vertex
  of the node set's polygon, a re-entrant corner of angle pi + h / rho:
  its exact stress is singular, weakly; T2 on a fixed polygon, refined,
  shows it (last table).

Errors are signed, in %.  Tables into ``benchmarks/README.md`` and
``docs/guide/accuracy.md`` (sections ``stress_hole_*``; ``--quick`` only
prints).

    python benchmarks/stress_hole.py [--problems kirsch ellipse] [--quick]
"""
import warnings

import numpy as np
import skfem as fem

import skfem_pg as pg
from skfem_pg.analysis import kirsch_displacement
from skfem_pg.analysis.postprocess import particle_fields
from skfem_pg.formulations import linear_elasticity
from skfem_pg.materials import LinearElastic
from harness import demo_parser, markdown_table, update_results
from recipes_2d import RESULTS, occ_mesh, on
from recipes_2d import _dirichlet as dirichlet

#: the PG variants: the default, and the moment quadrature
VARIANTS = {"PG default": {},
            "PG MQ": dict(shape="WTE2", family_quadrature="moments")}
QUICK = False


def write(name, text):
    if QUICK:  # seconds-long node sets: printed, not written
        print(text)
        return
    for page in RESULTS:
        print("updated", update_results(page, "stress_hole_" + name, text))


def fe_nodal_average(mesh, elem, u, stress):
    """Unweighted average over the cells at each vertex of the FE stress
    ``stress(grad)`` evaluated at the cells' corners, ``(n, components)``
    (the components of ``stress``'s leading axes, flattened)."""
    corners = mesh.init_refdom().p
    b = fem.Basis(mesh, fem.ElementVector(elem),
                  quadrature=(corners, np.ones(corners.shape[1])))
    s = stress(b.interpolate(u).grad)  # (..., cells, corners)
    t = mesh.t[:corners.shape[1]].T
    return np.moveaxis(np.stack([
        np.bincount(t.ravel(), si.ravel(), minlength=mesh.nvertices)
        for si in s.reshape(-1, *t.shape)]), 0, -1) / np.bincount(
            t.ravel(), minlength=mesh.nvertices)[:, None]


def solve(K, f, D, x=None):
    return fem.solve(*fem.condense(K, f, x=x, D=D),
                     solver=pg.solvers.direct)


# -- Kirsch --------------------------------------------------------------
LAM, MU = 1.5, 1.0
R_OUT = 5.0


def polar_grid(n, triangles):
    m = fem.MeshQuad.init_tensor(R_OUT ** np.linspace(0, 1, n + 1),
                                 np.linspace(0, np.pi / 2, 2 * n + 1))
    m = fem.MeshQuad(np.array([m.p[0] * np.cos(m.p[1]),
                               m.p[0] * np.sin(m.p[1])]), m.t)
    return m.to_meshtri() if triangles else m


def stress_tensor(g):
    eps = 0.5 * (g + np.swapaxes(g, 0, 1))
    return 2 * MU * eps + LAM * (eps[0, 0] + eps[1, 1]) * np.eye(2).reshape(
        (2, 2) + (1,) * (g.ndim - 2))


def kirsch_errors(mesh, sigma):
    """(tip error, largest hoop error over the hole) in %, from node
    stresses ``sigma`` ``(n, 2, 2)``."""
    tip = int(np.argmin(np.hypot(mesh.p[0], mesh.p[1] - 1)))
    hole = np.nonzero(np.abs(np.hypot(*mesh.p) - 1) < 1e-9)[0]
    t = np.arctan2(mesh.p[1, hole], mesh.p[0, hole])
    s = sigma[hole]
    hoop = (s[:, 0, 0] * np.sin(t) ** 2 + s[:, 1, 1] * np.cos(t) ** 2
            - 2 * s[:, 0, 1] * np.sin(t) * np.cos(t))
    return (100 * (sigma[tip, 0, 0] / 3 - 1),
            100 * np.abs(hoop - (1 - 2 * np.cos(2 * t))).max() / 3)


def kirsch_solve(basis, mesh):
    x = mesh.p
    outer = np.nonzero(np.hypot(*x) > R_OUT - 1e-9)[0]
    D = np.unique(np.concatenate([
        2 * outer, 2 * outer + 1,
        2 * np.nonzero(np.abs(x[1]) < 1e-12)[0] + 1,
        2 * np.nonzero(np.abs(x[0]) < 1e-12)[0]]))
    xd = np.zeros(basis.N)
    xd[2 * outer], xd[2 * outer + 1] = kirsch_displacement(x[:, outer],
                                                           LAM, MU)
    K = pg.assemble(linear_elasticity(LAM, MU), basis)
    return solve(K, np.zeros(basis.N), D, x=xd)


def quarter_annulus(occ):
    disk, _ = occ.cut([(2, occ.addDisk(0, 0, 0, R_OUT, R_OUT))],
                      [(2, occ.addDisk(0, 0, 0, 1, 1))])
    occ.intersect(disk, [(2, occ.addRectangle(0, 0, 0, 2 * R_OUT,
                                              2 * R_OUT))])


def gmsh_annulus(h, quad):
    """gmsh cells of size h r / 4 (graded towards the hole)."""
    return occ_mesh(quarter_annulus, h, quad=quad,
                    size_at=lambda x, y: min(1.0, 0.25 * np.hypot(x, y)))


#: Kirsch node sets: label -> (mesh of a size, sizes, quick sizes)
KIRSCH_NODE_SETS = {
    "the polar grid split into triangles":
        (lambda n: polar_grid(n, True), (8, 16, 32, 64), (4, 8)),
    "the polar grid (quadrilaterals)":
        (lambda n: polar_grid(n, False), (8, 16, 32, 64), (4, 8)),
    "gmsh triangles, graded":
        (lambda h: gmsh_annulus(h, False), (0.4, 0.2, 0.1, 0.05), (0.4,)),
    "gmsh quadrilaterals, graded":
        (lambda h: gmsh_annulus(h, True), (0.4, 0.2, 0.1, 0.05), (0.4,)),
}


def kirsch_study(quick):
    material = LinearElastic(lam=LAM, mu=MU)
    parts = []
    for label, (make, sizes, quick_sizes) in KIRSCH_NODE_SETS.items():
        rows = []
        for size in quick_sizes if quick else sizes:
            mesh = make(size)
            elem = pg.particles.linear_elements(mesh)[0]
            fe = fem.Basis(mesh, fem.ElementVector(elem))
            avg = fe_nodal_average(mesh, elem, kirsch_solve(fe, mesh),
                                   stress_tensor).reshape(-1, 2, 2)
            row = [mesh.nvertices, *kirsch_errors(mesh, avg)]
            for kw in VARIANTS.values():
                b = pg.FamilyBasis(mesh, dim=2, **kw)
                sig = particle_fields(b, material, kirsch_solve(b, mesh))
                row += kirsch_errors(mesh, sig["cauchy"].reshape(
                    -1, 3, 3)[:, :2, :2])
            rows.append(row)
            print("kirsch", label, row, flush=True)
        fe_name = "T1" if isinstance(mesh, fem.MeshTri) else "Q1"
        head = ["nodes"] + ["{} {}".format(v, q) for v in
                            [fe_name + " nodal avg.", *VARIANTS]
                            for q in ("tip", "max hoop")]
        parts.append("**{}**\n\n".format(label[0].upper() + label[1:])
                     + markdown_table(head, [
                         [r[0]] + ["{:+.2f}".format(v) if i % 2 == 0
                                   else "{:.2f}".format(v)
                                   for i, v in enumerate(r[1:])]
                         for r in rows]))
    write("kirsch", "`python benchmarks/stress_hole.py --problems kirsch`"
          ": the exact solution; sigma_xx at the hole's top (exact 3) "
          "and the largest hoop-stress error over the hole's particles, "
          "in % of 3.\n\n" + "\n\n".join(parts))


# -- the elliptic hole -----------------------------------------------------
A, B, L = 2.0, 1.0, 10.0
E_LAM, E_MU = 100.0, 40.0
LIGAMENT = np.array([[A, A + 0.05], [0.0, 0.0]])


def ellipse_plate(occ):
    loop = occ.addCurveLoop([occ.addEllipse(0, 0, 0, A, B)])
    occ.cut([(2, occ.addRectangle(0, 0, 0, L, L))],
            [(2, occ.addPlaneSurface([loop]))])


def graded(size, quad=False, order=1, fine=0.1):
    return occ_mesh(ellipse_plate, size, quad=quad, order=order,
                    size_at=lambda x, y: min(1.0, fine + 0.25 * np.hypot(
                        x - A, y)))


def syy(g):
    eps = 0.5 * (g + np.swapaxes(g, 0, 1))
    return 2 * E_MU * eps[1, 1] + E_LAM * (eps[0, 0] + eps[1, 1])


def ellipse_solve(basis, mesh):
    K = pg.assemble(linear_elasticity(E_LAM, E_MU), basis)
    top = mesh.facets_satisfying(on(1, L))
    if isinstance(basis, pg.FamilyBasis):
        f = pg.traction(basis, top, [0.0, 1.0])
    else:
        f = fem.LinearForm(lambda v, w: v[1]).assemble(
            fem.FacetBasis(mesh, basis.elem, facets=top))
    D = dirichlet(basis, mesh, [(on(0, 0), (0,)), (on(1, 0), (1,))])
    return solve(K, f, D)


def point_stress(mesh, elem, u, points):
    """sigma_yy of an FE solution at ``points`` (the cells' own field)."""
    finder = (fem.MeshTri(mesh.p, mesh.t) if isinstance(mesh, fem.MeshTri2)
              else mesh).element_finder()
    cells = finder(*points)
    local = mesh.mapping().invF(points[:, :, None], tind=cells)[:, :, 0]
    out = []
    for j, c in enumerate(cells):
        b = fem.Basis(mesh, fem.ElementVector(elem), elements=np.array([c]),
                      quadrature=(local[:, j:j + 1], np.ones(1)))
        out.append(syy(b.interpolate(u).grad)[0, 0])
    return np.array(out)


def node_tip_stress(mesh, elem, u):
    """sigma_yy of an FE solution at the tip vertex, averaged over its
    cells (the reference: T2, whose average converges)."""
    return fe_nodal_average(mesh, elem, u, lambda g: syy(g)[None])[
        int(np.argmin(np.hypot(mesh.p[0] - A, mesh.p[1]))), 0]


def read_points(mesh, nodal):
    """Node values read at the tip and the ligament point through the
    mesh's linear interpolation."""
    elem = pg.particles.linear_elements(mesh)[0]
    return fem.Basis(mesh, elem).probes(LIGAMENT) @ nodal


def ellipse_study(sizes, ref_sizes):
    refs = []
    for s in ref_sizes:
        m = graded(s, order=2, fine=0.02)
        u = ellipse_solve(fem.Basis(m, fem.ElementVector(
            fem.ElementTriP2())), m)
        refs.append((m.nvertices, node_tip_stress(m, fem.ElementTriP2(), u),
                     point_stress(m, fem.ElementTriP2(), u,
                                  LIGAMENT[:, 1:])[0]))
        print("reference", refs[-1], flush=True)
    (n0, tip0, lig0), (n1, tip, lig) = refs
    ref = np.array([tip, lig])
    material = LinearElastic(lam=E_LAM, mu=E_MU)
    parts = []
    for quad in (False, True):
        rows = []
        for s in sizes:
            mesh = graded(s, quad=quad)
            elem = pg.particles.linear_elements(mesh)[0]
            u = ellipse_solve(fem.Basis(mesh, fem.ElementVector(elem)), mesh)
            avg = fe_nodal_average(mesh, elem, u, lambda g: syy(g)[None])
            row = [mesh.nvertices, *(100 * (read_points(mesh, avg[:, 0])
                                            / ref - 1))]
            for kw in VARIANTS.values():
                b = pg.FamilyBasis(mesh, dim=2, **kw)
                sig = particle_fields(b, material, ellipse_solve(b, mesh))
                row += list(100 * (read_points(mesh, sig["cauchy"][:, 4])
                                   / ref - 1))
            rows.append(row)
            print("ellipse", "quad" if quad else "tri", row, flush=True)
        fe_name = "Q1" if quad else "T1"
        head = ["nodes"] + ["{} {}".format(v, q) for v in
                            [fe_name + " nodal avg.", *VARIANTS]
                            for q in ("tip", "x = 2.05")]
        parts.append("**{}**\n\n".format(
            "gmsh quadrilaterals" if quad else "gmsh triangles")
            + markdown_table(head, [[r[0]] + ["{:+.2f}".format(v)
                                              for v in r[1:]] for r in rows]))
    # the polygon's own corner: T2 on fixed node sets, refined
    rows = []
    for quad in (False, True):
        mesh = graded(sizes[len(sizes) // 2], quad=quad)
        elem = fem.ElementQuad2() if quad else fem.ElementTriP2()
        row = ["gmsh {}, {} nodes".format("quads" if quad else "triangles",
                                          mesh.nvertices)]
        for r in (1, 2, 3):
            m = mesh.refined(r)
            u = ellipse_solve(fem.Basis(m, fem.ElementVector(elem)), m)
            row.append("{:+.2f}".format(100 * (node_tip_stress(m, elem, u)
                                               / tip - 1)))
        rows.append(row)
        print("polygon", row, flush=True)
    write("ellipse", (
        "`python benchmarks/stress_hole.py --problems ellipse`: sigma_yy "
        "at the tip (Kt = {:.4f} against the remote unit traction) and at "
        "x = 2.05 on the ligament ({:.4f}), by T2 on curved elements, {} "
        "nodes ({:+.1e} and {:+.1e} to {} nodes); signed errors in %.\n\n"
        .format(tip, lig, n1, tip0 / tip - 1, lig0 / lig - 1, n0)
        + "\n\n".join(parts)
        + "\n\nThe tip of the node set's polygon is a corner: T2 on one "
        "node set's polygon, its cells split 2, 4, 8 times, reads a tip "
        "stress that keeps growing (against the curved Kt):\n\n"
        + markdown_table(["polygon", "split 2", "split 4", "split 8"],
                         rows)))


def main(problems, quick):
    global QUICK
    QUICK = quick
    warnings.filterwarnings("ignore", message="Indefinite matrix")
    if "kirsch" in problems:
        kirsch_study(quick)
    if "ellipse" in problems:
        ellipse_study((0.7, 0.35) if quick else (0.7, 0.5, 0.35, 0.25, 0.18),
                      (0.4, 0.3) if quick else (0.2, 0.14))


if __name__ == "__main__":
    ap = demo_parser(__doc__)
    choices = ["kirsch", "ellipse"]
    ap.add_argument("--problems", nargs="+", default=choices,
                    choices=choices, help="which problems to study")
    args = ap.parse_args()
    main(args.problems, args.quick)
