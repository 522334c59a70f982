"""A fixed-size grid observation, for agents that need a feature vector (SB3 DQN)."""
import gymnasium as gym
import numpy as np
from gymnasium import spaces

from boxtrees import GridCounts

from ._worlds import _world_rules

__all__ = ["GridObservation"]


class GridObservation(gym.ObservationWrapper):
    """Observe the per-cell, per-type object counts of an ``n_bins x n_bins`` grid.

    The featurisation is `boxtrees.GridCounts` over the view square
    ``[-view_size, view_size]^2`` with the env's ``n_types`` types (the thesis's grid
    representation), so the vector is laid out as ``GridCounts.transform`` documents.

    Parameters
    ----------
    env : gymnasium.Env
        An ObjectWorld env (wrappers allowed) with a Discrete action space.
    n_bins : int, default=10
        Cells along each axis.

    Attributes
    ----------
    grid : boxtrees.GridCounts
        The fitted transformer; ``grid.transform(batch)`` featurises a batch of
        observations (e.g. an `envs.RaggedBatch`) at once.

    Examples
    --------
    >>> import gymnasium as gym
    >>> import envs
    >>> from fqi import GridObservation
    >>> env = GridObservation(gym.make("ObjectWorld-v0"), n_bins=10)
    >>> env.reset(seed=0)[0].shape
    (400,)
    """

    def __init__(self, env, n_bins=10):
        super().__init__(env)
        rules = _world_rules(env)
        if not isinstance(env.observation_space, spaces.Sequence):
            raise ValueError(f"GridObservation needs object-set observations (a Sequence "
                             f"space); got {env.observation_space}")
        view = rules.obs_bound
        self.grid = GridCounts(n_bins, view_bounds=(-view, view, -view, view),
                               n_types=rules.n_types).fit([np.empty((0, 3))])
        n_features = len(self.grid.get_feature_names_out())
        self.observation_space = spaces.Box(0.0, np.inf, shape=(n_features,), dtype=np.float32)

    def observation(self, observation):
        return self.grid.transform([observation])[0].astype(np.float32)
