"""scikit-learn habits on the box forests: warm_start, class_weight, oob_score, max_samples,
sparse targets, and the importance of object types and regions (boxtrees._inspection)."""
import pickle
import warnings

import numpy as np
import pytest
from scipy.sparse import csr_matrix
from sklearn.base import clone
from sklearn.datasets import make_classification
from sklearn.ensemble import ExtraTreesClassifier
from sklearn.inspection import partial_dependence, permutation_importance
from sklearn.metrics import mean_absolute_error
from sklearn.utils.class_weight import compute_sample_weight
from sklearn.utils.estimator_checks import parametrize_with_checks

from boxtrees import (
    BoxExtraTreeClassifier, BoxExtraTreeRegressor, BoxExtraTreesClassifier, BoxExtraTreesRegressor,
    ObjectSets, make_box_regression, region_importance, type_importance,
)

FORESTS = (BoxExtraTreesRegressor, BoxExtraTreesClassifier)
SMALL = dict(n_tests=50, min_samples_split=5)


def box_task(n, Forest, random_state=0):
    """`make_box_regression` sets, with the target as it is or as a class (above the median)."""
    X, y = make_box_regression(n, random_state=random_state)
    return X, y if Forest is BoxExtraTreesRegressor else np.where(y > np.median(y), "hi", "lo")


def coin_sets(n, rng, flip=0.0):
    """Sets of objects of types 0 and 1 in [-3, 3]^2; the label says whether one of type 0 is
    in the unit square around the origin (a share ``flip`` of the labels flipped)."""
    X = [np.column_stack([rng.uniform(-3, 3, (k, 2)), rng.integers(0, 2, k)])
         for k in rng.integers(0, 12, n)]
    y = np.array([((np.abs(s[:, :2]).max(1) < 1) & (s[:, 2] == 0)).any() for s in X])
    return X, y ^ (rng.random(n) < flip)


# warm_start


@pytest.mark.parametrize("Forest", FORESTS)
@pytest.mark.parametrize("n_jobs", [1, 2])
def test_warm_start_grows_only_the_new_trees_of_the_single_fit(Forest, n_jobs):
    X, y = box_task(300, Forest)
    forest = Forest(4, warm_start=True, random_state=0, n_jobs=n_jobs, **SMALL).fit(X, y)
    first = list(forest.estimators_)
    forest.set_params(n_estimators=7).fit(X, y)
    assert len(forest) == 7 and all(a is b for a, b in zip(forest.estimators_, first))
    single = Forest(7, random_state=0, n_jobs=2, **SMALL).fit(X, y)
    assert [e.random_state for e in forest] == [e.random_state for e in single]
    np.testing.assert_array_equal(forest.apply(X), single.apply(X))
    if Forest is BoxExtraTreesClassifier:
        np.testing.assert_array_equal(forest.predict_proba(X), single.predict_proba(X))
    else:
        np.testing.assert_array_equal(forest.predict(X), single.predict(X))


def test_warm_start_refuses_fewer_trees_and_warns_when_none_are_added():
    X, y = box_task(200, BoxExtraTreesRegressor)
    forest = BoxExtraTreesRegressor(4, warm_start=True, random_state=0, **SMALL).fit(X, y)
    trees = list(forest.estimators_)
    with pytest.raises(ValueError, match=r"n_estimators=3 must be larger or equal to "
                                         r"len\(estimators_\)=4 when warm_start==True"):
        forest.set_params(n_estimators=3).fit(X, y)
    with pytest.warns(UserWarning, match="does not fit new trees"):
        forest.set_params(n_estimators=4).fit(X, y)
    assert forest.estimators_ == trees
    # without warm_start, a fit starts over
    forest.set_params(warm_start=False, n_estimators=2).fit(X, y)
    assert len(forest) == 2 and forest.estimators_[0] is not trees[0]


def test_warm_start_refuses_data_its_trees_cannot_read_and_keeps_the_forest():
    rng = np.random.default_rng(0)
    X, y = coin_sets(300, rng)
    forest = BoxExtraTreesClassifier(3, warm_start=True, random_state=0, **SMALL).fit(X, y)
    before = forest.predict_proba(X)
    wider = [np.column_stack([s[:, :2], s[:, :1], s[:, 2:]]) for s in X]     # d = 3
    with pytest.raises(ValueError, match="n_attributes_ is 3, was 2"):
        forest.set_params(n_estimators=5).fit(wider, y)
    with pytest.raises(ValueError, match="classes_"):
        forest.fit(X, np.where(y, "yes", "no"))
    only_type_1 = [s[s[:, 2] == 1] for s in X]
    with pytest.raises(ValueError, match=r"types \[0\] are missing"):
        forest.fit(only_type_1, y)
    assert len(forest) == 3 and forest.n_attributes_ == 2
    np.testing.assert_array_equal(forest.predict_proba(X), before)


