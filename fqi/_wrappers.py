"""A fixed-size grid observation, for agents that need a feature vector (SB3 DQN)."""
from __future__ import annotations

from collections.abc import Sequence

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from boxtrees import GridCounts

from ._observations import _object_bounds, _row_box

__all__ = ["GridObservation"]


class GridObservation(gym.ObservationWrapper):
    """Observe the per-cell, per-type object counts of an ``n_bins x n_bins`` grid.

    The featurisation is `boxtrees.GridCounts` over the view square with ``n_types`` types
    (the thesis's grid representation), so the vector is laid out as
    ``GridCounts.transform`` documents.

    Parameters
    ----------
    env : gymnasium.Env
        An env (wrappers allowed) observing object sets, ``Sequence(Box(shape=(d + 1,)))``
        rows ``[f_1, ..., f_d, type]``; the grid lies over the first two attributes.
    n_bins : int, default=10
        Cells along each axis.
    view_bounds : tuple of 4 floats, default=None
        ``(xmin, xmax, ymin, ymax)`` of the grid; default: the x and y bounds of the
        observation space's rows.
    n_types : int, default=None
        Number of object types; default: the upper bound of the rows' type column, plus 1.

    Attributes
    ----------
    grid : boxtrees.GridCounts
        The fitted transformer; ``grid.transform(batch)`` featurises a batch of
        observations (e.g. a `boxtrees.ObjectSets`) at once.

    Examples
    --------
    >>> import gymnasium as gym
    >>> import numpy as np
    >>> from fqi import GridObservation
    >>> class Objects(gym.Env):  # one object of type 0 at (1, 2); types 0 .. 3 in [-10, 10]^2
    ...     observation_space = gym.spaces.Sequence(gym.spaces.Box(
    ...         np.array([-10, -10, 0]), np.array([10, 10, 3]), dtype=np.float32), stack=True)
    ...     action_space = gym.spaces.Discrete(2)
    ...     def reset(self, *, seed=None, options=None):
    ...         return np.array([[1.0, 2.0, 0.0]], dtype=np.float32), {}
    >>> env = GridObservation(Objects(), n_bins=10)
    >>> obs, _ = env.reset()
    >>> obs.shape, obs.sum()
    ((400,), np.float32(1.0))
    """

    def __init__(self, env: gym.Env, n_bins: int = 10, view_bounds: Sequence[float] | None = None,
                 n_types: int | None = None) -> None:
        super().__init__(env)
        view_bounds, n_types = _object_bounds(env.observation_space, view_bounds, n_types)
        width = _row_box(env.observation_space).shape[0]
        self.grid = GridCounts(n_bins, view_bounds=view_bounds,
                               n_types=n_types).fit([np.empty((0, width))])
        n_features = len(self.grid.get_feature_names_out())
        self.observation_space = spaces.Box(0.0, np.inf, shape=(n_features,), dtype=np.float32)

    def observation(self, observation: np.ndarray) -> np.ndarray:
        return self.grid.transform([observation])[0].astype(np.float32)
