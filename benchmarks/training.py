"""stable-baselines3 agents trained and scored the same way in every benchmark.

- `train_sb3`: an SB3 algorithm on a vector of envs, from rl-zoo3-style hyperparameters,
  with one torch thread and no log folder;
- `EvalCallback`: scores the model on fixed reset seeds (`fqi.evaluate`) every
  ``eval_freq`` environment steps and when training ends, for SB3 models and `fqi.FQI`
  alike, and times training without its evaluations (`timed_learn`);
- `StopAt`: ends training after a number of environment steps;
- `WrappedPolicy`: a model trained on an observation wrapper's output, playing from the
  env's own observations.

Importing this module imports stable-baselines3 (and torch).
"""
import inspect
import time
from contextlib import contextmanager

import numpy as np
import torch
from stable_baselines3 import DQN, PPO
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.env_util import make_vec_env
from stable_baselines3.common.logger import Logger
from stable_baselines3.common.vec_env import VecNormalize

from fqi import evaluate

__all__ = ["ALGORITHMS", "train_sb3", "timed_learn", "EvalCallback", "StopAt",
           "WrappedPolicy", "torch_threads"]

ALGORITHMS = {"DQN": DQN, "PPO": PPO}


@contextmanager
def torch_threads(n_threads=1):
    """Torch's thread pool at `n_threads` inside the block, restored after it. On 2
    shared cores the default pool trained 12x slower than one thread (measured)."""
    threads = torch.get_num_threads()
    torch.set_num_threads(n_threads)
    try:
        yield
    finally:
        torch.set_num_threads(threads)


