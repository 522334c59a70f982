"""No value reachable from Python makes a boxtrees kernel read or write out of bounds, and
memory follows the objects present, not the largest type id.

test_boxtrees_asan.py runs this file again on an AddressSanitizer build.
"""
import pickle
import tracemalloc
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from boxtrees import BoxExtraTreesRegressor, BoxTree, GridCounts, ObjectSets, make_box_regression
from boxtrees._builder import build_tree
from boxtrees._layout import MAX_GROUP_COLUMNS
from conftest import THESIS_FOREST
from boxtrees._predictor import PackedForest, apply_leaves, predict_mean

NODE_ARRAYS = ("children_left", "children_right", "object_type", "box", "threshold", "value",
               "impurity", "n_node_samples", "weighted_n_node_samples")


def small_sets(rng, n, per_set=4, n_types=3):
    return [np.column_stack([rng.uniform(-3, 3, (per_set, 2)), rng.integers(0, n_types, per_set)])
            for _ in range(n)]


@pytest.fixture(scope="module")
def forest():
    rng = np.random.default_rng(0)
    X = small_sets(rng, 80)
    return BoxExtraTreesRegressor(3, n_tests=10, min_samples_split=5, random_state=0).fit(
        X, rng.normal(size=80))


def test_a_batch_changed_after_it_was_built_gets_a_value_error(forest):
    buf = np.zeros((8, 3), np.float32)
    sets = ObjectSets(buf, [0, 4, 8])
    buf[:, 2] = -1000.0           # segfaulted before the kernels checked their inputs
    for call in (forest.predict, forest.apply, forest.decision_path,
                 lambda X: forest.fit(X, [1.0, 2.0]),
                 GridCounts(2, view_bounds=3).fit([np.empty((0, 3))]).transform):
        with pytest.raises(ValueError, match="negative type ids"):
            call(sets)
    buf[:, 2] = 0
    buf[5, 1] = np.nan
    with pytest.raises(ValueError, match=r"NaN or infinite values \(object row 5"):
        forest.predict(sets)
    buf[5, 1] = 0
    for offsets in ([0, 4, 10**9], [0, 6, 4], [-1, 4, 8]):
        sets.offsets[:] = offsets
        with pytest.raises(ValueError, match="offsets must be non-decreasing from 0"):
            forest.predict(sets)
    sets.offsets[:] = [0, 4, 8]
    assert forest.predict(sets).shape == (2,)


def test_kernels_check_their_inputs_on_every_call(forest):
    packed = forest._packed
    data = np.zeros((4, 3), np.float32)
    assert predict_mean(packed, data, np.array([0, 2, 4]), np.empty((2, 1))) == (0, -1)
    for offsets in ([0, 2, 5], [0, 3, 2], [-1, 2, 4]):   # the offset position of the problem
        problem, position = predict_mean(packed, data, np.array(offsets), np.empty((2, 1)))
        assert problem == 6 and 0 <= position < 3
    bad = data.copy()
    bad[3] = [0.0, 0.0, 1.5]
    assert predict_mean(packed, bad, np.array([0, 2, 4]), np.empty((2, 1))) == (4, 3)
    with pytest.raises(ValueError, match=r"out has shape \(3, 1\); expected \(2, 1\)"):
        predict_mean(packed, data, np.array([0, 2, 4]), np.empty((3, 1)))
    with pytest.raises(ValueError, match=r"expected \(2, 3\)"):
        apply_leaves(packed, data, np.array([0, 2, 4]), np.empty((2, 2), dtype=np.intp))
    with pytest.raises(ValueError, match="3 columns"):
        predict_mean(packed, np.zeros((4, 2), np.float32), np.array([0, 4]), np.empty((1, 1)))
    with pytest.raises(TypeError):
        predict_mean(object(), data, np.array([0, 4]), np.empty((1, 1)))


def _bounds(n_types, x=(0, 0)):
    """The builder's regions of a group of one column: x, then an unbounded y."""
    bounds = np.zeros((n_types, 2 * MAX_GROUP_COLUMNS), np.float32)
    bounds[:, :4] = [*x, -np.inf, np.inf]
    return bounds


def _build(sample_of, segment_ptr=(0, 3), n_samples=2):
    n = len(sample_of)
    objects = SimpleNamespace(x=np.zeros(n, np.float32), y=np.zeros(n, np.float32),
                              sample_of=np.asarray(sample_of), segment_ptr=list(segment_ptr),
                              band_edges=[[-np.inf, np.inf]], bounds=_bounds(1),
                              half_widths=np.ones((1, MAX_GROUP_COLUMNS)), group_sizes=[1])
    params = SimpleNamespace(test_type="fixed", n_tests=5, min_samples_split=2,
                             max_depth=-1, max_retries=1, refine_tests=False)
    return build_tree(objects, np.zeros(n_samples), np.ones(n_samples), params, 0)


