"""Bad input gets a clear error naming the problem; fuzzing the Cython boundary never crashes."""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from boxtrees import BoxExtraTreesRegressor, GridCounts, ObjectSets

GOOD = [np.array([[0.0, 1.0, 0], [2.0, -1.0, 1]]), np.empty((0, 3)), np.array([[1.0, 1.0, 2]])]
Y = np.array([1.0, 2.0, 3.0])


def small_forest(**params):
    return BoxExtraTreesRegressor(n_estimators=2, n_tests=5, min_samples_split=2, random_state=0, **params)


@pytest.mark.parametrize(
    "X, y, error, match",
    [
        ([np.array([[np.nan, 0.0, 0]])], [1.0], ValueError, "NaN or infinite"),
        ([np.array([[0.0, np.inf, 0]])], [1.0], ValueError, "NaN or infinite"),
        ([np.array([[0.0, 0.0, -1]])], [1.0], ValueError, "negative type"),
        ([np.array([[0.0, 0.0, 0.5]])], [1.0], ValueError, "non-integer type"),
        ([np.array([[0.0, 0.0, 2**30]])], [1.0], ValueError, "type ids >="),
        ([np.zeros((2, 1))], [1.0], ValueError, r"shape \(n_objects, d \+ 1\)"),
        ([np.zeros((2, 3)), np.zeros((1, 4))], [1.0, 2.0], ValueError,
         r"same columns.*set 0 has shape \(2, 3\) but set 1 has shape \(1, 4\)"),
        ([np.zeros((2, 3)), np.zeros(3)], [1.0, 2.0], ValueError, r"set 1 has shape \(3,\)"),
        ([np.zeros((2, 3, 1))], [1.0], ValueError, "shape"),
        (np.zeros((4, 2, 3)), np.ones(4), ValueError, r"3D array.*ObjectSets\.from_padded"),
        ([np.array([["a", "b", "c"]])], [1.0], TypeError, "must hold real numbers"),
        ([np.array([[1e39, 0.0, 0]])], [1.0], ValueError, "too large for float32"),
        (GOOD, [1.0, 2.0], ValueError, "3 samples but y has 2"),
        (GOOD, [1.0, np.nan, 2.0], ValueError, "NaN"),
        (GOOD, [1.0, np.inf, 2.0], ValueError, "infinity"),
        (GOOD, None, ValueError, "requires y"),
        (ObjectSets.from_sequence([]), [], ValueError, r"X is empty \(0 samples\)"),
        (np.empty((0, 3)), [], ValueError, "0 sample"),
        (np.array([[np.nan, 1.0]]), [1.0], ValueError, "NaN"),
    ],
)
def test_bad_fit_input_is_rejected_with_a_clear_error(X, y, error, match):
    with pytest.raises(error, match=match):
        small_forest().fit(X, y)


@pytest.mark.parametrize(
    "params, match",
    [
        ({"n_estimators": 0}, "n_estimators"),
        ({"n_tests": 0}, "n_tests"),
        ({"min_samples_split": -1}, "min_samples_split"),
        ({"min_samples_split": 0}, r"min_samples_split.*int in the range \[2, inf\) or a float in the range \(0.0, 1.0\]"),
        ({"min_samples_split": 1}, r"min_samples_split.*int in the range \[2, inf\)"),
        ({"min_samples_split": 1.5}, r"min_samples_split.*float in the range \(0.0, 1.0\]"),
        ({"n_tests": 2**64}, "'n_tests' parameter"),
        ({"max_depth": 2**64}, "'max_depth' parameter"),
        ({"max_retries": 2**64}, "'max_retries' parameter"),
        ({"n_estimators": 2**64}, "'n_estimators' parameter"),
        ({"view_bounds": 1e39}, "fit in float32"),
        ({"view_bounds": (-1e300, 1e300, -1.0, 1.0)}, "fit in float32"),
        ({"view_bounds": (1.0, 1.0 + 1e-12, 0.0, 1.0)}, "empty region in float32"),
        ({"test_type": "circle"}, "test_type"),
        ({"test_width": 0.0}, "test_width"),
        ({"test_width": -2.0}, "test_width"),
        ({"max_retries": -1}, "max_retries"),
        ({"max_depth": -3}, "max_depth"),
        ({"view_bounds": (1.0, 0.0, 0.0, 1.0)}, "xmin < xmax"),
        ({"view_bounds": (0.0, 1.0, 0.0)}, "view_bounds"),
        ({"view_bounds": (0.0, np.nan, 0.0, 1.0)}, "view_bounds"),
        ({"view_bounds": -1.0}, "view_bounds"),
        ({"random_state": "seed"}, "random_state"),
    ],
)
def test_bad_parameters_are_rejected_at_fit(params, match):
    forest = BoxExtraTreesRegressor(**params)  # no validation in __init__, as in scikit-learn
    with pytest.raises(ValueError, match=match):
        forest.fit(GOOD, Y)


