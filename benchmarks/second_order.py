"""Second order on the vertices (issue 48, item 1): where the package's
quadratic PG (U2) loses its convergence rates, measured.

The manufactured solution of the thesis (7.7) on [-1, 1]^2 (E = 100e3,
nu = 0.3, full Dirichlet boundary), regular and +-0.3h distorted node
sets, triangles and quadrilaterals, against T1/Q1 and T2/Q2 (on the same
cells: T2 has about four times the unknowns).  Errors are relative: L2
at the vertices with the lumped volumes (the same measure for every
method), H1 with each method's own quadrature.

Rows: the package's U2 variants by their Table 7.1 names and two
candidates built here from the package's arrays (not part of the
package):

* ``PG2 candidate`` — the moment-matched quadrature of the WTE2 fit
  (``family_quadrature="moments"``) as the trial basis, and test
  derivatives corrected per particle so that the second-order
  integration constraints (the discrete divergence theorem for constant
  and linear stresses, ``vc2.vc2_residuals``' targets with the FE
  surface moments) hold exactly: ``G_t^{kai} = G^{kai} + theta^i .
  (1, (y^{ka} - X^i)/h)`` for every point ``a`` of every family ``k``
  holding ``i``, one ``(1 + d)``-square system per particle and component
  (the correction of Chen, Hillman and Rueter 2013 on PG's families):
  a Petrov-Galerkin pair, no global solve;
* ``PG2 blend`` — the families' quadratic fits blended by the collocation
  mesh's hat functions into one conforming function,
  ``u(x) = sum_k N_k(x) u_k(x)`` (shape functions ``psi_i = sum_k N_k
  phi_{k,i}``: they reproduce quadratics and are Kronecker at the
  vertices, since each fit interpolates its master), Galerkin with a cell
  rule of degree 4 (exact for the energy of a quadratic field), the
  Dirichlet boundary by symmetric Nitsche terms (penalty 20 (lambda +
  2 mu) / h; the fits of interior particles do not vanish on the
  boundary): first a prototype here, now the package's ``PG2``
  (:mod:`skfem_pg.discretization.blend`), which this row runs.

Second part: the adjoint consistency functional ``T(z) = sum_i z_i tau_i``
(``tau = K I(u) - f``, ``z`` smooth and zero on the boundary), split by the
particles' ring from the boundary: its order bounds the L2 rate (Aubin-
Nitsche).  Third: the candidates' quadratic patch tests and their zero
modes on a free body.  Fourth: the blend on tetrahedra against O2 with
the same unknowns.  Fifth: the blend's couplings per particle against
T2/O2's per node at the same unknowns, on triangles and tetrahedra.
Tables into ``benchmarks/README.md`` (sections ``second_order_*``).

    python benchmarks/second_order.py [--sizes 8 16 32] [--quick]
"""
import time

import numpy as np
import scipy.sparse as sp
import skfem as fem
from skfem.helpers import dot

import skfem_pg as pg
from harness import demo_parser, markdown_table, update_results
from skfem_pg.analysis.convergence import (PlaneWaves, rates,
                                           solve_manufactured)
from skfem_pg.formulations import (Hyperelastic, WeakDirichlet,
                                   linear_elasticity)
from skfem_pg.materials import LinearElastic, lame
from skfem_pg.naming import parse
from recipes_2d import RESULTS

FIELD = PlaneWaves.hillman2019()
LAM, MU = lame(100e3, 0.3)
#: the package's U2 variants (Table 7.1 names)
PACKAGE = ["VCPBG V3m U2", "VCPBG V3m U2 MQ", "VC2PBG V4m U2",
           "VC2PBG V4s U2"]
CANDIDATE = "PG2 candidate"
BLEND = "PG2 blend"


def node_set(n, kind, distortion):
    m = fem.MeshQuad.init_tensor(np.linspace(-1, 1, n + 1),
                                 np.linspace(-1, 1, n + 1))
    if distortion:
        m = pg.meshing.distort(m, distortion, seed=n)
    return m.to_meshtri() if kind == "tri" else m


