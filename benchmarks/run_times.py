"""Run times of the demos, the benchmarks and the README's commands,
measured by running them, so that no page quotes a time by hand.

Each selected script runs at its default settings in a subprocess with an
empty cache (``SKFEM_PG_CACHE`` and ``SKFEM_PG_OUT`` in a temporary
folder): that is its first run.  A script that left something in the cache
runs once more: its cached run.  The test commands run in the source tree.
The measurements go to ``benchmarks/run_times.json`` (replaced atomically;
a measurement is kept until its script is measured again), from which this
script renders the demo table of ``benchmarks/README.md`` (section
``run_times``) and the times paragraph of ``README.md`` and
``docs/getting_started.md`` (section ``readme_times``, the same text in
both; ``tests/test_harness.py`` checks that they match the file).

Examples::

    python benchmarks/run_times.py --only cook_neohooke tests
    python benchmarks/run_times.py --below 180   # everything quoted < 3 min
    python benchmarks/run_times.py --render      # re-render, run nothing

Rows whose script has not been measured this way yet show the time
measured by hand when their issue closed, marked as such.
"""
import datetime
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

from harness import (demo_parser, markdown_table, update_results,
                     write_atomically)

from skfem_pg import threads

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
STORE = os.path.join(ROOT, "benchmarks", "run_times.json")
PAGES = {"benchmarks": os.path.join(ROOT, "benchmarks", "README.md"),
         "readme": os.path.join(ROOT, "README.md"),
         "getting_started": os.path.join(ROOT, "docs", "getting_started.md")}

