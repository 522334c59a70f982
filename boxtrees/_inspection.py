"""What the objects of each type, and of each region, contribute to a fitted estimator's
score: `type_importance` and `region_importance`, the object-set counterparts of
scikit-learn's ``permutation_importance`` (which reads ``X`` as a feature matrix)."""
from __future__ import annotations

from collections.abc import Callable
from numbers import Integral, Real
from typing import Any, Literal, Protocol

import numpy as np
from numpy.typing import ArrayLike
from sklearn.metrics import check_scoring
from sklearn.utils import Bunch, check_random_state
from sklearn.utils._param_validation import HasMethods, Interval, StrOptions

from ._objects import (ObjectSets, _offsets_from_sizes, as_object_sets, check_view_bounds,
                       fitted_region, is_feature_matrix)
from ._typing import ObjectSetsInput, RandomStateLike, validate_params

__all__ = ["region_importance", "type_importance"]

_COMMON = {
    "estimator": [HasMethods(["predict"])],
    "X": ["array-like"],
    "y": ["array-like", None],
    "types": ["array-like", None],
    "scoring": [str, callable, None],
    "n_repeats": [Interval(Integral, 1, None, closed="left")],
    "sample_weight": ["array-like", None],
    "random_state": ["random_state"],
}


class _Predictor(Protocol):
    """A fitted estimator: anything with ``predict``."""

    def predict(self, X: Any, /) -> Any: ...


class _Scores:
    """The estimator's score on batches of the object sets of ``X`` (``sets``), and on
    ``X`` itself (``baseline``); ``type_names``, the name of each of ``types``, from the
    names of ``X`` or else those the estimator was fitted with (None when unnamed)."""

    def __init__(self, estimator, X, y, types, scoring, sample_weight):
        if is_feature_matrix(X):
            raise TypeError("X is a feature matrix: use "
                            "sklearn.inspection.permutation_importance, which permutes its "
                            "columns; type_importance and region_importance read object sets")
        self.sets = as_object_sets(X)
        present = np.unique(self.sets.data[:, -1]).astype(np.intp)
        self.types = present if types is None else np.asarray(types).ravel()
        if self.types.dtype.kind not in "iu" or not self.types.size:
            raise ValueError(f"types must be one or more type ids (integers); got {types!r}")
        absent = np.setdiff1d(self.types, present)
        if absent.size:
            raise ValueError(f"types {absent.tolist()} have no object in X (its types: "
                             f"{present.tolist()})")
        names = self.sets.type_names
        if names is None:
            names = getattr(estimator, "type_names_", None)
        self.type_names = (names[self.types] if names is not None
                           and self.types.max() < len(names) else None)
        self._score = check_scoring(estimator, scoring=scoring)
        self._estimator, self._y = estimator, y
        self._weight = {} if sample_weight is None else {"sample_weight": sample_weight}
        self.baseline = self(self.sets)

    def __call__(self, sets):
        return float(self._score(self._estimator, sets, self._y, **self._weight))

    def regrouped(self, data, sample_of):
        """Object rows ``data`` gathered into as many sets, row ``i`` into set
        ``sample_of[i]``."""
        order = np.argsort(sample_of, kind="stable")
        sizes = np.bincount(sample_of, minlength=len(self.sets))
        return ObjectSets._trusted(np.ascontiguousarray(data[order]), _offsets_from_sizes(sizes),
                                   self.sets.type_names)

    def importances(self, drops, **fields):
        """The Bunch of score ``drops`` (repeats along the last axis), with ``fields``, and
        ``type_names`` when the types are named."""
        drops = np.asarray(drops, dtype=np.float64)
        if self.type_names is not None:
            fields["type_names"] = self.type_names
        return Bunch(importances_mean=drops.mean(axis=-1), importances_std=drops.std(axis=-1),
                     importances=drops, baseline_score=self.baseline, types=self.types, **fields)


