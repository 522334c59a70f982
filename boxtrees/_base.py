"""What the box-test tree estimators share: parameters, growing trees, walking them, and the
encoding of regression and classification targets."""
from __future__ import annotations

import inspect
import warnings
from collections.abc import Mapping
from dataclasses import dataclass
from functools import partial
from math import ceil
from numbers import Integral, Real

import numpy as np
from scipy.sparse import csr_matrix
from sklearn.base import BaseEstimator, ClassifierMixin, RegressorMixin
from sklearn.utils._param_validation import Interval, RealNotInt, StrOptions
from sklearn.utils.class_weight import compute_class_weight, compute_sample_weight
from sklearn.utils.multiclass import check_classification_targets
from sklearn.utils.validation import _check_sample_weight, check_is_fitted

from ._index import index_segments
from ._layout import MAX_GROUP_COLUMNS
from ._objects import (_FLOAT32_MAX, ObjectInputMixin, check_view_bounds, columns_of,
                       fitted_region, row_error)
from ._predictor import PackedForest, apply_leaves, predict_mean
from ._rows import RowProblem
from ._splitter import TEST_KINDS
from ._threads import side_by_side, threads_for
from ._typing import SetsOrMatrix

# prediction splits a batch into chunks of at least this many samples, one per thread,
# the calling thread's and those of the pool of this purpose
_PREDICT_CHUNK_MIN = 64
_PREDICT_POOL = "boxtrees-predict"
# y bands of the training-object index: at most this many, this many for large boxes
_MAX_BANDS = 32
_DEFAULT_BANDS = 8
# counts, ids and loop bounds of the Cython core are 32-bit
_INT32_MAX = 2**31 - 1
# targets whose largest magnitude is from this on (below its inverse) have squares, the node
# variances, that overflow (underflow) float64
_Y_MAX = 2.0**511
# the sampling region drawn from the training objects reaches this share of their extent
# beyond them, on every side
_REGION_MARGIN = 0.05