# class_weight


@pytest.mark.parametrize("bootstrap", [False, True])
def test_class_weight_weighs_the_samples_as_compute_sample_weight(bootstrap):
    rng = np.random.default_rng(0)
    X, y = coin_sets(400, rng, flip=0.1)
    sample_weight = rng.uniform(0.5, 2.0, len(y))
    for class_weight in ({False: 1.0, True: 5.0}, "balanced"):
        weighted = BoxExtraTreesClassifier(5, bootstrap=bootstrap, class_weight=class_weight,
                                           random_state=0, **SMALL).fit(X, y, sample_weight)
        plain = BoxExtraTreesClassifier(5, bootstrap=bootstrap, random_state=0, **SMALL)
        if class_weight == "balanced":
            # every class the same total weight: a weighted "balanced"
            totals = {c: sample_weight[y == c].sum() for c in (False, True)}
            class_weight = {c: sample_weight.sum() / (2 * t) for c, t in totals.items()}
        plain.fit(X, y, sample_weight * compute_sample_weight(class_weight, y))
        np.testing.assert_allclose(weighted.predict_proba(X), plain.predict_proba(X),
                                   atol=1e-12)
    unweighted = BoxExtraTreesClassifier(5, bootstrap=bootstrap, random_state=0, **SMALL)
    assert not np.allclose(unweighted.fit(X, y).predict_proba(X), weighted.predict_proba(X))


def test_class_weight_of_several_outputs_is_a_list_of_dicts():
    rng = np.random.default_rng(1)
    X, y = coin_sets(300, rng, flip=0.1)
    Y = np.column_stack([y, rng.integers(0, 3, len(y))])
    class_weight = [{0: 1.0, 1: 4.0}, {0: 1.0, 1: 2.0, 2: 0.5}]
    weighted = BoxExtraTreesClassifier(4, class_weight=class_weight, random_state=0,
                                       **SMALL).fit(X, Y)
    plain = BoxExtraTreesClassifier(4, random_state=0, **SMALL).fit(
        X, Y, compute_sample_weight(class_weight, Y))
    for a, b in zip(weighted.predict_proba(X), plain.predict_proba(X)):
        np.testing.assert_allclose(a, b, atol=1e-12)


def test_balanced_subsample_balances_each_trees_bootstrap_sample():
    rng = np.random.default_rng(2)
    X, y = coin_sets(300, rng, flip=0.1)
    params = dict(SMALL, view_bounds=3.5)   # the sampling region of every tree
    forest = BoxExtraTreesClassifier(3, class_weight="balanced_subsample", random_state=0,
                                     **params).fit(X, y)
    for tree in forest:
        draws = np.random.default_rng([tree.random_state, 1]).integers(0, len(y), len(y))
        weight = np.bincount(draws, minlength=len(y)) * compute_sample_weight(
            "balanced", y, indices=draws)
        alone = BoxExtraTreeClassifier(random_state=tree.random_state, **params).fit(X, y, weight)
        np.testing.assert_allclose(tree.predict_proba(X), alone.predict_proba(X), atol=1e-12)
    # without bootstrap samples, the balance is over the training set
    kinds = [BoxExtraTreesClassifier(3, bootstrap=False, class_weight=c, random_state=0,
                                     **params).fit(X, y).predict_proba(X)
             for c in ("balanced_subsample", "balanced")]
    np.testing.assert_array_equal(*kinds)


def test_balanced_class_weight_predicts_more_of_the_rare_class_as_sklearn_does():
    X, y = make_classification(800, n_features=6, weights=[0.9], flip_y=0.05, class_sep=0.5,
                               random_state=0)
    rare = {}
    for name, Forest in (("ours", BoxExtraTreesClassifier), ("sklearn", ExtraTreesClassifier)):
        for class_weight in (None, "balanced"):
            forest = Forest(20, class_weight=class_weight, min_samples_split=30, random_state=0)
            rare[name, class_weight] = forest.fit(X[:500], y[:500]).predict(X[500:]).mean()
    assert rare["ours", "balanced"] > 1.5 * rare["ours", None]
    assert rare["sklearn", "balanced"] > 1.5 * rare["sklearn", None]


