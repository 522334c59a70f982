"""Objects with any number of attributes: rows ``[f_1, ..., f_d, type]``."""
import pickle

import numpy as np
import pytest
from sklearn.metrics import r2_score

from boxtrees import (BoxExtraTreeClassifier, BoxExtraTreeRegressor, BoxExtraTreesClassifier,
                      BoxExtraTreesRegressor, GridCounts, ObjectSets)
from conftest import reference_leaf

ESTIMATORS = (BoxExtraTreesRegressor, BoxExtraTreesClassifier, BoxExtraTreeRegressor,
              BoxExtraTreeClassifier)


def object_sets(rng, n, d, max_objects=12, n_types=3, extent=5.0):
    """Ragged sets of objects with ``d`` attributes, many of them empty."""
    return [np.column_stack([rng.uniform(-extent, extent, (k, d)), rng.integers(0, n_types, k)])
            for k in rng.integers(0, max_objects + 1, n)]


def _small(estimator_class, **params):
    params = {"n_tests": 30, "min_samples_split": 5, "random_state": 0, **params}
    if estimator_class in (BoxExtraTreesRegressor, BoxExtraTreesClassifier):
        params["n_estimators"] = 4
    return estimator_class(**params)


def _trees(estimator):
    return [e.tree_ for e in estimator] if hasattr(estimator, "estimators_") else [estimator.tree_]


@pytest.mark.parametrize("d", [1, 3, 6])
@pytest.mark.parametrize("estimator_class", ESTIMATORS)
@pytest.mark.parametrize("test_type", ["fixed", "bounded", "random", "classic"])
def test_objects_of_d_attributes_fit_predict_and_pickle(d, estimator_class, test_type):
    rng = np.random.default_rng(d)
    X, X_test = object_sets(rng, 300, d), object_sets(rng, 60, d)
    y = np.array([float((s[:, d - 1] > 0).sum()) for s in X])
    if estimator_class in (BoxExtraTreesClassifier, BoxExtraTreeClassifier):
        y = y > 2
    model = _small(estimator_class, test_type=test_type, test_width=2.0).fit(X, y)
    assert model.n_attributes_ == d
    expected_groups = ((0,),) if d == 1 else ((0, 1),) + tuple((0, 1, c) for c in range(2, d))
    assert model.column_groups_ == expected_groups
    assert model.bounds_.shape == (model.n_types_, 2 * d)
    for tree in _trees(model):
        assert tree.box.shape == (tree.node_count, 2 * d) and tree.n_attributes == d
        inner = tree.children_left != -1
        # every test bounds the columns of one group, and only those
        bounded = ~(np.isneginf(tree.box[inner, 0::2]) & np.isposinf(tree.box[inner, 1::2]))
        spans = [set(np.flatnonzero(row)) for row in bounded]
        assert all(any(span <= set(group) for group in expected_groups) for span in spans)
    # the Cython traversal agrees with a plain walk over the exported arrays
    leaves = model.apply(X_test)
    leaves = leaves[:, None] if leaves.ndim == 1 else leaves
    for k, tree in enumerate(_trees(model)):
        assert leaves[:, k].tolist() == [reference_leaf(tree, s) for s in X_test]
    again = pickle.loads(pickle.dumps(model))
    np.testing.assert_array_equal(again.predict(X_test), model.predict(X_test))
    assert again.n_attributes_ == d


def test_a_test_can_read_an_attribute_beyond_the_position():
    # the target counts the objects of type 0 in a square region that move right (attribute 2):
    # a box over the position and the velocity, column group (0, 1, 2), reads it; positions
    # alone cannot tell it
    rng = np.random.default_rng(0)

    def sets(n):
        return [np.column_stack([rng.uniform(-3, 3, (k, 2)), rng.uniform(-1, 1, k),
                                 rng.integers(0, 2, k)]) for k in rng.integers(0, 15, n)]

    def target(s):
        return float(((np.abs(s[:, :2]).max(1) < 1.5) & (s[:, 2] > 0) & (s[:, 3] == 0)).sum())

    X, X_test = sets(3000), sets(600)
    y, y_test = [target(s) for s in X], [target(s) for s in X_test]
    params = dict(n_estimators=20, min_samples_split=5, test_type="random", random_state=0)
    moving = BoxExtraTreesRegressor(**params, column_groups=[(0, 1, 2)]).fit(X, y)
    positions = BoxExtraTreesRegressor(**params).fit([s[:, [0, 1, 3]] for s in X], y)
    with_motion = r2_score(y_test, moving.predict(X_test))
    without = r2_score(y_test, positions.predict([s[:, [0, 1, 3]] for s in X_test]))
    assert with_motion > 0.85 and with_motion > without + 0.3, (with_motion, without)


