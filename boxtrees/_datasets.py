"""Synthetic regression data over object sets."""
from __future__ import annotations

import math
from numbers import Integral, Real

import numpy as np
from numpy.typing import ArrayLike
from sklearn.utils import check_random_state
from sklearn.utils._param_validation import Interval

from ._objects import _FLOAT32_MAX, _MAX_TYPE, ObjectSets, _offsets_from_sizes
from ._typing import RandomStateLike, validate_params

__all__ = ["make_box_regression"]


def _is_finite(value):
    """Whether the real number ``value`` is finite (an int too large for a float is not)."""
    try:
        return math.isfinite(value)
    except OverflowError:
        return False


def _finite_vector(value: ArrayLike, name: str, shape: tuple[int, ...] | None = None
                   ) -> np.ndarray:
    """``value`` as a float64 array of finite numbers (1D, or of ``shape`` when given), or a
    ValueError naming the parameter ``name``."""
    what = f"The {name!r} parameter of make_box_regression must"
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{what} hold real numbers. Got {value!r} instead.") from None
    if shape is not None and array.shape != shape:
        raise ValueError(f"{what} have shape {shape}. Got {value!r}, of shape {array.shape}, "
                         f"instead.")
    if array.ndim != 1:
        raise ValueError(f"{what} be a 1D sequence of numbers. Got {value!r} instead.")
    if not np.isfinite(array).all():
        raise ValueError(f"{what} hold finite numbers. Got {value!r} instead.")
    return array


@validate_params(
    {
        "n_samples": [Interval(Integral, 1, None, closed="left")],
        "mean_objects": [Interval(Real, 0, None, closed="left")],
        "n_types": [Interval(Integral, 1, _MAX_TYPE, closed="both")],
        "extent": [Interval(Real, 0, _FLOAT32_MAX, closed="right")],
        "centre": ["array-like"],
        "half_width": [Interval(Real, 0, None, closed="neither")],
        "type_values": ["array-like"],
        "noise": [Interval(Real, 0, None, closed="left")],
        "random_state": ["random_state"],
    },
    prefer_skip_nested_validation=True,
)
def make_box_regression(
    n_samples: int = 1000,
    *,
    mean_objects: float = 16,
    n_types: int = 4,
    extent: float = 10.0,
    centre: ArrayLike = (0.0, 1.0),
    half_width: float = 1.5,
    type_values: ArrayLike = (100.0, -300.0),
    noise: float = 10.0,
    random_state: RandomStateLike = None,
) -> tuple[ObjectSets, np.ndarray]:
    """Generate random object sets whose target counts objects of some types inside a box.

    Each sample holds a Poisson(``mean_objects``) number of objects, uniform in
    ``[-extent, extent]^2`` with types uniform in ``0 .. n_types - 1``. The target adds
    ``type_values[t]`` for every object of type ``t < len(type_values)`` within
    ``half_width`` of ``centre`` (by default: +100 per coin, -300 per enemy near ``(0, 1)``,
    other types are distractors), plus Gaussian noise.

    Parameters
    ----------
    n_samples : int, default=1000
        Number of samples (object sets), at least 1.
    mean_objects : float, default=16
        Mean number of objects per set (the Poisson rate), finite and >= 0; 0 gives only
        empty sets.
    n_types : int, default=4
        Number of object types, in ``[1, 2**24]``: type ids are drawn uniformly in
        ``0 .. n_types - 1``. Must be at least ``len(type_values)``.
    extent : float, default=10.0
        Half-side of the square ``[-extent, extent]^2`` the objects are drawn in; positive
        and at most the float32 maximum (about 3.4e38).
    centre : array-like of 2 floats, default=(0.0, 1.0)
        Centre ``(x, y)`` of the box whose objects make the target; finite.
    half_width : float, default=1.5
        Half-width of that (square, open) box: an object counts when both its coordinates
        are strictly within ``half_width`` of ``centre``. Finite and positive.
    type_values : array-like of float, default=(100.0, -300.0)
        ``type_values[t]`` is what each object of type ``t`` inside the box adds to the
        target; types from ``len(type_values)`` on add nothing (distractors). Finite
        numbers, at most ``n_types`` of them; empty makes the target pure noise.
    noise : float, default=10.0
        Standard deviation of the Gaussian noise added to the target, finite and >= 0.
    random_state : int, RandomState instance or None, default=None
        Determines the random numbers. Pass an int for reproducible output across calls.

    Returns
    -------
    X : ObjectSets of length n_samples
        The object sets, rows ``[x, y, type]`` (float32).
    y : ndarray of shape (n_samples,)
        The targets.

    Raises
    ------
    ValueError
        If a parameter is out of its range, naming it (a parameter of the wrong type raises
        scikit-learn's ``InvalidParameterError``, a ValueError and a TypeError).

    Examples
    --------
    >>> from boxtrees import make_box_regression
    >>> X, y = make_box_regression(5, random_state=0)
    >>> len(X), y.shape, X.data.shape[1]
    (5, (5,), 3)
    """
    for name, value in (("mean_objects", mean_objects), ("half_width", half_width),
                        ("noise", noise)):
        if not _is_finite(value):
            raise ValueError(f"The {name!r} parameter of make_box_regression must be "
                             f"finite. Got {value!r} instead.")
    centre = _finite_vector(centre, "centre", shape=(2,))
    type_values = _finite_vector(type_values, "type_values")
    if len(type_values) > n_types:
        raise ValueError(
            f"type_values has {len(type_values)} values but n_types={n_types}: there is at "
            f"most one value per type id 0 .. n_types - 1 (pass a shorter type_values, or "
            f"a larger n_types)"
        )

    rng = check_random_state(random_state)
    sizes = rng.poisson(mean_objects, n_samples)
    n = int(sizes.sum())
    data = np.column_stack([rng.uniform(-extent, extent, (n, 2)), rng.randint(0, n_types, n)])
    X = ObjectSets(data, _offsets_from_sizes(sizes))
    values = np.zeros(n_types)
    values[: len(type_values)] = type_values
    near = (np.abs(data[:, :2] - centre) < half_width).all(axis=1)
    gain = np.where(near, values[data[:, 2].astype(np.intp)], 0.0)
    y = np.bincount(X.sample_index(), weights=gain, minlength=n_samples)
    return X, y + noise * rng.standard_normal(n_samples)
