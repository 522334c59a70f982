"""Synthetic regression data over object sets."""
import numpy as np
from sklearn.utils import check_random_state

from ._objects import ObjectSets, _offsets_from_sizes

__all__ = ["make_box_regression"]


def make_box_regression(
    n_samples=1000,
    *,
    mean_objects=16,
    n_types=4,
    extent=10.0,
    centre=(0.0, 1.0),
    half_width=1.5,
    type_values=(100.0, -300.0),
    noise=10.0,
    random_state=None,
):
    """Random object sets whose target counts objects of some types inside a box.

    Each sample holds a Poisson(``mean_objects``) number of objects, uniform in
    ``[-extent, extent]^2`` with uniform types. The target adds ``type_values[t]`` for every
    object of type ``t < len(type_values)`` within ``half_width`` of ``centre`` (by default:
    +100 per coin, -300 per enemy near ``(0, 1)``, other types are distractors), plus Gaussian
    noise.

    Parameters
    ----------
    n_samples : int, default=1000
    mean_objects : float, default=16
    n_types : int, default=4
    extent : float, default=10.0
    centre : tuple of 2 floats, default=(0.0, 1.0)
    half_width : float, default=1.5
    type_values : sequence of float, default=(100.0, -300.0)
    noise : float, default=10.0
        Standard deviation of the Gaussian noise.
    random_state : int, RandomState instance or None, default=None

    Returns
    -------
    X : ObjectSets of length n_samples
    y : ndarray of shape (n_samples,)
    """
    rng = check_random_state(random_state)
    sizes = rng.poisson(mean_objects, n_samples)
    n = int(sizes.sum())
    data = np.column_stack([rng.uniform(-extent, extent, (n, 2)), rng.randint(0, n_types, n)])
    X = ObjectSets(data, _offsets_from_sizes(sizes))
    values = np.zeros(n_types)
    values[: len(type_values)] = type_values
    near = (np.abs(data[:, :2] - np.asarray(centre)) < half_width).all(axis=1)
    gain = np.where(near, values[data[:, 2].astype(np.intp)], 0.0)
    y = np.bincount(X.sample_index(), weights=gain, minlength=n_samples)
    return X, y + noise * rng.standard_normal(n_samples)
