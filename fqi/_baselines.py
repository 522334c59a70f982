"""The regressors compared in the thesis, and stable-baselines3 DQN on the grid observation."""
import sys
import time
from dataclasses import dataclass

import gymnasium as gym
import numpy as np
from sklearn.base import clone
from sklearn.linear_model import Ridge
from sklearn.pipeline import make_pipeline

from boxtrees import BoxExtraTreesRegressor, GridCounts

from ._checks import _check_bool, _check_int, _check_n_jobs, _check_real, _check_seed
from ._envs import _spaces
from ._evaluate import _eval_seeds, evaluate
from ._observations import _object_bounds, _ObjectRows, _view_bounds
from ._wrappers import GridObservation

__all__ = ["make_box_forest", "make_grid_ridge", "train_dqn", "DQNResult"]

# DQN settings for 400,000 steps of an object-set game: the stable-baselines3 defaults are
# sized for Atari (1M-step buffer, 10,000-step target updates); these follow the rl-zoo
# settings for small discrete-action tasks (LunarLander-v2), with one gradient step per
# 4 env steps to keep the CPU cost bounded.
_DQN_DEFAULTS = {
    "learning_rate": 6.3e-4, "batch_size": 128, "buffer_size": 50_000, "learning_starts": 1000,
    "target_update_interval": 250, "train_freq": 4, "gradient_steps": 1,
    "exploration_fraction": 0.12, "exploration_final_eps": 0.1,
    "policy_kwargs": {"net_arch": [256, 256]},
}


def make_box_forest(env=None, *, test_type="fixed", test_width=1.0, n_estimators=30,
                    n_tests=500, min_samples_split=30, n_jobs=-1, random_state=None,
                    view_bounds=None):
    """A `boxtrees.BoxExtraTreesRegressor` drawing its tests in the env's view square.

    The thesis's forest: its tuned parameters are the defaults (M=30, K=500, n_min=30, fixed
    boxes of half-width TW=1 in the view's units), and its tests are neither refined nor
    grown on bootstrap samples, whatever the estimator's own defaults; ``test_type="classic"``
    is the classic-trees baseline (axis-aligned splits, also on a ``Box`` env's feature
    vector).

    Parameters
    ----------
    env : str, gymnasium.Env, gymnasium.vector.VectorEnv or callable, default=None
        For object-set observations ``Sequence(Box(shape=(d + 1,)))``, the bounds of its
        rows' attributes are the region the tests are drawn in (the view square for
        ``[x, y, type]``). None, or a ``Box`` env: the
        forest draws them in the bounding box of its training data.
    test_type, test_width, n_estimators, n_tests, min_samples_split, n_jobs, random_state
        As in `boxtrees.BoxExtraTreesRegressor` (``n_jobs=-1``: every core), and checked
        here against its parameter constraints rather than at the first fit.
    view_bounds : tuple of 2 * d floats, default=None
        ``(xmin, xmax, ymin, ymax)`` (``(low, high)`` per attribute), instead of the env's.

    Returns
    -------
    regressor : boxtrees.BoxExtraTreesRegressor

    Examples
    --------
    >>> from fqi import make_box_forest
    >>> make_box_forest(view_bounds=(-10, 10, -10, 10), n_estimators=5).n_tests
    500
    """
    if view_bounds is None and env is not None:
        space = _spaces(env)[0]
        if not isinstance(space, gym.spaces.Box):
            view_bounds = _view_bounds(space)
    # what the forest's constraints let through: True for an int, n_jobs=0 (joblib's error)
    n_estimators = _check_int("n_estimators", n_estimators, 1)
    n_tests = _check_int("n_tests", n_tests, 1)
    if n_jobs is not None:
        n_jobs = _check_n_jobs(n_jobs)
    forest = BoxExtraTreesRegressor(
        n_estimators, n_tests=n_tests, min_samples_split=min_samples_split,
        test_type=test_type, test_width=test_width, view_bounds=view_bounds,
        relative_width=False, refine_tests=False, bootstrap=False, max_retries=10,
        n_jobs=n_jobs, random_state=random_state)
    forest._validate_params()  # the rest, now rather than at the first fit
    return forest


