"""``make_box_regression``: a frozen random stream, a documented target, and bad parameters
rejected with an error naming them."""
import hashlib

import numpy as np
import pytest

from boxtrees import ObjectSets, make_box_regression


def _digest(X, y):
    h = hashlib.sha256()
    for array in (X.data, X.offsets.astype(np.int64), y):
        h.update(np.ascontiguousarray(array).tobytes())
    return h.hexdigest()


@pytest.mark.parametrize("seed, digest", [
    (0, "fbf4b19c88b0735bac9b3f8ea31e1368c66af633ce9b196c1fc8616d5b6a1eae"),
    (1, "e08f8e1a71cc35933d29a6f2e57f00a9af9d6d6630daa7a52d9ece0febeae18e"),
])
def test_the_default_output_is_frozen(seed, digest):
    """Cached results and other code depend on these exact data (the random stream of
    NumPy's legacy RandomState, which does not change across versions)."""
    X, y = make_box_regression(random_state=seed)
    assert _digest(X, y) == digest


def test_a_random_state_instance_gives_the_stream_of_its_seed():
    X, y = make_box_regression(50, random_state=np.random.RandomState(3))
    X_int, y_int = make_box_regression(50, random_state=3)
    np.testing.assert_array_equal(X.data, X_int.data)
    np.testing.assert_array_equal(y, y_int)


def test_output_follows_the_parameters():
    X, y = make_box_regression(200, mean_objects=5, n_types=3, extent=2.0, random_state=0)
    assert isinstance(X, ObjectSets) and len(X) == 200 and y.shape == (200,)
    assert X.data.dtype == np.float32 and (np.abs(X.data[:, :2]) <= 2.0).all()
    assert set(np.unique(X.data[:, 2]).tolist()) <= {0.0, 1.0, 2.0}


def test_without_noise_the_target_is_the_weighted_count_in_the_box():
    centre, half_width, type_values = np.array([0.5, -1.0]), 2.0, [1.0, 10.0]
    X, y = make_box_regression(100, n_types=3, centre=centre, half_width=half_width,
                               type_values=type_values, noise=0.0, random_state=0)
    values = np.array(type_values + [0.0])
    expected = [sum(values[int(t)] for x, yy, t in s
                    if abs(x - centre[0]) < half_width and abs(yy - centre[1]) < half_width)
                for s in X]
    np.testing.assert_allclose(y, expected, atol=1e-9)
    _, y_empty = make_box_regression(30, type_values=[], noise=0.0, random_state=0)
    assert (y_empty == 0).all()


def test_no_objects_gives_empty_sets_and_pure_noise():
    X, y = make_box_regression(10, mean_objects=0, noise=0.0, random_state=0)
    assert X.n_objects == 0 and len(X) == 10 and (y == 0).all()


@pytest.mark.parametrize("params, match", [
    ({"n_samples": 0}, "'n_samples' parameter"),
    ({"n_samples": 2.5}, "'n_samples' parameter"),
    ({"mean_objects": -1.0}, "'mean_objects' parameter"),
    ({"mean_objects": np.nan}, "'mean_objects' parameter"),
    ({"mean_objects": np.inf}, "'mean_objects' parameter"),
    ({"mean_objects": 2**2000}, "'mean_objects' parameter .* must be finite"),
    ({"n_types": 0}, "'n_types' parameter"),
    ({"n_types": 2.0}, "'n_types' parameter"),
    ({"n_types": 2**24 + 1}, "'n_types' parameter"),
    ({"n_types": 1}, "type_values has 2 values but n_types=1"),
    ({"n_types": 2, "type_values": [1.0, 2.0, 3.0]}, "type_values has 3 values but n_types=2"),
    ({"extent": 0.0}, "'extent' parameter"),
    ({"extent": -1.0}, "'extent' parameter"),
    ({"extent": np.inf}, "'extent' parameter"),
    ({"extent": 1e39}, "'extent' parameter"),
    ({"centre": 0.0}, "'centre' parameter"),
    ({"centre": (0.0,)}, r"'centre' parameter .* must have shape \(2,\)"),
    ({"centre": [[0.0, 1.0]]}, r"'centre' parameter .* must have shape \(2,\)"),
    ({"centre": (0.0, np.nan)}, "'centre' parameter .* finite"),
    ({"centre": ("a", "b")}, "'centre' parameter .* real numbers"),
    ({"half_width": 0.0}, "'half_width' parameter"),
    ({"half_width": -1.0}, "'half_width' parameter"),
    ({"half_width": np.inf}, "'half_width' parameter"),
    ({"type_values": 5.0}, "'type_values' parameter"),
    ({"type_values": [[1.0, 2.0]]}, "'type_values' parameter .* 1D"),
    ({"type_values": [np.inf]}, "'type_values' parameter .* finite"),
    ({"type_values": ["a"]}, "'type_values' parameter .* real numbers"),
    ({"noise": -1.0}, "'noise' parameter"),
    ({"noise": np.nan}, "'noise' parameter"),
    ({"random_state": "seed"}, "'random_state' parameter"),
])
def test_bad_parameters_are_rejected_with_an_error_naming_them(params, match):
    params = {"n_samples": 10, **params}
    with pytest.raises(ValueError, match=match):
        make_box_regression(**params)


def test_a_bad_parameter_draws_nothing_from_the_random_state():
    rng = np.random.RandomState(0)
    with pytest.raises(ValueError):
        make_box_regression(10, n_types=1, random_state=rng)
    np.testing.assert_array_equal(make_box_regression(10, random_state=rng)[1],
                                  make_box_regression(10, random_state=0)[1])
