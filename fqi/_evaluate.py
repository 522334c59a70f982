"""The thesis's evaluation: greedy play on fixed reference worlds, total reward."""
from numbers import Integral

import numpy as np

from envs import reference_worlds

from ._worlds import _batched_world, _world_rules

__all__ = ["evaluate", "RandomPolicy"]


class RandomPolicy:
    """The uniform random policy, with the stable-baselines3 ``predict`` signature.

    Parameters
    ----------
    env : str, gymnasium.Env or envs.WorldRules
        The ObjectWorld whose actions are drawn.
    seed : int or None, default=None
        Seeds the actions.

    Examples
    --------
    >>> from fqi import RandomPolicy, evaluate
    >>> score = evaluate(RandomPolicy("ObjectWorld-v0", seed=0), "ObjectWorld-v0", n_steps=500)
    """

    def __init__(self, env, seed=None):
        self.n_actions = _world_rules(env).n_actions
        self._rng = np.random.default_rng(seed)

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        """Uniform random actions: one per world for a batch (``len(observation)``
        worlds when it has ``offsets``), else one.

        Returns
        -------
        actions : int or ndarray of int
        state : None
        """
        if hasattr(observation, "offsets"):
            return self._rng.integers(self.n_actions, size=len(observation.offsets) - 1), None
        return self._rng.integers(self.n_actions), None


def evaluate(policy, env="ObjectWorld-v0", n_steps=20_000):
    """Total reward of a policy over `n_steps` steps on the fixed reference worlds.

    One episode of ``max_steps`` (50) steps is played on each of the first
    ``n_steps / max_steps`` reference worlds (`envs.reference_worlds`, which training never
    sees), all in lockstep on one `envs.BatchedObjectWorld`: the default 20,000 steps are
    the thesis's 400 episodes of 50 steps.

    Parameters
    ----------
    policy : object
        Anything with ``predict(obs, deterministic=True) -> (actions, state)`` that accepts
        a batch of observations with ``data`` and ``offsets`` (an `envs.RaggedBatch`): an
        `FQI` agent, `RandomPolicy`, `envs.GreedyPolicy`, or the DQN policy of `train_dqn`.
    env : str, gymnasium.Env or envs.WorldRules, default="ObjectWorld-v0"
        The game variant (its rules; the reference worlds are fixed by the seeds).
    n_steps : int, default=20_000
        Total steps, a positive multiple of ``max_steps``.

    Returns
    -------
    total_reward : float
    """
    rules = _world_rules(env)
    if not isinstance(n_steps, Integral) or isinstance(n_steps, bool) or n_steps < 1 \
            or n_steps % rules.max_steps:
        raise ValueError(f"n_steps must be a positive multiple of the episode length "
                         f"{rules.max_steps}; got {n_steps!r}")
    n_episodes = n_steps // rules.max_steps
    worlds = _batched_world(rules, n_episodes)
    obs, _ = worlds.reset(seed=reference_worlds(n_episodes))
    total = 0.0
    for _ in range(rules.max_steps):
        actions, _ = policy.predict(obs, deterministic=True)
        obs, rewards, _, _, _ = worlds.step(np.asarray(actions).reshape(n_episodes))
        total += float(rewards.sum())
    return total
