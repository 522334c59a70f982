"""``control``: a learner on a gymnasium task (classic control and any other registered id):
FQI with the library's defaults, or a stable-baselines3 algorithm with tuned settings,
scored on held-out episodes every few thousand steps."""
import inspect
from dataclasses import dataclass, field

import gymnasium as gym
import numpy as np
from sklearn.ensemble import ExtraTreesRegressor

from fqi import FQI, make_box_forest

from .. import plots
from ..cache import ListOf
from ..stats import median_steps, steps_to_threshold
from ._base import UnitKind, fmt

__all__ = ["Control", "REGRESSORS", "training_minutes"]

# The Extra-Trees of the FQI agents: 30 trees (or 150), nodes of fewer than 10 samples are
# leaves (or scikit-learn's default of 2: grown out), one job (so that every learner gets one
# core).
REGRESSORS = {
    "extra-trees": lambda: ExtraTreesRegressor(n_estimators=30, min_samples_split=10,
                                               n_jobs=1),
    "extra-trees, grown out": lambda: ExtraTreesRegressor(n_estimators=30, n_jobs=1),
    "extra-trees, 150 grown out": lambda: ExtraTreesRegressor(n_estimators=150, n_jobs=1),
    "box-classic": lambda: make_box_forest(test_type="classic", n_estimators=30, n_tests=10,
                                           min_samples_split=10, n_jobs=1),
}
_SECONDS_PER_STEP = 2.5e-3  # FQI's defaults on CartPole-v1 (30 trees), one core (measured)
# FQI's arguments a setting may give (the kind sets the others)
_FQI_SETTABLE = frozenset(inspect.signature(FQI).parameters) - {
    "regressor", "env", "eval_episodes", "seed"}


@dataclass(frozen=True)
class ControlSettings:
    """``env_id`` (a registered gymnasium id), ``learner`` ("fqi", "DQN" or "PPO"),
    ``steps`` (environment steps at full size), for FQI its ``regressor`` (a name of
    `REGRESSORS`) and ``fqi`` (`fqi.FQI` arguments other than its defaults), for SB3 its
    ``hyperparams`` (rl-zoo3's form, `training.train_sb3`); ``stop``: end the run after this
    many of its ``steps`` (None: run them all; schedules such as the exploration's still
    span ``steps``); the evaluation: ``eval_episodes`` held-out episodes every
    ``eval_every`` steps; ``threshold``: the task's solved score."""

    env_id: str
    learner: str = None
    steps: int = None
    regressor: str = "extra-trees"
    fqi: dict = field(default_factory=dict)
    hyperparams: dict = field(default_factory=dict)
    stop: int = None
    eval_every: int = 5000
    eval_episodes: int = 20
    threshold: float = None

    def __post_init__(self):
        if self.learner not in ("fqi", "DQN", "PPO"):
            raise ValueError(f"learner must be 'fqi', 'DQN' or 'PPO', got {self.learner!r}")
        if self.learner == "fqi" and self.regressor not in REGRESSORS:
            raise ValueError(f"regressor must be one of {tuple(REGRESSORS)}, got "
                             f"{self.regressor!r}")
        if not isinstance(self.steps, int) or self.steps < 1:
            raise ValueError(f"steps must be a whole number >= 1, got {self.steps!r}")
        if self.stop is not None and not (isinstance(self.stop, int)
                                          and not isinstance(self.stop, bool)
                                          and 1 <= self.stop <= self.steps):
            raise ValueError(f"stop must be None or a whole number from 1 to steps "
                             f"({self.steps}), got {self.stop!r}")
        unknown = sorted(set(self.fqi) - _FQI_SETTABLE)
        if unknown:
            raise ValueError(f"fqi takes no argument {', '.join(unknown)} here (the kind sets "
                             f"regressor, env, eval_episodes and seed; FQI's others: "
                             f"{', '.join(sorted(_FQI_SETTABLE))})")


