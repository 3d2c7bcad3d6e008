"""The demos' and benchmarks' harness (``demos/harness.py``, not part of
the package): its time-to-accuracy rule, and ``benchmarks/harness.py``
loading the one copy."""
import importlib.util
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _harness():
    spec = importlib.util.spec_from_file_location(
        "harness", os.path.join(ROOT, "demos", "harness.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


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