class BaseBoxTrees(ObjectInputMixin, BaseEstimator):
    """Parameters, fitting and traversal shared by a box-test tree and a forest of them.

    Fitting sets ``types_`` (the sorted type ids seen, or the column indices of a feature
    matrix), ``n_types_``, ``n_attributes_``, ``column_groups_``, ``bounds_`` and the private
    ``_packed`` form the traversal reads (rebuilt, and so validated again, when unpickled).
    """

    _parameter_constraints = {
        "n_tests": [Interval(Integral, 1, _INT32_MAX, closed="both")],
        "min_samples_split": [
            Interval(Integral, 2, None, closed="left"),
            Interval(RealNotInt, 0.0, 1.0, closed="right"),
        ],
        "test_type": [StrOptions(set(TEST_KINDS))],
        "test_width": [Interval(Real, 0, None, closed="neither")],
        "max_retries": [Interval(Integral, 0, _INT32_MAX, closed="both")],
        "refine_tests": ["boolean"],
        "max_depth": [Interval(Integral, 0, _INT32_MAX, closed="both"), None],
        "view_bounds": ["array-like", Interval(Real, 0, None, closed="neither"), dict, None],
        "column_groups": [list, tuple, None],
        "relative_width": ["boolean"],
    }

    def _fit_data(self, X, y, sample_weight, class_weight=None):
        """Validate the training data, set the fitted attributes the trees share and return
        the `_FitData` they grow on; ``class_weight`` (None, "balanced", a dict or a list of
        dicts, as scikit-learn's) multiplies the sample weights."""
        # a feature matrix stays a matrix: its columns are indexed directly
        sets, labels = self._validate_input(X, y, reset=True, requires_y=True, matrix=True)
        y = self._encode_targets(labels)
        # one entry per sample, a plain NumPy array, stands in for X
        sample_weight = _check_sample_weight(
            sample_weight, np.empty(len(sets), np.int8), dtype=np.float64, ensure_non_negative=True
        )
        if class_weight is not None:
            sample_weight = sample_weight * _class_weight_factors(class_weight, labels,
                                                                  sample_weight)
        kept = sample_weight > 0
        if not kept.all():
            sets, y, sample_weight = sets[kept], y[kept], sample_weight[kept]
        if not self._fitted_on_features and not sets.n_objects:
            warnings.warn("X holds no object (every set of positive weight is empty), so "
                          "there is no object to test and every tree is a single leaf, "
                          "predicting the mean target whatever the sets; check that the sets "
                          "hold their objects as rows [f_1, ..., f_d, type]",
                          UserWarning, stacklevel=4)
        if len(sets) > _INT32_MAX - 1:
            raise ValueError(f"at most {_INT32_MAX - 1} samples are supported, got {len(sets)}")
        with np.errstate(over="ignore"):
            total = sample_weight.sum()
        if not np.isfinite(total):
            raise ValueError("sample_weight sums to more than float64 holds (> 1.8e308); only "
                             "the weights' ratios matter: scale them down")
        # trees grow on weights and targets scaled by powers of two, exact in floating point:
        # the same trees, and no overflow in the sums of weight * target^2 whatever their units
        y_exponent, w_exponent = _scale_exponent(y), _scale_exponent(sample_weight)
        split = self.min_samples_split
        params = _TreeParams(
            test_type=self.test_type, n_tests=self.n_tests,
            min_samples_split=split if isinstance(split, Integral) else max(2, ceil(split * len(sets))),
            max_depth=-1 if self.max_depth is None else self.max_depth,
            max_retries=self.max_retries, refine_tests=bool(self.refine_tests),
        )
        objects = _TrainingObjects(self, sets)
        return _FitData(objects=objects, y=np.ldexp(y, y_exponent),
                        sample_weight=np.ldexp(sample_weight, w_exponent),
                        y_exponent=y_exponent, w_exponent=w_exponent, params=params,
                        kept=kept, labels=labels, fitted=self._data_attributes())

    def _data_attributes(self):
        """What fitting has learnt about the training data: every fitted attribute
        (scikit-learn's trailing underscore) but the trees and their out-of-bag estimates,
        and whether the data was a feature matrix."""
        return {name: value for name, value in vars(self).items()
                if (name.endswith("_") and not name.startswith(("_", "oob_"))
                    and name not in ("tree_", "estimators_"))
                or name == "_fitted_on_features"}

    def _node_arrays(self, arrays):
        """The builder's node arrays as the estimator's trees keep them."""
        return arrays

    def _pack(self, trees):
        self._packed = PackedForest(trees, self.types_)

    def _traverse(self, X, kernel, out, n_jobs=None):
        """Validate ``X`` and run a traversal kernel over its samples into ``out(n)``, split
        over up to ``threads_for(n_jobs)`` threads, the calling one among them, in chunks of
        at least `_PREDICT_CHUNK_MIN` samples."""
        if "_packed" not in self.__dict__:  # cheap test first: predict is called per step
            check_is_fitted(self)
        sets, _ = self._validate_input(X, reset=False)
        n = len(sets)
        out = out(n)
        packed = self._packed  # one forest for every chunk, even if another thread refits
        n_chunks = n // _PREDICT_CHUNK_MIN
        if n_chunks > 1:  # threads_for costs as much as predicting one sample
            n_threads = threads_for(n_jobs)
            n_chunks = min(n_threads, n_chunks)
        if n_chunks <= 1:
            results = [kernel(packed, sets.data, sets.offsets, out)]
        else:
            edges = np.linspace(0, n, n_chunks + 1).astype(np.intp)
            results = side_by_side(     # one pool whatever the number of chunks
                [partial(kernel, packed, sets.data, sets.offsets[a : b + 1], out[a:b])
                 for a, b in zip(edges[:-1], edges[1:])], _PREDICT_POOL, n_threads)
        for problem, row in results:
            if problem == RowProblem.BAD_OFFSETS:
                raise ValueError("the offsets of X changed while it was being read")
            if problem != RowProblem.OK:
                raise row_error(problem, row, sets.data, "X changed after it was validated: its rows")
        return out

    def _predict_mean(self, X, n_jobs=None):
        """Mean leaf values over the trees, shape (n_samples, n_outputs of the trees)."""
        n_outputs = self._packed.n_outputs if "_packed" in self.__dict__ else 0
        return self._traverse(X, predict_mean, lambda n: np.empty((n, n_outputs)), n_jobs)

    def _apply(self, X, n_jobs=None):
        n_trees = self._packed.n_trees if "_packed" in self.__dict__ else 0
        return self._traverse(X, apply_leaves, lambda n: np.empty((n, n_trees), dtype=np.intp), n_jobs)

    def _decision_path(self, X, trees, n_jobs=None):
        """Indicator of the nodes each sample passes through, all trees side by side, and the
        column where each tree's nodes start."""
        leaves = self._apply(X, n_jobs)
        starts = np.zeros(len(trees) + 1, dtype=np.intp)
        np.cumsum([tree.node_count for tree in trees], out=starts[1:])
        rows, cols = [], []
        for k, tree in enumerate(trees):
            parent = tree.parents()
            node, sample = leaves[:, k].copy(), np.arange(len(leaves))
            while node.size:        # up from the leaves; ids fall toward the root
                rows.append(sample)
                cols.append(node + starts[k])
                up = parent[node]
                sample, node = sample[up >= 0], up[up >= 0]
        rows, cols = np.concatenate(rows), np.concatenate(cols)
        indicator = csr_matrix((np.ones(len(rows), dtype=np.int8), (rows, cols)),
                               shape=(len(leaves), starts[-1]))
        indicator.sort_indices()
        return indicator, starts

    def __sklearn_is_fitted__(self):
        """Fitted once ``fit`` has grown the trees: a ``fit`` that failed (say, on bad ``y``
        after ``X`` was validated) leaves other fitted attributes, but no trees."""
        return "_packed" in self.__dict__

    def __getstate__(self):
        state = dict(super().__getstate__())  # a copy: object.__getstate__ returns __dict__ itself
        state.pop("_packed", None)
        return state

    def __setstate__(self, state):
        # a pickle from before a parameter existed gets the parameter's default
        defaults = {name: parameter.default for name, parameter
                    in inspect.signature(type(self).__init__).parameters.items()
                    if parameter.default is not inspect.Parameter.empty}
        super().__setstate__({**defaults, **state})
        trees = self._trees()
        if trees is not None:
            self._pack(trees)


