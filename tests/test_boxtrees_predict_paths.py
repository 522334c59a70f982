"""The single-set fast path of prediction (`ObjectInputMixin._one_set`) and the padded walk of
the portable kernel give what the general paths give, and reject what they reject, alike."""
import numpy as np
import pytest

from boxtrees import BoxExtraTreesClassifier, BoxExtraTreesRegressor, ObjectSets, make_box_regression
from boxtrees import _predictor


@pytest.fixture(scope="module")
def data():
    X, y = make_box_regression(600, random_state=0)
    test, _ = make_box_regression(60, random_state=1)
    return X, y, test


@pytest.fixture(scope="module")
def forest(data):
    X, y, _ = data
    return BoxExtraTreesRegressor(n_estimators=6, n_tests=50, min_samples_split=5, n_jobs=1,
                                  random_state=0).fit(X, y)


def _general(forest, X):
    """Predictions through the general path: a batch of sets, one of them X's."""
    pad = [np.zeros((1, 3), dtype=np.float32)]
    return forest.predict(list(X) + pad)[:-1]


@pytest.mark.parametrize("dtype", [np.float32, np.float64, np.int64])
def test_one_set_fast_path_equals_the_general_path(forest, data, dtype):
    _, _, test = data
    for s in list(test)[:20]:
        s = np.asarray(s).astype(dtype)
        expected = _general(forest, [s])
        for X in ([s], (s,), [np.asfortranarray(s)], ObjectSets.from_sequence([s])):
            np.testing.assert_array_equal(forest.predict(X), expected)


def test_batches_equal_single_calls(forest, data):
    _, _, test = data
    sets = [np.asarray(s) for s in test]
    one_by_one = np.concatenate([forest.predict([s]) for s in sets])
    for batch in (sets, ObjectSets.from_sequence(sets), tuple(sets)):
        np.testing.assert_array_equal(forest.predict(batch), one_by_one)
    leaves = np.vstack([forest.apply([s]) for s in sets])
    np.testing.assert_array_equal(forest.apply(sets), leaves)


def test_empty_sets_and_unknown_types(forest, data):
    _, _, test = data
    empty = [np.empty((0, 3)), np.empty((0, 3), dtype=np.float32), np.empty(0), np.empty((0, 5))]
    values = [forest.predict([e])[0] for e in empty]
    assert len(set(values)) == 1
    np.testing.assert_array_equal(forest.predict(ObjectSets.from_sequence([empty[0]])), values[:1])
    s = np.asarray(test[0])
    unknown = s.copy()
    unknown[:, -1] += 100                       # types no tree tests: as if there were none
    np.testing.assert_array_equal(forest.predict([unknown]), values[:1])
    mixed = np.vstack([s, unknown])             # the unknown objects change nothing
    np.testing.assert_array_equal(forest.predict([mixed]), forest.predict([s]))
    np.testing.assert_array_equal(forest.predict([mixed, empty[0], s]),
                                  [forest.predict([s])[0], values[0], forest.predict([s])[0]])


@pytest.mark.parametrize("X, error, match", [
    ([np.array([[np.nan, 0.0, 1]])], ValueError, "NaN or infinite"),
    ([np.array([[np.nan, 0.0, 1]], dtype=np.float32)], ValueError, "NaN or infinite"),
    ([np.array([[0.0, np.inf, 1]])], ValueError, "NaN or infinite"),
    ([np.array([[0.0, 0.0, -2]])], ValueError, "negative type"),
    ([np.array([[0.0, 0.0, 0.5]])], ValueError, "non-integer type"),
    ([np.array([[1e39, 0.0, 0]])], ValueError, "too large for float32"),
    ([np.array([[0.0, 0.0, 0.0, 1]])], ValueError, r"objects of 4 columns.*fitted on objects of 3"),
    ([np.zeros((2, 1))], ValueError, r"shape \(n_objects, d \+ 1\)"),
    ([np.array([["a", "b", "c"]])], TypeError, "must hold real numbers"),
    (np.zeros((2, 3)), ValueError, "fitted on object sets"),
])
def test_bad_single_sets_are_rejected_as_in_a_batch(forest, X, error, match):
    with pytest.raises(error, match=match) as single:
        forest.predict(X)
    if isinstance(X, list):         # the same error as from the general path
        with pytest.raises(error) as batch:
            forest.predict(X + [np.zeros((0, 3))])
        assert str(single.value) == str(batch.value)


def test_named_types_and_a_feature_matrix_take_the_general_path(data):
    X, y, test = data
    named = ObjectSets(X.data, X.offsets, type_names=["a", "b", "c", "d"])
    forest = BoxExtraTreesRegressor(n_estimators=3, n_tests=20, min_samples_split=5, n_jobs=1,
                                    random_state=0).fit(named, y)
    with pytest.warns(UserWarning, match="does not have type names"):
        forest.predict([np.asarray(test[0])])
    matrix = BoxExtraTreesClassifier(n_estimators=3, n_tests=5, n_jobs=1, random_state=0)
    matrix.fit(np.random.default_rng(0).normal(size=(50, 3)), np.arange(50) % 2)
    with pytest.raises(ValueError, match="fitted on a feature matrix"):
        matrix.predict([np.zeros((2, 3))])


def test_padded_walk_equals_the_compact_one():
    """A batch whose padding by type would take much room (many objects of one of many types)
    is walked in the compact layout; each set alone, padded: the same leaves."""
    rng = np.random.default_rng(0)
    sets = [np.column_stack([rng.uniform(0, 10, (10, 2)), rng.integers(0, 8, 10)])
            for _ in range(200)]
    y = [((s[:, 2] == 0) & (s[:, 0] < 5)).sum() for s in sets]
    forest = BoxExtraTreesRegressor(n_estimators=4, n_tests=30, min_samples_split=5, n_jobs=1,
                                    random_state=0).fit(sets, y)
    packed = forest._packed
    crowded = np.column_stack([rng.uniform(0, 10, (400, 2)), np.zeros(400)])
    batch = ObjectSets.from_sequence(sets[:10] + [crowded])
    both = np.empty((len(batch), packed.n_trees), dtype=np.intp)
    assert _predictor.apply_leaves(packed, batch.data, batch.offsets, both) == (0, -1)
    for i in range(len(batch)):
        one = batch[i:i + 1]
        alone = np.empty((1, packed.n_trees), dtype=np.intp)
        _predictor.apply_leaves(packed, one.data, one.offsets, alone)
        np.testing.assert_array_equal(alone[0], both[i])
    np.testing.assert_array_equal(forest.predict(batch),
                                  [forest.predict(batch[i:i + 1])[0] for i in range(len(batch))])
