"""A scripted reactive policy, the rough upper anchor for learned ones."""
import numpy as np

from ._rules import _DIRECTIONS, ENEMY, MONEY, WALL
from .batched import _check_offsets, _unwrapped_world

__all__ = ["GreedyPolicy"]

_MONEY_PULL = 100.0
_ENEMY_PUSH = 300.0
_SOFTENING = 0.5  # keeps the inverse-square pulls finite next to an object


def _check_rows(rows, n_types, name):
    """`rows` as an array of objects ``[dx, dy, type]``, checked as observations of the game.

    Raises a TypeError unless they are numbers, and a ValueError unless they have shape
    ``(n, 3)``, are finite and hold type ids in ``range(n_types)``.
    """
    expected = f"{name} must be an (n, 3) array of objects [dx, dy, type]"
    try:
        array = np.asarray(rows)
    except ValueError:
        raise ValueError(f"{expected}, got a ragged sequence") from None
    if array.dtype.kind not in "iuf":
        raise TypeError(f"{name} must hold numbers, got dtype {array.dtype}")
    if array.ndim != 2 or array.shape[1] != 3:
        raise ValueError(f"{expected} (a RaggedBatch for several worlds), got shape "
                         f"{array.shape}")
    if not np.isfinite(array).all():
        raise ValueError(f"{name} contains NaN or infinite values")
    known = np.isin(array[:, 2], np.arange(n_types))
    if not known.all():
        raise ValueError(f"{name} has type id {array[~known, 2][0]}; the types of this game "
                         f"are the ints 0 to {n_types - 1}")
    return array


class GreedyPolicy:
    """Greedy for money, away from enemies, never into a wall; swipes a lone enemy.

    Each move is scored by where it leads (noise ignored): the sum of
    ``100 / (d + 0.5)^2`` over the money in view minus ``300 / (d + 0.5)^2`` over the
    enemies, ``d`` being the distance from the move's end; a move whose path touches a wall
    is never taken while another is free. With the sword, a swipe whose square holds
    exactly one enemy beats every move. It only reads observations, like a learned policy.

    Parameters
    ----------
    env : ObjectWorldEnv or BatchedObjectWorld
        The (possibly wrapped) environment whose rules the policy plays by. Many worlds
        are one `BatchedObjectWorld` (``gymnasium.make_vec(id, num_envs=n)`` builds one),
        not a gymnasium ``SyncVectorEnv`` of single envs.

    Raises
    ------
    TypeError
        If `env` (unwrapped) is not an `ObjectWorldEnv` or a `BatchedObjectWorld`.

    Attributes
    ----------
    rules : WorldRules
        The rules of `env`, read once at construction.

    Examples
    --------
    >>> import numpy as np
    >>> import envs
    >>> worlds = envs.BatchedObjectWorld(4)
    >>> policy = envs.GreedyPolicy(worlds)
    >>> obs, _ = worlds.reset(seed=0)
    >>> actions, _ = policy.predict(obs)
    >>> actions.shape
    (4,)
    """

    def __init__(self, env):
        self.rules = _unwrapped_world(env, "GreedyPolicy").rules

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        """Actions for one observation or a batch (stable-baselines3 signature).

        Parameters
        ----------
        observation : array-like of shape (n, 3), or RaggedBatch
            One world's objects, or a batch with ``data`` and ``offsets``.
        state, episode_start, deterministic
            Unused (the policy is stateless and deterministic).

        Returns
        -------
        actions : int or ndarray of int of shape (n_worlds,)
        state : None

        Raises
        ------
        TypeError
            If the observation does not hold numbers.
        ValueError
            If it is not of shape ``(n, 3)`` (``data`` of a batch likewise, with valid
            ``offsets``), holds NaN or infinite values, or type ids not of this game.
        """
        n_types = self.rules.n_types
        if hasattr(observation, "data") and hasattr(observation, "offsets"):
            rows = _check_rows(observation.data, n_types, "observation.data")
            return self._actions(rows, _check_offsets(observation.offsets, len(rows))), None
        rows = _check_rows(observation, n_types, "observation")
        return self._actions(rows, np.array([0, len(rows)]))[0], None

    def _actions(self, rows, offsets):
        rules = self.rules
        n = len(offsets) - 1
        world = np.repeat(np.arange(n), np.diff(offsets))
        xy, types = rows[:, :2].astype(np.float64), rows[:, 2]
        scores = np.empty((n, rules.n_actions))
        for a, step in enumerate(_DIRECTIONS):
            rel = xy - step
            pull = 1.0 / (np.hypot(rel[:, 0], rel[:, 1]) + _SOFTENING) ** 2
            value = np.where(types == MONEY, _MONEY_PULL * pull, 0.0)
            value -= np.where(types == ENEMY, _ENEMY_PUSH * pull, 0.0)
            scores[:, a] = np.bincount(world, weights=value, minlength=n)
            along = np.clip(xy @ step, 0.0, 1.0)
            gap = xy - along[:, None] * step
            reach = rules.contact_radius + rules.move_noise  # margin for the noise
            wall = (types == WALL) & ((gap ** 2).sum(axis=1) <= reach ** 2)
            scores[np.bincount(world[wall], minlength=n) > 0, a] -= 1e9
        if rules.sword:
            half, size = rules.swipe_size / 2, rules.swipe_size
            for a, (dx, dy) in enumerate(_DIRECTIONS, start=4):
                along = xy[:, 0] * dx + xy[:, 1] * dy
                across = xy[:, 0] * dy - xy[:, 1] * dx
                inside = (types == ENEMY) & (along > 0) & (along <= size)
                inside &= np.abs(across) <= half
                lone = np.bincount(world[inside], minlength=n) == 1
                scores[:, a] = np.where(lone, 1e6, -1e12)
        return scores.argmax(axis=1)
