"""The documentation: every link of README.md and docs/*.md resolves, and the site builds with
no warning, runs every gallery example, and its API reference covers every public name.

The links: each relative link (and image) of the Markdown pages names a file or folder of the
repository, and its ``#anchor``, if any, a heading of the page it names (GitHub's anchors:
lower case, punctuation dropped, spaces as hyphens) or an ``<a id="...">`` of it. Links in
code are not links. No extra is needed.

The site: builds docs/ with ``sphinx-build -W --keep-going -b html`` into a temporary folder
(about 20 s on 2 cores, the examples included). The gallery's and autosummary's generated
pages land in docs/ (auto_examples/, generated/, gen_modules/, ignored by git), as in any
build. Needs the ``docs`` extra; those tests are skipped without it.
"""
import re
import subprocess
import sys
from pathlib import Path

import pytest

import boxtrees
import envs
import fqi

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted(path.stem for path in (ROOT / "examples").glob("plot_*.py"))
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]

# ```-fenced blocks, `code` spans, [text](target) and ![alt](target) links, headings, anchors
_FENCE = re.compile(r"^```.*?^```$", re.MULTILINE | re.DOTALL)
_CODE = re.compile(r"`[^`\n]*`")
_LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
_HEADING = re.compile(r"^#{1,6}\s+(.*?)\s*#*\s*$", re.MULTILINE)
_ANCHOR = re.compile(r'<a\s+(?:id|name)="([^"]+)"')


def _prose(page):
    """`page`'s text without its fenced blocks."""
    return _FENCE.sub("", page.read_text(encoding="utf-8"))


def _slug(heading):
    """GitHub's anchor of a Markdown heading."""
    heading = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", heading)  # a link: its text
    return re.sub(r"[^\w\- ]", "", heading.lower()).replace(" ", "-")


def _anchors(page):
    """The anchors of `page`: its headings' (a repeated one gets -1, -2, ...) and its
    ``<a id>`` tags'."""
    text = _prose(page)
    anchors, seen = set(_ANCHOR.findall(text)), {}
    for heading in _HEADING.findall(text):
        slug = _slug(heading)
        anchors.add(f"{slug}-{seen[slug]}" if slug in seen else slug)
        seen[slug] = seen.get(slug, 0) + 1
    return anchors


def _links(page):
    """The targets of `page`'s links and images, outside code."""
    return _LINK.findall(_CODE.sub("", _prose(page)))


def test_the_link_check_finds_links_and_anchors():
    assert sum(len(_links(page)) for page in PAGES) >= 50
    assert {"which-attributes-a-box-bounds-column_groups",
            "scikit-learns-forest-parameters-warm_start-oob_score-max_samples-class_weight"
            } <= _anchors(ROOT / "docs" / "boxtrees.md")
    assert "one-forest-in-the-moves-frame" in _anchors(ROOT / "docs" / "fqi.md")
    assert "control_cartpole" in _anchors(ROOT / "docs" / "results" / "REPORT.md")


@pytest.mark.parametrize("page", PAGES, ids=lambda page: page.name)
def test_links_resolve(page):
    broken = []
    for target in _links(page):
        if re.match(r"[a-z][a-z0-9+.-]*:", target):  # https:, mailto: ...: not checked here
            continue
        path, _, anchor = target.partition("#")
        linked = (page.parent / path).resolve() if path else page
        if not linked.exists():
            broken.append(f"{target}: no such file")
        elif anchor and linked.suffix == ".md" and anchor not in _anchors(linked):
            broken.append(f"{target}: no such anchor in {linked.relative_to(ROOT)}")
    assert not broken, broken


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    """The built site's folder (the build's output is in the failure message)."""
    for tool in ("sphinx", "sphinx_gallery", "numpydoc", "myst_parser", "pydata_sphinx_theme"):
        pytest.importorskip(tool)
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


def test_source_links_resolve(site):
    """viewcode's [source] links name pages it wrote, the inspection functions' included
    (Sphinx's own parser cannot read their module: docs/conf.py reads it instead)."""
    for name in ("type_importance", "region_importance", "make_box_regression"):
        html = (site / "generated" / f"boxtrees.{name}.html").read_text(encoding="utf-8")
        assert re.search(rf'href="[^"]*_modules/boxtrees/\w+\.html#{name}"', html), name
    for page in site.rglob("*.html"):
        html = page.read_text(encoding="utf-8")
        for target in re.findall(r'href="([^"#]*_modules/[^"#]+)', html):
            assert (page.parent / target).resolve().is_file(), (page.name, target)