def _scale_exponent(values):
    """The exponent ``k`` such that ``values * 2**k`` has its largest magnitude in [1, 2) (0
    for all zeros, and for unit weights: the builder has a faster path for those); applied
    with ``np.ldexp``, which reaches the subnormals too."""
    top = float(np.abs(values).max(initial=0.0))
    return 0 if top == 0.0 else 1 - int(np.frexp(top)[1])


@dataclass(frozen=True)
class _TreeParams:
    """How one tree is grown (see ``boxtrees._builder.build_tree``)."""

    test_type: str
    n_tests: int
    min_samples_split: int
    max_depth: int
    max_retries: int
    refine_tests: bool


@dataclass(frozen=True, eq=False)
class _FitData:
    """The training data as the trees grow on them.

    ``objects`` (`_TrainingObjects`), the encoded targets ``y`` and the weights
    ``sample_weight`` are those of the samples of positive weight (the mask ``kept`` over
    all the samples), ``y`` and the weights scaled by ``2**y_exponent`` and
    ``2**w_exponent``; ``labels`` are the validated targets of all the samples (the class
    labels for a classifier); ``fitted`` holds the fitted attributes that validating them
    set on the estimator (`BaseBoxTrees._data_attributes`), which every tree grown on them
    takes.
    """

    objects: object
    y: np.ndarray
    sample_weight: np.ndarray
    y_exponent: int
    w_exponent: int
    params: _TreeParams
    kept: np.ndarray
    labels: np.ndarray
    fitted: dict


