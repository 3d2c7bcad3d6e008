"""The census of inputs a user gets wrong (issues 28 and 47): each input
runs in its own process with a time limit and its outcome is classed.

The classes:

* ``correct`` — the right answer (or the right warning);
* ``named`` — an error whose message names the culprit (every token the
  case lists: a parameter, a driver, a boundary);
* ``bare`` — any other error (scikit-fem's, NumPy's, a ``KeyError``);
* ``silent`` — an answer without an error that is not the right one;
* ``hang`` — the time limit ran out;
* ``data loss`` — a file that mattered is unreadable afterwards.

The cases are issue 47's inputs (``source="issue 47"``: resume paths,
scenes and the reference cache, the registry, laws and controls,
scikit-fem scripts on a ``FamilyBasis``, the ``sn`` resultant) and inputs
of our own beside them (``source="own"``).  Each case is a script that
sets ``result``; ``ok`` is the expression on ``result`` (and ``said``, the
warnings' messages) that is true for the right answer, ``None`` where
only an error is right.  The code under test is whatever ``skfem_pg``
the interpreter imports, or the source tree given by ``--root`` (e.g. a
``git worktree`` of an earlier commit for the "before" column).

    python benchmarks/census.py [--root DIR] [--only ID ...] [--json F]
        [--compare BEFORE.json [--label TEXT]]

``--compare`` prints the classes before (a JSON of an earlier run) and
after side by side and writes them into ``benchmarks/README.md``
(section ``census``).
"""
import collections
import json
import os
import subprocess
import sys
import tempfile
import textwrap

CLASSES = ("correct", "named", "bare", "silent", "hang", "data loss")

#: the code every case starts from: small problems, built lazily
PRELUDE = '''
import os, warnings
import numpy as np
import skfem as fem
import skfem_pg as pg
from skfem_pg import materials as mat
from skfem_pg.formulations import model_for
from skfem_pg.solvers import checkpoint, lumped_mass

def strip(nx=8, ny=2, L=4.0):
    return fem.MeshQuad.init_tensor(
        np.linspace(0, L, nx + 1), np.linspace(0, 1, ny + 1)
    ).with_boundaries({"left": lambda x: np.isclose(x[0], 0),
                       "right": lambda x: np.isclose(x[0], L)})

def bar():
    basis = pg.FamilyBasis(strip(10, 2, 3.0), dim=2)
    D = basis.get_dofs("left").all()
    v0 = np.zeros(basis.N)
    v0[0::2] = 0.05 * basis.doflocs[0, 0::2]
    return basis, D, v0

def unl(basis):
    return model_for("Unl", basis, mat.NeoHookeIsoVol(mu=40.0, K=80.0))

def two_triangulations(n=4):
    quads = fem.MeshQuad.init_tensor(*(np.linspace(0, 1, n),) * 2)
    q = quads.t
    return (fem.MeshTri(quads.p, np.hstack([q[[0, 1, 2]], q[[0, 2, 3]]])),
            fem.MeshTri(quads.p, np.hstack([q[[0, 1, 3]], q[[1, 2, 3]]])))

TMP = os.environ["CENSUS_TMP"]
'''

#: runs one case: prints one JSON line after the marker
RUNNER = '''
import json, sys, warnings
code, ok = json.load(open(sys.argv[1]))
ns = {}
out = {}
with warnings.catch_warnings(record=True) as seen:
    warnings.simplefilter("always")
    try:
        exec(compile(code, "<case>", "exec"), ns)
    except BaseException as err:
        out["error"] = type(err).__name__
        out["message"] = str(err)[:600]
said = [str(w.message) for w in seen
        if not issubclass(w.category, DeprecationWarning)]
ns["said"] = said
import skfem_pg
out["module"] = skfem_pg.__file__
if "error" not in out:
    out["result"] = repr(ns.get("result"))[:200]
    try:
        out["ok"] = bool(eval(ok, ns)) if ok else False
    except BaseException as err:
        out["ok"] = False
        out["check"] = "{}: {}".format(type(err).__name__, err)[:300]
print("@@CENSUS@@" + json.dumps(out))
'''


def case(id, group, source, code, names, ok=None, data=False):
    """One input: ``names`` the tokens a named error contains (case
    insensitive), ``ok`` the right answer's test, ``data`` whether a wrong
    answer means a lost file."""
    return dict(id=id, group=group, source=source,
                code=textwrap.dedent(code), names=names, ok=ok, data=data)


