"""Extra-Trees forests whose node tests count objects in boxes: ``BoxExtraTreesRegressor``
and ``BoxExtraTreesClassifier``."""
from __future__ import annotations

import warnings
from collections.abc import Callable, Iterator, Sequence
from numbers import Integral
from typing import Any, Literal, Self

import numpy as np
from numpy.typing import ArrayLike
from joblib import Parallel, delayed
from scipy.sparse import csr_matrix
from sklearn.metrics import r2_score
from sklearn.utils import check_random_state
from sklearn.utils._param_validation import Interval, RealNotInt, StrOptions
from sklearn.utils.validation import check_is_fitted

from ._base import _INT32_MAX, BaseBoxTrees, ClassificationTargets, RegressionTargets, _Bootstrap
from ._extra_tree import _SEED_MAX, BoxExtraTreeClassifier, BoxExtraTreeRegressor
from ._typing import RandomStateLike, SetsOrMatrix, TestType, ViewBounds, fit_context

__all__ = ["BoxExtraTreesClassifier", "BoxExtraTreesRegressor"]

# fitted attributes the trees of a fit read: a warm start's new trees must see the same
_KEPT_BY_WARM_START = ("_fitted_on_features", "n_attributes_", "n_features_in_", "type_names_",
                       "n_outputs_", "classes_")


def _same(a, b):
    """Whether two fitted attributes are equal (None, numbers, arrays or lists of arrays)."""
    if isinstance(a, list) or isinstance(b, list):
        return (isinstance(a, list) and isinstance(b, list) and len(a) == len(b)
                and all(map(_same, a, b)))
    if a is None or b is None:
        return a is None and b is None
    return np.array_equal(a, b)