def test_warm_start_warns_that_balanced_weights_follow_each_fit():
    rng = np.random.default_rng(0)
    X, y = coin_sets(100, rng)
    with pytest.warns(UserWarning, match="computed from the data of each fit"):
        BoxExtraTreesClassifier(2, class_weight="balanced", warm_start=True, **SMALL).fit(X, y)


# oob_score and max_samples


def test_oob_prediction_is_the_mean_of_the_trees_that_left_each_sample_out():
    X, y = make_box_regression(60, random_state=0)
    y = np.column_stack([y, -2 * y])            # several outputs
    with pytest.warns(UserWarning, match="Some inputs do not have OOB scores"):
        forest = BoxExtraTreesRegressor(2, oob_score=True, random_state=0, **SMALL).fit(X, y)
    total, count = np.zeros_like(y), np.zeros(len(y))
    for tree in forest:
        draws = np.random.default_rng([tree.random_state, 1]).integers(0, len(y), len(y))
        out = np.bincount(draws, minlength=len(y)) == 0
        total[out] += tree.predict(X[out])
        count[out] += 1
    assert (count == 0).any() and (count > 0).any()
    with np.errstate(invalid="ignore"):
        expected = total / count[:, None]
    np.testing.assert_allclose(forest.oob_prediction_, expected, rtol=1e-12)
    scored = count > 0
    assert forest.oob_score_ == pytest.approx(
        forest._default_oob_score(y[scored], expected[scored]))


def test_oob_score_is_close_to_a_held_out_score():
    X, y = make_box_regression(1500, random_state=0)
    forest = BoxExtraTreesRegressor(20, oob_score=True, random_state=0, n_jobs=2).fit(
        X[:1000], y[:1000])
    assert forest.oob_prediction_.shape == (1000,)
    assert forest.oob_score_ > 0.85
    assert abs(forest.oob_score_ - forest.score(X[1000:], y[1000:])) < 0.03

    X, y = coin_sets(1500, np.random.default_rng(0), flip=0.1)
    classes = np.where(y, "yes", "no")
    forest = BoxExtraTreesClassifier(20, oob_score=True, random_state=0, n_jobs=2).fit(
        X[:1000], classes[:1000])
    proba = forest.oob_decision_function_
    assert proba.shape == (1000, 2) and np.allclose(proba.sum(axis=1), 1.0)
    assert forest.oob_score_ == np.mean(forest.classes_[proba.argmax(axis=1)] == classes[:1000])
    assert abs(forest.oob_score_ - forest.score(X[1000:], classes[1000:])) < 0.03


def test_oob_score_of_several_class_outputs_and_a_callable():
    X, y = coin_sets(400, np.random.default_rng(3), flip=0.1)
    Y = np.column_stack([y, ~y])
    forest = BoxExtraTreesClassifier(15, oob_score=True, random_state=0, **SMALL).fit(X, Y)
    assert [p.shape for p in forest.oob_decision_function_] == [(400, 2), (400, 2)]
    both = [forest.classes_[k][p.argmax(axis=1)] == Y[:, k]
            for k, p in enumerate(forest.oob_decision_function_)]
    assert forest.oob_score_ == pytest.approx(np.mean(both[0] & both[1]))

    X, y = make_box_regression(300, random_state=0)
    forest = BoxExtraTreesRegressor(15, oob_score=mean_absolute_error, random_state=0,
                                    **SMALL).fit(X, y)
    assert forest.oob_score_ == mean_absolute_error(y, forest.oob_prediction_)


@pytest.mark.parametrize("Forest", FORESTS)
def test_oob_score_and_max_samples_need_bootstrap(Forest):
    X, y = box_task(50, Forest)
    with pytest.raises(ValueError, match="Out of bag estimation only available if bootstrap=True"):
        Forest(2, bootstrap=False, oob_score=True).fit(X, y)
    with pytest.raises(ValueError, match="max_samples=10 .* bootstrap=True"):
        Forest(2, bootstrap=False, max_samples=10).fit(X, y)
    for bad in (0, 1.5, 0.0, "all"):
        with pytest.raises(ValueError, match="max_samples"):
            Forest(2, max_samples=bad).fit(X, y)


@pytest.mark.filterwarnings("ignore:Some inputs do not have OOB scores")
@pytest.mark.parametrize("max_samples, size", [(50, 50), (0.25, 50), (1.0, 200), (300, 300)])
def test_max_samples_sets_the_size_of_each_bootstrap_sample(max_samples, size):
    X, y = make_box_regression(200, random_state=0)
    forest = BoxExtraTreesRegressor(3, max_samples=max_samples, oob_score=True, random_state=0,
                                    **SMALL).fit(X, y)
    for tree in forest:        # unit weights: the root weighs the draws
        assert tree.tree_.weighted_n_node_samples[0] == size
        draws = np.random.default_rng([tree.random_state, 1]).integers(0, 200, size)
        assert tree.tree_.n_node_samples[0] == len(np.unique(draws))
    if size == 50:             # most samples are out of some tree's bag
        assert np.isfinite(forest.oob_prediction_).mean() > 0.9


