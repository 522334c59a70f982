"""Ragged batches of object sets, and the input checks shared by the estimators.

An object is a row ``[f_1, ..., f_d, type]``: ``d >= 1`` real attributes (a position, a size, a
velocity...) and a non-negative integer type id, last. A sample is a set of objects (possibly
empty). A batch of samples is stored as one ``(n_objects, d + 1)`` float32 array plus offsets,
so it is cheap to build, slice and hand to the Cython core.
"""
from __future__ import annotations

import warnings
from collections.abc import Iterable, Iterator, Sequence
from numbers import Integral
from typing import Any, NoReturn, Protocol, Self, overload

import numpy as np
from numpy.typing import ArrayLike
from scipy.sparse import issparse

from ._layout import MAX_TYPE as _MAX_TYPE
from ._rows import RowProblem, scan_offsets, scan_rows

__all__ = ["ObjectSets"]

_FLOAT32_MAX = float(np.finfo(np.float32).max)
_DEFAULT_WIDTH = 3  # the columns of a batch with no object at all: [x, y, type]


class _Frame(Protocol):
    """A table read by column name: a data frame, or a mapping of names to columns."""

    def __getitem__(self, name: str, /) -> Any: ...


def _offsets_from_sizes(sizes):
    """Offsets ``[0, cumsum(sizes)...]`` of sets with the given sizes."""
    offsets = np.zeros(len(sizes) + 1, dtype=np.intp)
    np.cumsum(sizes, out=offsets[1:])
    return offsets


_ROW_PROBLEMS = {
    RowProblem.NOT_FINITE: "contain NaN or infinite values",
    RowProblem.TOO_LARGE: "have attributes too large for float32 (|value| > 3.4e38)",
    RowProblem.NEGATIVE_TYPE: "have negative type ids; type ids must be integers >= 0",
    RowProblem.NON_INTEGER_TYPE: "have non-integer type ids; type ids must be integers >= 0",
    RowProblem.TYPE_TOO_LARGE: f"have type ids >= {_MAX_TYPE}, which are not supported",
}


def row_error(problem, row, data, what="object sets"):
    """The ValueError for ``problem`` (a `RowProblem`) at ``row`` of ``data``."""
    return ValueError(f"{what} {_ROW_PROBLEMS[problem]} (object row {row}: {data[row].tolist()})")


def _check_type_names(type_names, data):
    """Validate the labels of a batch's type ids: one for each id its rows use."""
    if type_names is None:
        return None
    names = np.asarray(type_names)
    if names.ndim != 1 or len(np.unique(names)) != len(names):
        raise ValueError("type_names must be a 1D sequence of distinct labels")
    if len(data) and data[:, -1].max() >= len(names):
        raise ValueError(f"the objects have type ids up to {int(data[:, -1].max())}, but "
                         f"type_names names {len(names)} types")
    return names


def fitted_region(rows, columns=None):
    """The region the training objects span along ``columns`` of their ``rows`` (a feature
    matrix's columns are one-attribute objects): ``(low, high)`` per column, shape
    (n_columns, 2); None when there is no object. ``columns=None``: every column, read in
    place (a feature matrix is not copied)."""
    if not len(rows):
        return None
    values = rows if columns is None else rows[:, list(columns)]
    return np.column_stack([values.min(axis=0), values.max(axis=0)])


def columns_of(group, n_attributes, most):
    """``group`` (an int, or a sequence of ints) as a tuple of 1 to ``most`` distinct
    attribute indices in ``[0, n_attributes)``, or None when it is not one."""
    group = (group,) if isinstance(group, Integral) else group
    try:
        group = tuple(group)
    except TypeError:
        return None
    if (not group or len(group) > most or len(set(group)) != len(group)
            or not all(isinstance(c, Integral) and 0 <= c < n_attributes for c in group)):
        return None
    return tuple(int(c) for c in group)


def _same_names(a, b):
    """Whether two batches' ``type_names`` are the same (both None, or equal labels)."""
    if a is None or b is None:
        return a is None and b is None
    return len(a) == len(b) and bool((np.asarray(a) == np.asarray(b)).all())


def _check_offsets(offsets, n_rows):
    """Validate batch offsets and return them as a C-contiguous intp array."""
    offsets = np.asarray(offsets)
    if offsets.ndim != 1 or offsets.size == 0 or not np.issubdtype(offsets.dtype, np.integer):
        raise ValueError("offsets must be a non-empty 1D integer array")
    offsets = np.ascontiguousarray(offsets, dtype=np.intp)
    bad = scan_offsets(offsets, n_rows)
    if bad >= 0:
        raise ValueError(
            f"offsets must be non-decreasing from 0 to n_objects={n_rows}; got "
            f"{offsets[bad]} at position {bad} of {len(offsets)}"
        )
    return offsets


def _empty_width(array):
    """The columns of an empty set: its own when it is 2D with at least 2, else [x, y, type]."""
    shape = np.shape(array)
    return shape[1] if len(shape) == 2 and shape[1] >= 2 else _DEFAULT_WIDTH


