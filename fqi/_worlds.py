"""Which ObjectWorld an argument names: an env id, an env (possibly wrapped), or rules."""
import dataclasses

import gymnasium as gym
from gymnasium import spaces

from envs import BatchedObjectWorld, WorldRules

__all__ = []


def _action_space(env):
    """The per-world action space of a gymnasium env or vector env."""
    space = getattr(env, "single_action_space", None)
    return space if space is not None else getattr(env, "action_space", None)


def _world_rules(env):
    """The `envs.WorldRules` of `env`, after checking its action space is discrete.

    Parameters
    ----------
    env : str, gymnasium.Env, gymnasium.vector.VectorEnv or envs.WorldRules
        A registered id (``"ObjectWorld-v0"``), an ObjectWorld env (wrappers allowed), a
        `envs.BatchedObjectWorld`, or the rules themselves.

    Returns
    -------
    rules : envs.WorldRules
    """
    if isinstance(env, WorldRules):
        return env
    if isinstance(env, str):
        made = gym.make(env)
        try:
            return _world_rules(made)
        finally:
            made.close()
    if not isinstance(env, (gym.Env, gym.vector.VectorEnv)):
        raise TypeError(f"env must be a gymnasium env id, a gymnasium env or envs.WorldRules; "
                        f"got {type(env).__name__}")
    space = _action_space(env)
    if not isinstance(space, spaces.Discrete):
        raise TypeError(f"fitted Q-iteration needs a Discrete action space (one regressor per "
                        f"action); got {space}")
    rules = getattr(env.unwrapped, "rules", None)
    if not isinstance(rules, WorldRules):
        raise TypeError(f"rollouts run on envs.BatchedObjectWorld, so env must be an ObjectWorld "
                        f"env (with env.unwrapped.rules); got {env.unwrapped!r}")
    return rules


def _batched_world(rules, n_worlds):
    """A `BatchedObjectWorld` of `n_worlds` worlds playing by `rules`."""
    return BatchedObjectWorld(n_worlds, **dataclasses.asdict(rules))
