"""The one runner: plan the (experiment, setting, seed) units, run the unfinished ones with
a progress bar, and gather the finished ones per setting."""
import sys
from dataclasses import dataclass
from pathlib import Path

from joblib import Parallel, delayed
from tqdm.auto import tqdm

from .cache import attempts, load_unit, mark_attempt, reset_attempts, save_unit, unit_path
from .registry import resolve
from .stats import summarise
from .units import run_unit

__all__ = ["Unit", "plan", "run", "gather", "seeds_for", "MAX_ATTEMPTS"]

# A unit that crashed this many times is skipped (reported missing; the command fails).
MAX_ATTEMPTS = 3


@dataclass(frozen=True)
class Unit:
    """One run to do: a setting of the experiment owning it, at one seed."""

    experiment: str
    label: str
    seed: int
    params: dict
    samples: int
    path: Path

    def cost(self, budget):
        """Rough run time in seconds on 2 free cores (measured at the quick budget), for
        the progress bar's ETA."""
        p = self.params
        if p["kind"] == "dqn":
            return 2.5e-3 * (budget.dqn_steps or budget.iterations * self.samples)
        trees = (p["n_estimators"] / 15 * (p["n_tests"] / 300) ** 0.5
                 if p.get("model") == "box" else 3.0)
        if p["kind"] == "rmse":
            return 0.1 * budget.rmse_samples / 1000 * budget.rmse_folds / 3 * trees
        iterations = (budget.attention_iterations if p["kind"] == "attention"
                      else budget.iterations)
        actions = 2.0 if p["env_id"] == "ObjectWorldSword-v0" else 1.0
        kept = 3.0 if p.get("keep_data") else 1.0
        objects = 9.0 if p.get("view") == "global" else 1.0  # ~360 objects, not ~40
        return 0.3 * iterations * self.samples / 1000 * trees * actions * kept * objects


def seeds_for(experiment, budget, seeds=None):
    """Seeds of an experiment: `seeds` if given (each once), else ``range(budget.seeds)``;
    the RMSE study and the attention figure use one data set / forest (seed 0), as the
    thesis."""
    if seeds is not None:
        return list(dict.fromkeys(seeds))
    n = 1 if experiment.kind in ("rmse", "attention") else budget.seeds
    return list(range(n))


def plan(experiments, budget, out, seeds=None):
    """Every unit the experiments need, each once (``same_as`` settings share their
    owner's units).

    Parameters
    ----------
    experiments : sequence of Experiment
    budget : Budget
    out : path-like
    seeds : sequence of int, default=None
        Overrides `seeds_for`.

    Returns
    -------
    units : list of Unit
    """
    units = {}
    for experiment in experiments:
        for label in experiment.settings:
            owner, owner_label = resolve(experiment, label)
            samples = int(budget.samples * owner.sample_scale)
            for seed in seeds_for(experiment, budget, seeds):
                path = unit_path(out, budget, owner.name, owner_label, seed)
                units.setdefault(path, Unit(owner.name, owner_label, seed,
                                            owner.params(owner_label, budget), samples, path))
    return list(units.values())


def _execute(unit, budget):
    mark_attempt(unit.path)
    result = run_unit(unit.params, budget, unit.seed, unit.samples)
    save_unit(unit.path, unit.params, budget, unit.samples, unit.experiment, unit.label,
              unit.seed, result)
    return unit, result["seconds"]


def run(units, budget, jobs=1, progress=True):
    """Run the units not already cached; show one progress bar with ETA over all of them.

    A unit's start counts as a crash until the unit finishes; an interrupt (Ctrl-C) takes
    the count back, so only crashes get a unit skipped (after `MAX_ATTEMPTS` of them).

    Parameters
    ----------
    units : list of Unit
    budget : Budget
    jobs : int, default=1
        Parallel processes (joblib loky). Each FQI run already uses every core for its
        forests, so 1 is usually fastest.
    progress : bool, default=True

    Returns
    -------
    done : list of (Unit, float)
        The units run now and their seconds (cached units are skipped).
    skipped : list of Unit
        The units not run because they crashed `MAX_ATTEMPTS` times.
    """
    crashes = {u.path: attempts(u.path) for u in units
               if load_unit(u.path, u.params, budget, u.samples, u.seed) is None}
    # Seed-major order, so an interrupted run leaves every setting with its first seeds
    # done; units that crashed before go last, and are skipped after MAX_ATTEMPTS crashes.
    todo = sorted((u for u in units if u.path in crashes),
                  key=lambda u: (crashes[u.path], u.seed))
    cached = len(units) - len(todo)
    skipped = [u for u in todo if crashes[u.path] >= MAX_ATTEMPTS]
    for u in skipped:
        print(f"skipping {u.experiment}/{u.label}/seed{u.seed}: it crashed {crashes[u.path]} "
              f"times (delete {u.path}.attempts to retry)", file=sys.stderr)
    todo = todo[:len(todo) - len(skipped)]
    done = []
    with tqdm(total=sum(u.cost(budget) for u in todo), disable=not progress, unit="s",
              bar_format="{l_bar}{bar}| [{elapsed}<{remaining}]{postfix}") as bar:
        bar.set_postfix_str(f"{len(todo)} to run, {cached} cached")
        if jobs == 1:
            results = (_execute(u, budget) for u in todo)
        else:
            results = Parallel(n_jobs=jobs, return_as="generator_unordered")(
                delayed(_execute)(u, budget) for u in todo)
        try:
            for unit, seconds in results:
                done.append((unit, seconds))
                bar.update(unit.cost(budget))
                bar.set_postfix_str(f"{unit.experiment}/{unit.label}/seed{unit.seed} "
                                    f"{seconds:.0f}s; {len(done)}/{len(todo)} run, "
                                    f"{cached} cached")
        except KeyboardInterrupt:
            results.close()  # stops the parallel workers before their counts are reset
            finished = {u.path for u, _ in done}
            for u in todo:
                if u.path not in finished and attempts(u.path) != crashes[u.path]:
                    reset_attempts(u.path, crashes[u.path])
            raise
    return done, skipped


def gather(experiment, budget, out, seeds=None):
    """Finished runs of each setting, summarised.

    Returns
    -------
    stats : dict of str to SettingStats
        Settings with at least one finished run, in registry order.
    runs : dict of str to list of dict
        The raw unit records per setting.
    """
    stats, runs = {}, {}
    for label in experiment.settings:
        owner, owner_label = resolve(experiment, label)
        params = owner.params(owner_label, budget)
        samples = int(budget.samples * owner.sample_scale)
        records = [load_unit(unit_path(out, budget, owner.name, owner_label, seed), params,
                             budget, samples, seed)
                   for seed in seeds_for(experiment, budget, seeds)]
        records = [r for r in records if r is not None]
        if records:
            runs[label] = records
            stats[label] = summarise(label, params["kind"], [r["result"] for r in records])
    return stats, runs