class Control(UnitKind):
    """The mean return on held-out episodes against environment steps, the steps to the
    task's threshold, and the seconds of training."""

    name = "control"
    Settings = ControlSettings
    budget_fields = ("control_scale",)

    def run(self, unit, checkpoint=None):
        from ...training import EvalCallback, StopAt, timed_learn, train_sb3  # imports torch

        settings, scale = unit.settings, unit.budget.control_scale
        steps = max(1, round(settings.steps * scale))
        evaluation = gym.make_vec(settings.env_id, settings.eval_episodes,
                                  vectorization_mode="sync")
        curve = EvalCallback(evaluation, max(1, round(settings.eval_every * scale)),
                             n_episodes=settings.eval_episodes)
        callback = curve if settings.stop is None else [
            curve, StopAt(max(1, round(settings.stop * scale)))]
        try:
            if settings.learner == "fqi":
                agent = FQI(REGRESSORS[settings.regressor](), settings.env_id,
                            eval_episodes=0, seed=unit.seed, **settings.fqi)
                seconds, cpu_seconds = timed_learn(agent, callback, total_timesteps=steps)
                done = agent.num_timesteps
                agent.get_env().close()
            else:
                model, seconds, cpu_seconds = train_sb3(
                    settings.learner, lambda: gym.make(settings.env_id), steps,
                    settings.hyperparams, seed=unit.seed, callback=callback)
                done = model.num_timesteps
        finally:
            evaluation.close()
        return {"reward": curve.evaluations[-1][1], "curve": curve.evaluations,
                "steps_to_threshold": steps_to_threshold(curve.evaluations,
                                                         settings.threshold),
                "total_timesteps": int(done),
                "train_seconds": seconds, "train_cpu_seconds": cpu_seconds,
                "eval_seconds": curve.eval_seconds}

    def cost(self, unit):
        settings = unit.settings
        steps = settings.steps if settings.stop is None else settings.stop
        seconds = _SECONDS_PER_STEP * steps * unit.budget.control_scale
        if settings.learner == "fqi":  # measured with 30 trees: the fits scale with them
            seconds *= REGRESSORS[settings.regressor]().n_estimators / 30
        return seconds

    def record_shape(self, budget):
        return {"reward": float, "curve": ListOf(ListOf(float, 2))}

    def curve(self, stats, records):
        curves = [np.array(r["result"]["curve"], dtype=float) for r in records]
        points = min(len(c) for c in curves)  # the same evaluations, but for the last's step
        curves = np.array([c[:points] for c in curves])
        rewards = curves[:, :, 1]
        return curves[:, :, 0].mean(axis=0), rewards.mean(axis=0), rewards.std(axis=0)

    def plot(self, experiment, stats, runs, budget):
        thresholds = {experiment.params(label).get("threshold") for label in stats}
        curves = {label: self.curve(s, runs[label]) for label, s in stats.items()}
        return plots.versus_steps(experiment, stats, curves, budget,
                                  ylabel="mean return, held-out episodes",
                                  threshold=thresholds.pop() if len(thresholds) == 1 else None)

    def table(self, experiment, stats, runs):
        lines = ["| setting | runs | final mean return +- sd over runs | runs solved | median "
                 "steps to the threshold (a run that never reached it counts as the last) | "
                 "training minutes per run (CPU) |",
                 "| --- | --- | --- | --- | --- | --- |"]
        for label, s in stats.items():
            results = [r["result"] for r in runs[label]]
            crossings = [r.get("steps_to_threshold") for r in results]
            median = median_steps(crossings)
            if experiment.params(label).get("threshold") is None:
                solved = steps = "-"
            else:
                solved = f"{sum(c is not None for c in crossings)}/{s.n_runs}"
                steps = "never" if median is None else fmt(median)
            lines.append(f"| {label} | {s.n_runs} | {s.score:,.1f} +- {s.score_sd:,.1f} | "
                         f"{solved} | {steps} | {training_minutes(results)} |")
        return lines


def training_minutes(results):
    """Mean training minutes per run, wall and CPU, as ``"wall (CPU)"`` for a table."""
    wall, cpu = (np.mean([r[key] for r in results]) / 60
                 for key in ("train_seconds", "train_cpu_seconds"))
    return f"{wall:.1f} ({cpu:.1f})"
