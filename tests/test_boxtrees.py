"""Correctness of BoxExtraTreesRegressor on object sets: traversal, learning, determinism."""
import os
import pickle
import time

import joblib
import numpy as np
import pytest
from sklearn.ensemble import ExtraTreesRegressor
from sklearn.metrics import r2_score

import boxtrees._base
import boxtrees._threads
from boxtrees import BoxExtraTreesRegressor, GridCounts, ObjectSets, make_box_regression
from boxtrees._rows import RowProblem
from boxtrees._threads import thread_pool, threads_for
from conftest import THESIS_FOREST, reference_leaf, run_in_fork


def thesis_forest(*args, **params):
    """A forest with the thesis's settings where ``params`` do not say otherwise."""
    return BoxExtraTreesRegressor(*args, **{**THESIS_FOREST, **params})


TEST_TYPES = ("fixed", "bounded", "random", "classic")


def random_sets(rng, n, max_objects=10, n_types=4, extent=5.0):
    """Ragged object sets with many empty ones."""
    return [
        np.column_stack([rng.uniform(-extent, extent, (k, 2)), rng.integers(0, n_types, k)])
        for k in rng.integers(0, max_objects + 1, n)
    ]


def trees_of(forest):
    """The node arrays of a forest's trees."""
    return [estimator.tree_ for estimator in forest]


KERNEL_WIDTHS = {"avx512": 16, "avx2": 8}  # the SIMD kernels' lanes, widest first


def _use_kernels(module, lanes):
    """Select ``module``'s kernels of ``lanes`` lanes, or skip where the CPU lacks them."""
    if module._set_simd(lanes) != lanes:
        module._set_simd()
        pytest.skip(f"the CPU does not run the {lanes}-lane kernels")


@pytest.fixture(params=[16, 1], ids=["avx512", "portable"])
def traversal_kernel(request):
    """Run the test with each traversal kernel the CPU runs: AVX-512 and portable."""
    from boxtrees import _predictor

    _use_kernels(_predictor, request.param)
    yield
    _predictor._set_simd()


@pytest.mark.parametrize("test_type", TEST_TYPES)
def test_predict_matches_numpy_reference_traversal(test_type, traversal_kernel):
    rng = np.random.default_rng(0)
    X, y = random_sets(rng, 400), rng.normal(size=400)
    forest = thesis_forest(
        n_estimators=7, n_tests=20, min_samples_split=4, test_type=test_type,
        test_width=1.5, random_state=0,
    ).fit(X, y)
    trees = trees_of(forest)
    # unseen type 9 at predict time must match no test; sets of up to 16 objects and of more,
    # which the AVX-512 kernel walks differently, side by side; sets with more objects of a
    # type than it tests at once (16)
    sized = [np.column_stack([rng.uniform(-5, 5, (k, 2)), rng.choice(types, k)])
             for k, types in [(16, [0, 1, 2, 3]), (17, [0, 1, 2, 3]), (16, [0, 1, 3]),
                              (17, [2]), (16, [9]), (15, [0, 1, 2, 3])]]
    X_new = (random_sets(rng, 300, n_types=10) + [np.empty((0, 3))]
             + random_sets(rng, 100, max_objects=20) + sized
             + random_sets(rng, 50, max_objects=80, n_types=2))
    leaves = np.array([[reference_leaf(t, s) for t in trees] for s in X_new])
    expected = np.mean(
        [[t.value[leaf] for t, leaf in zip(trees, row)] for row in leaves], axis=1
    )
    np.testing.assert_array_equal(forest.apply(X_new), leaves)
    np.testing.assert_allclose(forest.predict(X_new), expected, rtol=1e-12)
    assert all(t.node_count > 20 for t in trees_of(forest))


def spine_forest(d, rng):
    """A forest of long unbalanced spines, as box tests grow on sparse objects (the thesis's
    game): most tests split off the few samples with an object in their small box. Objects
    have ``d`` attributes; with 3, boxes over columns (0, 1) and (0, 1, 2) alternate."""
    X = sets_of(rng, d, rng.integers(2, 13, 2000))
    y = np.array([float((s[:, 0] > 5).sum()) for s in X]) + rng.normal(size=len(X))
    return thesis_forest(n_estimators=4, n_tests=40, min_samples_split=10,
                         random_state=0).fit(X, y)


