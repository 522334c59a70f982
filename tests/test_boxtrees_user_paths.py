"""The paths a user walks from scikit-learn's habits: object sets through its splitters and
indexing, named types on both sides of a fit, and the errors met on the way, each naming
its fix."""
import warnings

import numpy as np
import pandas as pd
import pytest
from sklearn.inspection import permutation_importance
from sklearn.model_selection import KFold, cross_validate, train_test_split
from sklearn.utils import _safe_indexing

from boxtrees import (
    BoxExtraTreeRegressor, BoxExtraTreesClassifier, BoxExtraTreesRegressor, ObjectSets,
    region_importance, type_importance,
)

SMALL = dict(n_tests=20, min_samples_split=2, random_state=0)


def detections(n_frames, seed=0):
    """A long table, one row per object: frame id, position, class label; frames
    ``0, 5, 10, ...`` have no object. The target counts the persons right of x = 50."""
    rng = np.random.default_rng(seed)
    rows = [(frame, *rng.uniform(0, 100, 2), ("car", "person")[rng.integers(2)])
            for frame in range(n_frames) if frame % 5 for _ in range(rng.integers(1, 6))]
    table = pd.DataFrame(rows, columns=["frame", "x", "y", "label"])
    right = table[(table.label == "person") & (table.x > 50)]
    y = right.groupby("frame").size().reindex(np.arange(n_frames), fill_value=0).to_numpy()
    return table, y.astype(float)


READ = dict(sample="frame", columns=["x", "y"], type="label")


def named_sets(n_frames=60):
    table, y = detections(n_frames)
    return ObjectSets.from_frame(table, samples=np.arange(n_frames), **READ), y


# --- object sets through scikit-learn's indexing, with their type names ----------------------


@pytest.mark.parametrize("index", [np.array([3, 0, 7]), np.arange(60) % 3 == 0, slice(5, 20, 2),
                                   [4, 1]], ids=["ints", "mask", "slice", "list"])
def test_safe_indexing_gives_object_sets_with_their_type_names(index):
    X, _ = named_sets()
    subset = _safe_indexing(X, index)
    assert isinstance(subset, ObjectSets) and subset.type_names.tolist() == ["car", "person"]
    expected = list(X)[index] if isinstance(index, slice) else \
        [X[i] for i in np.arange(len(X))[index]]
    assert len(subset) == len(expected)
    for got, want in zip(subset, expected):
        np.testing.assert_array_equal(got, want)


