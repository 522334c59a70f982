"""The estimators' defaults: the same model whatever the units of each attribute, and
accuracy that holds on sets larger than those seen at fit (docs/boxtrees.md, "Defaults")."""
import numpy as np
import pytest
from sklearn.metrics import r2_score

from benchmarks.bench_defaults import coin_task, scaled
from benchmarks.bench_sets import make_data
from boxtrees import BoxExtraTreesClassifier, BoxExtraTreesRegressor


@pytest.mark.parametrize("test_type", ["random", "fixed", "bounded", "classic"])
def test_the_defaults_give_the_same_model_in_any_units(test_type):
    X, y = coin_task(0, 2000)
    X_test, y_test = coin_task(1, 500)
    scores = {}
    for factors in ([1.0, 1.0], [100.0, 100.0], [0.01, 0.01], [100.0, 0.01]):
        forest = BoxExtraTreesRegressor(10, test_type=test_type, random_state=0)
        forest.fit(scaled(X, np.array(factors)), y)
        scores[tuple(factors)] = r2_score(y_test, forest.predict(scaled(X_test, np.array(factors))))
    original = scores[(1.0, 1.0)]
    assert original > (0.5 if test_type == "classic" else 0.9), scores   # (half-planes: coarse)
    assert all(abs(score - original) <= 0.02 for score in scores.values()), scores


def test_widths_in_the_data_units_are_what_the_thesis_ran():
    # the same task in pixels: the thesis's boxes of half-width 1 no longer fit it; the
    # defaults' do
    X, y = coin_task(0, 2000)
    X_test, y_test = coin_task(1, 500)
    absolute = BoxExtraTreesRegressor(10, test_type="fixed", test_width=1.0, relative_width=False,
                                      refine_tests=False, bootstrap=False,
                                      random_state=0).fit(scaled(X, np.array([100, 100])), y)
    relative = BoxExtraTreesRegressor(10, test_type="fixed", random_state=0).fit(
        scaled(X, np.array([100, 100])), y)
    pixels = scaled(X_test, np.array([100, 100]))
    assert r2_score(y_test, relative.predict(pixels)) > r2_score(y_test, absolute.predict(pixels)) + 0.5


@pytest.mark.parametrize("task", ["count", "compare"])
def test_the_defaults_keep_their_accuracy_on_sets_15_times_larger(task):
    (train, labels), tests = make_data(task, n_train=4000, n_test=300, seed=0)
    forest = BoxExtraTreesClassifier(30, random_state=0, n_jobs=1).fit(train, labels > 0.5)
    at_20 = forest.score(tests[20][0], tests[20][1] > 0.5)
    at_300 = forest.score(tests[300][0], tests[300][1] > 0.5)
    assert at_20 > 0.95 and at_300 > at_20 - 0.03, (at_20, at_300)
