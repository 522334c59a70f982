"""Every docstring example of the packages runs (each module of boxtrees, fqi and envs, and the
benchmarks' run statistics), and so does every ```python block of README.md and docs/*.md: a
block of ">>>" examples as a doctest (README.md's in tests/test_fqi_readme.py), any other as
a script. A block that cannot run in the tests (a long training run) has a marker on the
line above its fence, ``<!-- skip-test: why -->``; it is still compiled."""
import doctest
import importlib
import json
import pathlib
import pkgutil
import re
import sys
from dataclasses import dataclass

import pytest

import boxtrees
import envs
import fqi

MODULES = sorted(
    info.name
    for package in (boxtrees, fqi, envs)
    for info in pkgutil.iter_modules(package.__path__, package.__name__ + ".")
) + ["boxtrees", "fqi", "envs", "benchmarks.reproduce.stats"]

ROOT = pathlib.Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
PAGES = [README, *sorted((ROOT / "docs").glob("*.md"))]
# a ```python fence, the optional marker on the line above it, and the block up to its end
_BLOCK = re.compile(r"^(?:<!-- skip-test: (?P<skip>.+) -->\n)?```python\n(?P<code>.*?)^```$",
                    re.MULTILINE | re.DOTALL)


@dataclass(frozen=True)
class _Block:
    """One ```python block of a page: where its code starts, its code, its skip reason."""

    page: pathlib.Path
    line: int
    code: str
    skip: str = None

    @property
    def is_doctest(self):
        return any(line.lstrip().startswith(">>>") for line in self.code.splitlines())

    def __str__(self):
        return f"{self.page.relative_to(ROOT)}:{self.line}"

    def compiled(self):
        return compile(self.code, str(self), "exec")


def _blocks(page):
    text = page.read_text()
    return [_Block(page, text.count("\n", 0, match.start("code")) + 1, match["code"],
                   match["skip"])
            for match in _BLOCK.finditer(text)]


BLOCKS = [block for page in PAGES for block in _blocks(page)]


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples_run(name):
    result = doctest.testmod(importlib.import_module(name), optionflags=doctest.ELLIPSIS)
    assert result.failed == 0


def test_the_examples_are_found():
    """The estimators, the agent and the game each show a tested example."""
    finder = doctest.DocTestFinder()
    for obj in (boxtrees.BoxExtraTreesRegressor, boxtrees.BoxExtraTreesClassifier,
                fqi.FQI, fqi.evaluate, envs.PaddedObjects):
        assert any(test.examples for test in finder.find(obj)), obj


def test_every_python_block_of_the_pages_is_run_or_says_why_not():
    assert len(BLOCKS) >= 8  # the parsing finds them
    for page in PAGES:  # no other spelling of a Python fence escapes the parsing
        fences = re.findall(r"^```(\w*)$", page.read_text(), re.MULTILINE)
        assert not set(fences) & {"py", "python3", "pycon", "Python"}, page
    for block in BLOCKS:
        # doctest.testfile runs every example of a page: a marker cannot stop it
        assert not (block.is_doctest and block.skip), f"{block}: mark examples +SKIP instead"


@pytest.mark.parametrize("page", [page for page in PAGES[1:]
                                  if any(block.is_doctest for block in _blocks(page))],
                         ids=lambda page: page.name)
def test_page_doctests_run(page):
    result = doctest.testfile(str(page), module_relative=False, optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0, result


@pytest.mark.parametrize("block", [block for block in BLOCKS if not block.is_doctest], ids=str)
def test_page_scripts_run(block, tmp_path, monkeypatch):
    code = block.compiled()
    if block.skip:
        pytest.skip(block.skip)
    monkeypatch.chdir(tmp_path)  # what a script writes lands here
    exec(code, {"__name__": "__main__"})


def test_the_runs_comparison_of_reproduction_md(tmp_path, monkeypatch, capsys):
    """The script that checks a cluster's records against a local run ignores the timing
    fields only."""
    block, = [block for block in _blocks(ROOT / "docs" / "reproduction.md")
              if "timeless" in block.code]
    record = {"result": {"rewards": [1.0, 2.0], "seconds": 3.0,
                         "history": [{"t_fit": 0.5, "n_samples": 10}]}}
    for folder, seconds, t_fit, last in (("a", 3.0, 0.5, 2.0), ("b", 4.0, 0.7, 9.0)):
        for seed, reward in ((0, 2.0), (1, last)):
            path = tmp_path / folder / "runs" / "full" / "fqi_K" / "K=50" / f"seed{seed}.json"
            path.parent.mkdir(parents=True, exist_ok=True)
            result = {"rewards": [1.0, reward], "seconds": seconds,
                      "history": [{"t_fit": t_fit, "n_samples": 10}]}
            path.write_text(json.dumps({**record, "result": result}))
    monkeypatch.setattr(sys, "argv", ["compare.py", str(tmp_path / "a"), str(tmp_path / "b")])
    exec(block.compiled(), {"__name__": "__main__"})
    assert capsys.readouterr().out.splitlines() == ["same runs/full/fqi_K/K=50/seed0.json",
                                                    "DIFFERENT runs/full/fqi_K/K=50/seed1.json"]