@dataclass(frozen=True, eq=False)
class _Bootstrap:
    """How each tree of a forest draws its bootstrap sample: ``n_draws`` draws with
    replacement among the samples it is given, seeded by the tree's seed. A sample's weight
    is multiplied by the number of times it is drawn and, with ``labels`` (the samples' class
    labels, for ``class_weight="balanced_subsample"``), by the factor that balances the
    classes of the draw."""

    n_draws: int
    labels: np.ndarray | None = None

    def counts(self, seed, n):
        """How many times each of ``n`` samples is drawn for the tree of ``seed``: the
        draw recovers a tree's bootstrap sample from its seed."""
        draws = np.random.default_rng([seed, 1]).integers(0, n, self.n_draws)
        return np.bincount(draws, minlength=n)

    def weights(self, seed, sample_weight):
        """The weights of the tree of ``seed``'s bootstrap sample."""
        weight = sample_weight * self.counts(seed, len(sample_weight))
        if self.labels is not None:
            weight = weight * _class_weight_factors("balanced", self.labels, weight)
        return weight


def _class_weight_factors(class_weight, labels, sample_weight):
    """The factor scikit-learn's ``class_weight`` gives each sample's weight.

    A dict (a list of them, one per output) gives each class its weight;
    ``"balanced"`` gives every class of each output the same total of ``sample_weight``,
    among the samples of positive weight (the others get 0).

    Parameters
    ----------
    class_weight : "balanced", dict or list of dict
    labels : ndarray of shape (n_samples,) or (n_samples, n_outputs)
    sample_weight : ndarray of shape (n_samples,)

    Returns
    -------
    factors : ndarray of shape (n_samples,)
    """
    if class_weight != "balanced":
        return compute_sample_weight(class_weight, labels)
    weighted = sample_weight > 0
    columns = labels.reshape(len(labels), -1)[weighted]
    per_output = []
    for column in columns.T:
        classes = np.unique(column)
        balanced = compute_class_weight("balanced", classes=classes, y=column,
                                        sample_weight=sample_weight[weighted])
        per_output.append(dict(zip(classes, balanced)))
    factors = np.zeros(len(labels))
    factors[weighted] = compute_sample_weight(
        per_output[0] if len(per_output) == 1 else per_output, columns)
    return factors


class RegressionTargets(RegressorMixin):
    """Targets of a regressor: one column of real numbers, or several (multi-output).

    Sets ``n_outputs_``; ``predict`` gives shape (n_samples,) for one output, else
    (n_samples, n_outputs_).
    """

    _y_numeric = True

    def _encode_targets(self, y):
        y = np.ascontiguousarray(y, dtype=np.float64)
        if not np.isfinite(y).all():
            raise ValueError("y contains NaN or infinite values")
        top = np.abs(y).max(initial=0.0)
        if top >= _Y_MAX:
            raise ValueError(f"y has values of magnitude up to {top:.3g}: their squares, the "
                             f"node variances (impurity), overflow float64; rescale y below "
                             f"{_Y_MAX:.3g}")
        if 0 < top < 1 / _Y_MAX:
            warnings.warn(f"y has values of magnitude at most {top:.3g}: the trees grow on them "
                          f"rescaled, but their squares, the node variances (impurity), "
                          f"underflow float64 to 0, and so do feature_importances_; rescale y "
                          f"above {1 / _Y_MAX:.3g} to read them", UserWarning, stacklevel=4)
        self.n_outputs_ = 1 if y.ndim == 1 else y.shape[1]
        return y

    def predict(self, X: SetsOrMatrix) -> np.ndarray:
        """Predict the mean of the trees' leaf values.

        Parameters
        ----------
        X : object sets or feature matrix, of the kind seen at fit

        Returns
        -------
        y : ndarray of shape (n_samples,) or (n_samples, ``n_outputs_``)
        """
        values = self._predict_mean(X, getattr(self, "n_jobs", None))
        return values[:, 0] if self.n_outputs_ == 1 else values

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.target_tags.multi_output = True
        return tags