def sets_of(rng, d, sizes):
    """One set of each size in ``sizes``: objects of ``d`` attributes and 4 types."""
    return [np.column_stack([rng.uniform(-10, 10, (k, d)), rng.integers(0, 4, k)])
            for k in sizes]


@pytest.mark.parametrize("d", [1, 2, 3])
def test_left_chains_walk_to_the_leaves_of_the_reference_traversal(d, traversal_kernel):
    # the AVX-512 walk tests a run of nodes that mostly send samples left at once (sets of up
    # to 16 objects and larger ones walk differently); the leaves are those of a walk node by
    # node
    rng = np.random.default_rng(d)
    forest = spine_forest(d, rng)
    assert forest._packed.n_chains > 0
    X_new = sets_of(rng, d, list(range(17)) * 20 + [17, 20, 24, 30, 32, 40] * 5)
    leaves = np.array([[reference_leaf(t, s) for t in trees_of(forest)] for s in X_new])
    np.testing.assert_array_equal(forest.apply(X_new), leaves)


def test_training_counts_pick_the_chains_and_change_no_leaf(traversal_kernel):
    # which nodes form chains follows each tree's n_node_samples; counts that are unknown or
    # false change the chains (and the speed), never a leaf
    from boxtrees import BoxTree
    from boxtrees._predictor import PackedForest, apply_leaves

    rng = np.random.default_rng(4)
    forest = spine_forest(2, rng)
    batch = ObjectSets.from_sequence(sets_of(rng, 2, list(range(17)) * 10))
    expected = np.array([[reference_leaf(t, s) for t in trees_of(forest)] for s in batch])
    arrays = [{name: getattr(t, name) for name in t.__annotations__} for t in trees_of(forest)]
    n_chains = []
    for counts in (None, -1, "random", "huge"):
        trees = []
        for a in arrays:
            n = len(a["value"])
            false = {None: a["n_node_samples"], -1: np.full(n, -1),
                     "random": rng.integers(-2, 50, n), "huge": np.full(n, 2**40)}[counts]
            trees.append(BoxTree(**{**a, "n_node_samples": false}))
        packed = PackedForest(trees, forest.types_)
        leaves = np.empty((len(batch), len(trees)), dtype=np.intp)
        assert apply_leaves(packed, batch.data, batch.offsets, leaves) == (0, -1)
        np.testing.assert_array_equal(leaves, expected)
        n_chains.append(packed.n_chains)
    true, unknown, random, huge = n_chains
    assert true == forest._packed.n_chains > 0 and unknown == 0 and random != true
    assert huge == 0  # equal counts: every node seems to send all its samples right


def test_node_arrays_are_consistent_with_training_data():
    rng = np.random.default_rng(1)
    X, y = random_sets(rng, 300), rng.normal(size=300)
    forest = thesis_forest(n_estimators=3, n_tests=30, min_samples_split=10, random_state=0)
    forest.fit(X, y)
    leaves = forest.apply(X)
    for k, tree in enumerate(trees_of(forest)):
        inner = tree.children_left != -1
        left, right = tree.children_left[inner], tree.children_right[inner]
        np.testing.assert_array_equal(
            tree.n_node_samples[inner], tree.n_node_samples[left] + tree.n_node_samples[right]
        )
        assert (tree.weighted_n_node_samples[inner] >= 10).all()
        assert (tree.threshold[inner] >= 1).all() and (tree.threshold[~inner] == -2).all()
        assert tree.n_node_samples[0] == len(X)
        for leaf in np.unique(leaves[:, k]):
            assert tree.children_left[leaf] == -1
            np.testing.assert_allclose(tree.value[leaf], y[leaves[:, k] == leaf].mean())
            assert tree.n_node_samples[leaf] == (leaves[:, k] == leaf).sum()


