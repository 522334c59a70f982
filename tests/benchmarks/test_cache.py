"""The cache of finished units and the checkpoints of unfinished ones."""
import json
import os
from dataclasses import replace

import pytest

from benchmarks.reproduce import REGISTRY, runner
from benchmarks.reproduce.cache import (Checkpoint, attempts, load_unit, mark_attempt, save_unit,
                                        slug, unit_path)
from benchmarks.reproduce.cli import main
from benchmarks.reproduce.runner import gather

from harness import FQI_RESULT, TINY, make_unit, save_sampling


# ------------------------------------------------------------------------------ cache
def test_cache_round_trip_and_mismatch(tmp_path):
    unit = make_unit(tmp_path, "fqi_K", "K=50")
    path = unit.path
    assert path == tmp_path / "runs" / "tiny" / "fqi_K" / "K-50" / "seed0.json"
    save_unit(unit, FQI_RESULT)
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
    good = save_sampling(tmp_path, "normal", 0)
    bad = save_sampling(tmp_path, "mixed (every 5)", 0)
    bad.write_text(damage(bad))
    kept = good.stat().st_mtime_ns
    argv = ["--budget", "tiny", "--only", "sampling", "--seeds", "1", "--out", str(tmp_path),
            "--no-progress"]
    text = main([*argv, "--report-only"]).read_text()
    assert "| 3.9 | [sampling](#sampling) | 1/2 |" in text  # the good run, not the bad one
    # once, though keep_data's "mixed" setting reads the same file
    assert [line for line in capsys.readouterr().err.splitlines() if str(bad) in line] == [
        f"ignoring {bad}: not a run record ({problem}); it counts as missing"]
    monkeypatch.setattr(runner, "run_unit", lambda *args: dict(FQI_RESULT))
    main(argv)
    assert load_unit(make_unit(tmp_path, "sampling", "mixed (every 5)", samples=TINY.samples))[
        "result"] == FQI_RESULT  # run again
    assert good.stat().st_mtime_ns == kept


def test_a_run_is_never_counted_twice(tmp_path, capsys):
    seed0 = save_sampling(tmp_path, "normal", 0)
    stats, _ = gather(REGISTRY["sampling"], TINY, tmp_path, seeds=[0, 0])
    assert stats["normal"].n_runs == 1
    seed1 = unit_path(tmp_path, TINY, "sampling", "normal", 1)
    seed1.write_text(seed0.read_text())  # a copy is not the run of seed 1
    stats, _ = gather(REGISTRY["sampling"], TINY, tmp_path, seeds=[0, 1])
    assert stats["normal"].n_runs == 1
    assert f"ignoring {seed1}: not a run record (it records seed 0)" in capsys.readouterr().err


def test_a_checkpoint_serves_only_its_own_unit_and_code(tmp_path, capsys):
    unit = make_unit(tmp_path, "sampling", "normal")
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
    save_unit(unit, FQI_RESULT)
    assert not checkpoint.path.exists()


def test_a_start_that_saved_progress_is_no_crash_and_a_failed_save_no_failure(tmp_path,
                                                                              capsys):
    unit = make_unit(tmp_path, "sampling", "normal")
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
