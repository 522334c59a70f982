"""The grid representation of object sets: per-type object counts in the cells of a grid."""
from __future__ import annotations

from collections.abc import Sequence
from numbers import Integral, Real
from typing import Self

import numpy as np
from numpy.typing import ArrayLike
from sklearn.base import BaseEstimator, TransformerMixin
from sklearn.utils._param_validation import Interval
from sklearn.utils.validation import _check_feature_names_in, check_is_fitted

from ._objects import _MAX_TYPE, ObjectInputMixin, check_view_bounds, columns_of, fitted_region
from ._typing import SetsOrMatrix, fit_context

__all__ = ["GridCounts"]


class GridCounts(ObjectInputMixin, TransformerMixin, BaseEstimator):
    """Count the objects of each type in the cells of an ``n_bins x n_bins`` grid.

    This is the fixed-size "grid" state representation of the thesis: the view is cut into
    ``n_bins x n_bins`` equal cells and each sample becomes the ``n_bins * n_bins * n_types_``
    vector of per-cell, per-type counts, ordered as a C array of shape
    ``(n_bins, n_bins, n_types_)`` indexed ``[x cell, y cell, type]``, the types in the order
    of ``types_``. Objects outside the grid and types not in ``types_`` are ignored. The grid
    lies over two of the objects' attributes, ``columns`` (one for objects of one attribute:
    ``n_bins`` cells along it).

    A 2D feature matrix is read with column ``j`` as a one-dimensional object of type ``j``:
    each column's range is cut into ``n_bins`` cells and the output is the
    ``(n_bins, n_features)`` one-hot binning, flattened.

    Parameters
    ----------
    n_bins : int, default=10
        Number of cells along each axis.
    view_bounds : array-like of 4 floats or float, default=None
        Grid extent ``(xmin, xmax, ymin, ymax)`` over ``columns`` (``(low, high)`` for a grid
        over one column, as for a feature matrix), or a half-width ``r`` for ``[-r, r]^2``.
        None: the bounding box of the objects seen at fit (per column for a feature matrix).
    n_types : int, default=None
        Count the type ids ``0 .. n_types - 1`` (a fixed layout, whatever the data). None:
        count the type ids seen at fit, so the output size follows the types present, not
        the largest id.
    columns : tuple of 2 int, default=None
        The attributes along which the grid's x and y cells lie (objects ``[f_1, ..., f_d,
        type]``: indices into ``f``). None: ``(0, 1)``, the position of ``[x, y, type]``
        objects, or ``(0,)`` for objects of one attribute.

    Attributes
    ----------
    types_ : ndarray of int
        Sorted type ids counted (the column indices for a feature matrix).
    n_types_ : int
        ``len(types_)``.
    n_attributes_ : int
        Number of attributes of the objects seen at fit (1 for a feature matrix).
    columns_ : tuple of int
        The attributes the grid lies over.
    bounds_ : ndarray of shape (``n_types_``, 4)
        Grid extent used for each type, ``(xmin, xmax, ymin, ymax)`` over ``columns_``.
    n_features_in_ : int
        Number of columns, when fitted on a feature matrix.

    Examples
    --------
    >>> import numpy as np
    >>> from boxtrees import GridCounts
    >>> sets = [np.array([[-5.0, -5.0, 0], [5.0, 5.0, 1]]), np.empty((0, 3))]
    >>> GridCounts(n_bins=2, view_bounds=10).fit_transform(sets)
    array([[1., 0., 0., 0., 0., 0., 0., 1.],
           [0., 0., 0., 0., 0., 0., 0., 0.]])
    """

    _parameter_constraints = {
        "n_bins": [Interval(Integral, 1, None, closed="left")],
        "view_bounds": ["array-like", Interval(Real, 0, None, closed="neither"), None],
        "n_types": [Interval(Integral, 1, _MAX_TYPE, closed="both"), None],
        "columns": [tuple, list, None],
    }

    def __init__(self, n_bins: int = 10, *, view_bounds: ArrayLike | float | None = None,
                 n_types: int | None = None, columns: Sequence[int] | None = None) -> None:
        self.n_bins = n_bins
        self.view_bounds = view_bounds
        self.n_types = n_types
        self.columns = columns

    @fit_context(prefer_skip_nested_validation=True)
    def fit(self, X: SetsOrMatrix, y: object = None) -> Self:
        """Learn the grid extent and the number of types.

        Parameters
        ----------
        X : sequence of array-like of shape (n_i, d + 1), ObjectSets, or array of shape (n_samples, n_features)
            Object sets, or a feature matrix.
        y : Ignored
            Not used, present for API consistency by convention.

        Returns
        -------
        self : GridCounts
        """
        sets, _ = self._validate_input(X, reset=True)
        data, d = sets.data, self.n_attributes_
        self.columns_ = _grid_columns(self.columns, d)
        if self._fitted_on_features:
            self.types_ = np.arange(self.n_features_in_)
            self.n_types_ = self.n_features_in_
            if self.view_bounds is None:     # each column's range
                spanned = fitted_region(data[:, 0].reshape(len(sets), -1))
                self.bounds_ = np.column_stack(
                    [spanned, np.zeros((self.n_types_, 2))]).astype(np.float64)
            else:
                bounds = np.pad(check_view_bounds(self.view_bounds, 1), (0, 2))
                self.bounds_ = np.tile(bounds, (self.n_types_, 1))
            return self
        if self.n_types is not None:
            self.types_ = np.arange(self.n_types)
        else:
            self.types_ = np.unique(data[:, d].astype(np.intp)) if len(data) else np.zeros(1, np.intp)
        self.n_types_ = len(self.types_)
        columns = list(self.columns_)
        spanned = fitted_region(data, columns)
        if self.view_bounds is not None:
            bounds = check_view_bounds(self.view_bounds, len(columns))
        elif spanned is not None:
            bounds = spanned.ravel().astype(np.float64)
        else:
            raise ValueError("GridCounts needs view_bounds when X holds no object at all")
        self.bounds_ = np.tile(np.pad(bounds, (0, 4 - len(bounds))), (self.n_types_, 1))
        return self

    def _grid_shape(self):
        """Cells along x and y (one along y for a grid over one column)."""
        return self.n_bins, (self.n_bins if len(self.columns_) == 2 else 1)

    def transform(self, X: SetsOrMatrix) -> np.ndarray:
        """Count objects per cell and type.

        Parameters
        ----------
        X : object sets or feature matrix, of the kind seen at fit

        Returns
        -------
        counts : ndarray of shape (n_samples, n_bins * n_bins * ``n_types_``)
            (``n_bins * n_features`` for a feature matrix.)
        """
        check_is_fitted(self)
        sets, _ = self._validate_input(X, reset=False)
        nx, ny = self._grid_shape()
        n_out = nx * ny * self.n_types_
        data, d, columns = sets.data, self.n_attributes_, self.columns_
        types = np.searchsorted(self.types_, data[:, d].astype(np.intp))
        keep = self.types_[np.minimum(types, self.n_types_ - 1)] == data[:, d]
        types, data, sample = types[keep], data[keep], sets.sample_index()[keep]
        b = self.bounds_[types]
        ix = _cell(data[:, columns[0]], b[:, 0], b[:, 1], nx)
        iy = _cell(data[:, columns[1]], b[:, 2], b[:, 3], ny) if ny > 1 else np.zeros_like(ix)
        inside = (ix >= 0) & (iy >= 0)
        index = sample * n_out + (ix * ny + iy) * self.n_types_ + types
        counts = np.bincount(index[inside], minlength=len(sets) * n_out)
        return counts.reshape(len(sets), n_out).astype(np.float64)

    def get_feature_names_out(self, input_features: ArrayLike | None = None) -> np.ndarray:
        """Names of the output counts: ``"type{t}_x{i}_y{j}"`` (``"{feature}_bin{i}"`` for
        a feature matrix).

        Returns
        -------
        names : ndarray of str
        """
        check_is_fitted(self)
        nx, ny = self._grid_shape()
        if self._fitted_on_features:
            features = _check_feature_names_in(self, input_features)
            names = [f"{f}_bin{i}" for i in range(nx) for f in features]
        else:
            names = [f"type{t}_x{i}_y{j}" for i in range(nx) for j in range(ny) for t in self.types_]
        return np.asarray(names, dtype=object)


def _grid_columns(columns, n_attributes):
    """The attributes a grid lies over: ``columns`` validated, or (0, 1), or (0,) for objects
    of one attribute."""
    if columns is None:
        return (0, 1) if n_attributes >= 2 else (0,)
    checked = columns_of(columns, n_attributes, 2)
    if checked is None:
        raise ValueError(f"columns must be one or two distinct attribute indices in "
                         f"[0, {n_attributes}) (the objects have {n_attributes} attributes "
                         f"before their type); got {columns!r}")
    return checked


def _cell(v, low, high, n_bins):
    """Cell index of each value in ``n_bins`` equal cells of ``[low, high]``; -1 outside."""
    width = high - low
    scale = np.divide(n_bins, width, out=np.zeros_like(width), where=width > 0)
    cell = np.clip(np.floor((v - low) * scale), 0, n_bins - 1).astype(np.intp)
    return np.where((v < low) | (v > high), -1, cell)