def _check_rows(data, what="object sets"):
    """Validate object rows and return them as a C-contiguous float32 ``(n, d + 1)`` array."""
    data = np.asarray(data)
    if data.dtype.kind not in "biuf":
        raise TypeError(f"{what} must hold real numbers, got an array of dtype {data.dtype}")
    if data.size == 0:
        return np.empty((0, _empty_width(data)), dtype=np.float32)
    if data.ndim != 2 or data.shape[1] < 2:
        raise ValueError(
            f"{what} must be arrays of shape (n_objects, d + 1) with columns [f_1, ..., f_d, "
            f"type], d >= 1; got shape {data.shape}"
        )
    if data.dtype != np.float32:
        data = data.astype(np.float64, copy=False)
    data = np.ascontiguousarray(data)
    problem, row = scan_rows(data, _FLOAT32_MAX, _MAX_TYPE)
    if problem != RowProblem.OK:
        raise row_error(problem, row, data, what)
    return data.astype(np.float32, copy=False)


class ObjectSets:
    """A batch of object sets stored as one array of rows plus offsets.

    Each object is a row ``[f_1, ..., f_d, type]``: ``d >= 1`` attributes and its type id,
    last (``[x, y, type]`` for positions in the plane). Set ``i`` is
    ``data[offsets[i]:offsets[i + 1]]``. Building one (with the constructor,
    `from_sequence`, `from_features` or `concatenate`) validates its content; slicing and
    indexing return views or compact copies without re-validation. The arrays are
    not frozen (``sets[i]`` is a writable view): the estimators check a batch again each time
    they are given it, and their kernels check every index they read, so a batch changed
    after it was built gets a clear error, never an out-of-bounds access.

    Parameters
    ----------
    data : array-like of shape (n_objects, d + 1)
        Rows ``[f_1, ..., f_d, type]`` of all sets, set after set. Attributes must be finite;
        types non-negative integers.
    offsets : array-like of int of shape (n_sets + 1,)
        Non-decreasing, starting at 0 and ending at ``n_objects``.
    type_names : array-like of shape (n_names,), default=None
        The label of each type id (id ``t`` is ``type_names[t]``), when the types are named
        (`from_frame` names them); the estimators keep the names seen at fit and read the
        ids of a named batch through them.

    Attributes
    ----------
    data, offsets, type_names
        As given (validated).
    shape : tuple of int
        ``(n_sets,)``: a batch is indexed along its sets, as a 1D array of them (which
        scikit-learn's splitters and ``_safe_indexing`` read, and index with
        ``sets[indices, ...]``, keeping the batch and its ``type_names``).

    Examples
    --------
    >>> import numpy as np
    >>> from boxtrees import ObjectSets
    >>> sets = ObjectSets.from_sequence([np.array([[0.5, 1.0, 0]]), np.empty((0, 3))])
    >>> len(sets), sets.sizes.tolist(), sets.n_attributes
    (2, [1, 0], 2)
    """

    # _present_only: made by `from_frame` without ``samples``, so of the samples with objects
    # only (a sample without objects has no row); the batch's parts and joins keep it
    __slots__ = ("data", "offsets", "type_names", "_present_only")
    data: np.ndarray
    offsets: np.ndarray
    type_names: np.ndarray | None
    _present_only: bool

    def __init__(self, data: ArrayLike, offsets: ArrayLike,
                 type_names: ArrayLike | None = None) -> None:
        self.data = _check_rows(data)
        self.offsets = _check_offsets(offsets, len(self.data))
        self.type_names = _check_type_names(type_names, self.data)
        self._present_only = False

    @classmethod
    def _trusted(cls, data: np.ndarray, offsets: np.ndarray,
                 type_names: np.ndarray | None = None, present_only: bool = False) -> Self:
        """Wrap arrays that are already valid (internal: no checks, no copies)."""
        self = cls.__new__(cls)
        self.data, self.offsets, self.type_names = data, offsets, type_names
        self._present_only = present_only
        return self

    @classmethod
    def from_frame(cls, frame: _Frame, *, sample: str, columns: Sequence[str], type: str,
                   samples: ArrayLike | None = None) -> Self:
        """Build from a long table, one row per object: a data frame, or any mapping from
        column names to equal-length columns (pandas, polars, a dict of arrays).

        Parameters
        ----------
        frame : data frame or mapping of str to array-like
            One row per object.
        sample : str
            The column of the sample (set) each object belongs to: any hashable ids.
        columns : sequence of str
            The object's attribute columns, in order (``d = len(columns)``).
        type : str
            The column of the object types: labels of any kind (strings, categories) are
            named, their ids their positions in the sorted labels (`type_names`); integers
            ``>= 0`` are type ids themselves.
        samples : array-like, default=None
            Every sample id, in the order of the sets: samples without objects become empty
            sets (a group-by drops them). None: the ids present, sorted; a sample without
            objects has no row, and so no set (fitting on the batch with the targets of all
            the samples then says so).

        Returns
        -------
        ObjectSets

        Raises
        ------
        ValueError
            If a column is missing or holds bad values, or an object's sample is not in
            ``samples``.

        Examples
        --------
        >>> from boxtrees import ObjectSets
        >>> frame = {"frame": [7, 7, 9], "x": [0.5, 2.0, 1.0], "y": [1.0, 0.0, 3.0],
        ...          "label": ["car", "person", "car"]}
        >>> sets = ObjectSets.from_frame(frame, sample="frame", columns=["x", "y"],
        ...                              type="label", samples=[7, 8, 9])
        >>> sets.sizes.tolist(), sets.type_names.tolist(), sets[0].tolist()
        ([2, 0, 1], ['car', 'person'], [[0.5, 1.0, 0.0], [2.0, 0.0, 1.0]])
        """
        if isinstance(columns, str):
            raise TypeError(f"columns must be a sequence of column names, got the string "
                            f"{columns!r}; wrap one name in a list")
        names = [sample, *columns, type]
        read = {}
        for name in names:
            try:
                read[name] = np.asarray(frame[name])
            except (KeyError, IndexError, TypeError, ValueError):
                raise ValueError(f"the frame has no column {name!r}") from None
        lengths = {len(column) for column in read.values()}
        if len(lengths) != 1 or any(column.ndim != 1 for column in read.values()):
            raise ValueError(f"the columns {names} must be 1D and of one length")
        if not columns:
            raise ValueError("columns must name at least one attribute column")
        attributes = np.column_stack([read[name] for name in columns])
        if attributes.dtype.kind not in "biuf":
            raise TypeError(f"the attribute columns {list(columns)} must hold real numbers, "
                            f"got dtype {attributes.dtype}")
        labels = read[type]
        type_names = None
        if labels.dtype.kind in "biu" or (labels.dtype.kind == "f" and labels.size
                                          and np.isfinite(labels).all()
                                          and (labels == np.floor(labels)).all()):
            ids = labels
        else:
            if labels.size and any(label is None or label != label for label in labels):
                raise ValueError(f"the type column {type!r} has missing labels")
            type_names, ids = np.unique(labels, return_inverse=True)
        ids_of_samples = read[sample]
        known = np.unique(ids_of_samples) if samples is None else np.asarray(samples)
        if known.ndim != 1 or len(np.unique(known)) != len(known):
            raise ValueError("samples must be a 1D sequence of distinct sample ids")
        order = np.argsort(known, kind="stable")
        set_of = np.zeros(len(ids_of_samples), dtype=np.intp)
        found = np.zeros(len(ids_of_samples), dtype=bool)
        if len(known):
            position = np.minimum(np.searchsorted(known[order], ids_of_samples), len(known) - 1)
            set_of, found = order[position], known[order][position] == ids_of_samples
        if not found.all():
            raise ValueError(f"objects of sample {ids_of_samples[~found][0].item()!r} are in the "
                             f"frame, but that sample is not in samples")
        rows = np.argsort(set_of, kind="stable")        # objects in set order, then row order
        data = np.column_stack([attributes, np.asarray(ids, dtype=np.float64)])[rows]
        sizes = np.bincount(set_of, minlength=len(known))
        sets = cls(data.reshape(-1, len(columns) + 1), _offsets_from_sizes(sizes), type_names)
        sets._present_only = samples is None
        return sets

    @classmethod
    def from_sequence(cls, sets: Sequence[ArrayLike]) -> Self:
        """Build from a sequence of ``(n_i, d + 1)`` arrays (empty sets allowed).

        Parameters
        ----------
        sets : sequence of array-like of shape (n_i, d + 1)
            Rows ``[f_1, ..., f_d, type]``; every non-empty set has the same ``d``. An empty
            set may have any shape of size 0.

        Returns
        -------
        ObjectSets
        """
        if len(sets) == 1:  # fast path: one set, as when predicting for a single observation
            data = np.asarray(sets[0])
            if data.size == 0 or (data.ndim == 2 and data.shape[1] >= 2):
                data = _check_rows(data)
                return cls._trusted(data, np.array([0, len(data)], dtype=np.intp))
        arrays, first = [], None    # first: the position and shape of the first non-empty set
        for i, s in enumerate(sets):
            if s is None:
                raise ValueError(f"each object set must be an array of shape (n_objects, d + 1); "
                                 f"set {i} is None")
            a = np.asarray(s)
            if a.size == 0:
                arrays.append(a)
                continue
            if a.ndim != 2 or a.shape[1] < 2:
                raise ValueError(
                    f"each object set must have shape (n_objects, d + 1) with columns "
                    f"[f_1, ..., f_d, type], d >= 1; set {i} has shape {a.shape}"
                )
            if first is None:
                first = (i, a.shape)
            elif a.shape[1] != first[1][1]:
                raise ValueError(
                    f"every object set must have the same columns [f_1, ..., f_d, type]; set "
                    f"{first[0]} has shape {first[1]} but set {i} has shape {a.shape}"
                )
            arrays.append(a)
        if first is None:   # no object at all: the empty sets' width, if they agree
            widths = {_empty_width(a) for a in arrays}
            data = np.empty((0, widths.pop() if len(widths) == 1 else _DEFAULT_WIDTH))
        else:
            data = np.concatenate([a for a in arrays if a.size])
        sizes = np.fromiter((len(a) if a.size else 0 for a in arrays), dtype=np.intp,
                            count=len(arrays))
        return cls._trusted(_check_rows(data), _offsets_from_sizes(sizes))

    @classmethod
    def from_features(cls, X: ArrayLike) -> Self:
        """Read a 2D feature matrix as object sets: column ``j`` is one object of type ``j``.

        The value is the object's one attribute (as float32): rows ``[value, type]``, d = 1.
        Every sample is a set of ``n_features`` objects, one of each type.

        Parameters
        ----------
        X : array-like of shape (n_samples, n_features)
            Real, finite values that fit in float32; at most ``2**24`` features (the type
            ids float32 holds exactly).

        Returns
        -------
        ObjectSets
            ``n_samples`` sets of ``n_features`` objects.

        Raises
        ------
        TypeError
            If ``X`` does not hold real numbers.
        ValueError
            If ``X`` is not 2D, holds NaN, infinite or too large values, or has too many
            features.
        """
        X = np.asarray(X)
        if X.dtype.kind not in "biuf":
            raise TypeError(f"X must hold real numbers, got an array of dtype {X.dtype}")
        if X.ndim != 2:
            raise ValueError(
                f"X must be a 2D feature matrix of shape (n_samples, n_features); got shape {X.shape}"
            )
        if X.dtype.kind == "f" and X.size:
            if not np.isfinite(X).all():
                raise ValueError("X contains NaN or infinite values")
            if X.dtype.itemsize > 4 and np.abs(X).max() > _FLOAT32_MAX:
                raise ValueError("X has values too large for float32 (|value| > 3.4e38)")
        return cls._from_validated_features(X)

    @classmethod
    def _from_validated_features(cls, X):
        """`from_features` of a real, finite 2D matrix (the estimators' ``validate_data``
        has checked it: predict-time batches are not scanned twice)."""
        n_samples, n_features = X.shape
        if n_features > _MAX_TYPE:
            raise ValueError(f"X has {n_features} features; at most {_MAX_TYPE} are supported")
        data = np.empty((n_samples * n_features, 2), dtype=np.float32)
        data[:, 0] = X.ravel()
        data[:, 1] = np.tile(np.arange(n_features, dtype=np.float32), n_samples)
        return cls._trusted(data, _offsets_from_sizes(np.full(n_samples, n_features)))

    @classmethod
    def from_padded(cls, array: ArrayLike, mask: ArrayLike) -> Self:
        """Build from padded rows: sample ``i`` is the rows ``array[i, j]`` where
        ``mask[i, j]`` is true, in order.

        This is the layout of fixed-size observations, such as ``envs.PaddedObjects`` (its
        last column is the mask) or highway-env's kinematics (its ``presence`` column).

        Parameters
        ----------
        array : array-like of shape (n_sets, max_objects, d + 1)
            Rows ``[f_1, ..., f_d, type]``; masked-out rows may hold anything.
        mask : array-like of bool of shape (n_sets, max_objects)
            Which rows are objects.

        Returns
        -------
        ObjectSets

        Examples
        --------
        >>> import numpy as np
        >>> from boxtrees import ObjectSets
        >>> padded = np.array([[[1.0, 2.0, 0], [0, 0, 0]], [[0, 0, 0], [0, 0, 0]]])
        >>> ObjectSets.from_padded(padded, padded[:, :, 0] != 0).sizes.tolist()
        [1, 0]
        """
        array, mask = np.asarray(array), np.asarray(mask)
        if array.ndim != 3:
            raise ValueError(f"padded rows must be an array of shape (n_sets, max_objects, "
                             f"d + 1); got shape {array.shape}")
        if mask.shape != array.shape[:2]:
            raise ValueError(f"mask must have shape {array.shape[:2]} (n_sets, max_objects), "
                             f"one flag per row; got {mask.shape}")
        if mask.dtype != bool:
            if mask.dtype.kind not in "biu" or not np.isin(mask, (0, 1)).all():
                raise TypeError(f"mask must hold booleans (or 0/1), got dtype {mask.dtype}")
            mask = mask.astype(bool)
        data = _check_rows(array[mask].reshape(-1, array.shape[2]))
        return cls._trusted(data, _offsets_from_sizes(mask.sum(axis=1)))

    @classmethod
    def concatenate(cls, batches: Iterable[ObjectSets]) -> Self:
        """Join several batches into one, set order preserved.

        Each batch is checked as the constructor checks its arguments (its arrays may have
        changed since it was built), in one pass over its rows and offsets.

        Parameters
        ----------
        batches : iterable of ObjectSets
            The batches, in order; none gives an empty batch.

        Returns
        -------
        ObjectSets
            ``len(result) == sum(len(b) for b in batches)``.

        Raises
        ------
        TypeError
            If ``batches`` is not an iterable of ObjectSets (a single ObjectSets must be
            wrapped in a list).
        ValueError
            If the rows or offsets of a batch are invalid, naming the batch.
        """
        if isinstance(batches, ObjectSets) or _is_ragged_batch(batches):
            raise TypeError("ObjectSets.concatenate takes an iterable of ObjectSets, got a single "
                            "batch; wrap it in a list")
        try:
            batches = list(batches)
        except TypeError:
            raise TypeError(f"ObjectSets.concatenate takes an iterable of ObjectSets, got "
                            f"{type(batches).__name__}") from None
        if not batches:
            return cls._trusted(np.empty((0, _DEFAULT_WIDTH), dtype=np.float32),
                                np.zeros(1, dtype=np.intp))
        data, sizes, width = [], [], None
        for i, batch in enumerate(batches):
            if not isinstance(batch, ObjectSets):
                raise TypeError(
                    f"ObjectSets.concatenate takes ObjectSets; batch {i} is a "
                    f"{type(batch).__name__} (wrap arrays with ObjectSets(data, offsets) or "
                    f"ObjectSets.from_sequence)"
                )
            rows = _check_rows(batch.data, what=f"the rows of batch {i} of ObjectSets.concatenate")
            try:
                offsets = _check_offsets(batch.offsets, len(rows))
            except ValueError as error:
                raise ValueError(f"batch {i} of ObjectSets.concatenate: {error}") from None
            if len(rows):
                if width is not None and rows.shape[1] != width[1]:
                    raise ValueError(f"every batch of ObjectSets.concatenate must have the same "
                                     f"columns; batch {width[0]} has {width[1]} but batch {i} "
                                     f"has {rows.shape[1]}")
                width = width or (i, rows.shape[1])
            data.append(rows)
            sizes.append(np.diff(offsets))
        if width is not None:   # batches with no object may have other widths
            data = [rows if len(rows) else rows.reshape(0, width[1]) for rows in data]
        else:
            data = [np.empty((0, data[0].shape[1]), dtype=np.float32)]
        names = batches[0].type_names
        if any(not _same_names(batch.type_names, names) for batch in batches):
            raise ValueError("the batches of ObjectSets.concatenate must name their types alike "
                             "(the same type_names, or none)")
        return cls._trusted(np.concatenate(data), _offsets_from_sizes(np.concatenate(sizes)),
                            names, any(batch._present_only for batch in batches))

    def __len__(self) -> int:
        return len(self.offsets) - 1

    @property
    def sizes(self) -> np.ndarray:
        """Number of objects of each set, shape (n_sets,)."""
        return np.diff(self.offsets)

    @property
    def n_objects(self) -> int:
        """Total number of objects."""
        return len(self.data)

    @property
    def n_attributes(self) -> int:
        """Number of attributes of each object (``d``: its columns but the type)."""
        return self.data.shape[1] - 1

    def sample_index(self) -> np.ndarray:
        """The set each object row belongs to, shape (n_objects,)."""
        return np.repeat(np.arange(len(self), dtype=np.intp), self.sizes)

    @overload
    def __getitem__(self, index: int | np.integer) -> np.ndarray: ...

    @overload
    def __getitem__(self, index: slice | Sequence[int] | np.ndarray) -> ObjectSets: ...

    def __getitem__(self, index):
        """``sets[i]`` is the ``(n_i, d + 1)`` array of set ``i`` (a view); slices, integer arrays
        and boolean masks give a new ``ObjectSets``, with the same ``type_names``. An index
        may be followed by an ellipsis, ``sets[index, ...]``, as for a 1D array of sets."""
        if isinstance(index, tuple) and len(index) == 2 and index[1] is Ellipsis:
            index = index[0]
        if isinstance(index, Integral):
            n = len(self)
            if not -n <= index < n:
                raise IndexError(f"index {index} out of range for {n} object sets")
            index %= n
            return self.data[self.offsets[index] : self.offsets[index + 1]]
        if isinstance(index, slice):
            start, stop, step = index.indices(len(self))
            if step == 1:
                stop = max(start, stop)
                offsets = self.offsets[start : stop + 1]
                return ObjectSets._trusted(self.data[offsets[0] : offsets[-1]], offsets - offsets[0],
                                           self.type_names, self._present_only)
            index = np.arange(start, stop, step)
        index = np.asarray(index)
        if index.dtype == bool:
            if index.shape != (len(self),):
                raise IndexError(f"boolean mask of shape {index.shape} for {len(self)} sets")
            index = np.flatnonzero(index)
        elif not np.issubdtype(index.dtype, np.integer) or index.ndim != 1:
            raise IndexError("ObjectSets index must be an int, a slice, or a 1D int/bool array")
        index = np.where(index < 0, index + len(self), index)
        if index.size and (index.min() < 0 or index.max() >= len(self)):
            raise IndexError(f"index out of range for {len(self)} object sets")
        starts, sizes = self.offsets[index], self.sizes[index]
        offsets = _offsets_from_sizes(sizes)
        rows = np.repeat(starts - offsets[:-1], sizes) + np.arange(offsets[-1])
        return ObjectSets._trusted(self.data[rows], offsets, self.type_names, self._present_only)

    def __iter__(self) -> Iterator[np.ndarray]:
        for i in range(len(self)):
            yield self.data[self.offsets[i] : self.offsets[i + 1]]

    def __repr__(self) -> str:
        return (f"ObjectSets(n_sets={len(self)}, n_objects={self.n_objects}, "
                f"n_attributes={self.n_attributes})")

    def __array__(self, dtype: object = None, copy: bool | None = None) -> NoReturn:
        """Refused: a batch of sets is no array of features. scikit-learn's
        ``permutation_importance`` converts ``X`` with NumPy, and gets this error rather than
        one from inside NumPy."""
        raise TypeError(
            "ObjectSets is a batch of sets of objects, not an array of features: scikit-learn "
            "tools that read X as a feature matrix (sklearn.inspection.permutation_importance, "
            "partial_dependence) do not apply to it; boxtrees.type_importance and "
            "boxtrees.region_importance measure what the objects of each type, and of each "
            "region, bring to a score")

    @property
    def shape(self) -> tuple[int]:
        """``(n_sets,)``: the batch's length, as the shape of a 1D array of sets."""
        return (len(self),)

    def __getstate__(self) -> dict[str, Any]:
        return {"data": self.data, "offsets": self.offsets, "type_names": self.type_names,
                "present_only": self._present_only}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.data, self.offsets = state["data"], state["offsets"]
        self.type_names = state.get("type_names")
        self._present_only = state.get("present_only", False)


