"""scikit-learn's estimator checks, run on the real Cython engine.

The expected failures are strict (a check that passes fails the test, so the list stays
true): the one scikit-learn also expects of its own bootstrapping forests (a bootstrap draw
on repeated rows is not the draw on weighted rows), and, for the forest classifiers with
``"random"`` or ``"classic"`` tests, the class weights 1000 : 0.0001 of
``check_class_weight_classifiers``. Their splits cut leaves holding only the nearly
weightless classes, which predict them: 48-82% of the check's samples get the heavy class
(``"random"``) and 78-94% (``"classic"``), where it asks for more than 87% (scikit-learn's
own forests pass it only with the ``min_weight_fraction_leaf=0.01`` the check sets, which
the box trees do not have). With ``"fixed"`` and ``"bounded"`` tests (boxes of a set width)
the forests give the heavy class to 90-100% of them, and pass.
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
    failures = {}
    if getattr(estimator, "bootstrap", False):
        failures["check_sample_weight_equivalence_on_dense_data"] = \
            "a bootstrap sample of repeated rows differs from one of weighted rows"
    if "class_weight" in estimator.get_params() and estimator.test_type in ("random", "classic"):
        failures["check_class_weight_classifiers"] = \
            "splits cut leaves holding only the nearly weightless classes, which predict them " \
            "(no min_weight_fraction_leaf)"
    return failures


@parametrize_with_checks(ESTIMATORS, expected_failed_checks=expected_failures, xfail_strict=True)
def test_sklearn_compatible(estimator, check):
    check(estimator)
