"""Drive every Cython kernel of boxtrees, SIMD and portable, through edge cases.

Run under valgrind by test_boxtrees_memcheck.py and on an AddressSanitizer build by
test_boxtrees_asan.py; both fail on any invalid read or write in boxtrees code.

Imports only NumPy and the extension modules (not scikit-learn), to stay fast under valgrind.
"""
import importlib
import sys
import types
from types import SimpleNamespace
from pathlib import Path

import numpy as np

# load boxtrees' extension modules without running the package __init__ (scikit-learn)
package = types.ModuleType("boxtrees")
package.__path__ = [str(Path(__file__).resolve().parents[1] / "boxtrees")]
sys.modules["boxtrees"] = package
_builder = importlib.import_module("boxtrees._builder")
_predictor = importlib.import_module("boxtrees._predictor")
_rows = importlib.import_module("boxtrees._rows")
_tree = importlib.import_module("boxtrees._tree")
_NODE_ARRAYS = _builder.NODE_FIELDS


def grow(objects, target, weight, test_type, width=0.7, n_tests=20, seed=0, refine=False):
    """One tree from the builder, with small parameters."""
    params = SimpleNamespace(test_type=test_type, test_width=width, n_tests=n_tests,
                             min_samples_split=2, max_depth=-1, max_retries=2,
                             refine_tests=refine)
    return _builder.build_tree(objects, target, weight, params, seed)


def training_arrays(rng, n, per_sample, n_types, n_bands, spread):
    """Random objects (``per_sample`` each, or 0 to ``-per_sample`` if negative), indexed the
    way BoxExtraTreesRegressor does."""
    sizes = np.full(n, per_sample) if per_sample >= 0 else rng.integers(0, 1 - per_sample, n)
    data = np.column_stack([rng.uniform(-spread, spread, (sizes.sum(), 2)),
                            rng.integers(0, n_types, sizes.sum())]).astype(np.float32)
    offsets = np.concatenate([[0], np.cumsum(sizes)]).astype(np.intp)
    sample = np.repeat(np.arange(n), sizes).astype(np.int32)
    edges = np.concatenate([[-np.inf], np.linspace(-1, 1, n_bands + 1)[1:-1], [np.inf]])
    bands = np.searchsorted(edges[1:-1], data[:, 1], side="right")
    segments = data[:, 2].astype(np.intp) * n_bands + bands
    order = np.lexsort((data[:, 0], segments))
    segment_ptr = np.searchsorted(segments[order], np.arange(n_types * n_bands + 1)).astype(np.intp)
    return (data, offsets, np.ascontiguousarray(data[order, 0]), np.ascontiguousarray(data[order, 1]),
            sample[order], segment_ptr, edges)


