"""The vector envs that FQI and `evaluate` play on, built from what the user gives, and
tried once (a reset and a step, with the step's outputs checked) before the agent relies on
them.

An env argument is a registered id, a `gymnasium.Env` (wrappers allowed), a
`gymnasium.vector.VectorEnv` (used as it is) or a factory returning a `gymnasium.Env`.
Rollouts talk to gymnasium's vector API only, so a registered ``vector_entry_point`` (a
batched engine) is the fast path and every other env runs in a `SyncVectorEnv`.
"""
import copy
from functools import partial

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, SyncVectorEnv, VectorEnv

__all__ = []

# Training resets draw their seeds below this; `evaluate` defaults to seeds from here on, so
# its episodes are never trained on.
_TRAINING_SEED_END = 2**40

_ENV_FORMS = ("a registered env id, a gymnasium.Env, a gymnasium.vector.VectorEnv or a "
              "callable returning a gymnasium.Env")


def _check_env(env, name="env"):
    """TypeError unless `env` is one of the forms an env argument takes."""
    if not (isinstance(env, (str, gym.Env, VectorEnv)) or callable(env)):
        raise TypeError(f"{name} must be {_ENV_FORMS}; got {type(env).__name__}")


def _make_vector(env, n_envs):
    """A `VectorEnv` of `n_envs` copies of `env`; a `VectorEnv` is returned as it is.

    An id goes through ``gymnasium.make_vec(id, num_envs=n_envs)``: its registered vector
    entry point when it has one, a `SyncVectorEnv` otherwise. An env that gymnasium made is
    rebuilt the same way from its spec (kwargs and recorded wrappers included); any other
    env is copied with `copy.deepcopy`. A factory is called once per copy.
    """
    _check_env(env)
    if isinstance(env, VectorEnv):
        return env
    if isinstance(env, str):
        return gym.make_vec(env, num_envs=n_envs)
    if isinstance(env, gym.Env):
        spec = env.spec
        if _rebuildable(spec):
            mode = "sync" if spec.additional_wrappers else None
            return gym.make_vec(spec, num_envs=n_envs, vectorization_mode=mode)
        return SyncVectorEnv([partial(_deepcopy, env)] * n_envs)
    return SyncVectorEnv([partial(_called, env)] * n_envs)


def _close_built(vector, env):
    """Close `vector` when `_make_vector` built it from `env` (a vector env given as it is
    stays the caller's, open)."""
    if vector is not None and vector is not env:
        vector.close()


def _rebuildable(spec):
    """Whether ``gymnasium.make(spec)`` rebuilds the env that carries `spec`: it has an entry
    point and every wrapper recorded its arguments."""
    return (spec is not None and spec.entry_point is not None
            and all(w.kwargs is not None for w in spec.additional_wrappers))


def _deepcopy(env):
    try:
        return copy.deepcopy(env)
    except Exception as exc:  # an env holding a handle or a lock cannot be copied
        raise TypeError(f"{env} was not made by gymnasium.make (or has a wrapper that does "
                        f"not record its arguments), so it is copied, and copy.deepcopy "
                        f"failed ({type(exc).__name__}: {exc}); pass a factory (a callable "
                        f"returning a new env) or a gymnasium.vector.VectorEnv instead") from exc


def _called(factory):
    env = factory()
    if not isinstance(env, gym.Env):
        raise TypeError(f"the env factory {factory!r} must return a gymnasium.Env; it "
                        f"returned {type(env).__name__}")
    return env


def _copy_vector(vector, n_envs):
    """A new `VectorEnv` of `n_envs` envs like `vector`, from its spec; None without one."""
    spec = getattr(vector.unwrapped, "spec", None)
    if spec is None or spec.entry_point is None:
        return None
    spec = copy.copy(spec)
    spec.kwargs = {**spec.kwargs, "num_envs": n_envs}
    return gym.make_vec(spec)


def _spaces(env):
    """``(observation_space, action_space)`` of one env of `env` (any env form)."""
    _check_env(env)
    if isinstance(env, VectorEnv):
        return env.single_observation_space, env.single_action_space
    if isinstance(env, gym.Env):
        return env.observation_space, env.action_space
    made = gym.make(env) if isinstance(env, str) else _called(env)
    try:
        return made.observation_space, made.action_space
    finally:
        made.close()


