"""``BoxExtraTreesRegressor``: an Extra-Trees forest whose node tests count objects in boxes."""
from numbers import Integral, Real

import numpy as np
from joblib import Parallel, delayed, effective_n_jobs
from sklearn.base import BaseEstimator, RegressorMixin, _fit_context
from sklearn.utils import check_random_state
from sklearn.utils._param_validation import Interval, StrOptions
from sklearn.utils.validation import _check_sample_weight, check_is_fitted

from ._builder import TEST_KINDS, build_tree
from ._objects import ObjectInputMixin, check_view_bounds
from ._predictor import apply_leaves, predict_mean
from ._rows import group_by_type
from ._tree import BoxTree, PackedForest

__all__ = ["BoxExtraTreesRegressor"]

# below this many samples, prediction runs in the calling thread
_PARALLEL_PREDICT_MIN_SAMPLES = 2048
# y bands of the training-object index: at most this many, this many for large boxes
_MAX_BANDS = 32
_DEFAULT_BANDS = 8


class BoxExtraTreesRegressor(ObjectInputMixin, RegressorMixin, BaseEstimator):
    """Extra-Trees regression over sets of 2D objects, with box-count node tests.

    Each sample is a set of objects ``[x, y, type]`` of any size (possibly empty). A node test
    ``(type t, box, z)`` sends a sample left when fewer than ``z`` of its objects of type ``t``
    lie strictly inside the box ``(xmin, xmax) x (ymin, ymax)``. Each node keeps the best of
    ``n_tests`` random tests, scored by the weighted variance of the two children; the count
    threshold ``z`` is drawn uniformly among the integers in ``(min count, max count]`` of the
    node. Trees are grown on the full data (no bootstrap) and the forest predicts the mean of
    its trees.

    ``X`` may also be a 2D feature matrix: column ``j`` is then read as a one-dimensional object
    of type ``j`` and the tests are intervals on one column, drawn within the node's range of
    that column as in classic Extra-Trees (``test_type="classic"`` gives the classic
    axis-aligned random splits).

    Parameters
    ----------
    n_estimators : int, default=30
        Number of trees (M).
    n_tests : int, default=500
        Number of random tests drawn per node (K); the best one is kept.
    min_samples_split : float, default=30
        A node whose total sample weight (with unit weights: its number of samples) is below
        this becomes a leaf (n_min).
    test_type : {"fixed", "bounded", "random", "classic"}, default="fixed"
        How test boxes are drawn in the sampling region:

        - ``"fixed"``: centre uniform, half-width exactly ``test_width`` (square boxes);
        - ``"bounded"``: centre uniform, each half-width uniform in ``(0, test_width]``;
        - ``"random"``: the four bounds uniform in the region, sorted per axis;
        - ``"classic"``: a random axis and a uniform split value; the box is the half-plane
          below it.
    test_width : float, default=1.0
        Half-width (TW) for ``"fixed"`` and ``"bounded"`` tests.
    max_retries : int, default=10
        When none of a node's ``n_tests`` tests splits it, draw up to this many further
        rounds before making it a leaf.
    max_depth : int, default=None
        Maximum tree depth; None grows until the other stopping rules apply.
    view_bounds : array-like of 4 floats or float, default=None
        Sampling region ``(xmin, xmax, ymin, ymax)``, or a half-width ``r`` for ``[-r, r]^2``.
        None: the bounding box of the training objects (for a feature matrix: each node's
        range of the tested column).
    n_jobs : int, default=None
        Number of parallel jobs for ``fit`` (over trees) and large ``predict`` / ``apply``
        calls (over samples). None means 1 unless in a ``joblib.parallel_backend`` context; -1
        means all processors. Trees are built with the GIL released. Results do not depend
        on ``n_jobs``.
    random_state : int, RandomState instance or None, default=None
        Seeds the trees. The same value gives the same forest whatever ``n_jobs``.
    verbose : int, default=0
        Verbosity of the joblib loop over trees.

    Attributes
    ----------
    estimators_ : list of BoxTree
        The fitted trees, as flat node arrays.
    n_types_ : int
        Number of object types (one more than the largest type id at fit; the number of
        columns for a feature matrix). Types seen only at predict time match no test.
    bounds_ : ndarray of shape (n_types_, 4)
        Sampling region per type.
    n_features_in_ : int
        Number of columns, when fitted on a feature matrix.
    feature_names_in_ : ndarray of str
        Column names, when fitted on a data frame with string column names.

    See Also
    --------
    GridCounts : the fixed-size grid representation, for any scikit-learn regressor.
    sklearn.ensemble.ExtraTreesRegressor : classic Extra-Trees on feature matrices.

    Examples
    --------
    >>> import numpy as np
    >>> from boxtrees import BoxExtraTreesRegressor
    >>> rng = np.random.default_rng(0)
    >>> X = [np.column_stack([rng.uniform(-3, 3, (n, 2)), rng.integers(0, 2, n)])
    ...      for n in rng.integers(0, 8, 300)]
    >>> y = [float(((np.abs(s[:, :2]).max(1) < 1) & (s[:, 2] == 0)).sum()) for s in X]
    >>> forest = BoxExtraTreesRegressor(n_estimators=10, min_samples_split=5,
    ...                                 random_state=0).fit(X, y)
    >>> forest.predict(X[:3]).round(2).tolist() == np.round(forest.predict(X)[:3], 2).tolist()
    True
    """

    _parameter_constraints = {
        "n_estimators": [Interval(Integral, 1, None, closed="left")],
        "n_tests": [Interval(Integral, 1, None, closed="left")],
        "min_samples_split": [Interval(Real, 0, None, closed="left")],
        "test_type": [StrOptions(set(TEST_KINDS))],
        "test_width": [Interval(Real, 0, None, closed="neither")],
        "max_retries": [Interval(Integral, 0, None, closed="left")],
        "max_depth": [Interval(Integral, 0, None, closed="left"), None],
        "view_bounds": ["array-like", Interval(Real, 0, None, closed="neither"), None],
        "n_jobs": [Integral, None],
        "random_state": ["random_state"],
        "verbose": ["verbose"],
    }

    def __init__(
        self,
        n_estimators=30,
        *,
        n_tests=500,
        min_samples_split=30,
        test_type="fixed",
        test_width=1.0,
        max_retries=10,
        max_depth=None,
        view_bounds=None,
        n_jobs=None,
        random_state=None,
        verbose=0,
    ):
        self.n_estimators = n_estimators
        self.n_tests = n_tests
        self.min_samples_split = min_samples_split
        self.test_type = test_type
        self.test_width = test_width
        self.max_retries = max_retries
        self.max_depth = max_depth
        self.view_bounds = view_bounds
        self.n_jobs = n_jobs
        self.random_state = random_state
        self.verbose = verbose

    @_fit_context(prefer_skip_nested_validation=True)
    def fit(self, X, y, sample_weight=None):
        """Grow the forest.

        Parameters
        ----------
        X : sequence of array-like of shape (n_i, 3), ObjectSets, or array of shape (n_samples, n_features)
            Object sets (rows ``[x, y, type]``; empty sets allowed), or a feature matrix.
        y : array-like of shape (n_samples,)
            Target values.
        sample_weight : array-like of shape (n_samples,), default=None
            Non-negative weights; a weight of ``k`` acts like ``k`` copies of the sample and
            zero-weight samples are ignored. None gives every sample weight 1.

        Returns
        -------
        self : BoxExtraTreesRegressor
        """
        sets, y = self._validate_input(X, y, reset=True, requires_y=True)
        if not np.isfinite(y).all():
            raise ValueError("y contains NaN or infinite values")
        # ``sizes`` stands in for X: one entry per sample, a plain NumPy array
        sample_weight = _check_sample_weight(
            sample_weight, sets.sizes, dtype=np.float64, ensure_non_negative=True
        )
        keep = sample_weight > 0
        if not keep.all():
            sets, y, sample_weight = sets[keep], y[keep], sample_weight[keep]

        data = sets.data
        types = data[:, 2].astype(np.intp)
        if self._fitted_on_features:
            self.n_types_ = self.n_features_in_
        else:
            self.n_types_ = int(types.max()) + 1 if len(types) else 1
        self.bounds_ = self._sampling_region(data)
        local_x = self._fitted_on_features and self.view_bounds is None

        band_edges = self._band_edges()
        n_bands = len(band_edges) - 1
        bands = np.searchsorted(band_edges[1:-1], data[:, 1], side="right")
        segments = types * n_bands + bands
        order = np.lexsort((data[:, 0], segments))
        x_sorted = np.ascontiguousarray(data[order, 0])
        y_sorted = np.ascontiguousarray(data[order, 1])
        sample_of = sets.sample_index()[order].astype(np.int32)
        segment_ptr = np.searchsorted(
            segments[order], np.arange(self.n_types_ * n_bands + 1)
        ).astype(np.intp)

        rng = check_random_state(self.random_state)
        seeds = rng.randint(np.iinfo(np.int64).max, size=self.n_estimators, dtype=np.int64)
        max_depth = -1 if self.max_depth is None else self.max_depth
        trees = Parallel(n_jobs=self.n_jobs, verbose=self.verbose, prefer="threads")(
            delayed(build_tree)(
                x_sorted, y_sorted, sample_of, segment_ptr, band_edges, y, sample_weight, self.bounds_,
                local_x, self._fitted_on_features, self.test_type, float(self.test_width), self.n_tests,
                float(self.min_samples_split), max_depth, self.max_retries, int(seed),
            )
            for seed in seeds
        )
        self.estimators_ = [BoxTree(**arrays) for arrays in trees]
        self._packed = PackedForest(self.estimators_)
        return self

    def _sampling_region(self, data):
        """Region ``(xmin, xmax, ymin, ymax)`` in which tests of each type are drawn."""
        if self.view_bounds is not None:
            region = check_view_bounds(self.view_bounds)
        elif len(data):
            region = np.array([data[:, 0].min(), data[:, 0].max(), data[:, 1].min(), data[:, 1].max()])
        else:
            region = np.array([0.0, 1.0, 0.0, 1.0])
        bounds = np.tile(region, (self.n_types_, 1))
        if self._fitted_on_features:
            bounds[:, 2:] = [-np.inf, np.inf]
        return np.ascontiguousarray(bounds, dtype=np.float32)

    def _band_edges(self):
        """Edges of the y bands that index the training objects (an internal speed-up).

        Bands about twice as tall as a fixed or bounded box (measured best) let a test skip
        most objects of its type; wholly covered bands need no y comparison. Feature-matrix
        columns have no y.
        """
        if self._fitted_on_features:
            n_bands = 1
        elif self.test_type in ("fixed", "bounded"):
            height = float(self.bounds_[0, 3]) - float(self.bounds_[0, 2])
            n_bands = int(np.clip(np.ceil(height / (4 * self.test_width)), 1, _MAX_BANDS))
        else:
            n_bands = _DEFAULT_BANDS
        y0, y1 = float(self.bounds_[0, 2]), float(self.bounds_[0, 3])
        inner = y0 + (y1 - y0) * np.arange(1, n_bands) / n_bands
        return np.concatenate([[-np.inf], inner, [np.inf]])

    def _traverse(self, X, kernel, out):
        """Validate ``X`` and run a traversal kernel over its samples, in parallel chunks
        when the batch is large."""
        if "estimators_" not in self.__dict__:  # cheap test first: predict is called per step
            check_is_fitted(self)
        sets, _ = self._validate_input(X, reset=False)
        samples = group_by_type(sets.data, sets.offsets, self.n_types_)
        n = len(sets)
        out = out(n)
        # chunks of at least half the threshold each; joblib is not even asked for small batches
        n_jobs = 1
        if n >= _PARALLEL_PREDICT_MIN_SAMPLES:
            n_jobs = min(effective_n_jobs(self.n_jobs), n // (_PARALLEL_PREDICT_MIN_SAMPLES // 2))
        if n_jobs == 1:
            kernel(self._packed, samples, 0, n, out)
        else:
            edges = np.linspace(0, n, n_jobs + 1).astype(np.intp)
            Parallel(n_jobs=n_jobs, require="sharedmem")(
                delayed(kernel)(self._packed, samples, a, b, out) for a, b in zip(edges[:-1], edges[1:])
            )
        return out

    def predict(self, X):
        """Predict the mean of the trees' leaf values.

        Parameters
        ----------
        X : object sets or feature matrix, of the kind seen at fit

        Returns
        -------
        y : ndarray of shape (n_samples,)
        """
        return self._traverse(X, predict_mean, lambda n: np.empty(n, dtype=np.float64))

    def apply(self, X):
        """Index of the leaf each sample reaches in each tree.

        Parameters
        ----------
        X : object sets or feature matrix, of the kind seen at fit

        Returns
        -------
        leaves : ndarray of shape (n_samples, n_estimators)
            Node ids, local to each tree (as in ``estimators_[k]``).
        """
        return self._traverse(X, apply_leaves, lambda n: np.empty((n, self.n_estimators), dtype=np.intp))

    @property
    def feature_importances_(self):
        """Impurity-based importance of each object type (each column for a feature matrix):
        the weighted variance reduction of the tests on it, normalised per tree, averaged
        over trees, summing to 1 (all zeros if no tree splits).

        Returns
        -------
        importances : ndarray of shape (n_types_,)
        """
        check_is_fitted(self)
        total = np.mean([t.type_importances(self.n_types_) for t in self.estimators_], axis=0)
        return total / total.sum() if total.sum() > 0 else total

    def __getstate__(self):
        state = dict(super().__getstate__())  # a copy: object.__getstate__ returns __dict__ itself
        state.pop("_packed", None)
        return state

    def __setstate__(self, state):
        super().__setstate__(state)
        if "estimators_" in state:
            self._packed = PackedForest(self.estimators_)
