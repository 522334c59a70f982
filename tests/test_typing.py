"""Type hints of the public API (the packages ship ``py.typed``): every public function and
method of boxtrees and fqi is annotated, and the annotations type-check with mypy, on the
packages and on tests/typing_sample.py (the API as a user calls it), with the ``[tool.mypy]``
configuration of pyproject.toml (which ignores the missing type information of scikit-learn,
SciPy, joblib, tqdm and the Cython extensions). Needs mypy (the dev extra); skipped without
it. About 20 s: the first run reads the packages, the second finds them in its cache."""
import inspect
import subprocess
import sys
from pathlib import Path

import pytest

import boxtrees
import fqi

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("boxtrees", "fqi")


def _public_callables():
    """``(name, function)`` for every public function, and every ``__init__``, public method
    and property that the classes of the packages' ``__all__`` define themselves (not
    those inherited from scikit-learn, gymnasium or torch)."""
    for package in (boxtrees, fqi):
        for name in package.__all__:
            obj = getattr(package, name)
            if not inspect.isclass(obj):
                yield f"{package.__name__}.{name}", obj
                continue
            for klass in obj.__mro__:
                if klass.__module__.split(".")[0] not in PACKAGES:
                    continue
                for member, value in vars(klass).items():
                    if member.startswith("_") and member != "__init__":
                        continue
                    function = value.fget if isinstance(value, property) else \
                        getattr(value, "__func__", value)
                    if inspect.isfunction(function):
                        yield f"{package.__name__}.{name}.{member}", function


def test_every_public_function_and_method_is_annotated():
    missing = []
    for name, function in _public_callables():
        signature = inspect.signature(function)
        parameters = list(signature.parameters.values())
        if parameters and parameters[0].name in ("self", "cls"):
            parameters = parameters[1:]
        unannotated = [p.name for p in parameters if p.annotation is inspect.Parameter.empty]
        if signature.return_annotation is inspect.Signature.empty:
            unannotated.append("return")
        if unannotated:
            missing.append(f"{name}: {', '.join(unannotated)}")
    assert not missing, missing


@pytest.fixture(scope="module")
def cache_dir(tmp_path_factory):
    """One mypy cache for both runs, outside the checkout."""
    pytest.importorskip("mypy")
    return tmp_path_factory.mktemp("mypy_cache")


def _mypy(*arguments, cache_dir):
    command = [sys.executable, "-m", "mypy", "--config-file", str(ROOT / "pyproject.toml"),
               "--cache-dir", str(cache_dir), *arguments]
    done = subprocess.run(command, cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, f"{' '.join(command[2:])}:\n{done.stdout}{done.stderr}"


def test_the_public_api_as_a_user_calls_it(cache_dir):
    _mypy("tests/typing_sample.py", cache_dir=cache_dir)


def test_the_packages(cache_dir):
    _mypy(*PACKAGES, cache_dir=cache_dir)
