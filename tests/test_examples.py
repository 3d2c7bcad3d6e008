"""The short literate examples of ``docs/examples`` run and print what
their docstrings claim (as scikit-fem's ``tests/test_examples.py`` does):
each runs in its own process, writes its figure, and its printed numbers
are checked."""
import os
import re
import subprocess
import sys

import numpy as np
import pytest

EXAMPLES = os.path.join(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__))), "docs", "examples")


def run(name, tmp_path):
    out = subprocess.run([sys.executable, os.path.join(EXAMPLES, name)],
                         capture_output=True, text=True, timeout=600,
                         env={**os.environ, "SKFEM_PG_OUT": str(tmp_path),
                              "SKFEM_PG_CACHE": str(tmp_path / "cache"),
                              "MPLBACKEND": "Agg"})
    assert out.returncode == 0, out.stderr[-2000:]
    assert os.path.exists(tmp_path / name.replace(".py", ".png"))
    return out.stdout


def numbers(line):
    return [float(v) for v in re.findall(r"[-+]?\d+\.?\d*(?:e[-+]?\d+)?",
                                         line)]


def test_ex01_poisson(tmp_path):
    rows = re.findall(r"PG (\S+), Q1 (\S+)", run("ex01_poisson.py",
                                                   tmp_path))
    pg_err, q1_err = np.array(rows, dtype=float).T
    assert len(pg_err) == 3
    for e in (pg_err, q1_err):  # second order: 4x per halving of h
        assert np.all(e[:-1] / e[1:] > 2.8)
    assert pg_err[-1] < 1e-2 and q1_err[-1] < pg_err[-1]


def test_ex02_cantilever(tmp_path):
    lines = [l for l in run("ex02_cantilever.py", tmp_path).splitlines()
             if "tip error" in l]
    errors = np.abs([[float(v) for v in re.findall(r"([-+]\d+\.\d+)%", l)]
                     for l in lines])  # per cent
    assert errors.shape == (3, 4)
    assert np.all(errors[-1] < 3.0)  # per cent, at 1105 nodes
    assert np.all(errors[0] > errors[-1])


def test_ex03_coupling(tmp_path):
    out = run("ex03_coupling.py", tmp_path)
    assert numbers(out.split("patch test: max error")[1])[0] <= 1e-10
    q1, coupled, pg = map(float, re.search(
        r"Q1 (\S+) \| coupled (\S+) \| PG (\S+)", out).groups())
    assert q1 < coupled < pg


@pytest.mark.slow  # its Q2 overkill takes a minute when not cached
def test_ex04_incompressible(tmp_path):
    out = run("ex04_incompressible.py", tmp_path)
    err = {name: numbers(l.split("(")[1])[0] for l in out.splitlines()
           for name in ("Unl ", "UnlP0", "Q1 ", "Q1P0") if name in l + " "}
    assert err["Unl "] < -30 and err["Q1 "] < -30  # locking
    assert abs(err["UnlP0"]) < 5 and abs(err["Q1P0"]) < 5


def test_ex05_vibration(tmp_path):
    out = run("ex05_vibration.py", tmp_path)
    ref = numbers(out.split("cells):")[1])[0]
    for line in out.splitlines():
        if "first period" in line:
            period, energy = numbers(line.split("period")[1])[:2]
            assert abs(period / ref - 1) < 0.06
            assert energy < 1e-9
