"""Extra-Trees forests whose node tests count objects in boxes: ``BoxExtraTreesRegressor``
and ``BoxExtraTreesClassifier``."""
from numbers import Integral

import numpy as np
from sklearn.base import _fit_context
from sklearn.utils import check_random_state
from sklearn.utils._param_validation import Interval
from sklearn.utils.validation import check_is_fitted

from ._base import _INT32_MAX, BaseBoxTrees, ClassificationTargets, RegressionTargets
from ._extra_tree import BoxExtraTreeClassifier, BoxExtraTreeRegressor

__all__ = ["BoxExtraTreesClassifier", "BoxExtraTreesRegressor"]


class _Forest(BaseBoxTrees):
    """Fitting and walking a forest of trees of class ``_tree_class``."""

    _parameter_constraints = {
        **BaseBoxTrees._parameter_constraints,
        "n_estimators": [Interval(Integral, 1, _INT32_MAX, closed="both")],
        "bootstrap": ["boolean"],
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
        test_type="random",
        test_width=0.1,
        max_retries=10,
        max_depth=None,
        view_bounds=None,
        column_groups=None,
        relative_width=True,
        refine_tests=True,
        bootstrap=True,
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
        self.column_groups = column_groups
        self.relative_width = relative_width
        self.refine_tests = refine_tests
        self.bootstrap = bootstrap
        self.n_jobs = n_jobs
        self.random_state = random_state
        self.verbose = verbose

    @_fit_context(prefer_skip_nested_validation=True)
    def fit(self, X, y, sample_weight=None):
        """Grow the forest.

        Parameters
        ----------
        X : sequence of array-like of shape (n_i, d + 1), ObjectSets, or array of shape (n_samples, n_features)
            Object sets (rows ``[f_1, ..., f_d, type]``; empty sets allowed), or a feature
            matrix.
        y : array-like of shape (n_samples,) or (n_samples, n_outputs)
            Target values (class labels for a classifier).
        sample_weight : array-like of shape (n_samples,), default=None
            Non-negative weights, each a sample's share in the node means and variances: zero
            ignores a sample, and scaling all weights changes nothing. None gives every
            sample weight 1.

        Returns
        -------
        self : estimator
        """
        rng = check_random_state(self.random_state)
        seeds = rng.randint(np.iinfo(np.int64).max, size=self.n_estimators, dtype=np.int64)
        trees = self._fit_trees(X, y, sample_weight, seeds, self.n_jobs, self.verbose,
                                bootstrap=self.bootstrap)
        params = {name: getattr(self, name) for name in self._tree_class._get_param_names()
                  if name != "random_state"}
        # what fitting taught the forest about the data, its trees know too: every fitted
        # attribute (scikit-learn's trailing underscore) but the trees themselves
        fitted = {name: value for name, value in self.__dict__.items()
                  if (name.endswith("_") and not name.startswith("_") and name != "estimators_")
                  or name == "_fitted_on_features"}
        self.estimators_ = []
        for tree, seed in zip(trees, seeds):
            estimator = self._tree_class(**params, random_state=int(seed))
            estimator.__dict__.update(fitted, tree_=tree)
            estimator._pack([tree])
            self.estimators_.append(estimator)
        self._pack(trees)
        return self

    def _trees(self):
        return [e.tree_ for e in self.estimators_] if "estimators_" in self.__dict__ else None

    def apply(self, X):
        """Index of the leaf each sample reaches in each tree.

        Parameters
        ----------
        X : object sets or feature matrix, of the kind seen at fit

        Returns
        -------
        leaves : ndarray of shape (n_samples, n_estimators)
            Node ids, local to each tree (as in ``estimators_[k].tree_``).
        """
        return self._apply(X, self.n_jobs)

    def decision_path(self, X):
        """The nodes each sample passes through, in every tree.

        Parameters
        ----------
        X : object sets or feature matrix, of the kind seen at fit

        Returns
        -------
        indicator : sparse matrix of shape (n_samples, n_nodes)
            1 where a sample passes through a node; the trees' nodes side by side.
        n_nodes_ptr : ndarray of shape (n_estimators + 1,)
            Columns ``n_nodes_ptr[k]:n_nodes_ptr[k + 1]`` are tree ``k``'s nodes.
        """
        check_is_fitted(self)
        return self._decision_path(X, self._trees(), self.n_jobs)

    @property
    def feature_importances_(self):
        """Impurity-based importance of each type of ``types_`` (each column for a feature
        matrix): the weighted variance reduction of the tests on it, normalised per tree,
        averaged over trees, summing to 1 (all zeros if no tree splits).

        Returns
        -------
        importances : ndarray of shape (n_types_,)
        """
        check_is_fitted(self)
        total = np.mean([t.type_importances(self.types_) for t in self._trees()], axis=0)
        return total / total.sum() if total.sum() > 0 else total

    def __len__(self):
        """Number of fitted trees."""
        return len(self.estimators_)

    def __getitem__(self, index):
        """The ``index``-th fitted tree."""
        return self.estimators_[index]

    def __iter__(self):
        return iter(self.estimators_)


class BoxExtraTreesRegressor(RegressionTargets, _Forest):
    """Extra-Trees regression over sets of objects, with box-count node tests.

    Each sample is a set of objects of any size (possibly empty); an object is a row ``[f_1,
    ..., f_d, type]`` of ``d >= 1`` real attributes and an integer type id, last (``[x, y,
    type]`` for points in the plane). A node test ``(type t, box, z)`` sends a sample left
    when fewer than ``z`` of its objects of type ``t`` lie strictly inside the box: an open
    interval along each column of one of ``column_groups`` (for ``[x, y, type]`` objects,
    ``(xmin, xmax) x (ymin, ymax)``), the other attributes unbounded. Each node keeps the best of
    ``n_tests`` random tests, scored by the weighted variance of the two children; the count
    threshold ``z`` is drawn uniformly among the integers in ``(min count, max count]`` of the
    node. Trees are grown on the full data (unless ``bootstrap``) and the forest predicts the
    mean of its trees.

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
    min_samples_split : int or float, default=30
        A node with fewer samples than this becomes a leaf (n_min), as in scikit-learn: an
        int >= 2 is a number of samples, a float in ``(0, 1]`` a fraction of them (rounded
        up). Samples are counted whatever their weights, so scaling the weights changes
        nothing.
    test_type : {"fixed", "bounded", "random", "classic"}, default="fixed"
        How test boxes are drawn in the sampling region:

        - ``"fixed"``: centre uniform, half-width exactly ``test_width`` (square boxes);
        - ``"bounded"``: centre uniform, each half-width uniform in ``(0, test_width]``;
        - ``"random"``: the four bounds uniform in the region, sorted per axis;
        - ``"classic"``: a random axis and a uniform split value; the box is the half-plane
          below it.
    test_width : float, default=1.0
        Half-width (TW) for ``"fixed"`` and ``"bounded"`` tests, along each column of the box:
        in the attributes' units, or with ``relative_width`` a fraction of the sampling
        region's width along that column.
    max_retries : int, default=10
        When none of a node's ``n_tests`` tests splits it, draw up to this many further
        rounds before making it a leaf.
    max_depth : int, default=None
        Maximum tree depth; None grows until the other stopping rules apply.
    view_bounds : array-like of 2 * d floats or float, default=None
        Sampling region ``(low_1, high_1, ..., low_d, high_d)`` (for ``[x, y, type]``
        objects, ``(xmin, xmax, ymin, ymax)``), or a half-width ``r`` for ``[-r, r]^d``.
        None: the bounding box of the training objects (for a feature matrix: each node's
        range of the tested column).
    column_groups : sequence of sequences of int, default=None
        The groups of attributes a test's box may span, each of 1 to 8 distinct attribute
        indices (an int is a group of one); each test draws one group. None: the first two
        attributes (a position), alone and with each other attribute, ``[(0, 1), (0, 1, 2),
        ..., (0, 1, d - 1)]`` (``[(0,)]`` for ``d = 1``); see ``docs/boxtrees.md`` for the
        measurements behind it.
    relative_width : bool, default=False
        Read ``test_width`` as a fraction of the sampling region's width along each column,
        so that the boxes follow the units of every attribute.
    refine_tests : bool, default=False
        Refine the best of each node's tests on the node's training objects: each finite edge
        of its box is swept across the objects and moved to the tightest position of the best
        score, then the threshold is re-picked as the best one, for up to 3 rounds. Boxes then
        stop where the training data stop supporting them, so that on sets larger than those
        seen at fit the extra background objects do not cross the thresholds. Use it (with
        ``bootstrap=True``) when the sets at prediction may be larger than at training; see
        the set-size study in ``docs/set_sizes.md``. It costs a sort of the node's objects
        of the tested type per refined edge.
    bootstrap : bool, default=False
        Grow each tree on a bootstrap sample (``n_samples`` draws with replacement, as
        weights), as scikit-learn's ``bootstrap``; with ``refine_tests`` it makes the refined
        edges differ from tree to tree, so that the forest averages out their errors.
    n_jobs : int, default=None
        Number of parallel jobs for ``fit`` (over trees) and large ``predict`` / ``apply``
        calls (over samples). None means 1 unless in a ``joblib.parallel_backend`` context; -1
        means all processors. Trees are built with the GIL released. Results do not depend
        on ``n_jobs``.
    random_state : int, RandomState instance or None, default=None
        Seeds the trees: each gets an int ``random_state`` drawn from it. The same value
        gives the same forest whatever ``n_jobs``.
    verbose : int, default=0
        Verbosity of the joblib loop over trees.

    Attributes
    ----------
    estimators_ : list of BoxExtraTreeRegressor
        The fitted trees (also ``forest[k]``, ``len(forest)``, ``iter(forest)``); their node
        arrays are ``estimators_[k].tree_``.
    types_ : ndarray of int
        Sorted type ids seen at fit (the column indices for a feature matrix). Tests are
        drawn on these types only; other ids at predict time match no test.
    n_types_ : int
        ``len(types_)``.
    type_names_ : ndarray
        The label of each type id (``type_names_[t]`` names id ``t``), when fitted on
        object sets whose types are named (`ObjectSets.from_frame`); a batch whose types are
        named is read by name at predict.
    n_attributes_ : int
        Number of attributes ``d`` of the objects seen at fit (1 for a feature matrix).
    column_groups_ : tuple of tuple of int
        The column groups the tests draw from.
    bounds_ : ndarray of shape (n_types_, 2 * n_attributes_)
        Sampling region per type of ``types_``, ``(low, high)`` per attribute.
    n_features_in_ : int
        Number of columns, when fitted on a feature matrix.
    feature_names_in_ : ndarray of str
        Column names, when fitted on a data frame with string column names.

    See Also
    --------
    BoxExtraTreeRegressor : one tree of the forest.
    GridCounts : the fixed-size grid representation, for any scikit-learn regressor.
    sklearn.ensemble.ExtraTreesRegressor : classic Extra-Trees on feature matrices.

    Examples
    --------
    The target counts the objects of type 0 in the unit square around the origin; type 1 is
    a distractor. The forest learns the count from the sets alone, and only type 0 matters:

    >>> import numpy as np
    >>> from boxtrees import BoxExtraTreesRegressor
    >>> rng = np.random.default_rng(0)
    >>> def sets(n):
    ...     return [np.column_stack([rng.uniform(-3, 3, (k, 2)), rng.integers(0, 2, k)])
    ...             for k in rng.integers(0, 12, n)]
    >>> def count(s):
    ...     return float(((np.abs(s[:, :2]).max(1) < 1) & (s[:, 2] == 0)).sum())
    >>> X, X_test = sets(2000), sets(500)
    >>> forest = BoxExtraTreesRegressor(n_estimators=10, min_samples_split=5,
    ...                                 random_state=0).fit(X, [count(s) for s in X])
    >>> bool(forest.score(X_test, [count(s) for s in X_test]) > 0.9)
    True
    >>> forest.types_.tolist(), bool(forest.feature_importances_[0] > 0.9)
    ([0, 1], True)
    >>> # a set with one coin at the centre, as many distractors, or nothing
    >>> centre = [np.array([[0.0, 0.0, 0]]), np.array([[0.0, 0.0, 1]]), np.empty((0, 3))]
    >>> forest.predict(centre).round().tolist()
    [1.0, 0.0, 0.0]
    """

    _tree_class = BoxExtraTreeRegressor


class BoxExtraTreesClassifier(ClassificationTargets, _Forest):
    """Extra-Trees classification over sets of objects, with box-count node tests.

    The forest of `BoxExtraTreesRegressor` with a classification criterion: the Gini
    impurity, which for class indicator targets is the variance the regressor reduces, so
    the same engine grows both (``boxtrees/_criterion.pxd``); each leaf keeps the class
    frequencies of its training samples and ``predict_proba`` averages them over the trees.
    Labels may be of any type; several outputs (2D ``y``) are classified at once, as in
    scikit-learn's ``ExtraTreesClassifier``.

    Parameters
    ----------
    n_estimators, n_tests, min_samples_split, test_type, test_width, max_retries, max_depth, view_bounds, column_groups, relative_width, refine_tests, bootstrap, n_jobs, random_state, verbose
        As in `BoxExtraTreesRegressor`.

    Attributes
    ----------
    estimators_ : list of BoxExtraTreeClassifier
        The fitted trees (also ``forest[k]``, ``len(forest)``, ``iter(forest)``).
    classes_ : ndarray, or list of ndarray for several outputs
        The class labels, in the column order of ``predict_proba``.
    n_classes_ : int or list of int
    n_outputs_ : int
    types_, n_types_, type_names_, n_attributes_, column_groups_, bounds_, n_features_in_, feature_names_in_
        As in `BoxExtraTreesRegressor`.

    Examples
    --------
    Is there an object of type 0 in the unit square around the origin?

    >>> import numpy as np
    >>> from boxtrees import BoxExtraTreesClassifier
    >>> rng = np.random.default_rng(0)
    >>> X = [np.column_stack([rng.uniform(-3, 3, (k, 2)), rng.integers(0, 2, k)])
    ...      for k in rng.integers(0, 12, 1500)]
    >>> y = ["yes" if ((np.abs(s[:, :2]).max(1) < 1) & (s[:, 2] == 0)).any() else "no" for s in X]
    >>> forest = BoxExtraTreesClassifier(n_estimators=10, min_samples_split=5,
    ...                                  random_state=0).fit(X[:1000], y[:1000])
    >>> forest.classes_.tolist(), bool(forest.score(X[1000:], y[1000:]) > 0.9)
    (['no', 'yes'], True)
    >>> forest.predict([np.array([[0.0, 0.0, 0]]), np.array([[0.0, 0.0, 1]])]).tolist()
    ['yes', 'no']
    """

    _tree_class = BoxExtraTreeClassifier
