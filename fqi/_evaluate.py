"""The thesis's evaluation: greedy play on fixed reference worlds, total reward."""
import numpy as np

from envs import reference_worlds

from ._checks import _check_seed, _check_steps
from ._worlds import _batched_world, _world_rules

__all__ = ["evaluate", "RandomPolicy"]


class RandomPolicy:
    """The uniform random policy, with the stable-baselines3 ``predict`` signature.

    Parameters
    ----------
    env : str, gymnasium.Env or envs.WorldRules
        The ObjectWorld whose actions are drawn.
    seed : int >= 0 or None, default=None
        Seeds the actions.

    Examples
    --------
    >>> from fqi import RandomPolicy, evaluate
    >>> score = evaluate(RandomPolicy("ObjectWorld-v0", seed=0), "ObjectWorld-v0", n_steps=500)
    """

    def __init__(self, env, seed=None):
        self.n_actions = _world_rules(env).n_actions
        self._rng = np.random.default_rng(_check_seed("seed", seed))

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
        Its actions must be one int in ``[0, n_actions)`` per world (else a ValueError).
    env : str, gymnasium.Env or envs.WorldRules, default="ObjectWorld-v0"
        The game variant (its rules; the reference worlds are fixed by the seeds).
    n_steps : int, default=20_000
        Total steps, a positive multiple of ``max_steps``.

    Returns
    -------
    total_reward : float
    """
    if not callable(getattr(policy, "predict", None)):
        raise TypeError(f"policy must have a method predict(observation, deterministic=True) "
                        f"returning (actions, state); {type(policy).__name__} has no predict")
    rules = _world_rules(env)
    n_steps = _check_steps("n_steps", n_steps, rules.max_steps, allow_zero=False)
    n_episodes = n_steps // rules.max_steps
    worlds = _batched_world(rules, n_episodes)
    obs, _ = worlds.reset(seed=reference_worlds(n_episodes))
    total = 0.0
    for _ in range(rules.max_steps):
        actions = _policy_actions(policy, obs, rules.n_actions)
        obs, rewards, _, _, _ = worlds.step(actions)
        total += float(rewards.sum())
    return total


def _policy_actions(policy, obs, n_actions):
    """The actions of ``policy.predict`` for the batch `obs`, checked to be one int in
    ``[0, n_actions)`` per world, as an array of shape ``(len(obs),)``."""
    out = policy.predict(obs, deterministic=True)
    if not isinstance(out, tuple) or len(out) != 2:
        raise TypeError(f"policy.predict must return a pair (actions, state) as in "
                        f"stable-baselines3; it returned a {type(out).__name__}")
    actions = np.asarray(out[0])
    n_worlds = len(obs)
    if actions.size != n_worlds:
        raise ValueError(f"policy.predict returned {actions.size} actions (shape "
                         f"{actions.shape}) for a batch of {n_worlds} observations; expected "
                         f"{n_worlds}, one per world")
    if actions.dtype.kind not in "iu":
        raise ValueError(f"policy.predict must return int actions in [0, {n_actions}); it "
                         f"returned dtype {actions.dtype}")
    invalid = (actions < 0) | (actions >= n_actions)
    if invalid.any():
        raise ValueError(f"policy.predict returned action {actions[invalid].flat[0]}; the "
                         f"action space is Discrete({n_actions}), ints in [0, {n_actions})")
    return actions.reshape(n_worlds)