#: (key, command after ``python``, what it shows, the time measured by
#: hand when its issue closed, that time in seconds — what ``--below``
#: selects by)
SCRIPTS = [
    ("cook_neohooke", ["demos/cook_neohooke.py"],
     "main job: 2-D Cook, PG vs T1, error vs time, consistent vs FD "
     "tangent", "13 s first run, 8 s after", 13),
    ("cook_3d", ["demos/cook_3d.py"],
     "3-D Cook, neo-Hooke: time to 1 % and 0.3 % of PG (kNN and the thesis "
     "recipe), O1, O2 on gmsh tets, H1P0 on hex grids",
     "10 min (first run: 18 min, the H2 references)", 1080),
    ("compression_3d", ["demos/compression_3d.py"],
     "a block clamped on its loaded faces, compressed 30 %: PG vs H1 (O1 "
     "with `--tets`), completion, min J, inverted cells", "5 min", 300),
    ("punch", ["demos/punch.py"],
     "compress until failure: Q1 vs VC PBG Unl, inverted cells", "33 s", 33),
    ("plate_hole", ["demos/plate_hole.py"],
     "thesis 7.3.8: PPG around a hole coupled to Q1, σ_xx vs overkill and "
     "Kirsch", "80 s (first run)", 80),
    ("coupling", ["demos/coupling.py"],
     "FE–PG coupling through shared nodes", "30 s", 30),
    ("patch_test", ["demos/patch_test.py"], "Table 7.2", "8 s", 8),
    ("quadratic_patch_test", ["demos/quadratic_patch_test.py"],
     "Table 7.3", "4 s", 4),
    ("eigenmodes", ["demos/eigenmodes.py"],
     "free-block spectra (Fig. 7.6)", "4 s", 4),
    ("stability_patch", ["demos/stability_patch.py"],
     "Ganzenmüller et al.'s stability case", "7 s", 7),
    ("cook_membrane", ["demos/cook_membrane.py"],
     "linear Cook, convergence", "24 s first run, 5 s after", 24),
    ("cook_incompressible", ["demos/cook_incompressible.py"],
     "Cook, ν ≈ 0.5: Unl, UnlP0, Unl+P1C, U2P1, U2P1C vs Q1P0, T1, Q1, "
     "error vs time, against 16.4326 and a Q1P0 256² reference", "1 min",
     60),
    ("torsion", ["demos/torsion.py"],
     "thesis Table 7.4: largest single rotation step, fewest steps per "
     "turn; `--full` is the thesis' 16×16×80 (days)", "12 min", 720),
    ("punch_3d", ["demos/punch_3d.py"],
     "thesis 7.3.3: min u_z against an H1P0 reference, ν = 0.4 and "
     "0.49999, inverted cells", "5 min", 300),
    ("plastic_cylinder", ["demos/plastic_cylinder.py"],
     "J2 plasticity: thick-walled cylinder, inner pressure against the "
     "limit (2/√3)σ_y ln(b/a), Newton residuals", "12 s", 12),
    ("necking", ["demos/necking.py"],
     "thesis 7.3.5 / Fig. 7.24: cylindrical necking, force and neck radius "
     "vs elongation, max ē_p of ten formulations against an H1P0 "
     "overkill; VTU series", "10 min", 600),
    ("taylor", ["demos/taylor.py"],
     "thesis 7.3.7 / Table 7.6: Taylor anvil impact (explicit; `--newmark` "
     "for the mixed ones): length, mushroom radius, max ē_p beside the "
     "literature band; VTU series", "5.5 min; `--explicit` 22 min", 330),
    ("cook_dynamic", ["demos/cook_dynamic.py"],
     "thesis 7.2.4 / Fig. 7.12: dynamic Cook, four PG variants in TL and "
     "UL", "2 min", 120),
    ("torsion_dynamic", ["demos/torsion_dynamic.py"],
     "thesis 7.3.6 / Table 7.5: dynamic torsion, max ē_p at 360°, failure "
     "angle", "5 min", 300),
    ("two_hole_plate", ["demos/two_hole_plate.py"],
     "thesis 8.1 / Fig. 8.1: ductile fracture of a plate with two holes, "
     "Johnson–Cook damage on PG U1SIG and Unl (connectivity kept, and "
     "crack-aware families) beside FE Q1 erosion; crack snapshots, bottom "
     "force and energies; VTU series", "14 min", 840),
    ("kalthoff_winkler", ["demos/kalthoff_winkler.py"],
     "Kalthoff–Winkler impact with the bond-based comparator (PMB) and PG "
     "Unl with a brittle criterion (connectivity kept, crack-aware): the "
     "crack angles against the experiment's 70 degrees", "2 min", 120),
    ("poiseuille", ["demos/poiseuille.py"],
     "thesis 8.2 / Fig. 8.2: Poiseuille start-up of water, PG UnlP0 with "
     "the local VC beside FE Q1P0, against the analytic series; VTU "
     "series", "12 s", 12),
    ("dam_break", ["demos/dam_break.py"],
     "thesis 8.2: the dam break against Martin & Moyce, PG UnlP0 "
     "re-neighboured (free_surface_flow: alpha shape, merged particles) "
     "beside the total Lagrangian run; VTU series", "4.5 min", 270),
    ("cook_mpi", ["demos/cook_mpi.py"],
     "3-D Cook on 1 or 2 MPI ranks (`mpirun -n 2`): per-rank timings, "
     "Newton and KSP iterations, difference to the serial run (serial "
     "here)", "20 s", 20),
    ("taylor_mpi", ["demos/taylor_mpi.py"],
     "thesis 7.3.7 on 1 or 2 MPI ranks (`mpirun -n 2`): explicit central "
     "differences on ranks against the serial run (steps, difference, "
     "time split per rank, particle-steps/s); .pvtu series", "1.7 min",
     100),
    ("assembly_scaling", ["benchmarks/assembly_scaling.py"],
     "preprocessing / assembly / solve vs Q1 (2-D, up to 251k particles) "
     "and H1 (`--dim 3`), both FE assembly paths", "minutes", 600),
    ("newton_3d", ["benchmarks/newton_3d.py"],
     "one 3-D Newton iteration, PG vs O1 / H1P0: material, assembly, "
     "solve", "20 min", 1200),
    ("material_library", ["benchmarks/material_library.py"],
     "FElupe's laws through FElupeMaterial against the package's: stress "
     "and tangent at 1e5 points, Newton on FElupe's cube (H1, PG)",
     "10 s", 30),
    ("flow", ["benchmarks/flow.py"],
     "thesis 8.2: a column of water at rest (2-D, 3-D, perturbed), "
     "Poiseuille's start-up, the dam break against Martin & Moyce (total "
     "Lagrangian and re-neighboured); PG UnlP0 with the local VC beside "
     "FE Q1P0/H1P0 and the refused formulations", "8 min", 480),
    ("fracture_energy", ["benchmarks/fracture_energy.py"],
     "elastic–brittle fracture: (W_int − stored − released − closure) / "
     "W_int and the closure of PG kept and crack-aware (global and local VC) and PMB on the mode-I "
     "plate (gmsh triangles, h = 2 and 1 mm, the step scaled), the slower "
     "pull with the crack band and the nonlocal criterion, and "
     "Kalthoff–Winkler; `--fine`: the nonlocal criterion to h = 0.5 mm, "
     "the step halved (22 min on one core, 2026-12-07)", "12 min", 720),
    ("crack_paths", ["benchmarks/crack_paths.py"],
     "Kalthoff–Winkler's crack direction on square grids and gmsh "
     "triangles at 2 and 1 mm: PMB, PG kept and crack-aware with the "
     "strain and the stress criterion, against the experiment's 70 "
     "degrees (grids 41 min and triangles 73 min, in two processes beside "
     "other jobs, 2026-12-07); `--tracked`: PMB beside PG with the crack "
     "tracking, at the default hold limit and lifted (grids 32 min and "
     "triangles 41 min, side by side, 2026-12-08)", "75 min", 4500),
    ("factor_reuse", ["benchmarks/factor_reuse.py"],
     "modified Newton (reuse=True) against full Newton: whole solves of "
     "the 3-D Cook, a bracket, necking, the punch", "5 min", 600),
    ("scale_3d", ["benchmarks/scale_3d.py"],
     "3-D linear elasticity from mesh to solution up to 100k particles, "
     "peak memory", "15 min", 900),
    ("accuracy_study", ["benchmarks/accuracy_study.py"],
     "PG variants' errors relative to Q1/T1 on the same nodes", "minutes",
     600),
    ("bending_3d", ["benchmarks/bending_3d.py"],
     "why VC PBG Unl is soft on 3-D tets", "1.5 min", 90),
    ("solvers_3d", ["benchmarks/solvers_3d.py"],
     "PARDISO, SuperLU and AMG on the same 3-D PG and O1 matrices: where "
     "`\"auto\"` switches", "15 min", 900),
    ("recipes_3d", ["benchmarks/recipes_3d.py"],
     "the thesis recipe against kNN, O1, O2 (H1 on hex grids): Cook, "
     "cantilever, plate with a hole, linear, against O2/H2 overkills",
     "10 min", 600),
    ("recipes_2d", ["benchmarks/recipes_2d.py"],
     "2-D recipes (family rule, weights, bond weight exponent) against "
     "T1/Q1: four elastic geometries on triangles and quadrilaterals, "
     "Poisson, against T2 overkills", "6 min", 360),
    ("gallery", ["benchmarks/gallery.py"],
     "scikit-fem's ex03, ex11, ex22 with the basis swapped: FE against "
     "the PG default and MQ on the same nodes, against overkills",
     "2 min", 120),
    ("second_order", ["benchmarks/second_order.py"],
     "why the package's U2 loses its rates: the manufactured solution's "
     "L2/H1 rates of the U2 variants, a per-particle Petrov VC2 "
     "candidate and the conforming blend of the fits, T1/Q1, T2/Q2; the "
     "adjoint consistency by ring; the blend on tetrahedra against O2; "
     "the stencils in 2-D and 3-D", "4 min", 240),
    ("pg2_vs_quadratic", ["benchmarks/pg2_vs_quadratic.py"],
     "PG2 (the blended quadratic basis) against T1/T2, O1/O2, H1/H2 and "
     "PG per unknown and per second: a curved cantilever and a plate "
     "with a hole (2-D, linear), a neo-Hooke cantilever of hexahedra "
     "(3-D)", "10 min", 600),
    ("census", ["benchmarks/census.py"],
     "68 wrong inputs, each in its own process: correct, named or bare "
     "error, silent, hang, data loss (`--compare` before/after)",
     "40 s", 40),
    ("stress_hole", ["benchmarks/stress_hole.py"],
     "particle stresses at a hole against T1/Q1 nodal averages: Kirsch's "
     "exact solution, an elliptic hole against a curved T2 overkill",
     "2 min", 120),
    ("infsup_mixed", ["benchmarks/infsup_mixed.py"],
     "inf-sup values of the mixed PG pairs beside Q1P0, MINI (thesis Fig. "
     "7.15)", "1 min", 60),
    ("mixed_newton", ["benchmarks/mixed_newton.py"],
     "one Newton iteration of every mixed formulation vs PBG Unl and Q1P0 "
     "/ H1P0", "5 min", 300),
    ("plasticity_cost", ["benchmarks/plasticity_cost.py"],
     "a plastic Newton iteration against the hyperelastic one: PG Unl, "
     "U1SUnl, U1SIG, H1P0", "1 min", 60),
    ("dynamics_cost", ["benchmarks/dynamics_cost.py"],
     "explicit step per formulation vs O1/H1, Newmark step vs Newton "
     "iteration", "3 min", 180),
    ("mpi_scaling", ["benchmarks/mpi_scaling.py"],
     "strong and weak scaling on 1 and 2 ranks against serial PG and H1 "
     "(sparse direct)", "minutes", 600),
    ("explicit_scaling", ["benchmarks/explicit_scaling.py"],
     "explicit central differences on 1 and 2 ranks: strong and weak "
     "scaling, the serial driver beside them", "10 min", 600),
    ("local_vc", ["benchmarks/local_vc.py"],
     "local against global VC correction: manufactured rates, linear Cook "
     "2-D and 3-D against overkills (with H1, O1, O2), the correction's "
     "cost", "2 min", 120),
]

