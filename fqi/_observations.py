"""Observations as the regressors take them: a feature matrix, or object sets.

The observation space of the env decides:

- ``Box``: one flattened float row per observation, a 2D matrix any scikit-learn regressor
  takes;
- ``Sequence(Box(shape=(d + 1,)))``, ``d >= 1``: object sets (rows ``[f_1, ..., f_d, type]``,
  ``[x, y, type]`` for the thesis's game), one `boxtrees.ObjectSets` (``data`` + ``offsets``)
  per batch;
- anything else: a TypeError that names the space and what to wrap it in.
"""
import numpy as np
from gymnasium import spaces

from boxtrees import ObjectSets

__all__ = []


def _observation_format(space):
    """The `_FeatureRows` or `_ObjectRows` reading observations of `space`."""
    if isinstance(space, spaces.Box):
        return _FeatureRows(space)
    if isinstance(space, spaces.Sequence) and isinstance(space.feature_space, spaces.Box):
        return _ObjectRows(space)     # (which checks its rows)
    raise TypeError(f"FQI takes Box observations (feature vectors) or Sequence(Box(shape=(d + "
                    f"1,))) (object sets of [f_1, ..., f_d, type] rows); got {space}: wrap the env in "
                    f"gymnasium.wrappers.FlattenObservation (for Dict, Tuple, Discrete, "
                    f"MultiDiscrete and MultiBinary spaces) or in a gymnasium.ObservationWrapper "
                    f"returning a Box")


class _FeatureRows:
    """``Box`` observations as the rows of a 2D float matrix (float64 for a float64 space,
    else float32)."""

    what = "a 2D float matrix (one flattened observation per row)"

    def __init__(self, space):
        self.space = space
        self.dtype = np.float64 if space.dtype == np.float64 else np.float32
        self.n_features = int(np.prod(space.shape))

    def batch(self, obs, source="the env returned a batch"):
        """A vector env's batched observations as a new matrix, checked to be finite;
        `source` says where they came from in errors."""
        return self._finite(self._matrix(np.array(obs, dtype=self.dtype), source), source)

    def replaced(self, batch, mask, observations):
        """`batch` with the rows of `mask` replaced by `observations`, one each."""
        out = batch.copy()
        out[mask] = self.batch(np.stack([np.asarray(o) for o in observations]))
        return out

    concatenate = staticmethod(np.concatenate)

    def as_input(self, observation):
        """One observation (of the space's shape) or a batch of them, as ``(matrix,
        whether it was one)``."""
        array = np.asarray(observation)
        if array.dtype.kind not in "biuf":
            raise TypeError(f"observation must hold numbers, got dtype {array.dtype}")
        single = array.shape == self.space.shape
        matrix = self._matrix(array[None] if single else array, "the observation is")
        return self._finite(matrix, "the observation is"), single

    def _finite(self, matrix, source):
        if not np.isfinite(matrix).all():
            raise ValueError(f"{source} not finite (NaN or infinite values); the observation "
                             f"space is {self.space}")
        return matrix

    def _matrix(self, array, source):
        shape = self.space.shape
        if array.ndim != len(shape) + 1 or array.shape[1:] != shape:
            raise ValueError(f"{source} of shape {array.shape}; expected {shape} for one "
                             f"observation or (batch, {', '.join(map(str, shape))}) for a "
                             f"batch (observation space {self.space})")
        return array.reshape(len(array), self.n_features).astype(self.dtype, copy=False)