def _is_ragged_batch(X):
    """Duck-typed ObjectSets: ``data`` rows plus ``offsets`` (not a data frame, not a sparse
    DIA matrix, which has attributes of those names)."""
    return (
        hasattr(X, "offsets") and hasattr(X, "data")
        and not hasattr(X, "columns") and not issparse(X)
    )


def _is_set_like(item):
    """Whether one item of a sequence looks like an object set (2D or empty), without
    converting it."""
    ndim = getattr(item, "ndim", None)
    if ndim is not None:
        return ndim >= 2 or item.size == 0
    if isinstance(item, (list, tuple)):
        return len(item) == 0 or isinstance(item[0], (list, tuple)) or getattr(item[0], "ndim", 0) >= 1
    return False


def _is_sequence_of_items(X):
    """A list, a tuple, a 1D object array or a pandas Series of objects."""
    if isinstance(X, (list, tuple)):
        return True
    return getattr(X, "ndim", None) == 1 and getattr(X, "dtype", None) == object


def _no_samples_error(estimator):
    """The ValueError for an ``X`` with no sample, saying what a sample is."""
    return ValueError(
        f"X is empty (0 samples), but {type(estimator).__name__} needs at least one: a sample "
        f"is a set of objects, an array of shape (n_objects, d + 1) of rows [f_1, ..., f_d, "
        f"type] (a set may be empty, the batch may not), or a row of a feature matrix")