#: the README's test commands: key, pytest arguments, what they run
TESTS = [
    ("tests", [], "the fast set (the README's test command)"),
    ("tests_study", ["-m", "study or slow"],
     "the verification studies and slow tests"),
    ("tests_demo", ["-m", "demo"], "the demos' `--quick` runs"),
]


def measure_script(command):
    """``{"first": s, "cached": s or None}`` of ``python command`` at its
    defaults, from an empty cache; raises ``RuntimeError`` with the
    script's last output lines if it fails."""
    with tempfile.TemporaryDirectory(prefix="skfem_pg_times_") as tmp:
        cache, out = os.path.join(tmp, "cache"), os.path.join(tmp, "out")
        env = dict(os.environ, SKFEM_PG_CACHE=cache, SKFEM_PG_OUT=out,
                   MPLBACKEND="Agg")
        times = {}
        for run in ("first", "cached"):
            t0 = time.perf_counter()
            done = subprocess.run([sys.executable] + command, cwd=ROOT,
                                  env=env, capture_output=True, text=True)
            times[run] = time.perf_counter() - t0
            if done.returncode:
                raise RuntimeError("{} failed ({}):\n{}".format(
                    " ".join(command), done.returncode,
                    "\n".join((done.stdout + done.stderr)
                              .splitlines()[-20:])))
            if not (os.path.isdir(cache) and os.listdir(cache)):
                times["cached"] = None
                break
    return times


