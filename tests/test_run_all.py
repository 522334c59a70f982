"""benchmarks/run_all.py: registry, runner (end to end at the tiny budget, here and on a
local Dask cluster), cache and resume, findings and the report writer."""
import errno
import json
import os
import re
from contextlib import contextmanager
from dataclasses import replace

import dask
import numpy as np
import pytest
from distributed.diagnostics.plugin import WorkerPlugin
from matplotlib.colors import to_rgb

import envs
from benchmarks.reproduce import BUDGETS, EXPERIMENTS, REGISTRY
from benchmarks.reproduce import plots, runner
from benchmarks.reproduce.cache import (Checkpoint, attempts, load_unit, mark_attempt,
                                        save_unit, slug, unit_path)
from benchmarks.reproduce.cli import main, parse_seeds
from benchmarks.reproduce.findings import (AtLeast, Falls, Faster, HighestPeak, MoreStable,
                                           NearRandom, Ranking, Sign, Similar)
from benchmarks.reproduce.registry import Experiment, resolve
from benchmarks.reproduce.report import figure_name, write_outputs
from benchmarks.reproduce.runner import MAX_ATTEMPTS, ClusterError, cluster, gather, plan, run
from benchmarks.reproduce.kinds import KINDS
from benchmarks.reproduce.stats import SettingStats
from benchmarks.reproduce.units import Unit
from envs._render import _STYLE
from fqi import FQI

TINY = BUDGETS["tiny"]


def _unit(out, experiment, label, seed=0, budget=TINY, samples=200):
    """The unit of a registry setting (a same_as setting's own, not its owner's)."""
    return Unit(experiment, label, seed, REGISTRY[experiment].params(label, budget), samples,
                budget, unit_path(out, budget, experiment, label, seed))


# ------------------------------------------------------------------------------ registry
def test_registry_covers_every_thesis_figure_once():
    figures = [e.figure for e in EXPERIMENTS if e.figure != "extra"]
    assert sorted(figures) == sorted(["A.1", "A.2", "A.3", "A.4", "A.5", "3.1", "3.2", "3.3",
                                      "3.4", "3.5", "3.6", "3.8", "3.9", "3.10"])
    assert {e.name for e in EXPERIMENTS if e.figure == "extra" and not e.explains} == {
        "keep_data", "dqn", "attention", "ceiling", "ceiling_sword", "baselines",
        "search_dqn_grid", "search_dqn_objects", "search_ppo_objects"}
    ablations = [e for e in EXPERIMENTS if e.explains]
    assert {name for e in ablations for name in e.explains} == {
        "rmse_K", "rmse_nmin", "rmse_TW", "rmse_grid", "fqi_grid", "representations",
        "fqi_TW", "sampling", "sword"}
    for ablation in ablations:
        assert ablation.figure == "extra" and ablation.hypothesis and ablation.findings
        assert all(REGISTRY[name].figure != "extra" for name in ablation.explains)
    assert {e.name for e in EXPERIMENTS if e.on_demand} == {
        "search_dqn_grid", "search_dqn_objects", "search_ppo_objects"}
    assert len(REGISTRY) == len(EXPERIMENTS)


def _rule_labels(rule):
    labels = []
    for name in ("groups", "labels", "others"):
        value = getattr(rule, name, ())
        labels += [x for group in value for x in group] if name == "groups" else list(value)
    labels += [getattr(rule, name) for name in ("label", "stable", "reference")
               if hasattr(rule, name)]
    return labels


@pytest.mark.parametrize("experiment", EXPERIMENTS, ids=lambda e: e.name)
def test_every_setting_resolves_and_every_rule_names_real_settings(experiment):
    kinds = {"fqi", "rmse", "dqn", "sb3", "policy", "attention"}
    assert experiment.kind in kinds
    for label in experiment.settings:
        owner, owner_label = resolve(experiment, label)
        params = owner.params(owner_label)
        assert params["kind"] in kinds
        assert params["env_id"].startswith("ObjectWorld")
        if params["kind"] == "sb3":
            assert {"algo", "observation", "hyperparams", "step_scale"} <= set(params)
            assert "gamma" in params["hyperparams"]      # searched, never SB3's default
        elif params["kind"] == "policy":
            assert params["policy"] in ("planner", "greedy", "random")
        elif params.get("model", "box") == "box" and params["kind"] != "dqn":
            assert {"test_type", "n_estimators", "n_tests", "min_samples_split"} <= set(params)
    for rule in experiment.findings:
        assert set(_rule_labels(rule)) <= set(experiment.settings), rule
    assert experiment.ceiling is None or experiment.ceiling in experiment.settings


def test_thesis_axes_and_budgets():
    assert list(REGISTRY["fqi_nmin"].settings) == ["n_min=10", "n_min=20", "n_min=30"]
    assert list(REGISTRY["rmse_grid"].settings) == ["N=5", "N=10", "N=16", "N=21"]
    assert REGISTRY["fqi_K"].params("K=50")["n_estimators"] == 15  # standard M
    assert REGISTRY["representations"].params("classic")["n_tests"] == 500  # tuned K
    assert REGISTRY["treasure"].params("global")["view"] == "global"
    full = BUDGETS["full"]
    assert (full.seeds, full.iterations, full.samples, full.eval_steps) == (5, 20, 20_000,
                                                                             20_000)
    sword = [u for u in plan([REGISTRY["sword"]], full, "out") if u.seed == 0]
    assert {u.samples for u in sword} == {40_000}


