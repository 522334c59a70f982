"""The documentation site: it builds with no warning, runs every gallery example, and its API
reference covers every public name.

Builds docs/ with ``sphinx-build -W --keep-going -b html`` into a temporary folder (about
20 s on 2 cores, the examples included). The gallery's and autosummary's generated pages
land in docs/ (auto_examples/, generated/, gen_modules/, ignored by git), as in any build.
Needs the ``docs`` extra; skipped without it.
"""
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("sphinx")
pytest.importorskip("sphinx_gallery")
pytest.importorskip("numpydoc")
pytest.importorskip("myst_parser")
pytest.importorskip("pydata_sphinx_theme")

import boxtrees  # noqa: E402
import envs  # noqa: E402
import fqi  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted(path.stem for path in (ROOT / "examples").glob("plot_*.py"))


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    """The built site's folder (the build's output is in the failure message)."""
    out = tmp_path_factory.mktemp("site")
    command = [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-b", "html",
               "-d", str(out / "doctrees"),
               # run every example, even one whose output docs/auto_examples already has
               "-D", "sphinx_gallery_conf.run_stale_examples=True",
               str(ROOT / "docs"), str(out / "html")]
    done = subprocess.run(command, cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, (f"sphinx-build failed ({done.returncode}):\n"
                                  f"{done.stdout[-4000:]}\n{done.stderr[-8000:]}")
    return out / "html"


def test_pages(site):
    for page in ("index", "user_guide", "api", "auto_examples/index", "boxtrees", "fqi",
                 "game", "thesis", "results/REPORT", "reproduction"):
        assert (site / f"{page}.html").is_file(), page


def test_examples_ran_and_drew(site):
    assert len(EXAMPLES) >= 3
    for name in EXAMPLES:
        html = (site / "auto_examples" / f"{name}.html").read_text(encoding="utf-8")
        assert "sphx-glr-single-img" in html or "sphx-glr-multi-img" in html, name
        assert "Traceback" not in html, name
        assert list((site / "_images").glob(f"sphx_glr_{name}_*.png")), name


@pytest.mark.parametrize("package", [boxtrees, envs, fqi], ids=lambda p: p.__name__)
def test_every_public_name_is_documented(site, package):
    api = (site / "api.html").read_text(encoding="utf-8")
    for name in package.__all__:
        qualified = f"{package.__name__}.{name}"
        page = site / "generated" / f"{qualified}.html"
        assert page.is_file() or f'id="{qualified}"' in api, qualified