class ClassificationTargets(ClassifierMixin):
    """Targets of a classifier: labels of any type, one column or several (multi-output).

    Each output's labels become class indicator columns (a single 0/1 column for two
    classes of a single output), the targets the regression criterion turns into Gini
    impurity (``boxtrees/_criterion.pxd``); the trees keep each output's class frequencies.
    Sets ``classes_``, ``n_classes_`` and ``n_outputs_`` (lists of them for several outputs).
    """

    _y_numeric = False

    def _encode_targets(self, y):
        check_classification_targets(y)
        columns = np.asarray(y).reshape(len(y), -1)
        classes, codes = zip(*(np.unique(c, return_inverse=True) for c in columns.T))
        self.n_outputs_ = columns.shape[1]
        single = self.n_outputs_ == 1
        self.classes_ = classes[0] if single else list(classes)
        self.n_classes_ = len(classes[0]) if single else [len(c) for c in classes]
        if single and len(classes[0]) == 2:
            return codes[0].astype(np.float64)
        return np.hstack([np.eye(len(c))[code] for c, code in zip(classes, codes)])

    def _node_arrays(self, arrays):
        """Class frequencies of every output in ``value``, Gini impurity (mean over outputs)."""
        value = arrays["value"]
        if value.ndim == 1:         # the single indicator of a binary output: p(class 1)
            value = np.column_stack([1.0 - value, value])
        arrays["value"] = value
        arrays["impurity"] = np.mean([1.0 - (b * b).sum(axis=1) for b in self._per_output(value)],
                                     axis=0)
        return arrays

    def _per_output(self, values):
        """Split class-frequency columns into one block per output."""
        return np.split(values, np.cumsum(np.atleast_1d(self.n_classes_))[:-1], axis=1)

    def predict_proba(self, X: SetsOrMatrix) -> np.ndarray | list[np.ndarray]:
        """Class probabilities: the mean over the trees of the leaves' class frequencies.

        Parameters
        ----------
        X : object sets or feature matrix, of the kind seen at fit

        Returns
        -------
        proba : ndarray of shape (n_samples, ``n_classes_``), or a list of them per output
            Columns in the order of ``classes_``.
        """
        blocks = self._per_output(self._predict_mean(X, getattr(self, "n_jobs", None)))
        return blocks[0] if self.n_outputs_ == 1 else blocks

    def predict_log_proba(self, X: SetsOrMatrix) -> np.ndarray | list[np.ndarray]:
        """Logarithm of `predict_proba` (``-inf`` for a zero probability)."""
        proba = self.predict_proba(X)
        with np.errstate(divide="ignore"):
            return np.log(proba) if self.n_outputs_ == 1 else [np.log(p) for p in proba]

    def predict(self, X: SetsOrMatrix) -> np.ndarray:
        """The most probable class of each sample (the first in ``classes_`` on a tie).

        Returns
        -------
        y : ndarray of shape (n_samples,) or (n_samples, ``n_outputs_``)
        """
        return self._most_probable(self.predict_proba(X))

    def _most_probable(self, proba):
        """The most probable class of each row of ``proba`` (as `predict_proba` gives it)."""
        if self.n_outputs_ == 1:
            return self.classes_.take(proba.argmax(axis=1))
        return np.column_stack([c.take(p.argmax(axis=1)) for c, p in zip(self.classes_, proba)])


