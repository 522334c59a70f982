"""One Extra-Tree whose node tests count objects in boxes: ``BoxExtraTreeRegressor`` and
``BoxExtraTreeClassifier``."""
from __future__ import annotations

from collections.abc import Sequence
from numbers import Integral
from typing import Self

import numpy as np
from numpy.typing import ArrayLike
from scipy.sparse import csr_matrix
from sklearn.utils import check_random_state
from sklearn.utils._param_validation import Interval
from sklearn.utils.validation import check_is_fitted

from ._base import BaseBoxTrees, ClassificationTargets, RegressionTargets
from ._builder import build_tree
from ._tree import BoxTree
from ._typing import RandomStateLike, SetsOrMatrix, TestType, ViewBounds, fit_context

__all__ = ["BoxExtraTreeClassifier", "BoxExtraTreeRegressor"]

_SEED_MAX = np.iinfo(np.int64).max


def _tree_seed(random_state):
    """The seed of one tree's generator: an int is used as it is, otherwise one is drawn.

    Parameters
    ----------
    random_state : int, RandomState instance or None
        The tree's ``random_state`` parameter (already validated).

    Returns
    -------
    seed : int
        An int in ``[0, 2**63 - 1)`` when drawn.
    """
    if isinstance(random_state, Integral):
        return int(random_state)
    return int(check_random_state(random_state).randint(_SEED_MAX, dtype=np.int64))


class _SingleTree(BaseBoxTrees):
    """Fitting and walking one tree (the regressor and the classifier share it)."""

    tree_: BoxTree

    _parameter_constraints = {
        **BaseBoxTrees._parameter_constraints,
        "random_state": [Interval(Integral, 0, _SEED_MAX, closed="both"), "random_state"],
    }

    def __init__(
        self,
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
        random_state: RandomStateLike = None,
    ) -> None:
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
        self.random_state = random_state

    @fit_context(prefer_skip_nested_validation=True)
    def fit(self, X: SetsOrMatrix, y: ArrayLike, sample_weight: ArrayLike | None = None) -> Self:
        """Grow the tree.

        Parameters
        ----------
        X : sequence of array-like of shape (n_i, d + 1), ObjectSets, or array of shape (n_samples, n_features)
            Object sets (rows ``[f_1, ..., f_d, type]``; empty sets allowed), or a feature
            matrix.
        y : array-like of shape (n_samples,)
            Target values (class labels for a classifier); 2D for several outputs.
        sample_weight : array-like of shape (n_samples,), default=None
            Non-negative weights (see `BoxExtraTreesRegressor.fit`).

        Returns
        -------
        self : estimator
        """
        return self._fit(self._fit_data(X, y, sample_weight), _tree_seed(self.random_state))

    def _fit(self, data, seed, bootstrap=None, pack=True):
        """Grow the tree of ``seed`` on validated training data (`_FitData`; with a
        `_Bootstrap`, on the bootstrap sample of ``seed``), taking the fitted attributes of
        the data: a forest asks each of its trees to fit so, on the data it validated, and
        then hands each its share of the forest's packed trees (``pack=False``)."""
        for name, value in data.fitted.items():
            setattr(self, name, value)
        weight = data.sample_weight
        if bootstrap is not None:
            weight = bootstrap.weights(seed, weight)
        arrays = build_tree(data.objects, data.y, weight, data.params, seed)
        # back in the units of y and of the weights
        arrays["value"] = np.ldexp(arrays["value"], -data.y_exponent)
        arrays["impurity"] = np.ldexp(arrays["impurity"], -2 * data.y_exponent)
        arrays["weighted_n_node_samples"] = np.ldexp(arrays["weighted_n_node_samples"],
                                                     -data.w_exponent)
        self.tree_ = BoxTree.from_builder(self._node_arrays(arrays), self.types_,
                                          self.column_groups_, self.n_attributes_)
        if pack:
            self._pack([self.tree_])
        return self

    def _trees(self):
        return [self.tree_] if "tree_" in self.__dict__ else None

    def apply(self, X: SetsOrMatrix) -> np.ndarray:
        """Return the index of the leaf each sample reaches.

        Parameters
        ----------
        X : object sets or feature matrix, of the kind seen at fit

        Returns
        -------
        X_leaves : ndarray of shape (n_samples,)
            For each sample, the id of the leaf it ends in (a node id of ``tree_``).
        """
        check_is_fitted(self)
        return self._apply(X)[:, 0]

    def decision_path(self, X: SetsOrMatrix) -> csr_matrix:
        """Return the nodes each sample passes through, from the root to its leaf, as a
        CSR indicator matrix of shape ``(n_samples, tree_.node_count)``: 1 where sample
        ``i`` passes through node ``j`` (`X` as for `apply`)."""
        check_is_fitted(self)
        return self._decision_path(X, [self.tree_])[0]

    def get_depth(self) -> int:
        """Length of the longest root-to-leaf path."""
        check_is_fitted(self)
        return self.tree_.max_depth

    def get_n_leaves(self) -> int:
        """Number of leaves."""
        check_is_fitted(self)
        return self.tree_.n_leaves

    @property
    def feature_importances_(self) -> np.ndarray:
        """Impurity-based importance of each type of ``types_`` (each column for a feature
        matrix), summing to 1 (all zeros for a single leaf), shape (``n_types_``,).

        On held-out object sets, `type_importance` measures the loss of score without each
        type: the set counterpart of scikit-learn's ``permutation_importance``, which
        permutes the columns of a feature matrix and refuses object sets.
        """
        check_is_fitted(self)
        return self.tree_.type_importances(self.types_)


