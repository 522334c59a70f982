"""The runner, here: every experiment end to end at the tiny budget, resuming, order of the
units, crashes and interrupts."""
import json
from dataclasses import replace

import numpy as np
import pytest

from benchmarks.reproduce import EXPERIMENTS, REGISTRY, runner
from benchmarks.reproduce.cache import Checkpoint, attempts, load_unit, mark_attempt, unit_path
from benchmarks.reproduce.report import figure_name
from benchmarks.reproduce.runner import MAX_ATTEMPTS, plan, run
from fqi import FQI

from harness import FQI_RESULT, TINY, interrupt

DEFAULT_EXPERIMENTS = [e for e in EXPERIMENTS if not e.on_demand]


def test_every_experiment_runs_end_to_end(tiny_run):
    out, report = tiny_run
    for experiment in DEFAULT_EXPERIMENTS:
        assert (out / figure_name(experiment)).stat().st_size > 5000, experiment.name
        assert (out / f"{experiment.name}.csv").exists()
    text = report.read_text()
    for experiment in EXPERIMENTS:   # the searches run (and are reported) only when named
        assert (f'<a id="{experiment.name}"></a>' in text) != experiment.on_demand
    assert "Partial" not in text
    summary = json.loads((out / "summary.json").read_text())
    assert set(summary["experiments"]) == {e.name for e in DEFAULT_EXPERIMENTS}
    fqi = summary["experiments"]["representations"]["settings"]["fixed TW=1"]
    assert fqi["n_runs"] == 1 and np.isfinite(fqi["score"])
    record = json.loads(unit_path(out, TINY, "representations", "fixed TW=1", 0).read_text())
    assert len(record["result"]["rewards"]) == TINY.iterations
    assert record["result"]["history"][0]["n_samples"] == TINY.samples
    sword = json.loads(unit_path(out, TINY, "sword", "classic", 0).read_text())
    assert sword["result"]["history"][0]["n_samples"] == 2 * TINY.samples
    rmse = json.loads(unit_path(out, TINY, "rmse_K", "K=300", 0).read_text())["result"]
    assert len(rmse["fold_rmse"]) == TINY.rmse_folds and len(rmse["action_rmse"]) == 4
    attention = json.loads(unit_path(out, TINY, "attention", "bounded TW=4", 0).read_text())
    assert len(attention["result"]["actions"]) == 4
    assert all(len(t) == 9 for a in attention["result"]["actions"] for t in a["tests"])
    # the tests of every type a forest tests are drawn, each with the sign of its effect
    for action in attention["result"]["actions"]:
        drawn = {int(t[4]) for t in action["tests"]}
        assert drawn == {t for t, share in enumerate(action["type_usage"]) if share > 0}


def test_second_invocation_reuses_the_cache_and_resumes(tiny_run):
    out, _ = tiny_run
    units = plan([REGISTRY["representations"]], TINY, out)
    assert run(units, progress=False) == ([], [])  # everything cached
    units[2].path.unlink()
    before = units[0].path.stat().st_mtime_ns
    rerun, _ = run(units, progress=False)
    assert [u.path for u, _ in rerun] == [units[2].path]
    assert units[2].path.exists() and units[0].path.stat().st_mtime_ns == before


def _without_times(result):
    return {**result, "seconds": None,
            "history": [{k: v for k, v in r.items() if not k.startswith("t_")}
                        for r in result["history"]]}


def test_an_interrupted_fqi_run_resumes_from_its_last_iteration_to_the_same_result(
        tmp_path, monkeypatch):
    monkeypatch.setattr(Checkpoint, "interval", 0.0)  # a save after every iteration
    budget = replace(TINY, iterations=3)
    uninterrupted, resumed = (plan([REGISTRY["treasure"]], budget, tmp_path / name,
                                   seeds=[0])[3] for name in ("once", "twice"))
    assert resumed.label == "global"
    run([uninterrupted], progress=False)
    iterate = FQI._iterate

    def stop_at_the_third(agent, n_samples):
        if agent.iteration == 2:
            raise KeyboardInterrupt
        return iterate(agent, n_samples)

    monkeypatch.setattr(FQI, "_iterate", stop_at_the_third)
    with pytest.raises(KeyboardInterrupt):
        run([resumed], progress=False)
    checkpoint = Checkpoint(resumed, runner._environment())
    assert checkpoint.load()["agent"].iteration == 2 and attempts(resumed.path) == 0
    resumed_iterations = []
    monkeypatch.setattr(FQI, "_iterate",
                        lambda agent, n_samples: resumed_iterations.append(agent.iteration)
                        or iterate(agent, n_samples))
    run([resumed], progress=False)
    assert resumed_iterations == [2]  # only the missing iteration ran
    assert not checkpoint.path.exists()  # gone with the finished result
    first, second = (load_unit(u)["result"] for u in (uninterrupted, resumed))
    assert _without_times(second) == _without_times(first)


def test_units_run_seed_major_and_longest_first_within_a_seed(tmp_path, monkeypatch):
    order = []

    def record(unit, checkpoint):
        order.append((unit.seed, unit.cost()))
        return dict(FQI_RESULT)

    monkeypatch.setattr(runner, "run_unit", record)
    units = plan([REGISTRY["fqi_M"]], TINY, tmp_path, seeds=[0, 1])  # M=5, 15, 30 each
    run(units, progress=False)
    assert [seed for seed, _ in order] == [0] * 3 + [1] * 3
    for seed in (0, 1):
        costs = [cost for s, cost in order if s == seed]
        assert costs == sorted(costs, reverse=True) and costs[0] > costs[-1]


def test_units_that_crashed_run_last_and_are_skipped_after_max_attempts(tiny_run):
    out, _ = tiny_run
    units = plan([REGISTRY["fqi_K"]], TINY, out)
    for u in units:
        u.path.unlink()
    mark_attempt(units[0].path)  # crashed once: retried after the others
    for _ in range(MAX_ATTEMPTS):
        mark_attempt(units[1].path)  # crashed too often: skipped
    assert attempts(units[1].path) == MAX_ATTEMPTS
    done, skipped = run(units, progress=False)
    assert [u.path for u, _ in done] == [units[2].path, units[0].path]
    assert skipped == [units[1]]
    assert attempts(units[0].path) == 0 and not units[1].path.exists()


def test_interrupts_are_not_counted_as_crashes(tmp_path, monkeypatch):
    units = plan([REGISTRY["sampling"]], TINY, tmp_path, seeds=[0])
    mark_attempt(units[0].path)  # one real crash before
    monkeypatch.setattr(runner, "run_unit", interrupt)
    for _ in range(MAX_ATTEMPTS + 1):
        with pytest.raises(KeyboardInterrupt):
            run(units, progress=False)
    assert [attempts(u.path) for u in units] == [1, 0]
    monkeypatch.setattr(runner, "run_unit", lambda *args: dict(FQI_RESULT))
    done, skipped = run(units, progress=False)
    assert [u for u, _ in done] == [units[1], units[0]] and skipped == []
