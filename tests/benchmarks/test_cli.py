"""`python -m benchmarks.run_all`'s command line: arguments checked before any work, one
error line for what a user can fix, exit codes."""
import errno

import pytest

from benchmarks.reproduce import REGISTRY, runner
from benchmarks.reproduce.cache import attempts, mark_attempt, save_unit
from benchmarks.reproduce.cli import main, parse_seeds
from benchmarks.reproduce.runner import MAX_ATTEMPTS, plan

from harness import FQI_RESULT, TINY, interrupt


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
        f"python -m benchmarks.run_all: error: cannot write under --out {tmp_path}: "
        f"Permission denied: "
        f"{unit.path.parent}"]

    def missing(*args):
        raise FileNotFoundError(errno.ENOENT, "No such file or directory", "/elsewhere")

    monkeypatch.undo()
    monkeypatch.setattr(runner, "run_unit", missing)
    with pytest.raises(FileNotFoundError):  # a unit's own error keeps its traceback
        main(argv)


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
    assert err.endswith(f"python -m benchmarks.run_all: error: 1 run(s) skipped after "
                        f"crashing {MAX_ATTEMPTS} "
                        f"times (listed above); the report counts them as missing\n")
    assert "| extra | [attention](#attention) | 0/1 |" in (tmp_path / "REPORT.md").read_text()


def test_an_interrupted_command_says_so_in_one_line(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(runner, "run_unit", interrupt)
    with pytest.raises(SystemExit) as exit_:
        main(["--budget", "tiny", "--only", "attention", "--out", str(tmp_path),
              "--no-progress"])
    assert exit_.value.code == 130
    assert capsys.readouterr().err.splitlines() == [
        "python -m benchmarks.run_all: interrupted; finished runs are cached: run the same "
        "command to resume"]
    unit, = plan([REGISTRY["attention"]], TINY, tmp_path)
    assert attempts(unit.path) == 0


def test_plan_prints_the_runs_and_the_runner_s_estimate_and_writes_nothing(tmp_path, capsys):
    units = plan([REGISTRY["fqi_nmin"]], TINY, tmp_path)
    argv = ["--budget", "tiny", "--only", "fqi_nmin", "--out", str(tmp_path), "--plan"]
    for cached in (0, 1):
        hours = [unit.cost() / 3600 for unit in units[cached:]]
        assert main(argv) is None
        assert capsys.readouterr().out == (
            f"{len(units)} runs planned at the tiny budget, {len(units) - cached} of them not "
            f"cached: about {sum(hours):.1f} h by the runner's estimate (2 free cores, one run "
            f"at a time), the longest {max(hours):.1f} h\n")
        save_unit(units[0], FQI_RESULT)
    assert [path.name for path in tmp_path.rglob("*") if path.is_file()] == ["seed0.json"]
