"""``games``: a learner on a real game seen as a set of objects (an Atari game through
`envs.AtariObjects`, a highway-env task through `envs.HighwayObjects`): box FQI, a
stable-baselines3 DQN or PPO reading the same objects (`envs.PaddedObjects` through
`fqi.SetEncoder`), the random policy or a scripted one, scored on held-out episodes every
few thousand steps."""
import time
from dataclasses import dataclass, field

import gymnasium as gym
import numpy as np

import envs
from boxtrees import BoxExtraTreesRegressor
from fqi import FQI, RandomPolicy, evaluate

from ._base import fmt
from .control import Control, training_minutes
from .sb3 import with_set_encoder

__all__ = ["Games", "HUMAN_SCORES"]

# The random and human scores that normalise Atari scores (Mnih et al., 2015, as the
# literature uses them): 0 is random play, 1 the human tester.
HUMAN_SCORES = {"Pong": (-20.7, 9.3), "Freeway": (0.0, 29.6), "Boxing": (0.1, 12.1)}
_LEARNERS = ("fqi", "DQN", "PPO", "random", "scripted")
_ATARI = "AtariObjects-v0"
# Rough seconds on one core: an environment step of each suite, a learner's own per step
# (FQI's fits and predictions, SB3's updates through the set encoder), and the steps of an
# evaluation episode (Atari's at most the budget's cap, highway-fast's 30 s of driving)
_ENV_SECONDS = {True: 1e-3, False: 0.04}             # by whether the game is Atari's
_LEARNER_SECONDS = {"fqi": 4e-3, "DQN": 3e-3, "PPO": 2e-3, "random": 0.0, "scripted": 0.0}
_EPISODE_STEPS = {True: 2_000, False: 30}


def _pong(env):
    """Move the paddle towards the ball's height; stay still without a ball."""
    ball, actions = env.type_names.index("Ball"), env.action_names
    up, down, stay = actions.index("RIGHT"), actions.index("LEFT"), actions.index("NOOP")

    def act(rows, step):
        balls = rows[rows[:, -1] == ball]
        if not len(balls) or abs(balls[0, 1]) < 4:
            return stay
        return up if balls[0, 1] < 0 else down
    return act


def _freeway(env):
    """Always cross: UP."""
    up = env.action_names.index("UP")
    return lambda rows, step: up


def _boxing(env):
    """Close in to 15 pixels across, keep 4 to 10 pixels of height from the enemy (punches
    land off its level: docs/games.md), and punch every other step (a new punch needs the
    button released)."""
    enemy, actions = env.type_names.index("Enemy"), env.action_names
    near, low, high = 15, 4, 10

    def act(rows, step):
        enemies = rows[rows[:, -1] == enemy]
        if not len(enemies):
            return actions.index("NOOP")
        x, y = enemies[0, :2]
        vertical = ("DOWN" if y > 0 else "UP") if abs(y) > high else (
            ("UP" if y > 0 else "DOWN") if abs(y) < low else "")
        name = vertical + ("RIGHT" if x > near else "LEFT" if x < -near else "")
        return actions.index(name or ("FIRE" if step % 2 == 0 else "NOOP"))
    return act


def _highway(env):
    """Keep the lane: faster while it is clear for 30 m ahead, slower otherwise."""
    actions = env.unwrapped.action_type.actions_indexes
    faster, slower = actions["FASTER"], actions["SLOWER"]

    def act(rows, step):
        ahead = (rows[:, 0] > 0) & (rows[:, 0] < 30) & (np.abs(rows[:, 1]) < 2)
        return slower if ahead[1:].any() else faster
    return act


_SCRIPTS = {"Pong": _pong, "Freeway": _freeway, "Boxing": _boxing,
            "highway-fast-v0": _highway, "highway-v0": _highway}


