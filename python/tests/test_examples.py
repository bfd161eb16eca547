"""The notebook-style examples of examples/python run to their end, and the README's Python
example does what it says."""

import pathlib
import re
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]


def test_the_tour_runs(tmp_path):
    run = subprocess.run([sys.executable, str(ROOT / "examples" / "python" / "tour.py")], capture_output=True, text=True, cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    out = run.stdout
    assert "Planet(preset:earthlike:7" in out
    assert re.search(r"\d+ surfaces along the column", out)
    assert "Path(" in out and "not found" not in out
    assert re.search(r"the ground at 10, 20: (-?[\d.]+) m before the dig, (-?[\d.]+) m after", out)
    before, after = map(float, re.search(r"(-?[\d.]+) m before the dig, (-?[\d.]+) m after", out).groups())
    assert after < before
    assert re.search(r"\d+ chunks welded: \d+ vertices", out)


def test_the_readme_example_runs(tmp_path):
    readme = (ROOT / "README.md").read_text()
    section = readme.split("## Use it from Python", 1)[1]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    assert "moon" in run.stdout