class _TrainingObjects:
    """The training objects indexed for the tree builder.

    A test's box spans the columns of one column group: its x column, its y column if it has
    two, and further columns read in the objects' rows (``attributes``, ``object_of``) if it
    has more. Every group indexes all the objects of sets, in segments, one per (group,
    type position, y band), sorted by x in each; ``sample_of`` is the sample of each object.
    A feature matrix is passed as it is, as ``columns`` (the builder reads it in place; its
    values are one attribute, one group). Sets the estimator's ``types_``, ``n_types_``,
    ``column_groups_`` and ``bounds_``.
    """

    def __init__(self, estimator, sets):
        features = estimator._fitted_on_features
        d = estimator.n_attributes_
        if features:          # ``sets`` is the feature matrix: each column is one attribute
            estimator.types_ = np.arange(estimator.n_features_in_)
            spanned = fitted_region(sets)
        else:
            data = sets.data
            estimator.types_, position = np.unique(data[:, d].astype(np.intp), return_inverse=True)
            if not len(estimator.types_):
                estimator.types_ = np.zeros(1, dtype=np.intp)
            spanned = fitted_region(data, range(d))
            if spanned is None:          # no object at all: any region will do
                spanned = np.tile([0.0, 1.0], (d, 1))
        low, high = spanned[:, 0], spanned[:, 1]
        estimator.n_types_ = n_types = len(estimator.types_)
        estimator.column_groups_ = groups = _column_groups(estimator.column_groups, d)
        per_type = isinstance(estimator.view_bounds, Mapping)
        if per_type and features:
            raise ValueError("view_bounds as a mapping of type ids applies to object sets; a "
                             "feature matrix takes one (low, high) for every column")
        if estimator.view_bounds is not None and not per_type:
            region = np.tile(check_view_bounds(estimator.view_bounds, d), (n_types, 1))
        elif features:        # each column's own range
            region = np.column_stack([low, high])
        else:
            region = np.tile(_with_margin(low, high).ravel(), (n_types, 1))
        if per_type:
            for object_type, bounds in _type_regions(estimator.view_bounds, d).items():
                region[estimator.types_ == object_type] = bounds
        estimator.bounds_ = region.astype(np.float32)
        width = float(estimator.test_width)
        if estimator.relative_width:
            half = width * (region[:, 1::2] - region[:, 0::2])      # (n_types, d)
        else:
            half = np.full((n_types, d), width)
        # per (group, type): the region along the group's columns, and the half-widths; a
        # group of one column has an unbounded y extent
        n_groups = len(groups)
        self.group_sizes = np.array([len(columns) for columns in groups], dtype=np.intp)
        self.bounds = np.zeros((n_groups * n_types, 2 * MAX_GROUP_COLUMNS), dtype=np.float32)
        self.half_widths = np.zeros((n_groups * n_types, MAX_GROUP_COLUMNS))
        self.extra_columns = np.full((n_groups, MAX_GROUP_COLUMNS - 2), -1, dtype=np.intp)
        for g, columns in enumerate(groups):
            mine = slice(g * n_types, (g + 1) * n_types)
            for axis, column in enumerate(columns):
                self.bounds[mine, 2 * axis:2 * axis + 2] = region[:, 2 * column:2 * column + 2]
                self.half_widths[mine, axis] = half[:, column]
            if len(columns) == 1:
                self.bounds[mine, 2:4] = [-np.inf, np.inf]
            self.extra_columns[g, :max(len(columns) - 2, 0)] = columns[2:]
        self.local_x = features and estimator.view_bounds is None
        self.columns = None
        if features:
            # read in place; strides that are not whole elements are copied away
            self.columns = sets if not any(s % sets.itemsize for s in sets.strides) else \
                np.ascontiguousarray(sets)
        else:
            self._index_objects(estimator, sets, position)

    def _index_objects(self, estimator, sets, position):
        data, groups, n_types = sets.data, estimator.column_groups_, estimator.n_types_
        edges = [_band_edges(estimator, *self._group_extent(g, n_types))
                 for g in range(len(groups))]
        n_bands = max(len(e) for e in edges) - 1
        # every group has n_bands bands; the last ones of a group with fewer are empty
        self.band_edges = np.array([np.pad(e, (0, n_bands + 1 - len(e)), constant_values=np.inf)
                                    for e in edges])
        self.x, self.y, self.sample_of, object_of, self.segment_ptr = index_segments(
            data, sets.sample_index().astype(np.int32), position, groups, n_types,
            self.band_edges)
        if (self.group_sizes > 2).any():   # their further columns are read in the rows
            self.attributes = np.ascontiguousarray(data[:, :estimator.n_attributes_])
            self.object_of = object_of

    def _group_extent(self, group, n_types):
        """The y extent that the regions of a column group's types span, ``(ymin, ymax)``, and
        their smallest y half-width (what the group's bands are cut for)."""
        mine = slice(group * n_types, (group + 1) * n_types)
        return (self.bounds[mine, 2].min(), self.bounds[mine, 3].max(),
                self.half_widths[mine, 1].min())