class EvalCallback(BaseCallback):
    """Score the model every `eval_freq` environment steps and once more when training
    ends, as stable-baselines3's ``EvalCallback`` does, on fixed reset seeds.

    It works with stable-baselines3 models and with `fqi.FQI` (whose ``learn`` calls it
    after each iteration). With SB3, whose last updates come after the last step's call,
    the evaluation of the final step waits for the end of training.

    Parameters
    ----------
    eval_env : str, gymnasium.Env, gymnasium.vector.VectorEnv or callable
        The env played, as for `fqi.evaluate`.
    eval_freq : float
        An evaluation at the first step at or after each multiple of it.
    seeds : sequence of int, default=None
        One reset seed per episode (default: `fqi.evaluate`'s held-out seeds, `n_episodes`
        of them).
    n_episodes : int, default=None
        As for `fqi.evaluate`.
    policy : callable, default=None
        ``policy(model)``: what plays (default: the model itself).
    score : {"mean", "total"}, default="mean"
        The `fqi.Evaluation` field recorded.
    scale : float, default=1.0
        Multiplies the recorded score.
    verbose : int, default=0
        1: print each evaluation.

    Attributes
    ----------
    evaluations : list of [int, float]
        ``[num_timesteps, score]`` of each evaluation.
    eval_seconds, eval_cpu_seconds : float
        Wall and CPU time spent evaluating.
    """

    def __init__(self, eval_env, eval_freq, *, seeds=None, n_episodes=None, policy=None,
                 score="mean", scale=1.0, verbose=0):
        super().__init__(verbose)
        if not eval_freq > 0:
            raise ValueError(f"eval_freq must be > 0, got {eval_freq!r}")
        if score not in ("mean", "total"):
            raise ValueError(f"score must be 'mean' or 'total', got {score!r}")
        self.eval_env, self.eval_freq = eval_env, eval_freq
        self.seeds, self.n_episodes = seeds, n_episodes
        self.policy, self.score, self.scale = policy, score, scale
        self.evaluations = []
        self.eval_seconds = self.eval_cpu_seconds = 0.0
        self._due, self._end = eval_freq, None

    def _on_training_start(self):
        # the step count at which training ends: SB3 keeps it; FQI's learn has the steps of
        # the call (None with n_iterations, whose calls come after whole iterations)
        total = self.locals.get("total_timesteps")
        self._end = getattr(self.model, "_total_timesteps", None) or (
            None if total is None else self.model.num_timesteps + total)

    def _on_step(self):
        if self.num_timesteps >= self._due and (self._end is None
                                                or self.num_timesteps < self._end):
            self._evaluate()
        return True

    def _on_training_end(self):
        self.num_timesteps = self.model.num_timesteps
        if not self.evaluations or self.evaluations[-1][0] != self.num_timesteps:
            self._evaluate()

    def _evaluate(self):
        start, cpu_start = time.perf_counter(), time.process_time()
        player = self.model if self.policy is None else self.policy(self.model)
        result = evaluate(player, self.eval_env, n_episodes=self.n_episodes, seeds=self.seeds)
        value = float(getattr(result, self.score) * self.scale)
        self.evaluations.append([int(self.num_timesteps), value])
        self.eval_seconds += time.perf_counter() - start
        self.eval_cpu_seconds += time.process_time() - cpu_start
        self._due = (self.num_timesteps // self.eval_freq + 1) * self.eval_freq
        if self.verbose:
            print(f"{self.num_timesteps:,} steps: {self.score} return {value:,.1f}")


class StopAt(BaseCallback):
    """Ends ``learn`` once the model has taken `steps` environment steps (counting every
    ``learn`` call's): a run on the schedule of a longer ``total_timesteps`` (its
    exploration decays as in that run), cut short.

    An SB3 model stops after the vector step that reaches `steps` (fewer than ``n_envs``
    steps past it); `fqi.FQI` calls its callbacks after each iteration, so it stops after
    the first iteration whose collection reaches `steps` (its round's end, up to
    ``n_envs - 1`` steps more), skipping that round's remaining backups. An `EvalCallback`
    beside it scores the last step either way (at training's end).
    """

    def __init__(self, steps):
        super().__init__()
        self.steps = steps

    def _on_step(self):
        return self.num_timesteps < self.steps


def timed_learn(model, callback=None, **learn_kwargs):
    """``model.learn(callback=callback, **learn_kwargs)``, timed without the evaluations of
    the `EvalCallback` objects of `callback` (one, or a list).

    Returns
    -------
    seconds, cpu_seconds : float
        Wall and CPU time of training.
    """
    evaluations = [c for c in (callback if isinstance(callback, list) else [callback])
                   if isinstance(c, EvalCallback)]

    def evaluating():
        return (sum(c.eval_seconds for c in evaluations),
                sum(c.eval_cpu_seconds for c in evaluations))

    before = evaluating()
    start, cpu_start = time.perf_counter(), time.process_time()
    model.learn(callback=callback, **learn_kwargs)
    seconds, cpu_seconds = time.perf_counter() - start, time.process_time() - cpu_start
    after = evaluating()  # of this call only: a callback may have scored earlier calls
    return seconds - (after[0] - before[0]), cpu_seconds - (after[1] - before[1])


def train_sb3(algo, make_env, total_timesteps, hyperparams, *, seed=None, callback=None,
              policy="MlpPolicy"):
    """Train a stable-baselines3 algorithm on copies of an env, one torch thread.

    Parameters
    ----------
    algo : {"DQN", "PPO"}
    make_env : callable
        Returns one training env (wrapped as the model observes it).
    total_timesteps : int
    hyperparams : dict
        The algorithm's keyword arguments, as rl-zoo3 writes them: ``n_envs`` training envs
        (default 1) and ``normalize`` (default False: True trains on rewards scaled by a
        running estimate of the return's spread, `VecNormalize` on rewards only; the
        observations hold padding rows and a presence mask) are taken out.
    seed : int, default=None
        Seeds the algorithm and the training envs.
    callback : BaseCallback or list of them, default=None
        An `EvalCallback` is timed apart from training.
    policy : str, default="MlpPolicy"

    Returns
    -------
    model : stable_baselines3.common.base_class.BaseAlgorithm
    seconds, cpu_seconds : float
        Wall and CPU time of training (evaluations excluded).
    """
    hyperparams = dict(hyperparams)
    n_envs = hyperparams.pop("n_envs", 1)
    normalize = hyperparams.pop("normalize", False)
    algorithm = ALGORITHMS[algo]
    train_env = make_vec_env(make_env, n_envs=n_envs, seed=seed)
    if normalize:  # the evaluations play the raw env and count raw rewards
        gamma = hyperparams.get("gamma",
                                inspect.signature(algorithm).parameters["gamma"].default)
        train_env = VecNormalize(train_env, norm_obs=False, norm_reward=True, gamma=gamma)
    try:
        model = algorithm(policy, train_env, seed=seed, device="cpu", **hyperparams)
        model.set_logger(Logger(None, []))  # SB3's default logger makes a folder per run
        with torch_threads(1):
            seconds, cpu_seconds = timed_learn(model, callback,
                                               total_timesteps=total_timesteps)
    finally:
        train_env.close()
    return model, seconds, cpu_seconds


class WrappedPolicy:
    """A model trained on an observation wrapper's output, playing from the env's own
    observations (the wrapper's ``observation`` applied to each of a batch).

    Parameters
    ----------
    model : object
        Has ``predict(batch, deterministic=True)``.
    wrapper : gymnasium.ObservationWrapper
    sampled : bool, default=False
        Always play the model's non-deterministic actions (as rl-zoo3 plays Atari games),
        even when asked for greedy ones.
    """

    def __init__(self, model, wrapper, sampled=False):
        self.model, self.wrapper, self.sampled = model, wrapper, sampled

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        batch = np.stack([self.wrapper.observation(observation[i])
                          for i in range(len(observation))])
        return self.model.predict(batch, deterministic=deterministic and not self.sampled)[0], None