I47, OWN = "issue 47", "own"
CASES = [
    # -- resume paths -----------------------------------------------------
    case("explicit-resumed-by-newton", "resume", I47, """
        from skfem_pg.solvers import central_difference, newton
        basis, D, v0 = bar()
        ck = checkpoint.Every(os.path.join(TMP, "dyn"), steps=5)
        central_difference(unl(basis), lumped_mass(basis, 1.0), 0.3, D=D,
                           v0=v0, verbose=False, checkpoint=ck)
        u, hist = newton(unl(basis), D=D, resume=ck.path)
        result = len(hist)
        """, ["explicit", "newton"]),
    case("save-load-1.5", "resume", I47, """
        basis, D, v0 = bar()
        p = checkpoint.save(os.path.join(TMP, "x"), unl(basis),
                            np.zeros(basis.N), 1.5)
        from skfem_pg.solvers import newton
        u, hist = newton(unl(basis), D=D, resume=p)
        result = len(hist)
        """, ["load"]),
    case("save-load-nan", "resume", I47, """
        basis, D, v0 = bar()
        p = checkpoint.save(os.path.join(TMP, "x"), unl(basis),
                            np.zeros(basis.N), float("nan"))
        from skfem_pg.solvers import newton
        u, hist = newton(unl(basis), D=D, resume=p)
        result = len(hist)
        """, ["load"]),
    case("crack-on-other-triangulation", "resume", I47, """
        from skfem_pg.formulations import CrackAware
        a, b = two_triangulations(7)
        steel = mat.J2Plasticity.from_young(
            200e3, 0.29, hardening=mat.JohnsonCookHardening(792.0, 510.0, 0.26),
            damage=mat.JohnsonCookDamage(0.05, 3.44, -2.12, 0.3))
        model = CrackAware(pg.FamilyBasis(a, dim=2, families="mesh"), steel)
        u = np.zeros(model.N)
        st = model.state(u)
        model.commit(st)
        c = a.p[:, a.t].mean(axis=1)
        one = np.zeros(a.nelements, dtype=bool)
        one[np.argmin(np.hypot(c[0] - 0.5, c[1] - 0.5))] = True
        model.update(u, np.array(st["F"]), one)
        path = checkpoint.save(os.path.join(TMP, "crack"), model, u, 0.5)
        other = CrackAware(pg.FamilyBasis(b, dim=2, families="mesh"), steel)
        checkpoint.load(path, other)
        result = None
        """, ["cells"]),
    case("static-resumed-by-central-difference", "resume", I47, """
        from skfem_pg.solvers import central_difference, newton
        basis, D, v0 = bar()
        ck = checkpoint.Every(os.path.join(TMP, "st"), steps=1)
        f = np.zeros(basis.N)
        f[basis.get_dofs("right").nodal["u^1"]] = 0.01
        newton(unl(basis), f, D=D, checkpoint=ck)
        central_difference(unl(basis), lumped_mass(basis, 1.0), 0.3, D=D,
                           verbose=False, resume=ck.path)
        result = None
        """, ["static", "explicit"]),
    case("plain-npz-as-checkpoint", "resume", I47, """
        basis, D, v0 = bar()
        np.savez(os.path.join(TMP, "results.npz"), u=np.zeros(basis.N))
        checkpoint.load(os.path.join(TMP, "results.npz"), unl(basis))
        result = None
        """, ["not a skfem-pg checkpoint"]),
    case("save-wrong-length", "resume", I47, """
        basis, D, v0 = bar()
        checkpoint.save(os.path.join(TMP, "x"), unl(basis),
                        np.zeros(basis.N + 2), 0.5)
        result = None
        """, ["unknowns"]),
    case("save-infinite-x", "resume", OWN, """
        basis, D, v0 = bar()
        checkpoint.save(os.path.join(TMP, "x"), unl(basis),
                        np.full(basis.N, np.inf), 0.5)
        result = None
        """, ["finite"]),
    case("failed-save-keeps-the-old-file", "resume", OWN, """
        basis, D, v0 = bar()
        model = unl(basis)
        p = checkpoint.save(os.path.join(TMP, "keep"), model,
                            np.zeros(basis.N), 0.25)
        try:
            checkpoint.save(os.path.join(TMP, "keep"), model,
                            np.full(basis.N + 1, 1.0), 0.5)
        except Exception:
            pass
        try:
            result = checkpoint.load(p, unl(basis))[1]
        except Exception as err:  # the file that mattered is gone
            result = repr(err)
        """, ["never"], ok="result == 0.25", data=True),
    case("checkpoint-of-another-mesh-size", "resume", OWN, """
        basis, D, v0 = bar()
        p = checkpoint.save(os.path.join(TMP, "m"), unl(basis),
                            np.zeros(basis.N), 0.5)
        other = pg.FamilyBasis(strip(12, 2, 3.0), dim=2)
        checkpoint.load(p, unl(other))
        result = None
        """, ["another model", "unknowns"]),
    # -- scenes and the reference cache ------------------------------------
    case("clamped-and-moved", "scene", I47, """
        from skfem_pg.scenes import Scene
        sc = Scene("both", strip(), mat.NeoHooke(lam=10.0, mu=4.0),
                   clamped=["right"], prescribed={"right": {0: 0.1}})
        sc.setup("PG")
        result = None
        """, ["right", "clamped", "prescribed"]),
    case("component-out-of-range", "scene", I47, """
        from skfem_pg.scenes import Scene
        sc = Scene("bad", strip(), mat.NeoHooke(lam=10.0, mu=4.0),
                   clamped=["left"], prescribed={"right": {2: 0.1}})
        sc.setup("PG")
        result = None
        """, ["component 2"]),
    case("prescribed-nan", "scene", OWN, """
        from skfem_pg.scenes import Scene
        sc = Scene("bad", strip(), mat.NeoHooke(lam=10.0, mu=4.0),
                   clamped=["left"], prescribed={"right": {0: float("nan")}})
        sc.setup("PG")
        result = None
        """, ["finite"]),
    case("corner-shared-with-two-values", "scene", OWN, """
        from skfem_pg.scenes import Scene
        m = strip().with_boundaries({
            "left": lambda x: np.isclose(x[0], 0),
            "bottom": lambda x: np.isclose(x[1], 0)})
        sc = Scene("c", m, mat.NeoHooke(lam=10.0, mu=4.0),
                   prescribed={"left": {1: 0.0}, "bottom": {1: 0.2}})
        sc.setup("PG")
        result = None
        """, ["different values"]),
] + [
    case("cache-key-" + what, "scene", I47, """
        from skfem_pg.scenes import Scene
        def key(A=792.0, D1=0.05, sy=None):
            if sy is None:
                law = mat.J2Plasticity(
                    mu=80.0, K=160.0,
                    hardening=mat.JohnsonCookHardening(A, 510.0, 0.26),
                    damage=mat.JohnsonCookDamage(D1, 3.44, -2.12, 1.0))
            else:
                law = mat.J2Plasticity(mu=80.0, K=160.0, sigma_y0=sy,
                                        H=0.13)
            sc = Scene("law", strip(), law, clamped=["left"],
                       prescribed={"right": {0: 0.01}})
            return sc.fingerprint(2, "Q2", {"tol": 1e-9})
        result = key(**%s) != key(**%s)
        """ % (a, b), ["never"], ok="result")
    for what, a, b in (("A-one-ulp", "{}", "{'A': np.nextafter(792.0, 800)}"),
                       ("A-792.00008", "{}", "{'A': 792.00008}"),
                       ("D1-0.05000001", "{}", "{'D1': 0.05000001}"),
                       ("sy0-0.4500001", "{'sy': 0.45}",
                        "{'sy': 0.4500001}"))
] + [
    # -- registry and builder --------------------------------------------
    case("register-fe-name", "registry", I47, """
        from skfem_pg.formulations import Hyperelastic
        calls = []
        def build(basis, material, tangent):
            calls.append(1)
            return Hyperelastic(basis, material, tangent=tangent)
        pg.register_formulation("Q1", "MTE1", build)
        from skfem_pg.scenes import Scene
        sc = Scene("q", strip(), mat.NeoHooke(lam=10.0, mu=4.0), clamped=["left"],
                   tractions={"right": [0.0, 0.01]})
        sc.setup("Q1")
        result = calls
        """, ["Q1", "FE"], ok="result"),
    case("register-ul-builder", "registry", I47, """
        from skfem_pg.formulations import Hyperelastic
        calls = []
        def build(basis, material, tangent):
            calls.append(1)
            return Hyperelastic(basis, material, tangent=tangent)
        pg.register_formulation("MyUL", "MTE1", build,
                                updated_lagrangian=True)
        from skfem_pg.scenes import Scene
        sc = Scene("u", strip(), mat.NeoHooke(lam=10.0, mu=5.0), clamped=["left"],
                   tractions={"right": [0.0, 0.1]}, steps=2)
        sc.setup("VCPBG V5m MyUL UL")
        result = calls
        """, ["updated_lagrangian"], ok="result"),
    case("register-wrong-signature", "registry", I47, """
        pg.register_formulation("Two", "MTE1", lambda basis, material: 0)
        from skfem_pg.scenes import Scene
        sc = Scene("t", strip(), mat.NeoHooke(lam=10.0, mu=4.0), clamped=["left"],
                   tractions={"right": [0.0, 0.01]})
        sc.setup("VCPBG V5m Two")
        result = None
        """, ["build", "tangent"]),
    case("from-spec-of-another-dim", "registry", I47, """
        from skfem_pg.discretization.builder import BasisSpec
        sq = fem.MeshTri.init_tensor(*(np.linspace(0, 1, 5),) * 2)
        spec = BasisSpec.resolve(pg.Particles.from_mesh(sq), dim=2)
        cube = pg.Particles.from_mesh(fem.MeshTet.init_tensor(
            *(np.linspace(0, 1, 3),) * 3))
        result = pg.FamilyBasis.from_spec(cube, spec).ncomp
        """, ["dim=2", "3-D"], ok="result == 3"),
    case("nan-area-vectors", "registry", I47, """
        sq = fem.MeshTri.init_tensor(*(np.linspace(0, 1, 5),) * 2)
        p = pg.Particles.from_mesh(sq)
        A = p.area_vectors().copy()
        A[0, 3] = np.nan
        pg.FamilyBasis(p, dim=2, area_vectors=A)
        result = None
        """, ["area", "particle 3"]),
    case("vc-tolerance-negative", "registry", I47, """
        sq = fem.MeshTri.init_tensor(*(np.linspace(0, 1, 5),) * 2)
        pg.FamilyBasis(sq, dim=2, vc_tolerance=-1.0)
        result = None
        """, ["vc_tolerance", "got -1"]),
    case("vc-tolerance-string", "registry", OWN, """
        sq = fem.MeshTri.init_tensor(*(np.linspace(0, 1, 5),) * 2)
        pg.FamilyBasis(sq, dim=2, vc_tolerance="1e-8")
        result = None
        """, ["vc_tolerance", "'1e-8'"]),
    case("register-not-callable", "registry", OWN, """
        pg.register_formulation("Nope", "MTE1", 3.0)
        result = None
        """, ["build", "callable"]),
    # -- laws and controls -------------------------------------------------
    case("jc-damage-d2-zero-steep-d3", "laws", I47, """
        d = mat.JohnsonCookDamage(0.3, 0.0, -300.0, 1.0)
        t = np.array([-5.0, -1.0, 0.0, 1.0 / 3.0, 2.0])
        result = d.failure_strain(t)
        """, ["never"], ok="np.all(result == 0.3)"),
    case("jc-damage-d1-negative-d2-zero", "laws", I47, """
        mat.JohnsonCookDamage(-0.1, 0.0, -2.0, 1.0)
        result = None
        """, ["D1", "D2"]),
    case("newmark-gamma-0.3", "laws", I47, """
        from skfem_pg.solvers import NewmarkControls
        NewmarkControls(gamma=0.3)
        result = None
        """, ["gamma"]),
    case("newmark-beta-inf", "laws", I47, """
        from skfem_pg.solvers import NewmarkControls
        NewmarkControls(beta=float("inf"))
        result = None
        """, ["beta"]),
    case("explicit-safety-3", "laws", I47, """
        from skfem_pg.solvers import ExplicitControls
        ExplicitControls(safety=3.0)
        result = None
        """, ["safety"]),
    case("newton-ten-million-steps", "laws", I47, """
        from skfem_pg.solvers import NewtonControls
        NewtonControls(steps=10_000_000)
        result = None
        """, ["steps", "min_step"]),
    case("bond-horizon-inf", "laws", I47, """
        from skfem_pg.formulations.bond_based import BondBased
        b = pg.FamilyBasis(fem.MeshQuad.init_tensor(
            *(np.linspace(0, 1, 9),) * 2), dim=2)
        BondBased(b, 1.0, horizon=np.inf)
        result = None
        """, ["horizon"]),
    case("bond-horizon-body-spanning", "laws", I47, """
        from skfem_pg.formulations.bond_based import BondBased
        b = pg.FamilyBasis(fem.MeshQuad.init_tensor(
            *(np.linspace(0, 1, 9),) * 2), dim=2)
        BondBased(b, 1.0, horizon=100.0, absolute=True)
        result = None
        """, ["horizon", "body"]),
    case("bond-on-element-subset", "laws", I47, """
        from skfem_pg.formulations.bond_based import BondBased
        m = fem.MeshTri.init_tensor(*(np.linspace(0, 1, 9),) * 2)
        part = pg.FamilyBasis(pg.Particles.from_mesh(
            m, elements=np.arange(20)), dim=2)
        BondBased(part, 1.0)
        result = None
        """, ["volume"]),
    case("vtu-series-empty-folder", "laws", I47, """
        from skfem_pg.io import VTUSeries
        os.chdir(TMP)
        VTUSeries("")
        result = None
        """, ["folder"]),
    case("explicit-safety-zero", "laws", OWN, """
        from skfem_pg.solvers import ExplicitControls
        ExplicitControls(safety=0.0)
        result = None
        """, ["safety"]),
    case("newmark-beta-negative", "laws", OWN, """
        from skfem_pg.solvers import NewmarkControls
        NewmarkControls(beta=-0.25)
        result = None
        """, ["beta"]),
    case("bond-horizon-nan", "laws", OWN, """
        from skfem_pg.formulations.bond_based import BondBased
        b = pg.FamilyBasis(fem.MeshQuad.init_tensor(
            *(np.linspace(0, 1, 9),) * 2), dim=2)
        BondBased(b, 1.0, horizon=float("nan"))
        result = None
        """, ["horizon"]),
    # -- scikit-fem scripts on a FamilyBasis --------------------------------
    case("ex26-element-dofs-by-cells", "scikit-fem", I47, """
        sq = fem.MeshTri.init_tensor(*(np.linspace(0, 1, 5),) * 2)
        b = pg.FamilyBasis(sq)
        result = b.element_dofs[:, np.array([0, 3])]
        """, ["families", "nodal_dofs"], ok=None),
    case("ex17-cell-values-on-a-circle", "scikit-fem", I47, """
        from skfem_pg.discretization.coefficients import cell_values_at_members
        c = fem.MeshTri.init_circle(4)
        b = pg.FamilyBasis(c)
        k = np.where(np.hypot(*c.p[:, c.t].mean(axis=1)) < 0.5, 10.0, 1.0)
        result = cell_values_at_members(b, k)
        """, ["never"], ok="np.all(np.isfinite(result))"),
    case("ex17-p0-interpolated", "scikit-fem", I47, """
        from skfem.helpers import dot, grad
        sq = fem.MeshQuad.init_tensor(*(np.linspace(0, 1, 5),) * 2)
        b = pg.FamilyBasis(sq)
        @fem.BilinearForm
        def cond(u, v, w):
            return w.k * dot(grad(u), grad(v))
        k = fem.Basis(sq, fem.ElementQuad0()).interpolate(np.ones(16))
        result = cond.assemble(b, k=k)
        """, ["cell_values_at_members"], ok=None),
    case("ex17-wx-on-the-interface", "scikit-fem", I47, """
        from skfem.helpers import dot, grad
        m = fem.MeshQuad.init_tensor(*(np.linspace(0, 1, 33),) * 2)
        b = pg.FamilyBasis(m)
        P = fem.Basis(m, fem.ElementQuad1()).probes(np.array([[0.5], [0.5]]))
        def solve(cut):
            @pg.BilinearForm
            def cond(u, v, w):
                return np.where(w.x[0] < cut, 1.0, 10.0) * dot(grad(u), grad(v))
            @pg.LinearForm
            def heat(v, w):
                return 1.0 * v
            return (P @ fem.solve(*fem.condense(cond.assemble(b), heat.assemble(b),
                                                D=b.get_dofs())))[0]
        result = solve(0.5 - 1e-9) / solve(0.5 + 1e-9) - 1
        """, ["never"], ok="abs(result) < 0.01"),
    case("ex21-p2-element", "scikit-fem", I47, """
        m = fem.MeshTri.init_tensor(*(np.linspace(0, 1, 5),) * 2)
        result = pg.FamilyBasis(m, fem.ElementTriP2()).N
        """, ["element", "dim"], ok=None),
    case("literal-swap-element", "scikit-fem", I47, """
        m = fem.MeshTri.init_tensor(*(np.linspace(0, 1, 5),) * 2)
        result = pg.FamilyBasis(m, fem.ElementTriP1()).N
        """, ["element", "dim"], ok="result == m.nvertices"),
    case("intorder-keyword", "scikit-fem", I47, """
        m = fem.MeshTri.init_tensor(*(np.linspace(0, 1, 5),) * 2)
        result = pg.FamilyBasis(m, intorder=4).N
        """, ["intorder=4", "famil"], ok=None),
    case("ex38-point-source", "scikit-fem", I47, """
        m = fem.MeshTri.init_tensor(*(np.linspace(0, 1, 5),) * 2)
        p1 = fem.Basis(m, fem.ElementTriP1())
        x = np.array([0.3, 0.2])
        result = np.abs(pg.FamilyBasis(m).point_source(x)
                        - p1.point_source(x)).max()
        """, ["never"], ok="result < 1e-14"),
    case("ex38-project-shape", "scikit-fem", I47, """
        m = fem.MeshTri.init_tensor(*(np.linspace(0, 1, 5),) * 2)
        pg.FamilyBasis(m).project(lambda x: np.vstack([x[0], x[1]]))
        result = None
        """, ["(dim, n)"]),
    case("ex13-p2-facet-basis", "scikit-fem", I47, """
        m = fem.MeshTri.init_tensor(*(np.linspace(0, 1, 5),) * 2)
        b = pg.FamilyBasis(m)
        u = b.project(lambda x: x[0])
        fb = fem.FacetBasis(m, fem.ElementTriP2())
        result = fem.Functional(lambda w: w.u).assemble(
            fb, u=fb.interpolate(u))
        """, ["FamilyBasis"], ok="abs(result - 2.0) < 1e-12"),
    case("ex13-basis-boundary", "scikit-fem", OWN, """
        m = fem.MeshTri.init_tensor(*(np.linspace(0, 1, 5),) * 2)
        b = pg.FamilyBasis(m)
        fb = b.boundary()
        result = fem.Functional(lambda w: w.u).assemble(
            fb, u=fb.interpolate(b.project(lambda x: x[0])))
        """, ["never"], ok="abs(result - 2.0) < 1e-12"),
    case("with-element", "scikit-fem", OWN, """
        m = fem.MeshTri.init_tensor(*(np.linspace(0, 1, 5),) * 2)
        pg.FamilyBasis(m).with_element(fem.ElementDG(fem.ElementTriP1()))
        result = None
        """, ["particle_fields"]),
    case("point-source-on-vector-basis", "scikit-fem", OWN, """
        m = fem.MeshTri.init_tensor(*(np.linspace(0, 1, 5),) * 2)
        pg.FamilyBasis(m, dim=2).point_source(np.array([0.3, 0.2]))
        result = None
        """, ["vector"]),
    case("element-dofs-by-cell-list", "scikit-fem", OWN, """
        m = fem.MeshQuad.init_tensor(*(np.linspace(0, 1, 5),) * 2)
        b = pg.FamilyBasis(m, dim=2)
        result = b.element_dofs[:, [1, 2]]
        """, ["families", "nodal_dofs"], ok=None),
    case("cell-values-wrong-length", "scikit-fem", OWN, """
        from skfem_pg.discretization.coefficients import cell_values_at_members
        m = fem.MeshQuad.init_tensor(*(np.linspace(0, 1, 5),) * 2)
        cell_values_at_members(pg.FamilyBasis(m), np.ones(15))
        result = None
        """, ["16"]),
    # -- solvers and drivers (own) --------------------------------------------
    case("central-difference-dt-above-limit", "solvers", OWN, """
        from skfem_pg.solvers import central_difference
        basis, D, v0 = bar()
        tr = central_difference(unl(basis), lumped_mass(basis, 1.0), 0.3,
                                D=D, v0=v0, dt=0.1, verbose=False)
        result = np.abs(tr.series("relative_error")).max()
        """, ["dt", "stable"], ok="result < 0.05"),
    case("newmark-linear-acceleration-dt-above-limit", "solvers", OWN, """
        from skfem_pg.solvers import newmark, stable_time_step
        basis, D, v0 = bar()
        m = lumped_mass(basis, 1.0)
        dt = 3 * stable_time_step(unl(basis), m, safety=1.0)
        tr = newmark(unl(basis), m, 60 * dt, dt, D=D, v0=v0, beta=1 / 6,
                     verbose=False)
        result = np.abs(tr.series("relative_error")).max()
        """, ["dt", "beta"], ok="result < 0.05"),
    case("factorization-nan-matrix", "solvers", OWN, """
        import scipy.sparse as sp
        from skfem_pg.solvers import Factorization
        A = sp.identity(4, format="csr")
        A.data[2] = np.nan
        result = Factorization(A).solve(np.ones(4))
        """, ["non-finite", "row 2"]),
    case("factorization-nan-load", "solvers", OWN, """
        import scipy.sparse as sp
        from skfem_pg.solvers import Factorization
        result = Factorization(sp.identity(3, format="csr")).solve(
            np.array([1.0, np.nan, 0.0]))
        """, ["non-finite", "right-hand side"]),
    case("factorization-dense", "solvers", OWN, """
        from skfem_pg.solvers import Factorization
        result = Factorization(2 * np.eye(3)).solve(np.ones(3))
        """, ["never"], ok="np.allclose(result, 0.5)"),
    case("probes-points-as-rows", "solvers", OWN, """
        m = fem.MeshTri.init_tensor(*(np.linspace(0, 1, 5),) * 2)
        result = pg.FamilyBasis(m).probes(
            np.array([[0.5, 0.5], [0.2, 0.5], [0.1, 0.1]]))
        """, ["(dim, n)", "x.T"]),
    case("newton-u0-nan", "solvers", OWN, """
        from skfem_pg.solvers import newton
        basis, D, v0 = bar()
        newton(unl(basis), np.zeros(basis.N), D=D,
               u0=np.full(basis.N, np.nan))
        result = None
        """, ["u0", "non-finite"]),
    case("mass-negative-density", "solvers", OWN, """
        basis, D, v0 = bar()
        lumped_mass(basis, -1.0)
        result = None
        """, ["rho"]),
    case("scene-unknown-boundary", "scene", OWN, """
        from skfem_pg.scenes import Scene
        Scene("x", strip(), mat.NeoHooke(lam=10.0, mu=4.0), clamped=["nope"])
        result = None
        """, ["nope"]),
    case("scene-traction-3-components-in-2d", "scene", OWN, """
        from skfem_pg.scenes import Scene
        Scene("x", strip(), mat.NeoHooke(lam=10.0, mu=4.0), clamped=["left"],
              tractions={"right": [0.0, 1.0, 0.0]}).solve("PG")
        result = None
        """, ["2 components"]),
    case("jc-hardening-negative-A", "laws", OWN, """
        mat.JohnsonCookHardening(-1.0, 510.0, 0.26)
        result = None
        """, ["A"]),
    case("vtu-into-a-missing-folder", "laws", OWN, """
        basis, D, v0 = bar()
        pg.write_vtu(os.path.join(TMP, "nodir", "x.vtu"), basis,
                     u=np.zeros(basis.N))
        result = None
        """, ["nodir"]),
    # -- the sn resultant -----------------------------------------------------
    case("sn-traction-resultant", "sn", I47, """
        mesh = pg.meshing.cook_membrane(8).with_boundaries(
            {"right": lambda x: np.isclose(x[0], 48.0)})
        basis = pg.FamilyBasis(mesh, dim=2, vc_boundary="sn")
        f = pg.traction(basis, "right", [0.0, 1.0])
        result = f.reshape(-1, 2).sum(axis=0)[1]
        """, ["never"],
         ok="abs(result - 16.0) < 1e-10 or any('min-norm' in s for s in said)"),
    case("s-traction-resultant", "sn", OWN, """
        m = fem.MeshTri.init_circle(3)
        mesh = m.with_boundaries({"rim": lambda x: x[1] > 0.5})
        basis = pg.FamilyBasis(mesh, dim=2, vc_boundary="s")
        f = pg.traction(basis, "rim", [1.0, 0.0])
        fe = pg.traction(fem.Basis(mesh, fem.ElementVector(fem.ElementTriP1())),
                         "rim", [1.0, 0.0])
        result = (f.reshape(-1, 2).sum(axis=0)[0], fe.reshape(-1, 2).sum(axis=0)[0])
        """, ["never"], ok="abs(result[0] - result[1]) < 1e-10 * abs(result[1])"
         " or any('min-norm' in s for s in said)"),
]