class _ScriptedPolicy:
    """A rule from one env's observation rows and its count of steps so far to an action,
    with the ``predict`` signature of stable-baselines3 over a vector env's batch (one count
    per position in the batch)."""

    def __init__(self, rule):
        self.rule, self._steps = rule, None

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        if self._steps is None or len(self._steps) != len(observation):
            self._steps = np.zeros(len(observation), dtype=np.int64)
        actions = np.array([self.rule(np.asarray(rows), step)
                            for rows, step in zip(observation, self._steps)])
        self._steps += 1
        return actions, None


@dataclass(frozen=True)
class GamesSettings:
    """``env_id``: ``"AtariObjects-v0"`` (`envs.AtariObjects`) or a highway-env id such as
    "highway-fast-v0" (wrapped in `envs.HighwayObjects`), made with ``env_kwargs`` (the
    Atari game's name and arguments, or highway-env's ``config``); ``learner`` ("fqi",
    "DQN", "PPO", "random" or "scripted") and ``steps`` (environment steps at full size,
    for the learners); for FQI ``forest`` (`boxtrees.BoxExtraTreesRegressor` arguments)
    and ``fqi`` (`fqi.FQI` arguments other than its defaults); for SB3 ``hyperparams``
    (rl-zoo3's form, `training.train_sb3`), ``max_objects`` (the padded rows) and
    ``sampled_actions`` (the evaluations play actions drawn from the policy, as rl-zoo3
    plays Atari games, instead of the greedy ones); the evaluation: ``eval_episodes``
    held-out episodes every ``eval_every`` steps."""

    env_id: str
    learner: str = None
    steps: int = None
    env_kwargs: dict = field(default_factory=dict)
    forest: dict = field(default_factory=dict)
    fqi: dict = field(default_factory=dict)
    hyperparams: dict = field(default_factory=dict)
    max_objects: int = 32
    sampled_actions: bool = False
    eval_every: int = 50_000
    eval_episodes: int = 5

    def __post_init__(self):
        if self.atari and "game" not in self.env_kwargs:
            raise ValueError(f"{_ATARI} needs env_kwargs['game'], got {self.env_kwargs!r}")
        if self.learner not in _LEARNERS:
            raise ValueError(f"learner must be one of {_LEARNERS}, got {self.learner!r}")
        if self.learner == "scripted" and self.game not in _SCRIPTS:
            raise ValueError(f"no scripted policy for {self.game!r} (scripts: "
                             f"{', '.join(_SCRIPTS)})")
        if self.sampled_actions and self.learner not in ("DQN", "PPO"):
            raise ValueError(f"sampled_actions is for the DQN and PPO learners, not "
                             f"{self.learner!r}")
        learns = self.learner in ("fqi", "DQN", "PPO")
        if learns and not (isinstance(self.steps, int) and self.steps >= 1):
            raise ValueError(f"steps must be a whole number >= 1, got {self.steps!r}")

    @property
    def atari(self):
        """Whether the game is an Atari game."""
        return self.env_id == _ATARI

    @property
    def game(self):
        """The Atari game's name, or the highway-env id."""
        return self.env_kwargs["game"] if self.atari else self.env_id

    def make_env(self, budget):
        """The game as object sets (an env `gymnasium.make` rebuilds from its spec)."""
        if self.atari:
            frames = ({} if budget.game_frames is None
                      else {"max_num_frames_per_episode": budget.game_frames})
            return gym.make(_ATARI, **{**self.env_kwargs, **frames})
        return envs.HighwayObjects(gym.make(f"highway_env:{self.env_id}", **self.env_kwargs))


