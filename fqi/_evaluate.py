"""Greedy play on fixed reset seeds: total and mean return, for any policy with ``predict``."""
from __future__ import annotations

from collections.abc import Sequence
import warnings
from dataclasses import dataclass

import numpy as np
from gymnasium.vector import AutoresetMode

from ._checks import _check_int, _check_seed
from ._envs import (_TRAINING_SEED_END, _autoreset_mode, _close_built, _make_vector,
                    _n_actions, _seeded_reset, _spaces)
from ._observations import _observation_format
from ._typing import EnvLike, Observation, Policy

__all__ = ["evaluate", "Evaluation", "RandomPolicy"]

_DEFAULT_EPISODES = 10
# The steps an episode may last when the env states no time limit (its spec's
# ``max_episode_steps``): an episode that never ends must not hang an evaluation.
_STEP_CAP = 1_000


@dataclass(frozen=True)
class Evaluation:
    """What `evaluate` returns.

    Attributes
    ----------
    total : float
        Sum of the episodes' returns (the thesis's score: 400 episodes of 50 steps).
    mean, std : float
        Mean and standard deviation of the episodes' returns.
    returns : ndarray of float64 of shape (n_episodes,)
        Undiscounted return of each episode, in the order of the seeds.
    lengths : ndarray of int of shape (n_episodes,)
        Steps of each episode.
    seeds : tuple of int
        The reset seed of each episode.
    """

    total: float
    mean: float
    std: float
    returns: np.ndarray
    lengths: np.ndarray
    seeds: tuple[int, ...]


def _eval_seeds(n_episodes: int | None, seeds: Sequence[int] | None, name: str = "n_episodes",
                seeds_name: str = "seeds", default: int = _DEFAULT_EPISODES
                ) -> tuple[int, ...]:
    """The reset seeds of an evaluation: `seeds` (checked, and `n_episodes` of them when
    both are given), else ``2**40, 2**40 + 1, ...``, `n_episodes` of them (`default` when
    it is None); none for ``n_episodes=0``."""
    if n_episodes is not None:
        n_episodes = _check_int(name, n_episodes, 0)
        if n_episodes == 0:
            return ()
    if seeds is None:
        n = default if n_episodes is None else n_episodes
        return tuple(range(_TRAINING_SEED_END, _TRAINING_SEED_END + n))
    if isinstance(seeds, (str, bytes)) or not hasattr(seeds, "__len__"):
        raise TypeError(f"{seeds_name} must be a sequence of ints, got {seeds!r}")
    seeds = tuple(_check_int(f"{seeds_name}[{i}]", s, 0) for i, s in enumerate(seeds))
    if n_episodes is not None and n_episodes != len(seeds):
        raise ValueError(f"{name}={n_episodes} but {len(seeds)} {seeds_name} were given; "
                         f"give one seed per episode (or leave {name} out)")
    return seeds


class RandomPolicy:
    """The uniform random policy, with the stable-baselines3 ``predict`` signature.

    Parameters
    ----------
    env : str, gymnasium.Env, gymnasium.vector.VectorEnv or callable
        The env whose actions are drawn (its action space must be ``Discrete``) and whose
        observations it is given (one, or a batch).
    seed : int >= 0 or None, default=None
        Seeds the actions.

    Examples
    --------
    >>> from fqi import RandomPolicy, evaluate
    >>> result = evaluate(RandomPolicy("CartPole-v1", seed=0), "CartPole-v1", n_episodes=5)
    >>> result.returns.shape
    (5,)
    """

    def __init__(self, env: EnvLike, seed: int | None = None) -> None:
        observation_space, action_space = _spaces(env)
        self.n_actions = _n_actions(action_space)
        self._observations = _observation_format(observation_space)
        self._rng = np.random.default_rng(_check_seed("seed", seed))

    def predict(self, observation: Observation, state: object = None,
                episode_start: object = None, deterministic: bool = True
                ) -> tuple[np.integer | np.ndarray, None]:
        """Uniform random actions: one for one observation, one per observation of a batch.

        Parameters
        ----------
        observation : array-like
            One observation of the env's space, or a batch of them (as its vector env
            returns them); checked, then only its size is used.
        state, episode_start, deterministic
            Ignored (stable-baselines3's signature): the actions are random whatever
            `deterministic`.

        Returns
        -------
        actions : numpy int or ndarray of int
        state : None
        """
        batch, single = self._observations.as_input(observation)
        if single:
            return self._rng.integers(self.n_actions), None
        return self._rng.integers(self.n_actions, size=len(batch)), None


