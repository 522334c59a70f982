"""Summaries of one setting's runs: the numbers the plots, the findings and the report use
(each unit kind's ``summarise`` makes them, `kinds`)."""
from dataclasses import dataclass

import numpy as np

__all__ = ["SettingStats", "LAST_WINDOW", "last_window", "sd", "se", "steps_to_threshold",
           "median_steps"]

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
    kind : str
        The unit kind of the runs (`kinds.KINDS`).
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


def sd(values):
    """Sample standard deviation of per-run scores (0 for a single run)."""
    return float(np.std(values, ddof=1)) if len(values) > 1 else 0.0


def se(values):
    """Standard error of the mean of every value of `values` (NaN for a single value)."""
    values = np.ravel(values)
    return float(np.std(values, ddof=1) / np.sqrt(len(values))) if len(values) > 1 else np.nan


def steps_to_threshold(evaluations, threshold):
    """The steps of the first ``[steps, score]`` of `evaluations` (an `EvalCallback`'s)
    scoring at least `threshold`; None if none does, or if `threshold` is None."""
    if threshold is None:
        return None
    return next((steps for steps, score in evaluations if score >= threshold), None)


def median_steps(crossings):
    """The median of runs' `steps_to_threshold` values, a run that never reached the
    threshold (None) counting as later than every other: None when that median run (or
    either of the middle two) never reached it, or without runs.

    >>> median_steps([15004, None, 25015, None, 20010])
    25015.0
    >>> median_steps([None, 20000, None]) is None
    True
    """
    median = np.median([np.inf if c is None else c for c in crossings]) if crossings else None
    return None if median is None or median == np.inf else float(median)