def run_case(c, root, timeout):
    """Runs one case in its own process; returns its class and details."""
    with tempfile.TemporaryDirectory() as tmp:
        spec = os.path.join(tmp, "case.json")
        with open(spec, "w") as f:
            json.dump([PRELUDE + c["code"], c["ok"]], f)
        env = dict(os.environ, CENSUS_TMP=tmp, MPLBACKEND="Agg",
                   PYTHONWARNINGS="ignore")
        if root:
            env["PYTHONPATH"] = os.path.abspath(root)
        try:
            proc = subprocess.run([sys.executable, "-c", RUNNER, spec],
                                  capture_output=True, text=True, env=env,
                                  timeout=timeout, cwd=tmp)
        except subprocess.TimeoutExpired:
            return dict(cls="hang")
    marker = [ln for ln in proc.stdout.splitlines()
              if ln.startswith("@@CENSUS@@")]
    if not marker:
        return dict(cls="bare", error="crash",
                    message=proc.stderr.strip()[-400:])
    out = json.loads(marker[-1][len("@@CENSUS@@"):])
    if "error" in out:
        text = (out["error"] + ": " + out["message"]).lower()
        named = all(t.lower() in text for t in c["names"])
        out["cls"] = "named" if named else "bare"
    elif out.get("ok"):
        out["cls"] = "correct"
    else:
        out["cls"] = "data loss" if c["data"] else "silent"
    return out


