"""The one runner: plan the (experiment, setting, seed) units, run the unfinished ones with
a progress bar (here, or on a Dask cluster), and gather the finished ones per setting."""
import hashlib
import importlib.metadata
import logging
import platform
import sys
from collections import deque
from contextlib import contextmanager
from pathlib import Path

from joblib import Parallel, delayed
from tqdm.auto import tqdm

import boxtrees
import envs
import fqi

from . import kinds as _kinds
from . import units as _units
from .cache import (Checkpoint, attempts, load_unit, mark_attempt, save_unit, set_attempts,
                    unit_path)
from .registry import resolve
from .units import Unit, run_unit

__all__ = ["plan", "setting_units", "run", "gather", "seeds_for", "cluster", "ClusterError",
           "MAX_ATTEMPTS"]

# A unit that crashed this many times is skipped (reported missing; the command fails).
MAX_ATTEMPTS = 3


def seeds_for(experiment, budget, seeds=None):
    """Seeds of an experiment: `seeds` if given (each once), else ``range(experiment.seeds)``
    (at most the budget's seeds, so a smaller budget stays small) or ``range(budget.seeds)``;
    unless the experiment says, a kind that runs one seed (`kinds.UnitKind.one_seed`: the
    RMSE study and the attention figure use one data set / forest, as the thesis, and a
    reference policy's score one run) runs seed 0. (A ``same_as`` setting is run, and read,
    with the seeds of the experiment owning it.)"""
    if seeds is not None:
        return list(dict.fromkeys(seeds))
    if experiment.seeds is not None:
        return list(range(min(experiment.seeds, budget.seeds)))
    return list(range(1 if _kinds.KINDS[experiment.kind].one_seed else budget.seeds))


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
            for unit in setting_units(experiment, label, budget, out, seeds):
                units.setdefault(unit.path, unit)
    return list(units.values())


def setting_units(experiment, label, budget, out, seeds=None):
    """The units of one setting: its owner's (``same_as`` followed), at the owner's seeds.

    Returns
    -------
    units : list of Unit
    """
    owner, owner_label = resolve(experiment, label)
    samples = int(budget.samples * owner.sample_scale)
    params = owner.params(owner_label, budget)
    return [Unit(owner.name, owner_label, seed, params, samples, budget,
                 unit_path(out, budget, owner.name, owner_label, seed))
            for seed in seeds_for(owner, budget, seeds)]


def _execute(unit):
    checkpoint = Checkpoint(unit, _environment())
    mark_attempt(unit.path)
    result = run_unit(unit, checkpoint)
    save_unit(unit, result)
    return unit, result["seconds"]


def _say_skipped(unit, crashes):
    tqdm.write(f"skipping {unit.name}: it crashed {crashes} times (delete "
               f"{unit.path}.attempts to retry, and its .partial, if any, to start over)",
               file=sys.stderr)


def run(units, jobs=1, progress=True, client=None):
    """Run the units not already cached; show one progress bar with ETA over all of them.

    A unit's start counts as a crash until the unit finishes; an interrupt (Ctrl-C) takes
    the count back, so only crashes get a unit skipped (after `MAX_ATTEMPTS` of them). On a
    cluster, each worker that died running a unit is one crash of it; the unit is then
    retried after the others, or skipped. Run here, an FQI run saves its state after its
    iterations (`cache.Checkpoint`, at most once a minute) and a restart resumes it from
    there, to the same result; on a cluster it starts over.

    Parameters
    ----------
    units : list of Unit
    jobs : int, default=1
        Parallel processes (joblib loky). An FQI run's forests use every core, but its
        simulation and the neural baselines use one, so on 2 cores 2 processes finish
        first (`make bench` runs 2). Ignored with `client`.
    progress : bool, default=True
    client : distributed.Client, default=None
        Run the units as tasks on this Dask cluster (see `cluster`); this process writes
        their results, so the workers need no access to the cache.

    Returns
    -------
    done : list of (Unit, float)
        The units run now and their seconds (cached units are skipped).
    skipped : list of Unit
        The units not run because they crashed `MAX_ATTEMPTS` times.

    Raises
    ------
    ClusterError
        If a worker of `client` runs other code than this process (nothing is counted).
    """
    crashes = {u.path: attempts(u.path) for u in units if load_unit(u) is None}
    # Seed-major order, so an interrupted run leaves every setting with its first seeds
    # done; within a seed the longest first, so parallel processes end together; units that
    # crashed before go last, and are skipped after MAX_ATTEMPTS crashes.
    todo = sorted((u for u in units if u.path in crashes),
                  key=lambda u: (crashes[u.path], u.seed, -u.cost()))
    cached = len(units) - len(todo)
    skipped = [u for u in todo if crashes[u.path] >= MAX_ATTEMPTS]
    for u in skipped:
        _say_skipped(u, crashes[u.path])
    todo = todo[:len(todo) - len(skipped)]
    done = []
    with tqdm(total=sum(u.cost() for u in todo), disable=not progress, unit="s",
              bar_format="{l_bar}{bar}| [{elapsed}<{remaining}]{postfix}") as bar:
        bar.set_postfix_str(f"{len(todo)} to run, {cached} cached")
        results = _results(todo, jobs, client, crashes, skipped)
        try:
            for unit, seconds in results:
                done.append((unit, seconds))
                bar.update(unit.cost())
                bar.set_postfix_str(f"{unit.name} {seconds:.0f}s; {len(done)}/{len(todo)} "
                                    f"run, {cached} cached")
        except (KeyboardInterrupt, ClusterError):  # neither is a crash of the units
            results.close()  # stops the parallel workers before their counts are reset
            _take_back(todo, done, crashes)
            raise
    return done, skipped