def _long_table_error(X, n_targets, error):
    """The ValueError for a data frame ``X`` that failed to read as a feature matrix
    (``error``) and looks like a long table of objects, one row per object: columns that do
    not hold numbers, or more rows than the ``n_targets`` (None: unknown). None for any
    other ``X``."""
    if not hasattr(X, "columns") or not hasattr(X, "__getitem__"):
        return None
    other = [name for name in X.columns if np.asarray(X[name]).dtype.kind not in "biuf"]
    if other:
        reason = f"its columns {other} do not hold numbers"
    elif n_targets is not None and len(X) > n_targets:
        reason = f"it has {len(X)} rows for {n_targets} targets"
    else:
        return None
    return ValueError(
        f"X is a data frame, read as a feature matrix (one row per sample), but {reason} "
        f"({error}). If X is a long table of objects (one row per object), build the sets "
        f"with ObjectSets.from_frame(X, sample=<sample column>, columns=[<attribute columns>], "
        f"type=<type column>, samples=<every sample id, in the order of y>)")


def is_feature_matrix(X):
    """Whether ``X`` is read as a 2D feature matrix rather than as object sets.

    Object sets are an :class:`ObjectSets` (or any object with ``data`` and ``offsets``
    arrays, such as the batched observations of ``envs``), a 3D array (rejected there: padded
    rows need their mask, `ObjectSets.from_padded`), or a sequence (list, tuple, 1D object array, pandas Series)
    of which any item is a 2D array or empty: the sets path then names the position of every
    item that is not a set. Anything else (2D arrays, data frames, sparse matrices, lists of
    rows, and invalid inputs) goes the feature-matrix way, where scikit-learn's own validation
    reports what is wrong with it.
    """
    if isinstance(X, ObjectSets) or _is_ragged_batch(X):
        return False
    if isinstance(X, np.ndarray) and X.ndim == 3:
        return False
    if _is_sequence_of_items(X):
        return not (isinstance(X, np.ndarray) or any(_is_set_like(item) for item in X))
    return True