class Games(Control):
    """The mean return on held-out episodes against environment steps (a fixed policy's
    once), Atari's also human-normalised, and the seconds of training."""

    name = "games"
    Settings = GamesSettings
    budget_fields = ("control_scale", "game_frames")

    def run(self, unit, checkpoint=None):
        settings, budget = unit.settings, unit.budget
        env = settings.make_env(budget)
        evaluation = gym.make_vec(env.spec, settings.eval_episodes, vectorization_mode="sync")
        try:
            if settings.learner in ("random", "scripted"):
                return self._play(unit, env, evaluation)
            return self._learn(unit, env, evaluation)
        finally:
            evaluation.close()
            env.close()

    def _play(self, unit, env, evaluation):
        """A fixed policy's result: its score, once."""
        settings = unit.settings
        policy = (RandomPolicy(env, seed=unit.seed) if settings.learner == "random"
                  else _ScriptedPolicy(_SCRIPTS[settings.game](env.unwrapped)))
        start = time.perf_counter()
        score = float(evaluate(policy, evaluation, n_episodes=settings.eval_episodes).mean)
        return self._result(settings, score, [[0, score]], 0, 0.0, 0.0,
                            time.perf_counter() - start)

    def _learn(self, unit, env, evaluation):
        """A learner's result: its score every ``eval_every`` steps and at the end."""
        from ...training import EvalCallback, WrappedPolicy, timed_learn, train_sb3

        settings, budget = unit.settings, unit.budget
        steps = max(1, round(settings.steps * budget.control_scale))
        padded = envs.PaddedObjects(env, settings.max_objects)
        curve = EvalCallback(evaluation, max(1, round(settings.eval_every
                                                      * budget.control_scale)),
                             n_episodes=settings.eval_episodes,
                             policy=(None if settings.learner == "fqi"
                                     else lambda model: WrappedPolicy(
                                         model, padded, sampled=settings.sampled_actions)))
        if settings.learner == "fqi":
            agent = FQI(BoxExtraTreesRegressor(**settings.forest), env, eval_episodes=0,
                        seed=unit.seed, **settings.fqi)
            seconds, cpu_seconds = timed_learn(agent, curve, total_timesteps=steps)
            done = agent.num_timesteps
            agent.get_env().close()
        else:
            model, seconds, cpu_seconds = train_sb3(
                settings.learner,
                lambda: envs.PaddedObjects(settings.make_env(budget), settings.max_objects),
                steps, with_set_encoder(settings.hyperparams), seed=unit.seed, callback=curve)
            done = model.num_timesteps
        return self._result(settings, curve.evaluations[-1][1], curve.evaluations, done,
                            seconds, cpu_seconds, curve.eval_seconds)

    @staticmethod
    def _result(settings, score, curve, steps, seconds, cpu_seconds, eval_seconds):
        low, high = HUMAN_SCORES.get(settings.game, (None, None))
        return {"reward": score, "curve": curve, "total_timesteps": int(steps),
                "human_normalised": None if low is None else (score - low) / (high - low),
                "train_seconds": seconds, "train_cpu_seconds": cpu_seconds,
                "eval_seconds": eval_seconds}

    def cost(self, unit):
        settings, budget = unit.settings, unit.budget
        step = _ENV_SECONDS[settings.atari]
        steps = (settings.steps or 0) * budget.control_scale
        episode = _EPISODE_STEPS[settings.atari]
        if settings.atari and budget.game_frames is not None:
            episode = min(episode, budget.game_frames / 4)
        evaluations = 1 + (settings.steps or 0) // settings.eval_every
        return (steps * (step + _LEARNER_SECONDS[settings.learner])
                + evaluations * settings.eval_episodes * episode * step)

    def curve(self, stats, records):
        if records[0]["result"]["total_timesteps"] == 0:
            return None     # a fixed policy: a line
        return super().curve(stats, records)

    def table(self, experiment, stats, runs):
        lines = ["| setting | runs | final mean return +- sd over runs | human-normalised | "
                 "environment steps | training minutes per run (CPU) |",
                 "| --- | --- | --- | --- | --- | --- |"]
        for label, s in stats.items():
            results = [r["result"] for r in runs[label]]
            normalised = [r["human_normalised"] for r in results]
            normalised = None if None in normalised else float(np.mean(normalised))
            trained = any(r["train_seconds"] for r in results)  # not a fixed policy
            lines.append(f"| {label} | {s.n_runs} | {s.score:,.1f} +- {s.score_sd:,.1f} | "
                         f"{fmt(normalised, 2)} | "
                         f"{fmt(results[0]['total_timesteps']) if trained else '-'} | "
                         f"{training_minutes(results)} |")
        return lines