def _errors(mesh, u_vertices, h1, field=FIELD):
    V = pg.Particles.from_mesh(mesh).volumes
    u_ex = field(mesh.p).T
    e = u_vertices.reshape(u_ex.shape) - u_ex
    l2 = np.sqrt(np.sum(V * (e ** 2).sum(1)) / np.sum(V * (u_ex ** 2).sum(1)))
    return {"nodes": mesh.nvertices, "L2": float(l2), "H1": float(h1)}


def fe(mesh, order, field=FIELD):
    """T1/Q1 (order 1) or T2/Q2 (order 2) on the node set's cells; O2 on
    tetrahedra."""
    e = {(1, fem.MeshTri): fem.ElementTriP1(),
         (1, fem.MeshQuad): fem.ElementQuad1(),
         (2, fem.MeshTri): fem.ElementTriP2(),
         (2, fem.MeshQuad): fem.ElementQuad2(),
         (2, fem.MeshTet): fem.ElementTetP2()}[order, type(mesh)]
    d = mesh.dim()
    t0 = time.perf_counter()
    basis = fem.Basis(mesh, fem.ElementVector(e), intorder=6 if d == 2
                      else 5)
    K = pg.assemble(linear_elasticity(LAM, MU), basis)
    b = field.body_force(LAM, MU)
    f = fem.LinearForm(lambda v, w: dot(b(w.x), v)).assemble(basis)
    x = field(basis.doflocs)[np.arange(basis.N) % d, np.arange(basis.N)]
    u = fem.solve(*fem.condense(K, f, x=x, D=basis.get_dofs()),
                  solver=pg.solvers.direct)
    seconds = time.perf_counter() - t0
    uh = basis.interpolate(u)
    g = field.grad(basis.global_coordinates().value)
    h1 = np.sqrt(np.sum(basis.dx * ((uh.grad - g) ** 2).sum((0, 1)))
                 / np.sum(basis.dx * (g ** 2).sum((0, 1))))
    out = _errors(mesh, u[basis.nodal_dofs].T.ravel(), h1, field)
    out.update(dofs=basis.N, seconds=seconds, nnz=K.nnz / basis.N)
    return out