def _type_regions(view_bounds, n_attributes):
    """A mapping ``view_bounds`` validated: type id -> its region as `check_view_bounds` gives
    it (``2 * n_attributes`` floats)."""
    regions = {}
    for object_type, bounds in view_bounds.items():
        if not isinstance(object_type, Integral) or isinstance(object_type, bool):
            raise TypeError(f"view_bounds as a mapping takes type ids (ints) as keys; got "
                            f"{object_type!r}")
        regions[int(object_type)] = check_view_bounds(bounds, n_attributes,
                                                      name=f"view_bounds[{object_type!r}]")
    return regions


def _with_margin(low, high):
    """The objects' bounding box ``(low, high)`` per attribute, widened on every side by
    `_REGION_MARGIN` of its width (of ``max(|value|, 1)`` for a constant attribute): boxes are
    open, so a box drawn within the bounding box itself could never hold the objects that lie
    on its border. Shape (d, 2)."""
    low, high = np.asarray(low, dtype=np.float64), np.asarray(high, dtype=np.float64)
    width = high - low
    margin = _REGION_MARGIN * np.where(width > 0, width, np.maximum(np.abs(low), 1.0))
    return np.clip(np.column_stack([low - margin, high + margin]), -_FLOAT32_MAX, _FLOAT32_MAX)


def _column_groups(column_groups, n_attributes):
    """The column groups a test's box may span, validated: ``column_groups`` or, for None,
    the first two attributes (a position), alone and with each other attribute."""
    most = MAX_GROUP_COLUMNS
    if column_groups is None:
        if n_attributes == 1:
            return ((0,),)
        return ((0, 1),) + tuple((0, 1, c) for c in range(2, n_attributes))
    groups = []
    for group in column_groups:
        group = columns_of(group, n_attributes, most)
        if group is None:
            raise ValueError(
                f"column_groups must be a non-empty sequence of groups of 1 to {most} distinct "
                f"attribute indices in [0, {n_attributes}) (the objects have {n_attributes} "
                f"attributes before their type); got {column_groups!r}"
            )
        groups.append(group)
    if not groups:
        raise ValueError("column_groups must name at least one group of columns; got "
                         f"{column_groups!r}")
    return tuple(groups)


def _band_edges(estimator, y0, y1, y_half_width):
    """Edges of the y bands that index the training objects of one column group (an internal
    speed-up), from the y extent ``(y0, y1)`` of its regions.

    Bands about twice as tall as a fixed or bounded box (measured best) let a test skip most
    objects of its type; wholly covered bands need no y test. A group of one column (an
    unbounded y extent) has one band.
    """
    y0, y1 = float(y0), float(y1)
    if not np.isfinite(y0):
        return np.array([-np.inf, np.inf])
    if estimator.test_type in ("fixed", "bounded"):
        height = y1 - y0
        n_bands = int(np.clip(np.ceil(height / (4 * y_half_width)), 1, _MAX_BANDS)) \
            if y_half_width > 0 else _MAX_BANDS
    else:
        n_bands = _DEFAULT_BANDS
    inner = y0 + (y1 - y0) * np.arange(1, n_bands) / n_bands
    return np.concatenate([[-np.inf], inner, [np.inf]])
