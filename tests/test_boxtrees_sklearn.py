"""scikit-learn's estimator checks, run on the real Cython engine.

No expected failures, except one that scikit-learn also expects of its own bootstrapping
forests: a bootstrap draw on repeated rows is not the draw on weighted rows.
"""
from sklearn.utils.estimator_checks import parametrize_with_checks

from boxtrees import (
    BoxExtraTreeClassifier, BoxExtraTreeRegressor, BoxExtraTreesClassifier, BoxExtraTreesRegressor,
    GridCounts,
)

TEST_TYPES = ("fixed", "bounded", "random", "classic")
# the thesis's engine: widths in the data's units, no refinement, no bootstrap
PLAIN = dict(relative_width=False, refine_tests=False)
ESTIMATORS = (
    # the defaults (refined tests, bootstrap forests), with each test type
    [BoxExtraTreesRegressor(n_estimators=5, test_type=t, random_state=0) for t in TEST_TYPES]
    + [BoxExtraTreeRegressor(test_type=t, random_state=0) for t in TEST_TYPES]
    + [BoxExtraTreesClassifier(n_estimators=5, test_type=t, random_state=0) for t in TEST_TYPES]
    + [BoxExtraTreeClassifier(test_type=t, random_state=0) for t in TEST_TYPES]
    # the thesis's settings
    + [Forest(n_estimators=5, test_type=t, bootstrap=False, random_state=0, **PLAIN)
       for Forest in (BoxExtraTreesRegressor, BoxExtraTreesClassifier) for t in TEST_TYPES]
    + [BoxExtraTreeRegressor(test_type="fixed", random_state=0, **PLAIN)]
    + [GridCounts(n_bins=4)]
)


def expected_failures(estimator):
    if not getattr(estimator, "bootstrap", False):
        return {}
    return {"check_sample_weight_equivalence_on_dense_data":
            "a bootstrap sample of repeated rows differs from one of weighted rows"}


@parametrize_with_checks(ESTIMATORS, expected_failed_checks=expected_failures)
def test_sklearn_compatible(estimator, check):
    check(estimator)