def as_object_sets(X):
    """Return object-set input ``X`` (see :func:`is_feature_matrix`) as validated ObjectSets.

    An ``ObjectSets`` is validated again (its arrays may have changed since it was built; no
    copy is made when they are still float32 and intp).
    """
    if isinstance(X, ObjectSets) or _is_ragged_batch(X):
        return ObjectSets(X.data, X.offsets, getattr(X, "type_names", None))
    if isinstance(X, np.ndarray) and X.ndim == 3:
        raise ValueError(
            f"X is a 3D array of shape {X.shape}: its rows may be padding, which would be read "
            f"as objects. Pass ObjectSets.from_padded(X, mask) with the mask of the rows that "
            f"are objects, or a list of (n_i, d + 1) arrays"
        )
    return ObjectSets.from_sequence(list(X) if hasattr(X, "iloc") else X)


def _check_targets(y):
    """``y`` as one column (1D) or several (2D); a column vector becomes 1D, with the
    warning scikit-learn gives."""
    from sklearn.exceptions import DataConversionWarning

    y = np.asarray(y)
    if y.ndim == 2 and y.shape[1] == 1:
        warnings.warn("A column-vector y was passed when a 1d array was expected. Please "
                      "change the shape of y to (n_samples,), for example using ravel().",
                      DataConversionWarning, stacklevel=4)
        y = y[:, 0]
    if y.ndim not in (1, 2) or (y.ndim == 2 and y.shape[1] == 0):
        raise ValueError(f"y must have shape (n_samples,) or (n_samples, n_outputs); got {y.shape}")
    return y