def test_column_groups_choose_the_columns_a_box_spans():
    rng = np.random.default_rng(1)
    X = object_sets(rng, 200, 4)
    y = rng.normal(size=200)
    forest = BoxExtraTreesRegressor(3, n_tests=20, min_samples_split=5, random_state=0,
                                    column_groups=[(0, 1), (2, 3)]).fit(X, y)
    assert forest.column_groups_ == ((0, 1), (2, 3))
    for tree in _trees(forest):
        inner = tree.children_left != -1
        bounded = ~(np.isneginf(tree.box[inner, 0::2]) & np.isposinf(tree.box[inner, 1::2]))
        assert set(map(tuple, bounded.astype(int))) <= {(1, 1, 0, 0), (0, 0, 1, 1)}
    # a single int is a group of one column; the groups may overlap
    one = BoxExtraTreesRegressor(2, n_tests=20, random_state=0,
                                 column_groups=[3, (3, 0)]).fit(X, y)
    assert one.column_groups_ == ((3,), (3, 0))
    # d = 2 with its default group spelled out grows the same trees
    X2 = object_sets(rng, 200, 2)
    a = BoxExtraTreesRegressor(3, n_tests=20, random_state=0).fit(X2, y)
    b = BoxExtraTreesRegressor(3, n_tests=20, random_state=0, column_groups=[(0, 1)]).fit(X2, y)
    np.testing.assert_array_equal(a.predict(X2), b.predict(X2))
    for ta, tb in zip(_trees(a), _trees(b)):
        np.testing.assert_array_equal(ta.box, tb.box)


@pytest.mark.parametrize("groups", [[(0, 4)], [(0, 1, 2, 3)], [()], [], [(1, 1)], [(-1,)], ["a"],
                                    [(0.5,)]])
def test_bad_column_groups_are_rejected(groups):
    X = object_sets(np.random.default_rng(0), 50, 3)
    with pytest.raises(ValueError, match="column_groups must"):
        BoxExtraTreesRegressor(2, column_groups=groups).fit(X, np.zeros(50))


def test_a_box_spans_at_most_eight_columns():
    X = object_sets(np.random.default_rng(0), 50, 10)
    BoxExtraTreesRegressor(2, column_groups=[range(8)]).fit(X, np.zeros(50))
    with pytest.raises(ValueError, match="groups of 1 to 8 distinct attribute indices"):
        BoxExtraTreesRegressor(2, column_groups=[range(9)]).fit(X, np.zeros(50))


@pytest.mark.parametrize("groups", [[(0, 1, 2)], [(2, 0, 4, 1), (3,)], [(4, 3, 2, 1, 0)],
                                    [(1, 0), (2, 3, 4)]])
@pytest.mark.parametrize("test_type", ["fixed", "bounded", "random", "classic"])
@pytest.mark.parametrize("refine_tests", [False, True])
def test_boxes_over_groups_of_more_columns_walk_as_in_numpy(groups, test_type, refine_tests):
    rng = np.random.default_rng(5)
    # test sets of up to 16 objects and of more (walked differently with AVX-512)
    X = object_sets(rng, 300, 5, max_objects=20)
    X_test = object_sets(rng, 80, 5, max_objects=20)
    y = np.array([float(((s[:, :3] > 0).all(axis=1)).sum()) for s in X])
    forest = BoxExtraTreesRegressor(3, n_tests=30, min_samples_split=4, test_type=test_type,
                                    test_width=0.2, column_groups=groups, bootstrap=False,
                                    refine_tests=refine_tests, random_state=0).fit(X, y)
    paths, starts = forest.decision_path(X)
    reached = np.asarray(paths.sum(axis=0)).ravel()
    for k, tree in enumerate(_trees(forest)):
        inner = tree.children_left != -1
        bounded = ~(np.isneginf(tree.box[inner, 0::2]) & np.isposinf(tree.box[inner, 1::2]))
        assert bounded.sum(axis=1).max() <= max(len(g) for g in groups)
        assert forest.apply(X_test)[:, k].tolist() == [reference_leaf(tree, s) for s in X_test]
        # the builder split the training samples as the exported tests send them
        np.testing.assert_array_equal(reached[starts[k]:starts[k + 1]], tree.n_node_samples)