#: the checks of the quoted numbers, left out of the measured runs: they
#: fail until the numbers are measured, i.e. while they are
UNMEASURED = ["--deselect", "tests/test_harness.py::"
              "test_quoted_times_are_the_measured_ones",
              "--deselect", "tests/test_harness.py::"
              "test_quoted_test_counts_are_of_the_current_suite"]


#: test modules whose collection depends on an optional extra (mpi4py,
#: PyVista): left out of the counts, which identify the suite
OPTIONAL = ["tests/test_distributed.py", "tests/test_plotting.py"]


def count_tests(args):
    """How many tests ``python -m pytest args`` selects, without running
    them, the modules of :data:`OPTIONAL` left out (their collection
    depends on what is installed): what identifies the suite a quoted
    count and time are of, and the count the README quotes (the checks
    of :data:`UNMEASURED` included: they pass once the numbers are
    stored)."""
    ignore = [a for m in OPTIONAL for a in ("--ignore", m)]
    done = subprocess.run(
        [sys.executable, "-m", "pytest", "--collect-only", "-q", "-p",
         "no:cacheprovider"] + ignore + args, cwd=ROOT,
        capture_output=True, text=True)
    found = re.findall(r"(\d+)(?:/\d+)? tests? collected", done.stdout)
    if done.returncode not in (0, 5) or not found:
        raise RuntimeError("pytest --collect-only {} failed: {}".format(
            " ".join(args), done.stdout.strip()[-300:]))
    return int(found[-1])