def test_splitters_and_cross_validation_keep_the_type_names():
    X, y = named_sets()
    X_train, X_test, y_train, y_test = train_test_split(X, y, random_state=0)
    assert isinstance(X_train, ObjectSets) and isinstance(X_test, ObjectSets)
    assert X_train.type_names.tolist() == X_test.type_names.tolist() == ["car", "person"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")   # no warning of names lost on the way
        forest = BoxExtraTreesRegressor(5, **SMALL).fit(X_train, y_train)
        forest.predict(X_test)
        result = cross_validate(BoxExtraTreesRegressor(5, **SMALL), X, y, cv=KFold(3),
                                return_estimator=True)
    assert forest.type_names_.tolist() == ["car", "person"]
    assert all(e.type_names_.tolist() == ["car", "person"] for e in result["estimator"])


def test_named_and_unnamed_types_across_a_fit_warn_as_feature_names_do():
    X, y = named_sets()
    unnamed = ObjectSets(X.data, X.offsets)
    named = BoxExtraTreesRegressor(5, **SMALL).fit(X, y)
    with pytest.warns(UserWarning, match=r"X does not have type names, but "
                                         r"BoxExtraTreesRegressor was fitted with type names"
                                         r".*type_names_"):
        from_ids = named.predict(list(unnamed))
    np.testing.assert_array_equal(from_ids, named.predict(X))
    plain = BoxExtraTreeRegressor(**SMALL).fit(unnamed, y)
    with pytest.warns(UserWarning, match=r"X has type names, but BoxExtraTreeRegressor was "
                                         r"fitted without type names"):
        from_names = plain.predict(X)
    np.testing.assert_array_equal(from_names, plain.predict(unnamed))
    # both named: read by name, whatever the order of the names (no warning)
    table, _ = detections(60)
    renamed = ObjectSets.from_frame(table.assign(label=table.label.map({"car": "van",
                                                                        "person": "person"})),
                                    samples=np.arange(60), **READ)
    assert renamed.type_names.tolist() == ["person", "van"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert named.predict(renamed).shape == (60,)


# --- messages that name the fix -------------------------------------------------------------


@pytest.mark.parametrize("X", [[], (), np.array([]), pd.Series([], dtype=object),
                               ObjectSets.from_sequence([])],
                         ids=["list", "tuple", "array", "series", "ObjectSets"])
def test_empty_data_is_said_to_be_empty(X):
    match = r"X is empty \(0 samples\).*a sample is a set of objects"
    with pytest.raises(ValueError, match=match):
        BoxExtraTreesRegressor(2).fit(X, [])
    on_sets = BoxExtraTreesRegressor(2, **SMALL).fit(*named_sets(20))
    if not isinstance(X, ObjectSets):      # zero object sets predict zero values
        with pytest.raises(ValueError, match=match):
            on_sets.predict(X)


def test_a_long_table_at_fit_is_pointed_to_from_frame():
    table, y = detections(30)
    with pytest.raises(ValueError, match=r"columns \['label'\] .*ObjectSets\.from_frame"):
        BoxExtraTreesRegressor(2).fit(table, y)
    numbered = table.assign(label=(table.label == "person").astype(int))
    with pytest.raises(ValueError, match=rf"{len(table)} rows .* {len(y)} targets"
                                         r".*ObjectSets\.from_frame"):
        BoxExtraTreesRegressor(2).fit(numbered, y)
    # a feature matrix of the right length is still one
    features = pd.DataFrame({"a": np.arange(30.0), "b": np.ones(30)})
    assert BoxExtraTreesRegressor(2).fit(features, y).n_features_in_ == 2


def test_sets_of_a_frame_without_samples_say_the_empty_samples_were_dropped():
    table, y = detections(30)
    X = ObjectSets.from_frame(table, **READ)
    assert len(X) == 24               # the 6 frames without objects have no set
    with pytest.raises(ValueError, match=r"X has 24 samples but y has 30.*samples without "
                                         r"objects.*samples="):
        BoxExtraTreesRegressor(2).fit(X, y)
    with pytest.raises(ValueError, match=r"X has 23 samples but y has 30.*samples="):
        BoxExtraTreesRegressor(2).fit(X[1:], y)      # a part of such a batch is one as well
    with pytest.raises(ValueError, match=r"X has 30 samples but y has 24$"):
        BoxExtraTreesRegressor(2).fit(ObjectSets.from_frame(table, samples=np.arange(30),
                                                            **READ), y[:24])


def test_permutation_importance_on_sets_is_pointed_to_type_importance():
    X = [np.array([[i, 0.0, 0], [0.0, i, 1]]) for i in range(20)]   # equal sizes: a 3D array
    y = np.arange(20.0)
    forest = BoxExtraTreesRegressor(2, **SMALL).fit(X, y)
    # scikit-learn turns the sets into a 3D array and refuses it before any boxtrees code runs
    with pytest.raises(ValueError, match="dim 3"):
        permutation_importance(forest, X, y)
    # what the user reads instead: the importances' docstrings name the set equivalents
    for documented in (BoxExtraTreesRegressor.feature_importances_,
                       BoxExtraTreeRegressor.feature_importances_):
        assert "permutation_importance" in documented.__doc__
        assert "type_importance" in documented.__doc__
    with pytest.raises(TypeError, match="boxtrees.type_importance"):
        permutation_importance(forest, ObjectSets.from_sequence(X), y)


def test_fitting_sets_without_any_object_warns_that_every_tree_is_a_leaf():
    with pytest.warns(UserWarning, match=r"no object.*single leaf"):
        forest = BoxExtraTreesRegressor(2).fit([np.empty((0, 3))] * 5, np.arange(5.0))
    assert all(tree.tree_.node_count == 1 for tree in forest)
    with warnings.catch_warnings():
        warnings.simplefilter("error")       # one object is enough
        BoxExtraTreesRegressor(2).fit([np.empty((0, 3))] * 4 + [np.zeros((1, 3))],
                                      np.arange(5.0))


def test_importances_are_labelled_with_the_type_names():
    X, y = named_sets()
    forest = BoxExtraTreesRegressor(5, **SMALL).fit(X, y)
    result = type_importance(forest, X, y, n_repeats=2, random_state=0)
    assert result.types.tolist() == [0, 1]
    assert result.type_names.tolist() == ["car", "person"]
    assert result.importances_mean[1] > result.importances_mean[0]
    maps = region_importance(forest, X, y, types=[1], n_bins=2)
    assert maps.type_names.tolist() == ["person"]
    # unnamed types have no names to give
    plain = BoxExtraTreesClassifier(5, **SMALL).fit(list(X), y > 0)
    assert "type_names" not in type_importance(plain, list(X), y > 0, method="drop")
