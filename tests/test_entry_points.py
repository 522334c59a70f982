"""The reproduction's command line starts both ways the documentation gives it, from the
repository's root: ``python -m benchmarks.run_all`` and ``python benchmarks/run_all.py``
(and the latter in a fresh clone of the repository, with no file left by earlier runs).

Each case starts a Python process that parses its arguments and plans, running nothing
(about 3 s each)."""
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from benchmarks.reproduce.registry import REGISTRY

ROOT = Path(__file__).resolve().parents[1]
ENTRY_POINTS = {"module": ["-m", "benchmarks.run_all"], "script": ["benchmarks/run_all.py"]}


def _run(entry, *args, cwd=ROOT):
    done = subprocess.run([sys.executable, *ENTRY_POINTS[entry], *args], cwd=cwd,
                          capture_output=True, text=True, timeout=120)
    return done


@pytest.mark.parametrize("entry", ENTRY_POINTS)
def test_help_prints_the_usage_and_every_experiment(entry):
    done = _run(entry, "--help")
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("usage: "), done.stdout[:200]
    help_text = " ".join(done.stdout.split())  # argparse wraps the list of names
    for name in REGISTRY:
        assert name in help_text, name


@pytest.mark.parametrize("entry", ENTRY_POINTS)
def test_plan_counts_the_runs_and_writes_nothing(entry, tmp_path):
    out = tmp_path / "results"
    done = _run(entry, "--plan", "--only", "rmse_K", "--budget", "tiny", "--out", str(out))
    assert done.returncode == 0, done.stderr
    assert "runs planned at the tiny budget" in done.stdout, done.stdout
    assert not out.exists()


def test_an_unknown_experiment_is_refused_with_the_known_ones():
    done = _run("script", "--only", "no_such_experiment")
    assert done.returncode == 2
    assert "unknown experiment(s) no_such_experiment" in done.stderr, done.stderr
    assert all(name in done.stderr for name in REGISTRY), done.stderr


@pytest.mark.skipif(shutil.which("git") is None or not (ROOT / ".git").exists(),
                    reason="needs git and a git checkout")
def test_the_script_runs_in_a_fresh_clone(tmp_path):
    """A clone holds the committed files only: the test checks the last commit."""
    clone = tmp_path / "clone"
    subprocess.run(["git", "clone", "-q", str(ROOT), str(clone)], check=True, timeout=120)
    done = _run("script", "--help", cwd=clone)
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("usage: "), done.stdout[:200]
