"""benchmarks/bench_stopping.py at a tiny size: its measures of FQI's iterates are those of
the agents it traces, and a rerun reuses the finished runs."""
import json

import numpy as np
import pytest

from benchmarks import bench_offline, bench_stopping


def test_each_backup_is_measured_on_the_data_states():
    from fqi import RandomPolicy

    data, _ = bench_offline.collect(RandomPolicy("CartPole-v1", seed=0), 600, seed=0, n_envs=2)
    run = bench_stopping.trace_fqi(data, "fqi-nmin10", seed=0, n_iterations=3)
    assert [row["iteration"] for row in run["iterations"]] == [0, 1, 2]
    # the same seeded agents, stopped after 2 and 3 backups, give the measures
    agents = [bench_offline.make_agent("fqi-nmin10", seed=0).learn_offline(data, n_iterations=n)
              for n in (2, 3)]
    q = [agent.q_values(data["observations"]) for agent in agents]
    first, _, last = run["iterations"]
    assert first["q_change"] is None and first["greedy_flips"] is None
    assert last["q_rms"] == pytest.approx(np.sqrt(np.mean(q[1] ** 2)))
    assert last["q_change"] == pytest.approx(np.sqrt(np.mean((q[1] - q[0]) ** 2)))
    assert last["greedy_flips"] == np.mean(q[1].argmax(1) != q[0].argmax(1))
    assert 0 < last["q_change"] < last["q_rms"]  # a backup moves Q, by less than its size
    assert last["mean_return"] == bench_offline.held_out_return(agents[1])
    assert run["mean_return"] == last["mean_return"]
    assert all(8 <= row["mean_return"] <= 500 for row in run["iterations"])
    assert 0 < run["train_seconds"] and 0 < run["train_cpu_seconds"]


def test_the_quick_run_then_a_rerun_from_its_runs(tmp_path, monkeypatch, capsys):
    argv = ["--quick", "--out", str(tmp_path / "out"), "--data", str(tmp_path / "data")]
    bench_stopping.main(argv)
    report = json.loads((tmp_path / "out" / "bench_stopping.json").read_text())
    assert [(r["dataset"], r["method"]) for r in report["runs"]] == [
        ("random", method) for method in bench_offline.FQI_METHODS]
    assert all(len(r["iterations"]) == bench_stopping.QUICK["iterations"]
               for r in report["runs"])
    assert (tmp_path / "out" / "bench_stopping.png").stat().st_size
    printed = capsys.readouterr().out
    assert "| random | fqi-grown | 0 | from 2 |" in report["markdown"] in printed
    monkeypatch.setattr(bench_stopping, "trace_fqi", lambda *a: pytest.fail("retrained"))
    bench_stopping.main(argv)
    assert json.loads((tmp_path / "out" / "bench_stopping.json").read_text())["runs"] == \
        report["runs"]


def test_too_few_iterations_are_refused():
    with pytest.raises(SystemExit):
        bench_stopping.parse_args(["--iterations", "1"])