def check_view_bounds(view_bounds, n_attributes=2, name="view_bounds"):
    """Validate ``view_bounds`` (``(low_1, high_1, ..., low_d, high_d)``, for ``d = 2``
    ``(xmin, xmax, ymin, ymax)``, or a half-width ``r`` for ``[-r, r]^d``) and return it as a
    float array of ``2 * n_attributes``; the errors call it ``name``."""
    bounds = np.asarray(view_bounds, dtype=np.float64)
    if bounds.ndim == 0:
        bounds = np.tile([-bounds, bounds], n_attributes)
    if bounds.shape != (2 * n_attributes,) or not np.isfinite(bounds).all():
        what = "(xmin, xmax, ymin, ymax)" if n_attributes == 2 else \
            f"(low, high) of each of the {n_attributes} attributes"
        raise ValueError(
            f"{name} must be {what} of finite numbers or a positive half-width; got "
            f"{view_bounds!r}"
        )
    if np.abs(bounds).max() > _FLOAT32_MAX:
        raise ValueError(f"{name} must fit in float32 (|value| <= 3.4e38); got {view_bounds!r}")
    if (bounds[0::2] >= bounds[1::2]).any():
        raise ValueError(f"{name} needs each low below its high (xmin < xmax, ymin < ymax); "
                         f"got {view_bounds!r}")
    single = bounds.astype(np.float32)
    if (single[0::2] >= single[1::2]).any():
        raise ValueError(f"{name} collapses to an empty region in float32; got {view_bounds!r}")
    return bounds


