"""The regressors compared in the thesis: its box forest and grid counts with a ridge."""
from __future__ import annotations

from collections.abc import Mapping, Sequence

import gymnasium as gym
import numpy as np
from sklearn.base import clone
from sklearn.linear_model import Ridge
from sklearn.pipeline import Pipeline, make_pipeline

from boxtrees import BoxExtraTreesRegressor, GridCounts
from boxtrees._typing import RandomStateLike, TestType, ViewBounds

from ._checks import _check_int, _check_n_jobs, _check_real
from ._envs import _spaces
from ._observations import _object_bounds, _type_ids, _view_bounds
from ._typing import EnvLike

__all__ = ["make_box_forest", "make_grid_ridge"]

def make_box_forest(env: EnvLike | None = None, *, test_type: TestType = "fixed",
                    test_width: float = 1.0, n_estimators: int = 30, n_tests: int = 500,
                    min_samples_split: int | float = 30, n_jobs: int | None = -1,
                    random_state: RandomStateLike = None,
                    view_bounds: ViewBounds | None = None) -> BoxExtraTreesRegressor:
    """A `boxtrees.BoxExtraTreesRegressor` drawing its tests in the env's view square.

    The thesis's forest: its tuned parameters are the defaults (M=30, K=500, n_min=30, fixed
    boxes of half-width TW=1 in the view's units), and its tests are neither refined nor
    grown on bootstrap samples, whatever the estimator's own defaults; ``test_type="classic"``
    is the classic-trees baseline (axis-aligned splits, also on a ``Box`` env's feature
    vector).

    Parameters
    ----------
    env : str, gymnasium.Env, gymnasium.vector.VectorEnv or callable, default=None
        For object-set observations ``Sequence(Box(shape=(d + 1,)))``, the bounds of its
        rows' attributes are the region the tests are drawn in (the view square for
        ``[x, y, type]``). None, or a ``Box`` env: the
        forest draws them in the bounding box of its training data.
    test_type, test_width, n_estimators, n_tests, min_samples_split, n_jobs, random_state
        As in `boxtrees.BoxExtraTreesRegressor` (``n_jobs=-1``: every core), and checked
        here against its parameter constraints rather than at the first fit.
    view_bounds : tuple of 2 * d floats or dict, default=None
        ``(xmin, xmax, ymin, ymax)`` (``(low, high)`` per attribute), instead of the env's;
        or ``{type id: region}``, regions of their own for some types (as
        `boxtrees.BoxExtraTreesRegressor` takes them), the env's for the others.

    Returns
    -------
    regressor : boxtrees.BoxExtraTreesRegressor

    Examples
    --------
    >>> from fqi import make_box_forest
    >>> make_box_forest(view_bounds=(-10, 10, -10, 10), n_estimators=5).n_tests
    500
    """
    if env is not None and (view_bounds is None or isinstance(view_bounds, Mapping)):
        space = _spaces(env)[0]
        if not isinstance(space, gym.spaces.Box):
            whole = _view_bounds(space)
            view_bounds = whole if view_bounds is None else \
                {**dict.fromkeys(_type_ids(space), whole), **view_bounds}
    # what the forest's constraints let through: True for an int, n_jobs=0 (joblib's error)
    n_estimators = _check_int("n_estimators", n_estimators, 1)
    n_tests = _check_int("n_tests", n_tests, 1)
    if n_jobs is not None:
        n_jobs = _check_n_jobs(n_jobs)
    forest = BoxExtraTreesRegressor(
        n_estimators, n_tests=n_tests, min_samples_split=min_samples_split,
        test_type=test_type, test_width=test_width, view_bounds=view_bounds,
        relative_width=False, refine_tests=False, bootstrap=False, max_retries=10,
        n_jobs=n_jobs, random_state=random_state)
    forest._validate_params()  # the rest, now rather than at the first fit
    return forest


def make_grid_ridge(env: EnvLike | None = None, *, n_bins: int = 10, alpha: float = 1.0,
                    view_bounds: Sequence[float] | None = None,
                    n_types: int | None = None) -> Pipeline:
    """The thesis's grid representation: ``make_pipeline(GridCounts(n_bins), Ridge())``.

    Parameters
    ----------
    env : str, gymnasium.Env, gymnasium.vector.VectorEnv or callable, default=None
        An env observing object sets; the bounds of its rows fix the grid extent (the view
        square) and the number of types. Needed unless `view_bounds` and `n_types` are
        given.
    n_bins : int, default=10
        Cells along each axis, at least 1.
    alpha : float, default=1.0
        Ridge penalty, at least 0.
    view_bounds : tuple of 4 floats, default=None
    n_types : int, default=None
        Instead of the env's.

    Returns
    -------
    regressor : sklearn.pipeline.Pipeline

    Examples
    --------
    >>> from fqi import make_grid_ridge
    >>> make_grid_ridge(view_bounds=(-10, 10, -10, 10), n_types=4)[0].n_bins
    10
    """
    if env is None:
        if view_bounds is None or n_types is None:
            raise TypeError("make_grid_ridge needs an env observing object sets, or both "
                            "view_bounds and n_types")
    else:
        view_bounds, n_types = _object_bounds(_spaces(env)[0], view_bounds, n_types)
    grid = GridCounts(_check_int("n_bins", n_bins, 1), view_bounds=view_bounds,
                      n_types=n_types)
    clone(grid).fit([np.empty((0, 3))])  # its checks, now rather than at the first fit
    return make_pipeline(
        grid, Ridge(alpha=_check_real("alpha", alpha, 0.0, np.inf, high_inclusive=False)))