@pytest.mark.parametrize("test_type, width", [("fixed", 1.0), ("bounded", 2.0), ("random", None), ("classic", None)])
def test_box_shapes_follow_test_type(test_type, width):
    rng = np.random.default_rng(2)
    X, y = random_sets(rng, 300, extent=8.0), rng.normal(size=300)
    bounds = (-8.0, 8.0, -6.0, 6.0)
    forest = thesis_forest(
        n_estimators=3, n_tests=10, min_samples_split=5, test_type=test_type,
        test_width=width or 1.0, view_bounds=bounds, random_state=0,
    ).fit(X, y)
    boxes = np.concatenate([t.box[t.children_left != -1] for t in trees_of(forest)]).astype(float)
    sizes = boxes[:, [1, 3]] - boxes[:, [0, 2]]
    if test_type == "fixed":
        np.testing.assert_allclose(sizes, 2 * width, atol=1e-5)
    elif test_type == "bounded":
        assert (sizes > 0).all() and (sizes <= 2 * width + 1e-5).all()
        assert sizes.std() > 0.1
    if test_type in ("fixed", "bounded"):
        centres = (boxes[:, [0, 2]] + boxes[:, [1, 3]]) / 2
        assert (centres[:, 0] >= bounds[0] - 1e-5).all() and (centres[:, 0] <= bounds[1] + 1e-5).all()
        assert (centres[:, 1] >= bounds[2] - 1e-5).all() and (centres[:, 1] <= bounds[3] + 1e-5).all()
    elif test_type == "random":
        assert (boxes[:, 0] >= bounds[0]).all() and (boxes[:, 1] <= bounds[1]).all()
        assert (boxes[:, 2] >= bounds[2]).all() and (boxes[:, 3] <= bounds[3]).all()
    else:  # a half-plane: three infinite bounds, the upper bound of one axis finite
        assert (np.isinf(boxes).sum(axis=1) == 3).all()
        assert np.isneginf(boxes[:, [0, 2]]).all()
        assert np.isfinite(boxes[:, 1]).any() and np.isfinite(boxes[:, 3]).any()


def test_fixed_box_forest_learns_box_counts_better_than_grid_extra_trees():
    X, y = make_box_regression(4000, random_state=0)
    X_test, y_test = make_box_regression(2000, random_state=1)
    forest = thesis_forest(n_estimators=20, test_type="fixed", test_width=1.0,
                                    n_jobs=2, random_state=0).fit(X, y)
    ours = r2_score(y_test, forest.predict(X_test))
    grid = GridCounts(10).fit(X)
    et = ExtraTreesRegressor(n_estimators=20, min_samples_split=30, n_jobs=2, random_state=0)
    theirs = r2_score(y_test, et.fit(grid.transform(X), y).predict(grid.transform(X_test)))
    assert ours >= 0.85
    assert ours > theirs
    # the forest attends to coins and enemies (types 0 and 1), not to the distractors
    importances = forest.feature_importances_
    assert importances[:2].sum() > 0.8 and np.isclose(importances.sum(), 1.0)


def test_same_seed_same_forest_whatever_n_jobs_and_after_pickling():
    X, y = make_box_regression(600, random_state=0)
    X_new, _ = make_box_regression(300, random_state=1)
    params = dict(n_estimators=6, n_tests=50, min_samples_split=10, random_state=42)
    serial = thesis_forest(n_jobs=1, **params).fit(X, y)
    threaded = thesis_forest(n_jobs=2, **params).fit(X, y)
    expected = serial.predict(X_new)
    np.testing.assert_array_equal(threaded.predict(X_new), expected)
    np.testing.assert_array_equal(pickle.loads(pickle.dumps(threaded)).predict(X_new), expected)
    other = thesis_forest(n_jobs=1, **{**params, "random_state": 43}).fit(X, y)
    assert not np.array_equal(other.predict(X_new), expected)


@pytest.mark.parametrize("n", [1, 63, 64, 128, 129, 400, 5000])
@pytest.mark.parametrize("n_jobs", [2, 3, -1])
def test_parallel_predict_equals_serial_predict(n, n_jobs):
    # batches of a few hundred samples (one per env of a vector env) are split over threads too
    X, y = make_box_regression(500, random_state=0)
    X_new, _ = make_box_regression(n, random_state=1)
    forest = thesis_forest(n_estimators=4, n_tests=20, random_state=0).fit(X, y)
    serial, leaves = forest.predict(X_new), forest.apply(X_new)
    forest.set_params(n_jobs=n_jobs)
    np.testing.assert_array_equal(forest.predict(X_new), serial)
    np.testing.assert_array_equal(forest.apply(X_new), leaves)


