"""Every ```python snippet of docs/python.md runs, in a scratch folder holding what they read: tests/ (cube1.geo)
and out/wave, a short run of the wave scene with checkpoints at steps 100 and 200 and its fields.csv."""

import os
import re
import subprocess
import sys

import pytest

import basalt

from conftest import ROOT, run

SNIPPETS = re.findall(r"```python\n(.*?)```", (ROOT / "docs" / "python.md").read_text(), re.S)


@pytest.fixture(scope="module")
def work(bin_dir, tmp_path_factory):
    d = tmp_path_factory.mktemp("docs")
    os.symlink(ROOT / "tests", d / "tests")
    basalt.pack.box(size=(6, 6, 6), rmin=0.3, rmax=1.0, seed=7, output=d / "small.h5")
    run([bin_dir / "basalt-run", ROOT / "scenes" / "wave.toml", "--geometry", d / "small.h5", "--steps", 200,
         "--checkpoint-every", 100, "--output", d / "out" / "wave"])
    return d


def test_there_are_snippets():
    assert len(SNIPPETS) >= 5


@pytest.mark.parametrize("index", range(len(SNIPPETS)))
def test_snippet_runs(work, index):
    p = subprocess.run([sys.executable, "-c", SNIPPETS[index]], cwd=work, capture_output=True, text=True,
                       env=dict(os.environ))
    assert p.returncode == 0, f"docs/python.md snippet {index + 1}:\n{SNIPPETS[index]}\n{p.stdout}\n{p.stderr}"
