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
_layout = importlib.import_module("boxtrees._layout")
_splitter = importlib.import_module("boxtrees._splitter")
_predictor = importlib.import_module("boxtrees._predictor")
_rows = importlib.import_module("boxtrees._rows")
_tree = importlib.import_module("boxtrees._tree")
_index = importlib.import_module("boxtrees._index")
_NODE_ARRAYS = _tree._FIELDS


def grow(objects, target, weight, test_type, n_tests=20, seed=0, refine=False):
    """One tree from the builder, with small parameters."""
    params = SimpleNamespace(test_type=test_type, n_tests=n_tests,
                             min_samples_split=2, max_depth=-1, max_retries=2,
                             refine_tests=refine)
    return _builder.build_tree(objects, target, weight, params, seed)


def training_arrays(rng, n, per_sample, n_types, n_bands, spread, groups):
    """Random objects of ``1 + max column`` attributes (``per_sample`` each, or 0 to
    ``-per_sample`` if negative), indexed the way BoxExtraTreesRegressor does: one copy per
    column group (its x and y columns; a group of one column has one band)."""
    d = 1 + max(max(g) for g in groups)
    sizes = np.full(n, per_sample) if per_sample >= 0 else rng.integers(0, 1 - per_sample, n)
    data = np.column_stack([rng.uniform(-spread, spread, (sizes.sum(), d)),
                            rng.integers(0, n_types, sizes.sum())]).astype(np.float32)
    offsets = np.concatenate([[0], np.cumsum(sizes)]).astype(np.intp)
    sample = np.repeat(np.arange(n), sizes).astype(np.int32)
    edges = np.concatenate([[-np.inf], np.linspace(-1, 1, n_bands + 1)[1:-1], [np.inf]])
    one_band = np.concatenate([[-np.inf], np.full(n_bands, np.inf)])
    band_edges = np.array([edges if len(columns) > 1 else one_band for columns in groups])
    x, y, sample_of, object_of, segment_ptr = _index.index_segments(
        data, sample, data[:, d].astype(np.intp), groups, n_types, band_edges)
    width = _layout.MAX_GROUP_COLUMNS
    bounds = np.tile(np.array([-1, 1] * width, dtype=np.float32), (len(groups) * n_types, 1))
    extra = np.full((len(groups), width - 2), -1)
    for g, columns in enumerate(groups):
        if len(columns) == 1:
            bounds[g * n_types:(g + 1) * n_types, 2:4] = [-np.inf, np.inf]
        extra[g, :max(len(columns) - 2, 0)] = columns[2:]
    objects = SimpleNamespace(x=x, y=y, sample_of=sample_of, segment_ptr=segment_ptr,
                              band_edges=band_edges, bounds=bounds,
                              half_widths=np.full((len(bounds), width), 0.7),
                              group_sizes=[len(columns) for columns in groups],
                              attributes=np.ascontiguousarray(data[:, :d]),
                              object_of=object_of, extra_columns=extra)
    return data, offsets, objects