@validate_params(
    {**_COMMON, "method": [StrOptions({"permute", "drop"})]},
    prefer_skip_nested_validation=True,
)
def type_importance(estimator: _Predictor, X: ObjectSetsInput, y: ArrayLike, *,
                    method: Literal["permute", "drop"] = "permute",
                    types: ArrayLike | None = None,
                    scoring: str | Callable[..., float] | None = None, n_repeats: int = 5,
                    sample_weight: ArrayLike | None = None,
                    random_state: RandomStateLike = None) -> Bunch:
    """Importance of each object type: the loss of score when the objects of one type are
    shuffled between the samples, or removed.

    The object-set counterpart of scikit-learn's ``permutation_importance``, whose columns
    are the types here: with ``method="permute"``, each sample gets the objects of that
    type of another sample (a random permutation of the samples), keeping its other
    objects, so the type's objects keep their distribution but lose their link to the
    target; with ``"drop"``, every object of the type is removed.

    Parameters
    ----------
    estimator : estimator
        A fitted estimator that predicts on object sets (say, a `BoxExtraTreesRegressor`, or
        a pipeline of `GridCounts` and a scikit-learn estimator).
    X : sequence of array-like of shape (n_i, d + 1), or ObjectSets
        Object sets (rows ``[f_1, ..., f_d, type]``), held out from the fit to measure
        what generalises.
    y : array-like of shape (n_samples,) or (n_samples, n_outputs)
        Their targets.
    method : {"permute", "drop"}, default="permute"
        Shuffle the type's objects between the samples, or remove them.
    types : array-like of int, default=None
        The type ids to measure; None: every type with objects in ``X``, sorted.
    scoring : str or callable, default=None
        A scikit-learn scorer name or ``scorer(estimator, X, y)``; None: the estimator's
        ``score`` (R^2 for a regressor, accuracy for a classifier).
    n_repeats : int, default=5
        Number of permutations per type (``"drop"`` is not random: one).
    sample_weight : array-like of shape (n_samples,), default=None
        Weights of the samples in the score.
    random_state : int, RandomState instance or None, default=None
        Seeds the permutations.

    Returns
    -------
    result : Bunch
        ``importances_mean``, ``importances_std`` of shape (n_types,) and ``importances`` of
        shape (n_types, n_repeats) (``(n_types, 1)`` for ``"drop"``): the baseline score
        minus the score with the type's objects shuffled or removed; ``baseline_score``;
        ``types``, the type id of each row; ``type_names``, the name of each row, when the
        types are named (by ``X``'s ``type_names``, or else by the estimator's
        ``type_names_``).

    Raises
    ------
    TypeError
        If ``X`` is a feature matrix (use ``sklearn.inspection.permutation_importance``).
    ValueError
        If ``types`` are not type ids, or one of them has no object in ``X``.

    See Also
    --------
    region_importance : where, per type, the objects matter.

    Examples
    --------
    The target of `make_box_regression` adds 100 per object of type 0 and -300 per object of
    type 1 near ``(0, 1)``; types 2 and 3 are distractors:

    >>> from boxtrees import BoxExtraTreesRegressor, make_box_regression, type_importance
    >>> X, y = make_box_regression(800, random_state=0)
    >>> forest = BoxExtraTreesRegressor(10, random_state=0).fit(X[:500], y[:500])
    >>> result = type_importance(forest, X[500:], y[500:], random_state=0)
    >>> result.types.tolist(), result.importances_mean.argsort()[::-1].tolist()[:2]
    ([0, 1, 2, 3], [1, 0])
    >>> bool(abs(result.importances_mean[2]) < 0.05)
    True
    """
    scores = _Scores(estimator, X, y, types, scoring, sample_weight)
    sets, rng = scores.sets, check_random_state(random_state)
    data, sample_of = sets.data, sets.sample_index()
    drops = []
    for t in scores.types:
        mine = data[:, -1] == t
        if method == "drop":
            drops.append([scores.baseline - scores(scores.regrouped(data[~mine],
                                                                    sample_of[~mine]))])
            continue
        repeats = []
        for _ in range(n_repeats):
            # sample i gets the objects of this type of sample permutation[i]
            receiver = np.argsort(rng.permutation(len(sets)))
            owner = np.where(mine, receiver[sample_of], sample_of)
            repeats.append(scores.baseline - scores(scores.regrouped(data, owner)))
        drops.append(repeats)
    return scores.importances(drops)


