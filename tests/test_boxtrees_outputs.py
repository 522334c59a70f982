"""Several outputs and class labels: the classifiers, and multi-output regression."""
import numpy as np
import pytest

from boxtrees import (
    BoxExtraTreeClassifier, BoxExtraTreesClassifier, BoxExtraTreesRegressor, make_box_regression,
)
from conftest import THESIS_FOREST, THESIS_TREE

PARAMS = dict(THESIS_FOREST, n_estimators=4, n_tests=30, min_samples_split=10, random_state=0)


def presence(sets, region_type=0):
    """1 where a set has an object of ``region_type`` in the unit square at the origin."""
    return np.array([((np.abs(s[:, :2]).max(1) < 1) & (s[:, 2] == region_type)).any() for s in sets],
                    dtype=int)


@pytest.fixture(scope="module")
def data():
    X, y = make_box_regression(1200, mean_objects=12, extent=3.0, half_width=1.0, random_state=0)
    return list(X), y


def test_two_outputs_give_two_columns_and_a_scaled_copy_grows_the_same_trees(data):
    X, y = data
    single = BoxExtraTreesRegressor(**PARAMS).fit(X, y)
    double = BoxExtraTreesRegressor(**PARAMS).fit(X, np.column_stack([y, 3 * y]))
    assert double.n_outputs_ == 2 and single.n_outputs_ == 1
    pred = double.predict(X[:100])
    assert pred.shape == (100, 2) and single.predict(X[:100]).shape == (100,)
    # the criterion sums over outputs: (1 + 3^2) times one output's, so the same splits win
    for a, b in zip(single, double):
        np.testing.assert_array_equal(a.tree_.children_left, b.tree_.children_left)
        np.testing.assert_array_equal(a.tree_.box, b.tree_.box)
    np.testing.assert_allclose(pred, np.column_stack([single.predict(X[:100])] * 2) * [1, 3], rtol=1e-9)


def test_a_binary_classifier_is_the_regressor_on_the_class_indicator(data):
    X, _ = data
    labels = np.where(presence(X), "coin", "none")
    classifier = BoxExtraTreesClassifier(**PARAMS).fit(X, labels)
    regressor = BoxExtraTreesRegressor(**PARAMS).fit(X, (labels == "none").astype(float))
    proba = classifier.predict_proba(X)
    assert classifier.classes_.tolist() == ["coin", "none"]
    np.testing.assert_array_equal(proba[:, 1], regressor.predict(X))
    np.testing.assert_allclose(proba.sum(axis=1), 1.0)
    assert classifier.score(X, labels) > 0.95
    # leaves hold class frequencies and Gini impurity
    tree = classifier[0].tree_
    assert tree.value.shape == (tree.node_count, 2)
    np.testing.assert_allclose(tree.impurity, 1 - (tree.value ** 2).sum(axis=1))


def test_multiclass_and_multi_output_classification(data):
    X, y = data
    three = np.digitize(y, np.quantile(y, [1 / 3, 2 / 3]))            # classes 0, 1, 2
    forest = BoxExtraTreesClassifier(**PARAMS).fit(X, three)
    proba = forest.predict_proba(X)
    assert proba.shape == (len(X), 3) and forest.n_classes_ == 3
    np.testing.assert_allclose(proba.sum(axis=1), 1.0)
    assert (forest.predict(X) == three).mean() > 0.8
    both = np.column_stack([three, np.where(presence(X), "yes", "no")])
    multi = BoxExtraTreesClassifier(**PARAMS).fit(X, both)
    assert multi.n_outputs_ == 2 and multi.n_classes_ == [3, 2]
    assert [c.tolist() for c in multi.classes_] == [["0", "1", "2"], ["no", "yes"]]
    probas = multi.predict_proba(X[:50])
    assert [p.shape for p in probas] == [(50, 3), (50, 2)]
    assert multi.predict(X[:50]).shape == (50, 2)
    assert (multi.predict(X)[:, 1] == both[:, 1]).mean() > 0.95


def test_classifier_weights_and_a_single_tree(data):
    X, _ = data
    labels = presence(X)
    weights = np.where(labels == 1, 5.0, 1.0)
    weighted = BoxExtraTreesClassifier(**PARAMS).fit(X, labels, sample_weight=weights)
    halved = BoxExtraTreesClassifier(**PARAMS).fit(X, labels, sample_weight=weights / 2)
    np.testing.assert_allclose(weighted.predict_proba(X), halved.predict_proba(X), rtol=1e-9)
    # up-weighting the positives raises their probabilities at leaves holding both classes
    plain = BoxExtraTreesClassifier(**PARAMS).fit(X, labels)
    assert weighted.predict_proba(X)[:, 1].mean() > plain.predict_proba(X)[:, 1].mean()
    tree = BoxExtraTreeClassifier(**THESIS_TREE, min_samples_split=2, random_state=0).fit(X, labels)
    assert tree.score(X, labels) == 1.0 and tree.get_n_leaves() > 10
    with np.errstate(divide="ignore"):
        np.testing.assert_array_equal(np.log(tree.predict_proba(X[:5])), tree.predict_log_proba(X[:5]))