def test_predicting_on_objects_of_other_attributes_is_an_error():
    rng = np.random.default_rng(2)
    forest = BoxExtraTreesRegressor(2, n_tests=10, random_state=0).fit(object_sets(rng, 50, 3),
                                                                       rng.normal(size=50))
    with pytest.raises(ValueError, match=r"objects of 3 columns, but BoxExtraTreesRegressor "
                                         r"was fitted on objects of 4 columns .*d = 3"):
        forest.predict(object_sets(rng, 5, 2, max_objects=3) + [np.zeros((1, 3))])
    # sets with no object at all have nothing to read, whatever their shape
    assert forest.predict([np.empty((0, 3)), np.empty(0)]).shape == (2,)


def test_view_bounds_take_a_low_and_a_high_per_attribute():
    rng = np.random.default_rng(3)
    X, y = object_sets(rng, 100, 3), rng.normal(size=100)
    forest = BoxExtraTreesRegressor(2, n_tests=10, view_bounds=(-6, 6, -5, 5, -4, 4),
                                    random_state=0).fit(X, y)
    np.testing.assert_array_equal(forest.bounds_[0], [-6, 6, -5, 5, -4, 4])
    cube = BoxExtraTreesRegressor(2, n_tests=10, view_bounds=7.0, random_state=0).fit(X, y)
    np.testing.assert_array_equal(cube.bounds_[0], [-7, 7] * 3)
    with pytest.raises(ValueError, match="view_bounds must be \\(low, high\\) of each of the 3"):
        BoxExtraTreesRegressor(2, view_bounds=(-1, 1, -1, 1)).fit(X, y)


def test_view_bounds_per_type_draw_each_types_tests_in_its_own_region():
    rng = np.random.default_rng(4)
    X, y = object_sets(rng, 300, 2, max_objects=20, extent=9.0), rng.normal(size=300)
    forest = BoxExtraTreesRegressor(3, n_tests=50, min_samples_split=5, test_type="fixed",
                                    test_width=1.0, relative_width=False, refine_tests=False,
                                    view_bounds={0: 9.0, 1: (-2, 2, -1, 3), 7: 1.0},
                                    random_state=0).fit(X, y)
    # type 2 is not named: the training objects' bounding box; type 7 is absent: ignored
    np.testing.assert_array_equal(forest.bounds_[:2], [[-9, 9, -9, 9], [-2, 2, -1, 3]])
    assert forest.bounds_[2, 0] < -8.9 and forest.bounds_[2, 1] > 8.9
    trees = [tree.tree_ for tree in forest.estimators_]
    centres = {t: np.concatenate([tree.box[tree.object_type == t].reshape(-1, 2, 2).mean(axis=2)
                                  for tree in trees]) for t in (0, 1, 2)}
    assert all(len(c) > 10 for c in centres.values())
    inside = (centres[1] >= [-2, -1]) & (centres[1] <= [2, 3])
    assert inside.all()
    assert np.abs(centres[0]).max() > 4 and np.abs(centres[2]).max() > 4
    # one region for every type, as a dict or not, grows the same trees
    whole = {t: 9.0 for t in range(3)}
    a, b = (BoxExtraTreesRegressor(2, n_tests=20, view_bounds=v, random_state=1).fit(X, y)
            for v in (9.0, whole))
    for ta, tb in zip(a.estimators_, b.estimators_):
        np.testing.assert_array_equal(ta.tree_.box, tb.tree_.box)
    np.testing.assert_array_equal(a.predict(X), b.predict(X))
    # it survives cloning and pickling
    twin = pickle.loads(pickle.dumps(forest))
    np.testing.assert_array_equal(twin.predict(X), forest.predict(X))