def _results(todo, jobs, client, crashes, skipped):
    """``(unit, seconds)`` of the units of `todo` as they finish: on `client`'s cluster (see
    `_ClusterRun` for `crashes` and `skipped`), else in `jobs` processes here."""
    if client is not None:
        return _ClusterRun(client, crashes, skipped).results(todo)
    if jobs == 1:
        return (_execute(u) for u in todo)
    return Parallel(n_jobs=jobs, return_as="generator_unordered")(
        delayed(_execute)(u) for u in todo)


def _take_back(todo, done, crashes):
    """Set the crash counts of the units of `todo` not `done` back to `crashes`: their
    starts did not crash."""
    finished = {u.path for u, _ in done}
    for u in todo:
        if u.path not in finished and attempts(u.path) != crashes[u.path]:
            set_attempts(u.path, crashes[u.path])


class ClusterError(RuntimeError):
    """A Dask cluster that cannot run the units: not reachable, or its scheduler or a worker
    has other code than this process."""


@contextmanager
def cluster(scheduler=None, local_workers=None):
    """A client of a Dask cluster whose scheduler and workers have this process's code.

    Parameters
    ----------
    scheduler : str, default=None
        Address of a running cluster's scheduler (``tcp://host:8786``).
    local_workers : int, default=None
        Else start a cluster of this many worker processes here, one unit at a time each.

    Yields
    ------
    client : distributed.Client or None
        None if neither argument is given (run here).

    Raises
    ------
    ClusterError
        If dask.distributed is not installed, the scheduler cannot be reached, or it or a
        worker cannot import this project or has another version of it or of its
        libraries.
    """
    if scheduler is None and local_workers is None:
        yield None
        return
    try:
        import distributed  # noqa: F401 (a development dependency, imported when used)
    except ImportError:
        raise ClusterError("running on a Dask cluster needs dask.distributed: "
                           "pip install 'dask[distributed]'") from None
    with (_local_client(local_workers) if local_workers is not None
          else _remote_client(scheduler)) as client:
        _check_cluster(client)
        yield client


# Of the local cluster, set while it lives (it restarts dead workers): the scheduler does
# not retry a task whose worker died, so each death reaches the runner (which retries the
# unit last); worker processes are no daemons, or joblib inside them would run every
# parallel loop of a unit on one thread.
_LOCAL_CONFIG = {"distributed.scheduler.allowed-failures": 0, "distributed.worker.daemon": False}


@contextmanager
def _local_client(n_workers):
    import dask
    import distributed

    with dask.config.set(_LOCAL_CONFIG), distributed.LocalCluster(
            n_workers=n_workers, threads_per_worker=1, processes=True, dashboard_address=None,
            silence_logs=logging.ERROR) as local, distributed.Client(local) as client:
        yield client


def _remote_client(scheduler):
    import distributed

    try:
        return distributed.Client(scheduler)
    except (OSError, ValueError) as error:  # OSError includes the connection timeout
        raise ClusterError(f"cannot reach the Dask scheduler at {scheduler}: {error}") from None


# The libraries whose versions can change a unit's result.
_RESULT_LIBRARIES = ("numpy", "scipy", "scikit-learn", "joblib", "gymnasium", "torch",
                     "stable-baselines3")


def _describe_environment():
    """What a unit's result depends on besides its inputs: the Python and library versions
    and a digest of the project's sources (boxtrees, envs, fqi, the units and their kinds,
    and the training helper)."""
    environment = {"python": ".".join(platform.python_version_tuple()[:2])}
    for name in _RESULT_LIBRARIES:
        try:
            environment[name] = importlib.metadata.version(name)
        except importlib.metadata.PackageNotFoundError:
            environment[name] = None
    digest = hashlib.sha256()
    files = [p for package in (boxtrees, envs, fqi, _kinds)
             for p in sorted(Path(package.__file__).parent.iterdir())
             if p.suffix in (".py", ".pyx", ".pxd", ".h")]
    for path in [*files, Path(_units.__file__), Path(__file__).parents[1] / "training.py"]:
        digest.update(f"{path.parent.name}/{path.name}\0".encode() + path.read_bytes())
    environment["project sources"] = digest.hexdigest()[:12]
    return environment


