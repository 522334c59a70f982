"""``ObjectSets`` builders: what they build, and the clear errors they give on bad input."""
import numpy as np
import pytest

from boxtrees import ObjectSets

A = ObjectSets.from_sequence([np.array([[0.0, 1.0, 0], [2.0, 3.0, 1]]), np.empty((0, 3))])
B = ObjectSets.from_sequence([np.array([[4.0, 5.0, 2]])])


def _copy(sets):
    return ObjectSets(sets.data.copy(), sets.offsets.copy())


# --- from_features ------------------------------------------------------------------------


@pytest.mark.parametrize("dtype", [np.float32, np.float64, np.int64, bool])
def test_from_features_makes_one_object_of_each_type_per_sample(dtype):
    X = np.array([[1, 0, 1], [0, 1, 1]], dtype=dtype)
    sets = ObjectSets.from_features(X)
    assert len(sets) == 2 and sets.sizes.tolist() == [3, 3]
    assert sets.data.dtype == np.float32
    np.testing.assert_array_equal(sets.data[:, 0], X.ravel().astype(np.float32))
    assert sets.n_attributes == 1     # rows [value, type]
    assert sets.data[:, 1].tolist() == [0, 1, 2, 0, 1, 2]


def test_from_features_accepts_lists_and_empty_matrices():
    assert ObjectSets.from_features([[1.5, 2.5]]).data[:, 0].tolist() == [1.5, 2.5]
    assert len(ObjectSets.from_features(np.zeros((0, 3)))) == 0
    no_features = ObjectSets.from_features(np.zeros((2, 0)))
    assert len(no_features) == 2 and no_features.n_objects == 0


@pytest.mark.parametrize("X, error, match", [
    (np.zeros(3), ValueError, r"2D feature matrix .* got shape \(3,\)"),
    (np.zeros((2, 2, 2)), ValueError, r"2D feature matrix .* got shape \(2, 2, 2\)"),
    (np.array([[np.nan, 1.0]]), ValueError, "NaN or infinite"),
    (np.array([[np.inf, 1.0]], dtype=np.float32), ValueError, "NaN or infinite"),
    (np.array([[1e39, 1.0]]), ValueError, "too large for float32"),
    (np.array([["a", "b"]]), TypeError, "must hold real numbers"),
    (np.array([[1 + 1j]]), TypeError, "must hold real numbers"),
])
def test_from_features_rejects_bad_matrices(X, error, match):
    with pytest.raises(error, match=match):
        ObjectSets.from_features(X)


def test_from_features_rejects_more_features_than_type_ids():
    X = np.lib.stride_tricks.as_strided(np.zeros(1, np.float32), (1, 2**24 + 1), (0, 0))
    with pytest.raises(ValueError, match="at most 16777216"):
        ObjectSets.from_features(X)


# --- concatenate --------------------------------------------------------------------------


def test_concatenate_joins_the_sets_in_order():
    joined = ObjectSets.concatenate([A, B, A[1:]])
    assert joined.sizes.tolist() == [2, 0, 1, 0]
    expected = ObjectSets.from_sequence(list(A) + list(B) + list(A[1:]))
    np.testing.assert_array_equal(joined.data, expected.data)
    np.testing.assert_array_equal(joined.offsets, expected.offsets)
    assert joined.data.dtype == np.float32 and joined.offsets.dtype == np.intp
    # any iterable; none gives an empty batch
    assert ObjectSets.concatenate(iter([B])).sizes.tolist() == [1]
    empty = ObjectSets.concatenate([])
    assert len(empty) == 0 and empty.data.shape == (0, 3)


@pytest.mark.parametrize("batches, match", [
    (A, "got a single batch; wrap it in a list"),
    (5, "iterable of ObjectSets, got int"),
    ([A, np.zeros((2, 3))], r"batch 1 is a ndarray"),
    ([[np.zeros((1, 3))]], r"batch 0 is a list"),
    ([A, None], r"batch 1 is a NoneType"),
])
def test_concatenate_rejects_what_is_not_a_sequence_of_object_sets(batches, match):
    with pytest.raises(TypeError, match=match):
        ObjectSets.concatenate(batches)


def test_concatenate_names_the_batch_that_changed_after_it_was_built():
    bad_rows = _copy(B)
    bad_rows.data[0, 2] = -1
    with pytest.raises(ValueError, match=r"rows of batch 1 .* negative type ids.*object row 0"):
        ObjectSets.concatenate([A, bad_rows])
    bad_rows.data[0] = [np.nan, 0, 0]
    with pytest.raises(ValueError, match=r"rows of batch 1 .* NaN or infinite"):
        ObjectSets.concatenate([A, bad_rows])
    bad_offsets = _copy(A)
    bad_offsets.offsets[1] = 5
    with pytest.raises(ValueError, match=r"batch 2 of ObjectSets.concatenate: offsets must be"):
        ObjectSets.concatenate([A, B, bad_offsets])
    bad_shape = _copy(A)
    bad_shape.data = np.zeros((2, 1), np.float32)
    with pytest.raises(ValueError, match=r"rows of batch 0 .* shape \(n_objects, d \+ 1\)"):
        ObjectSets.concatenate([bad_shape])
