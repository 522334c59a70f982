"""The thesis's trees are frozen: objects ``[x, y, type]`` (d = 2) with the thesis's settings,
and feature matrices, grow the same trees, bit for bit, as the code behind the committed
results did (digests of every node array, taken before objects had d attributes)."""
import hashlib

import numpy as np
import pytest

from boxtrees import BoxExtraTreesClassifier, BoxExtraTreesRegressor, make_box_regression

# the thesis's settings (fqi.make_box_forest) and the variants the registry runs
THESIS = dict(n_tests=500, min_samples_split=30, test_width=1.0, max_retries=10,
              refine_tests=False, bootstrap=False)


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
    ("fixed", {}, "a8cbc610ae49369f"),
    ("bounded", {"test_width": 4.0}, "99706aec48198128"),
    ("random", {}, "39d4fe5f480207dc"),
    ("classic", {}, "446cdf5bca2b6c0c"),
    ("fixed", {"refine_tests": True, "bootstrap": True}, "4ed3b23047541c5e"),
    ("fixed", {"view_bounds": 12.0}, "d9f6ed25f0875c68"),
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
    dense = BoxExtraTreesRegressor(3, n_tests=10, min_samples_split=10, test_type="classic",
                                   random_state=2).fit(F, F[:, 0] - F[:, 3] ** 2)
    assert (_digest(classifier), _digest(dense, dense=True)) == ("22c401473023054c", "4bf40a9580e43553")