class BoxExtraTreeRegressor(RegressionTargets, _SingleTree):
    """One Extra-Tree over sets of objects, with box-count node tests.

    The trees of `BoxExtraTreesRegressor` (its ``estimators_``) are of this class; fitting one
    with the ``random_state`` a forest gave its tree grows that same tree (unless the forest
    bootstraps). See `BoxExtraTreesRegressor` for the test, the split rule and the inputs.

    Parameters
    ----------
    n_tests, min_samples_split, test_type, test_width, max_retries, max_depth, view_bounds, column_groups, relative_width, refine_tests
        As in `BoxExtraTreesRegressor`.
    random_state : int, RandomState instance or None, default=None
        An int in ``[0, 2**63)`` is the seed of the tree's random generator; a RandomState
        or None draws one.

    Attributes
    ----------
    tree_ : BoxTree
        The fitted tree, as flat node arrays.
    types_, n_types_, type_names_, n_attributes_, column_groups_, bounds_, n_features_in_, feature_names_in_
        As in `BoxExtraTreesRegressor`.

    Examples
    --------
    >>> import numpy as np
    >>> from boxtrees import BoxExtraTreeRegressor
    >>> X = [np.array([[0.5, 0.5, 0]]), np.array([[3.0, 3.0, 0]])] * 10
    >>> tree = BoxExtraTreeRegressor(min_samples_split=2, random_state=0).fit(X, [1.0, 0.0] * 10)
    >>> tree.predict([np.array([[0.4, 0.6, 0]]), np.array([[2.9, 2.9, 0]])]).tolist()
    [1.0, 0.0]
    >>> # two leaves: the root's box holds the object at (3, 3), whose sets go right (node 2)
    >>> tree.get_n_leaves(), tree.decision_path(X[:2]).toarray().tolist()
    (2, [[1, 1, 0], [1, 0, 1]])
    """


class BoxExtraTreeClassifier(ClassificationTargets, _SingleTree):
    """One Extra-Tree classifier over sets of objects, with box-count node tests.

    The trees of `BoxExtraTreesClassifier` are of this class. The split criterion is the
    Gini impurity (see `BoxExtraTreesClassifier`); leaves hold class frequencies.

    Parameters
    ----------
    n_tests, min_samples_split, test_type, test_width, max_retries, max_depth, view_bounds, column_groups, relative_width, refine_tests, random_state
        As in `BoxExtraTreeRegressor`.

    Attributes
    ----------
    tree_ : BoxTree
        The fitted tree; ``value`` holds each node's class frequencies.
    classes_ : ndarray, or list of ndarray for several outputs
        The class labels.
    n_classes_ : int or list of int
    n_outputs_ : int
    types_, n_types_, type_names_, n_attributes_, column_groups_, bounds_, n_features_in_, feature_names_in_
        As in `BoxExtraTreesRegressor`.

    Examples
    --------
    >>> import numpy as np
    >>> from boxtrees import BoxExtraTreeClassifier
    >>> X = [np.array([[0.5, 0.5, 0]]), np.array([[3.0, 3.0, 0]])] * 10
    >>> tree = BoxExtraTreeClassifier(min_samples_split=2, random_state=0).fit(X, ["a", "b"] * 10)
    >>> tree.predict([np.array([[0.5, 0.5, 0]]), np.array([[3.0, 3.0, 0]])]).tolist()
    ['a', 'b']
    """