# Described on import, next to importing the project: the code this process runs (its
# files may change later).
_ENVIRONMENT = _describe_environment()


def _environment():
    """This process's `_describe_environment` (run on the scheduler and the workers)."""
    return _ENVIRONMENT


def _mismatch(name, theirs, ours):
    """Why `name` (the scheduler or a worker), whose `_environment` is `theirs`, may not
    serve a client whose `_environment` is `ours`."""
    differences = ", ".join(f"{key} {theirs.get(key)} (here {value})"
                            for key, value in ours.items() if theirs.get(key) != value)
    return (f"{name} differs from this machine: {differences}; install the same version of "
            f"the project and its libraries on the scheduler and every worker")


def _check_cluster(client):
    """Raise `ClusterError` unless the scheduler (it unpickles the tasks) and every worker
    of `client` have this process's `_environment`."""
    try:
        found = {"the scheduler": client.run_on_scheduler(_environment)}
    except Exception as error:  # whatever the scheduler met importing or running it
        found = {"the scheduler": error}
    found.update((f"worker {worker}", theirs)
                 for worker, theirs in client.run(_environment, on_error="return").items())
    for name, theirs in found.items():
        if isinstance(theirs, Exception):
            raise ClusterError(f"{name} cannot run this project's code ({theirs}); install "
                               f"the project on the scheduler and every worker")
        if theirs != _environment():
            raise ClusterError(_mismatch(name, theirs, _environment()))


def _run_checked(environment, unit):
    """`run_unit` on a worker, if the worker has the client's `environment` (a worker that
    joined after `_check_cluster` is checked here)."""
    if _environment() != environment:
        from distributed import get_worker
        raise ClusterError(_mismatch(f"worker {get_worker().address}", _environment(),
                                     environment))
    return run_unit(unit)


class _ClusterRun:
    """Units run as tasks of a Dask cluster, as many at a time as it has worker threads, so
    a unit counts as started (`mark_attempt`) only while a worker runs it.

    Parameters
    ----------
    client : distributed.Client
    crashes : dict of Path to int
        Each unit's crash count before this run; raised for each worker that dies.
    skipped : list of Unit
        Where units that reach `MAX_ATTEMPTS` crashes are appended.
    """

    def __init__(self, client, crashes, skipped):
        self.client, self.crashes, self.skipped = client, crashes, skipped
        self.environment = _environment()
        self.queue, self.running = deque(), {}

    def results(self, todo):
        """Run `todo` in order (a unit whose worker died goes last again); write each result
        here and yield ``(unit, seconds)`` as it finishes. On leaving early (an interrupt,
        an error) the running tasks are cancelled."""
        from distributed import as_completed

        self.queue.extend(todo)
        finished = as_completed()
        try:
            while self.queue or self.running:
                finished.update(self._submit())
                outcome = self._collect(next(finished))
                if outcome is not None:
                    yield outcome
        finally:
            self.client.cancel(list(self.running))

    def _submit(self):
        """Start queued units while the cluster has idle threads (at least one unit runs,
        so a cluster without workers yet waits for them)."""
        threads = max(1, sum(self.client.nthreads().values()))
        futures = []
        while self.queue and len(self.running) < threads:
            unit = self.queue.popleft()
            mark_attempt(unit.path)
            future = self.client.submit(_run_checked, self.environment, unit, pure=False)
            self.running[future] = unit
            futures.append(future)
        return futures

    def _collect(self, future):
        """The finished task's ``(unit, seconds)`` once written, or None if its worker died
        (raises the unit's own error)."""
        from distributed import KilledWorker

        unit = self.running.pop(future)
        error = future.exception() if future.status == "error" else None
        if isinstance(error, KilledWorker):
            # the scheduler gave up after allowed_failures + 1 workers died running it
            self._crashed(unit, error.allowed_failures + 1)
            return None
        result = future.result()  # raises the unit's error, with its traceback
        save_unit(unit, result)
        return unit, result["seconds"]

    def _crashed(self, unit, deaths):
        count = self.crashes[unit.path] = self.crashes[unit.path] + deaths
        set_attempts(unit.path, count)
        tqdm.write(f"{unit.name}: the worker running it died ({count} crash(es); "
                   f"{MAX_ATTEMPTS} skip it)", file=sys.stderr)
        if count >= MAX_ATTEMPTS:
            _say_skipped(unit, count)
            self.skipped.append(unit)
        else:
            self.queue.append(unit)


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
        units = setting_units(experiment, label, budget, out, seeds)
        records = [r for r in map(load_unit, units) if r is not None]
        if records:
            runs[label] = records
            stats[label] = units[0].kind.summarise(label, [r["result"] for r in records])
    return stats, runs
