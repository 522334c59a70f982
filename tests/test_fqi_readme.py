"""The README's doctest examples run: the estimators, "FQI on your own environment" and
the game."""
import doctest
import pathlib

README = pathlib.Path(__file__).resolve().parents[1] / "README.md"


def test_readme_examples_run():
    result = doctest.testfile(str(README), module_relative=False)
    assert result.attempted >= 20 and result.failed == 0, result