def evaluate(policy: Policy, env: EnvLike, n_episodes: int | None = None,
             seeds: Sequence[int] | None = None,
             max_episode_steps: int | None = None) -> Evaluation:
    """Play one episode per reset seed with the policy's greedy actions.

    The episodes run side by side on a vector env (one env per episode; a given
    `gymnasium.vector.VectorEnv` plays them in rounds of its size), each reset with its
    own seed and played until it terminates, is truncated, or reaches `max_episode_steps`.
    Nothing else is random, so the same policy scores the same. The thesis's evaluation is
    ``seeds=envs.reference_worlds(400)`` on ObjectWorld: 400 episodes of 50 steps, 20,000
    steps, scored by ``total``.

    Parameters
    ----------
    policy : object
        Anything with ``predict(obs, deterministic=True) -> (actions, state)`` taking a batch
        of observations as the vector env returns them (an `FQI` agent, `RandomPolicy`, a
        stable-baselines3 model on a ``Box`` env): one int action in ``[0, n_actions)`` per
        env (else a ValueError).
    env : str, gymnasium.Env, gymnasium.vector.VectorEnv or callable
        As for `FQI`. A vector env is played as it is and left open; the vector env built
        from any other form is closed at the end.
    n_episodes : int, default=None
        Number of episodes: ``len(seeds)`` when seeds are given, else 10.
    seeds : sequence of int, default=None
        One reset seed per episode. Default: ``2**40, 2**40 + 1, ...``, seeds that `FQI`
        never trains on (it draws its reset seeds below ``2**40``). A vector env whose envs
        share one generator and take a single int seed (gymnasium's ``CartPoleVectorEnv``,
        behind ``"CartPole-v1"``) is reset with ``seeds[0]``: its episodes are then fixed
        by that seed and their number, not by one seed each (use
        ``gymnasium.make_vec(id, n, vectorization_mode="sync")`` for per-episode seeds).
    max_episode_steps : int, default=None
        Steps after which an episode is ended and scored as it stands. None: the env's time
        limit (its spec's ``max_episode_steps``) when it states one, else 1,000 steps, with
        a warning when an episode reaches them (an env whose episodes never end would
        otherwise be played forever: wrap it in ``gymnasium.wrappers.TimeLimit``).

    Returns
    -------
    result : Evaluation
        ``total``, ``mean`` and ``std`` of the returns, and each episode's return and length.

    Examples
    --------
    >>> import gymnasium as gym
    >>> from fqi import RandomPolicy, evaluate
    >>> env = gym.make_vec("CartPole-v1", 3, vectorization_mode="sync")
    >>> result = evaluate(RandomPolicy(env, seed=0), env, seeds=[0, 1, 2])
    >>> result.total == evaluate(RandomPolicy(env, seed=0), env, seeds=[0, 1, 2]).total
    True
    >>> result.returns.shape, bool(result.total == result.returns.sum())
    ((3,), True)
    """
    if not callable(getattr(policy, "predict", None)):
        raise TypeError(f"policy must have a method predict(observation, deterministic=True) "
                        f"returning (actions, state); {type(policy).__name__} has no predict")
    seeds = _eval_seeds(n_episodes, seeds)
    if not seeds:
        raise ValueError("n_episodes must be >= 1 (or give at least one seed)")
    if max_episode_steps is not None:
        max_episode_steps = _check_int("max_episode_steps", max_episode_steps, 1)
    vector = _make_vector(env, len(seeds))
    returns_by_round, lengths_by_round = [], []
    try:
        n_actions = _n_actions(vector.single_action_space)
        limit = _time_limit(vector)
        cap = max_episode_steps or limit or _STEP_CAP
        for start in range(0, len(seeds), vector.num_envs):
            round_returns, round_lengths = _play_round(policy, vector, n_actions,
                                                       seeds[start:start + vector.num_envs],
                                                       cap)
            returns_by_round.append(round_returns)
            lengths_by_round.append(round_lengths)
    finally:
        _close_built(vector, env)
    returns, lengths = np.concatenate(returns_by_round), np.concatenate(lengths_by_round)
    if max_episode_steps is None and limit is None and (lengths >= cap).any():
        warnings.warn(f"{(lengths >= cap).sum()} of {len(seeds)} evaluation episodes reached "
                      f"{cap:,} steps without ending and were ended there; the env states no "
                      f"time limit: wrap it in gymnasium.wrappers.TimeLimit (for FQI, as env "
                      f"or eval_env), or pass max_episode_steps to fqi.evaluate",
                      RuntimeWarning, stacklevel=2)
    return Evaluation(float(returns.sum()), float(returns.mean()), float(returns.std()),
                      returns, lengths, seeds)