def test_same_as_settings_share_their_owners_units(tmp_path):
    units = plan([REGISTRY["representations"], REGISTRY["dqn"]], BUDGETS["full"], tmp_path)
    assert len(units) == 5 * 5 + 5  # DQN's FQI settings are the representations' runs
    assert len({u.path for u in units}) == len(units)
    owners = {(u.experiment, u.label) for u in plan([REGISTRY["dqn"]], TINY, tmp_path)}
    assert ("representations", "fixed TW=1") in owners


def test_circular_same_as_is_rejected():
    loop = Experiment("loop", "extra", "t", "fqi", settings={"a": {"same_as": "loop/a"}})
    REGISTRY["loop"] = loop
    try:
        with pytest.raises(ValueError, match="circular"):
            resolve(loop, "a")
    finally:
        del REGISTRY["loop"]


def test_parse_seeds():
    assert parse_seeds("3") == [0, 1, 2]
    assert parse_seeds("0,2,4") == [0, 2, 4]
    assert parse_seeds("2-4") == [2, 3, 4]
    with pytest.raises(Exception, match="count"):
        parse_seeds("x")


_BAD_ARGUMENTS = [
    (["--seeds", "5-2"], "argument --seeds: '5-2' selects no seed"),
    (["--seeds", "0"], "argument --seeds: '0' selects no seed"),
    (["--seeds", ""], "argument --seeds: expected a count (3), a list (0,2,4) or a range"),
    (["--seeds", "0,0,0"], "argument --seeds: '0,0,0' repeats seed 0"),
    (["--seeds", "1,-2"], "argument --seeds: '1,-2' selects a seed outside 0 .. 4294967295"),
    (["--seeds", "1001"], "argument --seeds: '1001' selects 1,001 seeds, more than 1,000"),
    (["--jobs", "0"], "argument --jobs: expected a whole number of 1 or more, got '0'"),
    (["--jobs", "-1"], "argument --jobs: expected a whole number of 1 or more, got '-1'"),
    (["--only", ""], "argument --only: names no experiment; known: rmse_K"),
    (["--dask-local", "0"], "argument --dask-local: expected a whole number of 1 or more, got "
                            "'0'"),
    (["--scheduler", " "], "argument --scheduler: expected a scheduler address"),
    (["--scheduler", "tcp://host:8786", "--dask-local", "2"],
     "argument --dask-local: not allowed with argument --scheduler"),
    (["--scheduler", "tcp://host:8786", "--jobs", "2"],
     "argument --jobs: not allowed with argument --scheduler"),
    (["--dask-local", "2", "--jobs", "2"],
     "argument --jobs: not allowed with argument --dask-local"),
]


@pytest.mark.parametrize("argv, message", _BAD_ARGUMENTS,
                         ids=[" ".join(argv) for argv, _ in _BAD_ARGUMENTS])
def test_bad_arguments_are_rejected_before_any_work(tmp_path, capsys, argv, message):
    out = tmp_path / "out"
    with pytest.raises(SystemExit) as exit_:
        main([*argv, "--budget", "tiny", "--out", str(out), "--report-only"])
    assert exit_.value.code == 2
    assert message in capsys.readouterr().err
    assert not out.exists()


def test_out_blocked_by_a_file_is_rejected(tmp_path, capsys):
    blocker = tmp_path / "notes.txt"
    blocker.write_text("not a folder")
    for out in (blocker, blocker / "results"):
        with pytest.raises(SystemExit) as exit_:
            main(["--budget", "tiny", "--out", str(out), "--report-only"])
        assert exit_.value.code == 2
        assert f"argument --out: {blocker} exists and is not a folder" in capsys.readouterr().err
    assert blocker.read_text() == "not a folder"


def test_unwritable_out_is_one_error_line_and_other_errors_still_raise(tmp_path, capsys,
                                                                     monkeypatch):
    def denied(path):  # what a read-only folder answers (root may write anywhere)
        raise PermissionError(errno.EACCES, "Permission denied", str(path.parent))

    monkeypatch.setattr(runner, "mark_attempt", denied)
    argv = ["--budget", "tiny", "--only", "attention", "--out", str(tmp_path), "--no-progress"]
    with pytest.raises(SystemExit) as exit_:
        main(argv)
    assert exit_.value.code == 1
    unit, = plan([REGISTRY["attention"]], TINY, tmp_path)
    assert capsys.readouterr().err.splitlines() == [
        f"python -m benchmarks.run_all: error: cannot write under --out {tmp_path}: Permission denied: "
        f"{unit.path.parent}"]

    def missing(*args):
        raise FileNotFoundError(errno.ENOENT, "No such file or directory", "/elsewhere")

    monkeypatch.undo()
    monkeypatch.setattr(runner, "run_unit", missing)
    with pytest.raises(FileNotFoundError):  # a unit's own error keeps its traceback
        main(argv)