@pytest.mark.filterwarnings("ignore:Some inputs do not have OOB scores")
def test_pickles_keep_the_new_parameters_and_estimates_and_read_older_ones():
    X, y = coin_sets(200, np.random.default_rng(0), flip=0.1)
    forest = BoxExtraTreesClassifier(6, oob_score=True, class_weight="balanced", max_samples=0.8,
                                     random_state=0, **SMALL).fit(X, y)
    again = pickle.loads(pickle.dumps(forest))
    assert again.get_params() == forest.get_params()
    np.testing.assert_array_equal(again.oob_decision_function_, forest.oob_decision_function_)
    np.testing.assert_array_equal(again.predict_proba(X), forest.predict_proba(X))
    # a pickle from before the parameters existed: their defaults
    state = forest.__getstate__()
    for name in ("oob_score", "max_samples", "warm_start", "class_weight"):
        del state[name]
    older = BoxExtraTreesClassifier.__new__(BoxExtraTreesClassifier)
    older.__setstate__(state)
    np.testing.assert_array_equal(older.predict_proba(X), forest.predict_proba(X))
    assert clone(older).get_params() == {**forest.get_params(), "oob_score": False,
                                         "max_samples": None, "class_weight": None}


# sparse targets


@pytest.mark.parametrize("Estimator", [*FORESTS, BoxExtraTreeRegressor])
def test_sparse_targets_are_refused_with_a_type_error(Estimator):
    X, y = make_box_regression(30, random_state=0)
    y = (y > 0).astype(float)
    for inputs in (X, np.random.default_rng(0).normal(size=(30, 3))):
        for sparse_y in (csr_matrix(y[:, None]), csr_matrix(np.column_stack([y, y]))):
            with pytest.raises(TypeError, match="sparse targets are not supported"):
                Estimator().fit(inputs, sparse_y)


# inspection


def test_permutation_importance_and_partial_dependence_work_on_feature_matrices():
    rng = np.random.default_rng(0)
    X = rng.uniform(-1, 1, (400, 4))
    y = np.sin(3 * X[:, 2]) + 0.1 * rng.normal(size=400)
    forest = BoxExtraTreesRegressor(10, random_state=0, **SMALL).fit(X[:300], y[:300])
    result = permutation_importance(forest, X[300:], y[300:], n_repeats=3, random_state=0)
    assert result.importances_mean.argmax() == 2 and result.importances_mean[2] > 0.5
    curve = partial_dependence(forest, X, [2], grid_resolution=9)
    assert np.corrcoef(curve["average"][0], np.sin(3 * curve["grid_values"][0]))[0, 1] > 0.9


def test_sklearn_inspection_on_object_sets_points_to_type_importance():
    X, y = make_box_regression(100, random_state=0)
    forest = BoxExtraTreesRegressor(3, random_state=0, **SMALL).fit(X, y)
    with pytest.raises(TypeError, match="boxtrees.type_importance"):
        permutation_importance(forest, X, y)
    with pytest.raises(TypeError, match="permutation_importance"):
        type_importance(forest, np.zeros((3, 2)), np.zeros(3))


@pytest.fixture(scope="module")
def box_forest():
    """A forest on `make_box_regression` (type 1 drives the target, then type 0, near
    (0, 1); types 2 and 3 are distractors) and held-out sets."""
    X, y = make_box_regression(1000, random_state=0)
    forest = BoxExtraTreesRegressor(10, random_state=0, n_jobs=2).fit(X[:600], y[:600])
    return forest, X[600:], y[600:]


@pytest.mark.parametrize("method", ["permute", "drop"])
def test_type_importance_ranks_the_types_that_drive_the_target_first(box_forest, method):
    forest, X, y = box_forest
    result = type_importance(forest, X, y, method=method, n_repeats=3, random_state=0)
    assert result.types.tolist() == [0, 1, 2, 3]
    assert result.importances.shape == (4, 3 if method == "permute" else 1)
    assert result.importances_mean.argsort()[::-1][:2].tolist() == [1, 0]
    assert result.importances_mean[1] > 0.5 and np.abs(result.importances_mean[2:]).max() < 0.02
    assert result.baseline_score == pytest.approx(forest.score(X, y))
    again = type_importance(forest, X, y, method=method, n_repeats=3, random_state=0)
    np.testing.assert_array_equal(again.importances, result.importances)