class ObjectInputMixin:
    """Input handling shared by the estimators that accept object sets or a feature matrix.

    A feature matrix goes through scikit-learn's ``validate_data`` (dtype, finiteness, feature
    names, ``n_features_in_``) and is then read as object sets whose column ``j`` is a
    one-dimensional object of type ``j``. The kind seen at fit is remembered, and predicting
    or transforming with the other kind is an error.
    """

    def _named_as_fitted(self, sets):
        """``sets`` with its type ids read through its type names into the ids of the names
        seen at fit (a name not seen at fit gets an id no test reads).

        Names on one side only warn, as scikit-learn's feature names do: the ids are then
        read as they are, which is right only if they are numbered as at fit.
        """
        fitted = getattr(self, "type_names_", None)
        if (sets.type_names is None) != (fitted is None):
            has, was, read = (
                ("does not have", "with", "its type id t is read as the type named "
                 "type_names_[t]") if fitted is not None else
                ("has", "without", "its type ids are read as the ids seen at fit, and its "
                 "names ignored"))
            warnings.warn(f"X {has} type names, but {type(self).__name__} was fitted {was} "
                          f"type names: {read}. Name the types of both (ObjectSets.from_frame, "
                          f"or ObjectSets with type_names) to have them read by name",
                          UserWarning)
        if sets.type_names is None or fitted is None or _same_names(sets.type_names, fitted):
            return sets
        ids = {name: i for i, name in enumerate(fitted.tolist())}
        table = np.array([ids.get(name, len(fitted)) for name in sets.type_names.tolist()],
                         dtype=np.float32)
        data = sets.data.copy()
        if len(data):
            data[:, -1] = table[data[:, -1].astype(np.intp)]
        return ObjectSets._trusted(data, sets.offsets, fitted)

    def _one_set(self, X):
        """The fast path of `_validate_input` at predict time, for the input of a single
        observation: ``X`` a list or tuple of one non-empty 2D NumPy array whose rows have the
        fitted width, given to an estimator fitted on object sets without type names. Returns
        the validated ObjectSets, or None for any other ``X`` (which takes the general path).

        The general path would run the same checks on such an ``X``, in this order: it is not
        empty, it is read as object sets (a 2D item), the estimator was fitted on sets, then
        `_check_rows` of the array (whose errors are raised here as they are there), the
        width, and no type names on either side (no warning, no renaming)."""
        if type(X) is not list and type(X) is not tuple or len(X) != 1:
            return None
        data = X[0]
        if (type(data) is not np.ndarray or data.ndim != 2 or not data.shape[0]
                or data.shape[1] != self.__dict__.get("n_attributes_", -2) + 1
                or self.__dict__.get("_fitted_on_features", True)
                or self.__dict__.get("type_names_") is not None):
            return None
        data = _check_rows(data)
        return ObjectSets._trusted(data, np.array((0, len(data)), dtype=np.intp))

    def _validate_input(self, X, y=None, *, reset, requires_y=False, matrix=False):
        """Validate ``X`` (and ``y``) and return ``(sets, y)``; with ``matrix``, a feature
        matrix is returned as the validated float32 matrix instead of as object sets."""
        if not reset and not requires_y:
            sets = self._one_set(X)
            if sets is not None:
                return sets, None
        from sklearn.utils.validation import check_array, validate_data

        if requires_y and issparse(y):
            raise TypeError(f"sparse targets are not supported: y is a {type(y).__name__}; "
                            f"pass a dense array (y.toarray())")
        if (isinstance(X, (list, tuple)) or getattr(X, "ndim", None) == 1) and not len(X):
            raise _no_samples_error(self)
        dense = is_feature_matrix(X)
        if not reset:
            fitted_dense = self._fitted_on_features
            if dense and not fitted_dense:
                raise ValueError(
                    f"{type(self).__name__} was fitted on object sets, but X is read as a 2D "
                    f"feature matrix; pass a sequence of (n_i, d + 1) arrays or an ObjectSets "
                    f"(ObjectSets.from_frame reads a long table, one row per object; a single "
                    f"object set must be wrapped in a list)"
                )
            if not dense and fitted_dense:
                raise ValueError(
                    f"{type(self).__name__} was fitted on a feature matrix with "
                    f"{self.n_features_in_} features, but X holds object sets"
                )
        if dense:
            try:
                if requires_y:
                    X, y = validate_data(self, X, y, reset=reset, dtype=np.float32,
                                         multi_output=True, y_numeric=self._y_numeric)
                else:
                    X = validate_data(self, X, reset=reset, dtype=np.float32)
            except ValueError as error:
                long_table = _long_table_error(X, len(y) if hasattr(y, "__len__") else None,
                                               error)
                if long_table is None:
                    raise
                raise long_table from error
            sets = X if matrix else ObjectSets._from_validated_features(X)
            n_attributes = 1
        else:
            sets = as_object_sets(X)
            n_attributes = sets.n_attributes
            if reset:
                for attr in ("n_features_in_", "feature_names_in_"):
                    self.__dict__.pop(attr, None)
                if len(sets) == 0:
                    raise _no_samples_error(self)
            elif n_attributes != self.n_attributes_:
                if sets.n_objects:
                    raise ValueError(
                        f"X has objects of {n_attributes + 1} columns, but "
                        f"{type(self).__name__} was fitted on objects of "
                        f"{self.n_attributes_ + 1} columns ([f_1, ..., f_d, type], d = "
                        f"{self.n_attributes_})")
                n_attributes = self.n_attributes_   # no object: nothing to read
                sets = ObjectSets._trusted(sets.data.reshape(0, n_attributes + 1), sets.offsets,
                                           sets.type_names)
            if requires_y:
                if y is None:
                    raise ValueError(f"{type(self).__name__} requires y to be passed, but the target y is None")
                y = check_array(y, ensure_2d=False, dtype=np.float64 if self._y_numeric else None,
                                input_name="y")
        if reset:
            self._fitted_on_features = dense
            self.n_attributes_ = n_attributes
            self.__dict__.pop("type_names_", None)
            if not dense and sets.type_names is not None:
                self.type_names_ = sets.type_names
        elif not dense:
            sets = self._named_as_fitted(sets)
        if requires_y:
            y = _check_targets(y)
            if len(y) != len(sets):
                dropped = ""
                if isinstance(X, ObjectSets) and X._present_only and len(X) < len(y):
                    dropped = ("; X was built by ObjectSets.from_frame without samples, so the "
                               "samples without objects (no row in the frame) have no set: pass "
                               "samples=<every sample id, in the order of y> to give them empty "
                               "sets")
                raise ValueError(f"X has {len(sets)} samples but y has {len(y)}{dropped}")
        return sets, y
