"""Summaries of one setting's runs: the numbers the plots, the findings and the report use."""
from dataclasses import dataclass

import numpy as np

__all__ = ["SettingStats", "summarise", "LAST_WINDOW", "last_window"]

# A run's score: its mean reward over the last iterations (the thesis's "converges to").
LAST_WINDOW = 5


def last_window(budget):
    """How many iterations an FQI score averages at `budget`: the last `LAST_WINDOW`, or
    every iteration of a shorter run."""
    return min(LAST_WINDOW, budget.iterations)


@dataclass
class SettingStats:
    """One setting of one experiment, over its finished runs.

    Attributes
    ----------
    label : str
    kind : {"fqi", "rmse", "dqn", "sb3", "policy", "attention"}
    n_runs : int
    score : float
        FQI: mean over runs of the mean reward (per 20,000 steps) of the last
        `LAST_WINDOW` iterations; DQN, SB3, a reference policy: mean final reward; RMSE:
        mean RMSE.
    score_sd : float
        Standard deviation of the per-run scores (0 with one run).
    score_se : float
        Standard error of `score` from every value it averages (last-window rewards of
        every run; every fold's RMSE of one data set, or the per-data-set RMSEs of
        several): also defined for a single run.
    lower_is_better : bool
        True for RMSE.
    curve_mean, curve_sd : ndarray or None
        FQI: reward per iteration, mean and sd over runs; index 0 is the random policy.
    best : float
        FQI / DQN: best evaluation of any run (any iteration).
    instability : float
        FQI: mean absolute change of the reward between consecutive iterations (after
        iteration 1), averaged over runs; NaN otherwise.
    mean_peak : float
        FQI: the highest point of the mean curve over runs (iteration 1 on).
    spread : float
        FQI: the sd of the reward over runs, averaged over the iterations (1 on): the
        width of the figure's band; NaN with one run.
    random_reward : float
        FQI: mean reward of the uniform random policy on the same evaluation.
    seconds : float
        Mean wall time per run.
    """

    label: str
    kind: str
    n_runs: int
    score: float
    score_sd: float
    score_se: float
    lower_is_better: bool = False
    curve_mean: np.ndarray = None
    curve_sd: np.ndarray = None
    best: float = np.nan
    instability: float = np.nan
    mean_peak: float = np.nan
    spread: float = np.nan
    random_reward: float = np.nan
    seconds: float = np.nan


def summarise(label, kind, runs):
    """The `SettingStats` of a setting from its unit results.

    Parameters
    ----------
    label : str
    kind : str
        The unit kind that produced `runs`.
    runs : list of dict
        Unit results (see `reproduce.units`), at least one.

    Returns
    -------
    stats : SettingStats
    """
    seconds = float(np.mean([r["seconds"] for r in runs]))
    if kind == "fqi":
        curves = np.array([[r["random_reward"], *r["rewards"]] for r in runs])
        window = curves[:, 1:][:, -LAST_WINDOW:]
        scores = window.mean(axis=1)
        changes = np.abs(np.diff(curves[:, 1:], axis=1))
        return SettingStats(
            label, kind, len(runs), float(scores.mean()), _sd(scores), _se(window),
            curve_mean=curves.mean(axis=0), curve_sd=curves.std(axis=0),
            best=float(curves[:, 1:].max()),
            instability=float(changes.mean()) if changes.size else np.nan,
            mean_peak=float(curves[:, 1:].mean(axis=0).max()),
            spread=float(curves[:, 1:].std(axis=0).mean()) if len(runs) > 1 else np.nan,
            random_reward=float(curves[:, 0].mean()), seconds=seconds)
    if kind == "rmse":
        folds = np.array([r["fold_rmse"] for r in runs])
        scores = folds.mean(axis=1)
        # one data set: the folds' spread; several: how the score changes between data sets
        se = _se(folds) if len(runs) == 1 else _se(scores)
        return SettingStats(label, kind, len(runs), float(scores.mean()), _sd(scores),
                            se, lower_is_better=True, seconds=seconds)
    if kind in ("dqn", "sb3", "policy"):
        rewards = np.array([r["reward"] for r in runs])
        return SettingStats(label, kind, len(runs), float(rewards.mean()), _sd(rewards),
                            _se(rewards), best=float(rewards.max()), seconds=seconds)
    if kind == "attention":
        return SettingStats(label, kind, len(runs), np.nan, np.nan, np.nan, seconds=seconds)
    raise ValueError(f"unknown unit kind {kind!r}")


def _sd(values):
    return float(np.std(values, ddof=1)) if len(values) > 1 else 0.0


def _se(values):
    values = np.ravel(values)
    return float(np.std(values, ddof=1) / np.sqrt(len(values))) if len(values) > 1 else np.nan