def test_type_importance_permutes_only_the_objects_of_the_type():
    """A type the target ignores loses nothing; a classifier, a scorer and a subset of types."""
    X, y = coin_sets(600, np.random.default_rng(0))
    forest = BoxExtraTreesClassifier(10, random_state=0, **SMALL).fit(X[:400], y[:400])
    result = type_importance(forest, ObjectSets.from_sequence(X[400:]), y[400:], types=[1, 0],
                             scoring="balanced_accuracy", random_state=0)
    assert result.types.tolist() == [1, 0]
    assert result.importances_mean[1] > 0.3 and abs(result.importances_mean[0]) < 0.02
    with pytest.raises(ValueError, match=r"types \[5\] have no object in X"):
        type_importance(forest, X, y, types=[5])
    for bad in ([], [0.5], ["coin"]):
        with pytest.raises(ValueError, match="types must be one or more type ids"):
            type_importance(forest, X, y, types=bad)


def test_region_importance_maps_where_each_type_matters(box_forest):
    forest, X, y = box_forest
    maps = region_importance(forest, X, y, n_bins=5, extent=10.0)
    assert maps.importances_mean.shape == (4, 5, 5) and maps.importances.shape == (4, 5, 5, 1)
    np.testing.assert_array_equal(maps.x_edges, [-10, -6, -2, 2, 6, 10])
    sets = ObjectSets.from_sequence(X) if not isinstance(X, ObjectSets) else X
    per_type = np.bincount(sets.data[:, 2].astype(int))
    np.testing.assert_array_equal(maps.counts.sum(axis=(1, 2)), per_type)
    # the box around (0, 1) is in the middle cell: its objects of types 1 and 0 matter
    for k in (1, 0):
        assert np.unravel_index(maps.importances_mean[k].argmax(), (5, 5)) == (2, 2)
    assert maps.importances_mean[1, 2, 2] > 0.3
    assert np.abs(maps.importances_mean[2:]).max() < 0.02
    middle = np.zeros((5, 5), dtype=bool)
    middle[2, 2:4] = True            # the box reaches y = 2.5, into the cell above
    assert np.abs(maps.importances_mean[1][~middle]).max() < 0.02
    moved = region_importance(forest, X, y, n_bins=5, extent=10.0, types=[1], method="move",
                              n_repeats=2, random_state=0)
    assert moved.importances.shape == (1, 5, 5, 2)
    assert np.unravel_index(moved.importances_mean[0].argmax(), (5, 5)) == (2, 2)


def test_region_importance_on_objects_of_one_and_of_three_attributes():
    rng = np.random.default_rng(0)
    line = [np.column_stack([rng.uniform(0, 4, k), np.zeros(k)]) for k in rng.integers(0, 6, 400)]
    y = np.array([float(((s[:, 0] > 1) & (s[:, 0] < 2)).sum()) for s in line])
    forest = BoxExtraTreesRegressor(5, random_state=0, **SMALL).fit(line, y)
    maps = region_importance(forest, line, y, extent=(0, 4))
    assert maps.importances_mean.shape == (1, 4, 1) and maps.importances_mean[0, :, 0].argmax() == 1
    with pytest.raises(ValueError, match="extent needs each low below its high"):
        region_importance(forest, line, y, extent=(4, 0))
    space = [np.column_stack([s[:, :1], rng.uniform(0, 4, (len(s), 2)), s[:, 1:]]) for s in line]
    forest = BoxExtraTreesRegressor(5, random_state=0, **SMALL).fit(space, y)
    maps = region_importance(forest, space, y, n_bins=2)
    assert maps.importances_mean.shape == (1, 2, 2)
    assert (maps.importances_mean[0, 0] > 0.1).all() and (maps.importances_mean[0, 1] < 0.1).all()


# scikit-learn's checks with the new parameters


@parametrize_with_checks(
    [BoxExtraTreesRegressor(5, oob_score=True, max_samples=0.9, random_state=0),
     BoxExtraTreesClassifier(5, oob_score=True, max_samples=0.8, class_weight="balanced_subsample",
                             random_state=0)],
    expected_failed_checks=lambda estimator: {
        "check_sample_weight_equivalence_on_dense_data":
        "a bootstrap sample of repeated rows differs from one of weighted rows"})
def test_sklearn_compatible_with_the_new_parameters(estimator, check):
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", "Some inputs do not have OOB scores")
        check(estimator)
