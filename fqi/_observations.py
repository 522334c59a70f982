"""Observations as the regressors take them: a feature matrix, or object sets.

The observation space of the env decides:

- ``Box``: one flattened float row per observation, a 2D matrix any scikit-learn regressor
  takes;
- ``Sequence(Box(shape=(3,)))``: object sets (rows ``[x, y, type]``), one
  `boxtrees.ObjectSets` (``data`` + ``offsets``) per batch;
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
    if (isinstance(space, spaces.Sequence) and isinstance(space.feature_space, spaces.Box)
            and space.feature_space.shape == (3,)):
        return _ObjectRows(space)
    if isinstance(space, spaces.Sequence) and isinstance(space.feature_space, spaces.Box):
        raise TypeError(f"object-set observations must have rows of 3 numbers [x, y, type] "
                        f"(boxtrees.ObjectSets); got {space}: wrap the env in a "
                        f"gymnasium.ObservationWrapper that keeps those 3 columns")
    raise TypeError(f"FQI takes Box observations (feature vectors) or Sequence(Box(shape=(3,)))"
                    f" (object sets of [x, y, type] rows); got {space}: wrap the env in "
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

    def batch(self, obs):
        """A vector env's batched observations as a new matrix, checked to be finite."""
        matrix = self._matrix(np.array(obs, dtype=self.dtype), batch=True)
        if not np.isfinite(matrix).all():
            raise ValueError(f"the env returned observations with NaN or infinite values "
                             f"(observation space {self.space})")
        return matrix

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
        return self._matrix(array[None] if single else array, batch=False), single

    def _matrix(self, array, batch):
        shape = self.space.shape
        if array.ndim != len(shape) + 1 or array.shape[1:] != shape:
            source = "the env returned a batch" if batch else "observation has"
            raise ValueError(f"{source} of shape {array.shape}; expected {shape} for one "
                             f"observation or (batch, {', '.join(map(str, shape))}) for a "
                             f"batch (observation space {self.space})")
        return array.reshape(len(array), self.n_features).astype(self.dtype, copy=False)


class _ObjectRows:
    """``Sequence(Box(shape=(3,)))`` observations as `boxtrees.ObjectSets`.

    A batch from a vector env is anything with ``data`` and ``offsets`` (a batched engine's
    ragged batch) or one observation per env (gymnasium's batch of a ``Sequence`` space). As
    `predict` input, padded rows ``[x, y, type, valid]`` (``envs.PaddedObjects``) are
    accepted too.
    """

    what = "boxtrees.ObjectSets (variable-size sets of [x, y, type] rows)"

    def __init__(self, space):
        self.space = space

    def batch(self, obs):
        """A vector env's batched observations as an ObjectSets."""
        if hasattr(obs, "data") and hasattr(obs, "offsets"):
            return obs if isinstance(obs, ObjectSets) else ObjectSets(obs.data, obs.offsets)
        return ObjectSets.from_sequence([_rows(o) for o in obs])

    @staticmethod
    def replaced(batch, mask, observations):
        """`batch` with the sets of `mask` replaced by `observations`, one each."""
        new = iter(observations)
        return ObjectSets.from_sequence([_rows(next(new)) if replace else batch[i]
                                         for i, replace in enumerate(mask)])

    concatenate = staticmethod(ObjectSets.concatenate)

    def as_input(self, observation):
        """One ``(n, 3)`` array, or a batch (``data`` + ``offsets``, a list of ``(n_i, 3)``
        arrays, a ``(batch, n, 3)`` array), or padded rows ``(max_objects, 4)`` /
        ``(batch, max_objects, 4)``; returns ``(ObjectSets, whether it was one)``."""
        if hasattr(observation, "data") and hasattr(observation, "offsets"):
            return self.batch(observation), False
        if isinstance(observation, (list, tuple)):
            return ObjectSets.from_sequence(observation), False
        array = np.asarray(observation)
        if array.dtype.kind not in "biuf":
            raise TypeError(f"observation must hold numbers, got dtype {array.dtype}")
        if array.ndim in (2, 3) and array.shape[-1] in (3, 4):
            single = array.ndim == 2
            sets = array[None] if single else array
            if array.shape[-1] == 4:  # padded: keep the valid rows
                sets = [rows[rows[:, 3] > 0.5, :3] for rows in sets]
            return ObjectSets.from_sequence(list(sets)), single
        raise ValueError(f"observation must be an (n, 3) array of objects [x, y, type], a "
                         f"batch of them, or padded (max_objects, 4) / (batch, max_objects, 4) "
                         f"rows [x, y, type, valid] (envs.PaddedObjects); got shape "
                         f"{array.shape}")


def _rows(observation):
    """One observation of a ``Sequence(Box(shape=(3,)))`` space (stacked or a tuple of
    rows) as an ``(n, 3)`` array."""
    return np.asarray(observation, dtype=np.float32).reshape(-1, 3)


def _row_box(space):
    """The ``Box`` of the rows of object-set observations ``Sequence(Box(shape=(3,)))``."""
    if not (isinstance(space, spaces.Sequence) and isinstance(space.feature_space, spaces.Box)
            and space.feature_space.shape == (3,)):
        raise TypeError(f"view bounds and object types are read from object-set "
                        f"observations, Sequence(Box(shape=(3,))); got {space}")
    return space.feature_space


def _view_bounds(space):
    """The view square ``(xmin, xmax, ymin, ymax)`` of object-set observations: the x and y
    bounds of their rows."""
    box = _row_box(space)
    view_bounds = tuple(float(v) for v in (box.low[0], box.high[0], box.low[1], box.high[1]))
    if not np.isfinite(view_bounds).all():
        raise ValueError(f"the object rows of {space} have unbounded x or y; give "
                         f"view_bounds=(xmin, xmax, ymin, ymax)")
    return view_bounds


def _object_bounds(space, view_bounds=None, n_types=None):
    """The view square and number of types of object-set observations, read from the bounds
    of their rows' ``Box`` where not given.

    Returns
    -------
    view_bounds : tuple of 4 floats ``(xmin, xmax, ymin, ymax)``
    n_types : int
    """
    high = _row_box(space).high
    if view_bounds is None:
        view_bounds = _view_bounds(space)
    if n_types is None:
        if not np.isfinite(high[2]):
            raise ValueError(f"the object rows of {space} have an unbounded type; give "
                             f"n_types")
        n_types = int(high[2]) + 1
    return view_bounds, n_types
