"""scikit-learn's estimator checks, run on the real Cython engine (no expected failures)."""
from sklearn.utils.estimator_checks import parametrize_with_checks

from boxtrees import (
    BoxExtraTreeClassifier, BoxExtraTreeRegressor, BoxExtraTreesClassifier, BoxExtraTreesRegressor,
    GridCounts,
)

TEST_TYPES = ("fixed", "bounded", "random", "classic")
ESTIMATORS = (
    [BoxExtraTreesRegressor(n_estimators=5, test_type=t, random_state=0) for t in TEST_TYPES]
    + [BoxExtraTreeRegressor(test_type=t, random_state=0) for t in TEST_TYPES]
    + [BoxExtraTreesClassifier(n_estimators=5, test_type=t, random_state=0) for t in TEST_TYPES]
    + [BoxExtraTreeClassifier(test_type=t, random_state=0) for t in TEST_TYPES]
    + [GridCounts(n_bins=4)]
)


@parametrize_with_checks(ESTIMATORS, expected_failed_checks=lambda est: {})
def test_sklearn_compatible(estimator, check):
    check(estimator)
