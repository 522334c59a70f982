"""The regressors compared in the thesis, and stable-baselines3 DQN on the grid observation."""
import sys
import time
from dataclasses import dataclass

import gymnasium as gym
import numpy as np
from sklearn.linear_model import Ridge
from sklearn.pipeline import make_pipeline

from boxtrees import BoxExtraTreesRegressor, GridCounts

from ._checks import (_check_bool, _check_int, _check_n_jobs, _check_real, _check_seed,
                      _check_steps)
from ._evaluate import evaluate
from ._observations import _observation_batch
from ._worlds import _world_rules
from ._wrappers import GridObservation

__all__ = ["make_box_forest", "make_grid_ridge", "train_dqn", "DQNResult"]

# DQN settings for 400,000 steps of this game: the stable-baselines3 defaults are sized
# for Atari (1M-step buffer, 10,000-step target updates); these follow the rl-zoo
# settings for small discrete-action tasks (LunarLander-v2), with one gradient step per
# 4 env steps to keep the CPU cost bounded.
_DQN_DEFAULTS = {
    "learning_rate": 6.3e-4, "batch_size": 128, "buffer_size": 50_000, "learning_starts": 1000,
    "target_update_interval": 250, "train_freq": 4, "gradient_steps": 1,
    "exploration_fraction": 0.12, "exploration_final_eps": 0.1,
    "policy_kwargs": {"net_arch": [256, 256]},
}


def make_box_forest(env="ObjectWorld-v0", *, test_type="fixed", test_width=1.0,
                    n_estimators=30, n_tests=500, min_samples_split=30, n_jobs=-1,
                    random_state=None):
    """A `boxtrees.BoxExtraTreesRegressor` drawing its tests in the env's view square.

    The defaults are the thesis's tuned parameters (M=30, K=500, n_min=30, fixed boxes of
    half-width TW=1); ``test_type="classic"`` is the classic-trees baseline.

    Parameters
    ----------
    env : str, gymnasium.Env or envs.WorldRules, default="ObjectWorld-v0"
    test_type, test_width, n_estimators, n_tests, min_samples_split, n_jobs, random_state
        As in `boxtrees.BoxExtraTreesRegressor` (``n_jobs=-1``: every core), and checked
        here against its parameter constraints rather than at the first fit.

    Returns
    -------
    regressor : boxtrees.BoxExtraTreesRegressor
    """
    view = _world_rules(env).obs_bound
    # what the forest's constraints let through: True for an int, n_jobs=0 (joblib's error)
    n_estimators = _check_int("n_estimators", n_estimators, 1)
    n_tests = _check_int("n_tests", n_tests, 1)
    if n_jobs is not None:
        n_jobs = _check_n_jobs(n_jobs)
    forest = BoxExtraTreesRegressor(
        n_estimators, n_tests=n_tests, min_samples_split=min_samples_split,
        test_type=test_type, test_width=test_width, view_bounds=(-view, view, -view, view),
        n_jobs=n_jobs, random_state=random_state)
    forest._validate_params()  # the rest, now rather than at the first fit
    return forest


def make_grid_ridge(env="ObjectWorld-v0", *, n_bins=10, alpha=1.0):
    """The thesis's grid representation: ``make_pipeline(GridCounts(n_bins), Ridge())``.

    Parameters
    ----------
    env : str, gymnasium.Env or envs.WorldRules, default="ObjectWorld-v0"
        Fixes the grid extent (the view square) and the number of types.
    n_bins : int, default=10
        Cells along each axis, at least 1.
    alpha : float, default=1.0
        Ridge penalty, at least 0.

    Returns
    -------
    regressor : sklearn.pipeline.Pipeline
    """
    rules = _world_rules(env)
    view = rules.obs_bound
    return make_pipeline(
        GridCounts(_check_int("n_bins", n_bins, 1), view_bounds=(-view, view, -view, view),
                   n_types=rules.n_types),
        Ridge(alpha=_check_real("alpha", alpha, 0.0, np.inf, high_inclusive=False)))


