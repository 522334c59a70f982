"""A fixed-size observation for libraries that cannot take `Sequence` spaces."""
from numbers import Integral

import gymnasium as gym
import numpy as np
from gymnasium import spaces

__all__ = ["PaddedObjects", "strip_padding"]


class PaddedObjects(gym.ObservationWrapper, gym.utils.RecordConstructorArgs):
    """Pad the object set to a fixed ``(max_objects, d + 2)`` `Box` (e.g. for stable-baselines3).

    Row ``j`` is ``[f_1, ..., f_d, type, valid]`` (``[dx, dy, type, valid]`` for the
    thesis's game): the first ``n`` rows hold the observed objects with ``valid = 1``, the
    remaining rows are zeros (``valid = 0``). `strip_padding` turns padded observations
    back into object sets. When more than `max_objects` objects are observed, the
    `max_objects` nearest to the agent are kept (in their original order), the distance
    read off the first two attributes (the first alone when ``d = 1``), which are the
    position relative to the agent in every env of this package. The wrapper records
    `max_objects` in the env's spec, so ``gymnasium.make(env.spec)`` rebuilds it.

    Parameters
    ----------
    env : gymnasium.Env
        An environment whose observation space is ``Sequence(Box(d + 1,), stack=True)``
        with ``d >= 1``, such as `ObjectWorldEnv` or `AtariObjects`.
    max_objects : int
        Number of rows of the padded observation.

    Raises
    ------
    TypeError
        If `max_objects` is not an int (bools and floats such as ``8.0`` included).
    ValueError
        If `max_objects` is below 1, or the env's observation space is not
        ``Sequence(Box(d + 1,), stack=True)``.

    Examples
    --------
    >>> import gymnasium as gym
    >>> import envs
    >>> env = envs.PaddedObjects(gym.make("ObjectWorld-v0"), max_objects=128)
    >>> obs, _ = env.reset(seed=0)
    >>> obs.shape, envs.strip_padding(obs)[0].shape[1]
    ((128, 4), 3)
    """

    def __init__(self, env, max_objects):
        gym.utils.RecordConstructorArgs.__init__(self, max_objects=max_objects)
        gym.ObservationWrapper.__init__(self, env)
        space = env.observation_space
        if not (isinstance(space, spaces.Sequence) and space.stack
                and isinstance(space.feature_space, spaces.Box)
                and len(space.feature_space.shape) == 1 and space.feature_space.shape[0] >= 2):
            raise ValueError("PaddedObjects needs an observation space Sequence(Box(d + 1,), "
                             f"stack=True) with d >= 1, got {space}")
        if not isinstance(max_objects, Integral) or isinstance(max_objects, bool):
            raise TypeError(f"max_objects must be a positive int, got {max_objects!r}")
        if max_objects < 1:
            raise ValueError(f"max_objects must be a positive int, got {max_objects!r}")
        self.max_objects = int(max_objects)
        row = space.feature_space
        low = np.append(row.low, 0.0).astype(np.float32)
        high = np.append(row.high, 1.0).astype(np.float32)
        self.observation_space = spaces.Box(np.tile(low, (self.max_objects, 1)),
                                            np.tile(high, (self.max_objects, 1)),
                                            dtype=np.float32)

    def observation(self, observation):
        """Pad (or cut) one object set to the fixed ``(max_objects, d + 2)`` observation.

        Parameters
        ----------
        observation : ndarray of float32 of shape (n, d + 1)
            The wrapped env's observation, rows ``[f_1, ..., f_d, type]``.

        Returns
        -------
        padded : ndarray of float32 of shape (max_objects, d + 2)
            Rows ``[f_1, ..., f_d, type, 1]`` for the objects kept, then rows of zeros. If
            ``n > max_objects``, the `max_objects` objects nearest to the agent are kept, in
            their original order (ties at the cut broken by ``numpy.argpartition``).
        """
        width = observation.shape[1]
        padded = np.zeros((self.max_objects, width + 1), dtype=np.float32)
        if len(observation) > self.max_objects:
            dist = np.linalg.norm(observation[:, :min(2, width - 1)], axis=1)
            keep = np.sort(np.argpartition(dist, self.max_objects - 1)[:self.max_objects])
            observation = observation[keep]
        padded[:len(observation), :width] = observation
        padded[:len(observation), width] = 1.0
        return padded


def strip_padding(padded):
    """Object sets from observations padded by `PaddedObjects`.

    Parameters
    ----------
    padded : array-like of shape (max_objects, d + 2) or (batch, max_objects, d + 2)
        Rows ``[f_1, ..., f_d, type, valid]``.

    Returns
    -------
    sets : list of ndarray of float32 of shape (n_i, d + 1)
        The valid rows of each observation (a list of one for a single observation).
    """
    padded = np.asarray(padded, dtype=np.float32)
    if padded.ndim not in (2, 3) or padded.shape[-1] < 3:
        raise ValueError("padded observations must have shape (max_objects, d + 2) or "
                         "(batch, max_objects, d + 2), d >= 1, with a last 'valid' column; "
                         f"got {padded.shape}")
    batch = padded[None] if padded.ndim == 2 else padded
    return [rows[rows[:, -1] > 0.5, :-1] for rows in batch]