# ------------------------------------------------------------------------------ cache
def test_cache_round_trip_and_mismatch(tmp_path):
    unit = _unit(tmp_path, "fqi_K", "K=50")
    path = unit.path
    assert path == tmp_path / "runs" / "tiny" / "fqi_K" / "K-50" / "seed0.json"
    save_unit(unit, _FQI_RESULT)
    assert load_unit(unit)["result"]["rewards"] == [1.0, 2.0]
    assert list(path.parent.iterdir()) == [path]  # no temporary file left behind
    umask = os.umask(0)
    os.umask(umask)
    assert path.stat().st_mode & 0o777 == 0o666 & ~umask  # readable as any file, not 0600
    assert load_unit(replace(unit, params={**unit.params, "n_tests": 51})) is None
    assert load_unit(replace(unit, samples=400)) is None  # other samples per iteration
    assert load_unit(replace(unit, budget=replace(TINY, iterations=3))) is None
    assert load_unit(replace(unit, budget=replace(TINY, seeds=4))) is not None  # irrelevant
    assert load_unit(replace(unit, budget=replace(TINY, name="quick"))) is None
    path.write_text("{truncated")
    assert load_unit(unit) is None
    assert slug("mixed (every 5)") == "mixed_every_5"


# A finished FQI unit's result at the tiny budget (2 iterations).
_FQI_RESULT = {"rewards": [1.0, 2.0], "random_reward": -1.0, "seconds": 0.5}


def _save_sampling(out, label, seed):
    unit = _unit(out, "sampling", label, seed, samples=TINY.samples)
    save_unit(unit, _FQI_RESULT)
    return unit.path


def _without_seconds(path):
    record = json.loads(path.read_text())
    del record["result"]["seconds"]
    return json.dumps(record)


def _short_rewards(path):
    record = json.loads(path.read_text())
    record["result"]["rewards"] = [1.0]
    return json.dumps(record)


@pytest.mark.parametrize("damage, problem", [
    (lambda path: "null", "the record is not a JSON object"),
    (lambda path: "[1, 2]", "the record is not a JSON object"),
    (_without_seconds, "no result.seconds"),
    (_short_rewards, "result.rewards is not a list of 2"),
    (lambda path: "{truncated", "not readable as JSON"),
], ids=["null", "list", "no seconds", "short rewards", "truncated"])
def test_a_cached_file_that_is_no_run_record_counts_as_missing(tmp_path, capsys, monkeypatch,
                                                               damage, problem):
    good = _save_sampling(tmp_path, "normal", 0)
    bad = _save_sampling(tmp_path, "mixed (every 5)", 0)
    bad.write_text(damage(bad))
    kept = good.stat().st_mtime_ns
    argv = ["--budget", "tiny", "--only", "sampling", "--seeds", "1", "--out", str(tmp_path),
            "--no-progress"]
    text = main([*argv, "--report-only"]).read_text()
    assert "| 3.9 | [sampling](#sampling) | 1/2 |" in text  # the good run, not the bad one
    # once, though keep_data's "mixed" setting reads the same file
    assert [line for line in capsys.readouterr().err.splitlines() if str(bad) in line] == [
        f"ignoring {bad}: not a run record ({problem}); it counts as missing"]
    monkeypatch.setattr(runner, "run_unit", lambda *args: dict(_FQI_RESULT))
    main(argv)
    assert load_unit(_unit(tmp_path, "sampling", "mixed (every 5)", samples=TINY.samples))[
        "result"] == _FQI_RESULT  # run again
    assert good.stat().st_mtime_ns == kept


def test_a_run_is_never_counted_twice(tmp_path, capsys):
    seed0 = _save_sampling(tmp_path, "normal", 0)
    stats, _ = gather(REGISTRY["sampling"], TINY, tmp_path, seeds=[0, 0])
    assert stats["normal"].n_runs == 1
    seed1 = unit_path(tmp_path, TINY, "sampling", "normal", 1)
    seed1.write_text(seed0.read_text())  # a copy is not the run of seed 1
    stats, _ = gather(REGISTRY["sampling"], TINY, tmp_path, seeds=[0, 1])
    assert stats["normal"].n_runs == 1
    assert f"ignoring {seed1}: not a run record (it records seed 0)" in capsys.readouterr().err


# ------------------------------------------------------------------------------ end to end
@pytest.fixture(scope="module")
def tiny_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("run_all")
    report = main(["--budget", "tiny", "--out", str(out), "--no-progress"])
    return out, report


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


def test_a_test_effect_is_the_right_child_minus_the_left():
    from benchmarks.reproduce.kinds.attention import tree_tests
    from boxtrees import BoxExtraTreesRegressor

    rng = np.random.default_rng(0)
    X = [np.column_stack([rng.uniform(-3, 3, (4, 2)), rng.integers(0, 2, 4)]) for _ in range(300)]
    # more objects of type 0 near the origin: a higher target (they attract)
    y = [float(((np.abs(s[:, :2]).max(1) < 1) & (s[:, 2] == 0)).sum()) for s in X]
    tree = BoxExtraTreesRegressor(1, n_tests=50, min_samples_split=10, random_state=0).fit(X, y)[0].tree_
    rows = tree_tests(tree)
    root = rows[0]
    assert root[8] == tree.value[tree.children_right[0]] - tree.value[tree.children_left[0]]
    assert root[4] == 0 and root[8] > 0


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

    def stop_at_the_third(agent):
        if agent.iteration == 2:
            raise KeyboardInterrupt
        return iterate(agent)

    monkeypatch.setattr(FQI, "_iterate", stop_at_the_third)
    with pytest.raises(KeyboardInterrupt):
        run([resumed], progress=False)
    checkpoint = Checkpoint(resumed, runner._environment())
    assert checkpoint.load()["agent"].iteration == 2 and attempts(resumed.path) == 0
    resumed_iterations = []
    monkeypatch.setattr(FQI, "_iterate",
                        lambda agent: resumed_iterations.append(agent.iteration)
                        or iterate(agent))
    run([resumed], progress=False)
    assert resumed_iterations == [2]  # only the missing iteration ran
    assert not checkpoint.path.exists()  # gone with the finished result
    first, second = (load_unit(u)["result"] for u in (uninterrupted, resumed))
    assert _without_times(second) == _without_times(first)