def make_grid_ridge(env=None, *, n_bins=10, alpha=1.0, view_bounds=None, n_types=None):
    """The thesis's grid representation: ``make_pipeline(GridCounts(n_bins), Ridge())``.

    Parameters
    ----------
    env : str, gymnasium.Env, gymnasium.vector.VectorEnv or callable, default=None
        An env observing object sets; the bounds of its rows fix the grid extent (the view
        square) and the number of types. Needed unless `view_bounds` and `n_types` are
        given.
    n_bins : int, default=10
        Cells along each axis, at least 1.
    alpha : float, default=1.0
        Ridge penalty, at least 0.
    view_bounds : tuple of 4 floats, default=None
    n_types : int, default=None
        Instead of the env's.

    Returns
    -------
    regressor : sklearn.pipeline.Pipeline

    Examples
    --------
    >>> from fqi import make_grid_ridge
    >>> make_grid_ridge(view_bounds=(-10, 10, -10, 10), n_types=4)[0].n_bins
    10
    """
    if env is None:
        if view_bounds is None or n_types is None:
            raise TypeError("make_grid_ridge needs an env observing object sets, or both "
                            "view_bounds and n_types")
    else:
        view_bounds, n_types = _object_bounds(_spaces(env)[0], view_bounds, n_types)
    grid = GridCounts(_check_int("n_bins", n_bins, 1), view_bounds=view_bounds,
                      n_types=n_types)
    clone(grid).fit([np.empty((0, 3))])  # its checks, now rather than at the first fit
    return make_pipeline(
        grid, Ridge(alpha=_check_real("alpha", alpha, 0.0, np.inf, high_inclusive=False)))


class _GridModelPolicy:
    """A model trained on `GridObservation` features, playing from object sets."""

    def __init__(self, model, grid, observations):
        self.model = model
        self.grid = grid
        self._observations = observations

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        sets, single = self._observations.as_input(observation)
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
        Plays from object sets (``policy.predict(batch)``), for `fqi.evaluate`.
    reward : float
        Total return of the evaluation episodes (NaN when ``eval_episodes=0``).
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


def train_dqn(env, total_timesteps=400_000, *, n_bins=10, gamma=0.5, eval_episodes=None,
              eval_seeds=None, seed=None, torch_threads=1, progress_bar=False, **dqn_kwargs):
    """Train stable-baselines3 `DQN` on `GridObservation` and score it with `fqi.evaluate`.

    Parameters
    ----------
    env : str
        Registered id of an env observing object sets (a fresh env is made for training).
    total_timesteps : int, default=400_000
        Environment steps (20 FQI iterations of 20,000 samples are 400,000).
    n_bins : int, default=10
        Grid cells per axis of the observation.
    gamma : float, default=0.5
        Discount factor in ``[0, 1]`` (the FQI default, for a like-for-like comparison).
    eval_episodes, eval_seeds
        The evaluation after training, as `fqi.evaluate`'s `n_episodes` and `seeds`
        (default: 10 episodes on seeds from ``2**40``); ``eval_episodes=0`` skips it.
    seed : int >= 0 or None, default=None
        Seeds DQN (and through it the training resets, below ``2**40``).
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
    total_timesteps = _check_int("total_timesteps", total_timesteps, 1)
    gamma = _check_real("gamma", gamma, 0.0, 1.0)
    seeds = _eval_seeds(eval_episodes, eval_seeds, "eval_episodes", "eval_seeds")
    seed = _check_seed("seed", seed)
    torch_threads = _check_int("torch_threads", torch_threads, 1)
    progress_bar = _check_bool("progress_bar", progress_bar)
    reserved = sorted({"policy", "env", "gamma", "seed", "device"} & set(dqn_kwargs))
    if reserved:
        raise TypeError(f"train_dqn sets {reserved} itself (gamma and seed are its own "
                        f"arguments); they cannot be DQN keywords")
    train_env = GridObservation(gym.make(env), n_bins=n_bins)
    try:
        model = DQN("MlpPolicy", train_env, gamma=gamma, seed=seed, device="cpu",
                    **{**_DQN_DEFAULTS, **dqn_kwargs})
    except BaseException:
        train_env.close()
        raise
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
    policy = _GridModelPolicy(model, train_env.grid,
                              _ObjectRows(train_env.env.observation_space))
    reward = evaluate(policy, env, seeds=seeds).total if seeds else np.nan
    train_env.close()
    return DQNResult(model, policy, reward, trained - start, time.perf_counter() - trained,
                     total_timesteps)