@pytest.mark.parametrize("sample_of, segment_ptr, match", [
    ([0, 1, 2], (0, 3), r"sample ids in \[0, 2\)"),
    ([0, -1, 1], (0, 3), r"sample ids in \[0, 2\)"),
    ([0, 1, 1], (0, 4), "segment_ptr must rise from 0"),
    ([0, 1, 1], (1, 3), "segment_ptr must rise from 0"),
    ([0, 1, 1], (0, 2, 3), "n_types \\* n_bands \\+ 1"),
])
def test_the_tree_builder_checks_its_index_arrays(sample_of, segment_ptr, match):
    with pytest.raises(ValueError, match=match):
        _build(sample_of, segment_ptr)
    assert _build([0, 1, 1])["children_left"].shape == (1,)


def test_tree_arrays_are_read_only_and_rebuilt_trees_are_validated(forest):
    tree = forest[0].tree_
    with pytest.raises(ValueError, match="read-only"):
        tree.children_left[0] = 10**6
    arrays = {name: np.array(getattr(tree, name)) for name in NODE_ARRAYS}
    for name, value, match in [
        ("children_left", 10**6, "children must be"),
        ("children_right", 0, "children must be"),      # a cycle: the walk would never end
        ("object_type", 7, "not one of the forest's types"),
        ("threshold", 2**40, "int32"),
        ("box", np.nan, "NaN box bound"),
        ("value", np.inf, "non-finite value"),
    ]:
        edited = {**arrays, name: arrays[name].astype(np.float64 if name in ("box", "value") else np.int64)}
        edited[name][0] = value
        with pytest.raises(ValueError, match=match):
            PackedForest([BoxTree(**edited)], forest.types_)
    with pytest.raises(ValueError, match=r"box must have shape \(node_count, 2 \* n_attributes\)"):
        PackedForest([BoxTree(**{**arrays, "box": arrays["box"][:, :3]})], forest.types_)
    with pytest.raises(ValueError, match=r"box has shape \(\d+, 4\); \d+ nodes need"):
        PackedForest([BoxTree(**{**arrays, "box": arrays["box"][:-1]})], forest.types_)
    with pytest.raises(ValueError, match="at least one tree"):
        PackedForest([], forest.types_)


def test_an_unpickled_forest_with_a_corrupted_tree_is_rejected(forest):
    tree = forest[1].tree_
    left = np.array(tree.children_left)
    left[0] = 10**6
    corrupted = BoxTree(**{**{name: getattr(tree, name) for name in NODE_ARRAYS}, "children_left": left})
    edited = pickle.loads(pickle.dumps(forest))
    edited.estimators_[1].__dict__["tree_"] = corrupted   # as a hand-edited file would hold it
    blob = pickle.dumps(edited)
    with pytest.raises(ValueError, match="tree 0, node 0 children must be"):
        pickle.loads(blob)


# --- mutation fuzzing: containers and trees changed after validation ------------------------

value = st.one_of(st.floats(allow_nan=True, allow_infinity=True, width=32),
                  st.sampled_from([-1000.0, -1.0, 0.0, 1.0, 2.0, 2.5, 2.0**24, 2.0**31, 3e38]))


@settings(max_examples=200, deadline=None)
@given(n_sets=st.integers(0, 6), per_set=st.integers(0, 5), data=st.data())
def test_fuzz_batches_mutated_after_validation_predict_or_raise_value_error(forest, n_sets, per_set, data):
    rng = np.random.default_rng(data.draw(st.integers(0, 2**32 - 1)))
    sets = ObjectSets.from_sequence(small_sets(rng, n_sets, per_set, n_types=5))
    for _ in range(data.draw(st.integers(1, 4))):
        if data.draw(st.booleans()) and sets.n_objects:
            row, col = data.draw(st.integers(0, sets.n_objects - 1)), data.draw(st.integers(0, 2))
            sets.data[row, col] = data.draw(value)
        else:
            sets.offsets[data.draw(st.integers(0, n_sets))] = data.draw(st.integers(-5, 40))
    try:
        pred = forest.predict(sets)
    except ValueError as error:
        assert "offsets" in str(error) or "object row" in str(error)
        return
    assert pred.shape == (n_sets,) and np.isfinite(pred).all()