def main():
    rng = np.random.default_rng(0)
    xy = ((0, 1),)
    # every kernel width this CPU runs: AVX-512 (16 lanes), AVX2 (8), portable (1)
    widths = sorted({_splitter._set_simd(lanes) for lanes in (16, 8, 1)}, reverse=True)
    for case, (n, per_sample, n_types, n_bands, spread, groups) in enumerate(
        # boxes hitting every sample (several times), ragged sets, no objects, objects outside
        # the bounds, two samples, more objects of a type than a SIMD step takes (16) and
        # segments long enough to be searched; objects of 3, 1 and 6 attributes; refined
        # edges with candidates enough for the radix sort (256)
        [(40, 6, 1, 1, 0.5, xy), (60, -12, 3, 4, 1.0, xy), (30, 0, 2, 3, 1.0, xy),
         (50, -3, 4, 8, 5.0, xy), (2, 1, 1, 1, 1.0, xy), (40, -60, 2, 2, 1.0, xy),
         (50, -20, 3, 4, 1.0, ((0, 1), (2,))), (40, -30, 2, 2, 1.0, ((0,),)),
         (30, -40, 2, 3, 1.0, ((0, 1), (2, 5), (4,), (3,))),
         (40, -40, 2, 2, 1.0, ((0, 1, 2), (3,))), (30, -30, 3, 1, 1.0, ((4, 1, 0, 2, 3),)),
         (100, 40, 1, 2, 1.0, xy)]
    ):
        data, offsets, objects = training_arrays(rng, n, per_sample, n_types, n_bands, spread,
                                                 groups)
        d = data.shape[1] - 1
        target, weight = rng.normal(size=n), rng.uniform(0.5, 2, n)
        for test_type in ("random", "fixed", "bounded", "classic"):
            for lanes in widths:
                _splitter._set_simd(lanes)
                _predictor._set_simd(lanes)
                # one output, then two (multi-output sums)
                targets = target if seed_outputs(case) == 1 else np.column_stack([target, weight])
                # refined tests on the first tree; zero weights drop samples in the third
                some_zero = weight * (np.arange(n) % 3 != 1)
                trees = [_tree.BoxTree.from_builder(
                    grow(objects, targets, some_zero if seed == 2 else weight, test_type,
                         seed=seed, refine=seed == 0), np.arange(n_types), groups, d)
                         for seed in range(3)]
                forest = _predictor.PackedForest(trees, np.arange(n_types))
                out = np.empty((n, forest.n_outputs))
                assert _predictor.predict_mean(forest, data, offsets, out) == (0, -1)
                leaves = np.empty((n, 3), dtype=np.intp)
                assert _predictor.apply_leaves(forest, data, offsets, leaves) == (0, -1)
                for k in range(3):      # each tree alone, on its share of the forest's arrays
                    alone = np.empty((n, 1), dtype=np.intp)
                    assert _predictor.apply_leaves(forest.tree(k), data, offsets, alone) == (0, -1)
                    assert (alone[:, 0] == leaves[:, k]).all()
                corrupted_inputs(forest, trees, data, offsets)
            assert _rows.scan_rows(data, 3e38, 2**24)[0] == 0, case
    # a feature matrix, read in place whatever its strides: the column splitter
    n, n_features = 80, 3
    values = rng.normal(size=(n, 2 * n_features)).astype(np.float32)
    width = _layout.MAX_GROUP_COLUMNS
    bounds = np.zeros((n_features, 2 * width), dtype=np.float32)
    bounds[:, 2:4] = [-np.inf, np.inf]
    half = np.full((n_features, width), 0.3)
    for columns in (values[:, :n_features], values[::-1, ::2], np.asfortranarray(values[:, 1::2])):
        for test_type in ("classic", "random", "fixed"):
            for local_x in (True, False):
                for targets in (rng.normal(size=n), rng.normal(size=(n, 3))):
                    for refine in (False, True):
                        weight = rng.integers(0, 3, n).astype(float)  # zeros drop samples
                        grow(SimpleNamespace(columns=columns, bounds=bounds, local_x=local_x,
                                             half_widths=half, group_sizes=[1]),
                             targets, weight, test_type, n_tests=300, seed=1, refine=refine)
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
    d = data.shape[1] - 1
    if len(rows):
        rows[len(rows) // 2, d] = -1000.0
        assert _predictor.predict_mean(forest, rows, offsets, out)[0] != 0
        rows[len(rows) // 2, d] = 2.0 ** 30       # an id no tree tests: not a problem
        assert _predictor.predict_mean(forest, rows, offsets, out)[0] == 0
        rows[len(rows) // 3, d - 1] = np.nan      # the last attribute
        assert _predictor.predict_mean(forest, rows, offsets, out)[0] != 0
    for bad in ([0, len(data) + 1], [-1, 0], [0, 1, 0] if len(data) else [1, 0]):
        bad = np.array(bad, dtype=np.intp)
        assert _predictor.predict_mean(forest, data, bad,
                                       np.empty((len(bad) - 1, forest.n_outputs)))[0] != 0
    raised = 0
    changes = [{"children_left": 10**6}, {"children_left": 0}, {"object_type": 99},
               {"threshold": 2**40}, {"box": np.nan}, {"value": np.inf}]
    for change in changes:
        arrays = {name: np.array(getattr(trees[0], name)) for name in _NODE_ARRAYS}
        (name, value), = change.items()
        arrays[name] = arrays[name].astype(np.float64 if name in ("box", "value") else np.int64)
        arrays[name][0] = value
        try:
            _predictor.PackedForest([_tree.BoxTree(**arrays)], np.arange(4))
        except ValueError:
            raised += 1
    # a single-leaf tree has no inner node whose test or children could be bad
    assert raised == len(changes) or trees[0].node_count == 1, raised
    sample = np.array(trees[0].children_left)   # not a sample id: out of range for some
    try:
        zeros = np.zeros(len(sample), np.float32)
        grow(SimpleNamespace(x=zeros, y=zeros, sample_of=sample, segment_ptr=[0, len(sample)],
                             band_edges=[[-np.inf, np.inf]],
                             bounds=np.zeros((1, 2 * _layout.MAX_GROUP_COLUMNS), np.float32),
                             half_widths=np.ones((1, _layout.MAX_GROUP_COLUMNS)),
                             group_sizes=[1]),
             np.zeros(2), np.ones(2), "fixed")
    except ValueError:
        pass
    else:
        raise AssertionError("build_tree accepted sample ids out of range")


if __name__ == "__main__":
    main()
