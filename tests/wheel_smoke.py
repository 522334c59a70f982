"""Smoke test of an installed ``boxtrees``: it imports without the extras' libraries, fits and
predicts.

cibuildwheel runs it on every wheel it builds (``[tool.cibuildwheel]`` in pyproject.toml) and
tests/test_packaging.py in a fresh environment holding only the wheel and its runtime
dependencies. Run as a script, it has its own folder on ``sys.path``, not the source tree, so
the installed package is the one imported; it exits non-zero on failure.
"""
import sys

import numpy as np

import boxtrees
from boxtrees import BoxExtraTreesClassifier, BoxExtraTreesRegressor

# the `fqi`, `envs` and `baselines` extras' libraries: importing boxtrees needs none of them
EXTRAS = ("gymnasium", "torch", "stable_baselines3", "tqdm")


def _sets(rng, n):
    """``n`` sets of up to 12 objects ``[x, y, type]`` of types 0 and 1 in [-3, 3]^2."""
    return [np.column_stack([rng.uniform(-3, 3, (k, 2)), rng.integers(0, 2, k)])
            for k in rng.integers(0, 12, n)]


def _coins(s):
    """The number of type-0 objects in the unit square at the origin."""
    return float(((np.abs(s[:, :2]).max(1) < 1) & (s[:, 2] == 0)).sum())


def main():
    rng = np.random.default_rng(0)
    X, X_test = _sets(rng, 600), _sets(rng, 200)
    y, y_test = [_coins(s) for s in X], [_coins(s) for s in X_test]
    forest = BoxExtraTreesRegressor(n_estimators=10, random_state=0).fit(X, y)
    score = forest.score(X_test, y_test)
    assert score > 0.5, f"R^2 {score:.3f} on a task the forest learns (about 0.9)"
    assert forest.predict([np.array([[0.2, -0.5, 0]]), np.empty((0, 3))]).shape == (2,)
    labels = ["coin" if c else "none" for c in y]
    classifier = BoxExtraTreesClassifier(n_estimators=10, random_state=0).fit(X, labels)
    assert set(classifier.predict(X_test)) <= {"coin", "none"}
    loaded = sorted(name for name in EXTRAS if name in sys.modules)
    assert not loaded, f"boxtrees imported {loaded}"
    print(f"boxtrees {boxtrees.__version__} from {boxtrees.__file__}: R^2 {score:.3f}")


if __name__ == "__main__":
    main()