def tetrahedra_table(sizes):
    """The blend on the unit cube of tetrahedra (``PlaneWaves(3)``, full
    Dirichlet) against O2 with the same unknowns (n/2 cells per side)."""
    field = PlaneWaves(3)
    rows, series = [], []
    for n in sizes:
        cube = fem.MeshTet.init_tensor(*(np.linspace(0, 1, n + 1),) * 3)
        half = fem.MeshTet.init_tensor(*(np.linspace(0, 1, n // 2 + 1),)
                                       * 3)
        b, o = blend(cube, field=field), fe(half, 2, field)
        series.append(b)
        rows.append([n, b["dofs"], "{:.2e}".format(b["L2"]),
                     "{:.2e}".format(o["L2"]),
                     "{:.2f}".format(b["L2"] / o["L2"]),
                     "{:.2e}".format(b["H1"]), "{:.2e}".format(o["H1"]),
                     "{:.2f}".format(b["H1"] / o["H1"]),
                     "{:.0f} / {:.0f}".format(b["nnz"], o["nnz"]),
                     "{:.1f} / {:.1f}".format(b["seconds"], o["seconds"])])
        print(" | ".join(map(str, rows[-1])), flush=True)
    h = [1.0 / np.cbrt(r["nodes"]) for r in series]
    text = markdown_table(["n", "unknowns", "L2 blend", "L2 O2", "ratio",
                           "H1 blend", "H1 O2", "ratio",
                           "nnz / row, blend / O2",
                           "seconds, blend / O2"], rows)
    if len(series) > 1:
        text += "\n\nRates of the blend: L2 {:.2f}, H1 {:.2f}.".format(
            rates(h, [r["L2"] for r in series])[0],
            rates(h, [r["H1"] for r in series])[0])
    return text


def surface_moments(mesh):
    """FE surface moments of the hat functions: ``A^i = int N_i n``
    ``(n, d)`` and ``A2^i = int N_i x_c n_B`` ``(n, c, B)``."""
    d = mesh.dim()
    fb = fem.FacetBasis(mesh, pg.particles.linear_elements(mesh)[0],
                        intorder=4)
    A = np.array([fem.LinearForm(lambda v, w, B=B: v * w.n[B])
                  .assemble(fb) for B in range(d)]).T
    A2 = np.array([[fem.LinearForm(lambda v, w, c=c, B=B: v * w.x[c]
                                   * w.n[B]).assemble(fb)
                    for B in range(d)] for c in range(d)])
    return A, np.moveaxis(A2, -1, 0)


def _per_particle(values, mem, mask, n):
    """Sum ``values`` ``(k, i, ...)`` over the families, per member
    particle ``i``: ``(n, ...)``."""
    flat = values[mask].reshape(mask.sum(), -1)
    out = np.zeros((n, flat.shape[1]))
    np.add.at(out, mem[mask], flat)
    return out.reshape((n,) + values.shape[2:])


def candidate_basis(mesh):
    """``(basis, G, Gt)``: the moment-quadrature WTE2 trial derivatives
    and the per-particle second-order corrected test derivatives (module
    docstring)."""
    p = pg.Particles.from_mesh(mesh)
    basis = pg.FamilyBasis(p, dim=2, shape="WTE2",
                           family_quadrature="moments", vc=None)
    mem, mask = basis.families.padded()
    G, w, y = basis.G, basis.dx, basis.points
    n, d, X, V = p.n, p.dim, p.x, p.volumes
    h = np.mean(V) ** (1.0 / d)
    A, A2 = surface_moments(mesh)
    rel = (y[:, :, None, :] - X.T[mem][:, None, :, :]) / h  # (k, a, i, c)
    P = np.concatenate([np.ones(rel.shape[:-1] + (1,)), rel], axis=-1)
    wG = w[:, :, None, None] * G  # (k, a, i, B)
    S = _per_particle(np.einsum("kair,kaiB->kirB", P, wG), mem, mask, n)
    target = np.concatenate([A[:, None, :], (
        A2 - X.T[:, :, None] * A[:, None, :]
        - V[:, None, None] * np.eye(d)) / h], axis=1)  # (n, 1+d, B)
    support = w[:, :, None] * mask[:, None, :]  # (k, a, i)
    M = _per_particle(np.einsum("kai,kair,kais->kirs", support, P, P),
                      mem, mask, n)
    theta = np.linalg.solve(M, target - S)  # (n, 1+d, B)
    dG = np.einsum("kair,kirB->kaiB", P, theta[mem]) \
        * (support > 0)[..., None]
    return basis, G, G + dG


def petrov_stiffness(basis, G, Gt):
    """``K[2i + p, 2j + q] = sum_k sum_a w_ka Gt^{kai}_B C_pBqD
    G^{kaj}_D`` (linear elasticity)."""
    mem, mask = basis.families.padded()
    I = np.eye(2)
    C = LAM * np.einsum("ab,cd->abcd", I, I) + MU * (
        np.einsum("ac,bd->abcd", I, I) + np.einsum("ad,bc->abcd", I, I))
    Ke = np.einsum("ka,kaiB,pBqD,kajD->kipjq", basis.dx, Gt, C, G)
    rows = 2 * mem[:, :, None, None, None] + np.arange(2)[:, None, None]
    cols = 2 * mem[:, None, None, :, None] + np.arange(2)
    keep = mask[:, :, None, None, None] & mask[:, None, None, :, None]
    rows, cols, keep = np.broadcast_arrays(rows, cols, keep)
    N = 2 * basis.particles.n
    return sp.csr_matrix((Ke[keep], (rows[keep], cols[keep])), shape=(N, N))


def moment_load(basis, b):
    """The moment quadrature's load: the hat functions' integrals of ``b``
    (each family's points carry its master's value)."""
    f = np.zeros((basis.particles.n, 2))
    f[basis.families.masters] = np.einsum(
        "ka,Bka->kB", basis.dx, b(np.moveaxis(basis.points, -1, 0)))
    return f.ravel()


def candidate(mesh):
    t0 = time.perf_counter()
    basis, G, Gt = candidate_basis(mesh)
    K = petrov_stiffness(basis, G, Gt)
    f = moment_load(basis, FIELD.body_force(LAM, MU))
    D = mesh.boundary_nodes()
    dofs = (2 * D[:, None] + np.arange(2)).ravel()
    u = fem.solve(*fem.condense(K, f, x=FIELD(mesh.p).T.ravel(), D=dofs))
    seconds = time.perf_counter() - t0
    mem, mask = basis.families.padded()
    U = u.reshape(-1, 2)[mem] * mask[..., None]
    gu = np.einsum("kaiB,kip->kapB", G, U)
    ge = np.moveaxis(FIELD.grad(np.moveaxis(basis.points, -1, 0)),
                     (0, 1), (2, 3))
    wq = basis.dx[..., None, None]
    h1 = np.sqrt(np.sum(wq * (gu - ge) ** 2) / np.sum(wq * ge ** 2))
    out = _errors(mesh, u, h1)
    out.update(dofs=2 * mesh.nvertices, seconds=seconds)
    return out


def blend(mesh, beta=20.0, field=FIELD):
    """The ``PG2 blend`` row: the package's PG2 (``FamilyBasis(mesh,
    dim=d, order=2)``, Dirichlet by :class:`~skfem_pg.formulations.
    WeakDirichlet` with penalty ``beta``), linear elastic."""
    t0 = time.perf_counter()
    d = mesh.dim()
    mesh = mesh.with_boundaries({"all": mesh.boundary_facets()})
    basis = pg.FamilyBasis(mesh, dim=d, order=2)
    model = WeakDirichlet(Hyperelastic(basis, LinearElastic(lam=LAM, mu=MU)),
                          {"all": field}, penalty=beta)
    b = field.body_force(LAM, MU)
    f = pg.assemble(fem.LinearForm(lambda v, w: dot(b(np.asarray(w.x)), v)),
                    basis) + model.load()
    s = model.state(np.zeros(basis.N))
    K = model.tangent(s)
    u = pg.solvers.direct(K, f - model.internal_force(s))
    seconds = time.perf_counter() - t0
    U = basis.interpolate(u)
    ge = field.grad(np.asarray(basis.global_coordinates()))
    h1 = np.sqrt(np.sum(basis.dx * ((U.grad - ge) ** 2).sum((0, 1)))
                 / np.sum(basis.dx * (ge ** 2).sum((0, 1))))
    out = _errors(mesh, u, h1, field)
    out.update(dofs=basis.N, seconds=seconds, nnz=K.nnz / basis.N)
    return out


def package(mesh, name):
    kw, _ = parse(name)
    kw.pop("dim", None)
    out = solve_manufactured(mesh, FIELD, LAM, MU, "PG", **kw)
    out["dofs"] = 2 * mesh.nvertices
    return out


def rate_table(kind, distortion, sizes):
    meshes = [node_set(n, kind, distortion) for n in sizes]
    fe1, fe2 = ("T1", "T2") if kind == "tri" else ("Q1", "Q2")
    runs = {fe1: lambda m: fe(m, 1), fe2: lambda m: fe(m, 2),
            BLEND: blend, CANDIDATE: candidate}
    runs.update({name: (lambda m, name=name: package(m, name))
                 for name in PACKAGE})
    rows, runs_done = [], {}
    for name, run in runs.items():
        series = []
        for m in meshes:
            if len(series) >= 2 and all("error" in r for r in series):
                series.append({"error": series[-1]["error"],
                               "skipped": True})  # refused twice: its
                continue  # minimum-norm LSQR takes minutes at n = 64
            try:
                series.append(run(m))
            except Exception as err:  # a refused correction: its message
                series.append({"error": "{}: {}".format(
                    type(err).__name__, str(err).split(";")[0][:90])})
        ok = [r for r in series if "error" not in r]
        h = [1.0 / np.sqrt(r["nodes"]) for r in ok]
        cells = ["{:.2e}".format(r["L2"]) if "error" not in r
                 else "not run" if r.get("skipped") else "refused"
                 for r in series]
        r2 = r1 = ""
        if len(ok) >= 2:
            r2 = "{:.2f}".format(rates(h, [r["L2"] for r in ok])[0])
            r1 = "{:.2f}".format(rates(h, [r["H1"] for r in ok])[0])
        last = series[-1]
        rows.append([name] + cells + [
            r2, "{:.2e}".format(last["H1"]) if "error" not in last else "",
            r1, last.get("error", "")])
        print(" | ".join(map(str, rows[-1])), flush=True)
        if name in (fe2, BLEND):
            runs_done[name] = series
    head = (["method"] + ["L2, n = {}".format(n) for n in sizes]
            + ["L2 rate", "H1, n = {}".format(sizes[-1]), "H1 rate",
               "note"])
    # the same unknowns: the blend on n x n cells, FE2 on n/2 x n/2
    same = []
    for i, n in enumerate(sizes[1:], 1):
        q = fe(node_set(n // 2, kind, distortion), 2)
        b = runs_done[BLEND][i]
        same.append([n, b["dofs"], "{:.2e}".format(b["L2"]),
                     "{:.2e}".format(q["L2"]),
                     "{:.2f}".format(b["L2"] / q["L2"]),
                     "{:.2e}".format(b["H1"]), "{:.2e}".format(q["H1"]),
                     "{:.2f}".format(b["H1"] / q["H1"]),
                     "{:.0f}".format(b["nnz"])])
    return (markdown_table(head, rows) + "\n\nThe same unknowns: {} on "
            "n x n cells against {} on n/2 x n/2 (its vertices and "
            "mid-edge nodes are the blend's vertices on a regular set):\n\n"
            .format(BLEND, fe2) + markdown_table(
                ["n", "unknowns", "L2 blend", "L2 " + fe2, "ratio",
                 "H1 blend", "H1 " + fe2, "ratio", "blend nnz / row"],
                same))


def rings(mesh, depth=4):
    """Each vertex's distance in edges from the boundary (``depth`` and
    beyond: ``depth``)."""
    ring = np.full(mesh.nvertices, depth)
    ring[mesh.boundary_nodes()] = 0
    a, b = mesh.facets
    for r in range(1, depth):
        prev = ring == r - 1
        near = np.union1d(b[prev[a]], a[prev[b]])
        near = near[ring[near] > r]
        ring[near] = r
    return ring


def adjoint_table(sizes):
    """``T(z)`` by ring: the uncorrected moment quadrature and the
    candidate on regular triangles."""
    rows = []
    for label in ("WTE2 MQ, no correction", CANDIDATE):
        vals = []
        for n in sizes:
            m = node_set(n, "tri", 0.0)
            if label == CANDIDATE:
                basis, G, Gt = candidate_basis(m)
            else:
                basis = pg.FamilyBasis(m, dim=2, shape="WTE2",
                                       family_quadrature="moments", vc=None)
                G = Gt = basis.G
            K = petrov_stiffness(basis, G, Gt)
            f = moment_load(basis, FIELD.body_force(LAM, MU))
            tau = (K @ FIELD(m.p).T.ravel() - f).reshape(-1, 2)
            x, y = m.p
            z = (np.sin(np.pi * (x + 1) / 2) * np.sin(np.pi * (y + 1) / 2)
                 * np.exp(0.7 * x - 0.4 * y))
            ring = rings(m)
            T = [np.abs((z[:, None] * tau)[ring == r].sum(0)).max()
                 / (LAM + 2 * MU) for r in (1, 2, 3, 4)]
            vals.append(T)
        vals = np.array(vals)
        order = np.log(vals[-2] / vals[-1]) / np.log(sizes[-1] / sizes[-2])
        for r, name in enumerate(("ring 1", "ring 2", "ring 3",
                                  "ring 4 and in")):
            rows.append([label, name] + ["{:.2e}".format(v)
                                         for v in vals[:, r]]
                        + ["{:.2f}".format(order[r])])
    return markdown_table(["basis", "particles"] + ["n = {}".format(n)
                                                    for n in sizes]
                          + ["order"], rows)


class _Quadratic:
    """A quadratic displacement field (the quadratic patch test)."""
    H = np.array([[[0.6, 0.2], [0.2, -0.2]], [[-0.4, 0.1], [0.1, 0.5]]])
    g0 = np.array([[0.2, -0.1], [0.1, 0.3]])

    def __call__(self, x):
        x = np.asarray(x, float)
        return (np.tensordot(self.g0, x, 1)
                + 0.5 * np.einsum("abc,b...,c...->a...", self.H, x, x))

    def grad(self, x):
        return self.g0.reshape(2, 2, *([1] * (np.ndim(x) - 1))) + \
            np.einsum("abc,c...->ab...", self.H, np.asarray(x, float))


def patch_and_modes(kind, distortion, n):
    """The candidate's quadratic patch test with traction on the whole
    boundary (max |K u - f| / max |f|) and its zero eigenvalues on the
    free body (relative to the largest)."""
    m = node_set(n, kind, distortion)
    basis, G, Gt = candidate_basis(m)
    K = petrov_stiffness(basis, G, Gt)
    q = _Quadratic()
    lap = np.einsum("abb->a", q.H)
    graddiv = np.einsum("bab->a", q.H)
    b0 = -MU * lap - (LAM + MU) * graddiv
    f = moment_load(basis, lambda x: b0.reshape(2, 1, 1)
                    * np.ones(x.shape[1:]))

    def traction(x, nrm):
        g = q.grad(x)
        eps = 0.5 * (g + np.swapaxes(g, 0, 1))
        sig = 2 * MU * eps + LAM * (eps[0, 0] + eps[1, 1]) * np.eye(2)[
            (...,) + (None,) * (x.ndim - 1)]
        return np.einsum("ab...,b...->a...", sig, nrm)
    fb = fem.FacetBasis(m, fem.ElementVector(
        pg.particles.linear_elements(m)[0]), intorder=4)
    f = f + fem.LinearForm(lambda v, w: dot(traction(w.x, w.n), v)) \
        .assemble(fb)
    residual = np.abs(K @ q(m.p).T.ravel() - f).max() / np.abs(f).max()
    ev = np.abs(np.linalg.eigvals(K.toarray()))
    ev = np.sort(ev) / ev.max()
    return residual, int(np.sum(ev < 1e-10)), ev[3]


def blend_patch_and_modes(kind, distortion, n):
    """The blend's quadratic patch test with traction on the whole
    boundary (no Nitsche terms) and its free body's zero eigenvalues."""
    m = node_set(n, kind, distortion)
    basis = pg.FamilyBasis(m, dim=2, order=2)
    q = _Quadratic()
    K = pg.assemble(linear_elasticity(LAM, MU), basis)
    b0 = -MU * np.einsum("abb->a", q.H) - (LAM + MU) * np.einsum("bab->a",
                                                                 q.H)
    f = pg.assemble(fem.LinearForm(lambda v, w: dot(b0, v)), basis)

    def traction(v, w):
        g = q.grad(np.asarray(w.x))
        eps = 0.5 * (g + np.swapaxes(g, 0, 1))
        sig = 2 * MU * eps + LAM * (eps[0, 0] + eps[1, 1]) * np.eye(2)[
            :, :, None, None]
        return dot(np.einsum("abeq,beq->aeq", sig, w.n), v)
    f = f + pg.assemble(fem.LinearForm(traction), basis.boundary())
    residual = np.abs(K @ q(m.p).T.ravel() - f).max() / np.abs(f).max()
    ev = np.sort(np.abs(np.linalg.eigvalsh(K.toarray())))
    ev = ev / ev.max()
    return residual, int(np.sum(ev < 1e-10)), ev[3]


def stencil(mesh):
    """Non-zeros per row of the blend's (scalar) matrix, per particle,
    and its families' mean size."""
    from skfem.models.poisson import mass
    basis = pg.FamilyBasis(mesh, order=2)
    return (pg.assemble(mass, basis).nnz / mesh.nvertices,
            float(basis.fits.mask.sum(1).mean()))


def stencil_table(sizes):
    """The blend's couplings per particle against FE2's per node at the
    same unknowns, 2-D and 3-D (regular grids of the unit square/cube)."""
    from skfem.models.poisson import mass
    rows = []
    for name, mk, e2 in (
            ("triangles", lambda n: fem.MeshTri.init_tensor(
                *(np.linspace(0, 1, n + 1),) * 2), fem.ElementTriP2()),
            ("tetrahedra", lambda n: fem.MeshTet.init_tensor(
                *(np.linspace(0, 1, n + 1),) * 3), fem.ElementTetP2())):
        for n in sizes:
            nnz, size = stencil(mk(n))
            b2 = fem.Basis(mk(n // 2), e2)
            M = mass.assemble(b2)
            rows.append([name, n, mk(n).nvertices, "{:.1f}".format(size),
                         "{:.0f}".format(nnz),
                         "{:.0f}".format(M.nnz / M.shape[0])])
    return markdown_table(["cells", "n", "particles", "mean family",
                           "blend: couplings / particle",
                           "FE2 on n/2: couplings / node"], rows)


def write(name, text):
    for page in RESULTS[:1]:
        print("updated", update_results(page, "second_order_" + name, text))


def main(sizes, quick=False):
    print(pg.threads.describe())
    intro = ("`python benchmarks/second_order.py --sizes {}`: the thesis' "
             "manufactured solution (7.7), full Dirichlet, relative errors "
             "(L2 at the vertices, lumped volumes; H1 with each method's "
             "quadrature); rates: least squares over the node sets; "
             "'refused': the correction raised ('not run' after two "
             "refusals).".format(
                 " ".join(map(str, sizes))))
    text = [intro]
    for kind in ("tri", "quad"):
        for distortion in (0.0, 0.3):
            print("\n{} node sets, distortion {}".format(kind, distortion))
            text.append("\n{}, {} node sets:\n".format(
                "triangles" if kind == "tri" else "quadrilaterals",
                "regular" if distortion == 0 else
                "+-{}h distorted".format(distortion)))
            text.append(rate_table(kind, distortion, sizes))
            if quick:
                break
        if quick:
            break
    print("\n".join(text))
    if not quick:
        write("rates", "\n".join(text))
    adjoint = adjoint_table(sizes)
    print(adjoint)
    checks = []
    for label, test in ((CANDIDATE, patch_and_modes),
                        (BLEND, blend_patch_and_modes)):
        for kind, distortion in (("tri", 0.3), ("quad", 0.3)):
            res, zeros, first = test(kind, distortion, 6)
            checks.append([label, kind, "{:.1e}".format(res), zeros,
                           "{:.1e}".format(first)])
    check = markdown_table(["basis", "cells (+-0.3h)",
                            "quadratic patch residual", "zero eigenvalues",
                            "next / largest"], checks)
    print(check)
    cube = tetrahedra_table([4] if quick else [4, 6, 8])
    print(cube)
    if not quick:
        write("tetrahedra", "`python benchmarks/second_order.py`: the "
              "blend on the unit cube of tetrahedra (n cells per side, "
              "PlaneWaves(3), full Dirichlet by Nitsche) against O2 on "
              "n/2 cells per side (the same unknowns); seconds: the "
              "package's PG2 (basis, assembly, Nitsche terms, solve).\n\n"
              + cube)
    couplings = stencil_table([4, 8] if quick else [8, 12])
    print(couplings)
    if not quick:
        write("stencil", "`python benchmarks/second_order.py`: the "
              "couplings per row of the blend (particles sharing a cell's "
              "families; times the components for non-zeros) against "
              "T2/O2 on n/2 x n/2 cells (the same unknowns).\n\n"
              + couplings)
    if not quick:
        write("adjoint", "`python benchmarks/second_order.py`: T(z) = "
              "sum_i z_i tau_i by the particles' ring from the boundary "
              "(regular triangles; tau = K I(u) - f, z = sin sin exp, zero "
              "on the boundary, relative to lambda + 2 mu); its order "
              "bounds the L2 rate.\n\n" + adjoint
              + "\n\nThe candidates on 7 x 7 node sets: the quadratic patch "
              "test with traction on the whole boundary and the free "
              "body's zero eigenvalues (3 rigid-body modes expected).\n\n"
              + check)


if __name__ == "__main__":
    ap = demo_parser(__doc__)
    ap.add_argument("--sizes", type=int, nargs="+", default=[8, 16, 32, 64],
                    help="cells per side of the node sets")
    args = ap.parse_args()
    main(args.sizes if not args.quick else [4, 8], quick=args.quick)