def main():
    rng = np.random.default_rng(0)
    for case, (n, per_sample, n_types, n_bands, spread) in enumerate(
        # boxes hitting every sample (several times), ragged sets, no objects, objects outside
        # the bounds, two samples, more objects of a type than a SIMD step takes (16) and
        # segments long enough to be searched
        [(40, 6, 1, 1, 0.5), (60, -12, 3, 4, 1.0), (30, 0, 2, 3, 1.0), (50, -3, 4, 8, 5.0),
         (2, 1, 1, 1, 1.0), (40, -60, 2, 2, 1.0)]
    ):
        data, offsets, x, y, sample, segment_ptr, edges = training_arrays(
            rng, n, per_sample, n_types, n_bands, spread)
        target, weight = rng.normal(size=n), rng.uniform(0.5, 2, n)
        bounds = np.tile(np.array([-1, 1, -1, 1], dtype=np.float32), (n_types, 1))
        for test_type in ("random", "fixed", "bounded", "classic"):
            for simd in (True, False):
                _builder._set_simd(simd)
                _predictor._set_simd(simd)
                # one output, then two (multi-output sums)
                targets = target if seed_outputs(case) == 1 else np.column_stack([target, weight])
                objects = SimpleNamespace(x=x, y=y, sample_of=sample, segment_ptr=segment_ptr,
                                          band_edges=edges, bounds=bounds)
                # refined tests on the first tree; zero weights drop samples in the third
                some_zero = weight * (np.arange(n) % 3 != 1)
                trees = [_tree.BoxTree(**grow(objects, targets, some_zero if seed == 2 else weight,
                                              test_type, seed=seed, refine=seed == 0))
                         for seed in range(3)]
                forest = _predictor.PackedForest(trees, np.arange(n_types))
                out = np.empty((n, forest.n_outputs))
                assert _predictor.predict_mean(forest, data, offsets, out) == (0, -1)
                leaves = np.empty((n, 3), dtype=np.intp)
                assert _predictor.apply_leaves(forest, data, offsets, leaves) == (0, -1)
                corrupted_inputs(forest, trees, data, offsets)
            assert _rows.scan_rows(data, 3e38, 2**24)[0] == 0, case
    # a feature matrix, read in place whatever its strides: the column splitter
    n, n_features = 80, 3
    values = rng.normal(size=(n, 2 * n_features)).astype(np.float32)
    bounds = np.tile(np.array([0, 0, -np.inf, np.inf], dtype=np.float32), (n_features, 1))
    for columns in (values[:, :n_features], values[::-1, ::2], np.asfortranarray(values[:, 1::2])):
        for test_type in ("classic", "random", "fixed"):
            for local_x in (True, False):
                for targets in (rng.normal(size=n), rng.normal(size=(n, 3))):
                    for refine in (False, True):
                        weight = rng.integers(0, 3, n).astype(float)  # zeros drop samples
                        grow(SimpleNamespace(columns=columns, bounds=bounds, local_x=local_x),
                             targets, weight, test_type, width=0.3, n_tests=300, seed=1,
                             refine=refine)
    print("kernels ok")


def seed_outputs(case):
    """Number of target columns of a case: even cases have one, odd ones two."""
    return 1 + case % 2


def corrupted_inputs(forest, trees, data, offsets):
    """Inputs a validated batch or tree may turn into: each kernel reports them (a problem
    code, or a ValueError), and reads or writes nothing outside its arrays."""
    n = len(offsets) - 1
    out = np.empty((n, forest.n_outputs))
    rows = data.copy()
    if len(rows):
        rows[len(rows) // 2, 2] = -1000.0
        assert _predictor.predict_mean(forest, rows, offsets, out)[0] != 0
        rows[len(rows) // 2, 2] = 2.0 ** 30       # an id no tree tests: not a problem
        assert _predictor.predict_mean(forest, rows, offsets, out)[0] == 0
    for bad in ([0, len(data) + 1], [-1, 0], [0, 1, 0] if len(data) else [1, 0]):
        bad = np.array(bad, dtype=np.intp)
        assert _predictor.predict_mean(forest, data, bad,
                                       np.empty((len(bad) - 1, forest.n_outputs)))[0] != 0
    raised = 0
    for change in ({"children_left": 10**6}, {"children_left": 0}, {"object_type": 99},
                   {"threshold": 2**40}, {"box": np.nan}, {"value": np.inf}):
        arrays = {name: np.array(getattr(trees[0], name)) for name in _NODE_ARRAYS}
        (name, value), = change.items()
        arrays[name] = arrays[name].astype(np.float64 if name in ("box", "value") else np.int64)
        arrays[name][0] = value
        try:
            _predictor.PackedForest([_tree.BoxTree(**arrays)], np.arange(4))
        except ValueError:
            raised += 1
    # a single-leaf tree has no inner node whose test or children could be bad
    assert raised == 6 or trees[0].node_count == 1, raised
    sample = np.array(trees[0].children_left)   # not a sample id: out of range for some
    try:
        zeros = np.zeros(len(sample), np.float32)
        grow(SimpleNamespace(x=zeros, y=zeros, sample_of=sample, segment_ptr=[0, len(sample)],
                             band_edges=[-np.inf, np.inf], bounds=np.zeros((1, 4), np.float32)),
             np.zeros(2), np.ones(2), "fixed")
    except ValueError:
        pass
    else:
        raise AssertionError("build_tree accepted sample ids out of range")


if __name__ == "__main__":
    main()