def measure_tests(args):
    """``{"seconds": s, "passed": n, "collected": m}`` of ``python -m
    pytest -q args`` in the source tree (``collected``:
    :func:`count_tests`)."""
    t0 = time.perf_counter()
    done = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider"]
        + UNMEASURED + args, cwd=ROOT, capture_output=True, text=True)
    seconds = time.perf_counter() - t0
    last = done.stdout.strip().splitlines()[-1] if done.stdout else ""
    if done.returncode:
        raise RuntimeError("pytest {} failed: {}".format(" ".join(args),
                                                         last))
    passed = re.search(r"(\d+) passed", last)
    return {"seconds": seconds, "passed": int(passed.group(1)),
            "collected": count_tests(args)}


def _count(record):
    """The tests a command runs: its collected count (older records: the
    tests that passed)."""
    return record.get("collected", record["passed"])


def measure_decorators():
    """The README's one-line change, measured: one linear-elasticity
    stiffness matrix on the family basis of a 3-D hex grid (8 x 4 x 4
    cells, ex43's kind of mesh) with a form under scikit-fem's decorator
    (its generic path) and under skfem-pg's (the fast path); ``{"generic":
    s, "fast": s, "particles": n}``."""
    import warnings

    import numpy as np
    import skfem as fem
    from skfem.helpers import ddot, sym_grad, trace, eye

    import skfem_pg as pg

    def stiffness(u, v, w):
        e = sym_grad(u)
        return ddot(2 * e + eye(trace(e), 3), sym_grad(v))
    mesh = fem.MeshHex.init_tensor(np.linspace(0, 2, 9),
                                   *(np.linspace(0, 1, 5),) * 2)
    basis = pg.FamilyBasis(mesh, dim=3)
    out = {"particles": int(basis.particles.n)}
    for key, form in (("generic", fem.BilinearForm(stiffness)),
                      ("fast", pg.BilinearForm(stiffness))):
        t0 = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", pg.SlowAssemblyWarning)
            form.assemble(basis)
        out[key] = time.perf_counter() - t0
    return out


def measure_docs():
    """``{"seconds": s}`` of the README's documentation build
    (``sphinx-build -W -b html``) as on a clean checkout: the sources
    copied to a temporary folder without the gallery's executed
    examples, so that it runs them."""
    with tempfile.TemporaryDirectory(prefix="skfem_pg_docs_") as tmp:
        shutil.copytree(ROOT, os.path.join(tmp, "src"), ignore=(
            shutil.ignore_patterns(".git", "_build", "auto_examples",
                                   "sg_execution_times.rst", "out",
                                   "__pycache__", "*.egg-info")))
        src = os.path.join(tmp, "src")
        t0 = time.perf_counter()
        done = subprocess.run(
            [sys.executable, "-m", "sphinx", "-W", "-q", "-b", "html",
             "docs", os.path.join("docs", "_build", "html")], cwd=src,
            capture_output=True, text=True,
            env=dict(os.environ, MPLBACKEND="Agg"))
        seconds = time.perf_counter() - t0
    if done.returncode:
        raise RuntimeError("the docs build failed:\n" + "\n".join(
            (done.stdout + done.stderr).splitlines()[-20:]))
    return {"seconds": seconds}


#: further measurements the README quotes: key, function
OTHERS = {"decorators": measure_decorators, "docs": measure_docs}


def load():
    """The stored measurements (``{}`` before the first)."""
    if not os.path.exists(STORE):
        return {}
    with open(STORE) as fh:
        return json.load(fh)


def save(store):
    """Write the measurements (atomically)."""
    write_atomically(STORE, json.dumps(store, indent=1, sort_keys=True)
                     + "\n")


def seconds(s):
    """``8 s``, ``1.5 min``, ``18 min``."""
    if s < 90:
        return "{:.0f} s".format(s)
    return "{:.{}f} min".format(s / 60, 1 if s < 600 else 0)


def time_cell(entry, hand):
    """The time column of a script's row: measured, or the hand value."""
    if entry is None:
        return "{} (by hand)".format(hand)
    if entry["cached"] is None:
        text = seconds(entry["first"])
    else:
        text = "{} first run, {} cached".format(seconds(entry["first"]),
                                                seconds(entry["cached"]))
    return "{} ({})".format(text, entry["date"])


