"""Modified Newton against full Newton: the wall time of whole nonlinear
solves with ``NewtonControls.reuse`` (a tangent's factorization kept over
iterations and load steps while it contracts the residual by
``solvers.static.REUSE_CONTRACTION``) and without, FE and PG on the same
nodes, in the same run.

Problems: the 3-D Cook membrane of ``demos/cook_3d.py`` (neo-Hooke, 0.25
of its load in 2 steps, as ``benchmarks/newton_3d.py``) on gmsh tetrahedra;
an angle bracket of our own (``meshes/bracket.geo``: a base plate with two
bolt holes, clamped there, an upright with a hole pulled at its top face,
neo-Hooke, 4 steps); the necking bar of ``demos/necking.py`` (J2
plasticity, one eighth, its 10 adaptive steps); the 2-D punch of
``demos/punch.py`` pushed down until Newton fails (load step below
1e-3, as the demo; the compression reached is reported).  Reported: seconds, Newton
increments and fresh tangents (each one assembly and factorization), the
increments taken back, and the largest difference of the two answers.

    python benchmarks/factor_reuse.py [--quick] [--cook 1.6 1.0]
"""
import functools
import importlib.util
import os
import time

import numpy as np
import skfem as fem

import skfem_pg as pg
from harness import demo_parser, markdown_table, update_results
from skfem_pg.solvers import static

RESULTS = os.path.join(os.path.dirname(os.path.abspath(__file__)),
                       "README.md")
DEMOS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..",
                     "demos")