def test_a_checkpoint_serves_only_its_own_unit_and_code(tmp_path, capsys):
    unit = _unit(tmp_path, "sampling", "normal")
    path = unit.path
    code = {"project sources": "abc"}
    checkpoint = Checkpoint(unit, code)
    assert checkpoint.load() is None
    assert not checkpoint.save({"iteration": 1})  # not yet `interval` seconds
    assert not path.parent.exists()
    checkpoint.interval = 0.0
    assert checkpoint.save({"iteration": 1})
    assert checkpoint.load() == {"iteration": 1}
    assert sorted(p.name for p in path.parent.iterdir()) == ["seed0.json.partial"]
    for other in (Checkpoint(replace(unit, params={**unit.params, "n_tests": 51}), code),
                  Checkpoint(replace(unit, samples=400), code),
                  Checkpoint(replace(unit, budget=replace(TINY, iterations=3)), code),
                  Checkpoint(replace(unit, seed=1), code),
                  Checkpoint(unit, {"project sources": "abd"})):
        assert other.load() is None
    checkpoint.path.write_bytes(b"truncated")
    assert checkpoint.load() is None
    assert f"ignoring {checkpoint.path}: not a readable checkpoint (" in capsys.readouterr().err
    save_unit(unit, _FQI_RESULT)
    assert not checkpoint.path.exists()


def test_a_start_that_saved_progress_is_no_crash_and_a_failed_save_no_failure(tmp_path,
                                                                              capsys):
    unit = _unit(tmp_path, "sampling", "normal")
    path = unit.path
    mark_attempt(path)  # a start that crashed without saving anything
    checkpoint = Checkpoint(unit, {})
    checkpoint.interval = 0.0
    mark_attempt(path)  # this start
    assert attempts(path) == 2
    assert checkpoint.save({"iteration": 1}) and attempts(path) == 1
    checkpoint.path.unlink()
    checkpoint.path.mkdir()  # nothing can replace a folder: every save fails
    assert not checkpoint.save({"iteration": 2}) and not checkpoint.save({"iteration": 3})
    err = capsys.readouterr().err
    assert err.count(f"could not save the checkpoint {checkpoint.path} (") == 1
    assert "the run goes on without" in err
    assert [p.name for p in path.parent.iterdir() if p.name.endswith(".tmp")] == []


def test_units_run_seed_major_and_longest_first_within_a_seed(tmp_path, monkeypatch):
    order = []

    def record(unit, checkpoint):
        order.append((unit.seed, unit.cost()))
        return dict(_FQI_RESULT)

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


def test_a_unit_skipped_after_crashes_fails_the_command(tmp_path, capsys):
    unit, = plan([REGISTRY["attention"]], TINY, tmp_path)
    for _ in range(MAX_ATTEMPTS):
        mark_attempt(unit.path)
    with pytest.raises(SystemExit) as exit_:
        main(["--budget", "tiny", "--only", "attention", "--out", str(tmp_path),
              "--no-progress"])
    assert exit_.value.code == 1
    err = capsys.readouterr().err
    assert f"skipping attention/bounded TW=4/seed0: it crashed {MAX_ATTEMPTS} times" in err
    assert err.endswith(f"python -m benchmarks.run_all: error: 1 run(s) skipped after crashing {MAX_ATTEMPTS} "
                        f"times (listed above); the report counts them as missing\n")
    assert "| extra | [attention](#attention) | 0/1 |" in (tmp_path / "REPORT.md").read_text()


def _interrupt(*args):
    raise KeyboardInterrupt


def test_interrupts_are_not_counted_as_crashes(tmp_path, monkeypatch):
    units = plan([REGISTRY["sampling"]], TINY, tmp_path, seeds=[0])
    mark_attempt(units[0].path)  # one real crash before
    monkeypatch.setattr(runner, "run_unit", _interrupt)
    for _ in range(MAX_ATTEMPTS + 1):
        with pytest.raises(KeyboardInterrupt):
            run(units, progress=False)
    assert [attempts(u.path) for u in units] == [1, 0]
    monkeypatch.setattr(runner, "run_unit", lambda *args: dict(_FQI_RESULT))
    done, skipped = run(units, progress=False)
    assert [u for u, _ in done] == [units[1], units[0]] and skipped == []


