"""scikit-learn's estimator checks, run on the real Cython engine (no expected failures)."""
from sklearn.utils.estimator_checks import parametrize_with_checks

from boxtrees import BoxExtraTreesRegressor, GridCounts

ESTIMATORS = [
    BoxExtraTreesRegressor(n_estimators=5, test_type=test_type, random_state=0)
    for test_type in ("fixed", "bounded", "random", "classic")
] + [GridCounts(n_bins=4)]


@parametrize_with_checks(ESTIMATORS, expected_failed_checks=lambda est: {})
def test_sklearn_compatible(estimator, check):
    check(estimator)
