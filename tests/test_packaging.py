"""The sdist and the wheel as users get them.

Builds the sdist from a copy of this checkout and the wheel from the sdist (``python -m
build``, isolated: setuptools, Cython and numpy come from the package index), checks what
each holds, installs the wheel into a fresh virtual environment with its runtime dependencies
only (binary wheels only, so nothing compiles there) and runs tests/wheel_smoke.py in it:
``boxtrees`` imports with neither gymnasium nor torch installed, fits and predicts. Then the
``envs`` and ``fqi`` extras are installed, and their packages import.

Compiling the C++ core takes a minute or two of the machine's 2 cores and the test needs the
package index, so ``make test`` skips it; CI runs it after ``make test`` (.ci/run), with
``BOXTREES_TEST_DIST=1``.
"""
import os
import re
import shutil
import subprocess
import sys
import tarfile
import zipfile
from email.parser import Parser
from pathlib import Path

import pytest

import boxtrees

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("boxtrees", "envs", "fqi")
EXTENSIONS = ("_builder", "_layout", "_predictor", "_rows", "_splitter")
RUNTIME = {"numpy", "scipy", "scikit-learn", "joblib"}

pytestmark = pytest.mark.skipif(
    os.environ.get("BOXTREES_TEST_DIST") != "1",
    reason="builds the sdist and the wheel (compiles the core): BOXTREES_TEST_DIST=1 runs it",
)


def _run(command, **kwargs):
    """Run ``command``; its output, or a failure that shows the end of it."""
    result = subprocess.run([str(c) for c in command], capture_output=True, text=True,
                            timeout=1200, **kwargs)
    assert result.returncode == 0, (result.stdout + result.stderr)[-4000:]
    return result.stdout


@pytest.fixture(scope="module")
def dists(tmp_path_factory):
    """The paths of the sdist and of the wheel built from it."""
    tmp = tmp_path_factory.mktemp("dist")
    # a copy, so the build writes nothing into the checkout; the in-place build's C++ and
    # modules come along, as the sdist must leave them out
    source = tmp / "source"
    shutil.copytree(ROOT, source, ignore=shutil.ignore_patterns(
        ".*", "build", "dist", "*.egg-info", "__pycache__", "results"))
    _run([sys.executable, "-m", "build", "--outdir", tmp / "out", source])
    (sdist,) = (tmp / "out").glob("*.tar.gz")
    (wheel,) = (tmp / "out").glob("*.whl")
    return sdist, wheel


def test_the_sdist_holds_the_sources_and_nothing_built(dists):
    sdist, _ = dists
    with tarfile.open(sdist) as archive:
        names = {name.split("/", 1)[1] for name in archive.getnames() if "/" in name}
    sources = {str(p.relative_to(ROOT)).replace(os.sep, "/")
               for pattern in ("*.py", "*.pyx", "*.pxd", "*.h", "py.typed")
               for p in (ROOT / "boxtrees").glob(pattern)}
    assert {f"boxtrees/{name}.pyx" for name in EXTENSIONS} <= sources
    expected = sources | {f"{p}/py.typed" for p in PACKAGES} | {
        "setup.py", "pyproject.toml", "README.md", "LICENSE", "CHANGELOG.md"}
    assert expected <= names, sorted(expected - names)
    generated = [n for n in names if n.endswith((".cpp", ".so", ".pyd")) or n.startswith("tests/")]
    assert not generated, generated


def test_the_wheel_holds_the_compiled_core_and_needs_only_the_runtime_libraries(dists):
    _, wheel = dists
    with zipfile.ZipFile(wheel) as archive:
        names = set(archive.namelist())
        (metadata,) = [n for n in names if n.endswith(".dist-info/METADATA")]
        fields = Parser().parsestr(archive.read(metadata).decode())
    for name in EXTENSIONS:
        assert any(re.fullmatch(rf"boxtrees/{name}\..*(so|pyd)", n) for n in names), name
    assert {f"{p}/py.typed" for p in PACKAGES} <= names
    assert not [n for n in names if n.endswith(".cpp")]
    assert fields["Version"] == boxtrees.__version__
    requires = [re.match(r"[A-Za-z0-9_.-]+", r).group() for r in fields.get_all("Requires-Dist")
                if "extra ==" not in r]
    assert set(requires) == RUNTIME


def test_the_wheel_installs_and_runs_without_cython_or_the_extras(dists, tmp_path):
    _, wheel = dists
    subprocess.run([sys.executable, "-m", "venv", tmp_path / "env"], check=True)
    python = tmp_path / "env" / ("Scripts" if os.name == "nt" else "bin") / "python"
    install = [python, "-m", "pip", "install", "-q", "--only-binary", ":all:",
               "-c", ROOT / "constraints.txt"]
    _run([*install, wheel])
    _run([python, "-m", "pip", "check"])
    found = _run([python, "-c", "import importlib.util as u; print([m for m in ("
                  "'Cython', 'gymnasium', 'torch', 'stable_baselines3') if u.find_spec(m)])"])
    assert found.strip() == "[]"
    # a script: its own folder is on sys.path, not the checkout, so the wheel's boxtrees runs
    smoke = [python, ROOT / "tests" / "wheel_smoke.py"]
    assert str(tmp_path / "env") in _run(smoke, cwd=tmp_path)

    _run([*install, f"{wheel}[envs]"])
    _run([python, "-c", "import envs"])
    _run([*install, f"{wheel}[fqi]"])
    _run([python, "-c", "import fqi"])
    _run(smoke, cwd=tmp_path)   # gymnasium and tqdm installed now: still not imported
