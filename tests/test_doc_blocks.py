"""Every Python block of the README and the documentation pages runs as
written, in a namespace of its own, and the numbers its comments quote
(``# ... expr = 3.32``) are what the code computes, to the digits quoted.
The MPI guide's blocks run on two ranks in ``tests/test_distributed.py``
(``run_doc_block`` below)."""
import glob
import os
import re

import numpy as np
import pytest

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir)
HAS_DOCS = os.path.isdir(os.path.join(ROOT, "docs"))
#: pages whose blocks need MPI ranks (run by tests/test_distributed.py)
MPI_PAGES = ("docs/guide/mpi.md",)
#: pages whose blocks another test runs: the contributor guide's recipes
#: register formulations and family rules, which tests/test_contributing.py
#: removes again after each
ELSEWHERE = ("docs/guide/contributing.md",)


def pages():
    found = ["README.md"] + sorted(
        os.path.relpath(p, ROOT) for p in glob.glob(
            os.path.join(ROOT, "docs", "**", "*.md"), recursive=True))
    return [p for p in found if "auto_examples" not in p
            and os.path.isfile(os.path.join(ROOT, p))]


def blocks(page):
    """``(line, code)`` of each fenced ``python`` block of ``page``
    (indented blocks inside list items dedented)."""
    out, lines = [], open(os.path.join(ROOT, page)).read().split("\n")
    i = 0
    while i < len(lines):
        m = re.match(r"^(\s*)```python\s*$", lines[i])
        if m:
            indent, start, body = len(m.group(1)), i + 1, []
            i += 1
            while not re.match(r"^\s*```\s*$", lines[i]):
                body.append(lines[i][indent:])
                i += 1
            out.append((start + 1, "\n".join(body)))
        i += 1
    return out


#: a quoted number in a comment: ``expr = 3.32`` (the expression made of
#: names, indexing, attribute and call syntax)
CLAIM = re.compile(r"([A-Za-z_][\w\[\]:.,()]*?)\s*=\s*(-?\d+\.\d+)\b")


def claims(code):
    for line in code.split("\n"):
        if "#" in line:
            for expr, value in CLAIM.findall(line.split("#", 1)[1]):
                yield expr, value


def run_doc_block(code, where):
    """Run ``code`` in a namespace of its own; check its quoted numbers."""
    namespace = {"__name__": "__doc_block__"}
    exec(compile(code, where, "exec"), namespace)  # noqa: S102
    for expr, value in claims(code):
        got = float(eval(expr, namespace))  # noqa: S307
        digits = len(value.split(".")[1])
        assert round(got, digits) == float(value), (where, expr, got, value)


CASES = [(page, line, code) for page in pages()
         if page not in MPI_PAGES + ELSEWHERE for line, code in blocks(page)]


@pytest.mark.skipif(not HAS_DOCS, reason="needs the source tree's docs/")
@pytest.mark.parametrize("page, line, code", CASES,
                         ids=["{}:{}".format(p, n) for p, n, _ in CASES])
def test_block_runs_as_written(page, line, code, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # what a block writes lands here
    monkeypatch.setenv("MPLBACKEND", "Agg")
    run_doc_block(code, "{}:{}".format(page, line))


@pytest.mark.skipif(not HAS_DOCS, reason="needs the source tree's docs/")
def test_the_pages_have_blocks_and_claims():
    """The extractor finds the blocks (a changed fence would silently
    skip them) and the README's quoted deflections."""
    assert len(CASES) >= 3
    assert all(blocks(p) for p in ELSEWHERE)
    readme = [c for p, _, c in CASES if p == "README.md"]
    assert {e for e, _ in claims(readme[0])} >= {"u[1::2].max()",
                                                 "uc[1::2].max()"}
    assert sum(len(blocks(p)) for p in MPI_PAGES) == 2
    assert np.isclose(float(dict(claims("x = 1  # a.b = 2.50"))["a.b"]),
                      2.5)
