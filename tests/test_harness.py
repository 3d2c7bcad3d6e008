"""The demos' and benchmarks' harness (``demos/harness.py``, not part of
the package): its time-to-accuracy rule, and ``benchmarks/harness.py``
loading the one copy."""
import importlib.util
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _load(name, *path):
    spec = importlib.util.spec_from_file_location(
        name, os.path.join(ROOT, *path))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _harness():
    return _load("harness", "demos", "harness.py")


def test_time_to_target_waits_until_the_error_stays_there():
    """``first_within``: a method whose error crosses the target on its
    way (and leaves it again) has not reached it until it stays."""
    first_within = _harness().first_within
    rows = [dict(method="a", nodes=n, err=e) for n, e in
            ((10, 0.05), (20, 0.009), (40, 0.02), (80, 0.008), (160, 0.004))]
    rows.append(dict(method="b", nodes=10, err=0.5))
    assert first_within(rows, "a", 0.01)["nodes"] == 80
    assert first_within(rows, "a", 0.001) is None
    assert first_within(rows, "b", 0.01) is None
    assert first_within(rows, "c", 0.01) is None


def test_benchmarks_load_the_demos_harness():
    """``python benchmarks/NAME.py`` imports ``harness``: the demos' file,
    not a second copy."""
    code = ("import harness, os; print(os.path.relpath(harness.__file__, "
            "{!r}))".format(ROOT))
    out = subprocess.run([sys.executable, "-c", code], capture_output=True,
                         text=True, check=True,
                         cwd=os.path.join(ROOT, "benchmarks")).stdout
    assert out.strip() == os.path.join("demos", "harness.py")


def test_every_script_option_has_help_and_shows_its_default():
    """Every option of every demo and benchmark says what it is (the
    harness' parser shows the defaults), and every script builds its
    parser with the harness (``--out``, ``--quick``, the formatter)."""
    import ast
    import glob
    missing, raw = [], []
    for path in sorted(glob.glob(os.path.join(ROOT, "demos", "*.py"))
                       + glob.glob(os.path.join(ROOT, "benchmarks", "*.py"))):
        tree = ast.parse(open(path).read())
        for node in ast.walk(tree):
            if not isinstance(node, ast.Call):
                continue
            name = getattr(node.func, "attr", getattr(node.func, "id", ""))
            if name == "add_argument" and "help" not in {
                    k.arg for k in node.keywords}:
                missing.append("{}:{}".format(os.path.basename(path),
                                              node.lineno))
            if name == "ArgumentParser" and not path.endswith("harness.py"):
                raw.append(os.path.basename(path))
    assert not missing and not raw, (missing, raw)
    text = subprocess.run([sys.executable, os.path.join(ROOT, "demos",
                                                        "punch.py"), "--help"],
                          capture_output=True, text=True, check=True).stdout
    assert "(default: 64)" in text and "elements along the block" in text
    description = text.split("options:")[0].split("\n\n", 1)[1].strip()
    assert description.endswith(".")  # a whole sentence, not a first line
    for path in glob.glob(os.path.join(ROOT, "demos", "*.py")) + glob.glob(
            os.path.join(ROOT, "benchmarks", "*.py")):
        doc = ast.get_docstring(ast.parse(open(path).read()))
        first = " ".join(doc.strip().split("\n\n")[0].split())
        assert first.endswith((".", ":", ")", "?")), (path, first[-60:])


def _run_times():
    """``benchmarks/run_times.py`` as a module (it imports ``harness``
    through ``benchmarks/harness.py``)."""
    sys.path.insert(0, os.path.join(ROOT, "benchmarks"))
    try:
        return _load("run_times", "benchmarks", "run_times.py")
    finally:
        sys.path.remove(os.path.join(ROOT, "benchmarks"))


def _section(path, name):
    text = open(path).read()
    begin, end = "<!-- begin {} -->".format(name), \
        "<!-- end {} -->".format(name)
    assert begin in text and end in text, (path, name)
    return text.split(begin, 1)[1].split(end, 1)[0]