def render_table(store):
    """The demo table of ``benchmarks/README.md``."""
    rows = [("`{}`".format(" ".join(cmd)), shows,
             time_cell(store.get(key), hand))
            for key, cmd, shows, hand, _ in SCRIPTS]
    return ("Times on 2 cores at the default settings: the first run with an "
            "empty cache, and the cached run where the script caches "
            "something (its overkill references), written by "
            "`benchmarks/run_times.py` with the date measured; `(by hand)` "
            "marks times measured by hand when the script's issue closed, "
            "not yet re-measured by it.  Each script's docstring has its "
            "options; `--quick` runs a demo in seconds.\n\n"
            + markdown_table(["script", "shows", "time"], rows)
            .replace("| ---: | ---: |", "| --- | --- |", 1))


def render_readme(store):
    """The times paragraph of ``README.md`` and ``docs/getting_started.md``
    (``None`` until the main job and the test commands are measured)."""
    main = store.get("cook_neohooke")
    tests = [store.get(key) for key, _, _ in TESTS]
    forms, docs = store.get("decorators"), store.get("docs")
    if main is None or main["cached"] is None or None in tests \
            or forms is None or docs is None:
        return None
    fast, study, demo = tests
    return (
        "Measured by `benchmarks/run_times.py` on 2 cores ({}): the main job "
        "takes {} the first time (it computes its overkill then) and {} "
        "with the cached one; the test command runs {} tests in {}; "
        "`-m \"study or slow\"` {} in {}; `-m demo` {} in {}; the "
        "documentation builds in {}.  One 3-D stiffness matrix on {} "
        "particles takes {:.2f} s with a form under scikit-fem's decorator "
        "(its generic path) and {:.3f} s under skfem-pg's ({:.0f}x)."
        .format(main["date"], seconds(main["first"]),
                seconds(main["cached"]), _count(fast),
                seconds(fast["seconds"]), _count(study),
                seconds(study["seconds"]), _count(demo),
                seconds(demo["seconds"]), seconds(docs["seconds"]),
                forms["particles"], forms["generic"], forms["fast"],
                forms["generic"] / forms["fast"]))


def render(store):
    """Rewrite the three pages' sections from ``store``."""
    update_results(PAGES["benchmarks"], "run_times", render_table(store))
    text = render_readme(store)
    if text is not None:
        for page in ("readme", "getting_started"):
            update_results(PAGES[page], "readme_times", text)


def main():
    ap = demo_parser(__doc__, quick=False)
    keys = [k for k, *_ in SCRIPTS] + [k for k, _, _ in TESTS] + \
        list(OTHERS)
    ap.add_argument("--only", nargs="+", choices=keys, metavar="KEY",
                    help="measure these scripts (their file names without "
                    "'.py'), test commands and others ({})".format(
                        ", ".join([k for k, _, _ in TESTS] + list(OTHERS))))
    ap.add_argument("--below", type=float, help="measure every script "
                    "whose hand-measured time is below this many seconds, "
                    "the test commands and the others")
    ap.add_argument("--render", action="store_true",
                    help="only re-render the pages from the stored "
                    "measurements")
    args = ap.parse_args()
    if args.render:
        render(load())
        return
    if args.only:
        chosen = args.only
    elif args.below is not None:
        chosen = [k for k, _, _, _, s in SCRIPTS if s < args.below] + \
            [k for k, _, _ in TESTS] + list(OTHERS)
    else:
        ap.error("say what to measure: --only KEY ..., --below SECONDS or "
                 "--render")
    commands = {k: c for k, c, *_ in SCRIPTS}
    tests = {k: a for k, a, _ in TESTS}
    stamp = {"date": datetime.date.today().isoformat(),
             "threads": threads.describe()}
    for key in chosen:
        print("measuring", key, flush=True)
        store = load()
        if key in tests:
            store[key] = dict(measure_tests(tests[key]), **stamp)
        elif key in OTHERS:
            store[key] = dict(OTHERS[key](), **stamp)
        else:
            store[key] = dict(measure_script(commands[key]), **stamp)
        print("  ", store[key], flush=True)
        save(store)
        render(store)


if __name__ == "__main__":
    main()