def counts(results, source=None):
    n = collections.Counter(r["cls"] for r in results
                            if source is None or r["source"] == source)
    return [n.get(k, 0) for k in CLASSES]


def compare_table(before, after, label, timeout):
    rows = []
    for src in ("issue 47", "own", None):
        for name, res in (("before", before), ("after", after)):
            rows.append(["all" if src is None else src, name]
                        + counts(res, src))
    from harness import markdown_table
    table = markdown_table(["inputs", "code"] + list(CLASSES), rows)
    changed = ["| {} | {} | {} | {} |".format(b["id"], b["source"],
                                              b["cls"], a["cls"])
               for b, a in zip(before, after)]
    intro = ("`python benchmarks/census.py --compare BEFORE.json`: {} inputs,"
             " each in its own process (time limit {:g} s); before: {}, "
             "after: this tree.".format(len(after), timeout, label))
    return (intro + "\n\n" + table
            + "\n\n| input | source | before | after |\n|---|---|---|---|\n"
            + "\n".join(changed))


def main():
    from harness import demo_parser
    p = demo_parser(__doc__, quick=False)
    p.add_argument("--root", help="source tree to import skfem_pg from")
    p.add_argument("--only", nargs="*", help="case ids")
    p.add_argument("--timeout", type=float, default=120.0,
                   help="seconds per input before it counts as a hang")
    p.add_argument("--json", help="write the outcomes here")
    p.add_argument("--compare", help="an earlier run's JSON (before)")
    p.add_argument("--label", default="an earlier run",
                   help="what the earlier run ran (for the table)")
    args = p.parse_args()
    chosen = [c for c in CASES if not args.only or c["id"] in args.only]
    results = []
    for i, c in enumerate(chosen, 1):
        out = run_case(c, args.root, args.timeout)
        out.update(id=c["id"], group=c["group"], source=c["source"])
        results.append(out)
        print("[{}/{}] {:40s} {:9s} {}".format(
            i, len(chosen), c["id"], out["cls"],
            (out.get("error", "") + ": " + out.get("message", "")
             if "error" in out else out.get("result", ""))[:110]
            .replace("\n", " ")), flush=True)
    print("classes:", dict(zip(CLASSES, counts(results))))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(results, f, indent=1)
    if args.compare:
        with open(args.compare) as f:
            before = {r["id"]: r for r in json.load(f)}
        pairs = [(before[r["id"]], r) for r in results if r["id"] in before]
        text = compare_table([b for b, _ in pairs], [a for _, a in pairs],
                             args.label, args.timeout)
        print(text)
        from harness import update_results
        update_results(os.path.join(os.path.dirname(
            os.path.abspath(__file__)), "README.md"), "census", text)


if __name__ == "__main__":
    main()