def test_a_forest_in_a_pool_thread_predicts_on_its_share_of_the_cores(monkeypatch):
    # in the one thread of a pool working beside the calling thread, n_jobs=2 is one
    # thread: the caller's own
    X, y = make_box_regression(500, random_state=0)
    forest = thesis_forest(n_estimators=4, n_tests=20, n_jobs=2, random_state=0).fit(X, y)
    expected = forest.predict(X)

    def no_pool(*args):
        raise AssertionError("predicted on threads of its own")

    monkeypatch.setattr(boxtrees._threads, "thread_pool", no_pool)
    in_pool = thread_pool(1, "test-share").submit(forest.predict, X).result()
    np.testing.assert_array_equal(in_pool, expected)
    with pytest.raises(AssertionError, match="threads of its own"):
        forest.predict(X)           # outside a pool: 2 threads, the caller and one more


def test_side_by_side_runs_the_first_task_in_the_calling_thread_each_on_its_share():
    import threading

    from joblib import effective_n_jobs

    def task():
        return threading.current_thread(), threads_for(-1)

    results = boxtrees._threads.side_by_side([task] * 3, "test-side", n_threads=4)
    threads = [thread for thread, _ in results]
    assert threads[0] is threading.current_thread()
    assert all(thread is not threading.current_thread() for thread in threads[1:])
    assert [share for _, share in results] == [max(effective_n_jobs(-1) // 4, 1)] * 3
    assert threads_for(-1) == effective_n_jobs(-1)   # the calling thread's share is restored
    with pytest.raises(ValueError, match="3 tasks side by side need as many threads"):
        boxtrees._threads.side_by_side([task] * 3, "test-side", n_threads=2)


def test_a_forests_trees_walk_their_share_of_its_pack():
    X, y = make_box_regression(300, random_state=0)
    forest = thesis_forest(n_estimators=4, n_tests=50, random_state=0).fit(X, y)
    assert sum(tree._packed.n_chains for tree in forest.estimators_) == forest._packed.n_chains
    leaves = forest.apply(X)
    for k, tree in enumerate(forest.estimators_):
        alone = pickle.loads(pickle.dumps(tree))    # unpickled: packed on its own
        np.testing.assert_array_equal(tree.apply(X), leaves[:, k])
        np.testing.assert_array_equal(tree.predict(X), alone.predict(X))
    for k in (-1, 4):
        with pytest.raises(IndexError, match=f"tree {k} of a forest of 4 trees"):
            forest._packed.tree(k)


def test_threads_for_follows_joblib_whatever_it_remembers():
    from joblib import effective_n_jobs, parallel_config

    for n_jobs in (-1, -2, None, 1, 3):
        assert threads_for(n_jobs) == max(effective_n_jobs(n_jobs), 1)
    with parallel_config(n_jobs=3):          # joblib's default n_jobs (None) changes
        assert threads_for(None) == effective_n_jobs(None) == 3
    with parallel_config(backend="sequential"):
        assert threads_for(-1) == effective_n_jobs(-1) == 1
    assert threads_for(None) == 1 and threads_for(-1) == effective_n_jobs(-1)


def test_predictions_of_any_batch_size_share_one_pool():
    # one pool per thread count, not one per number of chunks a batch makes
    X, y = make_box_regression(512, random_state=0)
    forest = thesis_forest(n_estimators=2, n_tests=10, n_jobs=8, random_state=0).fit(X, y)
    before = set(boxtrees._threads._POOLS)
    for n in range(128, 513, 64):
        forest.predict(X[:n])
    assert set(boxtrees._threads._POOLS) - before <= {("boxtrees-predict", 7)}
    assert ("boxtrees-predict", 7) in boxtrees._threads._POOLS


@pytest.mark.skipif(not hasattr(os, "fork"), reason="needs os.fork")
def test_a_child_forked_from_a_pool_thread_belongs_to_no_pool():
    in_pool = thread_pool(2, "test-fork").submit(lambda: (
        threads_for(2), run_in_fork(lambda: threads_for(2) == 2))).result()
    assert in_pool == (1, True)


def test_a_failed_chunk_returns_only_after_the_other_chunks():
    # the caller's own chunk fails; the pool's chunk, still writing into the output, must
    # have finished when the error reaches the caller
    X, y = make_box_regression(500, random_state=0)
    forest = thesis_forest(n_estimators=4, n_tests=20, n_jobs=2, random_state=0).fit(X, y)
    finished = []

    def kernel(packed, data, offsets, out):
        if offsets[0] == 0:
            raise RuntimeError("first chunk")
        time.sleep(0.2)
        finished.append(len(out))
        return RowProblem.OK, -1

    with pytest.raises(RuntimeError, match="first chunk"):
        forest._traverse(X, kernel, lambda n: np.empty(n), n_jobs=2)
    assert finished == [250]


@pytest.mark.skipif(not hasattr(os, "fork"), reason="needs os.fork")
def test_a_forked_child_predicts_on_threads_of_its_own():
    X, y = make_box_regression(500, random_state=0)
    forest = thesis_forest(n_estimators=4, n_tests=20, n_jobs=2, random_state=0).fit(X, y)
    expected = forest.predict(X)  # the parent's prediction threads exist before the fork
    assert run_in_fork(lambda: np.array_equal(forest.predict(X), expected))


def test_dask_backend_builds_the_same_forest():
    distributed = pytest.importorskip("dask.distributed")
    X, y = make_box_regression(400, random_state=0)
    params = dict(n_estimators=4, n_tests=30, min_samples_split=10, random_state=7)
    expected = thesis_forest(**params).fit(X, y).predict(X)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, distributed.Client(cluster):
        with joblib.parallel_backend("dask"):
            forest = thesis_forest(n_jobs=-1, **params).fit(X, y)
            got = forest.predict(X)
    np.testing.assert_array_equal(got, expected)


def test_input_forms_give_identical_forests():
    rng = np.random.default_rng(3)
    sets = random_sets(rng, 200)
    y = rng.normal(size=200)
    params = dict(n_estimators=3, n_tests=20, min_samples_split=5, random_state=0)
    from_list = thesis_forest(**params).fit(sets, y)
    packed = ObjectSets.from_sequence(sets)
    from_packed = thesis_forest(**params).fit(packed, y)
    np.testing.assert_array_equal(from_list.predict(packed), from_packed.predict(sets))
    # a 3D array may hold padding: it needs its mask, through ObjectSets.from_padded
    cube = rng.uniform(-5, 5, (50, 4, 3))
    cube[:, :, 2] = rng.integers(0, 3, (50, 4))
    with pytest.raises(ValueError, match=r"3D array.*ObjectSets\.from_padded\(X, mask\)"):
        from_list.predict(cube)
    mask = rng.random((50, 4)) < 0.7
    np.testing.assert_array_equal(from_list.predict(ObjectSets.from_padded(cube, mask)),
                                  from_list.predict([c[m] for c, m in zip(cube, mask)]))


def test_integer_weights_act_as_repeated_samples_in_fully_grown_trees():
    # min_samples_split counts samples, as in scikit-learn: repeating a sample k times and
    # giving it weight k then grow the same trees only when nodes split down to 2 samples
    rng = np.random.default_rng(4)
    sets = random_sets(rng, 150)
    y = rng.normal(size=150)
    weights = rng.integers(0, 4, 150)
    params = dict(n_estimators=3, n_tests=20, min_samples_split=2, random_state=0)
    weighted = thesis_forest(**params).fit(sets, y, sample_weight=weights)
    repeated = thesis_forest(**params).fit(
        [s for s, w in zip(sets, weights) for _ in range(w)], np.repeat(y, weights)
    )
    np.testing.assert_allclose(weighted.predict(sets), repeated.predict(sets), rtol=1e-10)


@pytest.mark.parametrize("min_samples_split", [10, 0.05])
def test_trees_do_not_depend_on_the_scale_of_the_weights(min_samples_split):
    rng = np.random.default_rng(6)
    sets = random_sets(rng, 300)
    y = rng.normal(size=300)
    weights = rng.uniform(0.5, 2.0, 300)
    params = dict(n_estimators=3, n_tests=20, min_samples_split=min_samples_split, random_state=0)
    reference = thesis_forest(**params).fit(sets, y, sample_weight=weights)
    halved = thesis_forest(**params).fit(sets, y, sample_weight=0.5 * weights)
    normalised = thesis_forest(**params).fit(sets, y, sample_weight=weights / weights.sum())
    for other in (halved, normalised):
        for a, b in zip(trees_of(reference), trees_of(other)):
            np.testing.assert_array_equal(a.children_left, b.children_left)
            np.testing.assert_array_equal(a.box, b.box)
        np.testing.assert_allclose(other.predict(sets), reference.predict(sets), rtol=1e-9)
    assert min(t.node_count for t in trees_of(reference)) > 20


def test_min_samples_split_counts_samples_or_a_fraction_of_them():
    from sklearn.datasets import load_diabetes

    X, y = load_diabetes(return_X_y=True)
    w = np.random.default_rng(0).uniform(0.5, 1.5, len(y))
    # fully grown trees fit the training data whatever the scale of the weights
    forest = thesis_forest(n_estimators=3, min_samples_split=2, test_type="classic",
                                    random_state=0)
    assert forest.fit(X, y, sample_weight=w / w.sum()).score(X, y) > 0.999
    # a node of fewer than 0.1 * 442 = 44.2 samples (45, rounded up) is a leaf
    params = dict(n_estimators=2, test_type="classic", random_state=0)
    fraction = thesis_forest(min_samples_split=0.1, **params).fit(X, y)
    count = thesis_forest(min_samples_split=45, **params).fit(X, y)
    for tree, same in zip(trees_of(fraction), trees_of(count)):
        inner = tree.children_left != -1
        assert tree.n_node_samples[inner].min() >= 45 and inner.sum() > 5
        np.testing.assert_array_equal(tree.children_left, same.children_left)


def test_constant_target_and_objectless_data_give_single_leaf_trees():
    forest = thesis_forest(n_estimators=2).fit([np.empty((0, 3))] * 50, np.arange(50.0))
    assert all(t.node_count == 1 for t in trees_of(forest))
    np.testing.assert_allclose(forest.predict([np.array([[0.0, 0.0, 0]])]), 24.5)
    rng = np.random.default_rng(5)
    forest = thesis_forest(n_estimators=2).fit(random_sets(rng, 60), np.full(60, 3.0))
    assert all(t.node_count == 1 for t in trees_of(forest))


def test_max_depth_limits_trees():
    X, y = make_box_regression(500, random_state=0)
    forest = thesis_forest(n_estimators=3, max_depth=3, min_samples_split=2, random_state=0).fit(X, y)
    assert max(t.max_depth for t in trees_of(forest)) == 3


def _objects_of_four_attributes(n, seed=0):
    """Sets of up to 40 objects ``[a_0, ..., a_3, type]``, the target depending on all four
    attributes: the default column groups then include boxes over three attributes."""
    rng = np.random.default_rng(seed)
    X = [np.column_stack([rng.uniform(-5, 5, (k, 4)), rng.integers(0, 3, k)]).astype(np.float32)
         for k in rng.integers(0, 41, n)]
    y = np.array([((x[:, 4] == 0) & (np.abs(x[:, :2]).max(axis=1) < 2) & (x[:, 2] > 0)
                   & (x[:, 3] < 1)).sum() for x in X], dtype=float)
    return X, y + rng.normal(0, 0.1, n)


@pytest.mark.parametrize("lanes", KERNEL_WIDTHS.values(), ids=KERNEL_WIDTHS)
@pytest.mark.parametrize("d", [2, 4])
def test_simd_and_portable_kernels_grow_identical_trees(d, lanes):
    from boxtrees import _splitter

    X, y = make_box_regression(1500, random_state=0) if d == 2 else _objects_of_four_attributes(1500)
    params = dict(n_estimators=3, n_tests=50, min_samples_split=10, random_state=0)
    if d == 4:  # the defaults' column groups and refined tests
        params = dict(params, column_groups=None, refine_tests=True)
    try:
        _splitter._set_simd(1)
        portable = thesis_forest(test_type="random", **params).fit(X, y)
        _use_kernels(_splitter, lanes)
        simd = thesis_forest(test_type="random", **params).fit(X, y)
    finally:
        _splitter._set_simd()
    if d == 4:  # some boxes bound three attributes (the kernel that reads attribute rows)
        assert any((np.isfinite(t.box[t.children_left >= 0]).sum(axis=1) > 4).any()
                   for t in trees_of(simd))
    for a, b in zip(trees_of(portable), trees_of(simd)):
        np.testing.assert_array_equal(a.children_left, b.children_left)
        np.testing.assert_array_equal(a.box, b.box)
        np.testing.assert_array_equal(a.value, b.value)


def test_the_forest_is_a_sequence_of_tree_estimators_as_in_scikit_learn():
    from sklearn.base import clone

    X, y = make_box_regression(400, random_state=0)
    X_new, _ = make_box_regression(50, random_state=1)
    forest = thesis_forest(n_estimators=4, n_tests=30, min_samples_split=10,
                                    random_state=0).fit(X, y)
    assert len(forest) == 4 and list(forest) == forest.estimators_ and forest[-1] is forest.estimators_[3]
    np.testing.assert_allclose(np.mean([tree.predict(X_new) for tree in forest], axis=0),
                               forest.predict(X_new), rtol=1e-12)
    np.testing.assert_array_equal(np.column_stack([tree.apply(X_new) for tree in forest]),
                                  forest.apply(X_new))
    # a tree refitted from its own parameters (random_state included) is the same tree
    again = clone(forest[2]).fit(X, y)
    np.testing.assert_array_equal(again.tree_.box, forest[2].tree_.box)
    np.testing.assert_array_equal(again.predict(X_new), forest[2].predict(X_new))


def test_decision_path_holds_the_nodes_from_the_root_to_the_leaf():
    X, y = make_box_regression(300, random_state=0)
    forest = thesis_forest(n_estimators=3, n_tests=20, min_samples_split=10,
                                    random_state=0).fit(X, y)
    indicator, ptr = forest.decision_path(X[:40])
    leaves = forest.apply(X[:40])
    assert indicator.shape == (40, ptr[-1]) and ptr.tolist() == np.cumsum(
        [0] + [t.tree_.node_count for t in forest]).tolist()
    for k, estimator in enumerate(forest):
        tree, own = estimator.tree_, estimator.decision_path(X[:40]).toarray()
        np.testing.assert_array_equal(own, indicator[:, ptr[k]:ptr[k + 1]].toarray())
        depth = tree.node_depth()
        for i, leaf in enumerate(leaves[:, k]):
            path = np.flatnonzero(own[i])
            assert path[0] == 0 and path[-1] == leaf and len(path) == depth[leaf] + 1
            # each node on the path is the parent of the next
            assert all(nxt in (tree.children_left[node], tree.children_right[node])
                       for node, nxt in zip(path[:-1], path[1:]))


def test_random_tests_skip_constant_columns_and_columns_of_noise_width():
    rng = np.random.default_rng(0)
    X = np.zeros((300, 1001))
    X[:, 500] = rng.normal(size=300)
    y = 3 * X[:, 500]
    # one test per node: a draw on any of the 1000 constant columns would make a leaf
    forest = thesis_forest(3, n_tests=1, max_retries=0, test_type="classic",
                                    min_samples_split=2, random_state=0).fit(X, y)
    assert forest.score(X, y) > 0.999
    assert {int(t) for e in forest for t in e.tree_.object_type if t >= 0} == {500}
    # a column whose range is below 1e-7 is constant, as in scikit-learn's trees
    X = np.column_stack([rng.uniform(0, 5e-8, 300), rng.normal(size=300)])
    forest = thesis_forest(3, n_tests=5, test_type="classic", min_samples_split=2,
                                    random_state=0).fit(X, X[:, 0] * 1e7 + X[:, 1])
    assert all(0 not in e.tree_.object_type for e in forest)