def _time_limit(vector):
    """The ``max_episode_steps`` of the spec of `vector` or of its first env; None when
    neither states one."""
    specs = [getattr(vector, "spec", None)]
    envs = getattr(vector, "envs", None)
    if envs:
        specs.append(getattr(envs[0], "spec", None))
    limits = [spec.max_episode_steps for spec in specs
              if spec is not None and spec.max_episode_steps is not None]
    return limits[0] if limits else None


def _play_round(policy, vector, n_actions, seeds, cap):
    """Returns and lengths of one episode per seed, on the first ``len(seeds)`` envs of
    `vector` (the others replay the same seeds and are not counted), each ended after at
    most `cap` steps."""
    n_envs = vector.num_envs
    obs = _seeded_reset(vector, (list(seeds) * n_envs)[:n_envs])
    mode = _autoreset_mode(vector)
    returns, lengths = np.zeros(n_envs), np.zeros(n_envs, dtype=np.intp)
    playing = np.ones(n_envs, dtype=bool)
    counted = slice(len(seeds))
    while playing[counted].any():
        actions = _policy_actions(policy, obs, n_actions, n_envs)
        obs, rewards, terminated, truncated, _ = vector.step(actions)
        returns[playing] += np.asarray(rewards, dtype=np.float64)[playing]
        lengths[playing] += 1
        ended = playing & (np.asarray(terminated) | np.asarray(truncated) | (lengths >= cap))
        playing &= ~ended
        if ended.any() and mode is AutoresetMode.DISABLED:
            obs, _ = vector.reset(options={"reset_mask": ended})
    return returns[counted], lengths[counted]


def _policy_actions(policy, obs, n_actions, n_envs):
    """The actions of ``policy.predict`` for the batch `obs`, checked to be one int in
    ``[0, n_actions)`` per env, as an array of shape ``(n_envs,)``."""
    out = policy.predict(obs, deterministic=True)
    if not isinstance(out, tuple) or len(out) != 2:
        raise TypeError(f"policy.predict must return a pair (actions, state) as in "
                        f"stable-baselines3; it returned a {type(out).__name__}")
    actions = np.asarray(out[0])
    if actions.size != n_envs:
        raise ValueError(f"policy.predict returned {actions.size} actions (shape "
                         f"{actions.shape}) for a batch of {n_envs} observations; expected "
                         f"{n_envs}, one per env")
    if actions.dtype.kind not in "iu":
        raise ValueError(f"policy.predict must return int actions in [0, {n_actions}); it "
                         f"returned dtype {actions.dtype}")
    invalid = (actions < 0) | (actions >= n_actions)
    if invalid.any():
        raise ValueError(f"policy.predict returned action {actions[invalid].flat[0]}; the "
                         f"action space is Discrete({n_actions}), ints in [0, {n_actions})")
    return actions.reshape(n_envs)
