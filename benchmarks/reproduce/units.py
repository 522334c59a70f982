"""A unit of work: one setting of an experiment at one seed and budget, and running it."""
import time
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

from threadpoolctl import threadpool_limits

from .budgets import Budget
from .kinds import KINDS

__all__ = ["Unit", "run_unit"]


@dataclass(frozen=True)
class Unit:
    """One run to do: a setting of the experiment owning it, at one seed and budget.

    Parameters
    ----------
    experiment, label : str
        The owning experiment and the setting's label.
    seed : int
    params : dict
        The setting's parameters (`Experiment.params`); ``params["kind"]`` names its
        `kinds.UnitKind`. As recorded with its result: part of the cache key.
    samples : int
        Samples per FQI iteration (the budget's, scaled by the experiment).
    budget : Budget
    path : pathlib.Path
        Where its result is cached (`cache.unit_path`).
    """

    experiment: str
    label: str
    seed: int
    params: dict
    samples: int
    budget: Budget
    path: Path

    @property
    def kind(self):
        """The `kinds.UnitKind` that runs it."""
        return KINDS[self.params["kind"]]

    @cached_property
    def settings(self):
        """Its parameters, typed (the kind's ``Settings``)."""
        return self.kind.settings(self.params)

    @property
    def name(self):
        """``experiment/label/seed<k>``, for messages."""
        return f"{self.experiment}/{self.label}/seed{self.seed}"

    def cost(self):
        """Rough run time in seconds on 2 free cores (measured at the quick budget), for
        the progress bar's ETA."""
        return self.kind.cost(self)


def run_unit(unit, checkpoint=None):
    """Run one unit.

    Parameters
    ----------
    unit : Unit
    checkpoint : reproduce.cache.Checkpoint, default=None
        A resumable kind saves its state there (at most every ``checkpoint.interval``
        seconds) and resumes from what it finds there, to the result it would have had
        uninterrupted. Other kinds ignore it.

    Returns
    -------
    result : dict
        JSON-ready; always has ``seconds`` (a resumed run's: of all its parts).
    """
    start = time.perf_counter()
    # One BLAS thread: the forests bring their own threads, and on 2 shared cores the
    # ridge fit of the grid baseline ran 10x slower with OpenBLAS's 2 threads (measured).
    with threadpool_limits(1, user_api="blas"):
        result = unit.kind.run(unit, checkpoint if unit.kind.resumable else None)
    result["seconds"] = result.pop("earlier_seconds", 0.0) + time.perf_counter() - start
    return result
