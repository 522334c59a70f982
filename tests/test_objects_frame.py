"""Object sets from long tables (one row per object), with named types."""
import pickle

import numpy as np
import pandas as pd
import pytest

from boxtrees import BoxExtraTreesClassifier, BoxExtraTreesRegressor, GridCounts, ObjectSets


def detections(rng, n_frames, labels=("car", "person", "bike"), empty_every=5):
    """A detection table: frame id, box centre and size, class label; every
    ``empty_every``-th frame has no detection at all."""
    rows = []
    for frame in range(n_frames):
        if frame % empty_every == 0:
            continue
        for _ in range(rng.integers(1, 8)):
            rows.append((1000 + frame, *rng.uniform(0, 100, 2), *rng.uniform(1, 10, 2),
                         labels[rng.integers(len(labels))]))
    return pd.DataFrame(rows, columns=["frame", "x", "y", "w", "h", "label"])


def people_near_centre(frame_table, n_frames):
    """The target: persons whose box centre is within 25 of (50, 50), per frame."""
    near = frame_table[(frame_table.label == "person")
                       & ((frame_table.x - 50).abs() < 25) & ((frame_table.y - 50).abs() < 25)]
    return near.groupby("frame").size().reindex(1000 + np.arange(n_frames), fill_value=0).to_numpy()


def test_from_frame_keeps_empty_samples_in_the_given_order_and_names_the_types():
    rng = np.random.default_rng(0)
    table = detections(rng, 30)
    frames = 1000 + np.arange(30)[::-1]                  # the order of another table's rows
    sets = ObjectSets.from_frame(table, sample="frame", columns=["x", "y", "w", "h"],
                                 type="label", samples=frames)
    assert len(sets) == 30 and sets.n_attributes == 4
    assert sets.type_names.tolist() == ["bike", "car", "person"]
    for i, frame in enumerate(frames):
        mine = table[table.frame == frame]
        assert sets.sizes[i] == len(mine)
        np.testing.assert_allclose(sets[i][:, :4], mine[["x", "y", "w", "h"]].to_numpy(), rtol=1e-6)
        assert [sets.type_names[int(t)] for t in sets[i][:, 4]] == mine.label.tolist()
    # without samples: the ids present, sorted (the empty frames are unknown then)
    assert len(ObjectSets.from_frame(table, sample="frame", columns=["x"], type="label")) == 24


def test_categorical_and_integer_types():
    table = pd.DataFrame({"s": [1, 1, 2], "x": [0.0, 1.0, 2.0],
                          "kind": pd.Categorical(["b", "a", "b"]), "id": [3, 0, 3]})
    named = ObjectSets.from_frame(table, sample="s", columns=["x"], type="kind")
    assert named.type_names.tolist() == ["a", "b"] and named.data[:, 1].tolist() == [1, 0, 1]
    plain = ObjectSets.from_frame(table, sample="s", columns=["x"], type="id")
    assert plain.type_names is None and plain.data[:, 1].tolist() == [3, 0, 3]
    # a plain mapping of columns works as well as a data frame
    as_dict = ObjectSets.from_frame({c: table[c].to_numpy() for c in ("s", "x", "id")},
                                    sample="s", columns=["x"], type="id")
    np.testing.assert_array_equal(as_dict.data, plain.data)


def test_the_estimators_learn_from_frames_and_read_new_frames_by_type_name():
    rng = np.random.default_rng(1)
    train, test = detections(rng, 600), detections(rng, 200)
    read = dict(sample="frame", columns=["x", "y", "w", "h"], type="label")
    X = ObjectSets.from_frame(train, samples=1000 + np.arange(600), **read)
    X_test = ObjectSets.from_frame(test, samples=1000 + np.arange(200), **read)
    y, y_test = people_near_centre(train, 600), people_near_centre(test, 200)
    forest = BoxExtraTreesRegressor(20, random_state=0).fit(X, y)
    assert forest.type_names_.tolist() == ["bike", "car", "person"]
    assert forest.score(X_test, y_test) > 0.8
    # a frame whose labels come in another order, or with a label never seen at fit, is read
    # by name: the same prediction when the new label's objects are dropped
    renamed = test.assign(label=test.label.replace({"bike": "truck"}))
    X_renamed = ObjectSets.from_frame(renamed, samples=1000 + np.arange(200), **read)
    assert X_renamed.type_names.tolist() == ["car", "person", "truck"]
    without = ObjectSets.from_frame(test[test.label != "bike"], samples=1000 + np.arange(200),
                                    **read)
    np.testing.assert_array_equal(forest.predict(X_renamed), forest.predict(without))
    # a tree of the forest reads names as the forest does
    np.testing.assert_array_equal(forest[0].predict(X_renamed), forest[0].predict(without))
    again = pickle.loads(pickle.dumps(forest))
    np.testing.assert_array_equal(again.predict(X_renamed), forest.predict(X_renamed))
    # named types at predict, unnamed at fit: the ids are read as they are, with a warning
    plain = BoxExtraTreesClassifier(5, random_state=0).fit(
        ObjectSets(X.data, X.offsets), y > 0)
    with pytest.warns(UserWarning, match="X has type names, but BoxExtraTreesClassifier was "
                                         "fitted without type names"):
        named = plain.predict(X_test)
    np.testing.assert_array_equal(named, plain.predict(ObjectSets(X_test.data, X_test.offsets)))
    assert GridCounts(4).fit(X).transform(X_renamed).shape == (200, 4 * 4 * 3)


@pytest.mark.parametrize("kwargs, error, match", [
    (dict(columns=["nope"]), ValueError, "no column 'nope'"),
    (dict(columns="x"), TypeError, "sequence of column names"),
    (dict(columns=[]), ValueError, "at least one attribute column"),
    (dict(columns=["label"]), TypeError, "must hold real numbers"),
    (dict(columns=["x"], samples=[1000, 1001]), ValueError, "sample 1002 .* not in samples"),
    (dict(columns=["x"], samples=[[1000]]), ValueError, "1D sequence of distinct"),
])
def test_bad_frames_get_clear_errors(kwargs, error, match):
    table = pd.DataFrame({"frame": [1000, 1001, 1002], "x": [0.0, 1.0, np.nan],
                          "label": ["a", "b", "a"]})
    with pytest.raises(error, match=match):
        ObjectSets.from_frame(table.fillna(0.0), **{"sample": "frame", "type": "label", **kwargs})


def test_missing_values_are_named():
    table = pd.DataFrame({"s": [1, 2], "x": [0.0, np.nan], "t": ["a", "b"]})
    with pytest.raises(ValueError, match="NaN or infinite"):
        ObjectSets.from_frame(table, sample="s", columns=["x"], type="t")
    with pytest.raises(ValueError, match="missing labels"):
        ObjectSets.from_frame(table.fillna(0).assign(t=["a", None]), sample="s", columns=["x"],
                              type="t")


def test_batches_that_name_their_types_otherwise_do_not_join():
    a = ObjectSets(np.zeros((1, 3)), [0, 1], type_names=["car"])
    b = ObjectSets(np.zeros((1, 3)), [0, 1], type_names=["person"])
    with pytest.raises(ValueError, match="name their types alike"):
        ObjectSets.concatenate([a, b])
    assert ObjectSets.concatenate([a, a[:1]]).type_names.tolist() == ["car"]
    with pytest.raises(ValueError, match="names 1 types"):
        ObjectSets(np.array([[0.0, 0.0, 1]]), [0, 1], type_names=["car"])
