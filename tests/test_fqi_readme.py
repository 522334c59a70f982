"""The README's doctest examples run, among them "FQI on your own environment"."""
import doctest
import pathlib

import pytest

README = pathlib.Path(__file__).resolve().parents[1] / "README.md"


def test_readme_examples_run():
    result = doctest.testfile(str(README), module_relative=False)
    if result.attempted == 0:
        pytest.skip("the README has no doctest examples")
    assert result.failed == 0