class _Forest(BaseBoxTrees):
    """Fitting and walking a forest of trees of class ``_tree_class``."""

    estimators_: list[BoxExtraTreeRegressor | BoxExtraTreeClassifier]

    _parameter_constraints = {
        **BaseBoxTrees._parameter_constraints,
        "n_estimators": [Interval(Integral, 1, _INT32_MAX, closed="both")],
        "bootstrap": ["boolean"],
        "oob_score": ["boolean", callable],
        "max_samples": [
            None,
            Interval(RealNotInt, 0.0, 1.0, closed="right"),
            Interval(Integral, 1, _INT32_MAX, closed="both"),
        ],
        "warm_start": ["boolean"],
        "n_jobs": [Integral, None],
        "random_state": ["random_state"],
        "verbose": ["verbose"],
    }

    def __init__(
        self,
        n_estimators: int = 30,
        *,
        n_tests: int = 500,
        min_samples_split: int | float = 30,
        test_type: TestType = "random",
        test_width: float = 0.1,
        max_retries: int = 10,
        max_depth: int | None = None,
        view_bounds: ViewBounds | None = None,
        column_groups: Sequence[int | Sequence[int]] | None = None,
        relative_width: bool = True,
        refine_tests: bool = True,
        bootstrap: bool = True,
        oob_score: bool | Callable[[np.ndarray, np.ndarray], float] = False,
        max_samples: int | float | None = None,
        warm_start: bool = False,
        n_jobs: int | None = None,
        random_state: RandomStateLike = None,
        verbose: int = 0,
    ) -> None:
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
        self.oob_score = oob_score
        self.max_samples = max_samples
        self.warm_start = warm_start
        self.n_jobs = n_jobs
        self.random_state = random_state
        self.verbose = verbose

    @fit_context(prefer_skip_nested_validation=True)
    def fit(self, X: SetsOrMatrix, y: ArrayLike, sample_weight: ArrayLike | None = None) -> Self:
        """Grow the forest (with ``warm_start``, only the trees it does not have yet).

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
        if not self.bootstrap and self.oob_score:
            raise ValueError("Out of bag estimation only available if bootstrap=True")
        if not self.bootstrap and self.max_samples is not None:
            raise ValueError(f"max_samples={self.max_samples!r} sets the size of the bootstrap "
                             f"samples: use it with bootstrap=True, or set max_samples=None")
        grown = self.estimators_ if self.warm_start and "estimators_" in self.__dict__ else []
        if self.n_estimators < len(grown):
            raise ValueError(f"n_estimators={self.n_estimators} must be larger or equal to "
                             f"len(estimators_)={len(grown)} when warm_start==True")
        if grown and self.n_estimators == len(grown):
            warnings.warn("Warm-start fitting without increasing n_estimators does not fit new "
                          "trees.", UserWarning, stacklevel=3)
        class_weight, subsample = self._class_weight_of_fit()
        before = dict(self.__dict__)
        data = self._fit_data(X, y, sample_weight, class_weight)
        if grown:
            self._check_warm_start(before)
        for name in [name for name in self.__dict__ if name.startswith("oob_") and
                     name.endswith("_")]:
            del self.__dict__[name]     # the estimates of an earlier fit
        # each tree's seed is the one a single fit of all the trees draws for it
        seeds = check_random_state(self.random_state).randint(
            _SEED_MAX, size=self.n_estimators, dtype=np.int64)[len(grown):]
        bootstrap = None
        if self.bootstrap:
            kept = data.labels[data.kept]
            bootstrap = _Bootstrap(self._n_draws(len(kept)), kept if subsample else None)
        params = {name: getattr(self, name) for name in self._tree_class._get_param_names()
                  if name != "random_state"}
        # each new tree fits itself on the data validated here, taking what they taught the
        # forest (its fitted attributes)
        trees = [self._tree_class(**params, random_state=int(seed)) for seed in seeds]
        self.estimators_ = list(grown) + Parallel(
            n_jobs=self.n_jobs, verbose=self.verbose, prefer="threads"
        )(delayed(tree._fit)(data, tree.random_state, bootstrap, pack=False) for tree in trees)
        self._pack(self._trees())
        for k, estimator in enumerate(self.estimators_):    # each walks its share of the pack
            estimator._packed = self._packed.tree(k)
        if self.oob_score:
            self._set_oob_attributes(X, data, bootstrap)
        return self

    def _class_weight_of_fit(self):
        """The ``class_weight`` that weighs the whole training set, and whether each tree
        balances the classes of its own bootstrap sample instead (none for a regressor)."""
        return None, False

    def _n_draws(self, n):
        """The size of each tree's bootstrap sample, of ``n`` samples of positive weight."""
        if self.max_samples is None:
            return n
        if isinstance(self.max_samples, Integral):
            return self.max_samples
        return max(int(self.max_samples * n), 1)

    def _check_warm_start(self, before):
        """Check that the trees of the earlier fit (whose attributes were ``before``) fit the
        data just validated: the same kind of input, attributes, outputs and classes, and
        none of their types missing. If not, restore the earlier fit and raise a ValueError
        naming the difference."""
        changed = [name for name in _KEPT_BY_WARM_START
                   if not _same(before.get(name), self.__dict__.get(name))]
        missing = np.setdiff1d(before["types_"], self.types_)
        if not changed and not missing.size:
            return
        now = dict(self.__dict__)
        self.__dict__.clear()
        self.__dict__.update(before)
        if changed:
            name = changed[0]
            what = f"{name} is {now.get(name)!r}, was {before.get(name)!r}"
        else:
            what = f"the objects of types {missing.tolist()} are missing"
        raise ValueError(f"warm_start grows new trees beside the {len(self.estimators_)} "
                         f"fitted ones, on data of the same kind, but {what}; fit with "
                         f"warm_start=False to start over")

    def _out_of_bag_mean(self, X, data, bootstrap):
        """Each training sample's mean leaf value over the trees whose bootstrap sample left it
        out, shape (n_samples, n_outputs of the trees): NaN for a sample no tree left out
        (with the warning scikit-learn's forests give). The trees' samples are drawn again
        from their seeds."""
        leaves = self._apply(X, self.n_jobs)
        kept = np.flatnonzero(data.kept)
        total = np.zeros((len(leaves), self._packed.n_outputs))
        count = np.zeros(len(leaves))
        for k, estimator in enumerate(self.estimators_):
            out = np.ones(len(leaves), dtype=bool)
            out[kept[bootstrap.counts(estimator.random_state, len(kept)) > 0]] = False
            value = estimator.tree_.value
            total[out] += value.reshape(len(value), -1)[leaves[out, k]]
            count[out] += 1
        if not count.all():
            warnings.warn("Some inputs do not have OOB scores: no tree left them out of its "
                          "bootstrap sample. This probably means too few trees were used to "
                          "compute any reliable OOB estimates; their OOB predictions are NaN "
                          "and oob_score_ leaves them out.", UserWarning, stacklevel=5)
        with np.errstate(invalid="ignore"):
            return total / count[:, None]

    def _set_oob_attributes(self, X, data, bootstrap):
        """Set ``oob_score_`` and the out-of-bag predictions (`_oob_predictions`)."""
        mean = self._out_of_bag_mean(X, data, bootstrap)
        predicted = self._oob_predictions(mean)
        scored = ~np.isnan(mean).any(axis=1)
        score = self.oob_score if callable(self.oob_score) else self._default_oob_score
        self.oob_score_ = score(data.labels[scored], predicted[scored]) if scored.any() \
            else np.nan

    def _trees(self):
        return [e.tree_ for e in self.estimators_] if "estimators_" in self.__dict__ else None

    def apply(self, X: SetsOrMatrix) -> np.ndarray:
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

    def decision_path(self, X: SetsOrMatrix) -> tuple[csr_matrix, np.ndarray]:
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
    def feature_importances_(self) -> np.ndarray:
        """Impurity-based importance of each type of ``types_`` (each column for a feature
        matrix): the weighted variance reduction of the tests on it, normalised per tree,
        averaged over trees, summing to 1 (all zeros if no tree splits).

        Computed from the training data, it says what the trees split on, not what
        predicts well on new data: on held-out object sets, `type_importance` (and
        `region_importance`) measure the loss of score without each type, the set
        counterparts of scikit-learn's ``permutation_importance`` (which permutes the
        columns of a feature matrix, and refuses object sets).

        Returns
        -------
        importances : ndarray of shape (``n_types_``,)
        """
        check_is_fitted(self)
        total = np.mean([t.type_importances(self.types_) for t in self._trees()], axis=0)
        return total / total.sum() if total.sum() > 0 else total

    def __len__(self) -> int:
        """Number of fitted trees."""
        return len(self.estimators_)

    def __getitem__(self, index: int) -> BoxExtraTreeRegressor | BoxExtraTreeClassifier:
        """The ``index``-th fitted tree."""
        return self.estimators_[index]

    def __iter__(self) -> Iterator[BoxExtraTreeRegressor | BoxExtraTreeClassifier]:
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
    test_type : {"fixed", "bounded", "random", "classic"}, default="random"
        How test boxes are drawn in the sampling region:

        - ``"fixed"``: centre uniform, half-width exactly ``test_width`` (square boxes);
        - ``"bounded"``: centre uniform, each half-width uniform in ``(0, test_width]``;
        - ``"random"``: the four bounds uniform in the region, sorted per axis;
        - ``"classic"``: a random axis and a uniform split value; the box is the half-plane
          below it.
    test_width : float, default=0.1
        Half-width (TW) for ``"fixed"`` and ``"bounded"`` tests, along each column of the box:
        in the attributes' units, or with ``relative_width`` a fraction of the sampling
        region's width along that column.
    max_retries : int, default=10
        When none of a node's ``n_tests`` tests splits it, draw up to this many further
        rounds before making it a leaf.
    max_depth : int, default=None
        Maximum tree depth; None grows until the other stopping rules apply.
    view_bounds : array-like of 2 * d floats, float, dict or None, default=None
        Sampling region ``(low_1, high_1, ..., low_d, high_d)`` (for ``[x, y, type]``
        objects, ``(xmin, xmax, ymin, ymax)``), or a half-width ``r`` for ``[-r, r]^d``.
        None: the bounding box of the training objects (for a feature matrix: each node's
        range of the tested column). A dict gives object types their own regions, ``{type
        id: region}`` (each region as above), for objects whose tests matter in different
        places: a region near the agent for the walls it may walk into, the whole view for
        the coins it walks towards; types it does not name are drawn in the training
        objects' bounding box, and names of types absent at fit are ignored.
    column_groups : sequence of sequences of int, default=None
        The groups of attributes a test's box may span, each of 1 to 8 distinct attribute
        indices (an int is a group of one); each test draws one group. None: the first two
        attributes (a position), alone and with each other attribute, ``[(0, 1), (0, 1, 2),
        ..., (0, 1, d - 1)]`` (``[(0,)]`` for ``d = 1``); see ``docs/boxtrees.md`` for the
        measurements behind it.
    relative_width : bool, default=True
        Read ``test_width`` as a fraction of the sampling region's width along each column,
        so that the boxes follow the units of every attribute.
    refine_tests : bool, default=True
        Refine the best of each node's tests on the node's training objects: each finite edge
        of its box is swept across the objects and moved to the tightest position of the best
        score, then the threshold is re-picked as the best one, for up to 3 rounds. Boxes then
        stop where the training data stop supporting them, so that on sets larger than those
        seen at fit the extra background objects do not cross the thresholds. Use it (with
        ``bootstrap=True``) when the sets at prediction may be larger than at training; see
        the set-size study in ``docs/set_sizes.md``. It costs a sort of the node's objects
        of the tested type per refined edge.
    bootstrap : bool, default=True
        Grow each tree on a bootstrap sample (``n_samples`` draws with replacement among the
        samples of positive weight, as weights), as scikit-learn's ``bootstrap``; with
        ``refine_tests`` it makes the refined edges differ from tree to tree, so that the
        forest averages out their errors. A tree's sample is drawn from its seed (its
        ``random_state``), and drawn again from it for the out-of-bag estimates.
    oob_score : bool or callable, default=False
        Score the forest on the out-of-bag samples (``oob_score_``), as scikit-learn's
        forests do; needs ``bootstrap=True``. Each training sample is predicted by the trees
        whose bootstrap sample left it out. True scores with the estimator's ``score``
        metric (R^2 for the regressor, accuracy for the classifier); a callable
        ``score(y_true, y_pred)`` scores with it. Samples no tree left out are not scored
        (a warning says so).
    max_samples : int or float, default=None
        The size of each bootstrap sample, with ``bootstrap=True``: None draws as many
        samples as there are of positive weight, an int that many, a float in ``(0, 1]``
        that fraction of them (at least one).
    warm_start : bool, default=False
        Keep the fitted trees when ``fit`` is called again, and grow only the trees that
        ``n_estimators`` adds (fewer is an error; as many fits none, with a warning). The
        data must be of the same kind (attributes, types, outputs, classes). With the same
        int ``random_state`` and data, the forest is the one a single fit of all the trees
        grows. The out-of-bag estimates are computed again over all the trees, whose
        samples are drawn again with the current ``max_samples``.
    n_jobs : int, default=None
        Number of parallel jobs for ``fit`` (over trees) and large ``predict`` / ``apply``
        calls (over samples). None means 1 unless in a ``joblib.parallel_backend`` context; -1
        means all processors. Trees are built with the GIL released. A prediction called
        from one of the threads of a pool of ``p`` (such as `fqi.FQI`'s per-action threads)
        uses ``n_jobs / p`` of them, at least 1. Results do not depend on ``n_jobs``.
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
        named is read by name at predict. Names on one side only (at fit or at predict)
        warn, as scikit-learn's feature names do: the type ids are then read as they are.
    n_attributes_ : int
        Number of attributes ``d`` of the objects seen at fit (1 for a feature matrix).
    column_groups_ : tuple of tuple of int
        The column groups the tests draw from.
    bounds_ : ndarray of shape (``n_types_``, 2 * ``n_attributes_``)
        Sampling region per type of ``types_``, ``(low, high)`` per attribute.
    n_features_in_ : int
        Number of columns, when fitted on a feature matrix.
    feature_names_in_ : ndarray of str
        Column names, when fitted on a data frame with string column names.
    oob_score_ : float
        Score of the out-of-bag predictions, with ``oob_score``.
    oob_prediction_ : ndarray of shape (n_samples,) or (n_samples, n_outputs)
        Each training sample's mean prediction by the trees whose bootstrap sample left it
        out (NaN when none did), with ``oob_score``.

    See Also
    --------
    BoxExtraTreeRegressor : one tree of the forest.
    GridCounts : the fixed-size grid representation, for any scikit-learn regressor.
    type_importance, region_importance : what the objects of each type, and of each region,
        bring to the score (scikit-learn's ``permutation_importance`` reads ``X`` as a
        feature matrix).
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
    _default_oob_score = staticmethod(r2_score)

    def _oob_predictions(self, mean):
        """Set ``oob_prediction_`` from the out-of-bag mean leaf values; return it."""
        self.oob_prediction_ = mean[:, 0] if self.n_outputs_ == 1 else mean
        return self.oob_prediction_


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
    n_estimators, n_tests, min_samples_split, test_type, test_width, max_retries, max_depth, view_bounds, column_groups, relative_width, refine_tests, bootstrap, oob_score, max_samples, warm_start, n_jobs, random_state, verbose
        As in `BoxExtraTreesRegressor`.
    class_weight : {"balanced", "balanced_subsample"}, dict or list of dicts, default=None
        Weights of the classes, multiplying the sample weights, as in scikit-learn's
        forests: a dict ``{label: weight}`` (a list of them, one per output, for several
        outputs); ``"balanced"`` gives every class of each output the same total weight
        over the training set, ``"balanced_subsample"`` over each tree's bootstrap sample
        (``"balanced"`` without ``bootstrap``). None weighs every class 1.

    Attributes
    ----------
    estimators_ : list of BoxExtraTreeClassifier
        The fitted trees (also ``forest[k]``, ``len(forest)``, ``iter(forest)``).
    classes_ : ndarray, or list of ndarray for several outputs
        The class labels, in the column order of ``predict_proba``.
    n_classes_ : int or list of int
    n_outputs_ : int
    types_, n_types_, type_names_, n_attributes_, column_groups_, bounds_, n_features_in_, feature_names_in_, oob_score_
        As in `BoxExtraTreesRegressor`.
    oob_decision_function_ : ndarray of shape (n_samples, ``n_classes_``), or a list of them per output
        Each training sample's class probabilities by the trees whose bootstrap sample left
        it out (NaN when none did), as `predict_proba` gives them, with ``oob_score``.

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
    _parameter_constraints = {
        **_Forest._parameter_constraints,
        "class_weight": [StrOptions({"balanced", "balanced_subsample"}), dict, list, None],
    }

    def __init__(
        self,
        n_estimators: int = 30,
        *,
        n_tests: int = 500,
        min_samples_split: int | float = 30,
        test_type: TestType = "random",
        test_width: float = 0.1,
        max_retries: int = 10,
        max_depth: int | None = None,
        view_bounds: ViewBounds | None = None,
        column_groups: Sequence[int | Sequence[int]] | None = None,
        relative_width: bool = True,
        refine_tests: bool = True,
        bootstrap: bool = True,
        oob_score: bool | Callable[[np.ndarray, np.ndarray], float] = False,
        max_samples: int | float | None = None,
        warm_start: bool = False,
        class_weight: (Literal["balanced", "balanced_subsample"] | dict[Any, float]
                       | list[dict[Any, float]] | None) = None,
        n_jobs: int | None = None,
        random_state: RandomStateLike = None,
        verbose: int = 0,
    ) -> None:
        super().__init__(
            n_estimators, n_tests=n_tests, min_samples_split=min_samples_split,
            test_type=test_type, test_width=test_width, max_retries=max_retries,
            max_depth=max_depth, view_bounds=view_bounds, column_groups=column_groups,
            relative_width=relative_width, refine_tests=refine_tests, bootstrap=bootstrap,
            oob_score=oob_score, max_samples=max_samples, warm_start=warm_start, n_jobs=n_jobs,
            random_state=random_state, verbose=verbose,
        )
        self.class_weight = class_weight

    def _class_weight_of_fit(self):
        preset = isinstance(self.class_weight, str)
        if preset and self.warm_start:
            warnings.warn(f"class_weight={self.class_weight!r} is computed from the data of each "
                          f"fit: with warm_start, trees grown on other data weigh the classes "
                          f"otherwise. Pass the weights of the full data as a dict (say, from "
                          f"sklearn.utils.class_weight.compute_class_weight) instead",
                          UserWarning, stacklevel=4)
        if preset and self.class_weight == "balanced_subsample":
            return (None, True) if self.bootstrap else ("balanced", False)
        return self.class_weight, False

    def _oob_predictions(self, mean):
        """Set ``oob_decision_function_`` from the out-of-bag mean class frequencies; return
        the most probable classes."""
        proba = self._per_output(mean)
        self.oob_decision_function_ = proba[0] if self.n_outputs_ == 1 else proba
        return self._most_probable(self.oob_decision_function_)

    @staticmethod
    def _default_oob_score(y_true, y_pred):
        """Accuracy: the share of samples whose every output is predicted right
        (scikit-learn's ``accuracy_score`` refuses several outputs of more than 2 classes)."""
        right = np.asarray(y_true == y_pred).reshape(len(y_true), -1)
        return float(right.all(axis=1).mean())