def _n_actions(space):
    """The number of actions of a ``Discrete`` action space starting at 0."""
    if not isinstance(space, spaces.Discrete):
        raise TypeError(f"fitted Q-iteration needs a Discrete action space (one regressor per "
                        f"action); got {space}")
    if space.start != 0:
        raise ValueError(f"the actions must be numbered from 0; got {space}: wrap the env "
                         f"in a gymnasium.ActionWrapper that maps 0 .. {space.n - 1} to them")
    return int(space.n)


def _autoreset_mode(vector):
    """The autoreset mode of `vector` (``metadata["autoreset_mode"]``, gymnasium's default
    ``NEXT_STEP`` when it does not say)."""
    mode = vector.metadata.get("autoreset_mode", AutoresetMode.NEXT_STEP)
    try:
        return AutoresetMode(mode)
    except ValueError:
        raise ValueError(f"{vector} has an unknown metadata['autoreset_mode'] {mode!r}; "
                         f"expected one of {[m.value for m in AutoresetMode]}") from None


def _seeded_reset(vector, seeds):
    """``vector.reset`` with one seed per env; returns the observations.

    A vector env whose envs share one generator and so take a single int seed (gymnasium's
    ``CartPoleVectorEnv``) is reset with ``seeds[0]``.
    """
    try:
        obs, _ = vector.reset(seed=list(seeds))
    except (gym.error.Error, TypeError, ValueError):
        obs, _ = vector.reset(seed=int(seeds[0]))
    return obs


def _evaluation_vector(env, eval_env, vector, spaces, n):
    """The vector env of `n` evaluation episodes after each iteration (None for none): built
    from `eval_env`, which must have the `spaces`, else from `env` (a vector env rebuilt from
    its spec)."""
    if n == 0:
        return None
    if eval_env is not None:
        evaluation = _make_vector(eval_env, n)
        found = (evaluation.single_observation_space, evaluation.single_action_space)
        if found != spaces:
            _close_built(evaluation, eval_env)
            raise ValueError(f"eval_env has the spaces {found[0]} and {found[1]}; env "
                             f"has {spaces[0]} and {spaces[1]}")
        return evaluation
    if isinstance(env, VectorEnv):
        evaluation = _copy_vector(vector, n)
        if evaluation is None:
            raise ValueError("a vector env without a spec cannot be rebuilt for the "
                             "evaluation after each iteration: give eval_env, or "
                             "eval_episodes=0 (and evaluate with fqi.evaluate)")
        return evaluation
    return _make_vector(env, n)


def _tried(vector, observations):
    """Reset `vector` and take one step (action 0 everywhere), checking what it returns;
    the observations of the reset, as the regressor takes them."""
    calls = {"reset": lambda: vector.reset(),
             "step": lambda: vector.step(np.zeros(vector.num_envs, dtype=np.intp))}
    results = {}
    for name, call in calls.items():
        try:
            results[name] = call()
        except Exception as exc:
            raise RuntimeError(f"{vector}.{name} raised {type(exc).__name__}: {exc} (FQI "
                               f"tries the env once when it is set: a reset, then a step "
                               f"with action 0 in every env)") from exc
    first = observations.batch(results["reset"][0])
    obs, rewards, terminated, truncated, _ = results["step"]
    observations.batch(obs)
    _checked_step(rewards, terminated, truncated, vector.num_envs)
    return first


def _checked_step(rewards, terminated, truncated, n_envs):
    """The step's rewards (float64) and flags (bool), checked: one finite reward and one
    flag of each kind per env."""
    rewards = np.asarray(rewards)
    if rewards.shape != (n_envs,) or rewards.dtype.kind not in "biuf":
        raise ValueError(f"the env returned rewards of shape {rewards.shape} and dtype "
                         f"{rewards.dtype}; expected one number per env, shape ({n_envs},)")
    if not np.isfinite(rewards).all():
        raise ValueError(f"the env returned non-finite rewards (NaN or inf): "
                         f"{rewards[~np.isfinite(rewards)][:3].tolist()}")
    flags = []
    for name, flag in (("terminated", terminated), ("truncated", truncated)):
        flag = np.asarray(flag)
        if flag.shape != (n_envs,) or flag.dtype.kind not in "biu":
            raise ValueError(f"the env returned {name} of shape {flag.shape} and dtype "
                             f"{flag.dtype}; expected one bool per env, shape ({n_envs},)")
        flags.append(flag.astype(bool))
    return rewards.astype(np.float64), *flags