class _GridModelPolicy:
    """A model trained on `GridObservation` features, playing from object sets."""

    def __init__(self, model, grid):
        self.model = model
        self.grid = grid

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        sets, single = _observation_batch(observation)
        features = self.grid.transform(sets).astype(np.float32)
        actions, _ = self.model.predict(features, deterministic=deterministic)
        return (actions[0] if single else actions), None


@dataclass
class DQNResult:
    """What `train_dqn` returns.

    Attributes
    ----------
    model : stable_baselines3.DQN
    policy : object
        Plays from object sets (``policy.predict(ragged_batch)``), for `fqi.evaluate`.
    reward : float
        `fqi.evaluate` score (NaN when ``eval_steps=0``).
    train_seconds, eval_seconds : float
        Wall time of ``model.learn`` and of the evaluation.
    total_timesteps : int
    """

    model: object
    policy: object
    reward: float
    train_seconds: float
    eval_seconds: float
    total_timesteps: int


def train_dqn(env="ObjectWorld-v0", total_timesteps=400_000, *, n_bins=10, gamma=0.5,
              eval_steps=20_000, seed=None, torch_threads=1, progress_bar=False,
              **dqn_kwargs):
    """Train stable-baselines3 `DQN` on `GridObservation` and score it with `fqi.evaluate`.

    Parameters
    ----------
    env : str, default="ObjectWorld-v0"
        Registered id of the game variant (a fresh env is made for training).
    total_timesteps : int, default=400_000
        Environment steps (20 FQI iterations of 20,000 samples are 400,000).
    n_bins : int, default=10
        Grid cells per axis of the observation.
    gamma : float, default=0.5
        Discount factor in ``[0, 1]`` (the FQI default, for a like-for-like comparison).
    eval_steps : int, default=20_000
        Steps of the evaluation on the reference worlds, a multiple of the episode length
        (50); 0 skips it.
    seed : int >= 0 or None, default=None
        Seeds DQN (and through it the training worlds, below ``2**40``).
    torch_threads : int, default=1
        Torch threads while training (restored afterwards). On 2 shared cores the
        default thread pool ran 12x slower than one thread (measured, README "fqi").
    progress_bar : bool, default=False
    **dqn_kwargs
        Override the DQN settings (see ``_DQN_DEFAULTS`` in this module).

    Every argument is checked before training starts.

    Returns
    -------
    result : DQNResult
    """
    import torch
    from stable_baselines3 import DQN
    from stable_baselines3.common.logger import HumanOutputFormat, Logger

    if not isinstance(env, str):
        raise TypeError(f"env must be a registered env id, got {type(env).__name__}")
    rules = _world_rules(env)
    total_timesteps = _check_int("total_timesteps", total_timesteps, 1)
    gamma = _check_real("gamma", gamma, 0.0, 1.0)
    eval_steps = _check_steps("eval_steps", eval_steps, rules.max_steps, allow_zero=True)
    seed = _check_seed("seed", seed)
    torch_threads = _check_int("torch_threads", torch_threads, 1)
    progress_bar = _check_bool("progress_bar", progress_bar)
    train_env = GridObservation(gym.make(env), n_bins=n_bins)
    model = DQN("MlpPolicy", train_env, gamma=gamma, seed=seed, device="cpu",
                **{**_DQN_DEFAULTS, **dqn_kwargs})
    if model.tensorboard_log is None:
        # SB3's own logger would create an unused /tmp/SB3-<time> folder on every call
        model.set_logger(Logger(None, [HumanOutputFormat(sys.stdout)] if model.verbose else []))
    threads = torch.get_num_threads()
    torch.set_num_threads(torch_threads)
    try:
        start = time.perf_counter()
        model.learn(total_timesteps=total_timesteps, progress_bar=progress_bar)
        trained = time.perf_counter()
    finally:
        torch.set_num_threads(threads)
    policy = _GridModelPolicy(model, train_env.grid)
    reward = evaluate(policy, env, eval_steps) if eval_steps else np.nan
    train_env.close()
    return DQNResult(model, policy, reward, trained - start, time.perf_counter() - trained,
                     total_timesteps)