@pytest.mark.parametrize("position", [0, 1, 2])
@pytest.mark.parametrize("bad, match", [
    (np.zeros(3), r"set {} has shape \(3,\)"),
    (None, "set {} is None"),
    (np.zeros((2, 4)), r"set {} has shape \(2, 4\)"),
])
def test_a_bad_set_gets_the_same_message_at_every_position(position, bad, match):
    X = [np.zeros((2, 3)), np.zeros((1, 3)), np.empty((0, 3))]
    X[position] = bad
    with pytest.raises(ValueError, match=match.format(position)):
        small_forest().fit(X, Y)
    fitted = small_forest().fit(GOOD, Y)
    with pytest.raises(ValueError, match=match.format(position)):
        fitted.predict(X)


def test_a_pandas_series_of_sets_is_read_as_object_sets():
    pd = pytest.importorskip("pandas")
    series = pd.Series(GOOD, index=[10, 20, 30])
    np.testing.assert_array_equal(small_forest().fit(series, Y).predict(series),
                                  small_forest().fit(GOOD, Y).predict(GOOD))
    with pytest.raises(ValueError, match=r"set 1 has shape \(3,\)"):
        small_forest().fit(pd.Series([GOOD[0], np.zeros(3), GOOD[2]]), Y)


def test_bad_sample_weights_are_rejected():
    with pytest.raises(ValueError, match="[Nn]egative"):
        small_forest().fit(GOOD, Y, sample_weight=[1.0, -1.0, 1.0])
    with pytest.raises(ValueError, match="at least one non-zero"):
        small_forest().fit(GOOD, Y, sample_weight=np.zeros(3))
    with pytest.raises(ValueError, match="shape"):
        small_forest().fit(GOOD, Y, sample_weight=np.ones(4))


def test_predict_rejects_the_other_input_kind_and_bad_sets():
    on_sets = small_forest().fit(GOOD, Y)
    with pytest.raises(ValueError, match="fitted on object sets.*wrapped in a list"):
        on_sets.predict(np.zeros((2, 3)))
    with pytest.raises(ValueError, match="NaN"):
        on_sets.predict([np.array([[np.nan, 0.0, 1]])])
    with pytest.raises(ValueError, match="negative type"):
        on_sets.predict([np.array([[0.0, 0.0, -2]])])
    on_matrix = small_forest().fit(np.arange(12.0).reshape(3, 4), Y)
    with pytest.raises(ValueError, match="fitted on a feature matrix with 4 features"):
        on_matrix.predict(GOOD)
    with pytest.raises(ValueError, match="3 features.*expecting 4"):
        on_matrix.predict(np.zeros((2, 3)))
    with pytest.raises(TypeError, match="Sparse data"):
        on_matrix.predict(__import__("scipy.sparse").sparse.csr_array(np.zeros((2, 4))))


def test_grid_counts_rejects_bad_input():
    with pytest.raises(ValueError, match="n_bins"):
        GridCounts(n_bins=0).fit(GOOD)
    with pytest.raises(ValueError, match="needs view_bounds"):
        GridCounts().fit([np.empty((0, 3))])
    with pytest.raises(ValueError, match="negative type"):
        GridCounts().fit(GOOD).transform([np.array([[0.0, 0.0, -1]])])


def test_object_sets_rejects_inconsistent_offsets():
    with pytest.raises(ValueError, match="offsets"):
        ObjectSets(np.zeros((3, 3)), [0, 2])
    with pytest.raises(ValueError, match="offsets"):
        ObjectSets(np.zeros((3, 3)), [0, 2, 1, 3])
    with pytest.raises(IndexError):
        ObjectSets(np.zeros((3, 3)), [0, 3])[5]


# --- fuzzing the boundary -------------------------------------------------------------------

coordinate = st.one_of(
    st.floats(-10, 10, allow_nan=False),
    st.floats(-3e38, 3e38, allow_nan=False, allow_infinity=False),
    st.sampled_from([0.0, -0.0, 1e-38, 1e30, -1e30]),
)


@st.composite
def object_sets(draw, max_sets=12, max_objects=6, max_type=6):
    n = draw(st.integers(1, max_sets))
    sets = []
    for _ in range(n):
        k = draw(st.integers(0, max_objects))
        xy = draw(arrays(np.float64, (k, 2), elements=coordinate))
        types = draw(arrays(np.int64, (k,), elements=st.integers(0, max_type)))
        sets.append(np.column_stack([xy, types]))
    return sets


