"""The contributor guide's recipes run as written (issue 49): every
```python block of docs/guide/contributing.md, each in its own
interpreter (the recipes register rules and formulations)."""
import pathlib
import re
import subprocess
import sys

import pytest

GUIDE = pathlib.Path(__file__).resolve().parents[1] / "docs" / "guide" \
    / "contributing.md"
BLOCKS = re.findall(r"```python\n(.*?)```", GUIDE.read_text(), re.S) \
    if GUIDE.exists() else []


def test_the_guide_has_its_recipes():
    if not GUIDE.exists():
        pytest.skip("the tests run outside the repository (no docs/)")
    assert len(BLOCKS) == 4


@pytest.mark.parametrize("i", range(len(BLOCKS)))
def test_recipe_runs(i, tmp_path):
    script = tmp_path / "recipe{}.py".format(i + 1)
    script.write_text(BLOCKS[i])
    run = subprocess.run([sys.executable, str(script)], cwd=tmp_path,
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-3000:]