def test_quoted_times_are_the_measured_ones():
    """The README's and the getting-started page's times paragraph and
    the demo table of ``benchmarks/README.md`` are what
    ``benchmarks/run_times.py`` renders from its stored measurements
    (a hand edit of a time fails here), and every demo and benchmark
    script has its row."""
    rt = _run_times()
    store = rt.load()
    readme = _section(rt.PAGES["readme"], "readme_times")
    assert readme == _section(rt.PAGES["getting_started"], "readme_times")
    assert rt.render_readme(store) is not None
    assert readme.strip().startswith(rt.render_readme(store))
    assert _section(rt.PAGES["benchmarks"], "run_times").strip() \
        .startswith(rt.render_table(store))
    scripts = {" ".join(cmd) for _, cmd, *_ in rt.SCRIPTS}
    for folder in ("demos", "benchmarks"):
        for name in os.listdir(os.path.join(ROOT, folder)):
            if name.endswith(".py") and name not in ("harness.py",
                                                     "run_times.py"):
                assert "{}/{}".format(folder, name) in scripts, name


def test_quoted_test_counts_are_of_the_current_suite():
    """The test counts and times the README quotes were measured on the
    suite as it is: each test command selects as many tests now as when
    ``benchmarks/run_times.py`` measured it (a test added or removed since
    fails here until the commands are measured again)."""
    rt = _run_times()
    store = rt.load()
    stale = []
    for key, args, _ in rt.TESTS:
        now = rt.count_tests(args)
        then = store.get(key, {}).get("collected")
        if then != now:
            stale.append("{}: measured on {} tests, the suite has {}".format(
                key, then, now))
    assert not stale, (
        "the quoted test counts and times are of another suite ({}); "
        "measure them again: python benchmarks/run_times.py --only {}"
        .format("; ".join(stale), " ".join(k for k, _, _ in rt.TESTS)))


def test_pages_are_written_atomically(tmp_path):
    """``update_results`` replaces a section through a temporary file:
    the page keeps its other text and its permissions, no temporary file
    is left."""
    update_results = _harness().update_results
    page = tmp_path / "page.md"
    page.write_text("head\n<!-- begin a -->\nold\n<!-- end a -->\ntail\n")
    page.chmod(0o644)
    update_results(str(page), "a", "new")
    text = page.read_text()
    assert "new" in text and "old" not in text and text.startswith("head")
    assert text.rstrip().endswith("tail")
    assert oct(page.stat().st_mode & 0o777) == "0o644"
    assert os.listdir(tmp_path) == ["page.md"]


def test_the_census_classes_each_outcome():
    """``benchmarks/census.py`` (issue 47): each input in its own process;
    an error naming every token is named, another bare, a wrong answer
    silent (or data loss where a file mattered), a time-out a hang — and
    three of its own inputs are classed as the code now answers them."""
    census = _load("census", "benchmarks", "census.py")
    cls = {}
    for name, code, names, ok, data in (
            ("named", "raise ValueError('dt = 3 above the stable step')",
             ["dt", "stable"], None, False),
            ("bare", "raise KeyError('energy_T0')", ["dt"], None, False),
            ("silent", "result = 0.9", ["x"], "result == 1.0", False),
            ("data loss", "result = 0.5", ["x"], "result == 0.25", True),
            ("correct", "result = 1.0", ["x"], "result == 1.0", False),
            ("hang", "import time\ntime.sleep(30)", ["x"], None, False)):
        c = census.case(name, "test", "own", code, names, ok, data)
        cls[name] = census.run_case(c, None, 3.0 if name == "hang"
                                    else 60.0)["cls"]
    assert cls == {k: k for k in cls}
    chosen = {c["id"]: c for c in census.CASES}
    for id, want in (("save-wrong-length", "named"),
                     ("factorization-dense", "correct")):
        assert census.run_case(chosen[id], None, 120.0)["cls"] == want