def demo(name):
    """``demos/NAME.py`` as a module."""
    spec = importlib.util.spec_from_file_location(
        name, os.path.join(DEMOS, name + ".py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


class Recorder:
    """``newton`` with ``reuse`` set, recording each call's history and
    answer (put in place of a module's ``newton``)."""

    def __init__(self, reuse):
        self.reuse, self.hist, self.x = reuse, [], None

    def __call__(self, *args, **kw):
        try:
            x, hist = pg.solvers.newton(*args, reuse=self.reuse, **kw)
        except pg.solvers.ConvergenceError as err:  # the punch's end
            self.hist += err.history
            self.x, self.load = err.u, err.load
            raise
        self.hist += hist
        self.x, self.load = x, 1.0
        return x, hist


def timed(solve, reuse):
    """``solve(newton)`` with full or modified Newton: seconds, the
    answer and the Newton history."""
    rec = Recorder(reuse)
    t0 = time.perf_counter()
    try:
        solve(rec)
    except pg.solvers.ConvergenceError:
        if not getattr(solve, "until_failure", False):
            raise
    return time.perf_counter() - t0, rec.x, rec.hist, rec.load


def scene_solve(sc, scheme, load=1.0, steps=None):
    """A solve of ``sc.setup(scheme)`` at ``load`` times its load."""
    def solve(newton):
        basis, model, f, D, u_D, _ = sc.setup(scheme)
        newton(model, load * f, D=D, u_D=lambda t: u_D(load * t),
               steps=steps or sc.steps, verbose=False)
    return solve


def cook(size):
    mesh = pg.meshing.from_geo(pg.meshing.geo_path("cook3d.geo"),
                               size=size)
    sc = demo("cook_3d").scene(mesh.with_boundaries(
        {"left": lambda x: np.isclose(x[0], 0),
         "right": lambda x: np.isclose(x[0], 48)}))
    return "3-D Cook, tets", mesh.nvertices, [
        (m, scene_solve(sc, m, load=0.25, steps=2)) for m in ("O1", "PG")]


#: the bracket's bolt holes (centres in the base plate, radius)
BOLTS = ((10.0, 19.0), (30.0, 19.0), 3.5)


def bracket(size):
    """The angle bracket: clamped on its bolt holes, its upright's top
    face pulled away from the base (y) by a dead traction."""
    mesh = pg.meshing.from_geo(pg.meshing.geo_path("bracket.geo"),
                               size=size)

    def bolts(x):
        r = np.min([np.hypot(x[0] - a, x[1] - b) for a, b in BOLTS[:2]],
                   axis=0)
        return (r < BOLTS[2] + 1e-6) & (x[2] < 5.0 + 1e-6)
    mesh = mesh.with_boundaries({"bolts": bolts,
                                 "top": lambda x: np.isclose(x[2], 35.0)})
    sc = pg.Scene("bracket", mesh, demo("cook_3d").MATERIAL,
                  clamped=["bolts"], tractions={"top": [0.0, -0.6, 0.0]},
                  steps=4)
    return "bracket (own), tets", mesh.nvertices, [
        (m, scene_solve(sc, m)) for m in ("O1", "PG")]


def necking(n):
    mod = demo("necking")
    sc = mod.scene(n)

    def solve(label):
        def run(newton):
            mod.newton = newton
            r = mod.run(sc, mod.solved_name(label, False)[0])
            if r["status"] != "done":
                raise RuntimeError(r["status"])
        return run
    return "necking bar (J2), hexes", sc.mesh.nvertices, [
        ("H1P0", solve("FEM H1P0")), ("PG", solve("VCPBG Unl"))]


def punch(nx):
    mod = demo("punch")
    mesh = mod.block(nx, nx // 2)
    lam, mu = pg.materials.lame(mod.E, mod.NU)
    material = pg.materials.NeoHooke(lam=lam, mu=mu)

    def solve(basis):
        def run(newton):
            D = np.unique(np.concatenate([
                basis.get_dofs("punch").nodal["u^2"],
                basis.get_dofs("left").nodal["u^1"],
                basis.get_dofs("bottom").nodal["u^2"]]))
            u_D = np.zeros(basis.N)
            u_D[basis.get_dofs("punch").nodal["u^2"]] = -1.0
            newton(pg.formulations.Hyperelastic(basis, material), D=D,
                   u_D=u_D, steps=20, min_step=1e-3, verbose=False)
        run.until_failure = True
        return run
    return "2-D punch until failure, quads", mesh.nvertices, [
        ("Q1", solve(fem.Basis(mesh, fem.ElementVector(
            fem.ElementQuad1())))),
        ("PG", solve(pg.FamilyBasis(pg.Particles.from_mesh(mesh), dim=2)))]


def main():
    p = demo_parser(__doc__)
    p.add_argument("--cook", type=float, nargs="*", default=[1.6, 1.0],
                   help="gmsh sizes of the 3-D Cook node sets")
    p.add_argument("--bracket", type=float, default=1.5,
                   help="gmsh size of the bracket")
    p.add_argument("--necking", type=int, default=1,
                   help="the necking bar's refinement (demos/necking.py)")
    p.add_argument("--punch", type=int, default=64,
                   help="cells along the punch block")
    p.add_argument("--section", default="factor_reuse",
                   help="benchmarks/README.md section of the table")
    args = p.parse_args()
    if args.quick:
        args.cook, args.bracket, args.necking, args.punch = [3.0], 4.0, 1, 16
    print(pg.threads.describe())
    problems = [functools.partial(cook, s) for s in args.cook] + [
        functools.partial(bracket, args.bracket),
        functools.partial(necking, args.necking),
        functools.partial(punch, args.punch)]
    rows = []
    for make in problems:
        name, nodes, methods = make()
        print("{}: {} nodes".format(name, nodes), flush=True)
        for method, solve in methods:
            full = timed(solve, False)
            mod = timed(solve, True)
            if full[3] != mod[3]:  # the punch: where each one stopped
                diff = "stop at {:.3f} / {:.3f}".format(full[3], mod[3])
            else:
                diff = "{:.1e}".format(np.abs(mod[1] - full[1]).max()
                                       / np.abs(full[1]).max())
            its = [sum(len(h["residuals"]) - 1 for h in r[2])
                   for r in (full, mod)]
            tangents = sum(h["tangents"] for h in mod[2])
            undone = sum(h["undone"] for h in mod[2])
            rows.append([name, "{:,}".format(nodes), method,
                         "{:.2f}".format(full[0]), "{:.2f}".format(mod[0]),
                         "{:.2f}".format(mod[0] / full[0]),
                         "{} / {}".format(its[0], its[0]),
                         "{} / {}".format(its[1], tangents), str(undone),
                         diff])
            print("  {:5s} full {:.2f} s ({} increments), reuse {:.2f} s "
                  "({} increments, {} tangents, {} undone): {:.2f}; answers "
                  "differ by {}".format(method, full[0], its[0], mod[0],
                                            its[1], tangents, undone,
                                            mod[0] / full[0], diff),
                  flush=True)
        if not args.quick:
            write(rows, args)


def write(rows, args):
    table = markdown_table(
        ["problem", "nodes", "method", "full Newton [s]", "reuse [s]",
         "reuse / full", "full: increments / tangents",
         "reuse: increments / tangents", "undone", "answers differ"],
        rows)
    update_results(RESULTS, args.section, (
        "`python benchmarks/factor_reuse.py`: whole nonlinear solves with "
        "full Newton and with `reuse=True` (modified Newton: the "
        "factorization of a tangent kept while each increment cuts the "
        "residual by REUSE_CONTRACTION = {}; an increment that does not is "
        "undone and the tangent refreshed), in the same run ({}).  "
        "Tolerance 1e-9 (the necking demo's 1e-8); answers differ: max "
        "|u_reuse - u_full| / max |u_full|.\n\n{}").format(
            static.REUSE_CONTRACTION, pg.threads.describe(), table))


if __name__ == "__main__":
    main()