int_edit = st.tuples(st.sampled_from(NODE_ARRAYS[:3] + ("threshold", "n_node_samples")),
                    st.integers(0, 10**6),
                    st.integers(-3, 60) | st.sampled_from([2**31, -(2**31) - 1, 10**12]))
float_edit = st.tuples(st.sampled_from(("box", "value")), st.integers(0, 10**6),
                       st.floats(allow_nan=True, width=32))


@settings(max_examples=200, deadline=None)
@given(edits=st.lists(int_edit | float_edit, min_size=1, max_size=4))
def test_fuzz_edited_trees_are_packed_only_when_every_walk_stays_inside(forest, edits):
    tree = forest[0].tree_
    arrays = {name: np.array(getattr(tree, name)) for name in NODE_ARRAYS}
    arrays.update({name: arrays[name].astype(np.int64) for name in NODE_ARRAYS[:3] + ("threshold",)})
    for name, node, new in edits:
        arrays[name].reshape(tree.node_count, -1)[node % tree.node_count] = new
    try:
        packed = PackedForest([BoxTree(**arrays)], forest.types_)
    except ValueError:
        return
    rng = np.random.default_rng(1)
    batch = ObjectSets.from_sequence(small_sets(rng, 20))
    out = np.empty((len(batch), 1))
    assert predict_mean(packed, batch.data, batch.offsets, out) == (0, -1)
    assert np.isfinite(out).all()


# --- type ids: accuracy and memory follow the types present ---------------------------------

def test_one_object_of_a_huge_type_id_changes_neither_accuracy_nor_memory():
    from boxtrees import make_box_regression

    X, y = make_box_regression(2000, random_state=0)
    X_test, y_test = make_box_regression(1000, random_state=1)
    params = dict(n_estimators=10, n_tests=200, min_samples_split=10, test_width=1.5, random_state=0)
    plain = BoxExtraTreesRegressor(**params).fit(X, y).score(X_test, y_test)
    sets = list(X)
    sets[0] = np.vstack([sets[0], [[0.0, 0.0, 100_000]]])
    odd = BoxExtraTreesRegressor(**params).fit(sets, y)
    assert odd.types_.tolist() == [0, 1, 2, 3, 100_000]
    # before: every tree a single leaf (R^2 0), tests drawn on 100,001 mostly absent ids
    assert plain > 0.6 and odd.score(X_test, y_test) > plain - 0.05
    tracemalloc.start()
    odd.predict(X_test)
    GridCounts(4).fit(sets).transform(sets)
    huge = [np.array([[0.0, 0.0, 2**24 - 1], [1.0, 1.0, 0]])] * 30
    BoxExtraTreesRegressor(2, n_tests=5, min_samples_split=2).fit(huge[:3], [0.0, 1.0, 2.0]).predict(huge)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak < 50 * 2**20, peak        # was gigabytes: samples x (largest id + 1)
    assert GridCounts(2).fit(huge).transform(huge).shape == (30, 2 * 2 * 2)


def _grow_columns(columns, target, test_type="classic", local_x=True):
    bounds = _bounds(columns.shape[1], [-3, 3])
    objects = SimpleNamespace(columns=columns, bounds=bounds, local_x=local_x,
                              half_widths=np.full((len(bounds), MAX_GROUP_COLUMNS), 0.5),
                              group_sizes=[1])
    params = SimpleNamespace(test_type=test_type, n_tests=30,
                             min_samples_split=2, max_depth=-1, max_retries=1, refine_tests=False)
    return build_tree(objects, target, np.ones(len(target)), params, 7)


@pytest.mark.parametrize("test_type", ["classic", "random", "fixed"])
def test_the_tree_builder_reads_a_feature_matrix_in_place_whatever_its_strides(test_type):
    rng = np.random.default_rng(0)
    wide = rng.normal(size=(300, 8)).astype(np.float32)
    target = wide[:, 1] - wide[:, 5] ** 2
    plain = np.ascontiguousarray(wide[:, 1::2])
    for view, rows in ((wide[:, 1::2], slice(None)), (np.asfortranarray(plain), slice(None)),
                       (wide[::-1, 1::2], slice(None, None, -1))):   # negative row stride
        assert not view.flags.c_contiguous
        tree = _grow_columns(view, target[rows], test_type)
        reference = _grow_columns(np.ascontiguousarray(view), target[rows], test_type)
        for name in NODE_ARRAYS:
            np.testing.assert_array_equal(tree[name], reference[name])
    with pytest.raises(ValueError, match=r"columns must have shape \(300, 4\)"):
        _grow_columns(plain[:-1], target)
    with pytest.raises(ValueError, match=r"columns must have shape \(300, 3\)"):
        objects = SimpleNamespace(columns=plain, bounds=_bounds(3), local_x=True,
                                  half_widths=np.ones((3, MAX_GROUP_COLUMNS)), group_sizes=[1])
        build_tree(objects, target, np.ones(300), SimpleNamespace(
            test_type="classic", n_tests=3, min_samples_split=2, max_depth=-1,
            max_retries=0, refine_tests=False), 0)


