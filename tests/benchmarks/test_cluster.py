"""Running the units on a Dask cluster: the same results as here, written here, resumed,
refused when a worker has other code, and a dead worker counted as a crash."""
import json
import os
import re
from contextlib import contextmanager

import dask
import pytest
from distributed.diagnostics.plugin import WorkerPlugin

from benchmarks.reproduce import REGISTRY, runner
from benchmarks.reproduce.cache import attempts, load_unit, mark_attempt, save_unit
from benchmarks.reproduce.cli import main
from benchmarks.reproduce.runner import MAX_ATTEMPTS, ClusterError, cluster, plan, run

from harness import FQI_RESULT, TINY, interrupt

pytestmark = pytest.mark.slow   # a local cluster of worker processes: about 90 s


# ------------------------------------------------------------------------------ Dask cluster
def _timeless(value):
    """A run record without its timing fields (``seconds``, ``t_*``)."""
    if isinstance(value, dict):
        return {k: _timeless(v) for k, v in value.items()
                if not re.match(r"t_|.*seconds$", k)}
    return [_timeless(v) for v in value] if isinstance(value, list) else value


@pytest.fixture(scope="module")
def dask_client():
    with cluster(local_workers=2) as client:  # what --dask-local 2 runs on
        yield client


def test_runs_on_a_dask_cluster_equal_local_runs_bit_for_bit(tiny_run, dask_client, tmp_path):
    local, _ = tiny_run
    names = ["dqn", "rmse_K", "attention"]  # every kind of unit (dqn's FQI runs too)
    main(["--budget", "tiny", "--only", ",".join(names), "--out", str(tmp_path),
          "--scheduler", dask_client.scheduler.address, "--no-progress"])
    units = plan([REGISTRY[n] for n in names], TINY, tmp_path)
    assert sorted((tmp_path / "runs").rglob("seed*.json*")) == sorted(u.path for u in units)
    for unit in units:
        record = json.loads(unit.path.read_text())
        assert record["result"]["seconds"] > 0
        assert _timeless(record) == _timeless(json.loads(
            (local / unit.path.relative_to(tmp_path)).read_text())), unit.path


def test_an_unreachable_scheduler_is_one_error_line(tmp_path, capsys):
    with dask.config.set({"distributed.comm.timeouts.connect": "1s"}):
        with pytest.raises(SystemExit) as exit_:
            main(["--budget", "tiny", "--only", "attention", "--out", str(tmp_path),
                  "--scheduler", "tcp://127.0.0.1:1", "--no-progress"])
    assert exit_.value.code == 1
    assert capsys.readouterr().err.splitlines() == [
        "python -m benchmarks.run_all: error: cannot reach the Dask scheduler at "
        "tcp://127.0.0.1:1: Timed out "
        "trying to connect to tcp://127.0.0.1:1 after 1 s"]
    unit, = plan([REGISTRY["attention"]], TINY, tmp_path)
    assert attempts(unit.path) == 0


class _PatchRunner(WorkerPlugin):
    """Replaces attributes of the runner module in every worker, restarted ones too."""

    def __init__(self, patches):
        self.patches = patches

    def setup(self, worker):
        self.saved = {name: getattr(runner, name) for name in self.patches}
        for name, value in self.patches.items():
            setattr(runner, name, value)

    def teardown(self, worker):
        for name, value in self.saved.items():
            setattr(runner, name, value)


@contextmanager
def _on_workers(client, **patches):
    client.register_plugin(_PatchRunner(patches), name="patch-runner")
    try:
        yield
    finally:
        client.unregister_worker_plugin("patch-runner")


def _fake_run_unit(unit):
    return dict(FQI_RESULT)


def _mixed_kills_its_worker(unit):
    if unit.settings.resample_every == 5:
        os._exit(1)
    return dict(FQI_RESULT)


_REAL_ENVIRONMENT = runner._environment


def _other_numpy():
    return {**_REAL_ENVIRONMENT(), "numpy": "0.0"}


def _no_project():
    raise ModuleNotFoundError("No module named 'boxtrees'")


def test_a_cluster_run_is_written_here_and_resumes(dask_client, tmp_path, monkeypatch):
    units = plan([REGISTRY["sampling"]], TINY, tmp_path, seeds=[0, 1])
    written = []
    monkeypatch.setattr(runner, "save_unit", lambda unit, result: (
        written.append(unit.path), save_unit(unit, result)))
    with _on_workers(dask_client, run_unit=_fake_run_unit):
        done, skipped = run(units[:3], progress=False, client=dask_client)
        assert sorted(u.path for u, _ in done) == sorted(written) == sorted(
            u.path for u in units[:3])
        assert all(load_unit(u)["result"] == FQI_RESULT for u in units[:3])
        assert skipped == [] and not any(attempts(u.path) for u in units)
        assert run(units, progress=False, client=dask_client) == (
            [(units[3], FQI_RESULT["seconds"])], [])


def test_an_interrupted_cluster_run_is_no_crash(dask_client, tmp_path, monkeypatch):
    units = plan([REGISTRY["sampling"]], TINY, tmp_path, seeds=[0, 1])
    mark_attempt(units[0].path)  # one real crash before
    monkeypatch.setattr(runner, "save_unit", interrupt)  # Ctrl-C as the first result comes
    with _on_workers(dask_client, run_unit=_fake_run_unit):
        with pytest.raises(KeyboardInterrupt):
            run(units, progress=False, client=dask_client)
    assert [attempts(u.path) for u in units] == [1, 0, 0, 0]


@pytest.mark.parametrize("environment, problem", [
    (_other_numpy, r"differs from this machine: numpy 0\.0 \(here [0-9.]+\); install the "
                   r"same version of the project and its libraries on the scheduler and "
                   r"every worker"),
    (_no_project, r"cannot run this project's code \(No module named 'boxtrees'\); install "
                  r"the project on the scheduler and every worker"),
], ids=["other numpy", "no project"])
def test_workers_with_other_code_are_refused(dask_client, tmp_path, environment, problem):
    units = plan([REGISTRY["sampling"]], TINY, tmp_path, seeds=[0])
    with _on_workers(dask_client, _environment=environment):
        with pytest.raises(ClusterError, match=f"^worker tcp://[0-9.:]+ {problem}$"):
            with cluster(dask_client.scheduler.address):
                pass
        if environment is _other_numpy:  # a worker that joined later: refused by its task
            with pytest.raises(ClusterError, match=problem):
                run(units, progress=False, client=dask_client)
    assert not any(attempts(u.path) or u.path.exists() for u in units)


def test_a_worker_that_dies_is_a_crash_of_its_unit(dask_client, tmp_path, capsys):
    normal, mixed = plan([REGISTRY["sampling"]], TINY, tmp_path, seeds=[0])
    mark_attempt(mixed.path)  # crashed once before: its worker dies twice, then it is skipped
    with _on_workers(dask_client, run_unit=_mixed_kills_its_worker):
        done, skipped = run([normal, mixed], progress=False, client=dask_client)
    assert [u for u, _ in done] == [normal] and skipped == [mixed]
    assert attempts(mixed.path) == MAX_ATTEMPTS and not mixed.path.exists()
    name = "sampling/mixed (every 5)/seed0"
    assert [line for line in capsys.readouterr().err.splitlines() if name in line] == [
        f"{name}: the worker running it died (2 crash(es); 3 skip it)",
        f"{name}: the worker running it died (3 crash(es); 3 skip it)",
        f"skipping {name}: it crashed 3 times (delete {mixed.path}.attempts to retry, and "
        f"its .partial, if any, to start over)"]