class _ObjectRows:
    """``Sequence(Box(shape=(d + 1,)))`` observations as `boxtrees.ObjectSets`.

    A batch from a vector env is anything with ``data`` and ``offsets`` (a batched engine's
    ragged batch) or one observation per env (gymnasium's batch of a ``Sequence`` space). As
    `predict` input, padded rows ``[f_1, ..., f_d, type, valid]`` (``envs.PaddedObjects``)
    are accepted too.
    """

    what = "boxtrees.ObjectSets (variable-size sets of [f_1, ..., f_d, type] rows)"

    def __init__(self, space):
        self.space = space
        self.width = _row_box(space).shape[0]     # d + 1

    def _rows(self, observation, source="the env returned a batch"):
        """One observation (stacked, or a tuple of rows) as an ``(n, d + 1)`` array."""
        rows = np.asarray(observation, dtype=np.float32)
        if rows.size and (rows.ndim != 2 or rows.shape[1] != self.width):
            raise ValueError(f"{source} with an observation of shape {rows.shape}, but the "
                             f"rows of the observation space {self.space} have {self.width} "
                             f"numbers")
        return rows.reshape(-1, self.width)

    def batch(self, obs, source="the env returned a batch"):
        """A vector env's batched observations as an ObjectSets; `source` says where they
        came from in errors."""
        if hasattr(obs, "data") and hasattr(obs, "offsets"):
            return obs if isinstance(obs, ObjectSets) else ObjectSets(obs.data, obs.offsets)
        return ObjectSets.from_sequence([self._rows(o, source) for o in obs])

    def replaced(self, batch, mask, observations):
        """`batch` with the sets of `mask` replaced by `observations`, one each."""
        new = iter(observations)
        return ObjectSets.from_sequence([self._rows(next(new)) if replace else batch[i]
                                         for i, replace in enumerate(mask)])

    concatenate = staticmethod(ObjectSets.concatenate)

    def as_input(self, observation):
        """One ``(n, d + 1)`` array, or a batch (``data`` + ``offsets``, a list of ``(n_i, d +
        1)`` arrays, a ``(batch, n, d + 1)`` array), or padded rows ``(max_objects, d + 2)``
        / ``(batch, max_objects, d + 2)``; returns ``(ObjectSets, whether it was one)``."""
        if hasattr(observation, "data") and hasattr(observation, "offsets"):
            return self.batch(observation), False
        if isinstance(observation, (list, tuple)):
            return ObjectSets.from_sequence(observation), False
        array = np.asarray(observation)
        if array.dtype.kind not in "biuf":
            raise TypeError(f"observation must hold numbers, got dtype {array.dtype}")
        width = self.width
        if array.ndim in (2, 3) and array.shape[-1] in (width, width + 1):
            single = array.ndim == 2
            sets = array[None] if single else array
            if array.shape[-1] == width + 1:  # padded: keep the valid rows
                return ObjectSets.from_padded(sets[..., :width], sets[..., width] > 0.5), single
            return ObjectSets.from_sequence(list(sets)), single
        raise ValueError(f"observation must be an (n, {width}) array of objects [f_1, ..., f_d, "
                         f"type], a batch of them, or padded (max_objects, {width + 1}) / (batch, "
                         f"max_objects, {width + 1}) rows [f_1, ..., f_d, type, valid] "
                         f"(envs.PaddedObjects); got shape {array.shape}")


def _row_box(space):
    """The ``Box`` of the rows of object-set observations ``Sequence(Box(shape=(d + 1,)))``,
    ``d >= 1``."""
    if not (isinstance(space, spaces.Sequence) and isinstance(space.feature_space, spaces.Box)
            and len(space.feature_space.shape) == 1 and space.feature_space.shape[0] >= 2):
        raise TypeError(f"object-set observations have rows of at least 2 numbers [f_1, ..., "
                        f"f_d, type], Sequence(Box(shape=(d + 1,))); got {space}: wrap the env "
                        f"in a gymnasium.ObservationWrapper that returns such rows")
    return space.feature_space


def _view_bounds(space, n_columns=None):
    """The sampling region of object-set observations: ``(low, high)`` of each of the first
    ``n_columns`` attributes of their rows (None: all), ``(xmin, xmax, ymin, ymax)`` for
    ``[x, y, type]``."""
    box = _row_box(space)
    columns = range(box.shape[0] - 1 if n_columns is None else n_columns)
    view_bounds = tuple(float(v) for c in columns for v in (box.low[c], box.high[c]))
    if not np.isfinite(view_bounds).all():
        raise ValueError(f"the object rows of {space} have unbounded attributes among the "
                         f"first {len(columns)}; give view_bounds, (low, high) of each")
    return view_bounds


def _object_bounds(space, view_bounds=None, n_types=None):
    """The grid's extent (over the rows' first two attributes, the first alone for rows of
    one attribute) and the number of types of object-set observations, read from the bounds
    of their rows' ``Box`` where not given.

    Returns
    -------
    view_bounds : tuple of 4 floats ``(xmin, xmax, ymin, ymax)`` (2 for one attribute)
    n_types : int
    """
    box = _row_box(space)
    if view_bounds is None:
        view_bounds = _view_bounds(space, min(box.shape[0] - 1, 2))
    if n_types is None:
        n_types = len(_type_ids(space))
        if not n_types:
            raise ValueError(f"the object rows of {space} have an unbounded type; give "
                             f"n_types")
    return view_bounds, n_types


def _type_ids(space):
    """The type ids of object-set observations, from the bound of their rows' last column:
    ``range(n_types)``, empty when it is unbounded."""
    high = _row_box(space).high[-1]
    return range(int(high) + 1) if np.isfinite(high) else range(0)