def test_fit_on_a_feature_matrix_needs_memory_for_its_samples_not_a_copy_of_the_matrix():
    rng = np.random.default_rng(0)
    X = rng.normal(size=(40_000, 50)).astype(np.float32)      # 8 MB
    y = X[:, 0] - X[:, 1]
    forest = BoxExtraTreesRegressor(2, **{**THESIS_FOREST, "test_type": "classic"}, n_tests=50,
                                    min_samples_split=2000, random_state=0, n_jobs=1)
    tracemalloc.start()
    forest.fit(X, y)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    # per tree: a few arrays of one number per sample (about 2 MB here; the previous design
    # kept sorted copies of every column, three times the matrix)
    assert peak < X.nbytes / 2, peak
    assert forest.score(X, y) > 0.9


@pytest.mark.parametrize("weight", [1e-300, 3.0, 1e200, 1e300, 1e305])
def test_weights_of_any_finite_size_grow_the_trees_of_unit_weights(weight):
    X, y = make_box_regression(400, random_state=0)
    reference = BoxExtraTreesRegressor(4, random_state=0).fit(X, y)
    scaled = BoxExtraTreesRegressor(4, random_state=0).fit(X, y, sample_weight=np.full(400, weight))
    for a, b in zip(reference, scaled):
        np.testing.assert_array_equal(a.tree_.box, b.tree_.box)
        np.testing.assert_array_equal(a.tree_.n_node_samples, b.tree_.n_node_samples)
        np.testing.assert_allclose(b.tree_.weighted_n_node_samples,
                                   a.tree_.weighted_n_node_samples * weight, rtol=1e-12)
    np.testing.assert_allclose(scaled.predict(X), reference.predict(X), rtol=1e-12)
    np.testing.assert_allclose(scaled.feature_importances_, reference.feature_importances_,
                               rtol=1e-9)


@pytest.mark.parametrize("scale", [2.0**-500, 1e-100, 7.0, 1e100, 1e150])
def test_targets_of_any_representable_size_grow_the_same_trees(scale):
    X, y = make_box_regression(400, random_state=0)
    y = y / np.abs(y).max()
    reference = BoxExtraTreesRegressor(4, random_state=0).fit(X, y)
    scaled = BoxExtraTreesRegressor(4, random_state=0).fit(X, y * scale)
    for a, b in zip(reference, scaled):
        np.testing.assert_array_equal(a.tree_.box, b.tree_.box)
    np.testing.assert_allclose(scaled.predict(X) / scale, reference.predict(X), rtol=1e-12)
    np.testing.assert_allclose(scaled.feature_importances_, reference.feature_importances_,
                               rtol=1e-9)


def test_inputs_beyond_float64_are_named():
    X, y = make_box_regression(100, random_state=0)
    y = y / np.abs(y).max()
    with pytest.raises(ValueError, match=r"sample_weight sums to more than float64 holds"):
        BoxExtraTreesRegressor(2).fit(X, y, sample_weight=np.full(100, 1e308))
    with pytest.raises(ValueError, match=r"y has values of magnitude .* overflow float64"):
        BoxExtraTreesRegressor(2).fit(X, y * 1e307)
    # tiny targets grow their trees, but their variances underflow: said, not hidden
    reference = BoxExtraTreesRegressor(2, random_state=0).fit(X, y)
    with pytest.warns(UserWarning, match=r"underflow float64 to 0, and so do feature_importances_"):
        tiny = BoxExtraTreesRegressor(2, random_state=0).fit(X, y * 1e-300)
    np.testing.assert_allclose(tiny.predict(X) / 1e-300, reference.predict(X), rtol=1e-12)


def test_subnormal_targets_grow_their_trees():
    X, y = make_box_regression(100, random_state=0)
    y = y / np.abs(y).max()
    reference = BoxExtraTreesRegressor(2, random_state=0).fit(X, y)
    with pytest.warns(UserWarning, match="underflow"):
        tiny = BoxExtraTreesRegressor(2, random_state=0).fit(X, y * 2.0**-1040)
    assert np.isfinite(tiny.predict(X)).all()
    for a, b in zip(reference, tiny):
        np.testing.assert_array_equal(a.tree_.box, b.tree_.box)
