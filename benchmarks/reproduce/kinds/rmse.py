"""``rmse``: Appendix A's study, the k-fold cross-validated RMSE of the first FQI
iteration's regression (targets: immediate rewards) on random-play transitions."""
import dataclasses
from functools import lru_cache

import gymnasium as gym
import numpy as np
from sklearn.base import clone
from sklearn.model_selection import KFold

import envs
from boxtrees import ObjectSets

from .. import plots
from ..cache import ListOf
from ..stats import SettingStats, sd, se
from ._base import UnitKind, _seconds
from ._game import ForestSettings, forest_cost, make_env, regressor

__all__ = ["RMSE"]


class RMSE(UnitKind):
    """Per action, the RMSE of each fold of the budget's random-play data set (seed: the
    unit's), averaged over the actions."""

    name = "rmse"
    Settings = ForestSettings
    budget_fields = ("rmse_samples", "rmse_folds", "max_trees", "max_tests")
    one_seed = True

    def run(self, unit, checkpoint=None):
        settings, budget, seed = unit.settings, unit.budget, unit.seed
        env = make_env(settings)
        states, actions, rewards = _random_transitions(
            settings.env_id, tuple(sorted(settings.env_kwargs().items())),
            budget.rmse_samples, seed)
        template = regressor(settings, env, budget, seed)
        folds = KFold(budget.rmse_folds, shuffle=True, random_state=seed)
        per_action = []
        for action in range(env.action_space.n):
            index = np.flatnonzero(actions == action)
            X, y = states[index], rewards[index]
            errors = []
            for train, test in folds.split(index):
                model = clone(template).fit(X[train], y[train])
                errors.append(float(np.sqrt(np.mean((model.predict(X[test]) - y[test]) ** 2))))
            per_action.append(errors)
        per_action = np.array(per_action)
        return {"fold_rmse": per_action.mean(axis=0).tolist(),
                "action_rmse": per_action.mean(axis=1).tolist(),
                "n_samples": len(rewards)}

    def cost(self, unit):
        budget = unit.budget
        return (0.1 * budget.rmse_samples / 1000 * budget.rmse_folds / 3
                * forest_cost(unit.settings))

    def record_shape(self, budget):
        return {"fold_rmse": ListOf(float, budget.rmse_folds)}

    def summarise(self, label, runs):
        folds = np.array([r["fold_rmse"] for r in runs])
        scores = folds.mean(axis=1)
        # one data set: the folds' spread; several: how the score changes between data sets
        error = se(folds) if len(runs) == 1 else se(scores)
        return SettingStats(label, self.name, len(runs), float(scores.mean()), sd(scores),
                            error, lower_is_better=True, seconds=_seconds(runs))

    def values(self, result):
        return result["fold_rmse"]

    def plot(self, experiment, stats, runs, budget):
        return plots.rmse_bars(experiment, stats, runs, budget)

    def table(self, experiment, stats, runs):
        lines = ["| setting | RMSE (mean over folds and actions) | sd over folds | thesis |",
                 "| --- | --- | --- | --- |"]
        for label, s in stats.items():
            folds = [f for r in runs[label] for f in r["result"]["fold_rmse"]]
            sd = (sum((f - s.score) ** 2 for f in folds) / max(len(folds) - 1, 1)) ** 0.5
            lines.append(f"| {label} | {s.score:.2f} | {sd:.2f} | "
                         f"{experiment.thesis.get(label, '')} |")
        return lines


@lru_cache(maxsize=4)
def _random_transitions(env_id, env_kwargs, n_samples, seed):
    """`n_samples` (state, action, reward) of the uniform random policy on training worlds
    (seeds below the reference worlds'), shuffled later by the folds; `env_kwargs` as
    sorted pairs."""
    rules = gym.make(env_id, **dict(env_kwargs)).unwrapped.rules
    n_worlds = min(400, n_samples)
    worlds = envs.BatchedObjectWorld(n_worlds, **dataclasses.asdict(rules))
    rng = np.random.default_rng(seed)
    states, actions, rewards = [], [], []
    obs, _ = worlds.reset(seed=rng.integers(envs.REFERENCE_SEED_START, size=n_worlds).tolist())
    for step in range(-(-n_samples // n_worlds)):
        if step and step % rules.max_steps == 0:
            obs, _ = worlds.reset()  # lockstep worlds end their episodes together
        action = rng.integers(rules.n_actions, size=n_worlds)
        states.append(ObjectSets(obs.data.copy(), obs.offsets.copy()))
        actions.append(action)
        obs, reward, _, _, _ = worlds.step(action)
        rewards.append(reward.copy())
    return (ObjectSets.concatenate(states)[:n_samples],
            np.concatenate(actions)[:n_samples], np.concatenate(rewards)[:n_samples])
