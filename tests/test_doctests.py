"""Every docstring example of the packages runs (each module of boxtrees, fqi and envs)."""
import doctest
import importlib
import pkgutil

import pytest

import boxtrees
import envs
import fqi

MODULES = sorted(
    info.name
    for package in (boxtrees, fqi, envs)
    for info in pkgutil.iter_modules(package.__path__, package.__name__ + ".")
) + ["boxtrees", "fqi", "envs"]


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