@pytest.mark.parametrize("view_bounds, error, message", [
    ({"wall": 2.0}, TypeError, "type ids \\(ints\\) as keys; got 'wall'"),
    ({True: 2.0}, TypeError, "type ids \\(ints\\) as keys; got True"),
    ({1: (2, -2, -1, 1)}, ValueError, "view_bounds\\[1\\] needs each low below its high"),
    ({1: (-1, 1)}, ValueError, "view_bounds\\[1\\] must be \\(xmin, xmax, ymin, ymax\\)"),
    ({1: np.nan}, ValueError, "view_bounds\\[1\\] must be"),
])
def test_view_bounds_per_type_are_checked(view_bounds, error, message):
    rng = np.random.default_rng(5)
    X, y = object_sets(rng, 20, 2), rng.normal(size=20)
    with pytest.raises(error, match=message):
        BoxExtraTreesRegressor(2, view_bounds=view_bounds).fit(X, y)
    with pytest.raises(ValueError, match="mapping of type ids applies to object sets"):
        BoxExtraTreesRegressor(2, view_bounds={0: 1.0}).fit(rng.normal(size=(20, 3)), y)


def test_from_padded_keeps_the_masked_rows_in_order():
    padded = np.arange(2 * 3 * 4, dtype=float).reshape(2, 3, 4)
    padded[..., 3] = 1
    mask = np.array([[True, False, True], [False, False, False]])
    sets = ObjectSets.from_padded(padded, mask)
    assert sets.sizes.tolist() == [2, 0] and sets.n_attributes == 3
    np.testing.assert_array_equal(sets[0], padded[0, [0, 2]])
    # a 0/1 mask works too; anything else is refused
    assert ObjectSets.from_padded(padded, mask.astype(int)).sizes.tolist() == [2, 0]
    with pytest.raises(TypeError, match="mask must hold booleans"):
        ObjectSets.from_padded(padded, mask * 2.0)
    with pytest.raises(ValueError, match=r"mask must have shape \(2, 3\)"):
        ObjectSets.from_padded(padded, mask[:, :2])
    with pytest.raises(ValueError, match="padded rows must be an array of shape"):
        ObjectSets.from_padded(padded[0], mask[0])
    # masked-out rows may hold anything, even NaN
    padded[0, 1] = np.nan
    assert ObjectSets.from_padded(padded, mask).n_objects == 2


def test_object_sets_of_one_batch_share_their_columns():
    with pytest.raises(ValueError, match=r"set 0 has shape \(1, 4\) but set 2 has shape \(1, 3\)"):
        ObjectSets.from_sequence([np.zeros((1, 4)), np.empty((0, 3)), np.zeros((1, 3))])
    # empty sets of any shape join any batch; a batch of empty sets keeps their width
    assert ObjectSets.from_sequence([np.zeros((2, 5)), np.empty((0, 3))]).n_attributes == 4
    assert ObjectSets.from_sequence([np.empty((0, 5)), np.empty((0, 5))]).n_attributes == 4
    a = ObjectSets.from_sequence([np.zeros((1, 4))])
    b = ObjectSets.from_sequence([np.zeros((2, 3))])
    with pytest.raises(ValueError, match="same columns; batch 0 has 4 but batch 1 has 3"):
        ObjectSets.concatenate([a, b])
    assert ObjectSets.concatenate([a, ObjectSets.from_sequence([np.empty((0, 3))])]).n_attributes == 3


def test_grid_counts_lie_over_two_chosen_attributes():
    sets = [np.array([[-5.0, 0.0, 5.0, 0], [5.0, 0.0, -5.0, 1]]), np.empty((0, 4))]
    grid = GridCounts(n_bins=2, view_bounds=10, columns=(0, 2)).fit(sets)
    assert grid.columns_ == (0, 2)
    # type 0 at x cell 0, y cell 1; type 1 at x cell 1, y cell 0
    np.testing.assert_array_equal(grid.transform(sets)[0], [0, 0, 1, 0, 0, 1, 0, 0])
    assert GridCounts(n_bins=3).fit([np.array([[1.0, 0], [2.0, 1]])]).columns_ == (0,)
    with pytest.raises(ValueError, match="columns must be one or two distinct attribute"):
        GridCounts(columns=(0, 3)).fit(sets)
