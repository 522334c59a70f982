"""The thesis's trees are frozen: objects ``[x, y, type]`` (d = 2) with the thesis's settings,
and feature matrices, grow the same trees, bit for bit, as the code behind the committed
results did (digests of every node array, taken with the code before objects had d
attributes). The tests are drawn in the view square, as in the thesis's runs (a sampling
region read off the training objects has a margin since)."""
import hashlib

import numpy as np
import pytest

from boxtrees import BoxExtraTreesClassifier, BoxExtraTreesRegressor, make_box_regression

# the thesis's settings (fqi.make_box_forest, its view square) and the variants the registry
# and the set-size study run
THESIS = dict(n_tests=500, min_samples_split=30, test_type="fixed", test_width=1.0,
              relative_width=False, max_retries=10, refine_tests=False, bootstrap=False,
              view_bounds=12.0)


def _digest(forest, dense=False):
    h = hashlib.sha256()
    for estimator in forest:
        tree = estimator.tree_
        box = tree.box[:, :2] if dense else tree.box   # a column's interval
        for array in (tree.children_left, tree.children_right, tree.object_type, box,
                      tree.threshold, tree.value, tree.impurity, tree.n_node_samples,
                      tree.weighted_n_node_samples):
            h.update(np.ascontiguousarray(array).tobytes())
    return h.hexdigest()[:16]


CASES = [
    ("fixed", {}, "d9f6ed25f0875c68"),
    ("bounded", {"test_width": 4.0}, "947b396e6b037b53"),
    ("random", {}, "9344b0d6b8631edf"),
    ("classic", {}, "1fcf01e9e525ad4c"),
    ("fixed", {"refine_tests": True, "bootstrap": True}, "c59ece3c3e973aa4"),
    ("random", {"refine_tests": True, "bootstrap": True}, "7c10041e07de425e"),
]


@pytest.mark.parametrize("test_type, changes, digest", CASES)
def test_object_set_trees_are_frozen(test_type, changes, digest):
    X, y = make_box_regression(1500, random_state=3)
    forest = BoxExtraTreesRegressor(4, **{**THESIS, "test_type": test_type, **changes},
                                    random_state=0).fit(X, y)
    assert _digest(forest) == digest


def test_classifier_and_feature_matrix_trees_are_frozen():
    X, y = make_box_regression(1500, random_state=4)
    classifier = BoxExtraTreesClassifier(3, **THESIS, random_state=1).fit(X, y > np.median(y))
    rng = np.random.default_rng(0)
    F = rng.normal(size=(800, 6)).astype(np.float32)
    dense = BoxExtraTreesRegressor(3, **{**THESIS, "n_tests": 10, "min_samples_split": 10,
                                         "test_type": "classic", "view_bounds": None},
                                   random_state=2).fit(F, F[:, 0] - F[:, 3] ** 2)
    assert (_digest(classifier), _digest(dense, dense=True)) == ("505a13e24384164f", "4bf40a9580e43553")


def test_the_agents_thesis_forest_grows_the_thesis_trees():
    from fqi import make_box_forest

    X, y = make_box_regression(1500, random_state=3)
    forest = make_box_forest(n_estimators=4, view_bounds=12.0, n_jobs=1, random_state=0)
    assert _digest(forest.fit(X, y)) == CASES[0][2]