@validate_params(
    {**_COMMON, "n_bins": [Interval(Integral, 2, None, closed="left")],
     "method": [StrOptions({"drop", "move"})], "extent": ["array-like", Real, None]},
    prefer_skip_nested_validation=True,
)
def region_importance(estimator: _Predictor, X: ObjectSetsInput, y: ArrayLike, *,
                      n_bins: int = 4, method: Literal["drop", "move"] = "drop",
                      types: ArrayLike | None = None, extent: ArrayLike | float | None = None,
                      scoring: str | Callable[..., float] | None = None, n_repeats: int = 5,
                      sample_weight: ArrayLike | None = None,
                      random_state: RandomStateLike = None) -> Bunch:
    """Importance of each region, per object type: a map over a grid of cells on the
    objects' first two attributes (a position), each cell's value the loss of score when
    the objects of that type in the cell are removed, or moved out of it.

    With ``method="drop"`` the cell's objects of the type are removed from every sample;
    with ``"move"`` each is moved to a random position in another cell (uniform among the
    other cells, then within the cell), so the samples keep their numbers of objects and
    only where they are changes. A cell holding no object of the type is 0.

    Parameters
    ----------
    estimator : estimator
        A fitted estimator that predicts on object sets.
    X : sequence of array-like of shape (n_i, d + 1), or ObjectSets
        Object sets (rows ``[f_1, ..., f_d, type]``), held out from the fit.
    y : array-like of shape (n_samples,) or (n_samples, n_outputs)
        Their targets.
    n_bins : int, default=4
        Cells along each of the two attributes (along the one attribute of objects with
        ``d = 1``, where the grid is one row of cells).
    method : {"drop", "move"}, default="drop"
        Remove the cell's objects, or move them to other cells.
    types : array-like of int, default=None
        The type ids to map; None: every type with objects in ``X``, sorted.
    extent : array-like of 4 floats or float, default=None
        The grid's region ``(xmin, xmax, ymin, ymax)`` (``(low, high)`` for ``d = 1``), or a
        half-width ``r`` for ``[-r, r]^2``; None: the bounding box of the objects of ``X``.
        Objects outside it are left alone.
    scoring : str or callable, default=None
        A scikit-learn scorer name or ``scorer(estimator, X, y)``; None: the estimator's
        ``score``.
    n_repeats : int, default=5
        Number of random moves per cell (``"drop"`` is not random: one).
    sample_weight : array-like of shape (n_samples,), default=None
        Weights of the samples in the score.
    random_state : int, RandomState instance or None, default=None
        Seeds the moves.

    Returns
    -------
    result : Bunch
        ``importances_mean``, ``importances_std`` of shape (n_types, n_bins, n_bins) (cell
        ``[k, i, j]``: type ``types[k]``, ``x_edges[i]`` to ``x_edges[i + 1]``,
        ``y_edges[j]`` to ``y_edges[j + 1]``; ``(n_types, n_bins, 1)`` for ``d = 1``) and
        ``importances`` with the repeats along a last axis; ``counts``, the objects of each
        type in each cell, summed over the samples; ``x_edges``, ``y_edges``;
        ``baseline_score``; ``types``; ``type_names`` when the types are named (as in
        `type_importance`).

    Raises
    ------
    TypeError
        If ``X`` is a feature matrix.
    ValueError
        If ``types`` are not type ids, or one of them has no object in ``X``, or ``extent``
        is not a region.

    See Also
    --------
    type_importance : which types matter.

    Examples
    --------
    The objects of type 1 near ``(0, 1)`` drive the target of `make_box_regression`; on a
    5 x 5 grid over ``[-10, 10]^2`` they are in the middle cell:

    >>> import numpy as np
    >>> from boxtrees import BoxExtraTreesRegressor, make_box_regression, region_importance
    >>> X, y = make_box_regression(800, random_state=0)
    >>> forest = BoxExtraTreesRegressor(10, random_state=0).fit(X[:500], y[:500])
    >>> maps = region_importance(forest, X[500:], y[500:], n_bins=5, types=[1], extent=10)
    >>> maps.importances_mean.shape, maps.x_edges.tolist()
    ((1, 5, 5), [-10.0, -6.0, -2.0, 2.0, 6.0, 10.0])
    >>> [int(i) for i in np.unravel_index(maps.importances_mean[0].argmax(), (5, 5))]
    [2, 2]
    """
    scores = _Scores(estimator, X, y, types, scoring, sample_weight)
    sets, rng = scores.sets, check_random_state(random_state)
    data, sample_of = sets.data, sets.sample_index()
    plane = min(sets.n_attributes, 2)          # the attributes the grid is over
    if extent is None:
        region = fitted_region(data, range(plane))
        bounds = np.tile([0.0, 1.0], plane) if region is None else region.ravel()
    else:
        bounds = check_view_bounds(extent, plane, name="extent")
    edges = [np.linspace(bounds[2 * a], bounds[2 * a + 1], n_bins + 1) for a in range(plane)]
    if plane == 1:
        edges.append(np.array([-np.inf, np.inf]))
    shape = (len(edges[0]) - 1, len(edges[1]) - 1)
    cell = np.full(len(data), -1)              # of every object; -1 outside the grid
    inside = np.ones(len(data), dtype=bool)
    for a in range(plane):
        inside &= (data[:, a] >= edges[a][0]) & (data[:, a] <= edges[a][-1])
    index = [np.clip(np.searchsorted(e, data[:, a], side="right") - 1, 0, len(e) - 2)
             for a, e in enumerate(edges[:plane])] + [np.zeros(len(data), dtype=np.intp)]
    cell[inside] = np.ravel_multi_index((index[0][inside], index[1][inside]), shape)
    n_cells = shape[0] * shape[1]
    repeats = 1 if method == "drop" else n_repeats
    drops = np.zeros((len(scores.types), n_cells, repeats))
    counts = np.zeros((len(scores.types), n_cells), dtype=np.intp)
    for k, t in enumerate(scores.types):
        of_type = data[:, -1] == t
        counts[k] = np.bincount(cell[of_type & inside], minlength=n_cells)
        for c in np.flatnonzero(counts[k]):
            mine = of_type & (cell == c)
            if method == "drop":
                drops[k, c] = scores.baseline - scores(scores.regrouped(data[~mine],
                                                                        sample_of[~mine]))
                continue
            for r in range(repeats):
                moved = data.copy()
                # another cell for each object (the cells but c, uniformly), a point in it
                other = rng.randint(n_cells - 1, size=int(mine.sum()))
                other += other >= c
                to = np.unravel_index(other, shape)
                for a in range(plane):
                    moved[mine, a] = rng.uniform(edges[a][to[a]], edges[a][to[a] + 1])
                drops[k, c, r] = scores.baseline - scores(scores.regrouped(moved, sample_of))
    return scores.importances(drops.reshape(len(scores.types), *shape, repeats),
                              counts=counts.reshape(len(scores.types), *shape),
                              x_edges=edges[0], y_edges=edges[1])