@pytest.mark.filterwarnings("ignore:X holds no object")
@settings(max_examples=150, deadline=None)
@given(
    train=object_sets(max_type=3),
    test=object_sets(max_type=9),
    test_type=st.sampled_from(["fixed", "bounded", "random", "classic"]),
    width=st.floats(1e-3, 1e6),
    seed=st.integers(0, 2**32 - 1),
    data=st.data(),
)
def test_fuzz_valid_inputs_never_crash_and_predict_within_target_range(train, test, test_type, width, seed, data):
    y = np.array(data.draw(st.lists(st.floats(-1e6, 1e6), min_size=len(train), max_size=len(train))))
    forest = BoxExtraTreesRegressor(
        n_estimators=2, n_tests=7, min_samples_split=2, max_retries=2, test_type=test_type,
        test_width=width, random_state=seed,
    ).fit(train, y)
    pred = forest.predict(test)
    assert pred.shape == (len(test),) and np.isfinite(pred).all()
    assert (pred >= y.min() - 1e-6 * abs(y.min()) - 1e-9).all()
    assert (pred <= y.max() + 1e-6 * abs(y.max()) + 1e-9).all()
    assert forest.apply(test).shape == (len(test), 2)
    if sum(len(s) for s in train):
        grid = GridCounts(3).fit(train)
        counts = grid.transform(test)
        assert counts.shape == (len(test), 3 * 3 * grid.n_types_) and (counts >= 0).all()
    else:
        with pytest.raises(ValueError, match="needs view_bounds"):
            GridCounts(3).fit(train)


@pytest.mark.filterwarnings("ignore:X holds no object")
@settings(max_examples=150, deadline=None)
@given(
    raw=st.lists(
        arrays(
            np.float64,
            st.tuples(st.integers(0, 4), st.integers(0, 5)),
            elements=st.integers(-5, 5) | st.sampled_from([np.nan, np.inf, -np.inf, 0.5, 1e39, -1e39]),
        ),
        min_size=1,
        max_size=5,
    )
)
def test_fuzz_arbitrary_arrays_fail_only_with_value_or_type_errors(raw):
    y = np.zeros(len(raw))
    try:
        forest = small_forest().fit(raw, y)
    except (ValueError, TypeError):
        return
    assert np.isfinite(forest.predict(raw)).all()


# --- before fit -------------------------------------------------------------------------------

UNFITTED_CALLS = {
    "predict": lambda e: e.predict(GOOD),
    "apply": lambda e: e.apply(GOOD),
    "decision_path": lambda e: e.decision_path(GOOD),
    "score": lambda e: e.score(GOOD, [0, 1, 0]),
    "feature_importances_": lambda e: e.feature_importances_,
    "get_depth": lambda e: e.get_depth(),
    "get_n_leaves": lambda e: e.get_n_leaves(),
    "predict_proba": lambda e: e.predict_proba(GOOD),
    "predict_log_proba": lambda e: e.predict_log_proba(GOOD),
}


def _unfitted_cases():
    from boxtrees import BoxExtraTreeClassifier, BoxExtraTreeRegressor, BoxExtraTreesClassifier

    for cls in (BoxExtraTreeRegressor, BoxExtraTreeClassifier, BoxExtraTreesRegressor,
                BoxExtraTreesClassifier):
        for name, call in UNFITTED_CALLS.items():
            if name == "feature_importances_" or hasattr(cls, name):
                yield pytest.param(cls, call, id=f"{cls.__name__}.{name}")


@pytest.mark.parametrize("cls, call", list(_unfitted_cases()))
def test_every_prediction_method_raises_not_fitted_error_before_fit(cls, call):
    from sklearn.exceptions import NotFittedError

    with pytest.raises(NotFittedError, match=f"This {cls.__name__} instance is not fitted yet"):
        call(cls())


@pytest.mark.parametrize("method", ["predict", "apply", "decision_path", "predict_proba"])
@pytest.mark.parametrize("single", [True, False], ids=["tree", "forest"])
def test_an_estimator_whose_fit_failed_is_not_fitted(method, single):
    from sklearn.exceptions import NotFittedError

    from boxtrees import BoxExtraTreeClassifier, BoxExtraTreesClassifier

    estimator = BoxExtraTreeClassifier() if single else BoxExtraTreesClassifier()
    X = np.zeros((3, 2))
    with pytest.raises(ValueError, match="Unknown label type"):
        estimator.fit(X, [0.5, 1.5, 2.5])  # fails after validating X (n_features_in_ is set)
    with pytest.raises(NotFittedError):
        getattr(estimator, method)(X)