def test_an_interrupted_command_says_so_in_one_line(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(runner, "run_unit", _interrupt)
    with pytest.raises(SystemExit) as exit_:
        main(["--budget", "tiny", "--only", "attention", "--out", str(tmp_path),
              "--no-progress"])
    assert exit_.value.code == 130
    assert capsys.readouterr().err.splitlines() == [
        "python -m benchmarks.run_all: interrupted; finished runs are cached: run the same command to resume"]
    unit, = plan([REGISTRY["attention"]], TINY, tmp_path)
    assert attempts(unit.path) == 0


def test_report_marks_missing_runs_as_partial(tiny_run, tmp_path):
    out, _ = tiny_run
    report = main(["--budget", "tiny", "--out", str(out), "--seeds", "2",
                   "--only", "sampling", "--report-only", "--no-progress"])
    text = report.read_text()
    assert "Partial: 2 of 4 runs finished" in text  # seed 1 never ran
    assert "This invocation ran" not in text  # a report-only call runs nothing


# ------------------------------------------------------------------------------ findings
def _stats(label, score, se=1.0, **kwargs):
    return SettingStats(label, "fqi", 1, score, 0.0, se, **kwargs)


def test_ranking_holds_fails_and_flags_noise():
    rule = Ranking((("a", "b"), ("c",)), "a ~ b > c")
    good = {"a": _stats("a", 100), "b": _stats("b", 90), "c": _stats("c", 10)}
    assert rule.check(good).holds is True
    assert rule.check({**good, "c": _stats("c", 95)}).holds is False
    assert "c not worse than b" in rule.check({**good, "c": _stats("c", 95)}).explanation
    assert "within noise" in rule.check({**good, "c": _stats("c", 89)}).explanation
    assert rule.check({"a": good["a"]}).holds is None  # settings not run
    assert rule.check({"a": good["a"]}).explanation == "not run: b, c"
    assert rule.check({}).explanation == "not run at this budget yet"
    # false on the settings run so far: false whatever the missing one scores
    partial = rule.check({"a": good["a"], "c": _stats("c", 120)})
    assert partial.holds is False and partial.explanation.endswith("; not run: b")
    assert "c not worse than a" in partial.explanation
    assert rule.check({"a": good["a"], "c": good["c"]}).holds is None  # could still fail
    assert rule.check({"a": good["a"], "b": _stats("b", 1)}).holds is None  # one group


def test_faster_is_false_once_a_setting_run_so_far_breaks_it():
    rule = Faster("a", ("b", "c"), 0.5, "a needs half the time")
    stats = {label: _stats(label, 0, seconds=seconds)
             for label, seconds in (("a", 10.0), ("b", 30.0), ("c", 15.0))}
    assert rule.check(stats).holds is False
    assert rule.check({k: stats[k] for k in "ab"}).holds is None       # c could be slower
    partial = rule.check({k: stats[k] for k in "ac"})
    assert partial.holds is False and partial.explanation.endswith("; not run: b")
    assert rule.check({"b": stats["b"], "c": stats["c"]}).holds is None  # a not run


def test_ranking_lower_is_better_for_rmse():
    rule = Ranking((("K=300",), ("K=50",)), "K=300 lowest")
    rmse = {"K=300": SettingStats("K=300", "rmse", 1, 1.0, 0, 0.01, lower_is_better=True),
            "K=50": SettingStats("K=50", "rmse", 1, 2.0, 0, 0.01, lower_is_better=True)}
    assert rule.check(rmse).holds is True


def test_other_rules():
    a, b = _stats("a", 100, instability=5, best=200, random_reward=-100), \
        _stats("b", 0, instability=50, best=150, random_reward=-100)
    stats = {"a": a, "b": b}
    assert Similar(("a", "b"), "").check(stats).holds is False
    assert Similar(("a", "b"), "").check({"a": a, "b": _stats("b", 99)}).holds is True
    assert MoreStable("a", ("b",), "").check(stats).holds is True
    assert MoreStable("b", ("a",), "").check(stats).holds is False
    assert Sign("b", True, "").check(stats).holds is False
    assert Sign("a", True, "").check(stats).holds is True
    assert Sign("a", True, "").check({"a": _stats("a", 1.5)}).holds is False  # noise
    assert NearRandom("b", "a", "").check({"a": a, "b": _stats("b", -90, random_reward=-100)}
                                          ).holds is True
    assert HighestPeak("a", ("a", "b"), "").check(stats).holds is True
    peaks = {"a": _stats("a", 0, best=300, mean_peak=100), "b": _stats("b", 0, best=200,
                                                                      mean_peak=150)}
    assert HighestPeak("a", ("a", "b"), "").check(peaks).holds is True
    assert HighestPeak("a", ("a", "b"), "", of_mean=True).check(peaks).holds is False
    spread = {"a": _stats("a", 0, instability=5, spread=50), "b": _stats("b", 0,
                                                                         instability=9, spread=10)}
    assert MoreStable("a", ("b",), "").check(spread).holds is True
    assert MoreStable("a", ("b",), "", measure="spread").check(spread).holds is False
    one_run = {"a": _stats("a", 0), "b": _stats("b", 0)}   # spread is NaN with one run
    assert MoreStable("a", ("b",), "", measure="spread").check(one_run).explanation == \
        "needs at least 2 runs"
    with pytest.raises(ValueError, match="measure must be one of"):
        MoreStable("a", ("b",), "", measure="band")
    assert Falls(("b", "a"), "").check(stats).holds is True
    timed = {"a": _stats("a", 100, seconds=50.0), "b": _stats("b", 0, seconds=100.0)}
    assert Faster("a", ("b",), 0.5, "").check(timed).holds is True
    assert Faster("a", ("b",), 0.4, "").check(timed).holds is False
    assert "a 0.8, b 1.7" in Faster("a", ("b",), 0.5, "").check(timed).explanation
    ref = {**stats, "ref": _stats("ref", 80)}
    assert AtLeast(("a", "b"), "ref", 1.25, "").check(ref).holds is True   # the best of them
    assert AtLeast(("a", "b"), "ref", 1.3, "").check(ref).holds is False
    assert "goal 1.3 x ref 80 = 104" in AtLeast(("a", "b"), "ref", 1.3, "").check(ref).explanation
    assert AtLeast(("a", "b"), "ref", 1.0, "").check({"b": b, "ref": b}).holds is None


def test_summarise_fqi_runs():
    runs = [{"rewards": [0.0, 10.0, 20.0], "random_reward": -5.0, "seconds": 2.0},
            {"rewards": [0.0, 30.0, 40.0], "random_reward": -7.0, "seconds": 4.0}]
    s = KINDS["fqi"].summarise("x", runs)
    assert s.score == pytest.approx((10 + 70 / 3) / 2)  # mean of all 3 iterations (< 5)
    assert s.curve_mean.tolist() == [-6.0, 0.0, 20.0, 30.0]
    assert s.instability == pytest.approx(15.0) and s.best == 40.0 and s.seconds == 3.0
    assert s.mean_peak == 30.0 and s.spread == pytest.approx(20 / 3)  # sd 0, 10, 10
    assert np.isnan(KINDS["fqi"].summarise("x", runs[:1]).spread)
    rmse = [{"fold_rmse": [1.0, 3.0], "seconds": 1.0}, {"fold_rmse": [4.0, 6.0], "seconds": 1.0}]
    assert KINDS["rmse"].summarise("x", rmse[:1]).score_se == pytest.approx(1.0)
    assert KINDS["rmse"].summarise("x", rmse).score_se == pytest.approx(
        np.std([2, 5], ddof=1) / np.sqrt(2))


# ------------------------------------------------------------------------------ report
def test_report_shows_thesis_numbers_beside_ours_and_computed_verdicts(tmp_path):
    experiment = REGISTRY["sampling"]
    budget = replace(TINY, iterations=3)
    for label, curves in {"normal": ([90e3, 10e3, 50e3], [80e3, 20e3, 50e3]),
                          "mixed (every 5)": ([50e3, 60e3, 70e3], [55e3, 65e3, 75e3])}.items():
        for seed, curve in enumerate(curves):
            save_unit(_unit(tmp_path, "sampling", label, seed, budget, budget.samples),
                      {"rewards": list(curve), "random_reward": -95e3, "seconds": 60.0})
    report = write_outputs([experiment], budget, tmp_path, seeds=[0, 1])
    text = report.read_text()
    section = text[text.index('<a id="sampling">'):]
    assert "| mixed (every 5) | 2 | 62,500 +- 3,536 |" in section  # mean of the 3 it.
    assert "more stable, higher mean" in section  # the thesis's statement beside ours
    assert "- mixed has the higher mean: **yes**" in section
    assert "- mixed is more stable: **yes**" in section
    assert "| 3.9 | [sampling](#sampling) | 4/4 | mixed has the higher mean | yes |" in text
    assert (tmp_path / "fig3.9_sampling.png").exists()
    assert "Not run at this budget yet." in text  # the other experiments
    assert ("| 3.6 | [representations](#representations) | 0/10 | fixed ~ bounded > random box "
            "> grid > classic | n/a | not run at this budget yet |") in text


def test_figures_use_the_renderers_colours_and_envs_names():
    for kind, (colour, _, _) in _STYLE.items():  # a test box: the colour of what it tests
        assert to_rgb(plots._TYPE_COLOURS[kind]) == pytest.approx(np.array(colour) / 255)
    assert len(plots.TYPE_NAMES) == len(envs.TYPE_NAMES)
    assert plots.TYPE_NAMES[envs.MONEY_MARKER] == "money marker"
    assert plots.ACTION_NAMES == ("up", "right", "down", "left", "swipe up", "swipe right",
                                  "swipe down", "swipe left")


def test_budget_overrides_reach_every_setting_of_their_experiment_and_its_cache(tmp_path):
    budget = replace(TINY, overrides={"treasure": {"n_estimators": 1}})
    units = plan([REGISTRY["treasure"], REGISTRY["sampling"]], budget, tmp_path)
    trees = {(u.experiment, u.label): u.params["n_estimators"] for u in units}
    assert {v for (e, _), v in trees.items() if e == "treasure"} == {1}
    assert {v for (e, _), v in trees.items() if e == "sampling"} == {30}
    # a run cached without the override is not reused with it
    unit = next(u for u in units if u.experiment == "treasure")
    save_unit(replace(unit, params=REGISTRY["treasure"].params(unit.label)),
              {"rewards": [0.0], "seconds": 1.0})
    assert load_unit(unit) is None
    report = write_outputs([REGISTRY["treasure"]], budget, tmp_path).read_text()
    assert "`treasure` runs with n_estimators=1 (every setting alike)" in report


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
        "python -m benchmarks.run_all: error: cannot reach the Dask scheduler at tcp://127.0.0.1:1: Timed out "
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
    return dict(_FQI_RESULT)


def _mixed_kills_its_worker(unit):
    if unit.settings.resample_every == 5:
        os._exit(1)
    return dict(_FQI_RESULT)


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
        assert all(load_unit(u)["result"] == _FQI_RESULT for u in units[:3])
        assert skipped == [] and not any(attempts(u.path) for u in units)
        assert run(units, progress=False, client=dask_client) == (
            [(units[3], _FQI_RESULT["seconds"])], [])


def test_an_interrupted_cluster_run_is_no_crash(dask_client, tmp_path, monkeypatch):
    units = plan([REGISTRY["sampling"]], TINY, tmp_path, seeds=[0, 1])
    mark_attempt(units[0].path)  # one real crash before
    monkeypatch.setattr(runner, "save_unit", _interrupt)  # Ctrl-C as the first result comes
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


def test_bench_fqi_and_sweep_fqi_runs_are_registry_settings():
    """The thesis-scale benchmark and the sweeps build their agents from the registry."""
    from benchmarks import bench_fqi, sweep_fqi
    from benchmarks.reproduce.registry import REGISTRY

    for experiment, label, changes in [*bench_fqi.FQI_RUNS.values(), *sweep_fqi.REGIMES.values()]:
        params = REGISTRY[experiment].params(label)
        assert params["kind"] == "fqi" and set(changes) <= {"resample_every", "gamma"}
    assert sweep_fqi._params(sweep_fqi.REGIMES["offline"], 10)["resample_every"] is None
    assert sweep_fqi._params(sweep_fqi.REGIMES["keep"], 10)["n_estimators"] == 10


def test_baseline_searches_run_when_named_with_their_own_seeds_and_curves(tmp_path):
    report = main(["--budget", "tiny", "--only", "search_dqn_grid,search_dqn_objects",
                   "--out", str(tmp_path), "--no-progress"])
    search = REGISTRY["search_dqn_objects"]
    assert len(search.settings) == 8 and search.seeds == 2
    # its own 2 seeds at the full and quick budgets, at most the budget's (1 at tiny)
    assert runner.seeds_for(search, BUDGETS["full"]) == runner.seeds_for(
        search, BUDGETS["quick"]) == [0, 1]
    assert runner.seeds_for(search, TINY) == [0]
    assert runner.seeds_for(REGISTRY["rmse_K_datasets"], BUDGETS["full"]) == list(range(5))
    for name in ("search_dqn_grid", "search_dqn_objects"):
        for label in REGISTRY[name].settings:
            for seed in runner.seeds_for(REGISTRY[name], TINY):
                result = json.loads(unit_path(tmp_path, TINY, name, label, seed).read_text())["result"]
                steps = [s for s, _ in result["curve"]]
                assert len(steps) == 4 and steps == sorted(steps)
                assert result["curve"][-1] == [result["total_timesteps"], result["reward"]]
        assert f'<a id="{name}"></a>' in report.read_text()
    assert '<a id="search_ppo_objects"></a>' not in report.read_text()


@pytest.mark.parametrize("name", ["full", "quick"])
def test_the_tuned_baselines_are_scored_once_per_fqi_iteration(name):
    baselines, budget = REGISTRY["baselines"], BUDGETS[name]
    own = [label for label, setting in baselines.settings.items() if "same_as" not in setting]
    assert len(own) == 3
    assert [baselines.params(label, budget)["checkpoints"] for label in own] == [
        budget.iterations] * 3


@pytest.mark.parametrize("normalize, gamma", [(False, 0.9), (True, 0.9), (True, None)])
def test_a_ppo_run_on_the_objects_with_attention(normalize, gamma, monkeypatch):
    import stable_baselines3
    from stable_baselines3.common import vec_env

    from benchmarks import training
    from benchmarks.reproduce.units import run_unit

    wrapped = []

    class OtherDefault(stable_baselines3.PPO):  # a discount default of its own
        def __init__(self, *args, gamma=0.95, **kwargs):
            super().__init__(*args, gamma=gamma, **kwargs)

    class Recorded(vec_env.VecNormalize):
        def __init__(self, venv, **kwargs):
            super().__init__(venv, **kwargs)
            wrapped.append((kwargs, self))

    monkeypatch.setattr(training, "VecNormalize", Recorded)
    monkeypatch.setitem(training.ALGORITHMS, "PPO", OtherDefault)
    params = {**REGISTRY["search_ppo_objects"].params("CartPole, gamma 0.9, attention"),
              "hyperparams": {"n_envs": 2, "n_steps": 32, "batch_size": 32, "n_epochs": 1,
                              "normalize": normalize, **({} if gamma is None else
                                                         {"gamma": gamma})},
              "step_scale": 1.0, "max_objects": 32}
    result = run_unit(Unit("search_ppo_objects", "CartPole, gamma 0.9, attention", 0, params,
                           TINY.samples, TINY, None))
    assert params["attention"] and result["total_timesteps"] >= TINY.dqn_steps
    assert len(result["curve"]) == 4 and np.isfinite(result["reward"])
    # rewards only, at the run's discount (the algorithm's default if not set); never the
    # padded observations
    assert [kwargs for kwargs, _ in wrapped] == (
        [{"norm_obs": False, "norm_reward": True, "gamma": gamma or 0.95}] if normalize
        else [])
    # and the model trained through it: its return statistics saw every step
    assert all(env.ret_rms.count >= TINY.dqn_steps for _, env in wrapped)


def test_reference_policies_score_on_the_reference_worlds_as_learners_do():
    from fqi import evaluate
    from benchmarks.reproduce.units import run_unit

    budget = replace(TINY, eval_steps=150)  # 3 reference worlds
    seeds = envs.reference_worlds(3)
    worlds = envs.BatchedObjectWorld(3)
    def unit(params):
        return Unit("ceiling", "reference", 0, {"kind": "policy", "env_id": "ObjectWorld-v0",
                                                **params}, TINY.samples, budget, None)

    greedy = run_unit(unit({"policy": "greedy"}))
    direct = evaluate(envs.GreedyPolicy(worlds), worlds, seeds=seeds)
    assert greedy["episode_returns"] == direct.returns.tolist()
    assert greedy["reward"] == direct.total * budget.reward_scale
    planner = run_unit(unit({"policy": "planner", "depth": 2, "width": 2}))
    rewards = [envs.LookaheadPlanner(depth=2, width=2).play(envs.ObjectWorldEnv(), seed=s)[1]
               for s in seeds]
    assert planner["episode_returns"] == [float(r.sum()) for r in rewards]
    assert planner["player"] == "LookaheadPlanner(depth=2, width=2, route_width=50, discount=0.95)"


def test_baselines_share_their_owners_runs_and_read_against_the_ceiling(tiny_run):
    out, _ = tiny_run
    baselines = REGISTRY["baselines"]
    owners = {resolve(baselines, label)[0].name for label in baselines.settings}
    assert owners == {"representations", "keep_data", "baselines", "ceiling"}
    # one run of each reference policy, the budget's seeds for the rest
    assert len(runner.seeds_for(REGISTRY["ceiling"], BUDGETS["full"])) == 1
    stats, runs = gather(baselines, TINY, out)
    assert set(stats) == set(baselines.settings)
    section = (out / "REPORT.md").read_text().split('<a id="baselines"></a>')[1]
    ceiling = stats["look-ahead planner"].score
    for label, s in stats.items():
        assert f"| {label} | {s.n_runs} | {s.score:,.0f} +- {s.score_sd:,.0f} | " \
               f"{s.score / ceiling:.0%} |" in section
    fqi_run = runs["box FQI, fixed TW=1"][0]
    assert fqi_run["result"]["rewards"] == json.loads(unit_path(
        out, TINY, "representations", "fixed TW=1", 0).read_text())["result"]["rewards"]
    assert (out / "extra_baselines.png").stat().st_size > 0


def test_an_ablations_game_constants_and_ridge_penalty_reach_its_units():
    from benchmarks.reproduce.kinds._game import make_env, regressor

    def settings(experiment, label):
        return KINDS[experiment.kind].settings(experiment.params(label))

    rules = make_env(settings(REGISTRY["rmse_TW_reach"], "TW=2.5, reach 2")).unwrapped.rules
    assert (rules.contact_radius, rules.start_clearance) == (2.0, 2.0)
    assert make_env(settings(REGISTRY["rmse_TW"], "TW=2.5")).unwrapped.rules.contact_radius \
        == 0.6
    grid = settings(REGISTRY["fqi_grid_alpha"], "N=15, alpha=1000")
    ridge = regressor(grid, make_env(grid), TINY, 0)
    assert ridge[0].n_bins == 15 and ridge[-1].alpha == 1000.0
    other = regressor(settings(REGISTRY["fqi_grid"], "N=15"), make_env(grid), TINY, 0)
    assert other[-1].alpha == 1.0


def test_each_ablation_is_reported_under_why_it_differs_in_the_sections_it_explains(tiny_run):
    out, _ = tiny_run
    text = (out / "REPORT.md").read_text()
    sections = dict(re.findall(r'<a id="(\w+)"></a>\n(.*?)(?=<a id=|\Z)', text, re.S))
    summary = json.loads((out / "summary.json").read_text())["experiments"]
    for ablation in (e for e in EXPERIMENTS if e.explains):
        for name in ablation.explains:
            why = sections[name].split("### Why it differs", 1)[1]
            assert f"([{ablation.name}](#{ablation.name})," in why
            assert ablation.hypothesis in why
            claims = [rule.claim for rule in REGISTRY[name].findings]
            for finding in summary[ablation.name]["findings"]:   # the computed verdicts
                mark = {True: "yes", False: "no"}.get(finding["holds"], "n/a")
                line = f"- {finding['claim']}: **{mark}**. {finding['explanation']}"
                # listed where they re-check one of the section's own claims, only there
                related = any(finding["claim"] == c or finding["claim"].endswith(f": {c}")
                              for c in claims)
                assert (line in why) == related, (name, line)
            assert re.search(r"Shown( so far)?: (recovered in this ablation|undetermined|not "
                             r"recovered)",
                             why)
    rep = sections["representations"].split("### Why it differs", 1)[1]
    assert "grid + ridge reaches a positive reward: **" in rep and "10 > 15 > 21" not in rep
